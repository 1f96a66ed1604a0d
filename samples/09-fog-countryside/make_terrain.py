#!/usr/bin/env python3
"""Writes terrain.off: a procedural rolling countryside (a height field) for
samples/09-fog-countryside. Pure Python, deterministic; run from this folder:
    python3 make_terrain.py
The paper's Fig. 6 uses a real elevation model; Debian's python3-matplotlib-data
(sample_data/jacksboro_fault_dem.npz) is not installed here, so the hills are
a sum of sines instead (heights 0 to about 7 world units over 80 x 80)."""
import math

N = 64          # vertices per side
HALF = 40.0     # the field spans [-HALF, HALF] on x and z

def height(x, z):
    h = 2.2 * math.sin(0.09 * x + 0.4) * math.cos(0.07 * z - 0.3)
    h += 1.3 * math.sin(0.21 * x + 0.13 * z + 1.1)
    h += 0.6 * math.cos(0.37 * z - 0.19 * x)
    return max(0.0, h + 2.6)

verts = []
for j in range(N):
    for i in range(N):
        x = -HALF + 2.0 * HALF * i / (N - 1)
        z = -HALF + 2.0 * HALF * j / (N - 1)
        verts.append((x, height(x, z), z))
faces = []
for j in range(N - 1):
    for i in range(N - 1):
        a = j * N + i
        b, c, d = a + 1, a + N, a + N + 1
        faces.append((a, c, b))  # counter-clockwise seen from +y
        faces.append((b, c, d))
with open("terrain.off", "w") as f:
    f.write("OFF\n%d %d 0\n" % (len(verts), len(faces)))
    for v in verts:
        f.write("%.4f %.4f %.4f\n" % v)
    for t in faces:
        f.write("3 %d %d %d\n" % t)
