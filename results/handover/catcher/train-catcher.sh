#!/bin/bash
cd /work/main
.dev/d60/dexcube train rot --mode pair --object cube --square --angle-threshold 0.05 --init results/training/rot-pair-cube-square-freshw-td3-seed1 --init-actor models/rot-td3-19 --critic-only-epochs 2 --anchor 10 --noise-eps 0.1 --random-eps 0.05 --starts runs/s60/strays-46M.safetensors --start-share 0.5 --failed-weight 8 --td3 --threads 1 --seed 60 --epochs 100 --snapshot-every 4 --out runs/s60/rot-td3-19-strays-a005-td3-seed60 > runs/s60/train-catcher.log 2>&1
