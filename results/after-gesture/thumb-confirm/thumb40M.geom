3246 starts from runs/s59/yp40M.safetensors
by the cube's yaw from square to the hand:
   0 to  5 degrees: 286 starts, 6 failed (2.1%)
   5 to 15 degrees: 945 starts, 21 failed (2.2%)
  15 to 25 degrees: 634 starts, 17 failed (2.7%)
  25 to 35 degrees: 699 starts, 7 failed (1.0%)
  35 to 45 degrees: 682 starts, 7 failed (1.0%)
by the distance from the resting point across the palm:
   0 to   3 mm: 392 starts, 7 failed (1.8%)
   3 to   6 mm: 839 starts, 11 failed (1.3%)
   6 to  10 mm: 686 starts, 9 failed (1.3%)
  10 to 100 mm: 1329 starts, 31 failed (2.3%)
by the side of the resting point (x across the palm, y along the hand):
  x < 0 (towards the thumb): 452 starts, 18 failed (4.0%)
  x > 0 (towards the little finger): 2794 starts, 40 failed (1.4%)
  y < 0 (towards the fingertips): 0 starts, 0 failed (0.0%)
  y > 0 (towards the wrist): 3246 starts, 58 failed (1.8%)
runs/s59/thumb40M.safetensors: 452 starts, 18 marked failed
