"""A scenefit-scene/1 scene as a renderer-neutral description, shared by the
Blender worker (blender_scripts/worker.py) and the Mitsuba worker
(workers/mitsuba_worker.py), so that a shape, a light or a material field is
read and checked once; each worker keeps only what its renderer builds from
the description. scenefit writes this module beside each worker, next to
jsonlines.py (the Blender worker also finds it in ../workers).

``describe(scene)`` returns plain Python values, in the scene's own frame
(y up, metres), the numbers as the scene gives them (no renderer's
conversion applied; directions and normals not normalised, so that each
worker keeps its own arithmetic):

- ``width``, ``height``, ``samples``, ``indirect``, ``ambient``;
- ``camera``: ``type``, ``position``, ``look_at``, ``up`` and ``fov_y``
  (perspective, degrees) or ``height`` (orthographic); or, for ``pinhole``,
  ``fx``, ``fy``, ``cx``, ``cy`` (pixels), ``to_world`` (3x3 rows: the
  OpenCV camera's x right, y down, z forward axes as columns) and
  ``centre`` (see ``pinhole``);
- ``lights``: ``name``, ``type`` (point or directional), ``color``,
  ``intensity``, ``radius``, and ``position`` and ``power`` (the falloff
  exponent: 1/d^power) or ``direction``;
- ``objects``: ``name``, ``shape`` (``type`` and its fields in world space:
  sphere ``center``, ``radius``; plane ``point``, ``normal``; quad
  ``corner``, ``edge_u``, ``edge_v``; box ``min``, ``max``; mesh ``file``,
  an absolute path to a PLY or OBJ file scenefit has read and checked) and
  ``material``: the project's convention values (docs/renderers.md, "One
  material convention") and its ``kind``: lambertian (diffuse only), phong
  (the built-in tracer's lobes, or any material with texture maps) or
  principled (transmitting: glass); ``maps``: each texture map present
  (``texture_map``), ``n2_own``: whether ``shininess2`` is the material's
  own (else it follows ``shininess`` and a shininess map).
"""

import math

import jsonlines


class SceneError(jsonlines.RequestError):
    """A scene a worker cannot build (answered as ok:false)."""


# ---------------------------------------------------------------- checked values
def num(v, where):
    if isinstance(v, bool):
        raise SceneError("%s: expected a number, got %r" % (where, v))
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise SceneError("%s: expected a number, got %r" % (where, v))
    if not math.isfinite(x):
        raise SceneError("%s: not finite: %r" % (where, v))
    return x


def vec3(v, where):
    if not isinstance(v, (list, tuple)) or len(v) != 3 or any(isinstance(x, bool) for x in v):
        raise SceneError("%s: expected a list of 3 numbers, got %r" % (where, v))
    try:
        out = tuple(float(x) for x in v)
    except (TypeError, ValueError):
        raise SceneError("%s: expected a list of 3 numbers, got %r" % (where, v))
    if not all(math.isfinite(x) for x in out):
        raise SceneError("%s: not finite: %r" % (where, v))
    return out


def obj(d, key, where, required=True):
    """The object d[key] ({} when absent and not required)."""
    v = d.get(key)
    if v is None and not required:
        return {}
    if not isinstance(v, dict):
        raise SceneError("%s.%s: missing or not an object" % (where, key))
    return v


def count(d, key, where, default):
    v = d.get(key, default)
    if not isinstance(v, int) or isinstance(v, bool) or v <= 0:
        raise SceneError("%s.%s: must be a positive integer, got %r" % (where, key, v))
    return v


def named_entries(scene, key, singular):
    """(name, "key.name", entry) for each entry of the scene's list `key`;
    an entry without a name is called singular + its index."""
    entries = scene.get(key, []) or []
    if not isinstance(entries, list):
        raise SceneError("scene.%s: expected a list" % key)
    for i, entry in enumerate(entries):
        if not isinstance(entry, dict):
            raise SceneError("%s[%d]: expected an object" % (key, i))
        name = str(entry.get("name", "%s%d" % (singular, i)))
        yield name, "%s.%s" % (key, name), entry


