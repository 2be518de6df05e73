4000 starts from runs/s57/spec-33000000.safetensors
by the cube's yaw from square to the hand:
   0 to  5 degrees: 407 starts, 16 failed (3.9%)
   5 to 15 degrees: 1068 starts, 37 failed (3.5%)
  15 to 25 degrees: 814 starts, 28 failed (3.4%)
  25 to 35 degrees: 864 starts, 22 failed (2.5%)
  35 to 45 degrees: 847 starts, 25 failed (3.0%)
by the distance from the resting point across the palm:
   0 to   3 mm: 547 starts, 12 failed (2.2%)
   3 to   6 mm: 1001 starts, 26 failed (2.6%)
   6 to  10 mm: 914 starts, 30 failed (3.3%)
  10 to 100 mm: 1538 starts, 60 failed (3.9%)
by the side of the resting point (x across the palm, y along the hand):
  x < 0 (towards the thumb): 958 starts, 48 failed (5.0%)
  x > 0 (towards the little finger): 3042 starts, 80 failed (2.6%)
  y < 0 (towards the fingertips): 727 starts, 34 failed (4.7%)
  y > 0 (towards the wrist): 3273 starts, 94 failed (2.9%)
runs/s57/yp33M.safetensors: 3273 starts, 94 marked failed
