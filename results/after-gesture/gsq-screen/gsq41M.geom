4000 starts from runs/s59/wrist-41000000.safetensors
by the cube's yaw from square to the hand:
   0 to  5 degrees: 376 starts, 18 failed (4.8%)
   5 to 15 degrees: 1050 starts, 29 failed (2.8%)
  15 to 25 degrees: 846 starts, 14 failed (1.7%)
  25 to 35 degrees: 878 starts, 18 failed (2.1%)
  35 to 45 degrees: 850 starts, 18 failed (2.1%)
by the distance from the resting point across the palm:
   0 to   3 mm: 496 starts, 7 failed (1.4%)
   3 to   6 mm: 1017 starts, 19 failed (1.9%)
   6 to  10 mm: 946 starts, 26 failed (2.7%)
  10 to 100 mm: 1541 starts, 45 failed (2.9%)
by the side of the resting point (x across the palm, y along the hand):
  x < 0 (towards the thumb): 1004 starts, 44 failed (4.4%)
  x > 0 (towards the little finger): 2996 starts, 53 failed (1.8%)
  y < 0 (towards the fingertips): 733 starts, 42 failed (5.7%)
  y > 0 (towards the wrist): 3267 starts, 55 failed (1.7%)
runs/s59/gsq41M.safetensors: 242 starts, 27 marked failed
