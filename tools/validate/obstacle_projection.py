#!/usr/bin/env python3
"""Outside check of the solver's projection around an obstacle, standard
library only, no splatfx code linked.

The case is written out here from its definition: 8 x 14 x 6 cells of 0.5, a
vertical channel (x and z sides shut, floor and ceiling open: pressure 0
outside), a solid box over cells x 2..5, y 5..7, z 1..4, uniform upward flow 1
on every face that is not a wall (a face with a solid cell on either side is a
wall of a static obstacle: 0). The pressure solves the discrete Poisson
problem on the fluid cells (walls: no flux term) by conjugate gradient in
double precision to a relative residual of 1e-13; the faces that are not walls
lose the pressure gradient. Reads the CSV `splatfx-bench obstacles
--validation` prints (axis, i, j, k, u) and prints the largest difference.

    splatfx-bench obstacles --validation > obstacle_case.csv
    python3 tools/validate/obstacle_projection.py obstacle_case.csv
"""
import csv
import math
import sys

NX, NY, NZ, H = 8, 14, 6, 0.5
DIMS = (NX, NY, NZ)


def solid(c):
    x, y, z = c
    return 2 <= x <= 5 and 5 <= y <= 7 and 1 <= z <= 4


def inside(c):
    return all(0 <= c[a] < DIMS[a] for a in range(3))


def wall(a, f):
    """Face f (index along axis a between cells f - e_a and f) is a wall."""
    lo = list(f)
    lo[a] -= 1
    lo = tuple(lo)
    if a != 1 and (f[a] == 0 or f[a] == DIMS[a]):
        return True  # shut sides
    return (inside(lo) and solid(lo)) or (inside(f) and solid(f))


def faces(a):
    d = list(DIMS)
    d[a] += 1
    for k in range(d[2]):
        for j in range(d[1]):
            for i in range(d[0]):
                yield (i, j, k)


u = {}
for a in range(3):
    for f in faces(a):
        u[(a, f)] = 1.0 if (a == 1 and not wall(a, f)) else 0.0

cells = [(i, j, k) for k in range(NZ) for j in range(NY) for i in range(NX) if not solid((i, j, k))]
index = {c: n for n, c in enumerate(cells)}


def hi_face(c, a):
    f = list(c)
    f[a] += 1
    return tuple(f)


rhs = []
for c in cells:
    div = sum((u[(a, hi_face(c, a))] - u[(a, c)]) / H for a in range(3))
    rhs.append(-div)


def apply_a(x):
    out = [0.0] * len(cells)
    for n, c in enumerate(cells):
        acc = 0.0
        for a in range(3):
            for side in (-1, 1):
                f = hi_face(c, a) if side > 0 else c
                if wall(a, f):
                    continue
                nb = list(c)
                nb[a] += side
                nb = tuple(nb)
                if not inside(nb):
                    acc += x[n] / (H * H)  # open: pressure 0 outside
                    continue
                acc += (x[n] - x[index[nb]]) / (H * H)
        out[n] = acc
    return out


p = [0.0] * len(cells)
r = list(rhs)
d = list(r)
rr = sum(v * v for v in r)
rr0 = rr
while rr > 1e-26 * rr0:
    q = apply_a(d)
    alpha = rr / sum(di * qi for di, qi in zip(d, q))
    p = [pi + alpha * di for pi, di in zip(p, d)]
    r = [ri - alpha * qi for ri, qi in zip(r, q)]
    rr_new = sum(v * v for v in r)
    d = [ri + (rr_new / rr) * di for ri, di in zip(r, d)]
    rr = rr_new


def pressure(c):
    return p[index[c]] if inside(c) and not solid(c) else 0.0


expected = {}
for a in range(3):
    for f in faces(a):
        v = u[(a, f)]
        if not wall(a, f):
            lo = list(f)
            lo[a] -= 1
            v -= (pressure(f) - pressure(tuple(lo))) / H
        expected[(a, f)] = v

worst, where = 0.0, None
with open(sys.argv[1]) as fh:
    rows = list(csv.DictReader(fh))
for row in rows:
    key = (int(row["axis"]), (int(row["i"]), int(row["j"]), int(row["k"])))
    diff = abs(float(row["u"]) - expected[key])
    if diff > worst:
        worst, where = diff, key
print(f"{len(rows)} faces, {len(cells)} fluid cells; largest |u_splatfx - u_here| = {worst:.3g} at {where}; "
      f"largest |u| here = {max(abs(v) for v in expected.values()):.4f}")
