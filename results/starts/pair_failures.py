"""Pairs two recordings of the same episodes (`dexcube eval-stage ... --record-starts`) by their failure marks.

Usage: python3 results/starts/pair_failures.py FIRST.safetensors SECOND.safetensors

Standard library only; the files are read by `drops_by_start.load`. Both must hold the same episodes (the same
start states, so the same stage, seed and count) and mark failures with the same meaning; otherwise it says so
and exits with 2. It prints how many episodes each policy failed, how many the second fixed and how many it
failed anew, and the two-sided sign test on those discordant episodes. Files from sessions 13 to 19 name the
marks `dropped`, later ones `failed`.
"""
import math, sys
from drops_by_start import load, origin

def marks(recording):
    return [x != 0 for x in recording.get('failed') or recording['dropped']]

def discordant(first, second):
    """How many of the paired marks are set in the first only, and how many in the second only."""
    return (sum(x and not y for x, y in zip(first, second)),
            sum(y and not x for x, y in zip(first, second)))

def sign_test(fixed, new):
    n = fixed + new
    if n == 0:
        return 1.0
    return min(1.0, 2 * sum(math.comb(n, i) for i in range(min(fixed, new) + 1)) / 2 ** n)

def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    first, second = load(sys.argv[1]), load(sys.argv[2])
    if first['state'] != second['state']:
        print("the two recordings do not hold the same episodes (their start states differ): record both with the same stage, --seed and --episodes", file=sys.stderr)
        sys.exit(2)
    meaning = origin(first)['failure'], origin(second)['failure']
    if meaning[0] != meaning[1]:
        print(f"the two recordings mark failures differently ({meaning[0]} against {meaning[1]}): record both with the same stage", file=sys.stderr)
        sys.exit(2)
    a, b = marks(first), marks(second)
    fixed, new = discordant(a, b)
    print(f"episodes {len(a)}; failed: first {sum(a)}, second {sum(b)}; fixed {fixed}, new {new}; "
          f"sign test p = {sign_test(fixed, new):.3g}; meaning {meaning[0]}/{meaning[1]}")

if __name__ == '__main__':
    main()
