"""Compares how fast training runs learn, from each run's metrics.csv (as `dexcube train` writes it).

Usage: python3 results/training/learning_speed.py RUN_DIR [RUN_DIR ...]

Standard library only. Over the epochs every run reached, it prints for each run its mean train success over
the last 10 of them (200 episodes an epoch, so 2,000 episodes: steadier than the 10 to 16 test episodes an
epoch) and the first epoch whose mean train success over the 5 epochs ending there reaches 0.5 ("never" if
none does). These are session 23's measures for TD3 against DDPG on U' on the block (results/TRAINING.md).
"""
import csv, os, sys

WINDOW, LAST, LEVEL = 5, 10, 0.5


def train_success(run):
    path = os.path.join(run, 'metrics.csv')
    try:
        with open(path, newline='') as f:
            return [float(row['train_success']) for row in csv.DictReader(f)]
    except (OSError, KeyError, ValueError) as e:
        sys.exit(f'learning_speed: cannot read train_success from {path} ({e}); pass run folders of `dexcube train`')


def first_reaching(values):
    for end in range(WINDOW, len(values) + 1):
        if sum(values[end - WINDOW:end]) / WINDOW >= LEVEL:
            return end - 1
    return None


def main(runs):
    if not runs:
        sys.exit(__doc__.strip().splitlines()[2])
    curves = {run: train_success(run) for run in runs}
    common = min(len(c) for c in curves.values())
    if common < LAST:
        sys.exit(f'learning_speed: the runs share only {common} epochs; at least {LAST} are needed')
    print(f'over the {common} epochs all runs reached')
    print(f'| run | train success, epochs {common - LAST} to {common - 1} | first epoch whose {WINDOW}-epoch mean reaches {LEVEL} |')
    print('|---|---|---|')
    for run, curve in curves.items():
        shared = curve[:common]
        reached = first_reaching(shared)
        print(f'| {os.path.basename(os.path.normpath(run))} | {sum(shared[-LAST:]) / LAST:.3f} | '
              f'{"never" if reached is None else reached} |')


if __name__ == '__main__':
    main(sys.argv[1:])
