#!/usr/bin/env python3
"""Where breast_resection's cone stays joined (docs/cutting.md, "Where the cone stays joined").

usage: cone_junction.py POINTS.vtp CHECKPOINT.phx[.xz] [SPACING]

POINTS.vtp: any points file of the same scene and --refine (its rest positions and flags);
CHECKPOINT: a run's checkpoint.phx (docs/checkpoint.md: sections 2, 3 and 9). SPACING (m, default
0.002, the scene's at K = 2): neighbours are the 26 of the cubic lattice (support radius twice the
spacing). Prints the live pairs joining the phyxels reachable from the carcinoma through phyxels
inside the planned cone (apex (10, 10, 4.08) mm, axis z, half-angle 35 degrees) to those
reachable from the fixed layer through phyxels outside it, grouped by azimuth and distance from
the apex, then the phyxels of the piece at those pairs. Those pairs overcount where the blade
passed inside the planned cone (a sheet of phyxels just inside it goes with the breast), so last
it prints the fewest live pairs whose severing would free the carcinoma (a minimum cut between
the phyxels within 6 mm of its centre and the fixed layer; unit capacities, Edmonds-Karp). Pure
Python (no numpy).
"""
import lzma, math, re, struct, sys
from collections import Counter, defaultdict, deque

APEX, CENTRE, HALF = (0.010, 0.010, 0.00408), (0.010, 0.010, 0.025), math.radians(35)


def read_vtp(path):
    raw = open(path, 'rb').read()
    head = raw[:raw.index(b'<AppendedData')].decode()
    n = int(re.search(r'NumberOfPoints="(\d+)"', head).group(1))
    base = raw.index(b'_', raw.index(b'<AppendedData')) + 1
    def array(name, fmt, comps):
        off = int(re.search(r'Name="%s"[^>]*offset="(\d+)"' % name, head).group(1))
        return struct.unpack_from('<%d%s' % (comps * n, fmt), raw, base + off + 8)
    r = array('rest_position', 'd', 3)
    return [tuple(r[3 * i:3 * i + 3]) for i in range(n)], array('flags', 'I', 1)


def read_checkpoint(path):
    data = lzma.open(path).read() if path.endswith('.xz') else open(path, 'rb').read()
    p, out = 24, {'severed': set()}
    for _ in range(struct.unpack_from('<I', data, 12)[0]):
        tag, length = struct.unpack_from('<IQ', data, p)
        p += 12
        if tag == 2:
            out['step'] = struct.unpack_from('<q', data, p)[0]
        elif tag == 3:
            c = struct.unpack_from('<Q', data, p)[0]
            out['u'] = struct.unpack_from('<%dd' % (3 * c), data, p + 8)
        elif tag == 9:
            for k in range(struct.unpack_from('<Q', data, p)[0]):
                i, j, _ = struct.unpack_from('<IIf', data, p + 8 + 12 * k)
                out['severed'].add((i, j))
        p += length
    return out


def cone_distance(x):  # m, > 0 outside the planned cone
    dx, dy, dz = (x[k] - APEX[k] for k in range(3))
    return math.hypot(dx, dy) * math.cos(HALF) - dz * math.sin(HALF)


def min_cut(adj, sources, sinks):
    """The fewest pairs of adj (undirected, each of capacity 1) separating sources from sinks."""
    flow, sinks = defaultdict(int), set(sinks)
    while True:
        prev, todo, end = {s: None for s in sources}, deque(sources), None
        while todo and end is None:
            u = todo.popleft()
            for v in adj[u]:
                if v not in prev and flow[(u, v)] < 1:
                    prev[v] = u
                    if v in sinks:
                        end = v
                        break
                    todo.append(v)
        if end is None:
            return sorted((u, v) for u in prev for v in adj[u] if v not in prev)
        while prev[end] is not None:
            u = prev[end]
            flow[(u, end)] += 1
            flow[(end, u)] -= 1
            end = u


def main():
    rest, flags = read_vtp(sys.argv[1])
    ck = read_checkpoint(sys.argv[2])
    h = float(sys.argv[3]) if len(sys.argv) > 3 else 0.002
    n, u = len(rest), ck['u']
    cur = lambda i: tuple(rest[i][k] + u[3 * i + k] for k in range(3))
    key = {tuple(round(c / h * 2) for c in x): i for i, x in enumerate(rest)}
    adj = defaultdict(list)
    for i, x in enumerate(rest):
        k0 = tuple(round(c / h * 2) for c in x)
        for o in [(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1)]:
            j = key.get(tuple(k0[m] + 2 * o[m] for m in range(3)))
            if j is not None and i < j and (i, j) not in ck['severed']:
                adj[i].append(j)
                adj[j].append(i)
    inside = [cone_distance(x) < 0 for x in rest]
    def reach(starts, ok):
        seen = set(s for s in starts if ok(s))
        todo = deque(seen)
        while todo:
            for j in adj[todo.popleft()]:
                if j not in seen and ok(j):
                    seen.add(j)
                    todo.append(j)
        return seen
    c0 = min(range(n), key=lambda i: math.dist(rest[i], CENTRE))
    piece = reach([c0], lambda i: inside[i])
    breast = reach([i for i in range(n) if flags[i] & 1], lambda i: not inside[i])
    joins = [(i, j) for i in piece for j in adj[i] if j in breast]
    print(f"step {ck['step']}: {n} phyxels, {len(ck['severed'])} pairs severed; piece {len(piece)}, "
          f"breast {len(breast)}, {len(joins)} live pairs between them")
    groups = Counter()
    for i, j in joins:
        m = [(rest[i][k] + rest[j][k]) / 2 for k in range(3)]
        az = math.degrees(math.atan2(m[1] - APEX[1], m[0] - APEX[0])) % 360
        groups[(int(az // 15) * 15, int(1e3 * math.dist(m, APEX) // 5) * 5)] += 1
    for (az, d), c in sorted(groups.items()):
        print(f"  azimuth {az}-{az + 15} deg, {d}-{d + 5} mm from the apex: {c} pairs")
    for i in sorted(set(i for i, _ in joins)):
        print(f"  piece phyxel {i} at {tuple(round(1e3 * v, 1) for v in rest[i])} mm: cone distance "
              f"{1e3 * cone_distance(rest[i]):+.2f} mm at rest, {1e3 * cone_distance(cur(i)):+.2f} now; "
              f"live pairs to the piece {sum(j in piece for j in adj[i])}, "
              f"to the breast {sum(j in breast for j in adj[i])}")
    tumour = [i for i in range(n) if math.dist(rest[i], CENTRE) < 0.006]
    cut = min_cut(adj, tumour, [i for i in range(n) if flags[i] & 1])
    print(f"fewest live pairs holding the carcinoma (a minimum cut): {len(cut)}")
    for i, j in cut:
        az = math.degrees(math.atan2(rest[i][1] - APEX[1], rest[i][0] - APEX[0])) % 360
        print(f"  {i} - {j}: azimuth {az:.0f} deg, {1e3 * math.dist(rest[i], APEX):.1f} mm from the "
              f"apex; cone distance {1e3 * cone_distance(rest[i]):+.2f} / {1e3 * cone_distance(rest[j]):+.2f} "
              f"mm at rest, {1e3 * cone_distance(cur(i)):+.2f} / {1e3 * cone_distance(cur(j)):+.2f} now")


if __name__ == '__main__':
    main()
