#!/bin/bash
# Screens the 04:09 rule's snapshots in order, each as it appears: A = the seen member's run, B = rot-td3-19's.
cd /work/main
B=./.dev/d48/dexcube-c
A_RUN=runs/s48/rot-seen47-a005-td3-seed40
B_RUN=runs/s48/rot-td3-19-a005-td3-seed48
SEEN=results/training/rot-pair-cube-square-seen-mixedw-td3-seed6/snapshots/epoch-0047
for job in A:0007 B:0007 A:0015 B:0015 A:0023 B:0023 A:0031 A:0039; do
  arm=${job%%:*}; ep=${job##*:}
  if [ $arm = A ]; then run=$A_RUN; else run=$B_RUN; fi
  snap=$run/snapshots/epoch-$ep
  while [ ! -f $snap.json ]; do
    [ -f runs/s48/STOP ] && exit 0
    sleep 20
  done
  sleep 5
  name=rot-3-$arm-$ep
  if [ $arm = A ]; then $B ensemble --out runs/s48/$name $snap models/rot-dropw20 models/rot-td3-19
  else $B ensemble --out runs/s48/$name $SEEN models/rot-dropw20 $snap; fi
  $B eval-stage rot --episodes 1000 --seed 2000000 --threads 1 --rot-policy runs/s48/$name --episodes-csv runs/s48/$name-fresh2000000.csv > runs/s48/$name-fresh2000000.txt 2>&1
  echo "$(date +%H:%M) $name: $(python3 results/goal-lead/pair_episodes.py results/episode-length/rot-mf-fresh2000000.csv runs/s48/$name-fresh2000000.csv)" >> runs/s48/screens.log
done
