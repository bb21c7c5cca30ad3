"""scenefit Blender worker: renders scenefit-scene/1 JSON scenes with Cycles.

Run (persistent JSON-lines worker, docs/plugins.md; the protocol itself is
workers/jsonlines.py, found beside this script or in ../workers):

    blender -b --factory-startup -noaudio --python-exit-code 1 \
        -P blender_scripts/worker.py -- [--threads N] [--quiet]

Protocol
--------
At start the script keeps a private duplicate of fd 1 for protocol messages
and points fd 1 at fd 2 (``--quiet``: at /dev/null), so that everything
Blender/Cycles print after that goes to stderr.  NOTE: Blender itself prints
a banner line ("Blender 3.4.1") on stdout *before* this script runs; a
client must skip non-JSON lines until the ready line.  Options: --threads N
(default 1, 0 = automatic), --quiet.  SCENEFIT_WORKER_TIMING=1 in the
environment logs per-request timings to stderr.

    -> {"ready": true, "renderer": "blender 3.4.1"}
    <- {"id": 17, "scene": {...}, "output": "/path/17.png", "seed": 5}
    -> {"id": 17, "ok": true}      or   {"id": 17, "ok": false, "error": "..."}

"seed" is optional (default 0); unknown request keys are ignored.  A line
that is not JSON, or a scene that cannot be built, is answered with ok:false
(id null when it cannot be read) and the worker keeps serving.  EOF on stdin
ends the worker with exit code 0.  stderr carries Blender's render log and
must be drained (or redirected) by the client.

Scene -> Blender mapping (docs/renderers.md)
----------------------------------------------------
Coordinates: scene is right-handed, y up, metres; Blender is right-handed,
z up.  A scene point (x, y, z) becomes Blender (x, -z, y) (a +90 deg rotation
about x: no mirroring).

Camera
  perspective: sensor_fit VERTICAL, angle_y = fov_y_deg (vertical FOV).
  orthographic: sensor_fit VERTICAL, ortho_scale = height (vertical extent).
  pinhole: as perspective, from fx, fy, cx, cy (Worker._apply_pinhole:
    angle_y, pixel aspect, lens shift), placed by rotation and translation.
  Oriented from position / look_at / up (camera -Z looks at look_at, +Y is
  the component of `up` orthogonal to the view direction).  Clip range
  1e-4 .. 1e6 m.  Resolution image.width x image.height, 100 %, pixel
  aspect 1.
Lights (light objects are invisible to camera rays)
  point: POINT light at position, power P = 4*pi*I W (Cycles gives P/(4 pi)
    W/sr), colour = color, shadow_soft_size = radius (same total power).
    falloff_power p other than 2 (falloff "none" is p = 0): light node tree
    Light Falloff(Strength 1).Linear (= the distance d) ^ (2 - p) ->
    Emission strength, which turns Cycles' 1/d^2 into 1/d^p.
  directional: SUN with strength E (W/m^2), angle 2*radius (its angular
    diameter), colour = color, its emission direction is -direction.
Ambient
  World: Background(color = ambient, strength 1) seen by every ray except
  camera rays (Light Path "Is Camera Ray" -> empty shader = black).  World
  importance sampling is off when ambient is black.
Shapes
  sphere: a shared smooth-shaded UV-sphere mesh (128 segments x 64 rings,
    unit radius, vertices pushed out by 1/sqrt(cos(pi/128)) so the faceted
    silhouette straddles the true one); the object carries centre
    (location) and radius (uniform scale).  Silhouette error <= 1.5e-4 of
    the radius (under 0.01 px for a sphere 50 px in radius; measured: a
    40 px sphere covers 5026.0 px^2 against pi*40^2 = 5026.55).
  plane: a 2 km x 2 km quad (shared mesh), located at `point`, local +Z
    rotated onto `normal`.
  quad: its own 4-vertex mesh corner, corner+u, corner+u+v, corner+v.
  box: a shared flat-shaded unit cube [0,1]^3, location = min, scale = size.
  transform (an object's placement, scene_common.transform): every object
    is the child of an empty whose world matrix is that transform in
    Blender's frame (identity when absent), so the shape's own placement
    above is kept as it is.
  Cycles shades both sides of every face.
Materials (per object, linked to the object's material slot)
  specular = specular2 = reflection = transmission = 0 ("lambertian"):
    Diffuse BSDF (Lambertian), roughness 0, colour = diffuse*color.
  transmission = 0 ("phong", the built-in tracer's material, see
    Worker._phong_graph): Diffuse BSDF + two Glossy BSDFs (Ashikhmin-Shirley,
    Roughness (2/(n+2))^(1/4), colour ks (n+8)/(n+1) H.V max(N.L, N.V)
    F(H.V)/F0 computed per shading point for the first light, which makes
    each the normalised Blinn-Phong lobe ks (n+8)/(8 pi) (N.H)^n F/F0) + a
    sharp Glossy BSDF of colour `reflection`, added.
  transmission > 0 ("principled", glass): Principled BSDF (GGX), Base Color
    = diffuse*color, Metallic 0, Specular = clamp(specular, 0, 1), Roughness
    = (2/(shininess+2))^(1/4), Transmission = transmission, Transmission
    Roughness 0, IOR = ior; then Mix Shader (fac = reflection) with a white
    Glossy BSDF (GGX, roughness 0 = mirror).
Texture maps (color_map, specular_map, shininess_map, normal_map; docs/scene-format.md
  "Textures", in the "phong" graph; refused on glass)
  Each map an Image Texture (Linear = bilinear between texel centres,
    Repeat) of a float image of the values scenefit decodes (decoded_image:
    the sRGB curve and `range` applied here), at scenefit's (u, v) x scale
    (Worker._uv_socket: a sphere's longitude and latitude per shading
    point, a mapped plane turned so its local x, y are e_u, e_v, UV maps on
    a quad, the box template (box_uvs) and a mesh, a PLY's `u v` renamed
    `s t` for the importer: ply_with_st).  Diffuse colour = albedo x the
    colour map; per lobe ks x the specular map's red, the exponent the
    shininess map's red, the lobe's colour factor and roughness computed
    from them per shading point (Worker._map_graph).  Decoded images are
    kept for the worker's life.
  normal_map: a Normal Map node (tangent space about the UV map on a
    quad, box or mesh; object space on a plane, whose local axes are e_u,
    e_v, n, and on a sphere, its vector turned by the sphere's east,
    north and outward directions: Worker._sphere_frame) feeding the
    diffuse and glossy lobes and their colour factor; the mirror keeps the
    true normal (Worker._normal_map).
Render
  Cycles, CPU, samples = render.samples, adaptive sampling off, denoising
  off, pixel filter BOX width 1, seed = request seed (not animated), clamping
  off, light sampling threshold 0, no path guiding.  render.indirect true:
  8 bounces of every kind; false: all bounces 0 (direct light only).
  View transform Standard, look None, exposure 0, gamma 1, no curves, film
  exposure 1, dither 0, film not transparent.  Output PNG 8-bit RGB.
Reuse
  The built scene is kept.  If a request's scene has the same structure
  (camera type; lights by name, type and falloff kind inverse_square /
  custom; objects by name, shape type, material kind lambertian / phong
  / principled and texture maps' settings) as the previous one,
  only values are updated in place; otherwise every datablock the worker
  made is removed (bpy.data.*.remove) and the scene is rebuilt.  Cycles
  persistent data is on, so unchanged geometry (BVH) and shaders are kept
  between renders.
"""

