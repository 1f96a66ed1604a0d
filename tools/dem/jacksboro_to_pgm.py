#!/usr/bin/env python3
"""Converts matplotlib's Jacksboro fault elevation model into the 16-bit PGM
heightmap committed as samples/22-fog-jacksboro/data/jacksboro_dem.pgm.

Source: Debian's python-matplotlib-data (not a build dependency; fetch it once):
    cd /tmp && apt-get download python-matplotlib-data && dpkg-deb -x python-matplotlib-data_*.deb mpl
    python3 tools/dem/jacksboro_to_pgm.py /tmp/mpl/usr/share/matplotlib/mpl-data/sample_data/jacksboro_fault_dem.npz \
        samples/22-fog-jacksboro/data/jacksboro_dem.pgm

The .npz holds `elevation` (344 x 403 int16, metres, row 0 = north), the grid
step `dx`, `dy` (degrees, 3 arc-seconds) and the corners. The output is each
2 x 2 block's mean rounded to whole metres (171 x 201 samples, 6 arc-seconds,
about 185 m north-south and 150 m east-west; the southernmost block row dropped), stored as binary PGM (P5,
maxval 65535, big-endian 16-bit, row 0 = north), one value = one metre.
Pure Python (zipfile + struct: no numpy), deterministic.
"""
import ast
import struct
import sys
import zipfile


def read_npy(z, name):
    b = z.read(name)
    if b[:6] != b"\x93NUMPY":
        raise SystemExit(name + ": not an .npy array")
    major = b[6]
    hl = struct.unpack("<H", b[8:10])[0] if major == 1 else struct.unpack("<I", b[8:12])[0]
    start = (10 if major == 1 else 12) + hl
    header = ast.literal_eval(b[start - hl:start].decode("latin1"))  # a dict literal (numpy's format)
    return header, b[start:]


def main():
    if len(sys.argv) != 3:
        raise SystemExit("usage: jacksboro_to_pgm.py jacksboro_fault_dem.npz out.pgm")
    z = zipfile.ZipFile(sys.argv[1])
    header, data = read_npy(z, "elevation.npy")
    if header["descr"] != "<i2" or header["fortran_order"]:
        raise SystemExit("unexpected elevation layout: %r" % (header,))
    rows, cols = header["shape"]
    v = struct.unpack("<%dh" % (rows * cols), data[: rows * cols * 2])
    # 172 x 201 blocks; the last (southern) block row is dropped so the grid has
    # 170 x 200 cells, which steps of 2, 5 and 10 divide (a ground-fog "step").
    orows, ocols = rows // 2 - 1, cols // 2
    out = []
    for r in range(orows):
        for c in range(ocols):
            s = v[(2 * r) * cols + 2 * c] + v[(2 * r) * cols + 2 * c + 1] + v[(2 * r + 1) * cols + 2 * c] + v[(2 * r + 1) * cols + 2 * c + 1]
            m = (s + 2) // 4  # round half up, integers only
            if not 0 <= m <= 65535:
                raise SystemExit("elevation %d outside 16 bits" % m)
            out.append(m)
    with open(sys.argv[2], "wb") as f:
        f.write(b"P5\n# Jacksboro fault DEM (matplotlib sample_data), metres, 2x2 means; tools/dem/jacksboro_to_pgm.py\n")
        f.write(b"%d %d\n65535\n" % (ocols, orows))
        f.write(struct.pack(">%dH" % len(out), *out))
    print("wrote %s: %d x %d, %d..%d m" % (sys.argv[2], ocols, orows, min(out), max(out)))


if __name__ == "__main__":
    main()
