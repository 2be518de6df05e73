"""Where several recordings of the same episodes all fail: the starts no policy gets past.

Usage: python3 results/starts/common_failures.py OUT.safetensors RECORDING.safetensors...

Standard library only. Every recording (`dexcube eval-stage ... --record-starts`) must hold the same
episodes with the same failure meaning, as `pair_failures.py` asks. It prints how many episodes are failed
by none, one, two, ... of the recordings, and writes the starts to OUT marked failed where every recording
failed, so that `stage2_start_geometry OUT` (or `stage1_start_geometry`) shows where those starts lie.
"""
import sys
from collections import Counter
from drops_by_start import load, origin
from merge_starts import refuse, write_starts
from pair_failures import marks

def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    out, recordings = sys.argv[1], [load(path) for path in sys.argv[2:]]
    first = recordings[0]
    for path, recording in zip(sys.argv[3:], recordings[1:]):
        if recording['state'] != first['state']:
            refuse(f"{path} does not hold the same episodes as {sys.argv[2]}: record all with the same stage, --seed and --episodes")
        if origin(recording)['failure'] != origin(first)['failure']:
            refuse(f"{path} marks failures differently from {sys.argv[2]}: record all with the same stage")
    failed_by = [sum(column) for column in zip(*(marks(r) for r in recordings))]
    counts = Counter(failed_by)
    print("episodes failed by k of the %d recordings: %s" % (len(recordings),
          ", ".join(f"k={k}: {counts[k]}" for k in range(len(recordings) + 1))))
    write_starts(out, first['state'], first['goal'],
                 [1.0 if k == len(recordings) else 0.0 for k in failed_by], first['__metadata__'])
    print(f"wrote {out}: {len(failed_by)} starts, {counts[len(recordings)]} marked failed (failed by every recording)")

if __name__ == '__main__':
    main()
