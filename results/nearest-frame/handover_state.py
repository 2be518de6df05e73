"""How the cube moves when Stage 2 takes over in the operator, for two recordings of Stage 2 starts.

Usage: python3 results/nearest-frame/handover_state.py FIRST.safetensors SECOND.safetensors

Standard library only. Each file is `dexcube eval --record-layer-starts` on the `cube` scene. Its
states are MuJoCo's physics state as `Sim::physics_state` writes it: time, qpos (the hand's 24
joints, the cube's free joint, the seven cubelets' ball joints: 59), qvel (51), the solver's warm
start (51), then the controls (20). For the hand's joint speed, the cube's speed and the cube's
spin, the script prints each file's median and ninetieth percentile. It also prints the Stage 2
failures above and below the median of both files pooled. Session 62 in `results/TRAINING.md`.
"""
import math, os, sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'starts'))
from drops_by_start import load

QVEL = 1 + 59


def norm(values):
    return math.sqrt(sum(v * v for v in values))


def rows(path):
    recording = load(path)
    for state, failed in zip(recording['state'], recording['failed']):
        yield (norm(state[QVEL:QVEL + 24]), norm(state[QVEL + 24:QVEL + 27]),
               norm(state[QVEL + 27:QVEL + 30]), failed > 0.5)


def quantile(values, p):
    values = sorted(values)
    return values[int(p * (len(values) - 1))]


def main(args):
    if len(args) != 2:
        sys.exit(__doc__)
    first, second = list(rows(args[0])), list(rows(args[1]))
    for k, name in enumerate(['hand joint speed (rad/s)', 'cube speed (m/s)', 'cube spin (rad/s)']):
        pooled = sorted(row[k] for row in first + second)
        median = pooled[len(pooled) // 2]
        for label, chosen in (('first', first), ('second', second)):
            values = [row[k] for row in chosen]
            above = [row for row in chosen if row[k] >= median]
            below = [row for row in chosen if row[k] < median]
            print(f"{name:26s} {label:6s} median {quantile(values, 0.5):.4f}, 90th {quantile(values, 0.9):.4f}; "
                  f"failed above the pooled median {sum(r[3] for r in above)}/{len(above)}, "
                  f"below {sum(r[3] for r in below)}/{len(below)}")


if __name__ == '__main__':
    main(sys.argv[1:])
