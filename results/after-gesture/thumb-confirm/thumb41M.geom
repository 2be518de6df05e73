3267 starts from runs/s59/yp41M.safetensors
by the cube's yaw from square to the hand:
   0 to  5 degrees: 295 starts, 6 failed (2.0%)
   5 to 15 degrees: 889 starts, 14 failed (1.6%)
  15 to 25 degrees: 653 starts, 8 failed (1.2%)
  25 to 35 degrees: 715 starts, 13 failed (1.8%)
  35 to 45 degrees: 715 starts, 14 failed (2.0%)
by the distance from the resting point across the palm:
   0 to   3 mm: 375 starts, 1 failed (0.3%)
   3 to   6 mm: 832 starts, 10 failed (1.2%)
   6 to  10 mm: 710 starts, 11 failed (1.5%)
  10 to 100 mm: 1350 starts, 33 failed (2.4%)
by the side of the resting point (x across the palm, y along the hand):
  x < 0 (towards the thumb): 450 starts, 16 failed (3.6%)
  x > 0 (towards the little finger): 2817 starts, 39 failed (1.4%)
  y < 0 (towards the fingertips): 0 starts, 0 failed (0.0%)
  y > 0 (towards the wrist): 3267 starts, 55 failed (1.7%)
runs/s59/thumb41M.safetensors: 450 starts, 16 marked failed
