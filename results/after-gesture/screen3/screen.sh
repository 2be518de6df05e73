#!/bin/bash
# screen.sh NAME SNAPSHOT STARTS TAG THREADS: NAME's card (let-go 10, then the gesture) replayed on STARTS.
# As session 55 ran it, from the repository root, with its build at .dev/d55c/dexcube and its files under runs/s55;
# the STARTS it used are results/starts/layer-gesture-fingertips-fresh2[78]000000.safetensors.
set -e
cd /work/main
B=.dev/d55c/dexcube
NAME=$1; SNAP=$2; STARTS=$3; TAG=$4; T=$5
if [ "$SNAP" != "-" ] && [ ! -f runs/s55/cards/$NAME.json ]; then
  $B handover $SNAP --member 0 --let-go 10 --out runs/s55/cards/$NAME-lg > /dev/null
  $B start-gesture runs/s55/cards/$NAME-lg --actuators 3,6,9,13 --action -1 --steps 5 --out runs/s55/cards/$NAME > /dev/null
fi
P=runs/s55/cards/$NAME; [ "$SNAP" = "-" ] && P=models/layer-gesture
# --starts runs the first min(--episodes, starts) of them: every start.
$B eval-stage layer --object cube --episodes 100000 --threads $T --layer-policy $P --starts $STARTS --episodes-csv runs/s55/screen$TAG/$NAME.csv > runs/s55/screen$TAG/$NAME.txt 2>&1
head -1 runs/s55/screen$TAG/$NAME.txt
