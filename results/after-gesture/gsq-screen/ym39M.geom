4000 starts from runs/s59/wrist-39000000.safetensors
by the cube's yaw from square to the hand:
   0 to  5 degrees: 376 starts, 17 failed (4.5%)
   5 to 15 degrees: 1129 starts, 45 failed (4.0%)
  15 to 25 degrees: 849 starts, 24 failed (2.8%)
  25 to 35 degrees: 820 starts, 19 failed (2.3%)
  35 to 45 degrees: 826 starts, 20 failed (2.4%)
by the distance from the resting point across the palm:
   0 to   3 mm: 540 starts, 13 failed (2.4%)
   3 to   6 mm: 1004 starts, 14 failed (1.4%)
   6 to  10 mm: 970 starts, 48 failed (4.9%)
  10 to 100 mm: 1486 starts, 50 failed (3.4%)
by the side of the resting point (x across the palm, y along the hand):
  x < 0 (towards the thumb): 1013 starts, 64 failed (6.3%)
  x > 0 (towards the little finger): 2987 starts, 61 failed (2.0%)
  y < 0 (towards the fingertips): 755 starts, 56 failed (7.4%)
  y > 0 (towards the wrist): 3245 starts, 69 failed (2.1%)
runs/s59/ym39M.safetensors: 755 starts, 56 marked failed
