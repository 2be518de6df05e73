"""Counts, for each episode of several recordings of the same episodes, in how many of them it failed.

Usage: python3 results/guide/failure_counts.py [--always-out OUT.safetensors] RECORDING.safetensors...

Standard library only; the recordings are `dexcube eval-stage ... --record-starts` files of the same stage, seed
and count (read by results/starts/drops_by_start.py), such as one policy run unchanged and nudged
(`dexcube guide P --critics RUN --candidates 1 --spread 0.0001 --seed N`). It prints how many episodes failed in
k of the n recordings for each k, and the mean failure rate with the share of it from episodes that failed in
every recording: the part of the failures that is the placement's, not chaos's. With --always-out it also writes
the first recording with only those episodes marked failed, so that the start-geometry example
(`cargo run --release -p dexcube-operator --example stage2_start_geometry -- OUT.safetensors`) says where they sit.
"""
import os, sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'starts'))
from drops_by_start import load
from merge_starts import write_starts
from pair_failures import marks


def write_marked(path, recording, flags):
    """`recording`'s starts and goals with `flags` as its failure marks, written to `path`."""
    metadata = dict(recording['__metadata__'])
    metadata['command'] = (f"python3 results/guide/failure_counts.py --always-out {path} ... (marks: failed in "
                           f"every recording; starts from {metadata.get('command', 'an unnamed recording')})")
    write_starts(path, recording['state'], recording['goal'], flags, metadata)


def main():
    paths, always_out = sys.argv[1:], None
    if paths[:1] == ['--always-out']:
        always_out, paths = paths[1], paths[2:]
    if len(paths) < 2:
        sys.exit(__doc__)
    recordings = [load(p) for p in paths]
    if any(r['state'] != recordings[0]['state'] for r in recordings[1:]):
        sys.exit("the recordings do not hold the same episodes (their start states differ)")
    failed = [marks(r) for r in recordings]
    n, episodes = len(failed), len(failed[0])
    counts = [sum(f[i] for f in failed) for i in range(episodes)]
    for k in range(n + 1):
        print(f"failed in {k} of {n}: {counts.count(k)} episodes")
    total = sum(counts)
    always = counts.count(n) * n
    print(f"mean failures per run {total / n:.1f} of {episodes}; from episodes failed in every run: "
          f"{always / n:.0f} ({always / max(total, 1):.0%})")
    if always_out:
        write_marked(always_out, recordings[0], [c == n for c in counts])
        print(f"wrote {always_out}: the first recording with the {counts.count(n)} episodes failed in every run marked")


if __name__ == '__main__':
    main()
