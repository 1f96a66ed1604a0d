#!/usr/bin/env python3
"""Outside check of splatfx's VDB reference (readVdbDensity + denseMedium,
trilinear, through renderVolumeExact): the file is read here by OpenVDB's own
Python module (Debian's python3-openvdb, /usr/bin/python3) and each ray's
optical depth is integrated by a composite Simpson rule on OpenVDB's voxel
values interpolated trilinearly, refined until two results agree to 1e-10.

    /usr/bin/python3 tools/validate/vdb_reference.py --write DIR      # DIR/validation.vdb
    splatfx-bench vdb --validation --out DIR > vdb_case.csv
    /usr/bin/python3 tools/validate/vdb_reference.py DIR/validation.vdb vdb_case.csv
"""
import csv
import math
import os
import sys

import pyopenvdb as vdb


def write(folder):
    g = vdb.FloatGrid(0.0)
    g.name = 'density'
    g.gridClass = vdb.GridClass.FOG_VOLUME
    g.transform = vdb.createLinearTransform(voxelSize=0.25)
    acc = g.getAccessor()
    for z in range(3):
        for y in range(4):
            for x in range(5):
                acc.setValueOn((x, y, z), 0.2 + 0.1 * ((7 * x + 3 * y + 5 * z) % 11))
    g.fill((8, 0, 0), (15, 7, 7), 0.6, True)  # one 8^3 node-aligned constant region: OpenVDB stores it as a tile
    os.makedirs(folder, exist_ok=True)
    vdb.write(os.path.join(folder, 'validation.vdb'), grids=[g])


def main():
    if len(sys.argv) == 3 and sys.argv[1] == '--write':
        write(sys.argv[2])
        return 0
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    g = vdb.read(sys.argv[1], 'density')
    vs = g.transform.voxelSize()[0]
    acc = g.getConstAccessor()
    (lo, hi) = g.evalActiveVoxelBoundingBox()

    def value(i, j, k):
        v, on = acc.probeValue((i, j, k))
        return v if on else 0.0

    def sigma(x, y, z):
        u = [x / vs, y / vs, z / vs]  # index space: voxel centres on integers (no translation here)
        f = [math.floor(c) for c in u]
        w = [u[a] - f[a] for a in range(3)]
        s = 0.0
        for c in range(8):
            d = (c & 1, (c >> 1) & 1, (c >> 2) & 1)
            wt = 1.0
            for a in range(3):
                wt *= w[a] if d[a] else 1.0 - w[a]
            if wt > 0.0:
                s += wt * value(int(f[0]) + d[0], int(f[1]) + d[1], int(f[2]) + d[2])
        return s

    # Kinks at voxel-centre planes z = k vs: Simpson on each voxel interval is exact for the
    # cubic the trilinear reading is along a line; still refined as a check.
    z0, z1 = (lo[2] - 1) * vs, (hi[2] + 1) * vs

    def tau(x, y):
        def simpson(n):
            total = 0.0
            for k in range(lo[2] - 1, hi[2] + 1):
                a, b = k * vs, (k + 1) * vs
                h = (b - a) / n
                s = sigma(x, y, a) + sigma(x, y, b)
                for i in range(1, n):
                    s += (4.0 if i % 2 else 2.0) * sigma(x, y, a + i * h)
                total += s * h / 3.0
            return total

        n, prev = 2, None
        while True:
            cur = simpson(n)
            if prev is not None and abs(cur - prev) < 1e-10 or n > 64:
                return cur
            prev, n = cur, n * 2

    rows = [r for r in csv.reader(l for l in open(sys.argv[2]) if not l.startswith('#'))][1:]
    worst = 0.0
    for x, y, alpha in rows:
        mine = -math.expm1(-tau(float(x), float(y)))
        worst = max(worst, abs(mine - float(alpha)))
        print(f"x {float(x):.3f} y {float(y):+.3f}: splatfx {float(alpha):.7f}  OpenVDB + Simpson {mine:.7f}  diff {mine - float(alpha):+.2e}")
    print(f"largest difference in alpha: {worst:.2e} over {len(rows)} rays (z from {z0} to {z1})")
    return 0


if __name__ == '__main__':
    sys.exit(main())
