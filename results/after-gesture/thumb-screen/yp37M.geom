4000 starts from runs/s58/wrist-37000000.safetensors
by the cube's yaw from square to the hand:
   0 to  5 degrees: 367 starts, 18 failed (4.9%)
   5 to 15 degrees: 1075 starts, 27 failed (2.5%)
  15 to 25 degrees: 852 starts, 13 failed (1.5%)
  25 to 35 degrees: 858 starts, 13 failed (1.5%)
  35 to 45 degrees: 848 starts, 21 failed (2.5%)
by the distance from the resting point across the palm:
   0 to   3 mm: 510 starts, 6 failed (1.2%)
   3 to   6 mm: 1017 starts, 16 failed (1.6%)
   6 to  10 mm: 901 starts, 32 failed (3.6%)
  10 to 100 mm: 1572 starts, 38 failed (2.4%)
by the side of the resting point (x across the palm, y along the hand):
  x < 0 (towards the thumb): 952 starts, 48 failed (5.0%)
  x > 0 (towards the little finger): 3048 starts, 44 failed (1.4%)
  y < 0 (towards the fingertips): 740 starts, 45 failed (6.1%)
  y > 0 (towards the wrist): 3260 starts, 47 failed (1.4%)
runs/s58/yp37M.safetensors: 3260 starts, 47 marked failed
