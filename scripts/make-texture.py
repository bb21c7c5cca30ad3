#!/usr/bin/env python3
"""Writes the example textures of scenes/textured/ with the standard
library alone (zlib; no image package): a colour map (a checker of two
tints under a soft diagonal band, 8-bit RGB PNG, sRGB-encoded) and a
specular map (vertical stripes of 1.0 and 0.25, 8-bit grey PNG, linear)
and a normal map (bumps.png: the tangent-space normals, OpenGL +Y up,
linear, of the height field h = 0.06 sin(2 pi u) sin(2 pi v), 8-bit RGB),
and sphere_bumps.png, a normal map made for a sphere (the slopes of a
height over the direction from its centre, by longitude and latitude),
which POV-Ray can draw on a sphere as well as the other renderers.
The patterns are made by this code; nothing is downloaded.

    python3 scripts/make-texture.py OUT_DIR [--size N]

scenes/textured/ holds `python3 scripts/make-texture.py scenes/textured`.
"""

import argparse
import math
import os
import struct
import zlib


def png(path, width, height, rows, channels):
    """An 8-bit PNG (colour type 2 RGB or 0 grey) of `rows` (lists of ints)."""
    def chunk(kind, data):
        c = struct.pack(">I", len(data)) + kind + data
        return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    kind = {3: 2, 1: 0}[channels]
    raw = b"".join(b"\x00" + bytes(r) for r in rows)
    data = (b"\x89PNG\r\n\x1a\n"
            + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, kind, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
    with open(path, "wb") as f:
        f.write(data)


def color_rows(n):
    rows = []
    for j in range(n):
        row = []
        for i in range(n):
            check = ((i * 8 // n) + (j * 8 // n)) % 2
            base = (230, 200, 120) if check else (90, 140, 200)
            band = 0.75 + 0.25 * math.cos(2 * math.pi * (i + j) / n)
            row += [int(round(c * band)) for c in base]
        rows.append(row)
    return rows


def specular_rows(n):
    return [[255 if (i * 6 // n) % 2 == 0 else 64 for i in range(n)] for _ in range(n)]


def normal_rows(n, a=0.06):
    """Texel (i, j): u = (i + 1/2)/n, v = 1 - (j + 1/2)/n (rows from the
    top); the normal (-dh/du, -dh/dv, 1) normalised, as 255 (n + 1)/2."""
    rows = []
    for j in range(n):
        row = []
        v = 1.0 - (j + 0.5) / n
        for i in range(n):
            u = (i + 0.5) / n
            hu = a * 2 * math.pi * math.cos(2 * math.pi * u) * math.sin(2 * math.pi * v)
            hv = a * 2 * math.pi * math.sin(2 * math.pi * u) * math.cos(2 * math.pi * v)
            k = math.sqrt(hu * hu + hv * hv + 1.0)
            row += [int(round(255 * (c / k * 0.5 + 0.5))) for c in (-hu, -hv, 1.0)]
        rows.append(row)
    return rows


def sphere_normal_rows(n, a=0.03):
    """A normal map made for a sphere, 2n x n: the slopes of the height
    h(d) = a (sin 6x cos 5y + cos(7z + 1) sin 4xy) over the direction d
    from its centre (per unit radius), texel (i, j) at longitude 2 pi u
    and latitude pi (v - 1/2), in the frame a sphere's map is read in:
    T east (along +u), B north (along +v)."""
    def h(x, y, z):
        return a * (math.sin(6 * x) * math.cos(5 * y) + math.cos(7 * z + 1) * math.sin(4 * x * y))
    rows, e = [], 1e-5
    for j in range(n):
        row = []
        lat = math.pi * (0.5 - (j + 0.5) / n)
        for i in range(2 * n):
            lon = 2 * math.pi * (i + 0.5) / (2 * n)
            d = (math.cos(lat) * math.cos(lon), math.sin(lat), -math.cos(lat) * math.sin(lon))
            g = []
            for k in range(3):
                p = [d[m] + (e if m == k else 0.0) for m in range(3)]
                q = [d[m] - (e if m == k else 0.0) for m in range(3)]
                g.append((h(*p) - h(*q)) / (2 * e))
            gd = sum(g[k] * d[k] for k in range(3))
            t = [g[k] - gd * d[k] for k in range(3)]
            east = (d[2] / math.cos(lat), 0.0, -d[0] / math.cos(lat))
            north = (d[1] * east[2], d[2] * east[0] - d[0] * east[2], -d[1] * east[0])
            ge = sum(t[k] * east[k] for k in range(3))
            gn = sum(t[k] * north[k] for k in range(3))
            k = math.sqrt(ge * ge + gn * gn + 1.0)
            row += [int(round(255 * (c / k * 0.5 + 0.5))) for c in (-ge, -gn, 1.0)]
        rows.append(row)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--size", type=int, default=64)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    png(os.path.join(a.out, "checker.png"), a.size, a.size, color_rows(a.size), 3)
    png(os.path.join(a.out, "stripes.png"), a.size, a.size, specular_rows(a.size), 1)
    png(os.path.join(a.out, "bumps.png"), a.size, a.size, normal_rows(a.size), 3)
    side = 2 * a.size
    png(os.path.join(a.out, "sphere_bumps.png"), 2 * side, side, sphere_normal_rows(side), 3)


if __name__ == "__main__":
    main()
