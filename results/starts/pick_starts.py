"""Keeps the starts of a recording whose replay began at least some angle from the goal.

Usage: python3 results/starts/pick_starts.py OUT.safetensors STARTS.safetensors REPLAY.csv MIN_START_ANGLE

REPLAY.csv is `dexcube eval-stage rot --starts STARTS.safetensors --episodes-csv REPLAY.csv` run over all of
STARTS: row k is start k, and its `start_angle_error` is how far (rad) the cube began from its goal. With the
closest states of `eval-stage --record-closest`, a minimum of 0.5 picks the stuck cubes, the misses that never
came near their pose. Standard library only. The output keeps the recording's metadata, with this command added
to its own, and is written through a temporary file and a rename (`merge_starts.write_starts`). A replay that
does not cover the recording row for row is refused with exit code 2.
"""
import csv, sys
from drops_by_start import load
from merge_starts import refuse, write_starts


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    out, starts_path, replay_path, min_angle = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
    recording = load(starts_path)
    with open(replay_path, newline='') as f:
        rows = list(csv.DictReader(f))
    if len(rows) != len(recording['failed']):
        refuse(f"{replay_path} has {len(rows)} episodes but {starts_path} holds {len(recording['failed'])} starts: "
               f"replay all of them (--episodes {len(recording['failed'])})")
    if [int(row['episode']) for row in rows] != list(range(len(rows))):
        refuse(f"{replay_path}: its rows are not episodes 0, 1, 2, ... in order")
    kept = [k for k, row in enumerate(rows) if float(row['start_angle_error']) >= min_angle]
    if not kept:
        refuse(f"no start of {starts_path} began {min_angle} rad or more from its goal")
    metadata = dict(recording['__metadata__'])
    metadata['command'] = (f"python3 results/starts/pick_starts.py {out} {starts_path} {replay_path} {min_angle} "
                           f"(from {starts_path}: {metadata.get('command', '?')})")
    write_starts(out, [recording['state'][k] for k in kept], [recording['goal'][k] for k in kept],
                 [recording['failed'][k] for k in kept], metadata)
    print(f"{out}: {len(kept)} of {len(rows)} starts, each {min_angle} rad or more from its goal")


if __name__ == '__main__':
    main()
