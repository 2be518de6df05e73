"""Tabulates Stage 2 screens on recorded starts (session 42): for each `eval-stage` output
given, the placements left square, the jams (the layer never turned and the cube left out of
its good state), the turns never begun with the cube square, and against the recorded policy
the failures fixed and failed anew, with a two-sided sign test on them.

    python3 results/wide-layer/screens.py SCREEN.txt...
"""

import pathlib
import re
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent / "starts"))
from pair_failures import sign_test  # noqa: E402


def number(pattern, text, default=0):
    found = re.search(pattern, text)
    return int(found.group(1)) if found else default


def screen(path):
    text = open(path).read()
    successes, episodes = map(int, re.search(r": (\d+)/(\d+) = ", text).groups())
    skewed = number(r"successes that left the cube out of its good state[^:]*: (\d+)", text)
    recorded = number(r"did not leave the layer turned with the cube square: (\d+)", text)
    again = number(r"this one failed so from (\d+)", text)
    failures = episodes - (successes - skewed)
    fixed, new = recorded - again, failures - again
    return {
        "left square": successes - skewed,
        "jams": number(r"never turned, and the cube ended out of its good state: (\d+)", text),
        "never turned, square": number(r"never turned \(within [^)]*\): (\d+)", text),
        "of the recorded failures": f"{again} of {recorded}",
        "fixed / anew, p": f"{fixed} / {new}, p = {sign_test(fixed, new):.2g}",
    }


if __name__ == "__main__":
    rows = [(path, screen(path)) for path in sys.argv[1:]]
    if not rows:
        sys.exit(__doc__)
    columns = list(rows[0][1])
    print("| screen | " + " | ".join(columns) + " |")
    print("|---" * (len(columns) + 1) + "|")
    for path, row in rows:
        print(f"| {path.rsplit('/', 1)[-1]} | " + " | ".join(str(row[c]) for c in columns) + " |")
