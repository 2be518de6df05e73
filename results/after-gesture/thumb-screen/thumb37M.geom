3260 starts from runs/s58/yp37M.safetensors
by the cube's yaw from square to the hand:
   0 to  5 degrees: 286 starts, 10 failed (3.5%)
   5 to 15 degrees: 898 starts, 15 failed (1.7%)
  15 to 25 degrees: 662 starts, 7 failed (1.1%)
  25 to 35 degrees: 693 starts, 7 failed (1.0%)
  35 to 45 degrees: 721 starts, 8 failed (1.1%)
by the distance from the resting point across the palm:
   0 to   3 mm: 382 starts, 4 failed (1.0%)
   3 to   6 mm: 814 starts, 6 failed (0.7%)
   6 to  10 mm: 684 starts, 13 failed (1.9%)
  10 to 100 mm: 1380 starts, 24 failed (1.7%)
by the side of the resting point (x across the palm, y along the hand):
  x < 0 (towards the thumb): 422 starts, 14 failed (3.3%)
  x > 0 (towards the little finger): 2838 starts, 33 failed (1.2%)
  y < 0 (towards the fingertips): 0 starts, 0 failed (0.0%)
  y > 0 (towards the wrist): 3260 starts, 47 failed (1.4%)
runs/s58/thumb37M.safetensors: 422 starts, 14 marked failed
