"""scenefit import FILE.blend: the loaded .blend's active scene as a
scenefit-scene/1 scene (docs/interchange.md, "Blender": the mapping tables).

Run by scenefit (src/interchange/blend_import.rs):

    blender -b FILE.blend --factory-startup --disable-autoexec -noaudio \
        --python-exit-code 1 -P import_blend.py -- RESULT.json OUT_DIR STEM

Writes RESULT.json = {"scene": {...}, "warnings": [...]} and, into OUT_DIR,
one OBJ per mesh part (STEM.NAME.obj: positions, normals, UVs, in the
scene's frame) and a PNG for every texture image that is packed, generated
or not a PNG/OpenEXR file (STEM.IMAGE.png). A user's error (no camera, a
file Blender could not load) is printed as one line "scenefit-error: ...".

Frames: Blender is z up, the scene y up (worker.py): a Blender point
(X, Y, Z) is the scene point (X, Z, -Y). What cannot be mapped is reported
in one warning per kind, listing the names it concerns.
"""

import json
import math
import os
import sys

import bpy
from mathutils import Matrix, Vector

# Blender (x, y, z) -> scene (x, z, -y), and its inverse
TO_SCENE = Matrix(((1, 0, 0, 0), (0, 0, 1, 0), (0, -1, 0, 0), (0, 0, 0, 1)))
TO_BLENDER = TO_SCENE.inverted()
# Principled BSDF's specular level s is F0 = 0.08 s (docs/renderers.md)
F0_PER_LEVEL = 0.08
# shininess for roughness 0 (a mirror-like highlight the format can hold)
MAX_SHININESS = 1.0e4
PRINCIPLED_UNUSED = (("Metallic", 0.0), ("Subsurface", 0.0), ("Sheen", 0.0),
                     ("Clearcoat", 0.0), ("Anisotropic", 0.0), ("Specular Tint", 0.0),
                     ("Alpha", 1.0))


def user_error(msg):
    print("scenefit-error: " + msg, flush=True)
    sys.exit(1)


class Warnings:
    """One warning per kind, naming every datablock it concerns."""

    def __init__(self):
        self.kinds = {}

    def add(self, kind, name):
        names = self.kinds.setdefault(kind, [])
        if name not in names:
            names.append(name)

    def lines(self):
        return ["%s: %s" % (kind, ", ".join(names)) for kind, names in sorted(self.kinds.items())]


class Names:
    """Scene names (1 to 64 of A-Z a-z 0-9 _ -), unique per list."""

    def __init__(self):
        self.used = set()

    def take(self, name):
        base = "".join(c if c.isascii() and (c.isalnum() or c in "_-") else "_" for c in name)[:60] or "x"
        out, i = base, 2
        while out in self.used:
            out, i = "%s_%d" % (base, i), i + 1
        self.used.add(out)
        return out


def vec(v):
    return [float(x) for x in v]


def to_scene(v):
    """A Blender point or direction in the scene's frame."""
    return [float(v[0]), float(v[2]), -float(v[1])]


# ---------------------------------------------------------------- camera
def intrinsics(cam, width, height, r):
    """fx, fy, cx, cy in pixels (OpenCV's convention, the centre of the
    top-left pixel at 0, 0) of a perspective camera, as Blender's
    viewplane: the fitted axis, its sensor size, the pixel aspect, the
    lens shift in units of the fitted axis."""
    ax, ay = r.pixel_aspect_x, r.pixel_aspect_y
    ycor = ay / ax
    fit = cam.sensor_fit
    if fit == "AUTO":
        fit = "HORIZONTAL" if ax * width >= ay * height else "VERTICAL"
        sensor = cam.sensor_width
    else:
        sensor = cam.sensor_width if fit == "HORIZONTAL" else cam.sensor_height
    viewfac = width if fit == "HORIZONTAL" else ycor * height
    fx = cam.lens * viewfac / sensor
    fy = fx / ycor
    cx = width / 2.0 - 0.5 - cam.shift_x * viewfac
    cy = height / 2.0 - 0.5 + cam.shift_y * viewfac / ycor
    return fx, fy, cx, cy, viewfac