# ---------------------------------------------------------------- small vector math
def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def mul(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    return math.sqrt(dot(a, a))


def normalize(a, where):
    n = norm(a)
    if n == 0.0:
        raise SceneError("%s: zero-length vector" % where)
    return mul(a, 1.0 / n)


# ---------------------------------------------------------------- the parts
def roughness(n):
    """The microfacet roughness both workers give a Blinn-Phong exponent n
    (docs/renderers.md, "Shininess, roughness, specular level")."""
    return (2.0 / (n + 2.0)) ** 0.25


def material(m, where):
    """The convention values of a material, checked."""
    if m is None:
        m = {}
    if not isinstance(m, dict):
        raise SceneError("%s: expected an object" % where)
    if "color" not in m:
        raise SceneError("%s.color: missing" % where)
    color = vec3(m["color"], where + ".color")
    kd = num(m.get("diffuse", 1.0), where + ".diffuse")
    v = {"color": color, "kd": kd, "albedo": (kd * color[0], kd * color[1], kd * color[2])}
    for key, field, default in (("ks", "specular", 0.0), ("n", "shininess", 10.0),
                                ("kr", "reflection", 0.0), ("kt", "transmission", 0.0),
                                ("ior", "ior", 1.5), ("ks2", "specular2", 0.0),
                                ("f0", "fresnel", 1.0)):
        v[key] = num(m.get(field, default), "%s.%s" % (where, field))
    v["n2"] = num(m.get("shininess2", v["n"]), where + ".shininess2")
    v["n2_own"] = "shininess2" in m
    v["maps"] = {k: texture_map(m[k], k, "%s.%s" % (where, k)) for k in MAP_KEYS if m.get(k) is not None}
    if v["kt"] != 0.0:
        v["kind"] = "principled"
    elif v["ks"] == 0.0 and v["ks2"] == 0.0 and v["kr"] == 0.0 and not v["maps"]:
        v["kind"] = "lambertian"
        return v
    else:
        v["kind"] = "phong"
    if v["kind"] == "phong" and (v["n"] < 0.0 or v["n2"] < 0.0):
        raise SceneError("%s.shininess: must be >= 0, got %r" % (where, min(v["n"], v["n2"])))
    if v["kind"] == "phong" and not 0.0 < v["f0"] <= 1.0:
        raise SceneError("%s.fresnel: must be in (0, 1], got %r" % (where, v["f0"]))
    if v["kind"] == "principled" and v["n"] < 0.0:
        raise SceneError("%s.shininess: must be >= 0, got %r" % (where, v["n"]))
    if v["kind"] == "principled" and v["ior"] <= 0.0:
        raise SceneError("%s.ior: must be > 0, got %r" % (where, v["ior"]))
    return v


# The texture maps of a material (docs/scene-format.md, "Textures").
MAP_KEYS = ("color_map", "specular_map", "shininess_map", "normal_map")


def texture_map(t, key, where):
    """A map's file and settings, its defaults resolved as scenefit does:
    ``file``, ``encoding`` (srgb for a colour map other than OpenEXR,
    linear otherwise), ``scale`` (u, v) and ``range`` (lo, hi)."""
    if isinstance(t, str):
        t = {"file": t}
    if not isinstance(t, dict):
        raise SceneError("%s: expected a path or an object" % where)
    f = path(t.get("file"), where + ".file")
    enc = t.get("encoding")
    if enc is None:
        enc = "srgb" if key == "color_map" and not f.lower().endswith(".exr") else "linear"
    if enc not in ("srgb", "linear"):
        raise SceneError("%s.encoding: expected srgb or linear, got %r" % (where, enc))

    def pair(k, default):
        v = t.get(k, default)
        if not isinstance(v, (list, tuple)) or len(v) != 2:
            raise SceneError("%s.%s: expected two numbers, got %r" % (where, k, v))
        return (num(v[0], where + "." + k), num(v[1], where + "." + k))
    return {"file": f, "encoding": enc, "scale": pair("scale", [1, 1]), "range": pair("range", [0, 1])}


def plane_axes(n):
    """A plane's texture axes (e_u, e_v) for its normal n: as
    src/scene/texture/uv.rs (e_u = unit y x n, or the unit part of x
    across n when |n_y| > 0.999; e_v = n x e_u)."""
    n = normalize(n, "plane normal")
    if abs(n[1]) > 0.999:
        eu = normalize(sub((1.0, 0.0, 0.0), mul(n, n[0])), "plane e_u")
    else:
        eu = normalize(cross((0.0, 1.0, 0.0), n), "plane e_u")
    return eu, cross(n, eu)


def falloff_power(L, where):
    """A point light's falloff exponent: `falloff_power`, else 2
    (inverse_square) or 0 (none)."""
    falloff = L.get("falloff", "inverse_square")
    if falloff not in ("none", "inverse_square"):
        raise SceneError("%s.falloff: unknown %r (inverse_square or none)" % (where, falloff))
    if "falloff_power" in L:
        return num(L["falloff_power"], where + ".falloff_power")
    return 0.0 if falloff == "none" else 2.0


def light(name, where, L):
    out = {"name": name, "type": L.get("type", "point"),
           "color": vec3(L.get("color", [1, 1, 1]), where + ".color"),
           "intensity": num(L.get("intensity", 1.0), where + ".intensity"),
           "radius": num(L.get("radius", 0.0), where + ".radius")}
    if out["intensity"] < 0.0:
        raise SceneError("%s.intensity: must be >= 0" % where)
    if out["radius"] < 0.0:
        raise SceneError("%s.radius: must be >= 0" % where)
    if out["type"] == "point":
        out["position"] = vec3(L.get("position"), where + ".position")
        out["power"] = falloff_power(L, where)
    elif out["type"] == "directional":
        out["direction"] = vec3(L.get("direction"), where + ".direction")
        normalize(out["direction"], where + ".direction")
        if out["radius"] >= math.pi / 2:
            raise SceneError("%s.radius: must be below pi/2 for a directional light" % where)
    else:
        raise SceneError("%s.type: unknown %r (point or directional)" % (where, out["type"]))
    return out


# The fields of each shape: (name, kind) with kind "point" or "number".
SHAPES = {
    "sphere": (("center", "point"), ("radius", "number")),
    "plane": (("point", "point"), ("normal", "point")),
    "quad": (("corner", "point"), ("edge_u", "point"), ("edge_v", "point")),
    "box": (("min", "point"), ("max", "point")),
    "mesh": (("file", "path"),),
}


def path(v, where):
    """A file's path as scenefit writes it (absolute, the file already
    read and checked by scenefit)."""
    if not isinstance(v, str) or not v:
        raise SceneError("%s: expected a file's path, got %r" % (where, v))
    return v


def shape(sh, where):
    """A shape's type and fields, checked: the one place a new shape's
    fields are read."""
    stype = sh.get("type")
    if stype not in SHAPES:
        raise SceneError("%s.type: unknown %r (%s)" % (where, stype, ", ".join(SHAPES)))
    out = {"type": stype}
    for field, kind in SHAPES[stype]:
        read = {"point": vec3, "number": num, "path": path}[kind]
        out[field] = read(sh.get(field), "%s.%s" % (where, field))
    if stype == "sphere" and out["radius"] <= 0.0:
        raise SceneError("%s.radius: must be > 0" % where)
    if stype == "plane":
        normalize(out["normal"], where + ".normal")
    if stype == "quad" and norm(cross(out["edge_u"], out["edge_v"])) < 1e-12:
        raise SceneError("%s: edge_u and edge_v are parallel or zero" % where)
    if stype == "box" and not all(out["max"][k] > out["min"][k] for k in range(3)):
        raise SceneError("%s: max must exceed min on every axis" % where)
    return out


def rotation_xyz(deg):
    """Rows of Rz Ry Rx for angles in degrees: about world x first."""
    cx, cy, cz = (math.cos(math.radians(a)) for a in deg)
    sx, sy, sz = (math.sin(math.radians(a)) for a in deg)
    rx = ((1, 0, 0), (0, cx, -sx), (0, sx, cx))
    ry = ((cy, 0, sy), (0, 1, 0), (-sy, 0, cy))
    rz = ((cz, -sz, 0), (sz, cz, 0), (0, 0, 1))
    return matmul3(rz, matmul3(ry, rx))


def matmul3(a, b):
    return tuple(tuple(sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)) for i in range(3))


