#!/bin/bash
# As run on the lent machine (session 44) from the repository root, with .dev/d44 holding the stripped
# binary, the start files and the snapshots as snaps/w<W>-<epoch> (runs/layer-yonly-a10-w<W>-td3-seed40/
# snapshots/epoch-<epoch>; check-w<W>-0001 is epoch-0001) and the ensembles as snaps/ens-*; kept as the record.
# Session 44's second call: four Stage 2 policies at the fresh seed 11000000, and the wide arm's
# best on the ensemble's recorded hand-overs. Everything lands in $OUT/s44b.tar.
set -u
D=.dev/d44
W=$OUT/s44b
mkdir -p $W
start=$(date +%s)
run() { name=$1; shift; ( $D/dexcube eval-stage layer "$@" > $W/$name.txt 2> $W/$name.err ) & }
for P in models/layer models/layer-w512-19 $D/snaps/w512-0019 $D/snaps/w256-0023; do
  name=$(basename $P)
  run $name-fresh11000000 --object cube --episodes 1000 --seed 11000000 --threads 3 --layer-policy $P --record-starts $W/$name-fresh11000000.safetensors
done
run w512-0019-handovers --starts $D/layer-starts-ens-train-seed1.safetensors --episodes 1000 --threads 4 --layer-policy $D/snaps/w512-0019
wait
echo "took $(( $(date +%s) - start )) s" > $W/times.txt
tar -cf $OUT/s44b.tar -C $OUT s44b
