"""Drop rates of recorded Stage 1 starts (`dexcube eval --record-starts`) by where the cube lies.

Usage: python3 results/starts/drops_by_start.py results/starts/starts-*.safetensors

Standard library only. It reads each start's physics state (MuJoCo's integration state on
the `cube` scene: time, then qpos with the hand's 24 joints first and the cube's free joint
next, then qvel, laid out as `Sim::physics_state` writes it), the pose asked for, and whether
the recorded policy then dropped the cube, and prints the drop rate in bins of: the angle
between the axis to bring up and the vertical (`tilt`, degrees, either face of the pair),
the cube's horizontal distance from the target position (cm), its offsets (cm), speed (cm/s)
and spin (rad/s).
"""
import json, struct, sys, math
def load(path):
    with open(path, 'rb') as f:
        data = f.read()
    n = struct.unpack_from('<Q', data)[0]; h = json.loads(data[8:8 + n]); base = 8 + n
    out = {'__metadata__': h.get('__metadata__', {})}
    for k, v in h.items():
        if k == '__metadata__': continue
        a, b = v['data_offsets']; cnt = (b - a) // 8
        vals = struct.unpack('<%dd' % cnt, data[base + a: base + b])
        shape = v['shape']
        if len(shape) == 2: vals = [vals[i*shape[1]:(i+1)*shape[1]] for i in range(shape[0])]
        out[k] = vals
    return out
def origin(recording):
    """The stage, scene and failure mark of a loaded recording, read as `dexcube` reads them
    (`load_starts`): a file with no stage is Stage 1's, and one with no failure mark (session
    19's and earlier) marks drops for Stage 1 and the square test for Stage 2."""
    metadata = recording['__metadata__']
    stage = metadata.get('stage', 'rot')
    failure = metadata.get('failure', 'dropped' if stage == 'rot' else 'not-square')
    return {'stage': stage, 'scene': metadata.get('scene'), 'failure': failure}
def qmul(a, b):
    w1,x1,y1,z1=a; w2,x2,y2,z2=b
    return (w1*w2-x1*x2-y1*y2-z1*z2, w1*x2+x1*w2+y1*z2-z1*y2, w1*y2-x1*z2+y1*w2+z1*x2, w1*z2+x1*y2-y1*x2+z1*w2)
def rot(q, v):
    w,x,y,z=q; p=(0,)+tuple(v); c=(w,-x,-y,-z)
    r=qmul(qmul(q,p),c); return r[1:]
def summarise(rows, key, bins):
    print(key)
    for lo, hi in bins:
        sel = [r for r in rows if lo <= r[key] < hi]
        dr = sum(r['dropped'] for r in sel)
        print(f"  [{lo},{hi}) n={len(sel)} drops={int(dr)} rate={dr/max(1,len(sel)):.3f}")
def main():
    rows = []
    for path in sys.argv[1:]:
        s = load(path)
        for st, g, d in zip(s['state'], s['pose_goal'], s['dropped']):
            pos = st[25:28]; quat = st[28:32]
            lin = st[84:87]; ang = st[87:90]
            gpos = g[:3]; gq = g[3:]
            off = [pos[i]-gpos[i] for i in range(3)]
            # goal face axis: which cube axis the goal puts up; angle between that axis now and world z
            # goal up axis in cube frame = inverse(gq) applied to z
            gi = (gq[0], -gq[1], -gq[2], -gq[3])
            axis_c = rot(gi, (0,0,1))
            axis_w = rot(quat, axis_c)
            tilt = math.degrees(math.acos(max(-1,min(1,abs(axis_w[2])))))  # pair mode: either face
            rows.append(dict(dropped=d, dx=off[0]*100, dy=off[1]*100, dz=off[2]*100,
                dist=math.hypot(off[0],off[1])*100, speed=math.sqrt(sum(x*x for x in lin))*100,
                spin=math.sqrt(sum(x*x for x in ang)), tilt=tilt))
    print('total', len(rows), int(sum(r['dropped'] for r in rows)))
    summarise(rows, 'tilt', [(0,10),(10,45),(45,80),(80,91)])
    summarise(rows, 'dist', [(0,0.5),(0.5,1),(1,1.5),(1.5,2),(2,3),(3,100)])
    summarise(rows, 'dz', [(-100,-1),(-1,-0.3),(-0.3,0.3),(0.3,1),(1,100)])
    summarise(rows, 'dx', [(-100,-1),(-1,-0.3),(-0.3,0.3),(0.3,1),(1,100)])
    summarise(rows, 'dy', [(-100,-1),(-1,-0.3),(-0.3,0.3),(0.3,1),(1,100)])
    summarise(rows, 'speed', [(0,0.5),(0.5,2),(2,5),(5,1000)])
    summarise(rows, 'spin', [(0,0.1),(0.1,0.5),(0.5,2),(2,1000)])
if __name__ == '__main__':
    main()
