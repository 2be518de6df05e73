#!/bin/bash
# Screens the 06:46 rule's snapshots in order, each as it appears: C = rot-td3-19's run, D = the seen member's.
cd /work/main
B=./.dev/d49/dexcube-c
C_RUN=runs/s49/rot-td3-19-closest-a005-td3-seed48
D_RUN=runs/s49/rot-seen47-closest-a005-td3-seed40
SEEN=results/training/rot-pair-cube-square-seen-mixedw-td3-seed6/snapshots/epoch-0047
for job in C:0007 D:0007 C:0015 D:0015 C:0023 D:0023 C:0031; do
  arm=${job%%:*}; ep=${job##*:}
  if [ $arm = C ]; then run=$C_RUN; else run=$D_RUN; fi
  snap=$run/snapshots/epoch-$ep
  while [ ! -f $snap.json ]; do
    [ -f runs/s49/STOP ] && exit 0
    sleep 20
  done
  sleep 5
  name=rot-3-$arm-$ep
  if [ $arm = D ]; then $B ensemble --out runs/s49/$name $snap models/rot-dropw20 models/rot-td3-19
  else $B ensemble --out runs/s49/$name $SEEN models/rot-dropw20 $snap; fi
  $B eval-stage rot --episodes 1000 --seed 2000000 --threads 1 --rot-policy runs/s49/$name --episodes-csv runs/s49/$name-fresh2000000.csv > runs/s49/$name-fresh2000000.txt 2>&1
  echo "$(date +%H:%M) $name: $(python3 results/goal-lead/pair_episodes.py results/episode-length/rot-mf-fresh2000000.csv runs/s49/$name-fresh2000000.csv)" >> runs/s49/screens.log
  $B eval-stage rot --starts runs/s49/rot-closest-fresh15000000.safetensors --episodes 1000 --threads 1 --rot-policy runs/s49/$name --episodes-csv runs/s49/$name-closest15000000.csv > runs/s49/$name-closest15000000.txt 2>&1
  echo "$(date +%H:%M) $name held-out closest: $(head -1 runs/s49/$name-closest15000000.txt)" >> runs/s49/screens.log
done
