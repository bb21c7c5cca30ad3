#!/usr/bin/env python3
"""Writes a mesh made by the project's own code (no downloaded data): an
icosahedron subdivided LEVEL times (20 * 4^LEVEL triangles), each vertex on
the unit sphere, optionally pushed in and out by a few smooth lobes (a
"blob", so that a fit sees a shape that is not a sphere), with vertex
normals from the face normals around each vertex. Binary little-endian
PLY by default, ASCII PLY or OBJ on request.

    python3 scripts/make-mesh.py LEVEL OUT [--blob] [--radius R] [--center X Y Z] [--ascii]

scenes/mesh_blob.ply is `python3 scripts/make-mesh.py 3 scenes/mesh_blob.ply --blob
--radius 0.5 --center 0 0.5 0`.
"""

import argparse
import math
import struct


def icosphere(level):
    t = (1.0 + 5 ** 0.5) / 2.0
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
             (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [unit(v) for v in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        mid = {}

        def middle(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                pa, pb = verts[a], verts[b]
                verts.append(unit(tuple((pa[k] + pb[k]) / 2 for k in range(3))))
                mid[key] = len(verts) - 1
            return mid[key]

        out = []
        for a, b, c in faces:
            ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
            out += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = out
    return verts, faces


def unit(v):
    n = math.sqrt(sum(x * x for x in v))
    return tuple(x / n for x in v)


def blob(v):
    """The radius of direction v: 1 plus three smooth lobes."""
    x, y, z = v
    return 1.0 + 0.18 * x * y + 0.12 * (z * z - x * x) + 0.1 * max(y, 0.0) ** 3


def normals(verts, faces):
    acc = [[0.0, 0.0, 0.0] for _ in verts]
    for f in faces:
        a, b, c = (verts[i] for i in f)
        u = [b[k] - a[k] for k in range(3)]
        w = [c[k] - a[k] for k in range(3)]
        n = (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])
        for i in f:
            for k in range(3):
                acc[i][k] += n[k]  # area-weighted
    return [unit(n) for n in acc]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("level", type=int)
    ap.add_argument("out")
    ap.add_argument("--blob", action="store_true")
    ap.add_argument("--radius", type=float, default=1.0)
    ap.add_argument("--center", type=float, nargs=3, default=(0.0, 0.0, 0.0))
    ap.add_argument("--ascii", action="store_true")
    a = ap.parse_args()
    verts, faces = icosphere(a.level)
    if a.blob:
        verts = [tuple(x * blob(v) for x in v) for v in verts]
    verts = [tuple(a.center[k] + a.radius * v[k] for k in range(3)) for v in verts]
    norms = normals(verts, faces)
    if a.out.endswith(".obj"):
        with open(a.out, "w") as f:
            f.write("# made by scripts/make-mesh.py\n")
            f.writelines("v %r %r %r\n" % v for v in verts)
            f.writelines("vn %r %r %r\n" % n for n in norms)
            f.writelines("f %d//%d %d//%d %d//%d\n" % (a + 1, a + 1, b + 1, b + 1, c + 1, c + 1)
                         for a, b, c in faces)
        return
    fmt = "ascii" if a.ascii else "binary_little_endian"
    head = ("ply\nformat %s 1.0\ncomment made by scenefit scripts/make-mesh.py\n"
            "element vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
            "property float nx\nproperty float ny\nproperty float nz\n"
            "element face %d\nproperty list uchar int vertex_indices\nend_header\n"
            % (fmt, len(verts), len(faces)))
    with open(a.out, "wb") as f:
        f.write(head.encode())
        for v, n in zip(verts, norms):
            if a.ascii:
                f.write(("%r %r %r %r %r %r\n" % (v + n)).encode())
            else:
                f.write(struct.pack("<6f", *v, *n))
        for face in faces:
            if a.ascii:
                f.write(("3 %d %d %d\n" % face).encode())
            else:
                f.write(struct.pack("<B3i", 3, *face))


if __name__ == "__main__":
    main()
