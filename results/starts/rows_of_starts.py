"""Writes a recorded run's rows for a subset of its recorded starts, numbered as a replay of the subset numbers them.

Usage: python3 results/starts/rows_of_starts.py RUN.csv RUN.safetensors SUBSET.safetensors OUT.csv

Standard library only. RUN.csv and RUN.safetensors are one `dexcube eval-stage --episodes-csv ... --record-starts ...`
run; SUBSET.safetensors holds some of its starts in their order (for example `stage2_start_geometry --only-side`).
Each subset start is found in the recording by its physics state and goal, and the run's row for it is written with
`episode` and `seed` set to the subset's index, as `eval-stage --starts SUBSET` numbers its rows, so the output pairs
with a replay by `results/goal-lead/pair_episodes.py` without replaying the recorded policy (session 57). It checks
each row against its start's failure mark, read as the recording's metadata names it (`drops_by_start.origin`).
Whatever it cannot pair (not one run, a mark it does not read, a start not found, a mark that disagrees) it refuses
with exit code 2 (`merge_starts.refuse`).
"""
import csv, os, sys
from drops_by_start import load, origin
from merge_starts import refuse
from pair_failures import marks

# Whether a row failed, for each failure mark an `eval-stage --record-starts` run writes (`RecordedFailure` in
# crates/env; the `dropped` mark of sessions 13 to 19 came from operator runs, which have no episodes CSV).
FAILED = {
    'dropped-or-missed': lambda row: row['ending'] != 'success',
    # Stage 2: a success at the last step may still have left a cubelet out of square.
    'not-square': lambda row: row['ending'] != 'success' or row['square'] == 'false',
}


def main(run_csv, run_starts, subset_starts, out_path):
    run = load(run_starts)
    subset = load(subset_starts)
    with open(run_csv) as f:
        rows = list(csv.DictReader(f))
    if len(rows) != len(run['state']):
        refuse(f"{run_csv} has {len(rows)} rows but {run_starts} {len(run['state'])} starts: they are not one run")
    mark = origin(run)['failure']
    if mark not in FAILED:
        refuse(f"{run_starts} marks failures as '{mark}', which this script does not read")
    index = {(tuple(s), tuple(g)): i for i, (s, g) in enumerate(zip(run['state'], run['goal']))}
    picked = []
    keys = zip(map(tuple, subset['state']), map(tuple, subset['goal']))
    for k, (key, failed) in enumerate(zip(keys, marks(subset))):
        i = index.get(key)
        if i is None:
            refuse(f"start {k} of {subset_starts} is not in {run_starts}")
        if FAILED[mark](rows[i]) != failed:
            refuse(f"start {k}: its row ({rows[i]['ending']}) disagrees with its '{mark}' mark")
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
