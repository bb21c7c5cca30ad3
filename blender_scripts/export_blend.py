"""scenefit export --to blender: a scenefit-scene/1 scene saved as a .blend
that renders as scenefit's Blender backend renders it (docs/interchange.md,
"Blender").

Run by scenefit (src/interchange/blend_export.rs), with worker.py,
scene_common.py and jsonlines.py beside this script:

    blender -b --factory-startup -noaudio --python-exit-code 1 \
        -P export_blend.py -- SCENE.json OUT.blend

The scene is built by the Blender worker's own code (worker.Worker.build and
apply: one translation of a scene for Blender, not two), then:

- the texture maps are the worker's own nodes (each map a float image of
  the decoded values, on every shape as the backend draws it);
- every image is packed into the .blend (the worker's generated ones as
  OpenEXR, lossless for their float values); meshes are datablocks in it;
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


def tag(w, scene, desc):
    """Plain names and the scenefit_* properties."""
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


def pack_maps():
    """The worker's decoded map images, generated in memory, packed as
    OpenEXR (a generated image is not an external file: `pack_all` leaves
    it out, and it would be saved empty)."""
    for img in bpy.data.images:
        if img.name.startswith(worker.PREFIX + "map_") and img.packed_file is None:
            img.file_format = "OPEN_EXR"
            img.pack()


def main():
    scene_path, out = _args()
    with open(scene_path) as f:
        scene = json.load(f)
    w = worker.Worker(threads=0)
    desc = describe(scene)
    w.build(worker.structure_of(desc))
    w.apply(desc)
    tag(w, scene, desc)
    pack_maps()
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
