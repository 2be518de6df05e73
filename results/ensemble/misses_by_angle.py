"""How far past the paper's angle threshold a stage's misses end, from `dexcube eval-stage --episodes-csv`.

Usage: python3 results/ensemble/misses_by_angle.py EPISODES.csv

Standard library only. Prints the endings, then the misses that kept the cube (not dropped) by their final angle
error, with how many of them left the cube square (every cubelet within 0.1 rad of its place) and how many had met
the test at some step, and how many successes left the cube out of square.
"""
import csv, sys
from collections import Counter

BINS = [0.1, 0.15, 0.2, 0.3, 0.5, 1.0, 2.0, 4.0]


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    rows = list(csv.DictReader(open(sys.argv[1])))
    print(f"{len(rows)} episodes:", dict(Counter(r['ending'] for r in rows)))
    misses = [r for r in rows if r['ending'] not in ('success', 'dropped')]
    print(f"{len(misses)} misses that kept the cube, by final angle error (rad):")
    for low, high in zip(BINS, BINS[1:]):
        there = [r for r in misses if low <= float(r['angle_error']) < high]
        square = sum(r['square'] == 'true' for r in there)
        met = sum(int(r['longest_hold']) > 0 for r in there)
        print(f"  {low} to {high}: {len(there)} ({square} square, {met} met the test at some step)")
    print(f"  of all {len(misses)}: {sum(r['square'] == 'false' for r in misses)} left the cube out of square")
    wins_out = sum(r['ending'] == 'success' and r['square'] == 'false' for r in rows)
    print(f"successes that left the cube out of square: {wins_out}")


if __name__ == '__main__':
    main()
