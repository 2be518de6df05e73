"""Pairs two recordings of the same episodes (`dexcube eval-stage ... --record-starts`) by their failure marks.

Usage: python3 results/starts/pair_failures.py FIRST.safetensors SECOND.safetensors

Standard library only. Both files must hold the same episodes (same stage, seed and count). It prints how
many episodes each policy failed, how many the second fixed and how many it failed anew, and the two-sided
sign test on those discordant episodes. Files from sessions 13 to 19 name the marks `dropped`, later ones `failed`.
"""
import json, struct, sys, math
def marks(path):
    f = open(path, 'rb'); n = struct.unpack('<Q', f.read(8))[0]; h = json.loads(f.read(n)); data = f.read()
    v = h.get('failed') or h['dropped']; a, b = v['data_offsets']; cnt = (b - a) // 8
    return [x != 0 for x in struct.unpack('<%dd' % cnt, data[a:b])], h.get('__metadata__', {})
(a, ma), (b, mb) = marks(sys.argv[1]), marks(sys.argv[2])
assert len(a) == len(b)
fixed = sum(1 for x, y in zip(a, b) if x and not y); new = sum(1 for x, y in zip(a, b) if y and not x)
n = fixed + new; k = min(fixed, new)
p = min(1.0, 2 * sum(math.comb(n, i) for i in range(k + 1)) / 2 ** n) if n else 1.0
print(f"episodes {len(a)}; failed: first {sum(a)}, second {sum(b)}; fixed {fixed}, new {new}; sign test p = {p:.3g}; meaning {ma.get('failure')}/{mb.get('failure')}")