def transform(t, where):
    """An object's `transform` as a 4x4 row-major matrix, or None."""
    if t is None:
        return None
    if not isinstance(t, dict):
        raise SceneError("%s: expected an object" % where)
    unknown = set(t) - {"translate", "rotate_deg", "scale"}
    if unknown:
        raise SceneError("%s: unknown key %r" % (where, sorted(unknown)[0]))
    move = vec3(t.get("translate", [0, 0, 0]), where + ".translate")
    turn = vec3(t.get("rotate_deg", [0, 0, 0]), where + ".rotate_deg")
    sc = t.get("scale", 1.0)
    sc = vec3(sc, where + ".scale") if isinstance(sc, list) else (num(sc, where + ".scale"),) * 3
    if any(k <= 0.0 for k in sc):
        raise SceneError("%s.scale: must be > 0, got %r" % (where, t.get("scale")))
    r = rotation_xyz(turn)
    return tuple(tuple(r[i][j] * sc[j] for j in range(3)) + (move[i],) for i in range(3)) + ((0.0, 0.0, 0.0, 1.0),)


def matmul4(a, b):
    """a b for 4x4 row-major matrices (b applied first)."""
    return tuple(tuple(sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)) for i in range(4))


def apply_point(m, p):
    """A 4x4 row-major affine matrix applied to a point."""
    return tuple(m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2] + m[i][3] for i in range(3))