import array
import json
import math
import os
import shutil
import struct
import sys
import tempfile
import time
import traceback

# Blender does not put a -P script's folder on sys.path: the protocol module
# and the shared scene reader (scene_common) sit beside this script (as
# scenefit writes them) or in the repository's workers/ folder.
_HERE = os.path.dirname(os.path.abspath(__file__))
for _dir in (os.path.join(_HERE, "..", "workers"), _HERE):
    if _dir not in sys.path:
        sys.path.insert(0, _dir)
import jsonlines  # noqa: E402
from scene_common import SceneError, describe, normalize, plane_axes, roughness  # noqa: E402

TIMING = bool(os.environ.get("SCENEFIT_WORKER_TIMING"))

# ---------------------------------------------------------------------------
# stdout discipline: keep a private protocol channel, send the noise away.
# ---------------------------------------------------------------------------


def _args_after_dashdash():
    argv = sys.argv
    return argv[argv.index("--") + 1:] if "--" in argv else []


def _parse_args(args):
    """--threads N (default 1; 0 = Blender's automatic count), --quiet."""
    opts = {"threads": 1, "quiet": False}
    i = 0
    while i < len(args):
        a = args[i]
        val = None
        if a == "--threads" and i + 1 < len(args):
            val = args[i + 1]
            i += 1
        elif a.startswith("--threads="):
            val = a.split("=", 1)[1]
        elif a == "--quiet":
            opts["quiet"] = True
        else:
            sys.stderr.write("worker.py: ignoring unknown argument %r\n" % a)
        if val is not None:
            try:
                opts["threads"] = max(0, int(val))
            except ValueError:
                sys.stderr.write("worker.py: bad --threads %r, using 1\n" % val)
        i += 1
    return opts


def log(*a):
    sys.stderr.write("worker.py: " + " ".join(str(x) for x in a) + "\n")
    sys.stderr.flush()


import bpy  # noqa: E402
import bmesh  # noqa: E402
from mathutils import Matrix, Vector  # noqa: E402

PREFIX = "sf_"  # every datablock this worker creates is named sf_*
# 128 x 64 keeps the silhouette within 1.5e-4 of the radius.  Cycles re-syncs
# a mesh whose object moves: a 256 x 128 sphere added ~0.03 s to each render
# that moved it, 128 x 64 adds ~0.007 s.
SPHERE_SEGMENTS = int(os.environ.get("SCENEFIT_SPHERE_SEGMENTS", 128))
SPHERE_RINGS = SPHERE_SEGMENTS // 2
PLANE_HALF = 1000.0  # the "infinite" plane is a 2 km quad


# ---------------------------------------------------------------------------
# Blender values (the scene is read by scene_common.describe, shared with the
# Mitsuba worker)
# ---------------------------------------------------------------------------


def _f32(x):
    return struct.unpack("f", struct.pack("f", x))[0]


def _set(owner, attr, value):
    """Assign only when the (float32) value changes: every RNA assignment tags
    the datablock for a depsgraph / Cycles update, even with an equal value."""
    cur = getattr(owner, attr)
    if isinstance(value, (int, float)):
        same = cur == _f32(value)
    else:
        value = tuple(value)
        same = len(cur) == len(value) and all(c == _f32(v) for c, v in zip(cur, value))
    if not same:
        setattr(owner, attr, value)


def B(p):
    """Scene (y up) point/vector -> Blender (z up)."""
    return Vector((p[0], -p[2], p[1]))


def _rot_z_to(direction, where):
    d = Vector(direction)
    if d.length < 1e-12:
        raise SceneError("zero-length direction in %s" % where)
    return d.normalized().to_track_quat("Z", "Y")


def fresh_nodes(owner, output_type):
    """Switches `owner` (world, light or material) to an empty node tree
    holding only a new output node of `output_type`; (tree, output)."""
    owner.use_nodes = True
    nt = owner.node_tree
    nt.nodes.clear()
    return nt, nt.nodes.new(output_type)


def falloff_kind(light):
    """inverse_square (Cycles' own), or custom: 1/d^p through a node tree."""
    if light["type"] != "point" or light["power"] == 2.0:
        return "inverse_square"
    return "custom"


def structure_of(desc):
    """The part of a described scene that decides which datablocks exist."""
    return (desc["camera"]["type"],
            tuple((L["name"], L["type"], falloff_kind(L)) for L in desc["lights"]),
            tuple((o["name"], o["shape"]["type"], o["material"]["kind"], o["shape"].get("file"),
                   map_signature(o["material"])) for o in desc["objects"]))


def import_mesh(path, name, where, mapped=False):
    """The mesh file scenefit read, imported with Blender's own importer as
    one mesh in Blender's frame (the scene's y up turned to z up, as B()),
    smooth-shaded when the file gives vertex normals; a mapped PLY with
    its texture coordinates however its header names them (ply_with_st)."""
    before = set(bpy.data.objects)
    tmp = tempfile.mkdtemp(prefix="scenefit_ply_") if mapped else None
    try:
        if path.lower().endswith(".obj"):
            bpy.ops.wm.obj_import(filepath=path, forward_axis="Y", up_axis="Z")
        else:
            bpy.ops.import_mesh.ply(filepath=ply_with_st(path, tmp) if mapped else path)
    except Exception as e:  # an importer reports a bad file as RuntimeError
        raise SceneError("%s: Blender could not import %s: %s" % (where, path, str(e).strip()))
    finally:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
    new = [o for o in bpy.data.objects if o not in before and o.type == "MESH"]
    if len(new) != 1:
        raise SceneError("%s: expected one mesh in %s, Blender imported %d" % (where, path, len(new)))
    me = new[0].data
    bpy.data.objects.remove(new[0], do_unlink=True)
    me.name = PREFIX + "mesh_" + name
    me.transform(Matrix.Rotation(math.pi / 2, 4, "X"))
    if not me.materials:
        me.materials.append(None)
    return me


# ---------------------------------------------------------------------------
# texture maps (docs/scene-format.md "Textures"; drawn in the phong graph)
# ---------------------------------------------------------------------------


def map_signature(m):
    """What of a material's maps decides the nodes built: every map's
    settings, and whether shininess2 follows a shininess map."""
    if not m["maps"]:
        return ()
    return (tuple(sorted((k, t["file"], t["encoding"], tuple(t["scale"]), tuple(t["range"]))
                         for k, t in m["maps"].items())), m["n2_own"])


