#!/usr/bin/env python3
"""The error of a colour map the diagnosis solved against the true texture.

    python3 scripts/texture-error.py DIAG/improved_scene.json OBJECT TRUTH.png

For every texel the map solved (a value other than 1), the mapped colour
(the map's value times the scene's `material.color`) against the truth
texture sampled bilinearly at the texel's centre, both linear (the truth
is an 8-bit sRGB PNG, the map a 16-bit linear PNG with its `range`), as
the mean absolute difference over the texels and channels. Texels with no
photograph behind them keep 1 and are not counted. Standard library only.
"""
import json
import os
import struct
import sys
import zlib


def read_png(path):
    """Width, height, channels and rows of integer samples (8 or 16 bits)."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, head = 8, b"", None
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            head = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    w, h, depth, ctype, _, _, interlace = head
    assert interlace == 0 and ctype in (0, 2, 6), path
    ch = {0: 1, 2: 3, 6: 4}[ctype]
    bpp = ch * depth // 8
    raw, stride, rows, prev = zlib.decompress(idat), w * bpp, [], bytearray(w * bpp)
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        prev = line
        if depth == 16:
            vals = [line[2 * i] << 8 | line[2 * i + 1] for i in range(w * ch)]
        else:
            vals = list(line)
        rows.append(vals)
    return w, h, ch, depth, rows


def srgb(v):
    return v / 12.92 if v <= 0.04045 else ((v + 0.055) / 1.055) ** 2.4


def main():
    scene_path, obj, truth_path = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    scene = json.load(open(scene_path))
    mat = scene["objects"][obj]["material"]
    ref = mat["color_map"]
    lo, hi = ref.get("range", [0.0, 1.0])
    w, h, ch, depth, rows = read_png(os.path.join(os.path.dirname(scene_path), ref["file"]))
    top = (1 << depth) - 1
    tw, th, tch, _, trows = read_png(truth_path)

    def truth(x, y, c):  # bilinear, repeat wrap, linear values
        x, y = x - 0.5, y - 0.5
        x0, y0 = int(x // 1), int(y // 1)
        fx, fy = x - x0, y - y0
        at = lambda i, j: srgb(trows[j % th][tch * (i % tw) + c] / 255.0)
        return ((1 - fx) * (1 - fy) * at(x0, y0) + fx * (1 - fy) * at(x0 + 1, y0)
                + (1 - fx) * fy * at(x0, y0 + 1) + fx * fy * at(x0 + 1, y0 + 1))

    err, count = 0.0, 0
    for j in range(h):
        for i in range(w):
            m = [lo + rows[j][ch * i + c] / top * (hi - lo) for c in range(3)]
            if all(abs(v - 1.0) < 1e-3 for v in m):
                continue
            x, y = (i + 0.5) / w * tw, (j + 0.5) / h * th
            err += sum(abs(m[c] * mat["color"][c] - truth(x, y, c)) for c in range(3)) / 3
            count += 1
    print(f"map {w}x{h}: {count} texels solved, mean absolute error {err / max(count, 1):.4f} (linear)")


if __name__ == "__main__":  # image-deviation.py imports read_png
    main()
