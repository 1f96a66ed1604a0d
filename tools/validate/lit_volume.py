#!/usr/bin/env python3
"""Independent check of splatfx's lit volume reference (issue 24, item 2).

Reads the small case `splatfx-bench lighting --validate FILE` writes (two voxels,
one point light, a Henyey-Greenstein phase, five pixels and the reference's
values for them) and integrates the same physics from scratch, in Python's
standard library only, without any splatfx code:

  * the Crawfis-Max kernel h(r) = (1 - x)^3 (1 + a x + b x^2), x = r^2 / 1.6^2,
    normalized to unit volume, and each voxel's extinction
    sigma_j(p) = ln 2 * tau_j / (F(0) * spacing) * h(|p - c_j| / spacing),
    tau_j = -log2(1 - opacity) (docs: reference.hpp, VolumeField);
  * the pixel ray through the pixel centre of a perspective look-at camera,
    from the near plane (OpenGL's conventions, row 0 at the top);
  * emission-absorption C = int T(t) sigma(t) colour * f(t) dt, T = exp(-int sigma),
    alpha = 1 - T, with f = albedo * I / d^2 * 4 pi * p_HG(mu) * exp(-depth to the light),
    mu between the light's travel and the direction to the eye;
  * every integral by composite 5-point Gauss-Legendre: the view ray on panels
    split at the kernels' support boundaries, the depth to the light on each
    kernel's chord, the view transmittance at each node by its own rule.

Run at N and 2N panels; the difference is the error estimate. Prints each
pixel, the largest difference to the reference and the estimate.

  python3 tools/validate/lit_volume.py lit_case.txt
"""
import math
import sys

R = 1.6
KA, KB = -1.5, 1.06103515625  # Crawfis & Max's criterion, as re-derived in docs/architecture.md
GX = (-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640)
GW = (0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665, 0.2369268850561891)


def raw(r):
    x = r * r / (R * R)
    if x >= 1.0:
        return 0.0
    t = 1.0 - x
    return t * t * t * (1.0 + KA * x + KB * x * x)


def gauss(f, a, b, panels):
    h = (b - a) / panels
    s = 0.0
    for p in range(panels):
        m = a + (p + 0.5) * h
        for x, w in zip(GX, GW):
            s += w * f(m + 0.5 * h * x)
    return s * 0.5 * h


NORM = 1.0 / (4.0 * math.pi * gauss(lambda r: r * r * raw(r), 0.0, R, 256))


def kernel(r):
    return NORM * raw(r)


F0 = 2.0 * gauss(lambda s: kernel(s), 0.0, R, 256)


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def mul(a, k):
    return (a[0] * k, a[1] * k, a[2] * k)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def norm(a):
    return math.sqrt(dot(a, a))


def unit(a):
    return mul(a, 1.0 / norm(a))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def read_case(path):
    case = {"voxels": [], "pixels": []}
    with open(path) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            key, *v = line.split()
            nums = [float(x) for x in v]
            if key == "voxel":
                case["voxels"].append(nums)
            elif key == "pixel":
                case["pixels"].append(nums)
            else:
                case[key] = nums
    return case


class Medium:
    def __init__(self, case):
        self.s = case["spacing"][0]
        self.vox = []
        for x, y, z, a in case["voxels"]:
            tau2 = -math.log2(1.0 - a)
            self.vox.append(((x, y, z), math.log(2.0) * tau2 / (F0 * self.s)))
        self.radius = R * self.s

    def sigma(self, p):
        return sum(k * kernel(norm(sub(p, c)) / self.s) for c, k in self.vox)

    def chords(self, o, d, t_max):
        """Each voxel's chord [t0, t1] of o + t d, t in [0, t_max], d unit."""
        out = []
        for c, k in self.vox:
            oc = sub(o, c)
            b = dot(oc, d)
            disc = b * b - (dot(oc, oc) - self.radius * self.radius)
            if disc <= 0.0:
                continue
            q = math.sqrt(disc)
            t0, t1 = max(-b - q, 0.0), min(-b + q, t_max)
            if t1 > t0:
                out.append((t0, t1, c, k))
        return out

    def depth(self, a, b, panels):
        """Optical depth along the segment a -> b, kernel by kernel over its chord."""
        d = sub(b, a)
        L = norm(d)
        if L == 0.0:
            return 0.0
        d = mul(d, 1.0 / L)
        tau = 0.0
        for t0, t1, c, k in self.chords(a, d, L):
            tau += k * gauss(lambda t: kernel(norm(sub(add(a, mul(d, t)), c)) / self.s), t0, t1, panels)
        return tau