def decoded_image(t, key):
    """The map file as a float image of scenefit's decoded values: the
    stored fractions (Non-Color: no colour management, 8 and 16 bits
    alike), through the sRGB curve when the encoding says so, then
    ``range``; alpha 1 (ignored). Decoded here, not by Cycles, because
    Cycles interpolates an sRGB byte image before decoding it. Plain
    Python (Blender's own Python may have no numpy): each distinct
    stored value is decoded once."""
    try:
        src = bpy.data.images.load(t["file"], check_existing=False)
    except RuntimeError as e:
        raise SceneError("%s: Blender cannot read %s: %s" % (key, t["file"], str(e).strip()))
    try:
        src.colorspace_settings.name = "Non-Color"
        src.reload()
        w, h = src.size
        px = array.array("f", bytes(4 * w * h * 4))
        src.pixels.foreach_get(px)
    finally:
        bpy.data.images.remove(src)
    lo, hi = t["range"]
    srgb = t["encoding"] == "srgb"
    memo = {}

    def decode(c):
        if srgb:
            c = c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4
        return lo + c * (hi - lo)
    for i in range(len(px)):
        if i % 4 == 3:
            px[i] = 1.0
            continue
        c = px[i]
        v = memo.get(c)
        if v is None:
            v = memo[c] = decode(c)
        px[i] = v
    img = bpy.data.images.new(PREFIX + "map_" + key, w, h, alpha=False, float_buffer=True, is_data=True)
    img.colorspace_settings.name = "Non-Color"
    img.pixels.foreach_set(px)
    img.use_fake_user = True
    return img


def ply_with_st(path, tmpdir):
    """A PLY file whose texture coordinates Blender's importer reads: it
    knows only ``s t``, so a header naming them ``u v`` or ``texture_u
    texture_v`` is copied into `tmpdir` with those names as ``s t`` (the
    body, ASCII or binary, unchanged). `path` itself when nothing to do."""
    with open(path, "rb") as f:
        head = f.read(65536)
        end = head.find(b"end_header")
        if end < 0:
            return path
        lines = head[:end].split(b"\n")
        names = [ln.split()[-1] for ln in lines if ln.startswith(b"property ")]
        if b"s" in names and b"t" in names:
            return path
        for a, b in ((b"u", b"v"), (b"texture_u", b"texture_v")):
            if a in names and b in names:
                break
        else:
            return path
        ren = {a: b"s", b: b"t"}
        out_lines = [ln.rsplit(b" ", 1)[0] + b" " + ren[ln.split()[-1]]
                     if ln.startswith(b"property ") and ln.split()[-1] in ren else ln for ln in lines]
        out = os.path.join(tmpdir, "uv.ply")
        with open(out, "wb") as g:
            g.write(b"\n".join(out_lines) + head[end:])
            while True:
                chunk = f.read(1 << 20)
                if not chunk:
                    break
                g.write(chunk)
    return out


def _math(nt, op, *args):
    """A Math node of `op` on `args`, each a socket, a node (its first
    output) or a number (the input's value)."""
    m = nt.nodes.new("ShaderNodeMath")
    m.operation = op
    for i, a in enumerate(args):
        if isinstance(a, bpy.types.Node):
            a = a.outputs[0]
        if isinstance(a, bpy.types.NodeSocket):
            nt.links.new(a, m.inputs[i])
        else:
            m.inputs[i].default_value = a
    return m


def box_uvs(me):
    """The unit cube template's texture coordinates, per face as a box's
    in src/scene/texture/uv.rs: a corner (a, b, c) of the cube in
    Blender's local frame is the fraction (x, y, z) = (a, c, 1 - b) of
    the box along the scene's axes (Worker._apply_shape: location min,
    scale size, y and z swapped)."""
    uv = me.uv_layers.new(name="UVMap")
    table = {(0, False): lambda x, y, z: (z, y), (0, True): lambda x, y, z: (1 - z, y),
             (1, False): lambda x, y, z: (x, z), (1, True): lambda x, y, z: (x, 1 - z),
             (2, False): lambda x, y, z: (1 - x, y), (2, True): lambda x, y, z: (x, y)}
    for p in me.polygons:
        nb = p.normal
        n = (nb.x, nb.z, -nb.y)  # in the scene's axes
        axis = max(range(3), key=lambda a: abs(n[a]))
        face = table[(axis, n[axis] > 0)]
        for li in p.loop_indices:
            a, b, c = me.vertices[me.loops[li].vertex_index].co
            uv.data[li].uv = face(a, c, 1.0 - b)


# ---------------------------------------------------------------------------
# the worker's Blender state
# ---------------------------------------------------------------------------


