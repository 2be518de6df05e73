4000 starts from runs/s59/wrist-40000000.safetensors
by the cube's yaw from square to the hand:
   0 to  5 degrees: 378 starts, 23 failed (6.1%)
   5 to 15 degrees: 1112 starts, 39 failed (3.5%)
  15 to 25 degrees: 832 starts, 23 failed (2.8%)
  25 to 35 degrees: 858 starts, 12 failed (1.4%)
  35 to 45 degrees: 820 starts, 15 failed (1.8%)
by the distance from the resting point across the palm:
   0 to   3 mm: 513 starts, 11 failed (2.1%)
   3 to   6 mm: 1029 starts, 22 failed (2.1%)
   6 to  10 mm: 933 starts, 32 failed (3.4%)
  10 to 100 mm: 1525 starts, 47 failed (3.1%)
by the side of the resting point (x across the palm, y along the hand):
  x < 0 (towards the thumb): 1013 starts, 59 failed (5.8%)
  x > 0 (towards the little finger): 2987 starts, 53 failed (1.8%)
  y < 0 (towards the fingertips): 754 starts, 54 failed (7.2%)
  y > 0 (towards the wrist): 3246 starts, 58 failed (1.8%)
runs/s59/gsq40M.safetensors: 259 starts, 35 marked failed