def camera_axes(ob):
    """The camera's right, up and backward axes in the scene's frame, and
    its position (scale dropped: Blender ignores it)."""
    m = TO_SCENE @ ob.matrix_world
    loc, rot, _ = m.decompose()
    r = rot.to_matrix()
    return r.col[0], r.col[1], r.col[2], loc


def rodrigues(rm):
    """The Rodrigues vector of a rotation matrix (angle <= pi)."""
    q = rm.to_quaternion()
    if q.w < 0:
        q.negate()
    axis, angle = q.to_axis_angle()
    return [float(a * angle) for a in axis]


def look_distance(pos, back, objects):
    """How far ahead of the camera its look_at is put: the distance to the
    centre of the imported objects along the view (1 when none is ahead)."""
    ahead = [-(Vector(o) - pos).dot(back) for o in objects]
    ahead = [d for d in ahead if d > 0]
    return sum(ahead) / len(ahead) if ahead else 1.0


def camera(scene, width, height, centres, warn):
    ob = scene.camera
    if ob is None or ob.type != "CAMERA":
        user_error("%s: the scene %r has no active camera; expected one" % (bpy.data.filepath, scene.name))
    cam = ob.data
    right, up, back, pos = camera_axes(ob)
    if cam.type == "PANO":
        user_error("%s: camera %r is panoramic; expected a perspective or orthographic camera"
                   % (bpy.data.filepath, ob.name))
    if cam.dof.use_dof:
        warn.add("depth of field not read (the scene's cameras are pinholes)", ob.name)
    d = look_distance(pos, back, centres)
    base = {"position": vec(pos), "look_at": vec(pos - back * d), "up": vec(up)}
    if cam.type == "ORTHO":
        fit_h = cam.sensor_fit == "VERTICAL" or (cam.sensor_fit == "AUTO" and height > width)
        if cam.shift_x or cam.shift_y:
            warn.add("orthographic lens shift not read", ob.name)
        return dict(base, type="orthographic",
                    height=cam.ortho_scale if fit_h else cam.ortho_scale * height / width)
    fx, fy, cx, cy, _ = intrinsics(cam, width, height, scene.render)
    if cam.shift_x == 0.0 and cam.shift_y == 0.0 and abs(fx - fy) <= 1e-9 * fx:
        return dict(base, type="perspective",
                    fov_y_deg=math.degrees(2.0 * math.atan(height / (2.0 * fy))))
    # OpenCV's camera: x right, y down, z forward; R maps world to camera
    to_world = Matrix((right, -up, -back)).transposed()
    rot = to_world.transposed()
    t = -(rot @ pos)
    return {"type": "pinhole", "fx": fx, "fy": fy, "cx": cx, "cy": cy,
            "rotation": rodrigues(rot), "translation": vec(t)}


# ---------------------------------------------------------------- lights
def light(inst, names, warn):
    ob = inst.object
    ld = ob.data
    m = TO_SCENE @ inst.matrix_world
    name = names.take(ob.original.get("scenefit_name", ob.name))
    out = {"name": name, "color": vec(ld.color)}
    if ld.use_nodes and ld.node_tree is not None and len(ld.node_tree.nodes) > 2:
        warn.add("light node trees not read (plain strength used)", ob.name)
    if ld.type == "SUN":
        axis = (m.to_3x3() @ Vector((0, 0, 1))).normalized()
        out.update(type="directional", direction=vec(axis), intensity=float(ld.energy),
                   radius=float(ld.angle) / 2.0)
        return out
    if ld.type == "SPOT":
        warn.add("spot lights read as point lights (cone and blend dropped)", ob.name)
    elif ld.type == "AREA":
        warn.add("area lights read as point lights of the same power at their centre", ob.name)
    # Cycles: a point light of power P gives P/(4 pi) W/sr (worker.py)
    out.update(type="point", position=vec(m.translation),
               intensity=float(ld.energy) / (4.0 * math.pi))
    radius = float(getattr(ld, "shadow_soft_size", 0.0))
    if ld.type == "AREA":
        radius = float(ld.size) / 2.0
    if radius > 0:
        out["radius"] = radius
    return out


