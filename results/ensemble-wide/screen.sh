#!/bin/bash
# Session 61: Stage 1 ensembles with more members, led and handing over as models/rot-lead-handover.
cd /work/main
D=.dev/d61/dexcube
R=results/training
M0=$R/rot-pair-cube-square-seen-mixedw-td3-seed6/snapshots/epoch-0047
M1=models/rot-dropw20
M2=models/rot-td3-19
X1=$R/rot-pair-cube-square-freshw-seed1/snapshots/epoch-0027
X2=models/rot-anchor57
X3=$R/rot-pair-cube-square-seen-mixedw-td3-seed6/snapshots/epoch-0027
X4=models/rot-td3-19
build() { # name members...
  local name=$1; shift
  $D ensemble --out runs/s61/$name-ens "$@" > /dev/null &&
  $D goal-lead runs/s61/$name-ens --share 0.5 --within 0.2 --out runs/s61/$name-lead > /dev/null &&
  $D handover runs/s61/$name-lead --member 2 --out runs/s61/$name > /dev/null
}
build C0 $M0 $M1 $M2
$D eval-stage rot --episodes 40 --seed 2000000 --threads 2 --rot-policy runs/s61/C0 --episodes-csv runs/s61/C0-check.csv > runs/s61/C0-check.txt 2>&1
python3 - <<'PY' > runs/s61/C0-check-compare.txt
import csv
a=list(csv.DictReader(open('runs/s61/C0-check.csv'))); b=list(csv.DictReader(open('results/handover/rot-lead-handover-fresh2M.csv')))[:40]
same=sum(x==y for x,y in zip(a,b)); print(f"{same} of {len(a)} rows equal to models/rot-lead-handover's")
PY
build C1 $M0 $M1 $M2 $X1
build C2 $M0 $M1 $M2 $X2
build C3 $M0 $M1 $M2 $X3
build C4 $M0 $M1 $M2 $X4
build C5 $M0 $M1 $M2 $X1 $X2
for C in C1 C2 C3 C4 C5; do
  $D eval-stage rot --episodes 1000 --seed 2000000 --threads 2 --rot-policy runs/s61/$C --episodes-csv runs/s61/$C-2M.csv > runs/s61/$C-2M.txt 2>&1
  python3 results/goal-lead/pair_episodes.py results/handover/rot-lead-handover-fresh2M.csv runs/s61/$C-2M.csv > runs/s61/$C-2M-paired.txt 2>&1
done
echo done > runs/s61/screen.done
