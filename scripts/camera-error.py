#!/usr/bin/env python3
"""Errors of a fitted OpenCV pinhole camera against known values.

Reads a fit's result.json and prints the errors docs/results.md quotes for
scenes/pinhole_calib.json: fx, fy, cx, cy (pixels), the rotation error
(degrees: the angle of R_fit^T R_true, the Rodrigues vectors turned into
matrices), the translation error (distance, and in % of the scene's size),
renders and wall seconds.

Usage: scripts/camera-error.py RUN/result.json [SCENE_SIZE=4]
The truth is the one of the command in docs/results.md; override it with
TRUTH='{"fx":..,"fy":..,"cx":..,"cy":..,"rotation":[..],"translation":[..]}'.
"""
import json
import math
import os
import sys

TRUTH = {
    "fx": 176.0,
    "fy": 172.0,
    "cx": 86.3,
    "cy": 54.2,
    "rotation": [-2.74624, -0.050617, 0.260152],
    "translation": [-0.049111, 0.274595, 3.855151],
}


def rodrigues(v):
    """The rotation matrix of a Rodrigues vector (OpenCV's convention)."""
    theta = math.sqrt(sum(x * x for x in v))
    if theta < 1e-15:
        return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    k = [x / theta for x in v]
    c, s = math.cos(theta), math.sin(theta)
    kx, ky, kz = k
    cross = [[0, -kz, ky], [kz, 0, -kx], [-ky, kx, 0]]
    return [
        [
            c * (i == j) + (1 - c) * k[i] * k[j] + s * cross[i][j]
            for j in range(3)
        ]
        for i in range(3)
    ]


def angle_between(a, b):
    """Degrees of the rotation R_a^T R_b."""
    trace = sum(a[k][i] * b[k][i] for i in range(3) for k in range(3))
    return math.degrees(math.acos(max(-1.0, min(1.0, (trace - 1) / 2))))


def main():
    result = json.load(open(sys.argv[1]))
    size = float(sys.argv[2]) if len(sys.argv) > 2 else 4.0
    truth = json.loads(os.environ["TRUTH"]) if "TRUTH" in os.environ else TRUTH
    p = {k.removeprefix("camera."): v for k, v in result["params"].items()}
    for key in ("fx", "fy", "cx", "cy"):
        print(f"{key}: {p[key]:.4f} (truth {truth[key]}), error {abs(p[key] - truth[key]):.4f} px")
    rot = angle_between(rodrigues(p["rotation"]), rodrigues(truth["rotation"]))
    print(f"rotation error: {rot:.4f} deg")
    d = math.dist(p["translation"], truth["translation"])
    print(f"translation: {[round(x, 6) for x in p['translation']]}, error {d:.5f} = {100 * d / size:.3f} % of {size:g}")
    dev = result["deviation"]
    dev = dev["average"] if isinstance(dev, dict) else dev
    print(f"deviation {dev:.5f} %, renders {result['evaluations']}, wall {result['wall_seconds']:.0f} s, stop: {result['stop_reason']}")


if __name__ == "__main__":
    main()
