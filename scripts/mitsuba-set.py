"""A calibrated photograph set no one here fitted before: a textured
rough-plastic ball (GGX, not the tracer's Phong) rendered by Mitsuba 3
under N directional lights, through a camera of its own (a gain, a power
law, photon noise, 8-bit PNG). Writes OUT/000.png..., mask.png, scene.json
(the DiLiGenT ball's set scene: each light's direction and intensity free
per photograph, the material and the ball's centre shared), shots.json and lights.txt (the true directions, one per line,
towards the light).

    python3 scripts/mitsuba-set.py OUT [SEED]
    env: GAMMA (the camera's encoding exponent, default 0.45; 1 = linear
    values), TEX (1: stains in the albedo, 0: uniform), ALPHA (GGX
    roughness, 0.12), NOISE (photon noise scale, 1), N (photographs, 20),
    ELMIN (lowest light elevation in degrees, 50)

Then: scenefit fit OUT/scene.json --shots OUT/shots.json -o FIT,
scenefit diagnose FIT -o DIAG, python3 scripts/light-error.py
DIAG/diagnosis.json OUT/lights.txt (docs/results.md, "A set rendered by
Mitsuba").
"""
import json
import math
import os
import shutil
import sys

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")
out = sys.argv[1]
seed = int(sys.argv[2]) if len(sys.argv) > 2 else 1
env = os.environ.get
gamma = float(env("GAMMA", "0.45"))
texture = env("TEX", "1") == "1"
alpha = float(env("ALPHA", "0.12"))
noise = float(env("NOISE", "1.0"))
count = int(env("N", "20"))
el_min = float(env("ELMIN", "50"))
os.makedirs(out, exist_ok=True)
rng = np.random.default_rng(seed)
W, H = 128, 96
HALF_HEIGHT = 1.3521 / 2  # the scene's orthographic height, halved

# The albedo: smooth stains over the sphere's UV square.
tw, th = 256, 128
u = np.linspace(0, 1, tw)[None, :]
v = np.linspace(0, 1, th)[:, None]
albedo = np.ones((th, tw, 3)) * np.array([0.55, 0.45, 0.35])
if texture:
    for _ in range(25):
        cu, cv, r = rng.uniform(0, 1), rng.uniform(0.2, 0.8), rng.uniform(0.02, 0.08)
        d2 = ((u - cu) ** 2 * 4 + (v - cv) ** 2) / r**2
        albedo *= 1 - rng.uniform(0.2, 0.6) * np.exp(-d2)[..., None]
    albedo *= 1 + 0.05 * rng.standard_normal((th, tw, 1))
mi.util.write_bitmap(f"{out}/albedo.exr", albedo.astype(np.float32))

dirs = []
for _ in range(count):
    el = math.radians(rng.uniform(el_min, 85))
    az = rng.uniform(0, 2 * math.pi)
    dirs.append([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
# Each LED its own tint and power.
tints = [[1 + 0.05 * rng.standard_normal(), 1.0, 1 + 0.05 * rng.standard_normal()] for _ in dirs]
powers = [rng.uniform(2.0, 3.0) for _ in dirs]

# Mitsuba's orthographic sensor spans [-1, 1] across the image's width,
# scaled by to_world; the same scale on both axes keeps pixels square.
scale = HALF_HEIGHT * W / H
shots = []
for i, d in enumerate(dirs):
    diffuse = (
        {"type": "bitmap", "filename": f"{out}/albedo.exr", "raw": True}
        if texture
        else {"type": "rgb", "value": [0.55, 0.45, 0.35]}
    )
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 4},
        "sensor": {
            "type": "orthographic",
            "to_world": mi.ScalarTransform4f.look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0])
            @ mi.ScalarTransform4f.scale([scale, scale, 1]),
            "film": {"type": "hdrfilm", "width": W, "height": H,
                     "rfilter": {"type": "box"}, "pixel_format": "rgba"},
            "sampler": {"type": "independent", "sample_count": 64, "seed": seed * 100 + i},
        },
        "ball": {
            "type": "sphere", "center": [0, 0, 0], "radius": 0.5,
            "bsdf": {"type": "roughplastic", "distribution": "ggx", "alpha": alpha,
                     "int_ior": 1.5, "diffuse_reflectance": diffuse},
        },
        "led": {"type": "directional", "direction": [-d[0], -d[1], -d[2]],
                "irradiance": {"type": "rgb", "value": [powers[i] * t for t in tints[i]]}},
    })
    img = np.array(mi.render(scene))
    rgb, coverage = img[..., :3], img[..., 3]
    # The camera: a gain, photon noise in linear light, a power law, 8 bits.
    lin = np.clip(rgb * 0.35, 0, None)
    lin = lin + noise * np.sqrt(lin / 2000) * rng.standard_normal(lin.shape)
    levels = np.round(np.clip(np.maximum(lin, 0) ** gamma, 0, 1) * 255).astype(np.uint8)
    name = f"{i:03d}"
    mi.util.write_bitmap(f"{out}/{name}.png", levels, write_async=False)
    shots.append({"name": name, "target": f"{name}.png", "mask": "mask.png"})
mask = np.repeat(((coverage > 0.999) * 255).astype(np.uint8)[..., None], 3, axis=2)
mi.util.write_bitmap(f"{out}/mask.png", mask, write_async=False)

here = os.path.dirname(os.path.abspath(__file__))
shutil.copy(os.path.join(here, "..", "scenes", "diligent_ball", "scene.json"), f"{out}/scene.json")
with open(f"{out}/shots.json", "w") as f:
    json.dump({"format": "scenefit-shots/1", "shots": shots}, f, indent=1)
with open(f"{out}/lights.txt", "w") as f:
    f.write("".join(" ".join(f"{x:.6f}" for x in d) + "\n" for d in dirs))
