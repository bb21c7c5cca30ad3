#!/usr/bin/env python3
"""What a finite-difference step does to an 8-bit image, per free coordinate.

For each coordinate of a scene's "free" list, renders the scene at a point
(the scene's values, overridden by --set) and at the point moved by +h and
-h of the coordinate's range, for h from 1e-4 to 3e-2 (the unit steps the
local phase uses, src/optimize/lm.rs), and prints: how many 8-bit values
changed (n), their mean absolute change in levels (mean, the statistic
lm::adapt_step steers by), the column's L1 norm per unit step (|J|1, which
should not depend on h where the difference is a derivative), and the
cosine between the forward and the backward column (agree: 1 when the
two one-sided differences see the same slope value by value).

Usage:
  scripts/difference-steps.py SCENE [--set PARAM=JSON ...]
Env: SCENEFIT (binary; default target/release/scenefit), BLUR (a box
blur's radius in pixels applied to every image before the differences,
default 0: what a coarse-to-fine pyramid's finer levels would see).
Pure Python (no numpy): renders BMPs through the CLI into a temporary
directory.
"""
import json
import os
import struct
import subprocess
import sys
import tempfile

STEPS = [1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2]


def render(binary, scene, values, out):
    args = [binary, "render", scene, "-o", out]
    for key, value in values.items():
        args += ["--set", f"{key}={json.dumps(value)}"]
    subprocess.run(args, check=True, capture_output=True)
    data = open(out, "rb").read()
    offset = struct.unpack_from("<I", data, 10)[0]
    width, height = struct.unpack_from("<ii", data, 18)
    row = (width * 3 + 3) & ~3
    values = [data[offset + y * row + i] for y in range(abs(height)) for i in range(width * 3)]
    return blur(values, width, abs(height), int(os.environ.get("BLUR", "0")))


def blur(values, width, height, radius):
    """A separable box blur of each channel, clamped at the borders."""
    if radius == 0:
        return values
    at = lambda v, x, y, c: v[(y * width + x) * 3 + c]
    out = list(values)
    for axis in (0, 1):
        src, out = out, [0.0] * len(values)
        for y in range(height):
            for x in range(width):
                for c in range(3):
                    taps = [
                        at(src, min(max(x + d, 0), width - 1), y, c) if axis == 0
                        else at(src, x, min(max(y + d, 0), height - 1), c)
                        for d in range(-radius, radius + 1)
                    ]
                    out[(y * width + x) * 3 + c] = sum(taps) / len(taps)
    return out


def coordinates(scene):
    """(param, index or None, span) per free coordinate."""
    for free in json.load(open(scene))["free"]:
        lo, hi = free["min"], free["max"]
        if isinstance(lo, list):
            for i, (a, b) in enumerate(zip(lo, hi)):
                yield free["param"], i, b - a
        else:
            yield free["param"], None, hi - lo


def current(scene, param):
    """A parameter's value in the scene file (dotted path, named lists)."""
    node = json.load(open(scene))
    for part in param.split("."):
        if isinstance(node, list):
            node = next(x for x in node if x.get("name") == part)
        else:
            node = node[part]
    return node


def main():
    binary = os.environ.get("SCENEFIT", "target/release/scenefit")
    scene, rest = sys.argv[1], sys.argv[2:]
    point = {}
    for i, arg in enumerate(rest):
        if arg == "--set":
            key, value = rest[i + 1].split("=", 1)
            point[key] = json.loads(value)
    coords = list(coordinates(scene))
    for param, _, _ in coords:
        point.setdefault(param, current(scene, param))
    tmp = tempfile.mkdtemp(prefix="difference-steps-")
    base = render(binary, scene, point, f"{tmp}/base.bmp")
    for param, index, span in coords:
        cells = [param + ("" if index is None else f"[{index}]")]
        for h in STEPS:
            columns = []
            for sign in (1, -1):
                moved = dict(point)
                if index is None:
                    moved[param] = point[param] + sign * h * span
                else:
                    moved[param] = list(point[param])
                    moved[param][index] += sign * h * span
                image = render(binary, scene, moved, f"{tmp}/moved.bmp")
                columns.append([(a - b) * sign for a, b in zip(image, base)])
            forward, backward = columns
            # A blurred difference is rarely exactly 0: count (and average)
            # the values that moved by half a level or more.
            moved_values = [abs(d) for d in forward if abs(d) >= 0.5]
            n = len(moved_values)
            total = sum(abs(d) for d in forward)
            dot = sum(a * b for a, b in zip(forward, backward))
            norm = (sum(a * a for a in forward) * sum(b * b for b in backward)) ** 0.5
            cells.append(
                f"h={h:g}: n={n} mean={sum(moved_values) / max(n, 1):.1f} "
                f"|J|1={total / h:.3g} agree={dot / norm if norm else 0:.2f}"
            )
        print(" | ".join(cells), flush=True)


if __name__ == "__main__":
    main()
