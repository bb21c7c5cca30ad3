#!/usr/bin/env python3
"""scenefit's Mitsuba 3 import (``scenefit import FILE.xml``): a Mitsuba XML
scene read by Mitsuba's own parser (``mi.parser``: includes, defaults,
references and version upgrades resolved as ``mi.load_file`` resolves them)
and mapped to a scenefit scene; meshes are loaded by Mitsuba and written as
PLY (positions in world space, normals, UVs), textures as the linear values
Mitsuba draws (16-bit linear PNG, with a range when beyond [0, 1]). The mapping tables are in docs/interchange.md.

    python3 mitsuba_import.py FILE.xml ASSETS_DIR ASSETS_PREFIX ANSWER.json

ANSWER.json gets {"ok": true, "scene": {...}, "warnings": [...]} (the
scene's file paths ASSETS_PREFIX/NAME, relative to the scene file) or
{"ok": false, "error": "...", "user": true|false}. What cannot be mapped
is one warning per kind, naming where it occurs; nothing is dropped
silently.
"""

import json
import math
import os
import re
import sys

import mitsuba_worker
from scene_common import SceneError, cross, dot, norm, normalize, sub

# The project's one roughness <-> shininess mapping (scene_common.roughness,
# docs/renderers.md): r = (2 / (n + 2))^(1/4), so n = 2 / r^4 - 2.
MAX_SHININESS = 10000.0


def shininess(r):
    """The Blinn-Phong exponent of a Principled roughness r."""
    r = min(max(r, 0.0), 1.0)
    if r <= (2.0 / (MAX_SHININESS + 2.0)) ** 0.25:
        return MAX_SHININESS
    return 2.0 / r ** 4 - 2.0


def fresnel0(eta):
    return ((eta - 1.0) / (eta + 1.0)) ** 2


