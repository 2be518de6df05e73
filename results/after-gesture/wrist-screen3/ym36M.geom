4000 starts from runs/s58/wrist-36000000.safetensors
by the cube's yaw from square to the hand:
   0 to  5 degrees: 393 starts, 20 failed (5.1%)
   5 to 15 degrees: 1064 starts, 48 failed (4.5%)
  15 to 25 degrees: 852 starts, 14 failed (1.6%)
  25 to 35 degrees: 844 starts, 18 failed (2.1%)
  35 to 45 degrees: 847 starts, 18 failed (2.1%)
by the distance from the resting point across the palm:
   0 to   3 mm: 511 starts, 8 failed (1.6%)
   3 to   6 mm: 1021 starts, 23 failed (2.3%)
   6 to  10 mm: 898 starts, 37 failed (4.1%)
  10 to 100 mm: 1570 starts, 50 failed (3.2%)
by the side of the resting point (x across the palm, y along the hand):
  x < 0 (towards the thumb): 944 starts, 64 failed (6.8%)
  x > 0 (towards the little finger): 3056 starts, 54 failed (1.8%)
  y < 0 (towards the fingertips): 731 starts, 57 failed (7.8%)
  y > 0 (towards the wrist): 3269 starts, 61 failed (1.9%)
runs/s58/ym36M.safetensors: 731 starts, 57 marked failed
