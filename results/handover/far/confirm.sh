#!/bin/bash
cd /work/main
D=.dev/d60/dexcube
$D eval-stage rot --episodes 4000 --seed 45000000 --threads 2 --rot-policy runs/s60/far0.8 --episodes-csv runs/s60/far0.8-45M.csv > runs/s60/far0.8-45M.txt 2>&1
$D eval-stage rot --episodes 4000 --seed 45000000 --threads 2 --rot-policy models/rot-lead-handover --episodes-csv runs/s60/lh-45M.csv > runs/s60/lh-45M.txt 2>&1
python3 results/goal-lead/pair_episodes.py runs/s60/lh-45M.csv runs/s60/far0.8-45M.csv > runs/s60/far0.8-45M-paired.txt 2>&1
