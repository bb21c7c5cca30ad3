#!/usr/bin/env python3
"""A small scenefit renderer plug-in: Lambertian spheres and planes under
point and directional lights, hard shadows, one ray through each pixel
centre. Pure Python (no packages), written to show the plug-in protocol of
docs/plugins.md, not to be fast.

One-shot (scenefit runs it once per render):
    python3 lambert.py SCENE.json OUT.png
    scenefit fit ... --renderer 'cmd:python3 examples/plugins/lambert.py {scene} {output}'

Persistent (JSON lines on stdin/stdout):
    python3 lambert.py --worker
    scenefit fit ... --renderer 'worker:python3 examples/plugins/lambert.py --worker'

It reads: image, camera (perspective/orthographic), ambient, lights (point
with inverse_square or no falloff, directional), sphere and plane objects,
material color and diffuse. It refuses quads and boxes; it ignores
specular, reflection and transmission (a Lambertian renderer).
"""

import json
import math
import os
import struct
import sys
import zlib


class SceneError(Exception):
    pass


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    n = math.sqrt(dot(a, a))
    if n == 0.0:
        raise SceneError("zero-length vector")
    return (a[0] / n, a[1] / n, a[2] / n)


def hit(obj, o, d):
    """Distance along the ray to obj, or None."""
    if obj[0] == "sphere":
        _, c, r = obj
        oc = sub(o, c)
        b = dot(oc, d)
        disc = b * b - (dot(oc, oc) - r * r)
        if disc < 0.0:
            return None
        s = math.sqrt(disc)
        for t in (-b - s, -b + s):
            if t > 1e-6:
                return t
        return None
    _, p, n = obj
    den = dot(n, d)
    if abs(den) < 1e-12:
        return None
    t = dot(sub(p, o), n) / den
    return t if t > 1e-6 else None


def normal_at(obj, x):
    if obj[0] == "sphere":
        return norm(sub(x, obj[1]))
    return obj[2]


def srgb(v):
    v = min(max(v, 0.0), 1.0)
    s = 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1.0 / 2.4) - 0.055
    return int(s * 255.0 + 0.5)


def write_png(path, w, h, rows):
    raw = b"".join(b"\x00" + bytes(r) for r in rows)

    def chunk(kind, data):
        c = kind + data
        return struct.pack(">I", len(data)) + c + struct.pack(">I", zlib.crc32(c) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 1)) + chunk(b"IEND", b"")
    # a temporary name, then a rename: scenefit never reads half a file
    tmp = "%s.tmp%d" % (path, os.getpid())
    with open(tmp, "wb") as f:
        f.write(png)
    os.replace(tmp, path)


def render(scene, out):
    w, h = scene["image"]["width"], scene["image"]["height"]
    cam = scene["camera"]
    pos = tuple(cam["position"])
    fwd = norm(sub(tuple(cam["look_at"]), pos))
    right = norm(cross(fwd, tuple(cam.get("up", [0, 1, 0]))))
    up = cross(right, fwd)
    ortho = cam["type"] == "orthographic"
    half_h = cam.get("height", 1.0) / 2.0 if ortho else math.tan(math.radians(cam.get("fov_y_deg", 40.0)) / 2.0)
    half_w = half_h * w / h
    ambient = scene.get("ambient", [0, 0, 0])
    objs, albedo = [], []
    for o in scene["objects"]:
        sh, m = o["shape"], o["material"]
        if sh["type"] == "sphere":
            objs.append(("sphere", tuple(sh["center"]), sh["radius"]))
        elif sh["type"] == "plane":
            objs.append(("plane", tuple(sh["point"]), norm(tuple(sh["normal"]))))
        else:
            raise SceneError("object %s: shape %s is not supported by this plug-in" % (o["name"], sh["type"]))
        kd = m.get("diffuse", 1.0)
        albedo.append([kd * c for c in m["color"]])
    lights = []
    for l in scene["lights"]:
        power = [l["intensity"] * c for c in l.get("color", [1, 1, 1])]
        if l["type"] == "point":
            lights.append(("point", tuple(l["position"]), power, l.get("falloff", "inverse_square") == "inverse_square"))
        else:
            lights.append(("directional", norm(tuple(l["direction"])), power, False))
    rows = []
    for py in range(h):
        row = []
        sy = (1.0 - 2.0 * (py + 0.5) / h) * half_h
        for px in range(w):
            sx = (2.0 * (px + 0.5) / w - 1.0) * half_w
            if ortho:
                o = tuple(pos[k] + right[k] * sx + up[k] * sy for k in range(3))
                d = fwd
            else:
                o = pos
                d = norm(tuple(fwd[k] + right[k] * sx + up[k] * sy for k in range(3)))
            best, bi = None, -1
            for i, obj in enumerate(objs):
                t = hit(obj, o, d)
                if t is not None and (best is None or t < best):
                    best, bi = t, i
            if bi < 0:
                row += [0, 0, 0]
                continue
            x = tuple(o[k] + d[k] * best for k in range(3))
            n = normal_at(objs[bi], x)
            if dot(n, d) > 0.0:
                n = (-n[0], -n[1], -n[2])
            a = albedo[bi]
            col = [a[k] * ambient[k] for k in range(3)]
            for kind, at, power, inv_sq in lights:
                if kind == "point":
                    to = sub(at, x)
                    dist = math.sqrt(dot(to, to))
                    ldir = (to[0] / dist, to[1] / dist, to[2] / dist)
                else:
                    ldir, dist = at, float("inf")
                cos = dot(n, ldir)
                if cos <= 0.0:
                    continue
                start = tuple(x[k] + n[k] * 1e-6 for k in range(3))
                if any((t := hit(obj, start, ldir)) is not None and t < dist for obj in objs):
                    continue
                e = cos / (dist * dist) if inv_sq else cos
                for k in range(3):
                    col[k] += a[k] / math.pi * power[k] * e
            row += [srgb(c) for c in col]
        rows.append(row)
    write_png(out, w, h, rows)


def worker():
    send = sys.stdout
    send.write(json.dumps({"ready": True, "renderer": "lambert.py 1"}) + "\n")
    send.flush()
    for line in sys.stdin:
        if not line.strip():
            continue
        rid = None
        try:
            req = json.loads(line)
            rid = req.get("id")
            render(req["scene"], req["output"])
            answer = {"id": rid, "ok": True}
        except Exception as e:  # a bad scene fails this render, not the worker
            answer = {"id": rid, "ok": False, "error": "%s: %s" % (type(e).__name__, e)}
        send.write(json.dumps(answer) + "\n")
        send.flush()


def main(argv):
    if argv == ["--worker"]:
        worker()
        return 0
    if len(argv) != 2:
        sys.stderr.write(__doc__)
        return 2
    with open(argv[0]) as f:
        scene = json.load(f)
    try:
        render(scene, argv[1])
    except (SceneError, KeyError) as e:
        sys.stderr.write("lambert.py: %s\n" % e)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
