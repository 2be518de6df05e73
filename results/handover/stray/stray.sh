#!/bin/bash
cd /work/main
D=.dev/d60s/dexcube
for M in 0 1 2; do
  DEXCUBE_STRAY=$M,0.05 $D eval-stage rot --episodes 1000 --seed 2000000 --threads 2 --rot-policy models/rot-lead-handover --episodes-csv runs/s60/stray$M-2M.csv > runs/s60/stray$M-2M.txt 2>&1
  python3 results/goal-lead/pair_episodes.py results/handover/rot-lead-handover-fresh2M.csv runs/s60/stray$M-2M.csv > runs/s60/stray$M-2M-paired.txt 2>&1
done
