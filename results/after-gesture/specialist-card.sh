#!/bin/bash
# specialist-card.sh OUT MEMBER0 MEMBER1 [MEMBER2]: a card made as models/layer-specialist is
# (session 56). MEMBER0 acts wherever the start gesture is not made, letting go for 10 steps
# after a 25-step stall; MEMBER1 acts alone where it is made. With MEMBER2, it acts alone where
# the cube starts towards the thumb and no gesture is made (`dexcube start-route`, session 58).
# Run from the repository root; B names the dexcube build (default: session 56's,
# .dev/d56/dexcube). The intermediate cards are written beside OUT (OUT-ens, OUT-lg, and
# OUT-gs with MEMBER2).
set -e
B=${B:-.dev/d56/dexcube}
$B ensemble --out $1-ens $2 $3 $4 > /dev/null
$B handover $1-ens --first 0 --member 0 --let-go 10 --out $1-lg > /dev/null
# Without MEMBER2 the gesture's card is the last; with it, the route is made on top of it.
GESTURE=$1${4:+-gs}
$B start-gesture $1-lg --actuators 3,6,9,13 --action -1 --steps 5 --member 1 --out $GESTURE > /dev/null
if [ -n "$4" ]; then
  $B start-route $GESTURE --member 2 --out $1 > /dev/null
fi
