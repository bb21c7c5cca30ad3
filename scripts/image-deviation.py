#!/usr/bin/env python3
"""The paper's deviation between two 8-bit images of the same size: per
channel 100 * mean |A - B| / 255, and their average (as `deviation` in
result.json; docs/usage.md). For comparing renders made through the CLI,
e.g. one scene drawn by two backends (scripts/backends-draw.sh).

    python3 scripts/image-deviation.py A.png B.png

Standard library only (the PNG reader of texture-error.py).
"""
import importlib.util
import os
import sys

here = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location("texture_error", os.path.join(here, "texture-error.py"))
texture_error = importlib.util.module_from_spec(spec)
spec.loader.exec_module(texture_error)


def channels(path):
    """Width, height, channels and rows of an 8-bit RGB(A) PNG."""
    w, h, ch, depth, rows = texture_error.read_png(path)
    if depth != 8 or ch < 3:
        sys.exit(f"{path}: expected an 8-bit RGB or RGBA PNG, got {depth}-bit with {ch} channels")
    return w, h, ch, rows


a_path, b_path = sys.argv[1], sys.argv[2]
wa, ha, cha, ra = channels(a_path)
wb, hb, chb, rb = channels(b_path)
if (wa, ha) != (wb, hb):
    sys.exit(f"{b_path}: expected {wa}x{ha} as {a_path}, got {wb}x{hb}")
sums = [0, 0, 0]
for y in range(ha):
    for x in range(wa):
        for c in range(3):
            sums[c] += abs(ra[y][cha * x + c] - rb[y][chb * x + c])
dev = [100.0 * s / (255.0 * wa * ha) for s in sums]
print(f"r {dev[0]:.3f} g {dev[1]:.3f} b {dev[2]:.3f} average {sum(dev) / 3:.3f} %")