# ---------------------------------------------------------------- materials
def linked_node(socket):
    return socket.links[0].from_node if socket.is_linked else None


def surface_node(mat):
    outs = [n for n in mat.node_tree.nodes if n.type == "OUTPUT_MATERIAL" and n.target in ("ALL", "CYCLES")]
    active = [n for n in outs if n.is_active_output] or outs
    return linked_node(active[0].inputs["Surface"]) if active else None


def texture_of(node, socket_name, ctx, where):
    """The color_map of an Image Texture linked to `socket_name`, or None."""
    tex = linked_node(node.inputs[socket_name])
    if tex is None:
        return None
    if tex.type != "TEX_IMAGE" or tex.image is None:
        ctx["warn"].add("node links into %s not read (its unlinked value used)" % socket_name, where)
        return None
    cmap = {"file": image_file(tex.image, ctx, where)}
    space = tex.image.colorspace_settings.name
    cmap["encoding"] = "srgb" if space == "sRGB" else "linear"
    if space not in ("sRGB", "Non-Color", "Linear", "Raw"):
        ctx["warn"].add("image colour spaces other than sRGB / linear read as linear", tex.image.name)
    mapping = linked_node(tex.inputs["Vector"])
    if mapping is not None and mapping.type == "MAPPING":
        sc = mapping.inputs["Scale"].default_value
        cmap["scale"] = [float(sc[0]), float(sc[1])]
        if any(mapping.inputs[k].is_linked for k in mapping.inputs.keys()) or \
                any(abs(x) > 0 for x in mapping.inputs["Location"].default_value) or \
                any(abs(x) > 0 for x in mapping.inputs["Rotation"].default_value):
            ctx["warn"].add("texture mapping other than a UV scale not read", where)
    elif mapping is not None and not (mapping.type == "TEX_COORD" or mapping.type == "UVMAP"):
        ctx["warn"].add("texture coordinates other than the UV map not read", where)
    if tex.interpolation != "Linear":
        ctx["warn"].add("image interpolation other than Linear read as bilinear", where)
    if tex.extension != "REPEAT":
        ctx["warn"].add("image extension other than REPEAT read as REPEAT", where)
    return cmap


def image_file(img, ctx, where):
    """The image's file, or a PNG copy beside the scene when it is packed,
    generated, or in a format scenefit does not read."""
    path = bpy.path.abspath(img.filepath, library=img.library) if img.filepath else ""
    ext = os.path.splitext(path)[1].lower()
    if img.packed_file is None and img.source == "FILE" and os.path.isfile(path) and ext in (".png", ".exr"):
        return os.path.abspath(path)
    dest = os.path.join(ctx["dir"], "%s.%s.png" % (ctx["stem"], Names().take(img.name)))
    w, h = img.size
    if w == 0 or h == 0:
        user_error("%s: image %r has no pixels Blender can read" % (bpy.data.filepath, img.name))
    copy = bpy.data.images.new("scenefit_copy", w, h, alpha=False, float_buffer=False)
    copy.colorspace_settings.name = "sRGB" if img.colorspace_settings.name == "sRGB" else "Non-Color"
    copy.pixels.foreach_set(pixels_of(img))
    copy.filepath_raw = dest
    copy.file_format = "PNG"
    copy.save()
    return dest


def pixels_of(img):
    import array
    buf = array.array("f", [0.0]) * (len(img.pixels))
    img.pixels.foreach_get(buf)
    return buf


def roughness_to_shininess(r):
    """The project's one mapping: roughness (2/(n+2))^(1/4) (docs/renderers.md)."""
    if r <= (2.0 / (MAX_SHININESS + 2.0)) ** 0.25:
        return MAX_SHININESS
    return 2.0 / r ** 4 - 2.0


