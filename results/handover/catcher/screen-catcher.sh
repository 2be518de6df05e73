#!/bin/bash
# Screens each snapshot of the catcher arm as it appears (session 60's 20:33 rule).
cd /work/main
P=.dev/d60p/dexcube
RUN=runs/s60/rot-td3-19-strays-a005-td3-seed60
M="results/training/rot-pair-cube-square-seen-mixedw-td3-seed6/snapshots/epoch-0047 models/rot-dropw20 models/rot-td3-19"
for E in 0003 0007 0011 0015 0019 0023 0027 0031; do
  S=$RUN/snapshots/epoch-$E
  while [ ! -f $S.json ]; do sleep 20; done
  sleep 5
  N=runs/s60/catch-$E
  $P ensemble $M $S --out $N-ens > /dev/null && $P goal-lead $N-ens --share 0.5 --within 0.2 --out $N-led > /dev/null && $P handover $N-led --member 2 --out $N > /dev/null
  DEXCUBE_MEAN_OF=3 DEXCUBE_STRAY=3,0.05 $P eval-stage rot --episodes 1000 --seed 2000000 --threads 1 --rot-policy $N --episodes-csv $N-2M.csv > $N-2M.txt 2>&1
  python3 results/goal-lead/pair_episodes.py results/handover/rot-lead-handover-fresh2M.csv $N-2M.csv > $N-2M-paired.txt 2>&1
done
