"""Pairs two `dexcube eval-stage ... --episodes-csv` files of the same episodes, episode by episode.

Usage: python3 results/goal-lead/pair_episodes.py FIRST.csv SECOND.csv
       python3 results/goal-lead/pair_episodes.py --handed-over FIRST.csv SECOND.csv

Standard library only. Episodes are matched by their seed; only those in both files count. It prints each
file's successes, drops and near misses (kept the cube, missed, final angle error under 0.2 rad), how many
episodes the second succeeded in where the first failed (fixed) and the other way round (failed anew), and the
two-sided sign test on those.

With --handed-over, FIRST is a run of a policy that hands over (`dexcube handover`) and SECOND a replay of the
starts it handed over, in order (`results/starts/pick_starts.py ... handed-over`, then `eval-stage --starts`,
whose rows number the starts 0, 1, 2, ...): FIRST's handed-over episodes are paired with SECOND's rows, and
FIRST's other episodes, the same for both, are added to both totals (session 52).
"""
import csv, os, sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'starts'))
from pair_failures import sign_test

def load(path):
    with open(path) as f:
        return {row['seed']: row for row in csv.DictReader(f)}

def handed_over(rows):
    """The handed-over episodes of a run, keyed by their order as a replay of their starts numbers them, and how
    many of the others succeeded."""
    if rows and 'handed_over' not in next(iter(rows.values())):
        sys.exit("the first file has no handed_over column: make it with a policy that hands over (dexcube handover)")
    handed = [row for row in rows.values() if row['handed_over'] == 'true']
    others = sum(row['ending'] == 'success' for row in rows.values() if row['handed_over'] != 'true')
    return {str(k): row for k, row in enumerate(handed)}, others

def main():
    args = sys.argv[1:]
    replay = args[:1] == ['--handed-over']
    if replay:
        args = args[1:]
    if len(args) != 2:
        sys.exit(__doc__)
    a, b = load(args[0]), load(args[1])
    if replay:
        a, others = handed_over(a)
        if len(a) != len(b):
            sys.exit(f"the first file handed over {len(a)} episodes but the second holds {len(b)}: "
                     f"replay all of the starts it handed over")
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
    if replay:
        total = lambda rows: others + sum(won(rows, s) for s in common)
        print(f"with the {others} successes of the episodes not handed over, the same for both: "
              f"first {total(a)}, second {total(b)}")

if __name__ == '__main__':
    main()
