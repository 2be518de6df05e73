4000 starts from runs/s57/spec-32000000.safetensors
by the cube's yaw from square to the hand:
   0 to  5 degrees: 376 starts, 10 failed (2.7%)
   5 to 15 degrees: 1122 starts, 43 failed (3.8%)
  15 to 25 degrees: 841 starts, 32 failed (3.8%)
  25 to 35 degrees: 815 starts, 30 failed (3.7%)
  35 to 45 degrees: 846 starts, 36 failed (4.3%)
by the distance from the resting point across the palm:
   0 to   3 mm: 536 starts, 15 failed (2.8%)
   3 to   6 mm: 1033 starts, 32 failed (3.1%)
   6 to  10 mm: 924 starts, 41 failed (4.4%)
  10 to 100 mm: 1507 starts, 63 failed (4.2%)
by the side of the resting point (x across the palm, y along the hand):
  x < 0 (towards the thumb): 1016 starts, 61 failed (6.0%)
  x > 0 (towards the little finger): 2984 starts, 90 failed (3.0%)
  y < 0 (towards the fingertips): 760 starts, 66 failed (8.7%)
  y > 0 (towards the wrist): 3240 starts, 85 failed (2.6%)
runs/s57/yp32M.safetensors: 3240 starts, 85 marked failed
