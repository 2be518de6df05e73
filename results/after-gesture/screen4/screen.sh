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
  $B ensemble --out $C/$NAME-ens models/layer-w512-19 $SNAP > /dev/null
  $B handover $C/$NAME-ens --first 0 --member 0 --let-go 10 --out $C/$NAME-lg > /dev/null
  $B start-gesture $C/$NAME-lg --actuators 3,6,9,13 --action -1 --steps 5 --member 1 --out $C/$NAME > /dev/null
fi
P=$C/$NAME; [ "$SNAP" = "-" ] && P=models/layer-specialist
N=$(python3 -c "import json,struct;f=open('$STARTS','rb');n=struct.unpack('<Q',f.read(8))[0];h=json.loads(f.read(n));print(max(v['shape'][0] for k,v in h.items() if k!='__metadata__'))")
$B eval-stage layer --object cube --episodes $N --threads $T --layer-policy $P --starts $STARTS --episodes-csv runs/s56/screen$TAG/$NAME.csv > runs/s56/screen$TAG/$NAME.txt 2>&1
head -1 runs/s56/screen$TAG/$NAME.txt
