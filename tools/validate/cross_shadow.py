#!/usr/bin/env python3
"""Outside check of one lit effect's shadow on another (tests/lighting/cross_shadow_test.cpp,
CrossShadows.PlumeBetweenTheSunAndAnEffectDarkensItByThePlumesTransmittance), standard
library only, no splatfx code linked.

The upper plume of that test is written out here from its definition: 4x4x4 voxels,
spacing 1, voxel (0, 0, 0) centred at (-2, 11, -1), opacity 0.2 + 0.05 x + 0.04 y + 0.05 z,
so extinction -ln(1 - opacity) per unit at each voxel centre, trilinear between centres
and falling to zero one voxel beyond (zero outside). The lower plume's 4x4x4 splat
centres sit at (-1.5, 4, -1.5) + (i, j, k). For each, the optical depth towards the sun
(travelling along (0.15, -1, -0.1)) is integrated piece by piece between the ray's
crossings of the voxel-centre planes (a cubic on each piece) by Simpson's rule; the
transmittance is exp(-depth). Prints the smallest, the largest and the mean
transmittance over the 64 centres, which the test prints from the lit reference
(litFactor) as "reference T".

    python3 tools/validate/cross_shadow.py
"""
import math

ORIGIN = (-2.0, 11.0, -1.0)
DIMS = (4, 4, 4)
SUN = (0.15, -1.0, -0.1)
# The test's opacities are float sums (0.2f + 0.05f x ...) and its depths are stored as floats;
# these are doubles: they differ by about 6e-8 relative, a change in T's 7th or 8th digit.


def value(x, y, z):
    if x < 0 or y < 0 or z < 0 or x >= DIMS[0] or y >= DIMS[1] or z >= DIMS[2]:
        return 0.0
    opacity = 0.2 + 0.05 * x + 0.04 * y + 0.05 * z
    return -math.log1p(-opacity)


def extinction(p):
    u = [(p[a] - ORIGIN[a]) for a in range(3)]
    i = [math.floor(c) for c in u]
    w = [u[a] - i[a] for a in range(3)]
    s = 0.0
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                wt = (w[0] if dx else 1 - w[0]) * (w[1] if dy else 1 - w[1]) * (w[2] if dz else 1 - w[2])
                if wt > 0.0:
                    s += wt * value(i[0] + dx, i[1] + dy, i[2] + dz)
    return s


def depth_to_sun(p):
    n = math.sqrt(sum(c * c for c in SUN))
    d = [-c / n for c in SUN]
    # Far enough to leave the plume's support (it reaches y = 15).
    length = (20.0 - p[1]) / d[1]
    cuts = {0.0, length}
    for a in range(3):
        if d[a] != 0.0:
            for m in range(-30, 30):
                t = (ORIGIN[a] + m - p[a]) / d[a]
                if 0.0 < t < length:
                    cuts.add(t)
    cuts = sorted(cuts)

    def simpson(t0, t1, panels):
        h = (t1 - t0) / panels
        total = 0.0
        for k in range(panels + 1):
            wgt = 1 if k in (0, panels) else (4 if k % 2 else 2)
            total += wgt * extinction([p[a] + (t0 + k * h) * d[a] for a in range(3)])
        return total * h / 3.0

    tau, worst = 0.0, 0.0
    for t0, t1 in zip(cuts, cuts[1:]):
        two, four = simpson(t0, t1, 2), simpson(t0, t1, 4)
        worst = max(worst, abs(two - four))
        tau += four
    return tau, worst


def main():
    ts, worst = [], 0.0
    for i in range(4):
        for j in range(4):
            for k in range(4):
                tau, w = depth_to_sun((-1.5 + i, 4.0 + j, -1.5 + k))
                ts.append(math.exp(-tau))
                worst = max(worst, w)
    print("outside check: min T %.9f, max T %.9f, mean T %.9f over %d centres" % (min(ts), max(ts), sum(ts) / len(ts), len(ts)))
    print("largest change of a piece's depth from 2 to 4 Simpson panels: %.3g (0 up to rounding: cubic pieces)" % worst)


if __name__ == "__main__":
    main()
