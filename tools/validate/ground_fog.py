#!/usr/bin/env python3
"""Independent check of splatfx's ground fog reference (integrateGroundFogRay).

Written from the definition in docs/volume.md / reference.hpp, not from the
C++ code, and using only the Python standard library: the fog layer of
Roettger & Ertl 2002, sec. 6 over a tiny height map, evaluated point by point
(find the cell, the triangle of the alternating split, interpolate terrain
and thickness by barycentric weights, test the point against the layer,
compute the scalar and the transfer function) and integrated along a few rays
by a plain midpoint rule with many steps (no piecewise analysis at all). The
emission-absorption model: C += T (1 - exp(-sigma h)) colour, T *= exp(-sigma h).

The midpoint rule is first order at the layer's boundaries (the extinction
jumps there), so each ray is run with N and 2N steps; the difference is its
error estimate. Compare the printed values with
    build/tools/bench/splatfx-bench groundfog --validate-case
which prints the C++ reference's values for the same case and rays.

Usage: python3 tools/validate/ground_fog.py [--steps N]
"""
import argparse
import math
import struct

# The case (the same numbers as splatfx-bench groundfog --validate-case).
NX, NZ = 3, 3
ORIGIN_X, ORIGIN_Z = -1.0, 0.5
SPACING = 1.5
TERRAIN = [0.0, 0.4, 1.1,
           0.2, -0.3, 0.6,
           0.9, 0.1, -0.2]
FOG_TOP = [1.2, 1.0, 0.9,    # point (2, 0): top below the terrain, no fog there
           1.4, 1.6, 1.0,
           1.3, 0.8, 1.1]
DENSITY = 0.8
# Transfer function: (scalar, colour, extinction per world unit), linear between.
TRANSFER = [(0.0, (1.0, 0.9, 0.8), 0.0),
            (0.4, (0.6, 0.7, 0.9), 1.2),
            (1.0, (0.2, 0.3, 0.7), 2.0)]
# Rays: origin, direction (normalized here), length.
RAYS = [((-2.0, 2.5, 0.0), (1.0, -0.6, 0.7), 10.0),
        ((3.5, 0.8, 1.2), (-1.0, 0.05, 0.3), 10.0),
        ((0.1, 3.0, 2.0), (0.05, -1.0, 0.02), 10.0),
        ((-1.5, 0.7, 3.9), (1.0, 0.0, -0.8), 10.0)]


def f32(x):
    """Round to IEEE single precision, as the desc's float heights are."""
    return struct.unpack('f', struct.pack('f', x))[0]


TERRAIN = [f32(v) for v in TERRAIN]
FOG_TOP = [f32(v) for v in FOG_TOP]
DENSITY = f32(DENSITY)
TRANSFER = [(f32(s), tuple(f32(c) for c in col), f32(e)) for s, col, e in TRANSFER]
SPACING = f32(SPACING)
ORIGIN_X, ORIGIN_Z = f32(ORIGIN_X), f32(ORIGIN_Z)


def transfer(s):
    if s <= TRANSFER[0][0]:
        return TRANSFER[0][1], TRANSFER[0][2]
    for (s0, c0, e0), (s1, c1, e1) in zip(TRANSFER, TRANSFER[1:]):
        if s <= s1:
            w = (s - s0) / (s1 - s0)
            return tuple(a + w * (b - a) for a, b in zip(c0, c1)), e0 + w * (e1 - e0)
    return TRANSFER[-1][1], TRANSFER[-1][2]


def field(x, y, z, depth):
    """(extinction, colour) at a world point; depth = densityDepthWorld."""
    gx = (x - ORIGIN_X) / SPACING
    gz = (z - ORIGIN_Z) / SPACING
    if gx < 0 or gz < 0 or gx > NX - 1 or gz > NZ - 1:
        return 0.0, (0.0, 0.0, 0.0)
    i = min(int(gx), NX - 2)
    j = min(int(gz), NZ - 2)
    u, v = gx - i, gz - j

    def at(arr, a, b):
        return arr[(i + a) + NX * (j + b)]

    def thick(a, b):
        return max(at(FOG_TOP, a, b) - at(TERRAIN, a, b), 0.0)

    # The triangle containing (u, v) and its barycentric weights.
    if (i + j) % 2 == 0:  # diagonal (0,0)-(1,1)
        corners = [(0, 0), (1, 0), (1, 1)] if u >= v else [(0, 0), (1, 1), (0, 1)]
    else:  # diagonal (1,0)-(0,1)
        corners = [(0, 0), (1, 0), (0, 1)] if u + v <= 1 else [(1, 0), (1, 1), (0, 1)]
    (ax, az), (bx, bz), (cx, cz) = corners
    det = (bx - ax) * (cz - az) - (cx - ax) * (bz - az)
    wb = ((u - ax) * (cz - az) - (cx - ax) * (v - az)) / det
    wc = ((bx - ax) * (v - az) - (u - ax) * (bz - az)) / det
    wa = 1.0 - wb - wc
    bottom = wa * at(TERRAIN, ax, az) + wb * at(TERRAIN, bx, bz) + wc * at(TERRAIN, cx, cz)
    h = wa * thick(ax, az) + wb * thick(bx, bz) + wc * thick(cx, cz)
    top = bottom + h
    if y < bottom or y > top or h <= 0.0:
        return 0.0, (0.0, 0.0, 0.0)
    s = DENSITY * (top - y) / depth if depth > 0 else DENSITY * (top - y) / h
    s = min(s, 1.0)
    col, ext = transfer(s)
    return ext, col


def integrate(origin, direction, length, depth, steps):
    n = math.sqrt(sum(c * c for c in direction))
    d = [c / n for c in direction]
    h = length / steps
    T = 1.0
    C = [0.0, 0.0, 0.0]
    for k in range(steps):
        t = (k + 0.5) * h
        sigma, col = field(origin[0] + t * d[0], origin[1] + t * d[1], origin[2] + t * d[2], depth)
        if sigma > 0.0:
            a = 1.0 - math.exp(-sigma * h)
            for ch in range(3):
                C[ch] += T * a * col[ch]
            T *= 1.0 - a
    return C + [1.0 - T]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--steps', type=int, default=200000, help='midpoint steps per ray (and twice that for the estimate)')
    args = ap.parse_args()
    for depth in (0.0, 2.5):
        model = "paper's scalar" if depth == 0 else 'affine scalar, densityDepthWorld %.1f' % depth
        print('model: %s' % model)
        for r, (o, dvec, length) in enumerate(RAYS):
            a = integrate(o, dvec, length, depth, args.steps)
            b = integrate(o, dvec, length, depth, 2 * args.steps)
            est = max(abs(x - y) for x, y in zip(a, b))
            print('  ray %d  RGBA %.7f %.7f %.7f %.7f  (step-doubling estimate %.1e)' % (r, b[0], b[1], b[2], b[3], est))


if __name__ == '__main__':
    main()
