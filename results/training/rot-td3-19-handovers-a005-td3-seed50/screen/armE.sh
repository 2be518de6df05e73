#!/bin/bash
cd /work/main
B=.dev/d50/dexcube4
while ! grep -q "recorded where" runs/s50/handovers-fresh20M.txt 2>/dev/null; do sleep 10; done
setsid $B train rot --mode pair --object cube --square --angle-threshold 0.05 --init results/training/rot-pair-cube-square-freshw-td3-seed1 --init-actor models/rot-td3-19 --critic-only-epochs 2 --anchor 10 --noise-eps 0.1 --random-eps 0.05 --starts runs/s50/handovers-fresh20M.safetensors --start-share 0.5 --failed-weight 8 --td3 --threads 1 --seed 50 --epochs 100 --snapshot-every 4 --out runs/s50/rot-td3-19-handovers-a005-td3-seed50 > runs/s50/armE.log 2>&1 &
R=runs/s50/rot-td3-19-handovers-a005-td3-seed50
for e in 0003 0007 0011 0015; do
  while [ ! -f $R/snapshots/epoch-$e.json ]; do sleep 10; done
  sleep 5
  $B ensemble results/training/rot-pair-cube-square-seen-mixedw-td3-seed6/snapshots/epoch-0047 models/rot-dropw20 $R/snapshots/epoch-$e --out runs/s50/E-$e > /dev/null
  $B goal-lead runs/s50/E-$e --share 0.5 --within 0.2 --out runs/s50/E-$e-lead > /dev/null
  $B handover runs/s50/E-$e-lead --member 2 --out runs/s50/E-$e-hand > /dev/null
  $B eval-stage rot --episodes 1000 --seed 2000000 --threads 1 --rot-policy runs/s50/E-$e-hand --episodes-csv runs/s50/E-$e-fresh2M.csv > runs/s50/E-$e-fresh2M.txt 2>&1
  echo "epoch $e $(date +%H:%M): $(python3 results/goal-lead/pair_episodes.py results/handover/rot-lead-handover-fresh2M.csv runs/s50/E-$e-fresh2M.csv | tail -1)"
done
