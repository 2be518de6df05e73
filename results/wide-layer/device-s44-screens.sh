#!/bin/bash
# As run on the lent machine (session 44) from the repository root, with .dev/d44 holding the stripped
# binary, the start files and the snapshots as snaps/w<W>-<epoch> (runs/layer-yonly-a10-w<W>-td3-seed40/
# snapshots/epoch-<epoch>; check-w<W>-0001 is epoch-0001) and the ensembles as snaps/ens-*; kept as the record.
# Session 44's device call: Stage 2 screens of both arms, then each arm's best on the other
# side and at the reported seed. Everything lands in $OUT/s44.tar (8 files at most come back).
set -u
D=.dev/d44
BIN=$D/dexcube
W=$OUT/s44
mkdir -p $W
pack() { tar -cf $OUT/s44.tar -C $OUT s44; }
nproc > $W/nproc.txt
start=$(date +%s)
# Phase 1: every screen at once, one thread each.
N1=${N1:-199}; N2=${N2:-801}; N3=${N3:-1000}
for snap in $D/snaps/*.safetensors; do
  name=$(basename $snap .safetensors)
  ( $BIN eval-stage layer --starts $D/layer-yonly-default-fresh8000000.safetensors --episodes $N1 --threads 1 --layer-policy $D/snaps/$name > $W/screen-$name.txt 2> $W/screen-$name.err ) &
done
wait
echo "phase 1: $(( $(date +%s) - start )) s" >> $W/times.txt
pack
# Each arm's best: fewest failures of the 199 (left square = successes - skewed), the later on a tie.
for arm in w512 w256; do
  best=""; bestfail=999
  for f in $(ls $W/screen-$arm-*.txt | sort); do
    succ=$(grep -oP ": \K\d+(?=/$N1 = )" $f)
    skew=$(grep -oP 'successes that left the cube out of its good state[^:]*: \K\d+' $f || echo 0)
    [ -z "$succ" ] && continue
    fail=$(( N1 - (succ - ${skew:-0}) ))
    if [ $fail -le $bestfail ]; then bestfail=$fail; best=$(basename $f .txt); best=${best#screen-}; fi
  done
  echo "$arm best $best fails $bestfail" >> $W/best.txt
  [ -z "$best" ] && continue
  ( $BIN eval-stage layer --starts $D/layer-yplus-default-fresh8000000.safetensors --episodes $N2 --threads 4 --layer-policy $D/snaps/$best > $W/yplus-$best.txt 2> $W/yplus-$best.err ) &
  ( $BIN eval-stage layer --object cube --episodes $N3 --seed 1000000 --threads 4 --layer-policy $D/snaps/$best --record-starts $W/$best-fresh1000000.safetensors > $W/$best-fresh1000000.txt 2> $W/$best-fresh1000000.err ) &
done
wait
echo "phase 2: $(( $(date +%s) - start )) s" >> $W/times.txt
pack
