#!/bin/bash
# Starts arm D once the held-out recording (seed 15000000) is done, so that it has its core.
cd /work/main
while ! grep -q "recorded where" runs/s49/rot-closest-fresh15000000.log 2>/dev/null; do sleep 10; done
exec .dev/d49/dexcube-c train rot --mode pair --object cube --square --see-misalignment --angle-threshold 0.05 --init results/training/rot-pair-cube-square-seen-mixedw-td3-seed6 --init-actor results/training/rot-pair-cube-square-seen-mixedw-td3-seed6/snapshots/epoch-0047 --critic-only-epochs 2 --anchor 10 --noise-eps 0.1 --random-eps 0.05 --starts results/starts/rot-closest-ens-fresh14000000.safetensors --start-share 0.5 --td3 --threads 1 --seed 40 --epochs 100 --snapshot-every 4 --out runs/s49/rot-seen47-closest-a005-td3-seed40 > runs/s49/armD.log 2>&1
