#!/bin/bash
# As run on the lent machine (session 44) from the repository root, with .dev/d44 holding the stripped
# binary, the start files and the snapshots as snaps/w<W>-<epoch> (runs/layer-yonly-a10-w<W>-td3-seed40/
# snapshots/epoch-<epoch>; check-w<W>-0001 is epoch-0001) and the ensembles as snaps/ens-*; kept as the record.
# Session 44's third call: two Stage 2 ensembles at the reported seed and at seed 11000000.
set -u
D=.dev/d44
W=$OUT/s44c
mkdir -p $W
start=$(date +%s)
for P in ens-w512-2 ens-w512-2-layer; do
  for S in 1000000 11000000; do
    ( $D/dexcube eval-stage layer --object cube --episodes 1000 --seed $S --threads 4 --layer-policy $D/snaps/$P --record-starts $W/$P-fresh$S.safetensors > $W/$P-fresh$S.txt 2> $W/$P-fresh$S.err ) &
  done
done
wait
echo "took $(( $(date +%s) - start )) s" > $W/times.txt
tar -cf $OUT/s44c.tar -C $OUT s44c
