#!/bin/bash
cd /work/main
D=.dev/d60/dexcube
for B in 0.8 0.5; do
  $D eval-stage rot --episodes 1000 --seed 2000000 --threads 2 --rot-policy runs/s60/far$B --episodes-csv runs/s60/far$B-2M.csv > runs/s60/far$B-2M.txt 2>&1
  python3 results/goal-lead/pair_episodes.py results/handover/rot-lead-handover-fresh2M.csv runs/s60/far$B-2M.csv > runs/s60/far$B-2M-paired.txt 2>&1
done