def principled(p, ctx, where):
    warn = ctx["warn"]
    base = p.inputs["Base Color"].default_value
    out = {"color": [float(base[0]), float(base[1]), float(base[2])]}
    cmap = texture_of(p, "Base Color", ctx, where)
    if cmap is not None:
        out["color"] = [1.0, 1.0, 1.0]
        out["color_map"] = cmap
    for key, neutral in PRINCIPLED_UNUSED:
        if key in p.inputs and (p.inputs[key].is_linked or abs(p.inputs[key].default_value - neutral) > 1e-6):
            warn.add("Principled %s not read" % key, where)
    em = p.inputs.get("Emission")
    if em is not None and (em.is_linked or any(x > 0 for x in em.default_value[:3])) and \
            p.inputs["Emission Strength"].default_value > 0:
        warn.add("Principled Emission not read", where)
    if p.inputs["Normal"].is_linked:
        warn.add("normal and bump maps not read", where)
    for key in ("Specular", "Roughness", "Transmission", "IOR"):
        if p.inputs[key].is_linked:
            warn.add("node links into %s not read (its unlinked value used)" % key, where)
    level = float(p.inputs["Specular"].default_value)
    n = roughness_to_shininess(float(p.inputs["Roughness"].default_value))
    kt = float(p.inputs["Transmission"].default_value)
    if kt > 0.0:
        # glass: the backends' principled BSDF takes the level itself
        out.update(transmission=kt, ior=float(p.inputs["IOR"].default_value), specular=level,
                   shininess=n)
    elif level > 0.0:
        f0 = min(1.0, F0_PER_LEVEL * level)
        out.update(specular=f0, fresnel=f0, shininess=n)
    return out


def diffuse_bsdf(d, ctx, where):
    c = d.inputs["Color"].default_value
    out = {"color": [float(c[0]), float(c[1]), float(c[2])]}
    cmap = texture_of(d, "Color", ctx, where)
    if cmap is not None:
        out["color"] = [1.0, 1.0, 1.0]
        out["color_map"] = cmap
    if d.inputs["Roughness"].default_value > 0 or d.inputs["Roughness"].is_linked:
        ctx["warn"].add("Diffuse BSDF roughness (Oren-Nayar) read as Lambertian", where)
    return out


def material(mat, ctx):
    """A Blender material in the project's convention."""
    if mat is None:
        return {"color": [0.8, 0.8, 0.8]}  # Cycles' default surface
    if "scenefit_material" in mat:  # written by scenefit export
        return json.loads(mat["scenefit_material"])
    where = mat.name
    c = mat.diffuse_color
    fallback = {"color": [float(c[0]), float(c[1]), float(c[2])]}
    if not mat.use_nodes or mat.node_tree is None:
        ctx["warn"].add("materials without nodes read as their diffuse colour", where)
        return fallback
    node = surface_node(mat)
    if node is not None and node.type == "BSDF_PRINCIPLED":
        return principled(node, ctx, where)
    if node is not None and node.type == "BSDF_DIFFUSE":
        return diffuse_bsdf(node, ctx, where)
    kind = node.bl_idname if node is not None else "nothing"
    ctx["warn"].add("surface shaders other than Principled or Diffuse BSDF read as their "
                    "viewport colour (%s)" % kind, where)
    return fallback


# ---------------------------------------------------------------- meshes
MESH_TYPES = ("MESH", "CURVE", "SURFACE", "META", "FONT")


def placement(mw):
    """(transform JSON or None, matrix baked into the vertices or None) of
    a world matrix: translate / rotate_deg / scale when it is one (no shear,
    no mirroring), else the whole matrix baked into the file."""
    m = TO_SCENE @ mw @ TO_BLENDER
    loc, rot, sc = m.decompose()
    again = Matrix.LocRotScale(loc, rot, sc)
    size = max(1.0, max(abs(x) for row in m for x in row))
    exact = all(abs(a - b) <= 1e-6 * size for ra, rb in zip(m, again) for a, b in zip(ra, rb))
    if not exact or min(sc) <= 0.0 or m.determinant() <= 0.0:
        return None, m
    if all(abs(m[i][j] - (i == j)) <= 1e-12 for i in range(4) for j in range(4)):
        return None, None
    euler = rot.to_matrix().to_euler("XYZ")  # R = Rz Ry Rx, as the scene's rotate_deg
    scale = float(sc[0]) if max(sc) - min(sc) <= 1e-9 * max(sc) else vec(sc)
    return {"translate": vec(loc), "rotate_deg": [math.degrees(a) for a in euler],
            "scale": scale}, None