class Worker:
    def __init__(self, threads):
        self.threads = threads
        self.structure = None  # structure of the built scene, None = nothing valid
        self.cam_obj = None
        self.cam_key = None
        self.lights = []   # list of (light object, falloff node or None)
        self.objects = []  # list of dicts: obj, shape, mesh(own), nodes
        self.scene = bpy.context.scene
        self._wipe_factory_scene()
        self._setup_render_constants()
        self._setup_world()
        self._templates = {}
        self._map_images = {}  # (file, encoding, range) -> decoded image

    # -- one-time setup ---------------------------------------------------
    def _wipe_factory_scene(self):
        for o in list(bpy.data.objects):
            bpy.data.objects.remove(o, do_unlink=True)
        for coll in (bpy.data.meshes, bpy.data.materials, bpy.data.lights,
                     bpy.data.cameras, bpy.data.worlds):
            for d in list(coll):
                coll.remove(d)

    def _setup_render_constants(self):
        s = self.scene
        r = s.render
        r.engine = "CYCLES"
        c = s.cycles
        c.device = "CPU"
        c.feature_set = "SUPPORTED"
        c.use_adaptive_sampling = False
        c.use_denoising = False
        c.use_preview_denoising = False
        c.pixel_filter_type = "BOX"
        c.filter_width = 1.0
        c.use_animated_seed = False
        c.sample_clamp_direct = 0.0
        c.sample_clamp_indirect = 0.0
        c.light_sampling_threshold = 0.0
        c.blur_glossy = 0.0
        c.sample_offset = 0
        c.use_layer_samples = "IGNORE"
        c.film_exposure = 1.0
        c.use_fast_gi = False
        c.caustics_reflective = True
        c.caustics_refractive = True
        c.min_light_bounces = 0
        c.min_transparent_bounces = 0
        c.time_limit = 0.0
        c.use_camera_cull = False
        c.use_distance_cull = False
        if hasattr(c, "use_guiding"):
            c.use_guiding = False
        if hasattr(c, "use_light_tree"):  # Blender >= 3.5
            c.use_light_tree = False
        r.film_transparent = False
        r.use_persistent_data = True
        if self.threads > 0:
            r.threads_mode = "FIXED"
            r.threads = self.threads
        else:
            r.threads_mode = "AUTO"
        r.resolution_percentage = 100
        r.pixel_aspect_x = 1.0
        r.pixel_aspect_y = 1.0
        r.use_border = False
        r.use_motion_blur = False
        r.dither_intensity = 0.0
        r.use_compositing = False
        r.use_sequencer = False
        r.use_file_extension = False
        im = r.image_settings
        im.file_format = "PNG"
        im.color_mode = "RGB"
        im.color_depth = "8"
        im.compression = 0
        s.display_settings.display_device = "sRGB"
        v = s.view_settings
        v.view_transform = "Standard"
        v.look = "None"
        v.exposure = 0.0
        v.gamma = 1.0
        v.use_curve_mapping = False
        s.sequencer_colorspace_settings.name = "sRGB"
        s.frame_set(1)
        # the active view layer: keep only the combined pass
        vl = s.view_layers[0]
        vl.use_pass_combined = True
        vl.use_pass_z = False

    def _setup_world(self):
        w = bpy.data.worlds.new(PREFIX + "world")
        nt, out = fresh_nodes(w, "ShaderNodeOutputWorld")
        bg = nt.nodes.new("ShaderNodeBackground")
        lp = nt.nodes.new("ShaderNodeLightPath")
        mix = nt.nodes.new("ShaderNodeMixShader")
        bg.inputs["Strength"].default_value = 1.0
        nt.links.new(lp.outputs["Is Camera Ray"], mix.inputs[0])
        nt.links.new(bg.outputs["Background"], mix.inputs[1])
        # mix.inputs[2] left empty: camera rays see black
        nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])
        w.cycles.sampling_method = "MANUAL"
        w.cycles.sample_map_resolution = 32
        w.cycles.max_bounces = 1024
        self.scene.world = w
        self.world_bg = bg
        self.world = w

    def template(self, kind):
        """Shared meshes, created once and never removed."""
        me = self._templates.get(kind)
        if me is not None:
            return me
        bm = bmesh.new()
        if kind == "sphere":
            bmesh.ops.create_uvsphere(bm, u_segments=SPHERE_SEGMENTS,
                                      v_segments=SPHERE_RINGS, radius=1.0)
            # vertices lie on the unit sphere, faces inside it; push out so
            # the silhouette error is split evenly (about half the sagitta).
            k = 1.0 / math.cos(math.pi / SPHERE_SEGMENTS) ** 0.5
            for v in bm.verts:
                v.co *= k
            smooth = True
        elif kind == "plane":
            h = PLANE_HALF
            vs = [bm.verts.new(c) for c in ((-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0))]
            bm.faces.new(vs)
            smooth = False
        elif kind == "box":
            bmesh.ops.create_cube(bm, size=1.0)
            bmesh.ops.translate(bm, verts=bm.verts, vec=(0.5, 0.5, 0.5))
            smooth = False
        else:
            raise AssertionError(kind)
        me = bpy.data.meshes.new(PREFIX + "template_" + kind)
        bm.to_mesh(me)
        bm.free()
        if kind == "box":
            box_uvs(me)  # unused by an unmapped box
        for p in me.polygons:
            p.use_smooth = smooth
        me.materials.append(None)  # one slot; the material is linked per object
        me.use_fake_user = True
        self._templates[kind] = me
        return me

    # -- build / clear ------------------------------------------------------
    def clear(self):
        self.structure = None
        coll = self.scene.collection
        for o in list(coll.objects):
            bpy.data.objects.remove(o, do_unlink=True)
        for o in list(bpy.data.objects):
            bpy.data.objects.remove(o, do_unlink=True)
        templates = set(self._templates.values())
        for me in list(bpy.data.meshes):
            if me not in templates:
                bpy.data.meshes.remove(me)
        for coll_ in (bpy.data.materials, bpy.data.lights, bpy.data.cameras):
            for d in list(coll_):
                coll_.remove(d)
        self.cam_obj = None
        self.cam_key = None
        self.lights = []
        self.objects = []

    def build(self, structure):
        self.clear()
        coll = self.scene.collection
        cam_type, light_structs, obj_structs = structure

        # camera
        if cam_type not in ("perspective", "orthographic", "pinhole"):
            raise SceneError("camera.type must be 'perspective', 'orthographic' or 'pinhole', got %r" % (cam_type,))
        cd = bpy.data.cameras.new(PREFIX + "camera")
        cd.type = "ORTHO" if cam_type == "orthographic" else "PERSP"
        cd.sensor_fit = "VERTICAL"
        cd.clip_start = 1e-4
        cd.clip_end = 1e6
        cd.shift_x = cd.shift_y = 0.0
        cam = bpy.data.objects.new(PREFIX + "camera", cd)
        coll.objects.link(cam)
        self.scene.camera = cam
        self.cam_obj = cam

        # lights
        for i, (name, ltype, falloff) in enumerate(light_structs):
            where = "light '%s'" % name
            if ltype == "point":
                ld = bpy.data.lights.new(PREFIX + "light_" + name, "POINT")
            elif ltype == "directional":
                ld = bpy.data.lights.new(PREFIX + "light_" + name, "SUN")
            else:
                raise SceneError("%s: type must be 'point' or 'directional', got %r" % (where, ltype))
            fnode = None
            if falloff == "custom":
                # Cycles' light falls off as 1/d^2; Light Falloff's Linear
                # output is d, so strength d^(2-p) makes it 1/d^p.
                nt, out = fresh_nodes(ld, "ShaderNodeOutputLight")
                em = nt.nodes.new("ShaderNodeEmission")
                lf = nt.nodes.new("ShaderNodeLightFalloff")
                lf.inputs["Strength"].default_value = 1.0
                lf.inputs["Smooth"].default_value = 0.0
                fnode = nt.nodes.new("ShaderNodeMath")
                fnode.operation = "POWER"
                em.inputs["Color"].default_value = (1, 1, 1, 1)
                nt.links.new(lf.outputs["Linear"], fnode.inputs[0])
                nt.links.new(fnode.outputs["Value"], em.inputs["Strength"])
                nt.links.new(em.outputs["Emission"], out.inputs["Surface"])
            ld.cycles.cast_shadow = True
            ld.cycles.use_multiple_importance_sampling = True
            ld.cycles.max_bounces = 1024
            lo = bpy.data.objects.new(PREFIX + "light_" + name, ld)
            lo.rotation_mode = "QUATERNION"
            lo.visible_camera = False
            coll.objects.link(lo)
            self.lights.append((lo, fnode))

        # objects
        for i, (name, stype, mkind, file, maps) in enumerate(obj_structs):
            where = "object '%s'" % name
            own_mesh = None
            if stype in ("sphere", "plane", "box"):
                me = self.template(stype)
            elif stype == "quad":
                me = bpy.data.meshes.new(PREFIX + "quad_" + name)
                me.from_pydata([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [], [(0, 1, 2, 3)])
                # (s, t) of corner + s edge_u + t edge_v: affine, so exact
                uv = me.uv_layers.new(name="UVMap")
                for li, c in zip(range(4), ((0, 0), (1, 0), (1, 1), (0, 1))):
                    uv.data[li].uv = c
                me.materials.append(None)
                own_mesh = me
            elif stype == "mesh":
                me = import_mesh(file, name, where, mapped=bool(maps))
                if maps and not me.uv_layers:
                    raise SceneError("%s: Blender read no texture coordinates from %s" % (where, file))
                own_mesh = me
            else:
                raise SceneError("%s: shape.type %r is not drawn by Blender's worker (it draws sphere, plane, quad, box and mesh)" % (where, stype))
            ob = bpy.data.objects.new(PREFIX + "obj_" + name, me)
            ob.rotation_mode = "QUATERNION"
            coll.objects.link(ob)
            place = bpy.data.objects.new(PREFIX + "place_" + name, None)
            coll.objects.link(place)
            ob.parent = place
            mat, nodes = self._make_material(PREFIX + "mat_" + name, mkind)
            if maps:
                if mkind != "phong":
                    raise SceneError("%s: texture maps on a transmitting material are not drawn by blender; use phong" % where)
                self._map_graph(mat.node_tree, nodes, maps, stype)
            ob.material_slots[0].link = "OBJECT"
            ob.material_slots[0].material = mat
            self.objects.append({"obj": ob, "place": place, "shape": stype, "mesh": own_mesh,
                                 "kind": mkind, "nodes": nodes, "mat": mat, "mapped": bool(maps)})
        self.structure = structure

    def _make_material(self, name, kind):
        mat = bpy.data.materials.new(name)
        nt, out = fresh_nodes(mat, "ShaderNodeOutputMaterial")
        out.target = "ALL"
        nodes = {}
        if kind == "lambertian":
            d = nt.nodes.new("ShaderNodeBsdfDiffuse")
            d.inputs["Roughness"].default_value = 0.0
            nt.links.new(d.outputs["BSDF"], out.inputs["Surface"])
            nodes["diffuse"] = d
        elif kind == "phong":
            self._phong_graph(nt, out, nodes)
        else:
            p = nt.nodes.new("ShaderNodeBsdfPrincipled")
            p.distribution = "GGX"
            p.subsurface_method = "BURLEY"
            for k, v in (("Metallic", 0.0), ("Specular Tint", 0.0), ("Anisotropic", 0.0),
                         ("Sheen", 0.0), ("Clearcoat", 0.0), ("Subsurface", 0.0),
                         ("Transmission Roughness", 0.0), ("Alpha", 1.0)):
                if k in p.inputs:
                    p.inputs[k].default_value = v
            if "Emission Strength" in p.inputs:
                p.inputs["Emission Strength"].default_value = 0.0
            p.inputs["Emission"].default_value = (0, 0, 0, 1)
            g = nt.nodes.new("ShaderNodeBsdfGlossy")
            g.distribution = "GGX"
            g.inputs["Color"].default_value = (1, 1, 1, 1)
            g.inputs["Roughness"].default_value = 0.0
            mix = nt.nodes.new("ShaderNodeMixShader")
            nt.links.new(p.outputs["BSDF"], mix.inputs[1])
            nt.links.new(g.outputs["BSDF"], mix.inputs[2])
            nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])
            nodes["principled"] = p
            nodes["mix"] = mix
        return mat, nodes

    def _phong_graph(self, nt, out, nodes):
        """The built-in tracer's material: Diffuse (Lambertian) + two
        Ashikhmin-Shirley glossy lobes + a mirror, added.  Cycles' isotropic
        Ashikhmin-Shirley lobe with roughness r = (2/(n+2))^(1/4) is
        (n+1)/(8 pi) (N.H)^n / (H.V max(N.L, N.V)); its colour is set per
        shading point to  ks (n+8)/(n+1) H.V max(N.L, N.V) F(H.V)/F0  for L
        the direction to the scene's first light, which turns it into
        ks (n+8)/(8 pi) (N.H)^n F/F0 exactly for that light."""
        N = nt.nodes
        L = nt.links

        def vmath(op, a, b=None):
            v = N.new("ShaderNodeVectorMath")
            v.operation = op
            L.new(a, v.inputs[0])
            if b is not None:
                L.new(b, v.inputs[1])
            return v

        def math(op, a=None, b=None):
            m = N.new("ShaderNodeMath")
            m.operation = op
            for i, x in enumerate((a, b)):
                if x is not None:
                    L.new(x, m.inputs[i])
            return m

        geo = N.new("ShaderNodeNewGeometry")
        at = N.new("ShaderNodeCombineXYZ")  # light position, or its direction
        # point light: L = at - P; directional: L = at (weight 0 on P)
        wp = vmath("SCALE", geo.outputs["Position"])
        d = vmath("SUBTRACT", at.outputs["Vector"], wp.outputs["Vector"])
        lv = vmath("NORMALIZE", d.outputs["Vector"])
        h = vmath("NORMALIZE", vmath("ADD", lv.outputs["Vector"], geo.outputs["Incoming"]).outputs["Vector"])
        hv = vmath("DOT_PRODUCT", h.outputs["Vector"], geo.outputs["Incoming"])
        nl = vmath("DOT_PRODUCT", geo.outputs["Normal"], lv.outputs["Vector"])
        nv = vmath("DOT_PRODUCT", geo.outputs["Normal"], geo.outputs["Incoming"])
        mx = math("MAXIMUM", nl.outputs["Value"], nv.outputs["Value"])
        one_minus = math("SUBTRACT", None, hv.outputs["Value"])
        one_minus.inputs[0].default_value = 1.0
        p5 = math("POWER", one_minus.outputs["Value"])
        p5.inputs[1].default_value = 5.0
        fr = math("MULTIPLY_ADD", p5.outputs["Value"])  # 1 + (1-F0)/F0 (1-H.V)^5
        fr.inputs[2].default_value = 1.0
        base = math("MULTIPLY", hv.outputs["Value"], mx.outputs["Value"])
        base = math("MULTIPLY", base.outputs["Value"], fr.outputs["Value"])
        diffuse = N.new("ShaderNodeBsdfDiffuse")
        diffuse.inputs["Roughness"].default_value = 0.0
        shader = diffuse.outputs["BSDF"]
        lobes = []
        for _ in range(2):
            k = math("MULTIPLY", base.outputs["Value"])
            g = N.new("ShaderNodeBsdfGlossy")
            g.distribution = "ASHIKHMIN_SHIRLEY"
            L.new(k.outputs["Value"], g.inputs["Color"])
            add = N.new("ShaderNodeAddShader")
            L.new(shader, add.inputs[0])
            L.new(g.outputs["BSDF"], add.inputs[1])
            shader = add.outputs["Shader"]
            lobes.append((k, g))
        mirror = N.new("ShaderNodeBsdfGlossy")
        mirror.distribution = "SHARP"
        add = N.new("ShaderNodeAddShader")
        L.new(shader, add.inputs[0])
        L.new(mirror.outputs["BSDF"], add.inputs[1])
        L.new(add.outputs["Shader"], out.inputs["Surface"])
        nodes.update({"diffuse": diffuse, "at": at, "weight": wp, "fresnel": fr,
                      "lobes": lobes, "mirror": mirror})


    # -- texture maps -------------------------------------------------------
    def map_image(self, t, key):
        """A map's decoded image, once per worker (kept across rebuilds)."""
        k = (t["file"], t["encoding"], tuple(t["range"]))
        if k not in self._map_images:
            self._map_images[k] = decoded_image(t, key)
        return self._map_images[k]

    def _uv_socket(self, nt, stype):
        """scenefit's (u, v) at the shading point, as x and y of a vector:
        a sphere's longitude and latitude from its object coordinates
        (Blender's local x, y, z are the scene's x, -z, y, so u =
        atan2(y, x) / 2 pi, v = 1/2 + asin(z) / pi, per point, no seam),
        a mapped plane's object x and y (its local axes are e_u and e_v:
        _apply_shape), the UV map of a quad, a box or a mesh."""
        N, L = nt.nodes, nt.links
        tc = N.new("ShaderNodeTexCoord")
        if stype == "plane":
            return tc.outputs["Object"]
        if stype != "sphere":
            return tc.outputs["UV"]
        d = N.new("ShaderNodeVectorMath")
        d.operation = "NORMALIZE"
        L.new(tc.outputs["Object"], d.inputs[0])
        xyz = N.new("ShaderNodeSeparateXYZ")
        L.new(d.outputs["Vector"], xyz.inputs[0])
        lon = _math(nt, "ARCTAN2", xyz.outputs["Y"], xyz.outputs["X"])
        lat = _math(nt, "ARCSINE", xyz.outputs["Z"])
        uv = N.new("ShaderNodeCombineXYZ")
        L.new(_math(nt, "MULTIPLY", lon, 0.5 / math.pi).outputs[0], uv.inputs[0])
        L.new(_math(nt, "MULTIPLY_ADD", lat, 1.0 / math.pi, 0.5).outputs[0], uv.inputs[1])
        return uv.outputs["Vector"]

    def _map_lookup(self, nt, uv, t, key, red):
        """An Image Texture of the decoded map (Linear = bilinear between
        texel centres, Repeat) at (u, v) x scale; its colour, or its red."""
        N, L = nt.nodes, nt.links
        sc = N.new("ShaderNodeVectorMath")
        sc.operation = "MULTIPLY"
        L.new(uv, sc.inputs[0])
        sc.inputs[1].default_value = (t["scale"][0], t["scale"][1], 1.0)
        tex = N.new("ShaderNodeTexImage")
        tex.image = self.map_image(t, key)
        tex.interpolation = "Linear"
        tex.extension = "REPEAT"
        L.new(sc.outputs["Vector"], tex.inputs["Vector"])
        if not red:
            return tex.outputs["Color"]
        # the red channel itself (a colour used as a number is its luminance)
        sep = N.new("ShaderNodeSeparateRGB")
        L.new(tex.outputs["Color"], sep.inputs[0])
        return sep.outputs["R"]

    def _map_graph(self, nt, nodes, sig, stype):
        """The maps in the phong graph (_phong_graph): diffuse colour =
        albedo x the colour map; per lobe, ks x the specular map's red and
        the exponent n = the shininess map's red (the second lobe's too
        when shininess2 follows), its colour factor ks (n+8)/(n+1) and
        roughness (2/(n+2))^(1/4) computed per shading point as
        _apply_phong computes them from the scalars."""
        maps, n2_own = {k: {"file": f, "encoding": e, "scale": s, "range": r}
                        for k, f, e, s, r in sig[0]}, sig[1]
        uv = self._uv_socket(nt, stype)
        if "color_map" in maps:
            mul = nt.nodes.new("ShaderNodeVectorMath")
            mul.operation = "MULTIPLY"
            nt.links.new(self._map_lookup(nt, uv, maps["color_map"], "color_map", False), mul.inputs[1])
            nt.links.new(mul.outputs["Vector"], nodes["diffuse"].inputs["Color"])
            nodes["albedo_mul"] = mul
        spec = self._map_lookup(nt, uv, maps["specular_map"], "specular_map", True) if "specular_map" in maps else 1.0
        shin = self._map_lookup(nt, uv, maps["shininess_map"], "shininess_map", True) if "shininess_map" in maps else None
        if "normal_map" in maps:
            self._normal_map(nt, nodes, uv, maps["normal_map"], stype)
        nodes["mapped_lobes"] = []
        for j, (k, g) in enumerate(nodes["lobes"]):
            ks = _math(nt, "MULTIPLY", 0.0, spec)
            n = _math(nt, "ADD", shin if shin is not None and (j == 0 or not n2_own) else 0.0, 0.0)
            f = _math(nt, "DIVIDE", _math(nt, "ADD", n, 8.0), _math(nt, "ADD", n, 1.0))
            nt.links.new(_math(nt, "MULTIPLY", ks, f).outputs[0], k.inputs[1])
            r = _math(nt, "POWER", _math(nt, "DIVIDE", 2.0, _math(nt, "ADD", n, 2.0)), 0.25)
            nt.links.new(r.outputs[0], g.inputs["Roughness"])
            nodes["mapped_lobes"].append((ks, n))

    def _normal_map(self, nt, nodes, uv, t, stype):
        """The normal map (tangent space, OpenGL +Y, linear) as the shading
        normal of the diffuse and glossy lobes and of the lobes' colour
        factor (the mirror keeps the true normal, as the built-in tracer
        does): a Normal Map node in tangent space about the UV map (quad,
        box, mesh); in object space for a plane (its local x, y, z are
        e_u, e_v, n) and for a sphere, whose vector is turned here into
        its east, north and outward directions (_sphere_frame)."""
        N, L = nt.nodes, nt.links
        color = self._map_lookup(nt, uv, t, "normal_map", False)
        nm = N.new("ShaderNodeNormalMap")
        if stype == "sphere":
            nm.space = "OBJECT"
            color = self._sphere_frame(nt, color)
        elif stype == "plane":
            nm.space = "OBJECT"
        else:
            nm.space = "TANGENT"  # the default (active) UV map
        L.new(color, nm.inputs["Color"])
        normal = nm.outputs["Normal"]
        L.new(normal, nodes["diffuse"].inputs["Normal"])
        for _, g in nodes["lobes"]:
            L.new(normal, g.inputs["Normal"])
        geo = next(n for n in N if n.bl_idname == "ShaderNodeNewGeometry")
        for link in [lk for lk in nt.links if lk.from_socket == geo.outputs["Normal"]]:
            L.new(normal, link.to_socket)

    def _sphere_frame(self, nt, color):
        """A tangent-space map value (colour in [0, 1]) on the sphere as
        the object-space one: m = 2 c - 1, then m.x T + m.y B + m.z N with
        N the unit object position, T = (-N.y, N.x, 0) normalised (east:
        the way scenefit's u grows, Blender's local axes being the
        scene's x, -z, y) and B = N x T (north); back to [0, 1]."""
        N, L = nt.nodes, nt.links

        def vec(op, a, b=None):
            v = N.new("ShaderNodeVectorMath")
            v.operation = op
            L.new(a, v.inputs[0])
            if b is not None:
                L.new(b, v.inputs[1])
            return v.outputs["Vector"]
        tc = N.new("ShaderNodeTexCoord")
        n = vec("NORMALIZE", tc.outputs["Object"])
        ns = N.new("ShaderNodeSeparateXYZ")
        L.new(n, ns.inputs[0])
        east = N.new("ShaderNodeCombineXYZ")
        L.new(_math(nt, "MULTIPLY", ns.outputs["Y"], -1.0).outputs[0], east.inputs[0])
        L.new(ns.outputs["X"], east.inputs[1])
        tv = vec("NORMALIZE", east.outputs["Vector"])
        bv = vec("CROSS_PRODUCT", n, tv)
        m = N.new("ShaderNodeSeparateXYZ")
        L.new(self._affine(nt, color, 2.0, -1.0), m.inputs[0])
        out = vec("ADD", vec("ADD", self._scaled(nt, tv, m.outputs["X"]), self._scaled(nt, bv, m.outputs["Y"])),
                  self._scaled(nt, n, m.outputs["Z"]))
        return self._affine(nt, out, 0.5, 0.5)

    @staticmethod
    def _affine(nt, v, a, b):
        """The vector socket `v` times `a` plus `b` (per component)."""
        s = nt.nodes.new("ShaderNodeVectorMath")
        s.operation = "MULTIPLY_ADD"
        nt.links.new(v, s.inputs[0])
        s.inputs[1].default_value = (a, a, a)
        s.inputs[2].default_value = (b, b, b)
        return s.outputs["Vector"]

    @staticmethod
    def _scaled(nt, v, k):
        """The vector socket `v` times the value socket `k`."""
        s = nt.nodes.new("ShaderNodeVectorMath")
        s.operation = "SCALE"
        nt.links.new(v, s.inputs[0])
        nt.links.new(k, s.inputs["Scale"])
        return s.outputs["Vector"]

    # -- values -------------------------------------------------------------
    def apply(self, desc):
        """Sets every value of the described scene (scene_common.describe)."""
        s = self.scene
        r = s.render
        if r.resolution_x != desc["width"]:
            r.resolution_x = desc["width"]
        if r.resolution_y != desc["height"]:
            r.resolution_y = desc["height"]
        c = s.cycles
        nb = 8 if desc["indirect"] else 0
        for attr, val in (("samples", desc["samples"]), ("max_bounces", nb), ("diffuse_bounces", nb),
                          ("glossy_bounces", nb), ("transmission_bounces", nb),
                          ("transparent_max_bounces", nb), ("volume_bounces", 0)):
            if getattr(c, attr) != val:
                setattr(c, attr, val)
        self._apply_camera(desc["camera"])

        # ambient
        amb = desc["ambient"]
        _set(self.world_bg.inputs["Color"], "default_value", (amb[0], amb[1], amb[2], 1.0))
        want = "MANUAL" if any(a != 0.0 for a in amb) else "NONE"
        if self.world.cycles.sampling_method != want:
            self.world.cycles.sampling_method = want

        for (lo, fnode), L in zip(self.lights, desc["lights"]):
            self._apply_light(lo, fnode, L)
        for ent, o in zip(self.objects, desc["objects"]):
            self._apply_place(ent["place"], o["transform"])
            self._apply_shape(ent, o["shape"], "object '%s'" % o["name"])
            self._apply_material(ent, o["material"], desc["lights"])

    def _apply_pinhole(self, cam):
        """A calibrated pinhole (scene_common.pinhole): Blender's camera
        looks along its -Z with +Y up, OpenCV's along +z with y down, so its
        world matrix is B [R^T diag(1, -1, -1) | centre]. Sensor fit
        VERTICAL: angle_y = 2 atan(H / (2 fy)); fx other than fy through the
        pixel aspect (fx/fy = aspect_y / aspect_x, each at least 1); the
        principal point through the lens shift, in units of the fitted
        axis (ycor H pixels, ycor = fx/fy): shift_x = (W/2 - 1/2 - cx) /
        (ycor H), shift_y = (cy + 1/2 - H/2) / H."""
        rt = cam["to_world"]
        cols = [Vector(tuple(rt[i][j] for i in range(3))) for j in range(3)]
        m = Matrix((B(cols[0]), B(-cols[1]), B(-cols[2]))).transposed().to_4x4()
        m.translation = B(cam["centre"])
        key = (tuple(map(tuple, rt)), tuple(cam["centre"]))
        if self.cam_key != key:
            self.cam_obj.matrix_world = m
            self.cam_key = key
        r = self.scene.render
        w, h = r.resolution_x, r.resolution_y
        ycor = cam["fx"] / cam["fy"]
        _set(r, "pixel_aspect_x", max(1.0, 1.0 / ycor))
        _set(r, "pixel_aspect_y", max(1.0, ycor))
        cd = self.cam_obj.data
        _set(cd, "angle_y", 2.0 * math.atan(h / (2.0 * cam["fy"])))
        _set(cd, "shift_x", (w / 2.0 - 0.5 - cam["cx"]) / (ycor * h))
        _set(cd, "shift_y", (cam["cy"] + 0.5 - h / 2.0) / h)

    def _apply_camera(self, cam):
        if cam["type"] == "pinhole":
            self._apply_pinhole(cam)
            return
        r = self.scene.render
        _set(r, "pixel_aspect_x", 1.0)
        _set(r, "pixel_aspect_y", 1.0)
        pos = B(cam["position"])
        look = B(cam["look_at"])
        up = B(cam["up"])
        f = look - pos
        if f.length < 1e-12:
            raise SceneError("camera.position equals camera.look_at")
        f.normalize()
        right = f.cross(up)
        if right.length < 1e-9:
            raise SceneError("camera.up is parallel to the view direction")
        right.normalize()
        tup = right.cross(f)
        m = Matrix((right, tup, -f)).transposed().to_4x4()
        m.translation = pos
        if self.cam_key != (tuple(pos), tuple(look), tuple(up)):
            self.cam_obj.matrix_world = m
            self.cam_key = (tuple(pos), tuple(look), tuple(up))
        cd = self.cam_obj.data
        if cd.type == "PERSP":
            fov = cam["fov_y"]
            if abs(cd.angle_y - math.radians(fov)) > 1e-7 * math.radians(fov):
                cd.angle_y = math.radians(fov)
        else:
            _set(cd, "ortho_scale", cam["height"])

    def _apply_light(self, lo, fnode, L):
        ld = lo.data
        _set(ld, "color", L["color"])
        if ld.type == "POINT":
            _set(lo, "location", B(L["position"]))
            _set(ld, "energy", 4.0 * math.pi * L["intensity"])
            _set(ld, "shadow_soft_size", L["radius"])
            if fnode is not None:
                _set(fnode.inputs[1], "default_value", 2.0 - L["power"])
        else:
            d = B(L["direction"])
            _set(lo, "rotation_quaternion", _rot_z_to(d, "light '%s'" % L["name"]))
            _set(ld, "energy", L["intensity"])
            # the sun's angle is its angular diameter
            _set(ld, "angle", 2.0 * L["radius"])

    def _apply_place(self, place, t):
        """The object's transform in Blender's frame: B t B^-1 with
        B (x, y, z) -> (x, -z, y)."""
        m = Matrix.Identity(4)
        if t is not None:
            b = Matrix(((1, 0, 0, 0), (0, 0, -1, 0), (0, 1, 0, 0), (0, 0, 0, 1)))
            m = b @ Matrix(t) @ b.inverted()
        if place.matrix_world != m:
            place.matrix_world = m

    def _apply_shape(self, ent, sh, where):
        ob = ent["obj"]
        st = ent["shape"]
        if st == "sphere":
            rad = sh["radius"]
            _set(ob, "location", B(sh["center"]))
            _set(ob, "scale", (rad, rad, rad))
        elif st == "plane":
            _set(ob, "location", B(sh["point"]))
            if ent["mapped"]:
                # local x, y = the texture axes e_u, e_v: object coordinates are (u, v)
                eu, ev = plane_axes(sh["normal"])
                n = normalize(sh["normal"], where + ".normal")
                rot = Matrix((B(eu), B(ev), B(n))).transposed().to_quaternion()
                _set(ob, "rotation_quaternion", rot)
            else:
                _set(ob, "rotation_quaternion", _rot_z_to(B(sh["normal"]), where))
        elif st == "box":
            lo_, hi = sh["min"], sh["max"]
            _set(ob, "location", (lo_[0], -hi[2], lo_[1]))
            # a near-zero extent would make a singular matrix; keep it tiny instead
            _set(ob, "scale", (max(hi[0] - lo_[0], 1e-9), max(hi[2] - lo_[2], 1e-9),
                              max(hi[1] - lo_[1], 1e-9)))
        elif st == "quad":
            c0 = B(sh["corner"])
            u = B(sh["edge_u"])
            v = B(sh["edge_v"])
            co = []
            for p in (c0, c0 + u, c0 + u + v, c0 + v):
                co.extend(p)
            me = ent["mesh"]
            old = [0.0] * 12
            me.vertices.foreach_get("co", old)
            if any(abs(a - b) > 0 for a, b in zip(old, co)):
                me.vertices.foreach_set("co", co)
                me.update()

    def _apply_material(self, ent, m, lights):
        a = m["albedo"]
        base = (a[0], a[1], a[2], 1.0)
        nodes = ent["nodes"]
        if ent["kind"] == "lambertian":
            _set(nodes["diffuse"].inputs["Color"], "default_value", base)
            return
        if ent["kind"] == "phong":
            self._apply_phong(nodes, m, base, lights)
            return
        p = nodes["principled"]
        _set(p.inputs["Base Color"], "default_value", base)
        _set(p.inputs["Specular"], "default_value", min(1.0, max(0.0, m["ks"])))
        _set(p.inputs["Roughness"], "default_value", roughness(m["n"]))
        _set(p.inputs["Transmission"], "default_value", min(1.0, max(0.0, m["kt"])))
        _set(p.inputs["IOR"], "default_value", m["ior"])
        _set(nodes["mix"].inputs[0], "default_value", min(1.0, max(0.0, m["kr"])))

    def _apply_phong(self, nodes, m, base, lights):
        f0 = m["f0"]
        _set(nodes["diffuse"].inputs["Color"], "default_value", base)
        if "albedo_mul" in nodes:
            _set(nodes["albedo_mul"].inputs[0], "default_value", base[:3])
        for (ks_node, n_node), (ks_, n_) in zip(nodes.get("mapped_lobes", ()),
                                                ((m["ks"], m["n"]), (m["ks2"], m["n2"]))):
            _set(ks_node.inputs[0], "default_value", max(ks_, 0.0))
            if not n_node.inputs[0].is_linked:
                _set(n_node.inputs[0], "default_value", n_)
        _set(nodes["fresnel"].inputs[1], "default_value", (1.0 - f0) / f0)
        for (k, g), (ks_, n_) in zip(nodes["lobes"], ((m["ks"], m["n"]), (m["ks2"], m["n2"]))):
            _set(k.inputs[1], "default_value", max(ks_, 0.0) * (n_ + 8.0) / (n_ + 1.0))
            _set(g.inputs["Roughness"], "default_value", roughness(n_))
        kr = min(max(m["kr"], 0.0), 1.0)
        _set(nodes["mirror"].inputs["Color"], "default_value", (kr, kr, kr, 1.0))
        # the lobe is exact for the first light (the usual single key light)
        at, w = (0.0, 1.0, 0.0), 0.0
        if lights:
            l0 = lights[0]
            if l0["type"] == "point":
                at, w = B(l0["position"]), 1.0
            else:
                at = B(l0["direction"])
        for i, c in enumerate(at):
            _set(nodes["at"].inputs[i], "default_value", c)
        _set(nodes["weight"].inputs["Scale"], "default_value", w)

    # -- one request ------------------------------------------------------
    def render(self, scene, output, seed, raw=False):
        # `raw` (raw pixels welcome) is declined: in background mode the
        # Render Result's pixels are not readable without a compositor
        # round trip, and the PNG (compression 0) costs ~1 ms of a
        # ~150 ms render (measured, SCENEFIT_WORKER_TIMING=1); the answer
        # then carries no "pixels" and scenefit decodes the PNG.
        t0 = time.perf_counter()
        desc = describe(scene)
        structure = structure_of(desc)
        if structure != self.structure:
            try:
                self.build(structure)
            except Exception:
                self.clear()
                raise
        try:
            self.apply(desc)
        except Exception:
            # values may be half-applied; force a rebuild next time
            self.structure = None
            raise
        if self.scene.cycles.seed != seed:
            self.scene.cycles.seed = seed
        t1 = time.perf_counter()
        out = os.path.abspath(output)
        d = os.path.dirname(out)
        if d and not os.path.isdir(d):
            os.makedirs(d, exist_ok=True)
        bpy.ops.render.render(write_still=False)
        t2 = time.perf_counter()
        img = bpy.data.images.get("Render Result")
        if img is None:
            raise RuntimeError("Blender produced no render result")
        img.save_render(out, scene=self.scene)
        if TIMING:
            log("timing build+apply %.4f render %.4f save %.4f" % (t1 - t0, t2 - t1, time.perf_counter() - t2))
            log("datablocks objects %d meshes %d materials %d lights %d cameras %d images %d"
                % (len(bpy.data.objects), len(bpy.data.meshes), len(bpy.data.materials),
                   len(bpy.data.lights), len(bpy.data.cameras), len(bpy.data.images)))
        if not os.path.isfile(out):
            raise RuntimeError("Blender did not write %s" % out)


def main():
    opts = _parse_args(_args_after_dashdash())
    channel = jsonlines.Channel(opts["quiet"])
    try:
        worker = Worker(opts["threads"])
    except Exception as e:
        traceback.print_exc()
        channel.failed("worker setup failed: %s" % e)
        sys.exit(1)
    channel.ready("blender " + bpy.app.version_string)
    # Cycles' seed is a non-negative int32.
    channel.serve(lambda scene, output, seed, raw: worker.render(scene, output, seed % 2147483647, raw))
    sys.stdout.flush()
    channel.close()
    # returning lets Blender quit normally, with exit code 0


if __name__ == "__main__":
    main()
