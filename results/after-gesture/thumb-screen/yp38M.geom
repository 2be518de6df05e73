4000 starts from runs/s58/wrist-38000000.safetensors
by the cube's yaw from square to the hand:
   0 to  5 degrees: 408 starts, 22 failed (5.4%)
   5 to 15 degrees: 1080 starts, 36 failed (3.3%)
  15 to 25 degrees: 807 starts, 21 failed (2.6%)
  25 to 35 degrees: 861 starts, 22 failed (2.6%)
  35 to 45 degrees: 844 starts, 23 failed (2.7%)
by the distance from the resting point across the palm:
   0 to   3 mm: 543 starts, 8 failed (1.5%)
   3 to   6 mm: 1008 starts, 24 failed (2.4%)
   6 to  10 mm: 924 starts, 39 failed (4.2%)
  10 to 100 mm: 1525 starts, 53 failed (3.5%)
by the side of the resting point (x across the palm, y along the hand):
  x < 0 (towards the thumb): 1002 starts, 57 failed (5.7%)
  x > 0 (towards the little finger): 2998 starts, 67 failed (2.2%)
  y < 0 (towards the fingertips): 724 starts, 54 failed (7.5%)
  y > 0 (towards the wrist): 3276 starts, 70 failed (2.1%)
runs/s58/yp38M.safetensors: 3276 starts, 70 marked failed
