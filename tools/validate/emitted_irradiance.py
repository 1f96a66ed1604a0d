#!/usr/bin/env python3
"""Independent check of splatfx's emitted irradiance reference (issue 27, item 3).

Reads the small case `splatfx-bench emitted --validate FILE` writes (two
plain splats of a truncated Gaussian kernel, one partly behind the other, a
few surface points with normals, and the reference's irradiance at each)
and integrates the same physics from scratch, in Python's standard library
only, without any splatfx code. Where the reference renders a cube of
pixels around the point and sums radiance x cosine x solid angle, this
integrates over the emitters' own surfaces:

  * the kernel h(r) = exp(-r^2 / (2 sigma^2)) truncated at the radius R
    (kernel units), its footprint F(r) = integral of h along a chord,
    = exp(-r^2 / (2 sigma^2)) sigma sqrt(2 pi) erf(sqrt(R^2 - r^2) / (sigma sqrt 2));
  * a splat (centre c, half-axes U, V reaching R) at a point x of its plane
    with (u, v) = its coordinates on U, V has opacity
    alpha = 1 - 2^(-density F(R |(u, v)|) / F(0)) and radiance colour x alpha;
  * E(p, n) = sum over splats of the integral over the splat's disc of
    radiance x T x max(n.w, 0) x |m.w| / |x - p|^2 dA, w the unit direction
    from p to x, m the splat's normal, T the transmittance 1 - alpha of
    every other splat whose plane the segment p-x crosses;
  * each disc integral in polar coordinates: composite 5-point
    Gauss-Legendre in the radius, the midpoint rule in the angle (periodic).

Run at N and 2N panels; the difference is the error estimate. Prints each
point, the reference's value, this value, and the largest relative difference.

  python3 tools/validate/emitted_irradiance.py emitted_case.txt
"""
import math
import sys

GX = (-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640)
GW = (0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665, 0.2369268850561891)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


class Splat:
    def __init__(self, fields, sigma, radius):
        v = [float(x) for x in fields]
        self.c, self.u, self.v = tuple(v[0:3]), tuple(v[3:6]), tuple(v[6:9])
        self.density, self.colour = v[9], tuple(v[10:13])
        self.sigma, self.R = sigma, radius
        self.m = cross(self.u, self.v)
        self.a = math.sqrt(dot(self.u, self.u))  # round splats: |U| = |V|, U perpendicular to V

    def footprint(self, r):
        if r >= self.R:
            return 0.0
        s = self.sigma
        return math.exp(-r * r / (2 * s * s)) * s * math.sqrt(2 * math.pi) * math.erf(math.sqrt(self.R * self.R - r * r) / (s * math.sqrt(2)))

    def alpha_at(self, x):
        d = sub(x, self.c)
        u, v = dot(d, self.u) / dot(self.u, self.u), dot(d, self.v) / dot(self.v, self.v)
        q = math.hypot(u, v)
        if q >= 1.0:
            return 0.0
        return 1.0 - 2.0 ** (-self.density * self.footprint(self.R * q) / self.footprint(0.0))

    def crossing(self, p, x):
        """Alpha where the segment p -> x crosses this splat's plane (0 if it does not)."""
        w = sub(x, p)
        den = dot(self.m, w)
        if abs(den) < 1e-300:
            return 0.0
        t = dot(self.m, sub(self.c, p)) / den
        if not (0.0 < t < 1.0):
            return 0.0
        return self.alpha_at((p[0] + t * w[0], p[1] + t * w[1], p[2] + t * w[2]))


def irradiance(splats, p, n, panels):
    total = [0.0, 0.0, 0.0]
    for s in splats:
        eu = tuple(x / s.a for x in s.u)
        ev = tuple(x / s.a for x in s.v)
        mn = math.sqrt(dot(s.m, s.m))
        m = tuple(x / mn for x in s.m)
        angles = 8 * panels
        acc = 0.0
        for i in range(panels):  # radius in [0, a]
            r0, r1 = s.a * i / panels, s.a * (i + 1) / panels
            for gx, gw in zip(GX, GW):
                r = 0.5 * (r0 + r1) + 0.5 * (r1 - r0) * gx
                wr = 0.5 * (r1 - r0) * gw * r
                for k in range(angles):
                    phi = 2 * math.pi * (k + 0.5) / angles
                    x = tuple(s.c[j] + r * (math.cos(phi) * eu[j] + math.sin(phi) * ev[j]) for j in range(3))
                    d = sub(x, p)
                    d2 = dot(d, d)
                    dl = math.sqrt(d2)
                    cos_n = dot(n, d) / dl
                    if cos_n <= 0.0:
                        continue
                    t = 1.0
                    for o in splats:
                        if o is not s:
                            t *= 1.0 - o.crossing(p, x)
                    acc += wr * (2 * math.pi / angles) * s.alpha_at(x) * t * cos_n * abs(dot(m, d)) / (dl * d2)
        for j in range(3):
            total[j] += s.colour[j] * acc
    return total


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    splats, points = [], []
    sigma = radius = None
    for line in open(sys.argv[1]):
        f = line.split()
        if not f or f[0].startswith('#'):
            continue
        if f[0] == 'kernel':
            sigma, radius = float(f[1]), float(f[2])
        elif f[0] == 'splat':
            splats.append(Splat(f[1:], sigma, radius))
        elif f[0] == 'point':
            v = [float(x) for x in f[1:]]
            points.append((tuple(v[0:3]), tuple(v[3:6]), tuple(v[6:9]), v[9]))
    worst = est = 0.0
    for p, n, ref, ref_est in points:
        nl = math.sqrt(dot(n, n))
        n = tuple(x / nl for x in n)
        coarse = irradiance(splats, p, n, 12)
        fine = irradiance(splats, p, n, 24)
        scale = max(fine)
        for j in range(3):
            worst = max(worst, abs(fine[j] - ref[j]) / scale)
            est = max(est, abs(fine[j] - coarse[j]) / scale)
        print('point (%.3f %.3f %.3f) reference %s (est %.2g) python %s' % (
            p[0], p[1], p[2], ' '.join('%.6g' % x for x in ref), ref_est, ' '.join('%.6g' % x for x in fine)))
    print('largest difference %.3g of the point\'s brightest channel; python error estimate %.2g' % (worst, est))


if __name__ == '__main__':
    main()
