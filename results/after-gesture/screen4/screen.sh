#!/bin/bash
# screen.sh NAME SNAPSHOT STARTS TAG THREADS: the card made as models/layer-specialist is, with SNAPSHOT
# as its gesture's member (or models/layer-specialist itself for SNAPSHOT "-"), replayed on STARTS.
# As session 56 ran it, from the repository root, with its build at .dev/d56/dexcube and its files
# under runs/s56; the STARTS are the gesture-side placements of seeds 30000000 and 31000000.
set -e
B=.dev/d56/dexcube
NAME=$1; SNAP=$2; STARTS=$3; TAG=$4; T=$5
C=runs/s56/cards; mkdir -p $C runs/s56/screen$TAG
if [ "$SNAP" != "-" ] && [ ! -f $C/$NAME.json ]; then
  B=$B results/after-gesture/specialist-card.sh $C/$NAME models/layer-w512-19 $SNAP
fi
P=$C/$NAME; [ "$SNAP" = "-" ] && P=models/layer-specialist
# --starts runs the first min(--episodes, starts) of them: every start.
$B eval-stage layer --object cube --episodes 100000 --threads $T --layer-policy $P --starts $STARTS --episodes-csv runs/s56/screen$TAG/$NAME.csv > runs/s56/screen$TAG/$NAME.txt 2>&1
head -1 runs/s56/screen$TAG/$NAME.txt
