#!/bin/bash
# card.sh NAME SNAPSHOT (session 56, from the repository root, its build at .dev/d56/dexcube): the 08:21 rule's card, SNAPSHOT as member 0 and the specialist as member 1.
set -e
B=.dev/d56/dexcube; C=runs/s56/cards
$B ensemble --out $C/$1-ens $2 results/training/layer-pg-s1-a10-w512-td3-seed55/snapshots/epoch-0031 > /dev/null
$B handover $C/$1-ens --first 0 --member 0 --let-go 10 --out $C/$1-lg > /dev/null
$B start-gesture $C/$1-lg --actuators 3,6,9,13 --action -1 --steps 5 --member 1 --out $C/$1 > /dev/null
