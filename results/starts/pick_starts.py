"""Keeps the starts of a recording whose replay began at least some angle from the goal, or whose episode was handed over.

Usage: python3 results/starts/pick_starts.py OUT.safetensors STARTS.safetensors REPLAY.csv MIN_START_ANGLE
       python3 results/starts/pick_starts.py OUT.safetensors STARTS.safetensors REPLAY.csv handed-over

REPLAY.csv is `dexcube eval-stage rot|layer --starts STARTS.safetensors --episodes-csv REPLAY.csv` run over all of
STARTS, or the `--episodes-csv` of the run that recorded STARTS (`--record-starts`): row k is start k. With a number,
the starts whose `start_angle_error` (how far, in radians, the cube began from its goal) is at least that are kept:
with the closest states of `eval-stage --record-closest`, a minimum of 0.5 picks the stuck cubes, the misses that
never came near their pose (session 50). With `handed-over`, the starts whose episode a policy that hands over
(`dexcube handover`) handed to its member are kept: a change to what happens after the handover (the member, letting
go) changes only those episodes, so replaying them alone gives the full run's figure exactly (session 52). Standard
library only. The output keeps the recording's metadata, with this command added to its own, and is written through
a temporary file and a rename (`merge_starts.write_starts`). A replay that does not cover the recording row for row,
or has no `handed_over` column where one is asked for, is refused with exit code 2.
"""
import csv, sys
from drops_by_start import load
from merge_starts import refuse, write_starts


def keeps(rows, replay_path, rule):
    """The row numbers the rule keeps, and the rule in words."""
    if rule == 'handed-over':
        if rows and 'handed_over' not in rows[0]:
            refuse(f"{replay_path} has no handed_over column: make it with a policy that hands over (dexcube handover)")
        return [k for k, row in enumerate(rows) if row['handed_over'] == 'true'], "handed over"
    try:
        min_angle = float(rule)
    except ValueError:
        refuse(f"'{rule}' is neither a minimum start angle (radians) nor 'handed-over'")
    kept = [k for k, row in enumerate(rows) if float(row['start_angle_error']) >= min_angle]
    return kept, f"each {min_angle} rad or more from its goal"


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    out, starts_path, replay_path, rule = sys.argv[1:]
    recording = load(starts_path)
    with open(replay_path, newline='') as f:
        rows = list(csv.DictReader(f))
    if len(rows) != len(recording['failed']):
        refuse(f"{replay_path} has {len(rows)} episodes but {starts_path} holds {len(recording['failed'])} starts: "
               f"replay all of them (--episodes {len(recording['failed'])})")
    if [int(row['episode']) for row in rows] != list(range(len(rows))):
        refuse(f"{replay_path}: its rows are not episodes 0, 1, 2, ... in order")
    kept, which = keeps(rows, replay_path, rule)
    if not kept:
        refuse(f"no start of {starts_path} was kept ({which})")
    metadata = dict(recording['__metadata__'])
    metadata['command'] = (f"python3 results/starts/pick_starts.py {out} {starts_path} {replay_path} {rule} "
                           f"(from {starts_path}: {metadata.get('command', '?')})")
    write_starts(out, [recording['state'][k] for k in kept], [recording['goal'][k] for k in kept],
                 [recording['failed'][k] for k in kept], metadata)
    successes = sum(rows[k]['ending'] == 'success' for k in kept)
    print(f"{out}: {len(kept)} of {len(rows)} starts, {which}; {successes} of them successes in {replay_path}")


if __name__ == '__main__':
    main()