def pixel(case, med, px, py, panels):
    eye, target, up = tuple(case["eye"]), tuple(case["target"]), tuple(case["up"])
    W, H = int(case["viewport"][0]), int(case["viewport"][1])
    fov, near = case["fovY"][0], case["near"][0]
    f = unit(sub(target, eye))
    r = unit(cross(f, up))
    u = cross(r, f)
    nx = (px + 0.5) / W * 2.0 - 1.0
    ny = (H - 1 - py + 0.5) / H * 2.0 - 1.0
    th = math.tan(0.5 * fov)
    d = unit(add(add(f, mul(r, nx * th * W / H)), mul(u, ny * th)))
    o = add(eye, mul(d, near / dot(d, f)))
    P = tuple(case["pointlight"][:3])
    I = case["pointlight"][3]
    g, albedo = case["hg"][0], case["albedo"][0]
    col = case["color"]

    def factor(p):
        fl = sub(p, P)
        dist = norm(fl)
        travel = mul(fl, 1.0 / dist)
        mu = dot(travel, unit(sub(eye, p)))
        phase = (1.0 - g * g) / (4.0 * math.pi * (1.0 + g * g - 2.0 * g * mu) ** 1.5)
        T = math.exp(-med.depth(p, P, 16))
        return albedo * I / (dist * dist) * 4.0 * math.pi * phase * T

    cs = med.chords(o, d, 1e9)
    knots = sorted(set([t for c in cs for t in c[:2]]))
    C, tau = 0.0, 0.0
    total = knots[-1] - knots[0] if knots else 0.0
    for a, b in zip(knots[:-1], knots[1:]):
        n = max(1, int(math.ceil(panels * (b - a) / total)))
        h = (b - a) / n
        for p in range(n):
            lo = a + p * h
            for x, w in zip(GX, GW):
                t = lo + 0.5 * h * (1.0 + x)
                pt = add(o, mul(d, t))
                # Transmittance at the node: the panel's start, then this node's own Gauss rule.
                tau_node = tau + gauss(lambda s: med.sigma(add(o, mul(d, s))), lo, t, 1)
                C += w * 0.5 * h * math.exp(-tau_node) * med.sigma(pt) * factor(pt)
            tau += gauss(lambda s: med.sigma(add(o, mul(d, s))), lo, lo + h, 1)
    alpha = 1.0 - math.exp(-tau)
    return [C * col[0], C * col[1], C * col[2], alpha]


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    case = read_case(sys.argv[1])
    med = Medium(case)
    worst, est = 0.0, 0.0
    for px, py, *ref in case["pixels"]:
        a = pixel(case, med, px, py, 200)
        b = pixel(case, med, px, py, 400)
        e = max(abs(x - y) for x, y in zip(a, b))
        d = max(abs(x - y) for x, y in zip(b, ref))
        est, worst = max(est, e), max(worst, d)
        print("pixel (%d, %d): python %s  splatfx %s  |diff| %.2e (python's own estimate %.1e)"
              % (px, py, " ".join("%.9f" % v for v in b), " ".join("%.9f" % v for v in ref), d, e))
    print("largest difference %.2e over %d pixels x RGBA; python's error estimate %.1e; the reference's %.1e"
          % (worst, len(case["pixels"]), est, case["reference_error_estimate"][0]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
