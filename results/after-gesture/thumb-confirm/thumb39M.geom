3245 starts from runs/s59/yp39M.safetensors
by the cube's yaw from square to the hand:
   0 to  5 degrees: 300 starts, 6 failed (2.0%)
   5 to 15 degrees: 963 starts, 27 failed (2.8%)
  15 to 25 degrees: 653 starts, 14 failed (2.1%)
  25 to 35 degrees: 654 starts, 11 failed (1.7%)
  35 to 45 degrees: 675 starts, 11 failed (1.6%)
by the distance from the resting point across the palm:
   0 to   3 mm: 389 starts, 4 failed (1.0%)
   3 to   6 mm: 831 starts, 8 failed (1.0%)
   6 to  10 mm: 746 starts, 22 failed (2.9%)
  10 to 100 mm: 1279 starts, 35 failed (2.7%)
by the side of the resting point (x across the palm, y along the hand):
  x < 0 (towards the thumb): 459 starts, 26 failed (5.7%)
  x > 0 (towards the little finger): 2786 starts, 43 failed (1.5%)
  y < 0 (towards the fingertips): 0 starts, 0 failed (0.0%)
  y > 0 (towards the wrist): 3245 starts, 69 failed (2.1%)
runs/s59/thumb39M.safetensors: 459 starts, 26 marked failed
