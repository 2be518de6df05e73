"""Pairs two operator evaluations (`dexcube eval ... --out PREFIX`, PREFIX.csv) cube by cube.

Usage: python3 results/pair_operator.py FIRST.csv SECOND.csv

Standard library only. A cube is its move distance, its index within that distance and the half it ran in
(rollback or open loop); `dexcube eval --seed S` draws the same scrambles for the same distance and index, so
a run of 20 cubes per distance pairs with the first 20 of a run of 100 at the same seed. Only cubes in both
files are compared. For each half and for both together it prints the cubes solved by each, the cubes solved
by only one and the two-sided sign test on those, the mean action number over all the paired cubes (as
Table I counts it) and, over the cubes both solved, how many took fewer actions in each with the sign test
on those, each stage's runs, the Stage 2 runs that left the cube out of its good state, and the
cubes lost to a drop in each stage.
"""
import csv, os, sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), 'starts'))
from pair_failures import discordant, sign_test


def read(path):
    try:
        with open(path, newline='') as f:
            return {(r['distance'], r['index'], r['rollback']): r for r in csv.DictReader(f)}
    except (OSError, KeyError) as e:
        sys.exit(f"cannot read {path} as a `dexcube eval` CSV ({e}): pass the PREFIX.csv an evaluation wrote")


def summary(rows):
    lost = lambda stage: sum(r['failure'].startswith(f'Dropped in Stage {stage}') for r in rows)
    total = lambda column: sum(int(r[column]) for r in rows)
    return (f"actions {total('actions') / len(rows):.2f}, Stage 1 runs {total('stage1_runs')}, "
            f"Stage 2 runs {total('stage2_runs')} ({total('stage2_misaligned')} left out of the good state), "
            f"lost to a drop in Stage 1 {lost(1)}, in Stage 2 {lost(2)}")


def compare(label, keys, first, second):
    a = [first[k]['solved'] == 'true' for k in keys]
    b = [second[k]['solved'] == 'true' for k in keys]
    only_a, only_b = discordant(a, b)
    print(f"{label}: cubes {len(keys)}; solved: first {sum(a)}, second {sum(b)}; "
          f"only first {only_a}, only second {only_b}; sign test p = {sign_test(only_a, only_b):.3g}")
    both = [k for k, x, y in zip(keys, a, b) if x and y]
    fewer_a = sum(int(first[k]['actions']) < int(second[k]['actions']) for k in both)
    fewer_b = sum(int(second[k]['actions']) < int(first[k]['actions']) for k in both)
    print(f"  of the {len(both)} both solved, fewer actions: first {fewer_a}, second {fewer_b}; "
          f"sign test p = {sign_test(fewer_a, fewer_b):.3g}")
    print(f"  first:  {summary([first[k] for k in keys])}")
    print(f"  second: {summary([second[k] for k in keys])}")


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    first, second = read(sys.argv[1]), read(sys.argv[2])
    keys = sorted(first.keys() & second.keys(), key=lambda k: (k[2], int(k[0]), int(k[1])))
    if not keys:
        sys.exit("the two evaluations share no cube (distance, index and half): run both with the same --seed")
    for half, label in (('true', 'rollback'), ('false', 'open loop')):
        in_half = [k for k in keys if k[2] == half]
        if in_half:
            compare(label, in_half, first, second)
    compare('both halves', keys, first, second)


if __name__ == '__main__':
    main()