def corners(me, tris, bake):
    """Positions, normals and UVs (scene frame) of `tris`, each listed once,
    and per triangle corner its (position, uv, normal) indices."""
    uv_layers = [l for l in me.uv_layers if l.active_render] or list(me.uv_layers)
    uv = uv_layers[0].data if uv_layers else None
    conv = TO_SCENE if bake is None else bake @ TO_SCENE
    nconv = conv.to_3x3().inverted().transposed()
    lists = ([], [], [])
    index = ({}, {}, {})

    def at(k, key, value):
        i = index[k].get(key)
        if i is None:
            i = index[k][key] = len(lists[k])
            lists[k].append(value())
        return i
    faces = []
    for t in tris:
        face = []
        for k in range(3):
            vi, li = t.vertices[k], t.loops[k]
            n = tuple(round(x, 7) for x in t.split_normals[k])
            p = at(0, vi, lambda: tuple(conv @ me.vertices[vi].co))
            u = at(1, tuple(uv[li].uv), lambda: tuple(uv[li].uv)) if uv else None
            m = at(2, n, lambda: tuple((nconv @ Vector(n)).normalized()))
            face.append((p, u, m))
        faces.append(face)
    return lists, faces


def write_obj(path, name, lists, faces):
    """A Wavefront OBJ: v, vt, vn and triangles v/vt/vn. OBJ rather than
    PLY: Blender's PLY importer (3.x) drops normals, its OBJ importer keeps
    them, so the Blender backend draws smooth parts smooth."""
    pos, uvs, nrm = lists
    out = ["# written by scenefit import", "o " + name]
    out += ["v %.9g %.9g %.9g" % p for p in pos]
    out += ["vt %.9g %.9g" % u for u in uvs]
    out += ["vn %.9g %.9g %.9g" % n for n in nrm]
    out.append("s 1")
    for f in faces:
        out.append("f " + " ".join("%d/%s/%d" % (p + 1, "" if u is None else u + 1, m + 1)
                                   for p, u, m in f))
    with open(path, "w") as fh:
        fh.write("\n".join(out) + "\n")


def mesh_objects(inst, base, ctx):
    """The scene objects of one evaluated mesh instance: one per material
    slot its triangles use."""
    ob = inst.object
    me = ob.to_mesh()
    try:
        me.calc_loop_triangles()
        if hasattr(me, "calc_normals_split"):
            me.calc_normals_split()
        by_slot = {}
        for t in me.loop_triangles:
            by_slot.setdefault(t.material_index, []).append(t)
        if not by_slot:
            ctx["warn"].add("objects without faces not read", ob.name)
            return []
        transform, bake = placement(inst.matrix_world)
        out = []
        for slot, tris in sorted(by_slot.items()):
            mat = ob.material_slots[slot].material if slot < len(ob.material_slots) else None
            name = base if len(by_slot) == 1 else "%s_%s" % (base, mat.name if mat else slot)
            name = ctx["names"].take(name)
            lists, faces = corners(me, tris, bake)
            fname = "%s.%s.obj" % (ctx["stem"], name)
            write_obj(os.path.join(ctx["dir"], fname), name, lists, faces)
            o = {"name": name, "shape": {"type": "mesh", "file": fname}, "material": material(mat, ctx)}
            if transform is not None:
                o["transform"] = transform
            out.append(o)
        ctx["centres"].append(TO_SCENE @ inst.matrix_world @ (sum((Vector(c) for c in ob.bound_box), Vector()) / 8))
        return out
    finally:
        ob.to_mesh_clear()


