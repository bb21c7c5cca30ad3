#!/usr/bin/env python3
"""scenefit's Mitsuba 3 export (``scenefit export --to mitsuba``): a scene
as a Mitsuba XML file that Mitsuba renders as scenefit's Mitsuba backend
does, because it is built by the backend's own code: the scene read by
scene_common.describe, planned by mitsuba_worker.make_plan and turned into
Mitsuba's scene description by MitsubaBackend.build_dict. This module only
writes that description as XML, with the files it names beside it:

    OUT/scene.xml            the scene
    OUT/meshes/NAME.ply|obj  each mesh file, copied
    OUT/textures/NAME_KEY.exr  each texture map as the linear values the
                             backend draws (decoded, range applied)
    OUT/scenefit_plugins.py  registers scenefit's own plug-ins
                             (scenefit_phong, scenefit_point, scenefit_sun),
                             generated from mitsuba_worker.register_plugins

    python3 mitsuba_export.py SCENE.json OUT RESULT.json

SCENE.json is the scene as scenefit loaded it (paths absolute). RESULT.json
gets {"ok": true, "warnings": [...]} or {"ok": false, "error": "...",
"user": true|false} (user: the scene's fault, exit 2).

To render the export (docs/interchange.md):

    import mitsuba as mi; mi.set_variant("llvm_ad_rgb")
    import sys; sys.path.insert(0, "OUT"); import scenefit_plugins
    img = mi.render(mi.load_file("OUT/scene.xml"))
"""

import inspect
import json
import os
import re
import shutil
import sys
from xml.sax.saxutils import quoteattr

import mitsuba_worker
from scene_common import SceneError

# What each key of build_dict's description is in XML: the tag of a nested
# plug-in by its key (objects O*, lights L* by their own type below).
PLUGIN_TAGS = {"integrator": "integrator", "sensor": "sensor", "sampler": "sampler",
               "film": "film", "rfilter": "rfilter", "emitter": "emitter",
               "ambient": "emitter", "bsdf": "bsdf", "bsdf_0": "bsdf", "bsdf_1": "bsdf"}
SHAPE_TYPES = ("sphere", "rectangle", "ply", "obj", "cube")
POINT_KEYS = ("position",)
VECTOR_KEYS = ("direction",)


