"""Writes the rows of a recorded run that belong to a subset of its recorded starts, numbered as a replay of the subset numbers them.

Usage: python3 results/starts/rows_of_starts.py RUN.csv RUN.safetensors SUBSET.safetensors OUT.csv

Standard library only. RUN.csv and RUN.safetensors are one `dexcube eval-stage --episodes-csv ... --record-starts ...`
run; SUBSET.safetensors holds some of its starts in their order (for example `stage2_start_geometry --only-side`).
Each subset start is found in the recording by its physics state and goal, and the run's row for it is written with
`episode` and `seed` set to the subset's index, as `eval-stage --starts SUBSET` numbers its rows, so the output pairs
with a replay by `results/goal-lead/pair_episodes.py` without replaying the recorded policy (session 57). It checks
that the recording's failure marks agree with the rows (failed: not a success, or not left square), and exits with 2 naming the first start it cannot find.
"""
import csv, os, sys
from drops_by_start import load


def main(run_csv, run_starts, subset_starts, out_path):
    run = load(run_starts)
    subset = load(subset_starts)
    with open(run_csv) as f:
        rows = list(csv.DictReader(f))
    if len(rows) != len(run['state']):
        sys.exit(f"{run_csv} has {len(rows)} rows but {run_starts} {len(run['state'])} starts: they are not one run")
    index = {(tuple(s), tuple(g)): i for i, (s, g) in enumerate(zip(run['state'], run['goal']))}
    picked = []
    for k, key in enumerate(zip(map(tuple, subset['state']), map(tuple, subset['goal']))):
        i = index.get(key)
        if i is None:
            print(f"start {k} of {subset_starts} is not in {run_starts}", file=sys.stderr)
            sys.exit(2)
        # A Stage 2 start is marked failed unless the layer turned with the cube square; a
        # success at the last step may still have left a cubelet out of square.
        failed = rows[i]['ending'] != 'success' or rows[i].get('square') == 'false'
        if failed != bool(subset['failed'][k]):
            print(f"start {k}: the row says {rows[i]['ending']} but the start is marked otherwise", file=sys.stderr)
            sys.exit(2)
        picked.append(dict(rows[i], episode=str(k), seed=str(k)))
    tmp = out_path + '.tmp'
    with open(tmp, 'w', newline='') as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0].keys()), lineterminator='\n')
        writer.writeheader()
        writer.writerows(picked)
    os.replace(tmp, out_path)
    print(f"{len(picked)} rows, {sum(r['ending'] == 'success' for r in picked)} successes, into {out_path}")


if __name__ == '__main__':
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    main(*sys.argv[1:])