class Importer:
    def __init__(self, mi, dr, state, path, assets, prefix):
        self.mi, self.dr, self.state, self.path = mi, dr, state, path
        self.base = os.path.dirname(os.path.abspath(path))
        self.assets, self.prefix = assets, prefix
        self.unmapped = {}  # kind -> [where]
        self.used = set()

    # --- helpers
    def warn(self, kind, where):
        self.unmapped.setdefault(kind, []).append(where)

    def warnings(self):
        out = []
        for kind, where in self.unmapped.items():
            shown = ", ".join(where[:5]) + (" and %d more" % (len(where) - 5) if len(where) > 5 else "")
            out.append("%s: %s: %s" % (self.path, kind, shown))
        return out

    def node(self, ref):
        i = ref.index() if callable(ref.index) else ref.index
        return self.state.nodes[i]

    def children(self, node):
        """(name, child node) for each nested object of node."""
        out = []
        for k in node.props.keys():
            v = node.props[k]
            if type(v).__name__ == "ResolvedReference":
                out.append((k, self.node(v)))
        return out

    def child_of_type(self, node, kind):
        return next((c for _, c in self.children(node) if str(c.type).endswith("." + kind)), None)

    def file_name(self, name, ext):
        base = re.sub(r"[^A-Za-z0-9_.-]", "_", name) or "object"
        n, k = base, 2
        while n + ext in self.used:
            n, k = "%s_%d" % (base, k), k + 1
        self.used.add(n + ext)
        return n + ext

    def resolve(self, fname):
        return fname if os.path.isabs(fname) else os.path.join(self.base, fname)

    def rows(self, t):
        m = t.matrix
        return [[float(m[i][j]) for j in range(4)] for i in range(4)]

    def value(self, props, key, default=None):
        """A plain value (float, or a colour/point as a list)."""
        if key not in props:
            return default
        v = props[key]
        if isinstance(v, (bool, int, float, str)):
            return v
        try:
            return [float(v[i]) for i in range(3)]
        except Exception:
            return v

    def colour(self, props, key, default, where):
        """A colour or number; a nested texture -> (value, texture node)."""
        if key not in props:
            return default, None
        v = props[key]
        if type(v).__name__ == "ResolvedReference":
            t = self.node(v)
            if t.props.plugin_name() == "bitmap":
                return [1.0, 1.0, 1.0], t
            self.warn("texture %r (not bitmap): its mean not taken, white used" % t.props.plugin_name(), where)
            return [1.0, 1.0, 1.0], None
        x = self.value(props, key)
        return (list(x) if isinstance(x, list) else [float(x)] * 3), None

    # --- textures
    def texture(self, t, name, key, where):
        """A bitmap as a texture map: linear values written as EXR."""
        mi, dr = self.mi, self.dr
        p = t.props
        fname = self.resolve(p["filename"])
        bmp = mi.Bitmap(fname)
        raw = bool(p["raw"]) if "raw" in p else False
        if raw:
            bmp.set_srgb_gamma(False)
        bmp = bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False)
        a, d, c, e = 1.0, 1.0, 0.0, 0.0
        if "to_uv" in p:
            m = self.rows(p["to_uv"])
            a, d, c, e = m[0][0], m[1][1], m[0][3], m[1][3]
            if abs(m[0][1]) > 1e-9 or abs(m[1][0]) > 1e-9:
                self.warn("texture to_uv with rotation or shear (not mapped: scale only)", where)
            if abs(c - round(c)) > 1e-6 or abs(e - round(e)) > 1e-6:
                self.warn("texture to_uv offset (not mapped: scale only)", where)
        if d > 0:
            # Mitsuba's v runs down the image, scenefit's up
            bmp.vflip()
        out = self.file_name("%s_%s" % (name, key), ".png")
        entry = {"file": self.prefix + "/" + out, "encoding": "linear"}
        data = mi.TensorXf(bmp)
        lo, hi = float(dr.min(data.array)), float(dr.max(data.array))
        if lo < 0.0 or hi > 1.0:
            # 16-bit levels hold [0, 1]: other values through the map's range
            entry["range"] = [lo, hi]
            data = (data - lo) / (hi - lo if hi > lo else 1.0)
        # a 16-bit linear PNG: scenefit's Mitsuba worker hangs on float
        # OpenEXR maps (mitsuba 3.9.1), and 16 bits keep what 8 would lose
        png = mi.Bitmap(data).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt16, srgb_gamma=False)
        png.write(os.path.join(self.assets, out))
        if (a, abs(d)) != (1.0, 1.0):
            entry["scale"] = [a, abs(d)]
        return entry

    # --- camera
    def camera(self, sensor, where):
        p = sensor.props
        film = self.child_of_type(sensor, "Film")
        w = int(film.props["width"]) if film is not None and "width" in film.props else 768
        h = int(film.props["height"]) if film is not None and "height" in film.props else 576
        sampler = self.child_of_type(sensor, "Sampler")
        spp = int(sampler.props["sample_count"]) if sampler is not None and "sample_count" in sampler.props else 4
        kind = p.plugin_name()
        if kind not in ("perspective", "thinlens"):
            raise SceneError("%s: %s: camera %r is not read (perspective or thinlens)" % (self.path, where, kind))
        if kind == "thinlens":
            self.warn("thinlens camera (drawn as a pinhole: no depth of field)", where)
        m = self.rows(p["to_world"]) if "to_world" in p else [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
        col = [tuple(m[i][j] for i in range(3)) for j in range(4)]
        axis = p["fov_axis"] if "fov_axis" in p else "x"
        if "fov" in p:
            fov = float(p["fov"])
        else:
            fl = str(p["focal_length"]) if "focal_length" in p else "50mm"
            fov = math.degrees(2.0 * math.atan(36.0 / (2.0 * float(fl.rstrip("m")))))
            axis = "x"
        t = math.tan(math.radians(fov) / 2.0)
        aspect = w / h
        if axis == "y":
            ty = t
        elif axis == "x":
            ty = t / aspect
        elif axis == "diagonal":
            ty = t / math.sqrt(aspect * aspect + 1.0)
        elif axis == "smaller":
            ty = t / aspect if w < h else t
        else:  # larger
            ty = t if w < h else t / aspect
        fov_y = math.degrees(2.0 * math.atan(ty))
        off = (float(p["principal_point_offset_x"]) if "principal_point_offset_x" in p else 0.0,
               float(p["principal_point_offset_y"]) if "principal_point_offset_y" in p else 0.0)
        sx, sy = norm(col[0]), norm(col[1])
        cam = {"type": "perspective", "position": list(col[3]),
               "look_at": [col[3][i] + col[2][i] / norm(col[2]) for i in range(3)],
               "up": [x / sy for x in col[1]], "fov_y_deg": fov_y}
        if abs(off[0]) > 1e-9 or abs(off[1]) > 1e-9 or abs(sx / sy - 1.0) > 1e-6:
            cam = self.pinhole(col, ty, off, w, h, sx / sy)
        return cam, w, h, spp

    def pinhole(self, col, ty, off, w, h, xscale):
        """The calibrated pinhole of a perspective camera with a principal
        point offset (mitsuba_worker.pinhole_plan, inverted)."""
        fy = h / (2.0 * ty)
        fx = fy / xscale
        x = normalize(tuple(-c for c in col[0]), "camera x")
        y = normalize(tuple(-c for c in col[1]), "camera y")
        z = normalize(col[2], "camera z")
        r = [list(x), list(y), list(z)]  # rows of R: world to camera
        t = [-dot(r[i], col[3]) for i in range(3)]
        return {"type": "pinhole", "fx": fx, "fy": fy,
                "cx": (0.5 - off[0]) * w - 0.5, "cy": (0.5 - off[1]) * h - 0.5,
                "rotation": rodrigues_of(r), "translation": t}


    # --- lights
    def light(self, e, name, where):
        """A light, or None (ambient and unmapped emitters)."""
        p, kind = e.props, e.props.plugin_name()
        if kind in ("point", "scenefit_point", "spot"):
            if kind == "spot":
                self.warn("spot light (drawn as a point light: no cone)", where)
            if "position" in p:
                pos = self.value(p, "position")
            else:
                pos = [self.rows(p["to_world"])[i][3] for i in range(3)] if "to_world" in p else [0.0, 0.0, 0.0]
            rgb, _ = self.colour(p, "intensity", [1.0, 1.0, 1.0], where)
            light = {"name": name, "type": "point", "position": pos}
            if kind == "scenefit_point" and float(p["power"]) != 2.0:
                light["falloff_power"] = float(p["power"])
        elif kind in ("directional", "scenefit_sun"):
            rgb, _ = self.colour(p, "irradiance", [1.0, 1.0, 1.0], where)
            if kind == "scenefit_sun":
                d = self.value(p, "direction")
            else:
                m = self.rows(p["to_world"]) if "to_world" in p else None
                travel = [m[i][2] for i in range(3)] if m else (self.value(p, "direction") or [0, 0, 1])
                d = [-x for x in travel]
            light = {"name": name, "type": "directional", "direction": list(normalize(d, where))}
            if kind == "scenefit_sun" and float(p["radius"]) > 0.0:
                light["radius"] = float(p["radius"])
        else:
            self.warn("emitter %r (not mapped)" % kind, where)
            return None
        return with_intensity(light, rgb)

    # --- materials
    def material(self, b, name, where):
        """The project's convention values of a BSDF node."""
        kind = b.props.plugin_name()
        if kind in ("twosided", "mask"):
            inner = self.child_of_type(b, "BSDF")
            if kind == "mask":
                self.warn("mask BSDF (opacity not mapped)", where)
            return self.material(inner, name, where) if inner is not None else {"color": [0.5] * 3}
        if kind == "blendbsdf":
            return self.blend(b, name, where)
        p = b.props
        m, tex = {}, None
        if kind == "diffuse":
            m["color"], tex = self.colour(p, "reflectance", [0.5] * 3, where)
        elif kind in ("plastic", "roughplastic"):
            m["color"], tex = self.colour(p, "diffuse_reflectance", [0.5] * 3, where)
            ks, _ = self.colour(p, "specular_reflectance", [1.0] * 3, where)
            f0 = fresnel0(float(p["int_ior"]) if "int_ior" in p and isinstance(p["int_ior"], float) else 1.49)
            if kind == "plastic":
                m["reflection"] = f0 * max(ks)
                m["specular"] = 0.0
            else:
                alpha = float(p["alpha"]) if "alpha" in p else 0.1
                m["specular"] = f0 / 0.08 * max(ks)
                m["shininess"] = shininess(math.sqrt(alpha))
        elif kind == "principled":
            m["color"], tex = self.colour(p, "base_color", [0.5] * 3, where)
            m["specular"] = float(p["specular"]) if "specular" in p else 0.5
            m["shininess"] = shininess(float(p["roughness"]) if "roughness" in p else 0.5)
            if "metallic" in p and float(p["metallic"]) > 0.0:
                self.warn("principled metallic (not mapped: dielectric)", where)
            if "spec_trans" in p and float(p["spec_trans"]) > 0.0:
                m["transmission"] = float(p["spec_trans"])
                m["ior"] = float(p["eta"]) if "eta" in p else 1.5
        elif kind in ("conductor", "roughconductor"):
            self.warn("%s (a metal, mapped as a white mirror)" % kind, where)
            m = {"color": [1.0, 1.0, 1.0], "diffuse": 0.0, "reflection": 1.0}
        elif kind == "scenefit_phong":
            return self.phong(b, name, where)
        else:
            self.warn("BSDF %r (not mapped: grey diffuse)" % kind, where)
            m["color"] = [0.5] * 3
        if tex is not None:
            m["color_map"] = self.texture(tex, name, "color_map", where)
        return m

    def phong(self, b, name, where):
        """scenefit's own BSDF, as the export wrote it."""
        p = b.props
        m = {"color": self.value(p, "albedo")}
        sc = float(p["scale"]) if "scale" in p else 1.0
        m["color"] = [c * sc for c in m["color"]]
        ks = float(p["ks"]) if "ks" in p else 0.0
        ks2 = float(p["ks2"]) if "ks2" in p else 0.0
        if ks != 0.0 or ks2 != 0.0:
            # without a lobe the shininess draws nothing: left at its default
            m["specular"] = ks * sc
            m["shininess"] = float(p["n"]) if "n" in p else 10.0
        if ks2 != 0.0:
            m["specular2"] = ks2 * sc
        if "n2_follows" in p and not bool(p["n2_follows"]):
            m["shininess2"] = float(p["n2"])
        if "f0" in p and float(p["f0"]) != 1.0:
            m["fresnel"] = float(p["f0"])
        for key in mitsuba_worker.MAP_KEYS:
            if key in p:
                m[key] = self.texture(self.node(p[key]), name, key, where)
        return m

    def blend(self, b, name, where):
        """A blend of a BSDF and a white mirror (the export's reflection)."""
        parts = [c for _, c in self.children(b) if str(c.type).endswith(".BSDF")]
        weight = float(b.props["weight"]) if "weight" in b.props and isinstance(b.props["weight"], float) else 0.5
        if len(parts) == 2 and parts[1].props.plugin_name() == "conductor":
            m = self.material(parts[0], name, where)
            if parts[0].props.plugin_name() != "scenefit_phong":
                m["color"] = [c * (1.0 - weight) for c in m["color"]]
                m["specular"] = m.get("specular", 0.0) * (1.0 - weight)
            m["reflection"] = weight
            return m
        self.warn("blendbsdf (the first BSDF kept)", where)
        return self.material(parts[0], name, where) if parts else {"color": [0.5] * 3}


    # --- shapes
    def transform_point(self, m, q):
        return [sum(m[i][j] * q[j] for j in range(3)) + m[i][3] for i in range(3)]

    def shape(self, n, name, where):
        """An object's shape, or None when it is not mapped."""
        p, kind = n.props, n.props.plugin_name()
        m = self.rows(p["to_world"]) if "to_world" in p else [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
        cols = [[m[i][j] for i in range(3)] for j in range(3)]
        scales = [norm(c) for c in cols]
        if kind == "sphere":
            c = self.value(p, "center", [0.0, 0.0, 0.0])
            r = float(p["radius"]) if "radius" in p else 1.0
            if max(scales) - min(scales) > 1e-6 * max(scales):
                self.warn("sphere scaled unevenly (its mean scale kept)", where)
            return {"type": "sphere", "center": self.transform_point(m, c), "radius": r * sum(scales) / 3.0}
        if kind == "rectangle":
            corner = self.transform_point(m, [-1, -1, 0])
            return {"type": "quad", "corner": corner,
                    "edge_u": list(sub(self.transform_point(m, [1, -1, 0]), corner)),
                    "edge_v": list(sub(self.transform_point(m, [-1, 1, 0]), corner))}
        if kind == "cube" and all(abs(m[i][j]) < 1e-12 for i in range(3) for j in range(3) if i != j) \
                and all(m[i][i] > 0 for i in range(3)):
            return {"type": "box", "min": self.transform_point(m, [-1, -1, -1]),
                    "max": self.transform_point(m, [1, 1, 1])}
        if kind in ("ply", "obj", "serialized", "cube"):
            return {"type": "mesh", "file": self.mesh(n, name, m)}
        self.warn("shape %r (not mapped)" % kind, where)
        return None

    def mesh(self, n, name, m):
        """A mesh loaded by Mitsuba (in world space) and written as PLY."""
        mi, p = self.mi, n.props
        d = {"type": p.plugin_name(), "to_world": mi.ScalarTransform4f(m)}
        for k in p.keys():
            v = p[k]
            if k == "filename":
                d[k] = self.resolve(v)
            elif k != "to_world" and isinstance(v, (bool, int, float, str)):
                d[k] = v
        shape = mi.load_dict(d)
        out = self.file_name(name, ".ply")
        shape.write_ply(os.path.join(self.assets, out))
        return self.prefix + "/" + out

    def area_light(self, n, name, where):
        """A sphere with an area emitter as a point light of that radius
        (the backend's own drawing of one); other emitting shapes: None."""
        e = self.child_of_type(n, "Emitter")
        if n.props.plugin_name() != "sphere":
            self.warn("area emitter on a %r (not mapped: the shape kept, unlit)" % n.props.plugin_name(), where)
            return None
        sh = self.shape(n, name, where)
        rgb, _ = self.colour(e.props, "radiance", [1.0] * 3, where)
        r = sh["radius"]
        light = {"name": name, "type": "point", "position": sh["center"], "radius": r}
        return with_intensity(light, [c * math.pi * r * r for c in rgb])

    def objects_and_lights(self, root):
        objects, lights, ambient = [], [], [0.0, 0.0, 0.0]
        for i, (_, n) in enumerate(self.children(root)):
            kind = str(n.type).split(".")[-1]
            name = n.props.id() or "%s%d" % (kind.lower(), i)
            where = "%s %r" % (kind.lower(), name)
            if kind == "Emitter":
                if n.props.plugin_name() == "constant":
                    ambient, _ = self.colour(n.props, "radiance", [1.0] * 3, where)
                    continue
                light = self.light(n, name, where)
                if light is not None:
                    lights.append(light)
            elif kind == "Shape":
                if self.child_of_type(n, "Emitter") is not None:
                    light = self.area_light(n, name, where)
                    if light is not None:
                        lights.append(light)
                        continue
                sh = self.shape(n, name, where)
                if sh is None:
                    continue
                b = self.child_of_type(n, "BSDF")
                mat = self.material(b, name, where) if b is not None else {"color": [0.5] * 3}
                objects.append({"name": name, "shape": sh, "material": mat})
            elif kind not in ("Sensor", "Integrator"):
                self.warn("%s (not mapped)" % kind.lower(), where)
        return objects, lights, ambient

    def scene(self):
        root = self.state.nodes[0]
        sensors = [c for _, c in self.children(root) if str(c.type).endswith(".Sensor")]
        if not sensors:
            raise SceneError("%s: no sensor (camera); expected a perspective sensor" % self.path)
        if len(sensors) > 1:
            self.warn("more than one sensor (the first used)", "scene")
        camera, w, h, spp = self.camera(sensors[0], "sensor")
        indirect = True
        integ = self.child_of_type(root, "Integrator")
        if integ is not None:
            k = integ.props.plugin_name()
            depth = int(integ.props["max_depth"]) if "max_depth" in integ.props else -1
            indirect = not (k == "direct" or (k == "path" and 0 <= depth <= 2))
            if k not in ("direct", "path"):
                self.warn("integrator %r (a path tracer used)" % k, "scene")
        objects, lights, ambient = self.objects_and_lights(root)
        return {"format": "scenefit-scene/1", "image": {"width": w, "height": h},
                "camera": camera, "ambient": ambient,
                "render": {"samples": spp, "indirect": indirect},
                "lights": lights, "objects": objects}


def rodrigues_of(r):
    """The Rodrigues vector of rotation matrix r (rows), angle in [0, pi]."""
    c = max(-1.0, min(1.0, (r[0][0] + r[1][1] + r[2][2] - 1.0) / 2.0))
    theta = math.acos(c)
    if theta < 1e-12:
        return [0.0, 0.0, 0.0]
    if math.pi - theta < 1e-6:
        # near pi: the axis from the diagonal
        k = [math.sqrt(max((r[i][i] + 1.0) / 2.0, 0.0)) for i in range(3)]
        i = max(range(3), key=lambda j: k[j])
        for j in range(3):
            if j != i:
                k[j] = math.copysign(k[j], r[i][j] + r[j][i])
        return [theta * x for x in k]
    s = 2.0 * math.sin(theta)
    v = [(r[2][1] - r[1][2]) / s, (r[0][2] - r[2][0]) / s, (r[1][0] - r[0][1]) / s]
    return [theta * x for x in v]


def with_intensity(light, rgb):
    """A light's colour and intensity from Mitsuba's RGB: intensity the
    largest channel, colour the RGB over it."""
    top = max(rgb)
    light["intensity"] = top
    light["color"] = [c / top for c in rgb] if top > 0 else [1.0, 1.0, 1.0]
    return light


def load(mi, path):
    """The parsed and resolved scene graph, or a user error."""
    P = mi.parser
    try:
        cfg = P.ParserConfig(mi.variant())
        state = P.parse_file(cfg, path)
        P.transform_upgrade(cfg, state)
        P.transform_resolve_references(cfg, state)
        P.transform_resolve(cfg, state)
    except Exception as e:
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        raise SceneError("%s: not a Mitsuba 3 scene Mitsuba can read: %s" % (path, first))
    if not state.nodes or not str(state.nodes[0].type).endswith(".Scene"):
        raise SceneError("%s: not a Mitsuba scene (its root is not <scene>)" % path)
    return state


def main(argv):
    path, assets, prefix, answer_file = argv[1:5]
    try:
        import drjit as dr
        import mitsuba as mi
        mi.set_variant("scalar_rgb")
        mi.set_log_level(mi.LogLevel.Warn)
        mitsuba_worker.register_plugins(mi, dr)
        imp = Importer(mi, dr, load(mi, path), path, assets, prefix)
        scene = imp.scene()
        answer = {"ok": True, "scene": scene, "warnings": imp.warnings()}
    except SceneError as e:
        answer = {"ok": False, "error": str(e), "user": True}
    except Exception as e:  # Mitsuba's own errors (a mesh it cannot load...)
        first = str(e).strip().splitlines()[0] if str(e).strip() else ""
        answer = {"ok": False, "error": "%s: %s: %s" % (path, type(e).__name__, first), "user": True}
    with open(answer_file, "w") as f:
        json.dump(answer, f)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
