#!/usr/bin/env python3
"""Outside check of splatfx's particle flight (ParticleEmitter::flightPosition,
particles.hpp), standard library only, no splatfx code linked.

The flight is dv/dt = a + k (w - v), dx/dt = v from (x0, v0). Here it is
integrated numerically by the classical Runge-Kutta method with step halving
until two successive results agree to 1e-11, and compared with the closed form
splatfx prints. Reads the CSV `splatfx-bench particles --validation` prints and
prints the largest difference.

    splatfx-bench particles --validation > flight_case.csv
    python3 tools/validate/particle_flight.py flight_case.csv
"""
import csv
import sys


def rk4(k, a, w, x0, v0, age, steps):
    h = age / steps
    x, v = list(x0), list(v0)

    def f(v):
        return [a[i] + k * (w[i] - v[i]) for i in range(3)]

    for _ in range(steps):
        k1v, k1x = f(v), v
        v2 = [v[i] + 0.5 * h * k1v[i] for i in range(3)]
        k2v, k2x = f(v2), v2
        v3 = [v[i] + 0.5 * h * k2v[i] for i in range(3)]
        k3v, k3x = f(v3), v3
        v4 = [v[i] + h * k3v[i] for i in range(3)]
        k4v, k4x = f(v4), v4
        x = [x[i] + h / 6.0 * (k1x[i] + 2 * k2x[i] + 2 * k3x[i] + k4x[i]) for i in range(3)]
        v = [v[i] + h / 6.0 * (k1v[i] + 2 * k2v[i] + 2 * k3v[i] + k4v[i]) for i in range(3)]
    return x


def integrate(k, a, w, x0, v0, age):
    steps = 16
    prev = rk4(k, a, w, x0, v0, age, steps)
    while True:
        steps *= 2
        cur = rk4(k, a, w, x0, v0, age, steps)
        if max(abs(cur[i] - prev[i]) for i in range(3)) < 1e-11 or steps > 1 << 16:
            return cur
        prev = cur


def main(path):
    worst = 0.0
    rows = 0
    with open(path) as f:
        for r in csv.DictReader(f):
            g = {key: float(val) for key, val in r.items()}
            want = integrate(g["k"], [g["ax"], g["ay"], g["az"]], [g["wx"], g["wy"], g["wz"]], [g["x0x"], g["x0y"], g["x0z"]],
                             [g["v0x"], g["v0y"], g["v0z"]], g["age"])
            got = [g["x"], g["y"], g["z"]]
            worst = max(worst, max(abs(got[i] - want[i]) for i in range(3)))
            rows += 1
    print(f"{rows} flights, largest |closed form - RK4| = {worst:.3e} world units")
    return 0 if worst < 1e-8 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
