#!/usr/bin/env python3
"""Outside check of splatfx's procedural-gas reference (proceduralGasMedium +
renderVolumeExact), standard library only, no splatfx code linked.

The steam density is written out here from its definition (Ebert & Parent 1990
as procedural_gas.hpp states it, over the seeded 4D gradient noise); the
integral is a composite Simpson rule along each ray, refined until two
successive results agree to 1e-9. Reads the CSV `splatfx-bench gases
--validation` prints (x, y, alpha of rays along -z) and prints the largest
difference.

    splatfx-bench gases --validation > gas_case.csv
    python3 tools/validate/gas_reference.py gas_case.csv
"""
import csv
import math
import struct
import sys

M64 = (1 << 64) - 1


def permutation(seed):
    p = list(range(256))
    s = seed
    for i in range(255, 0, -1):
        s = (s + 0x9E3779B97F4A7C15) & M64
        z = s
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & M64
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & M64
        z = z ^ (z >> 31)
        j = z % (i + 1)
        p[i], p[j] = p[j], p[i]
    return p + p


def fade(t):
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


def grad(h, x, y, z, w):
    axis = (h >> 3) & 3
    a, b, c = [(y, z, w), (x, z, w), (x, y, w), (x, y, z)][axis]
    return (-a if h & 1 else a) + (-b if h & 2 else b) + (-c if h & 4 else c)


def noise(perm, x, y, z, w):
    fx, fy, fz, fw = math.floor(x), math.floor(y), math.floor(z), math.floor(w)
    X, Y, Z, W = int(fx) & 255, int(fy) & 255, int(fz) & 255, int(fw) & 255
    x, y, z, w = x - fx, y - fy, z - fz, w - fw
    u, v, s, t = fade(x), fade(y), fade(z), fade(w)

    def h(i, j, k, l):
        return perm[perm[perm[perm[X + i] + Y + j] + Z + k] + W + l]

    def lerp(a, b, f):
        return a + (b - a) * f

    acc = []
    for l in range(2):
        zs = []
        for k in range(2):
            ys = [lerp(grad(h(0, j, k, l), x, y - j, z - k, w - l), grad(h(1, j, k, l), x - 1, y - j, z - k, w - l), u) for j in range(2)]
            zs.append(lerp(ys[0], ys[1], v))
        acc.append(lerp(zs[0], zs[1], s))
    return lerp(acc[0], acc[1], t) * 0.5


def wrap(s):
    return s - 256.0 * math.floor(s / 256.0)


def turbulence(perm, p, octaves=4, frequency=1.0):
    total, scale = 0.0, 1.0
    for _ in range(octaves):
        q = [c * frequency / scale for c in p]
        total += abs(noise(perm, wrap(q[0]), wrap(q[1]), wrap(q[2]), 0.0)) * scale
        scale *= 0.5
    return total


def steam(perm, p, t):
    """GasSteamDesc defaults: source 0, radius 0.3, spread 1.5, height 2, rise 0.4/s,
    swirl period 6 s radius 0.3, opaque 1.6, power 1.5; frequency 1, 4 octaves."""
    h = p[1]
    if not (h >= 0.0) or h >= 2.0:
        return 0.0
    hn = h / 2.0
    radius = 0.3 * (1.0 + 1.5 * hn)
    radial = 1.0 - (p[0] ** 2 + p[2] ** 2) / (radius * radius)
    if radial <= 0.0:
        return 0.0
    theta = 2.0 * math.pi * ((t - 6.0 * math.floor(t / 6.0)) / 6.0)
    period = 256.0
    rise = 0.4 * t - period * math.floor(0.4 * t / period)
    q = (p[0] + 0.3 * math.cos(theta), p[1] - rise, p[2] + 0.3 * math.sin(theta))
    d = 1.6 * turbulence(perm, q) * radial * (1.0 - hn)
    return min(max(d, 0.0), 1.0) ** 1.5


def f32(v):
    """The nearest float: the SDK takes the world point as floats and returns a float density."""
    return struct.unpack('f', struct.pack('f', v))[0]


def optical_depth(perm, x, y, t, cell, z0, z1):
    def sigma(z):
        d = steam(perm, (f32(x), f32(y), f32(z)), t)
        d = f32(d)
        return 0.0 if d <= 0.0 else -math.log1p(-min(d, 1.0)) / cell if d < 1.0 else 24.0 * math.log(2.0) / cell

    def simpson(n):
        hstep = (z1 - z0) / n
        s = sigma(z0) + sigma(z1)
        for i in range(1, n):
            s += (4.0 if i % 2 else 2.0) * sigma(z0 + i * hstep)
        return s * hstep / 3.0

    n, prev = 512, None
    while True:
        cur = simpson(n)
        if prev is not None and abs(cur - prev) < 1e-9:
            return cur
        if n >= 1 << 16:
            return cur
        prev, n = cur, n * 2


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    perm = permutation(1)
    rows = [r for r in csv.reader(l for l in open(sys.argv[1]) if not l.startswith('#'))][1:]
    worst = 0.0
    for x, y, alpha in rows:
        tau = optical_depth(perm, float(x), float(y), 2.5, 0.125, -1.0625, 1.0625)
        mine = -math.expm1(-tau)
        worst = max(worst, abs(mine - float(alpha)))
        print(f"x {float(x):+.3f} y {float(y):.3f}: splatfx {float(alpha):.7f}  here {mine:.7f}  diff {mine - float(alpha):+.2e}")
    print(f"largest difference in alpha: {worst:.2e} over {len(rows)} rays")
    return 0


if __name__ == '__main__':
    sys.exit(main())