def rodrigues(r):
    """Rows of the rotation of Rodrigues vector r (OpenCV's Rodrigues)."""
    theta = norm(r)
    if theta < 1e-300:
        return ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    k = mul(r, 1.0 / theta)
    c, s = math.cos(theta), math.sin(theta)
    kx = ((0.0, -k[2], k[1]), (k[2], 0.0, -k[0]), (-k[1], k[0], 0.0))
    return tuple(tuple((c if i == j else 0.0) + (1.0 - c) * k[i] * k[j] + s * kx[i][j]
                       for j in range(3)) for i in range(3))


def pinhole(cam, where):
    """A calibrated camera in OpenCV's conventions (x right, y down, z
    forward; pixel (0, 0) the centre of the top-left pixel): fx, fy, cx,
    cy, ``to_world`` (rows of R^T: the camera's x, y, z axes as columns)
    and ``centre`` (-R^T t). Distortion is refused by the Rust side."""
    out = {"type": "pinhole"}
    for key in ("fx", "fy", "cx", "cy"):
        out[key] = num(cam.get(key), "%s.%s" % (where, key))
    for key in ("fx", "fy"):
        if out[key] <= 0.0:
            raise SceneError("%s.%s: must be > 0, got %r" % (where, key, out[key]))
    d = cam.get("distortion")
    if d is not None and any(num(x, where + ".distortion") != 0.0 for x in d):
        raise SceneError("%s.distortion: lens distortion is drawn by phong only" % where)
    r = rodrigues(vec3(cam.get("rotation"), where + ".rotation"))
    t = vec3(cam.get("translation"), where + ".translation")
    rt = tuple(tuple(r[j][i] for j in range(3)) for i in range(3))
    out["to_world"] = rt
    out["centre"] = tuple(-sum(rt[i][j] * t[j] for j in range(3)) for i in range(3))
    return out


def camera(cam, where):
    if cam.get("type") == "pinhole":
        return pinhole(cam, where)
    out = {"type": cam.get("type", "perspective"),
           "position": vec3(cam.get("position"), where + ".position"),
           "look_at": vec3(cam.get("look_at"), where + ".look_at"),
           "up": vec3(cam.get("up", [0, 1, 0]), where + ".up")}
    if norm(sub(out["look_at"], out["position"])) == 0.0:
        raise SceneError("%s: position equals look_at" % where)
    if out["type"] == "perspective":
        out["fov_y"] = num(cam.get("fov_y_deg", 40.0), where + ".fov_y_deg")
        if not 0.0 < out["fov_y"] < 180.0:
            raise SceneError("%s.fov_y_deg: must be in (0, 180), got %r" % (where, out["fov_y"]))
    elif out["type"] == "orthographic":
        out["height"] = num(cam.get("height", 1.0), where + ".height")
        if out["height"] <= 0.0:
            raise SceneError("%s.height: must be > 0, got %r" % (where, out["height"]))
    else:
        raise SceneError("%s.type: unknown %r (perspective, orthographic or pinhole)" % (where, out["type"]))
    return out


def describe(scene):
    """The scene JSON, checked, as the neutral description of the module
    docstring."""
    if not isinstance(scene, dict):
        raise SceneError("scene: expected an object")
    img = obj(scene, "image", "scene")
    w, h = count(img, "width", "image", None), count(img, "height", "image", None)
    if w > 65536 or h > 65536:
        raise SceneError("image: size %dx%d out of range" % (w, h))
    render = obj(scene, "render", "scene", required=False)
    indirect = render.get("indirect", True)
    if not isinstance(indirect, bool):
        raise SceneError("render.indirect: must be true or false, got %r" % (indirect,))
    objects = []
    for name, where, o in named_entries(scene, "objects", "object"):
        objects.append({"name": name,
                        "shape": shape(obj(o, "shape", where), where + ".shape"),
                        "material": material(o.get("material"), where + ".material"),
                        "transform": transform(o.get("transform"), where + ".transform")})
    return {
        "width": w, "height": h, "indirect": indirect,
        "samples": count(render, "samples", "render", 16),
        "camera": camera(obj(scene, "camera", "scene"), "camera"),
        "ambient": vec3(scene.get("ambient", [0, 0, 0]), "scene.ambient"),
        "lights": [light(n, where, L) for n, where, L in named_entries(scene, "lights", "light")],
        "objects": objects,
    }
