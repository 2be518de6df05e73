"""Joins recordings of starts (`dexcube eval --record-starts`, `dexcube eval-stage --record-starts`) into one file.

Usage: python3 results/starts/merge_starts.py OUT.safetensors FIRST.safetensors SECOND.safetensors [...]

Standard library only; the inputs are read by `drops_by_start.load`. `dexcube train --starts` takes one file;
this one holds the starts of all the inputs, in order, so a run can draw the operator's hand-overs and fresh
placements alike (each failed start drawn --failed-weight times as often). The inputs must be of the same stage
and scene, with the same failure marks and the same state and goal sizes; otherwise it says which differ and
exits with 2 (a recording without a stage or failure mark is read as `dexcube` reads it,
`drops_by_start.origin`).
The output's metadata keeps the stage, scene and marks, and its command names this merge and the
inputs' own commands. It is written to a temporary file and then renamed.
"""
import json, os, struct, sys
from drops_by_start import load, origin


def refuse(message):
    print(message, file=sys.stderr)
    sys.exit(2)


def width(rows, name, path):
    sizes = {len(row) for row in rows}
    if len(sizes) != 1:
        refuse(f"{path}: its '{name}' rows differ in length")
    return sizes.pop()


def safetensors_bytes(tensors, metadata):
    """The file holding `tensors` ((name, shape, flat F64 values) each) and `metadata`."""
    header, blobs, offset = {}, [], 0
    for name, shape, values in tensors:
        blob = struct.pack('<%dd' % len(values), *values)
        header[name] = {'dtype': 'F64', 'shape': shape, 'data_offsets': [offset, offset + len(blob)]}
        blobs.append(blob)
        offset += len(blob)
    header['__metadata__'] = metadata
    text = json.dumps(header).encode()
    text += b' ' * (-len(text) % 8)
    return struct.pack('<Q', len(text)) + text + b''.join(blobs)


def write_starts(path, state, goal, failed, metadata):
    """Writes start rows, goal rows and failure marks as a recording at `path`, through a temporary file and a rename."""
    tensors = [(name, [len(rows), len(rows[0])], [x for row in rows for x in row])
               for name, rows in (('state', state), ('goal', goal))]
    tensors.append(('failed', [len(failed)], [float(x) for x in failed]))
    tmp = path + '.tmp'
    with open(tmp, 'wb') as f:
        f.write(safetensors_bytes(tensors, metadata))
    os.replace(tmp, path)


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    out, inputs = sys.argv[1], sys.argv[2:]
    recordings = [load(path) for path in inputs]
    for path, recording in zip(inputs, recordings):
        if 'failed' not in recording:
            refuse(f"{path} marks its starts with the older 'dropped' only: record it again to merge it")
    first = recordings[0]
    widths = {name: width(first[name], name, inputs[0]) for name in ('state', 'goal')}
    first_marks = origin(first)
    for path, recording in zip(inputs[1:], recordings[1:]):
        for key, value in origin(recording).items():
            if value != first_marks[key]:
                refuse(f"{inputs[0]} and {path} differ in {key}: {first_marks[key]} against {value}")
        for name in widths:
            if width(recording[name], name, path) != widths[name]:
                refuse(f"{inputs[0]} and {path} have '{name}' rows of different sizes")
    failed = [x for recording in recordings for x in recording['failed']]
    metadata = {key: value for key, value in first_marks.items() if value is not None}
    sources = '; '.join(f"{path}: {r['__metadata__'].get('command', '?')}" for path, r in zip(inputs, recordings))
    metadata['command'] = f"python3 results/starts/merge_starts.py {out} {' '.join(inputs)} (from {sources})"
    rows = {name: [row for r in recordings for row in r[name]] for name in widths}
    write_starts(out, rows['state'], rows['goal'], failed, metadata)
    print(f"{out}: {len(failed)} starts, {sum(1 for x in failed if x)} failed, from {len(inputs)} recordings")


if __name__ == '__main__':
    main()
