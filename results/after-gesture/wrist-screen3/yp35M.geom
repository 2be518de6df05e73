4000 starts from runs/s58/wrist-35000000.safetensors
by the cube's yaw from square to the hand:
   0 to  5 degrees: 375 starts, 18 failed (4.8%)
   5 to 15 degrees: 1081 starts, 33 failed (3.1%)
  15 to 25 degrees: 861 starts, 16 failed (1.9%)
  25 to 35 degrees: 853 starts, 16 failed (1.9%)
  35 to 45 degrees: 830 starts, 15 failed (1.8%)
by the distance from the resting point across the palm:
   0 to   3 mm: 552 starts, 9 failed (1.6%)
   3 to   6 mm: 968 starts, 16 failed (1.7%)
   6 to  10 mm: 971 starts, 33 failed (3.4%)
  10 to 100 mm: 1509 starts, 40 failed (2.7%)
by the side of the resting point (x across the palm, y along the hand):
  x < 0 (towards the thumb): 1000 starts, 58 failed (5.8%)
  x > 0 (towards the little finger): 3000 starts, 40 failed (1.3%)
  y < 0 (towards the fingertips): 705 starts, 44 failed (6.2%)
  y > 0 (towards the wrist): 3295 starts, 54 failed (1.6%)
runs/s58/yp35M.safetensors: 3295 starts, 54 marked failed