def safe(name):
    """A file name for an object's name."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name) or "object"


def matrix_text(rows):
    return " ".join(repr(float(x)) for r in rows for x in r)


def transform_rows(t):
    """The rows of a Mitsuba ScalarTransform (3x3 or 4x4)."""
    m = t.matrix
    n = 4 if "4" in type(t).__name__ else 3
    return [[float(m[i][j]) for j in range(n)] for i in range(n)]


def tag_of(key, value):
    if key in PLUGIN_TAGS:
        return PLUGIN_TAGS[key]
    if key in mitsuba_worker.MAP_KEYS:
        return "texture"
    if value["type"] in SHAPE_TYPES:
        return "shape"
    return "emitter"


def element(key, value, indent, ident=None):
    """The XML lines of one entry of a description: a nested plug-in, an
    rgb value, a transform or a plain property named `key`."""
    pad = "    " * indent
    name = quoteattr(key)
    if isinstance(value, dict) and value.get("type") == "rgb":
        return ["%s<rgb name=%s value=\"%s\"/>" % (pad, name, ", ".join(repr(float(x)) for x in value["value"]))]
    if isinstance(value, dict):
        tag = tag_of(key, value)
        attrs = "type=%s" % quoteattr(value["type"])
        if ident is not None:
            attrs += " id=%s" % quoteattr(ident)
        elif tag in ("texture", "bsdf") and key != "bsdf":
            # the plug-in reads these by name (scenefit_phong's maps, blendbsdf's)
            attrs += " name=%s" % name
        lines = ["%s<%s %s>" % (pad, tag, attrs)]
        for k, v in value.items():
            if k != "type":
                lines += element(k, v, indent + 1)
        return lines + ["%s</%s>" % (pad, tag)]
    if hasattr(value, "matrix"):
        return ["%s<transform name=%s><matrix value=\"%s\"/></transform>"
                % (pad, name, matrix_text(transform_rows(value)))]
    if isinstance(value, bool):
        return ["%s<boolean name=%s value=\"%s\"/>" % (pad, name, "true" if value else "false")]
    if isinstance(value, int):
        return ["%s<integer name=%s value=\"%d\"/>" % (pad, name, value)]
    if isinstance(value, float):
        return ["%s<float name=%s value=\"%r\"/>" % (pad, name, value)]
    if isinstance(value, str):
        return ["%s<string name=%s value=%s/>" % (pad, name, quoteattr(value))]
    if isinstance(value, (list, tuple)) and len(value) == 3:
        tag = "vector" if key in VECTOR_KEYS else "point"
        return ["%s<%s name=%s value=\"%s\"/>" % (pad, tag, name, ", ".join(repr(float(x)) for x in value))]
    raise SceneError("internal: cannot write %s = %r as XML" % (key, value))


class Exporter(mitsuba_worker.MitsubaBackend):
    """The backend's description, with each texture written as a file
    instead of held in memory."""

    def __init__(self, mi, dr, out):
        mitsuba_worker.MitsubaBackend.__init__(self, mi, dr)
        self.out = out
        self.current = "object"

    def texture(self, t, uv, key):
        d = mitsuba_worker.MitsubaBackend.texture(self, t, uv, key)
        rel = os.path.join("textures", "%s_%s.exr" % (safe(self.current), key))
        os.makedirs(os.path.join(self.out, "textures"), exist_ok=True)
        self.mi.Bitmap(d.pop("data")).write(os.path.join(self.out, rel))
        d["filename"] = rel
        return d


def write_unit_cube(mi, path):
    """Mitsuba's own cube [-1, 1]^3 (the worker's box) as an ASCII PLY
    with the (u, v) the worker gives it (`box_texcoords`), so the layout
    of a box's faces is stated once on the Python side."""
    params = mi.traverse(mi.load_dict({"type": "cube"}))
    pos = [float(x) for x in params["vertex_positions"]]
    nor = [float(x) for x in params["vertex_normals"]]
    faces = [int(x) for x in params["faces"]]
    uv = mitsuba_worker.box_texcoords(pos, nor)
    n = len(pos) // 3
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex %d\n" % n)
        for name in ("x", "y", "z", "nx", "ny", "nz", "u", "v"):
            f.write("property float %s\n" % name)
        f.write("element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(faces) // 3))
        for k in range(n):
            row = pos[3 * k:3 * k + 3] + nor[3 * k:3 * k + 3] + uv[2 * k:2 * k + 2]
            f.write(" ".join("%r" % x for x in row) + "\n")
        for k in range(0, len(faces), 3):
            f.write("3 %d %d %d\n" % tuple(faces[k:k + 3]))


def describe_for_xml(ex, plan, names):
    """build_dict's description, with each object's and light's key its
    scenefit name (the XML id), meshes copied beside the XML and placed,
    like boxes, by their to_world (the worker writes their vertices instead)."""
    objects = plan["objects"]
    # bsdf_dict is called per object by build_dict: name the textures after it
    original = ex.bsdf_dict
    queue = [o["name"] for o in objects]

    def bsdf_dict(m):
        ex.current = queue.pop(0) if queue else "object"
        return original(m)
    ex.bsdf_dict = bsdf_dict
    d = ex.build_dict(plan)
    out = {}
    for key, value in d.items():
        if key.startswith("O") and key[1:].isdigit():
            o = objects[int(key[1:])]
            if o["shape"] == "mesh":
                ext = ".obj" if o["file"].lower().endswith(".obj") else ".ply"
                rel = os.path.join("meshes", safe(o["name"]) + ext)
                os.makedirs(os.path.join(ex.out, "meshes"), exist_ok=True)
                shutil.copyfile(o["file"], os.path.join(ex.out, rel))
                value["filename"] = rel
                if o["transform"] is not None:
                    # the loaders place the file's vertices (normals too) by to_world
                    value["to_world"] = ex.T([list(r) for r in o["transform"]])
            elif o["shape"] == "box":
                hx, hy, hz = o["half"]
                place = mitsuba_worker.columns_matrix((hx, 0, 0), (0, hy, 0), (0, 0, hz), o["center"])
                if o["transform"] is not None:
                    place = mitsuba_worker.matmul4(o["transform"], place)
                value["to_world"] = ex.T([list(r) for r in place])
                if o["mapped"]:
                    # an XML cube keeps Mitsuba's own coordinates: a mapped
                    # box is a unit cube mesh carrying scenefit's per face
                    rel = os.path.join("meshes", safe(o["name"]) + ".ply")
                    os.makedirs(os.path.join(ex.out, "meshes"), exist_ok=True)
                    write_unit_cube(ex.mi, os.path.join(ex.out, rel))
                    value["type"], value["filename"] = "ply", rel
            out[(names["O"][int(key[1:])], key)] = value
        elif key.startswith("L") and key[1:].isdigit():
            out[(names["L"][int(key[1:])], key)] = value
        else:
            out[(None, key)] = value
    return out


def unique_ids(plan):
    """XML ids: each object's and light's name, made unique."""
    seen, names = set(), {"O": [], "L": []}
    for kind, items in (("O", plan["objects"]), ("L", plan["lights"])):
        for it in items:
            n, k = it["name"], 2
            while n in seen:
                n, k = "%s_%d" % (it["name"], k), k + 1
            seen.add(n)
            names[kind].append(n)
    return names


def plugins_module():
    """scenefit_plugins.py: register_plugins as the worker has it."""
    w = mitsuba_worker
    return ('"""scenefit\'s own Mitsuba plug-ins, for a scene written by `scenefit export\n'
            '--to mitsuba` (generated from scenefit\'s workers/mitsuba_worker.py).\n'
            'Set the variant first, then import this module, then load the scene:\n\n'
            '    import mitsuba as mi; mi.set_variant("llvm_ad_rgb")\n'
            '    import scenefit_plugins; scene = mi.load_file("scene.xml")\n"""\n\n'
            'import drjit as dr\nimport mitsuba as mi\n\n'
            'MAP_KEYS = %r\nPHONG_PARAMS = %r\n\n\n%s\n\n'
            'if mi.variant() is None:\n    mi.set_variant("scalar_rgb")\n'
            'register_plugins(mi, dr)\n'
            % (w.MAP_KEYS, w.PHONG_PARAMS, inspect.getsource(w.register_plugins)))


def export(scene, out):
    import drjit as dr
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    mitsuba_worker.register_plugins(mi, dr)
    _, plan = mitsuba_worker.make_plan(scene)
    ex = Exporter(mi, dr, out)
    names = unique_ids(plan)
    desc = describe_for_xml(ex, plan, names)
    lines = ['<?xml version="1.0" encoding="utf-8"?>',
             "<!-- written by scenefit export --to mitsuba; needs scenefit_plugins.py",
             "     (beside this file) imported before mi.load_file: docs/interchange.md -->",
             '<scene version="3.0.0">']
    for (ident, key), value in desc.items():
        if key == "type":
            continue
        lines += element(key, value, 1, ident)
    lines.append("</scene>")
    with open(os.path.join(out, "scene.xml"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(out, "scenefit_plugins.py"), "w") as f:
        f.write(plugins_module())
    # a check that Mitsuba reads back what was written
    mi.load_file(os.path.join(out, "scene.xml"))
    return []


def main(argv):
    scene_file, out, result = argv[1:4]
    try:
        with open(scene_file) as f:
            scene = json.load(f)
        warnings = export(scene, out)
        answer = {"ok": True, "warnings": warnings}
    except SceneError as e:
        answer = {"ok": False, "error": str(e), "user": True}
    except Exception as e:  # Mitsuba's own errors: a failed run
        answer = {"ok": False, "error": "%s: %s" % (type(e).__name__, str(e).strip()), "user": False}
    with open(result, "w") as f:
        json.dump(answer, f)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
