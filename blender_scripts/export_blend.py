"""scenefit export --to blender: a scenefit-scene/1 scene saved as a .blend
that renders as scenefit's Blender backend renders it (docs/interchange.md,
"Blender").

Run by scenefit (src/interchange/blend_export.rs), with worker.py,
scene_common.py and jsonlines.py beside this script:

    blender -b --factory-startup -noaudio --python-exit-code 1 \
        -P export_blend.py -- SCENE.json OUT.blend

The scene is built by the Blender worker's own code (worker.Worker.build and
apply: one translation of a scene for Blender, not two), then:

- a material's `color_map` (the one map the worker does not draw) becomes an
  Image Texture on the diffuse colour, through the mesh's UV map;
- every image is packed into the .blend; meshes are datablocks in it;
- each object, light and material carries a custom property (scenefit_name,
  scenefit_material) so that `scenefit import` reads back the names and
  the material values (the worker's Blinn-Phong node graph has no
  Principled equivalent);
- render threads are Blender's automatic count, the output path
  //OUT_####.png (`blender -b OUT.blend -f 1` writes OUT_0001.png beside it).
"""

import json
import os
import sys

_HERE = os.path.dirname(os.path.abspath(__file__))
for _dir in (os.path.join(_HERE, "..", "workers"), _HERE):
    if _dir not in sys.path:
        sys.path.insert(0, _dir)

import bpy  # noqa: E402
import worker  # noqa: E402  (the backend's scene build)
from scene_common import describe, named_entries  # noqa: E402


def _args():
    argv = sys.argv
    rest = argv[argv.index("--") + 1:] if "--" in argv else []
    if len(rest) != 2:
        raise SystemExit("export_blend.py: expected SCENE.json OUT.blend after --")
    return rest


def color_map_nodes(mat, socket, albedo, cmap):
    """Diffuse colour = albedo x the image, looked up by the UV map with the
    map's `scale` (u, v repeat per unit), as scenefit's color_map."""
    nt = mat.node_tree
    N, L = nt.nodes, nt.links
    img = bpy.data.images.load(cmap["file"], check_existing=True)
    img.colorspace_settings.name = "sRGB" if cmap["encoding"] == "srgb" else "Non-Color"
    img.alpha_mode = "NONE"
    uv = N.new("ShaderNodeTexCoord")
    mapping = N.new("ShaderNodeMapping")
    mapping.inputs["Scale"].default_value = (cmap["scale"][0], cmap["scale"][1], 1.0)
    tex = N.new("ShaderNodeTexImage")
    tex.image = img
    tex.interpolation = "Linear"
    tex.extension = "REPEAT"
    mix = N.new("ShaderNodeMixRGB")
    mix.blend_type = "MULTIPLY"
    mix.inputs[0].default_value = 1.0
    mix.inputs[1].default_value = (albedo[0], albedo[1], albedo[2], 1.0)
    L.new(uv.outputs["UV"], mapping.inputs["Vector"])
    L.new(mapping.outputs["Vector"], tex.inputs["Vector"])
    L.new(tex.outputs["Color"], mix.inputs[2])
    L.new(mix.outputs["Color"], socket)


def tag(w, scene, desc):
    """Plain names, the scenefit_* properties and the colour maps."""
    w.cam_obj.name = "Camera"
    for (lo, _), L in zip(w.lights, desc["lights"]):
        lo.name = lo.data.name = L["name"]
        lo["scenefit_name"] = L["name"]
    entries = {name: o for name, _, o in named_entries(scene, "objects", "object")}
    for ent, o in zip(w.objects, desc["objects"]):
        name = o["name"]
        ent["obj"].name = name
        ent["obj"]["scenefit_name"] = name
        ent["place"].name = name + "_place"
        mat = ent["mat"]
        mat.name = name
        mat["scenefit_material"] = json.dumps(entries[name].get("material") or {}, sort_keys=True)
        cmap = o["material"]["maps"].get("color_map")
        if cmap is not None:
            nodes = ent["nodes"]
            socket = (nodes["diffuse"].inputs["Color"] if "diffuse" in nodes
                      else nodes["principled"].inputs["Base Color"])
            if not ent["obj"].data.uv_layers:
                raise worker.SceneError(
                    "objects.%s: Blender read no texture coordinates from %s (its PLY importer "
                    "reads s, t; write them under those names, or use OBJ)" % (name, o["shape"]["file"]))
            color_map_nodes(mat, socket, o["material"]["albedo"], cmap)


def main():
    scene_path, out = _args()
    with open(scene_path) as f:
        scene = json.load(f)
    w = worker.Worker(threads=0)
    desc = describe(scene)
    w.build(worker.structure_of(desc))
    w.apply(desc)
    tag(w, scene, desc)
    s = bpy.context.scene
    s.cycles.seed = 0
    r = s.render
    r.threads_mode = "AUTO"
    r.use_persistent_data = False
    stem = os.path.splitext(os.path.basename(out))[0]
    r.filepath = "//" + stem + "_####.png"
    r.use_file_extension = False
    bpy.ops.file.pack_all()
    bpy.ops.wm.save_as_mainfile(filepath=out, check_existing=False, compress=False)


if __name__ == "__main__":
    try:
        main()
    except worker.SceneError as e:  # the user's scene: one line, exit 2
        print("scenefit-error: %s" % e, flush=True)
        sys.exit(1)
