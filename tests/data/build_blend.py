"""The .blend of tests/interchange_blender.rs, built as a user would in
Blender: a UV sphere smooth-shaded above its equator and flat below, a
plane, a point and a sun light, a camera with lens shift, two Principled
BSDF materials (one with an 8x8 image texture on its base colour; not
with `plain`), Cycles with direct light only and a 1-pixel box filter.

    blender -b --factory-startup -P build_blend.py -- OUT.blend TEXTURE.png [plain]

`blender -b OUT.blend -f 1` then writes truth_0001.png beside OUT.blend.
"""
import math
import sys

import bmesh
import bpy

out, tex_path = sys.argv[sys.argv.index("--") + 1:][:2]
plain = "plain" in sys.argv
for o in list(bpy.data.objects):
    bpy.data.objects.remove(o, do_unlink=True)
s = bpy.context.scene
# a 8x8 checker texture, saved as a PNG file
img = bpy.data.images.new("checker", 8, 8, alpha=False)
px = []
for j in range(8):
    for i in range(8):
        c = (0.9, 0.7, 0.2) if (i + j) % 2 else (0.2, 0.4, 0.8)
        px.extend(c + (1.0,))
img.pixels = px
img.filepath_raw = tex_path
img.file_format = "PNG"
img.save()
def principled(name, color, spec, rough, texture=None):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = color + (1.0,)
    p.inputs["Specular"].default_value = spec
    p.inputs["Roughness"].default_value = rough
    if texture is not None:
        t = m.node_tree.nodes.new("ShaderNodeTexImage")
        t.image = bpy.data.images.load(texture)
        m.node_tree.links.new(t.outputs["Color"], p.inputs["Base Color"])
    return m
# a UV sphere, smooth-shaded above its equator, flat below
bm = bmesh.new()
bm.loops.layers.uv.new("UVMap")
bmesh.ops.create_uvsphere(bm, u_segments=32, v_segments=16, radius=0.8, calc_uvs=True)
me = bpy.data.meshes.new("Ball")
bm.to_mesh(me)
bm.free()
for p in me.polygons:
    p.use_smooth = p.center.z > 0
ball = bpy.data.objects.new("Ball", me)
ball.location = (0.3, 0.2, 0.8)
ball.rotation_euler = (0.2, 0.0, 0.5)
me.materials.append(principled("Checker", (0.8, 0.8, 0.8), 0.5, 0.4, None if plain else tex_path))
s.collection.objects.link(ball)
bpy.ops.mesh.primitive_plane_add(size=6.0)
plane = bpy.context.object
plane.name = "Floor"
plane.data.materials.append(principled("Grey", (0.5, 0.55, 0.6), 0.3, 0.6))
# a point and a sun light
pd = bpy.data.lights.new("Lamp", "POINT")
pd.energy = 600.0
pd.shadow_soft_size = 0.0
lo = bpy.data.objects.new("Lamp", pd)
lo.location = (2.0, -1.5, 3.5)
s.collection.objects.link(lo)
sd = bpy.data.lights.new("Sun", "SUN")
sd.energy = 1.5
sd.angle = 0.0
so = bpy.data.objects.new("Sun", sd)
so.rotation_euler = (0.6, 0.3, 0.0)
s.collection.objects.link(so)
# a camera with lens shift
cd = bpy.data.cameras.new("Cam")
cd.lens = 35.0
cd.shift_x = 0.06
cd.shift_y = -0.04
co = bpy.data.objects.new("Cam", cd)
co.location = (0.5, -5.0, 2.6)
co.rotation_euler = (math.radians(68), 0.0, math.radians(4))
s.collection.objects.link(co)
s.camera = co
s.world = None
r = s.render
r.engine = "CYCLES"
r.resolution_x, r.resolution_y, r.resolution_percentage = 96, 72, 100
r.filepath = "//truth_####.png"
r.image_settings.file_format = "PNG"
r.image_settings.color_mode = "RGB"
r.dither_intensity = 0.0
s.view_settings.view_transform = "Standard"
c = s.cycles
c.samples = 64
c.use_denoising = False
c.use_adaptive_sampling = False
c.max_bounces = 0
c.pixel_filter_type = "BOX"
c.filter_width = 1.0
bpy.ops.wm.save_as_mainfile(filepath=out)
