"""Where Stage 1 fails from: its recorded starts binned by where and how the cube lies, with each bin's failures.

Usage: python3 results/starts/stage1_start_geometry.py STARTS.safetensors EPISODES.csv [STARTS2 EPISODES2 ...]

Each pair is one `dexcube eval-stage rot --record-starts STARTS --episodes-csv EPISODES` run (row k is start k).
Standard library only. From each start's physics state (the cube's free joint after the hand's 24 joints, as
`drops_by_start.py` reads it) and its pose goal it bins: the tilt of the goal's up axis from the vertical (either face
of the pair, 0 to 90 degrees), the whole angle the cube must turn (the CSV's `start_angle_error`), the cube's yaw from
square to the hand (0 to 45 degrees, as `stage2_start_geometry` reads it), and its offset from the goal's position
across the palm (x, towards the little finger) and along it (y, towards the wrist), in millimetres. A failure is any
ending but `success`; drops are counted apart (session 59).
"""
import csv, math, sys
from collections import Counter
from drops_by_start import load, rot
from merge_starts import refuse


def starts(path, episodes_path):
    recording = load(path)
    episodes = list(csv.DictReader(open(episodes_path)))
    if len(episodes) != len(recording['state']):
        refuse(f"{episodes_path} has {len(episodes)} rows and {path} {len(recording['state'])} starts: not one run")
    for state, goal, episode in zip(recording['state'], recording['goal'], episodes):
        position, orientation = state[25:28], state[28:32]
        goal_position, goal_orientation = goal[:3], goal[3:7]
        inverse = (goal_orientation[0], -goal_orientation[1], -goal_orientation[2], -goal_orientation[3])
        up = rot(orientation, rot(inverse, (0, 0, 1)))
        side = min((rot(orientation, axis) for axis in ((1, 0, 0), (0, 1, 0), (0, 0, 1))), key=lambda v: abs(v[2]))
        yaw = math.degrees(math.atan2(side[1], side[0])) % 90
        yield dict(ending=episode['ending'],
                   tilt=math.degrees(math.acos(min(1.0, abs(up[2])))),
                   angle=math.degrees(float(episode['start_angle_error'])),
                   yaw=min(yaw, 90 - yaw),
                   dx=1000 * (position[0] - goal_position[0]),
                   dy=1000 * (position[1] - goal_position[1]))


def main(args):
    if len(args) < 2 or len(args) % 2:
        sys.exit(__doc__)
    rows = [row for k in range(0, len(args), 2) for row in starts(args[k], args[k + 1])]
    endings = Counter(row['ending'] for row in rows)
    print(f"{len(rows)} starts, {len(rows) - endings['success']} failed: {dict(endings)}")
    for key, edges in [('tilt', [0, 10, 45, 80, 91]), ('angle', [0, 20, 45, 90, 181]),
                       ('yaw', [0, 5, 15, 25, 35, 45.1]), ('dx', [-100, -6, -3, 0, 3, 6, 100]),
                       ('dy', [-100, -6, -3, 0, 3, 6, 100])]:
        print(f"by {key}:")
        for low, high in zip(edges, edges[1:]):
            chosen = [row for row in rows if low <= row[key] < high]
            failed = sum(row['ending'] != 'success' for row in chosen)
            drops = sum(row['ending'] == 'dropped' for row in chosen)
            rate = 100 * failed / max(1, len(chosen))
            print(f"  {low:>5} to {high:<5}: {len(chosen):5d} starts, {failed:4d} failed ({rate:.1f}%), {drops} drops")


if __name__ == '__main__':
    main(sys.argv[1:])
