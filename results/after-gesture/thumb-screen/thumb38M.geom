3276 starts from runs/s58/yp38M.safetensors
by the cube's yaw from square to the hand:
   0 to  5 degrees: 311 starts, 9 failed (2.9%)
   5 to 15 degrees: 921 starts, 18 failed (2.0%)
  15 to 25 degrees: 620 starts, 14 failed (2.3%)
  25 to 35 degrees: 708 starts, 17 failed (2.4%)
  35 to 45 degrees: 716 starts, 12 failed (1.7%)
by the distance from the resting point across the palm:
   0 to   3 mm: 423 starts, 3 failed (0.7%)
   3 to   6 mm: 828 starts, 14 failed (1.7%)
   6 to  10 mm: 695 starts, 18 failed (2.6%)
  10 to 100 mm: 1330 starts, 35 failed (2.6%)
by the side of the resting point (x across the palm, y along the hand):
  x < 0 (towards the thumb): 465 starts, 22 failed (4.7%)
  x > 0 (towards the little finger): 2811 starts, 48 failed (1.7%)
  y < 0 (towards the fingertips): 0 starts, 0 failed (0.0%)
  y > 0 (towards the wrist): 3276 starts, 70 failed (2.1%)
runs/s58/thumb38M.safetensors: 465 starts, 22 marked failed
