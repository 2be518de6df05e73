"""Pairs two `dexcube eval-stage ... --episodes-csv` files of the same episodes, episode by episode.

Usage: python3 results/goal-lead/pair_episodes.py FIRST.csv SECOND.csv

Standard library only. Episodes are matched by their seed; only those in both files count. It prints each
file's successes, drops and near misses (kept the cube, missed, final angle error under 0.2 rad), how many
episodes the second succeeded in where the first failed (fixed) and the other way round (failed anew), and the
two-sided sign test on those.
"""
import csv, sys
from math import comb

def load(path):
    with open(path) as f:
        return {row['seed']: row for row in csv.DictReader(f)}

def sign_test(fixed, new):
    n = fixed + new
    if n == 0:
        return 1.0
    return min(1.0, 2 * sum(comb(n, i) for i in range(min(fixed, new) + 1)) / 2 ** n)

def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    a, b = load(sys.argv[1]), load(sys.argv[2])
    common = [seed for seed in a if seed in b]
    if not common:
        sys.exit("the two files share no episode (no seed in both): run both with the same --seed")
    won = lambda rows, s: rows[s]['ending'] == 'success'
    fixed = sum(1 for s in common if not won(a, s) and won(b, s))
    new = sum(1 for s in common if won(a, s) and not won(b, s))
    def counts(rows):
        successes = sum(won(rows, s) for s in common)
        drops = sum(rows[s]['ending'] == 'dropped' for s in common)
        near = sum(1 for s in common if rows[s]['ending'] not in ('success', 'dropped')
                   and float(rows[s]['angle_error']) < 0.2)
        return f"{successes} successes, {drops} drops, {near} near misses"
    print(f"{len(common)} episodes; first: {counts(a)}; second: {counts(b)}; "
          f"fixed {fixed}, failed anew {new}; sign test p = {sign_test(fixed, new):.3g}")

if __name__ == '__main__':
    main()
