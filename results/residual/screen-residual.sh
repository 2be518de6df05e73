#!/bin/bash
# Session 61: each residual snapshot shipped with its base, on seed 2000000's 1,000 placements.
cd /work/main
D=.dev/d61/dexcube-r
RUN=runs/s61/rot-residual-s01-td3-seed61
for E in "$@"; do
  while [ ! -f $RUN/snapshots/epoch-$E.json ]; do sleep 20; done
  sleep 5
  $D residual models/rot-lead-handover $RUN/snapshots/epoch-$E --out runs/s61/res-$E > /dev/null
  $D eval-stage rot --episodes 1000 --seed 2000000 --threads 1 --rot-policy runs/s61/res-$E --episodes-csv runs/s61/res-$E-2M.csv > runs/s61/res-$E-2M.txt 2>&1
  python3 results/goal-lead/pair_episodes.py results/handover/rot-lead-handover-fresh2M.csv runs/s61/res-$E-2M.csv > runs/s61/res-$E-2M-paired.txt 2>&1
done
