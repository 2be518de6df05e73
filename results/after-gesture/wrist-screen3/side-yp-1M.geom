1000 starts from runs/s58/wrist-1M.safetensors
by the cube's yaw from square to the hand:
   0 to  5 degrees: 109 starts, 8 failed (7.3%)
   5 to 15 degrees: 287 starts, 14 failed (4.9%)
  15 to 25 degrees: 218 starts, 2 failed (0.9%)
  25 to 35 degrees: 190 starts, 2 failed (1.1%)
  35 to 45 degrees: 196 starts, 7 failed (3.6%)
by the distance from the resting point across the palm:
   0 to   3 mm: 141 starts, 1 failed (0.7%)
   3 to   6 mm: 273 starts, 8 failed (2.9%)
   6 to  10 mm: 243 starts, 12 failed (4.9%)
  10 to 100 mm: 343 starts, 12 failed (3.5%)
by the side of the resting point (x across the palm, y along the hand):
  x < 0 (towards the thumb): 266 starts, 19 failed (7.1%)
  x > 0 (towards the little finger): 734 starts, 14 failed (1.9%)
  y < 0 (towards the fingertips): 205 starts, 15 failed (7.3%)
  y > 0 (towards the wrist): 795 starts, 18 failed (2.3%)
runs/s58/sidey+-1M.safetensors: 795 starts, 18 marked failed
