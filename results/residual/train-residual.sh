#!/bin/bash
# Session 61: a residual on top of models/rot-lead-handover (residual policy learning).
cd /work/main
.dev/d61/dexcube train rot --mode pair --object cube --square --see-misalignment --residual-of models/rot-lead-handover --residual-scale 0.1 --td3 --noise-eps 0.3 --random-eps 0.05 --critic-only-epochs 2 --threads 1 --seed 61 --epochs 100 --snapshot-every 4 --out runs/s61/rot-residual-s01-td3-seed61 > runs/s61/train-residual.log 2>&1