# ---------------------------------------------------------------- world, render
def ambient(world, warn):
    """The world's light as the scene's ambient: a Background node's colour
    times its strength (or the world colour without nodes)."""
    if world is None:
        return [0.0, 0.0, 0.0]
    if not world.use_nodes or world.node_tree is None:
        amb = vec(world.color)
        hidden = False
    else:
        bgs = [n for n in world.node_tree.nodes if n.type == "BACKGROUND"]
        if not bgs:
            warn.add("world shaders without a Background node not read", world.name)
            return [0.0, 0.0, 0.0]
        if len(bgs) > 1 or bgs[0].inputs["Color"].is_linked or bgs[0].inputs["Strength"].is_linked:
            warn.add("world node graphs read as one Background colour times its strength", world.name)
        c, k = bgs[0].inputs["Color"].default_value, bgs[0].inputs["Strength"].default_value
        amb = [float(c[i]) * float(k) for i in range(3)]
        hidden = any(n.type == "LIGHT_PATH" for n in world.node_tree.nodes)
    if any(a > 0 for a in amb) and not hidden:
        warn.add("the world is seen behind the scene in Blender; scenefit's background is black", world.name)
    return amb


def render_settings(scene, warn):
    r = scene.render
    width = max(1, round(r.resolution_x * r.resolution_percentage / 100.0))
    height = max(1, round(r.resolution_y * r.resolution_percentage / 100.0))
    if r.engine != "CYCLES":
        warn.add("render engines other than Cycles (settings read as Cycles')", r.engine)
    c = scene.cycles
    v = scene.view_settings
    if v.view_transform != "Standard" or v.look != "None" or v.exposure != 0 or v.gamma != 1 \
            or v.use_curve_mapping:
        warn.add("colour management other than Standard, no look, exposure 0, gamma 1 not read",
                 v.view_transform)
    if c.pixel_filter_type != "BOX" or c.filter_width != 1.0:
        warn.add("pixel filters other than a 1-pixel box read as one (scenefit's renders use it)",
                 scene.name)
    if c.use_denoising or c.film_exposure != 1.0 or r.film_transparent or r.use_motion_blur:
        warn.add("denoising, film exposure, transparent film and motion blur not read", scene.name)
    out = {"samples": int(c.samples), "indirect": c.max_bounces > 0}
    return width, height, out


# ---------------------------------------------------------------- the scene
def instances(depsgraph):
    """(instance, base name) of every object the render shows."""
    for inst in depsgraph.object_instances:
        ob = inst.object
        owner = inst.parent if inst.is_instance else ob
        if owner.original.hide_render or ob.original.hide_render:
            continue
        base = ob.original.get("scenefit_name", ob.name)
        if inst.is_instance:
            base = "%s_%s" % (inst.parent.name, ob.name)
        yield inst, base


def read_scene(ctx):
    scene = bpy.context.scene
    depsgraph = bpy.context.evaluated_depsgraph_get()
    warn = ctx["warn"]
    lights, objects, light_names = [], [], Names()
    for inst, base in instances(depsgraph):
        ob = inst.object
        if ob.type == "LIGHT":
            lights.append(light(inst, light_names, warn))
        elif ob.type in MESH_TYPES:
            objects.extend(mesh_objects(inst, base, ctx))
        elif ob.type not in ("CAMERA", "EMPTY"):
            warn.add("objects of type %s not read" % ob.type, ob.name)
    width, height, render = render_settings(scene, warn)
    cam = camera(scene, width, height, ctx["centres"], warn)
    return {"format": "scenefit-scene/1", "image": {"width": width, "height": height},
            "camera": cam, "ambient": ambient(scene.world, warn), "render": render,
            "lights": lights, "objects": objects}


def main():
    argv = sys.argv
    rest = argv[argv.index("--") + 1:] if "--" in argv else []
    if len(rest) != 3:
        raise SystemExit("import_blend.py: expected RESULT.json OUT_DIR STEM after --")
    result, out_dir, stem = rest
    if not bpy.data.filepath:
        user_error("Blender could not load the file as a .blend")
    ctx = {"warn": Warnings(), "names": Names(), "dir": out_dir, "stem": stem, "centres": []}
    scene = read_scene(ctx)
    if not scene["objects"]:
        ctx["warn"].add("no object to fit: the scene has no mesh the render shows", bpy.context.scene.name)
    with open(result, "w") as f:
        json.dump({"scene": scene, "warnings": ctx["warn"].lines()}, f, indent=1)


if __name__ == "__main__":
    main()
