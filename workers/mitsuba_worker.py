#!/usr/bin/env python3
"""scenefit's Mitsuba 3 worker: a persistent renderer speaking the JSON-lines
plug-in protocol (docs/plugins.md), spoken by workers/jsonlines.py beside it;
the scene is read by workers/scene_common.py (shared with the Blender worker).

    python3 workers/mitsuba_worker.py [--variant llvm_ad_rgb|scalar_rgb] [--threads N]

stdout carries protocol lines only: the first is
``{"ready": true, "renderer": "mitsuba <version> <variant>"}``; then every request line
``{"id": 17, "scene": {...}, "output": "/path/17.png", "seed": 5}`` (seed optional,
default 0, other keys ignored) gets exactly one answer ``{"id": 17, "ok": true}`` or
``{"id": 17, "ok": false, "error": "..."}``. A malformed line answers ok:false (with
"id": null when no id could be read) and the worker keeps serving. EOF -> exit 0.
Anything Mitsuba, Dr.Jit or Python print goes to stderr (fd 1 is pointed at fd 2
at start; the protocol writes to a private duplicate of the original stdout).

Variant: ``llvm_ad_rgb`` when DRJIT_LIBLLVM_PATH is set or
/usr/lib/x86_64-linux-gnu/libLLVM-19.so exists (the worker then sets
DRJIT_LIBLLVM_PATH itself; Mitsuba 3.9 does not run with LLVM 15), else ``scalar_rgb``.
``--threads`` (default 1) goes to ``dr.set_thread_count``: the Rust side runs
several workers at once.

Speed: the loaded Mitsuba scene is kept. When a request has the same *structure*
as the loaded scene (image size, camera type, render.indirect, ambient zero or
not, each light's name/type/soft-or-not, each object's name/shape type/material
kind), only the changed values are written through ``mi.traverse(scene)`` and
``params.update()``; otherwise the scene is rebuilt. samples and seed go to
``mi.render(scene, params, seed=..., spp=...)``, so they never force a rebuild.

Mapping (docs/renderers.md; scene: right-handed, y up, metres, linear RGB)
-------------------------------------------------------------------------------
Defaults: light color [1,1,1], falloff inverse_square, radius 0; material diffuse 1,
specular 0, shininess 10, reflection 0, transmission 0, ior 1.5; ambient [0,0,0];
render {samples 16, indirect true}; camera up [0,1,0].

camera
  perspective   -> ``perspective``, fov_axis "y", fov = fov_y_deg, to_world =
                   look_at(position, look_at, up). (Updated through sensor.x_fov =
                   2 atan(tan(fov_y/2) * width/height).)
  orthographic  -> ``orthographic``, to_world = look_at(...) * scale(s, s, 1) with
                   s = height*width/(2*height_px) (Mitsuba's orthographic camera sees
                   x in [-1,1], y in [-1/aspect, 1/aspect] in camera space), so the
                   vertical extent is ``height`` metres.
  pinhole       -> ``perspective`` (pinhole_plan): fov from fy, to_world from the
                   rotation and centre, principal_point_offset from cx, cy.
  If up is parallel to the viewing direction, another up is chosen (world -z,
  or +x when looking along z) instead of failing.
  film: ``hdrfilm`` width x height from ``image``, pixel_format rgb, rfilter box.
  sampler: ``multijitter`` (stratified: a narrow highlight within a pixel is
  averaged like the built-in tracer's grid; the independent sampler put a
  shininess-300 highlight 1.4 % off at 16 spp, this 0.3 %), sample_count =
  render.samples, seed = request seed.
integrator: hide_emitters = true (background black; area-light spheres are not
  seen by camera rays, though mirrors and glass show them).
  render.indirect true  -> ``path``, max_depth 9 (up to 8 bounces).
  render.indirect false -> ``direct`` (one emitter sample and one BSDF sample per
  camera sample, combined by MIS). This is the same estimator as the conventions'
  ``path`` with max_depth 2, without the path loop: ~40 % less CPU per render.
  SCENEFIT_MITSUBA_DIRECT=path in the environment selects path/max_depth 2 instead.
ambient A (linear RGB radiance, non-zero) -> ``constant`` emitter of radiance A,
  hidden from the camera by hide_emitters. Unlike the Phong tracer, it is occluded
  (this is physically based ambient light).
lights (intensity I times color)
  point, radius 0 -> ``point``, position, intensity = I*color (W/sr).
  point, radius r>0 -> a ``sphere`` of radius r at position with an ``area`` emitter
                   of radiance I*color/(pi r^2) (same intensity seen from afar) and a
                   black diffuse BSDF; it is invisible to camera rays (hide_emitters)
                   but does block other lights and indirect rays.
  directional    -> ``directional``, irradiance = E*color (W/m^2), travelling
                   along -direction (scene direction points towards the light).
                   radius r > 0: ``scenefit_sun`` (own emitter): each sample
                   from normalize(direction + r * uniform disk point).
  falloff_power p other than 2 (falloff "none" is p = 0), radius 0
                 -> ``scenefit_point`` (own emitter, register_plugins): intensity
                   I*color falling off as 1/d^p. With radius > 0: error (the
                   Rust side refuses it first).
objects
  sphere  -> ``sphere`` (to_world = translate(center) * scale(radius)).
  plane   -> ``rectangle`` of half-size 1000 m around `point`, normal = `normal`
             (an infinite plane is not available).
  mesh    -> ``ply`` or ``obj`` (by the file's extension) loading the file
             scenefit read (its vertex normals when it has them).
  quad    -> ``rectangle`` with to_world columns edge_u/2, edge_v/2,
             normalize(edge_u x edge_v), origin corner + (edge_u+edge_v)/2.
  box     -> ``cube`` mesh whose vertices are set to center + half_size * unit cube;
             with maps, its texture coordinates set to scenefit's per face
             (``box_texcoords``: each face the whole image, as uv.rs lays it).
  transform (an object's placement, scene_common.transform): its matrix times
             the shape's to_world; for a box, applied to each vertex; for a
             mesh, to the file's vertices (normals by the inverse transpose),
             written per candidate as a box's are.
materials (d = diffuse, c = color, ks = specular, n = shininess, kr = reflection,
  kt = transmission)
  ks = ks2 = kr = kt = 0 -> ``twosided`` ``diffuse`` with reflectance d*c
                      (Lambertian; not clamped to 1, negative values become 0).
  kt = 0           -> ``twosided`` ``scenefit_phong`` (own BSDF, register_plugins):
                      the built-in tracer's material, albedo d*c, lobes ks/n and
                      ks2/n2 (specular2, shininess2), Schlick F0 = fresnel;
                      kr > 0: ``blendbsdf`` (weight kr) with a white mirror, the
                      scenefit_phong half scaled by 1/(1-kr) so that the mirror
                      is added as in the built-in tracer.
  texture maps (color_map, specular_map, shininess_map; docs/scene-format.md
                      "Textures") -> ``scenefit_phong`` (also for a diffuse-only
                      material) holding each map as a ``bitmap`` of the file's
                      linear values (decoded as its encoding says, range
                      applied; raw, bilinear, repeat) looked up at scenefit's
                      (u, v): ``to_uv`` turns Mitsuba's coordinates into them
                      (a mapped sphere's to_world takes local z to +y, a
                      mapped plane's axes are scenefit's e_u, e_v, an OBJ's v
                      is flipped back) and flips v for the bitmap's rows.
                      A map on glass is refused (render/maps.rs).
  normal_map       -> a ``normalmap`` BSDF (its ``bitmap`` raw, as above)
                      around ``scenefit_phong``, inside the mirror's blend:
                      tangent space about Mitsuba's dP/du, which points as
                      scenefit's u on every shape drawn (the mapped sphere's
                      longitude, the plane's and quad's first axis, a
                      mesh's u), B = N x T: the built-in tracer's frame.
  kt > 0 (glass)   -> ``principled``: base_color d*c, metallic 0,
                      roughness (2/(n+2))^(1/4), specular level min(1, ks) (F0 = 0.08*ks, so
                      ks 0.5 <-> F0 0.04, as Blender); kt > 0: spec_trans = kt and eta = ior (Mitsuba then ignores
                      `specular`: F0 follows from ior).
                      kr > 0: ``blendbsdf`` (weight kr) of that and a white perfect
                      mirror (``conductor``, material none).
                      Without transmission the whole is wrapped in ``twosided``
                      (planes, quads and boxes shade on both sides); with transmission
                      it is not (a dielectric has two sides of its own).
  Known differences from the Phong tracer, for glass: the principled diffuse lobe
  is Disney's (brighter towards grazing angles), not Lambertian; the principled transmission
  is tinted by base_color = d*c (diffuse 0 gives black glass, as in Blender's
  Principled BSDF); the lobes are mixed energy-conserving (blend), not added.
Output: the film's linear RGB is converted with
``mi.Bitmap(img).convert(RGB, UInt8, srgb_gamma=True)`` (standard sRGB curve, clamped)
and written to a temporary name next to `output`, then os.replace'd: as raw
bytes when the request asks ``"pixels": "raw"`` (answered with ``"pixels": "raw"``),
else as PNG.

Speed, 2: in JIT (llvm) variants with a perspective camera, ``mi.render`` runs
through ``dr.freeze`` (``MitsubaBackend.freezable``): the kernels are recorded
once per scene structure and replayed with new values, instead of being traced
through Python for every request. SCENEFIT_MITSUBA_FREEZE=0 turns this off;
SCENEFIT_WORKER_DEBUG=1 prints each request's phase times to stderr.
"""

import argparse
import json
import math
import os
import sys
import time

import jsonlines
from scene_common import (MAP_KEYS, SceneError, add, apply_point, cross, describe, matmul4, mul, norm,
                          normalize, plane_axes, roughness, sub)

LLVM19 = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
PLANE_HALF_SIZE = 1000.0
MAX_DEPTH_INDIRECT = 9
# render.indirect false: Mitsuba's `direct` integrator (default) or, with
# SCENEFIT_MITSUBA_DIRECT=path in the environment, `path` with max_depth 2.
DIRECT_WITH_PATH = os.environ.get("SCENEFIT_MITSUBA_DIRECT", "") == "path"
# Frozen renders (MitsubaBackend.freezable) unless SCENEFIT_MITSUBA_FREEZE=0.
FREEZE = os.environ.get("SCENEFIT_MITSUBA_FREEZE", "1") != "0"
# Per-request phase times on stderr (PhaseTimer).
DEBUG = bool(os.environ.get("SCENEFIT_WORKER_DEBUG"))


# ---------------------------------------------------------------- small vector math
# (the scene is read by scene_common.describe, shared with the Blender worker)
def basis(n):
    """Two unit vectors u, v with (u, v, n) right-handed orthonormal (Duff et al.)."""
    sign = math.copysign(1.0, n[2])
    a = -1.0 / (sign + n[2])
    b = n[0] * n[1] * a
    u = (1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0])
    v = (b, sign + n[1] * n[1] * a, -n[1])
    return u, v


def columns_matrix(c0, c1, c2, t):
    """4x4 row-major matrix with the given columns and translation t."""
    return (
        (c0[0], c1[0], c2[0], t[0]),
        (c0[1], c1[1], c2[1], t[1]),
        (c0[2], c1[2], c2[2], t[2]),
        (0.0, 0.0, 0.0, 1.0),
    )


def look_at_matrix(origin, target, up, sx=1.0, sy=1.0):
    """Mitsuba's look_at (camera +z towards target, +y along up, +x = up x dir),
    with an optional scale of the camera's x and y axes."""
    d = normalize(sub(target, origin), "camera: look_at - position")
    upn = normalize(up, "camera.up")
    left = cross(upn, d)
    if norm(left) < 1e-6:
        # up parallel to the view direction: pick another up
        alt = (0.0, 0.0, -1.0) if abs(d[2]) < 0.9 else (1.0, 0.0, 0.0)
        left = cross(alt, d)
    left = normalize(left, "camera")
    new_up = cross(d, left)
    return columns_matrix(mul(left, sx), mul(new_up, sy), d, origin)


# ---------------------------------------------------------------- scene -> plan
def material_plan(m):
    """Mitsuba's values for the convention values `m` (scene_common.material)."""
    albedo = tuple(max(a, 0.0) for a in m["albedo"])
    kr, kt = m["kr"], m["kt"]
    if m["kind"] == "lambertian":
        return {"kind": ("lambert",), "albedo": albedo}
    if m["maps"] and m["kind"] != "phong":
        raise SceneError("texture maps on a transmitting material are not drawn by mitsuba; use phong")
    if m["kind"] == "phong":
        # The built-in tracer adds kr * L(mirror); a blend (1-kr) A + kr B
        # adds it too when A is scaled by 1/(1-kr) (kr capped below 1).
        mirror = min(max(kr, 0.0), 0.999)
        return {
            # the maps (files and settings) are part of what is built
            "kind": ("phong", kr > 0.0, repr(sorted(m["maps"].items()))),
            "maps": m["maps"], "n2_own": m["n2_own"],
            "albedo": albedo,
            "ks": max(m["ks"], 0.0), "n": m["n"], "ks2": max(m["ks2"], 0.0), "n2": m["n2"],
            "f0": m["f0"],
            "scale": 1.0 / (1.0 - mirror),
            "mirror": mirror,
        }
    ior = m["ior"]
    return {
        "kind": ("principled", kr > 0.0, kt > 0.0),
        "albedo": albedo,
        "roughness": min(max(roughness(m["n"]), 0.0), 1.0),
        "specular": min(max(m["ks"], 0.0), 1.0),
        "spec_trans": min(max(kt, 0.0), 1.0),
        "eta": ior if ior != 1.0 else 1.0001,
        "mirror": min(max(kr, 0.0), 1.0),
    }


def pinhole_plan(cam, w, h):
    """A calibrated pinhole as Mitsuba's ``perspective``: vertical fov
    2 atan(H / (2 fy)); Mitsuba's camera x points left and y up in the
    image, OpenCV's right and down, so to_world = [R^T diag(-1, -1, 1) |
    centre], its x column scaled by fy/fx for non-square pixels; the
    principal point through principal_point_offset (a fraction of the film,
    moving the image against the axis): 0.5 - (cx + 0.5)/W, 0.5 - (cy + 0.5)/H."""
    rt = cam["to_world"]
    col = [tuple(rt[i][j] for i in range(3)) for j in range(3)]
    fov = math.degrees(2.0 * math.atan(h / (2.0 * cam["fy"])))
    return {"type": "perspective", "fov_y": fov,
            "x_fov": math.degrees(2.0 * math.atan(math.tan(math.radians(fov) / 2.0) * w / h)),
            "to_world": columns_matrix(mul(col[0], -cam["fy"] / cam["fx"]), mul(col[1], -1.0), col[2],
                                       cam["centre"]),
            "offset": (0.5 - (cam["cx"] + 0.5) / w, 0.5 - (cam["cy"] + 0.5) / h)}


def camera_plan(cam, w, h):
    if cam["type"] == "pinhole":
        return pinhole_plan(cam, w, h)
    camera = {"type": cam["type"], "offset": (0.0, 0.0)}
    pos, target, up = cam["position"], cam["look_at"], cam["up"]
    if cam["type"] == "perspective":
        fov = cam["fov_y"]
        camera["fov_y"] = fov
        camera["x_fov"] = math.degrees(2.0 * math.atan(math.tan(math.radians(fov) / 2.0) * w / h))
        camera["to_world"] = look_at_matrix(pos, target, up)
    else:
        s = cam["height"] * w / (2.0 * h)
        camera["to_world"] = look_at_matrix(pos, target, up, s, s)
    return camera


def light_plan(L):
    name, where = L["name"], "lights." + L["name"]
    rgb = mul(L["color"], L["intensity"])
    r = L["radius"]
    if L["type"] == "point":
        power, p = L["power"], L["position"]
        if r > 0.0 and power != 2.0:
            raise SceneError("%s: an area light (radius > 0) falls off as 1/d^2; "
                             "falloff_power %r needs radius 0" % (where, power))
        if power != 2.0:
            return {"name": name, "type": "falloff_point", "position": p,
                    "intensity": rgb, "power": power}
        if r > 0.0:
            return {"name": name, "type": "sphere_light", "position": p, "radius": r,
                    "radiance": mul(rgb, 1.0 / (math.pi * r * r))}
        return {"name": name, "type": "point", "position": p, "intensity": rgb}
    d = normalize(L["direction"], where + ".direction")
    if r > 0.0:
        return {"name": name, "type": "sun", "direction": d, "irradiance": rgb, "radius": r}
    travel = mul(d, -1.0)
    u, v = basis(travel)
    return {"name": name, "type": "directional", "irradiance": rgb,
            "to_world": columns_matrix(u, v, travel, (0.0, 0.0, 0.0))}


def box_texcoords(positions, normals):
    """scenefit's (u, v) of each vertex of Mitsuba's unit cube (flat lists
    of x, y, z in [-1, 1] and of each vertex's face normal): every face
    the whole image, upright and unmirrored seen from outside
    (src/scene/texture/uv.rs, `box_uv`)."""
    uv = []
    for k in range(0, len(positions), 3):
        x, y, z = ((positions[k + a] + 1.0) / 2.0 for a in range(3))
        n = normals[k:k + 3]
        axis = max(range(3), key=lambda a: abs(n[a]))
        plus = n[axis] > 0.0
        if axis == 0:
            uv += [1.0 - z if plus else z, y]
        elif axis == 1:
            uv += [x, 1.0 - z if plus else z]
        else:
            uv += [x if plus else 1.0 - x, y]
    return uv


def object_plan(o):
    sh, where = o["shape"], "objects.%s.shape" % o["name"]
    stype = sh["type"]
    ob = {"name": o["name"], "shape": stype, "material": material_plan(o["material"])}
    mapped = bool(o["material"]["maps"])
    # Mitsuba's (u, v) -> scenefit's (src/scene/texture/uv.rs), as 2x3 rows
    ob["material"]["uv"] = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    if stype == "sphere":
        c, r = sh["center"], sh["radius"]
        if mapped:
            # local z to +y and local y to -z: Mitsuba's longitude
            # atan2(y, x) and colatitude from z become ours
            ob["to_world"] = columns_matrix((r, 0, 0), (0, 0, -r), (0, r, 0), c)
            ob["material"]["uv"] = ((1.0, 0.0, 0.0), (0.0, -1.0, 1.0))
        else:
            ob["to_world"] = columns_matrix((r, 0, 0), (0, r, 0), (0, 0, r), c)
    elif stype == "plane":
        n = normalize(sh["normal"], where + ".normal")
        u, v = plane_axes(n) if mapped else basis(n)
        ob["to_world"] = columns_matrix(mul(u, PLANE_HALF_SIZE), mul(v, PLANE_HALF_SIZE), n, sh["point"])
        # metres from `point`: local x in [-1, 1] is u_m in [0, 1]
        h = PLANE_HALF_SIZE
        ob["material"]["uv"] = ((2.0 * h, 0.0, -h), (0.0, 2.0 * h, -h))
    elif stype == "quad":
        c, eu, ev = sh["corner"], sh["edge_u"], sh["edge_v"]
        n = normalize(cross(eu, ev), where + ": edge_u x edge_v")
        ob["to_world"] = columns_matrix(mul(eu, 0.5), mul(ev, 0.5), n, add(c, mul(add(eu, ev), 0.5)))
    elif stype == "mesh":
        ob["file"] = sh["file"]
        if sh["file"].lower().endswith(".obj"):
            # Mitsuba's OBJ loader stores 1 - v (its images run v down)
            ob["material"]["uv"] = ((1.0, 0.0, 0.0), (0.0, -1.0, 1.0))
    else:  # box
        lo, hi = sh["min"], sh["max"]
        # the cube's own texture coordinates are replaced by scenefit's
        # per face (`box_texcoords`) when it carries maps
        ob["mapped"] = mapped
        ob["center"] = mul(add(lo, hi), 0.5)
        ob["half"] = mul(sub(hi, lo), 0.5)
    # the object's transform: after the shape's own placement
    ob["transform"] = o["transform"]
    if o["transform"] is not None and "to_world" in ob:
        ob["to_world"] = matmul4(o["transform"], ob["to_world"])
    return ob


def make_plan(scene):
    """Validate the scene JSON (scene_common.describe) and reduce it to
    Mitsuba's plain numbers. Returns (signature, plan)."""
    desc = describe(scene)
    w, h = desc["width"], desc["height"]
    ambient = desc["ambient"]
    has_ambient = any(a != 0.0 for a in ambient)
    lights = [light_plan(L) for L in desc["lights"]]
    objects = [object_plan(o) for o in desc["objects"]]
    camera = camera_plan(desc["camera"], w, h)
    plan = {"width": w, "height": h, "spp": desc["samples"], "indirect": desc["indirect"],
            "camera": camera, "ambient": ambient, "has_ambient": has_ambient,
            "lights": lights, "objects": objects}
    signature = (w, h, camera["type"], desc["indirect"], has_ambient,
                 tuple((L["name"], L["type"]) for L in lights),
                 tuple((o["name"], o["shape"], o.get("file"), o["material"]["kind"]) for o in objects))
    return signature, plan


# ---------------------------------------------------------------- own plug-ins
# The scalar parameters of the `scenefit_phong` BSDF besides `albedo`.
PHONG_PARAMS = ("ks", "n", "ks2", "n2", "f0", "scale")


def register_plugins(mi, dr):
    """Registers the two plug-ins that draw the built-in tracer's model
    exactly: `scenefit_phong`, its material (Lambertian plus normalised
    Blinn-Phong lobes with Schlick's factor), and `scenefit_point`, a point
    light falling off as 1/d^p for any p."""

    def prop(props, key, default):
        return float(props[key]) if (key in props) else default

    class ScenefitPhong(mi.BSDF):
        """f = scale * (albedo/pi + sum_lobes ks (n+8)/(8 pi) (N.H)^n * F(H.V)/F0),
        with F = F0 + (1-F0)(1-H.V)^5; white lobes; both sides alike.
        Sampled as a cosine-weighted hemisphere (the direct-light estimate
        comes from the lights; this only feeds MIS and indirect bounces)."""

        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.albedo = mi.Color3f(props["albedo"]) if ("albedo" in props) else mi.Color3f(0.5)
            # texture maps (docs/scene-format.md "Textures"), static textures
            for k in MAP_KEYS:
                setattr(self, k, props[k] if (k in props) else None)
            self.n2_follows = bool(props["n2_follows"]) if ("n2_follows" in props) else False
            defaults = {"ks": 0.0, "n": 10.0, "ks2": 0.0, "n2": 10.0, "f0": 1.0, "scale": 1.0}
            for k in PHONG_PARAMS:
                setattr(self, k, mi.Float(prop(props, k, defaults[k])))
            flags = mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide
            self.m_components = [flags]
            self.m_flags = flags
            self.parameters_changed([])

        def parameters_changed(self, keys):
            # opaque: a new value is a new input, not a new kernel to compile
            dr.make_opaque(self.albedo, *(getattr(self, k) for k in PHONG_PARAMS))

        def traverse(self, callback):
            callback.put("albedo", self.albedo, mi.ParamFlags.NonDifferentiable)
            for k in PHONG_PARAMS:
                callback.put(k, getattr(self, k), mi.ParamFlags.NonDifferentiable)

        def _side(self, si):
            return dr.select(mi.Frame3f.cos_theta(si.wi) < 0, -1.0, 1.0)

        def _value(self, si, wo):
            s = self._side(si)
            wi = mi.Vector3f(si.wi.x, si.wi.y, si.wi.z * s)
            wo = mi.Vector3f(wo.x, wo.y, wo.z * s)
            ok = (wi.z > 0) & (wo.z > 0)
            h = dr.normalize(wi + wo)
            nh = dr.maximum(h.z, 0.0)
            hv = dr.clip(dr.dot(h, wi), 0.0, 1.0)
            norm = 1.0 / (8.0 * dr.pi)
            albedo, ks, ks2, n, n2 = self.albedo, self.ks, self.ks2, self.n, self.n2
            if self.color_map is not None:
                albedo = albedo * self.color_map.eval(si)
            if self.specular_map is not None:
                k = self.specular_map.eval(si).x
                ks, ks2 = ks * k, ks2 * k
            if self.shininess_map is not None:
                n = self.shininess_map.eval(si).x
                n2 = n if self.n2_follows else n2
            lobe = (ks * (n + 8.0) * norm * dr.power(nh, n)
                    + ks2 * (n2 + 8.0) * norm * dr.power(nh, n2))
            fresnel = (self.f0 + (1.0 - self.f0) * dr.power(1.0 - hv, 5.0)) / self.f0
            value = (albedo * dr.inv_pi + lobe * fresnel) * (self.scale * wo.z)
            return dr.select(ok, value, 0.0), ok

        def eval(self, ctx, si, wo, active=True):
            value, _ = self._value(si, wo)
            return dr.select(active, value, 0.0)

        def pdf(self, ctx, si, wo, active=True):
            z = wo.z * self._side(si)
            return dr.select(active & (z > 0), z * dr.inv_pi, 0.0)

        def eval_pdf(self, ctx, si, wo, active=True):
            return self.eval(ctx, si, wo, active), self.pdf(ctx, si, wo, active)

        def sample(self, ctx, si, sample1, sample2, active=True):
            w = mi.warp.square_to_cosine_hemisphere(sample2)
            bs = mi.BSDFSample3f()
            bs.wo = mi.Vector3f(w.x, w.y, w.z * self._side(si))
            bs.pdf = mi.warp.square_to_cosine_hemisphere_pdf(w)
            bs.eta = 1.0
            bs.sampled_type = mi.UInt32(+mi.BSDFFlags.DiffuseReflection)
            bs.sampled_component = 0
            value, ok = self._value(si, bs.wo)
            ok = active & ok & (bs.pdf > 0)
            return bs, dr.select(ok, value / dr.maximum(bs.pdf, 1e-20), 0.0)

        def to_string(self):
            return "ScenefitPhong[]"

    class ScenefitPoint(mi.Emitter):
        """A point light of radiant intensity `intensity` whose irradiance
        falls off as 1/d^power (Mitsuba's `point` is 1/d^2 only)."""

        def __init__(self, props):
            mi.Emitter.__init__(self, props)
            self.position = mi.Point3f(props["position"]) if ("position" in props) else mi.Point3f(0.0)
            self.intensity = mi.Color3f(props["intensity"]) if ("intensity" in props) else mi.Color3f(1.0)
            self.power = mi.Float(prop(props, "power", 2.0))
            self.m_flags = mi.EmitterFlags.DeltaPosition
            self.parameters_changed([])

        def parameters_changed(self, keys):
            dr.make_opaque(self.position, self.intensity, self.power)

        def traverse(self, callback):
            for k in ("position", "intensity", "power"):
                callback.put(k, getattr(self, k), mi.ParamFlags.NonDifferentiable)

        def sample_direction(self, it, sample, active=True):
            ds = mi.DirectionSample3f()
            ds.p = self.position
            ds.n = mi.Normal3f(0.0)
            ds.uv = mi.Point2f(0.0)
            ds.time = it.time
            ds.pdf = 1.0
            ds.delta = True
            d = self.position - it.p
            dist = dr.norm(d)
            ds.d = d / dist
            ds.dist = dist
            # JIT variants hold emitter pointers in arrays, scalar ones the object
            ds.emitter = mi.EmitterPtr(self) if hasattr(mi, "EmitterPtr") else self
            return ds, dr.select(active, self.intensity * dr.power(dist, -self.power), 0.0)

        def pdf_direction(self, it, ds, active=True):
            return mi.Float(0.0)

        def eval_direction(self, it, ds, active=True):
            dist = dr.norm(self.position - it.p)
            return dr.select(active, self.intensity * dr.power(dist, -self.power), 0.0)

        def eval(self, si, active=True):
            return mi.Color3f(0.0)

        def sample_ray(self, time, sample1, sample2, sample3, active=True):
            # a direction uniform on the sphere, weighted like Mitsuba's point
            # light at 1 m (only light tracers call this)
            d = mi.warp.square_to_uniform_sphere(sample3)
            ray = mi.Ray3f(self.position, d, time)
            return ray, self.intensity * (4.0 * dr.pi)

        def sample_position(self, time, sample, active=True):
            ps = mi.PositionSample3f()
            ps.p = self.position
            ps.n = mi.Normal3f(0.0)
            ps.uv = mi.Point2f(0.0)
            ps.time = time
            ps.pdf = 1.0
            ps.delta = True
            return ps, mi.Color3f(1.0)

        def bbox(self):
            return mi.ScalarBoundingBox3f(mi.ScalarPoint3f(0.0))

        def to_string(self):
            return "ScenefitPoint[]"

    class ScenefitSun(mi.Emitter):
        """A directional light of angular size: each sample comes from a
        direction normalize(direction + radius * (disk point)), the disk
        uniform, as the built-in tracer's soft shadows; irradiance E on a
        surface facing it."""

        def __init__(self, props):
            mi.Emitter.__init__(self, props)
            self.direction = mi.Vector3f(props["direction"]) if ("direction" in props) else mi.Vector3f(0, 1, 0)
            self.irradiance = mi.Color3f(props["irradiance"]) if ("irradiance" in props) else mi.Color3f(1.0)
            self.radius = mi.Float(prop(props, "radius", 0.0))
            # each sample is one direction: a delta light for the integrators
            self.m_flags = mi.EmitterFlags.DeltaDirection
            self.parameters_changed([])

        def parameters_changed(self, keys):
            dr.make_opaque(self.direction, self.irradiance, self.radius)

        def traverse(self, callback):
            for k in ("direction", "irradiance", "radius"):
                callback.put(k, getattr(self, k), mi.ParamFlags.NonDifferentiable)

        def sample_direction(self, it, sample, active=True):
            frame = mi.Frame3f(dr.normalize(self.direction))
            disk = mi.warp.square_to_uniform_disk_concentric(sample)
            d = dr.normalize(frame.n + self.radius * (frame.s * disk.x + frame.t * disk.y))
            ds = mi.DirectionSample3f()
            far = 1e7
            ds.p = it.p + d * far
            ds.n = -d
            ds.uv = mi.Point2f(0.0)
            ds.time = it.time
            ds.pdf = 1.0
            ds.delta = True
            ds.d = d
            ds.dist = far
            ds.emitter = mi.EmitterPtr(self) if hasattr(mi, "EmitterPtr") else self
            return ds, dr.select(active, self.irradiance, 0.0)

        def pdf_direction(self, it, ds, active=True):
            return mi.Float(0.0)

        def eval_direction(self, it, ds, active=True):
            return dr.select(active, self.irradiance, 0.0)

        def eval(self, si, active=True):
            return mi.Color3f(0.0)

        def sample_ray(self, time, sample1, sample2, sample3, active=True):
            # only light tracers call this: a ray from far along the axis
            d = dr.normalize(self.direction)
            return mi.Ray3f(d * 1e7, -d, time), self.irradiance

        def sample_position(self, time, sample, active=True):
            ps = mi.PositionSample3f()
            ps.p = dr.normalize(self.direction) * 1e7
            ps.n = -dr.normalize(self.direction)
            ps.uv = mi.Point2f(0.0)
            ps.time = time
            ps.pdf = 1.0
            ps.delta = True
            return ps, mi.Color3f(1.0)

        def bbox(self):
            return mi.ScalarBoundingBox3f(mi.ScalarPoint3f(0.0))

        def to_string(self):
            return "ScenefitSun[]"

    mi.register_bsdf("scenefit_phong", lambda props: ScenefitPhong(props))
    mi.register_emitter("scenefit_sun", lambda props: ScenefitSun(props))
    mi.register_emitter("scenefit_point", lambda props: ScenefitPoint(props))


# ---------------------------------------------------------------- plan -> Mitsuba
class MitsubaBackend:
    def __init__(self, mi, dr):
        self.mi = mi
        self.dr = dr
        self.T = mi.ScalarTransform4f
        self.scene = None
        self.params = None
        self.signature = None
        self.values = {}         # param key -> last value written (plain tuples/floats)
        self.unit_cubes = {}     # param key of vertex_positions -> unit cube positions (list)
        self.rebuilds = 0
        self.frozen = None       # the loaded scene's frozen render, if any (draw)

    # --- dict construction
    def rgb(self, c):
        return {"type": "rgb", "value": list(c)}

    def bsdf_dict(self, m):
        kind = m["kind"]
        if kind[0] == "lambert":
            return {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": self.rgb(m["albedo"])}}
        if kind[0] == "phong":
            b = {"type": "scenefit_phong", "albedo": self.rgb(m["albedo"])}
            for k in PHONG_PARAMS:
                b[k] = m[k]
            for key, t in m["maps"].items():
                if key != "normal_map":
                    b[key] = self.texture(t, m["uv"], key)
            b["n2_follows"] = not m["n2_own"]
            if "normal_map" in m["maps"]:
                # tangent space about Mitsuba's dP/du (ours: object_plan
                # keeps u's direction); the mirror keeps the true normal
                b = {"type": "normalmap", "bsdf": b,
                     "normalmap": self.texture(m["maps"]["normal_map"], m["uv"], "normal_map")}
            if kind[1]:
                b = {"type": "blendbsdf", "weight": m["mirror"], "bsdf_0": b,
                     "bsdf_1": {"type": "conductor", "material": "none"}}
            return {"type": "twosided", "bsdf": b}
        _, has_mirror, has_trans = kind
        p = {"type": "principled", "base_color": self.rgb(m["albedo"]), "roughness": m["roughness"],
             "metallic": 0.0}
        if has_trans:
            p["spec_trans"] = m["spec_trans"]
            p["eta"] = m["eta"]
        else:
            p["specular"] = m["specular"]
        b = p
        if has_mirror:
            b = {"type": "blendbsdf", "weight": m["mirror"], "bsdf_0": p,
                 "bsdf_1": {"type": "conductor", "material": "none"}}
        if not has_trans:
            b = {"type": "twosided", "bsdf": b}
        return b

    def texture(self, t, uv, key):
        """A map as a ``bitmap`` of linear values (the file decoded as its
        encoding says, then ``range`` applied), bilinear, repeated, looked
        up at scenefit's (u, v) (``uv``: from Mitsuba's) times ``scale``,
        v up (Mitsuba's bitmap has its first row at v = 0)."""
        mi = self.mi
        try:
            bmp = mi.Bitmap(t["file"])
        except Exception as e:
            raise SceneError("%s: cannot read %s: %s" % (key, t["file"], str(e).strip()))
        bmp.set_srgb_gamma(t["encoding"] == "srgb")
        bmp = bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False)
        lo, hi = t["range"]
        data = mi.TensorXf(bmp) * (hi - lo) + lo
        su, sv = t["scale"]
        flip = ((su, 0.0, 0.0), (0.0, -sv, 1.0), (0.0, 0.0, 1.0))
        a = (uv[0], uv[1], (0.0, 0.0, 1.0))
        m = [[sum(flip[i][k] * a[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
        return {"type": "bitmap", "data": data, "raw": True, "filter_type": "bilinear",
                "wrap_mode": "repeat", "to_uv": mi.ScalarTransform3f(m)}

    def bsdf_values(self, key, m):
        """Traversed parameter keys of the BSDF built by bsdf_dict -> values."""
        kind = m["kind"]
        out = {}
        if kind[0] == "lambert":
            out[key + ".bsdf.brdf_0.reflectance.value"] = ("color", m["albedo"])
            return out
        if kind[0] == "phong":
            prefix = key + ".bsdf.brdf_0"
            if kind[1]:
                out[prefix + ".weight.value"] = ("float", m["mirror"])
                prefix += ".bsdf_0"
            if "normal_map" in m["maps"]:
                prefix += ".nested_bsdf"
            out[prefix + ".albedo"] = ("color", m["albedo"])
            for k in PHONG_PARAMS:
                out[prefix + "." + k] = ("float", m[k])
            return out
        _, has_mirror, has_trans = kind
        prefix = key + ".bsdf"
        if not has_trans:
            prefix += ".brdf_0"
        if has_mirror:
            out[prefix + ".weight.value"] = ("float", m["mirror"])
            prefix += ".bsdf_0"
        out[prefix + ".base_color.value"] = ("color", m["albedo"])
        out[prefix + ".roughness.value"] = ("float", m["roughness"])
        if has_trans:
            out[prefix + ".spec_trans.value"] = ("float", m["spec_trans"])
            out[prefix + ".eta"] = ("float", m["eta"])
        else:
            out[prefix + ".specular"] = ("float", m["specular"])
        return out

    def build_dict(self, plan):
        T = self.T
        cam = plan["camera"]
        sensor = {
            "type": cam["type"],
            "to_world": T(cam["to_world"]),
            "sampler": {"type": "multijitter", "sample_count": plan["spp"]},
            "film": {"type": "hdrfilm", "width": plan["width"], "height": plan["height"],
                     "pixel_format": "rgb", "rfilter": {"type": "box"}},
        }
        if cam["type"] == "perspective":
            sensor["fov_axis"] = "y"
            sensor["fov"] = cam["fov_y"]
            sensor["principal_point_offset_x"] = cam["offset"][0]
            sensor["principal_point_offset_y"] = cam["offset"][1]
        if plan["indirect"]:
            integrator = {"type": "path", "hide_emitters": True, "max_depth": MAX_DEPTH_INDIRECT}
        elif DIRECT_WITH_PATH:
            integrator = {"type": "path", "hide_emitters": True, "max_depth": 2}
        else:
            # same estimator as path with max_depth 2 (one emitter sample + one BSDF
            # sample, MIS), without the path loop: ~40 % less CPU per render
            integrator = {"type": "direct", "hide_emitters": True}
        d = {"type": "scene", "integrator": integrator, "sensor": sensor}
        if plan["has_ambient"]:
            d["ambient"] = {"type": "constant", "radiance": self.rgb(plan["ambient"])}
        for i, L in enumerate(plan["lights"]):
            key = "L%d" % i
            if L["type"] == "point":
                d[key] = {"type": "point", "position": list(L["position"]), "intensity": self.rgb(L["intensity"])}
            elif L["type"] == "sun":
                d[key] = {"type": "scenefit_sun", "direction": list(L["direction"]),
                          "irradiance": self.rgb(L["irradiance"]), "radius": L["radius"]}
            elif L["type"] == "falloff_point":
                d[key] = {"type": "scenefit_point", "position": list(L["position"]),
                          "intensity": self.rgb(L["intensity"]), "power": L["power"]}
            elif L["type"] == "sphere_light":
                r = L["radius"]
                d[key] = {"type": "sphere", "to_world": T(columns_matrix((r, 0, 0), (0, r, 0), (0, 0, r), L["position"])),
                          "emitter": {"type": "area", "radiance": self.rgb(L["radiance"])},
                          "bsdf": {"type": "diffuse", "reflectance": self.rgb((0.0, 0.0, 0.0))}}
            else:
                d[key] = {"type": "directional", "to_world": T(L["to_world"]), "irradiance": self.rgb(L["irradiance"])}
        for i, O in enumerate(plan["objects"]):
            key = "O%d" % i
            bsdf = self.bsdf_dict(O["material"])
            if O["shape"] == "sphere":
                d[key] = {"type": "sphere", "to_world": T(O["to_world"]), "bsdf": bsdf}
            elif O["shape"] in ("plane", "quad"):
                d[key] = {"type": "rectangle", "to_world": T(O["to_world"]), "bsdf": bsdf}
            elif O["shape"] == "mesh":
                # Mitsuba's own loaders: vertex normals used when the file has them
                kind = "obj" if O["file"].lower().endswith(".obj") else "ply"
                d[key] = {"type": kind, "filename": O["file"], "bsdf": bsdf}
            else:  # box: unit cube, vertices placed through the parameters
                d[key] = {"type": "cube", "bsdf": bsdf}
        return d

    def plan_values(self, plan):
        """Every traversed parameter this worker drives -> ("kind", value)."""
        v = {}
        cam = plan["camera"]
        v["sensor.to_world"] = ("transform", cam["to_world"])
        if cam["type"] == "perspective":
            v["sensor.x_fov"] = ("float", cam["x_fov"])
            v["sensor.principal_point_offset_x"] = ("float", cam["offset"][0])
            v["sensor.principal_point_offset_y"] = ("float", cam["offset"][1])
        if plan["has_ambient"]:
            v["ambient.radiance.value"] = ("color", plan["ambient"])
        for i, L in enumerate(plan["lights"]):
            key = "L%d" % i
            if L["type"] == "point":
                v[key + ".position"] = ("point", L["position"])
                v[key + ".intensity.value"] = ("color", L["intensity"])
            elif L["type"] == "sun":
                v[key + ".direction"] = ("vector", L["direction"])
                v[key + ".irradiance"] = ("color", L["irradiance"])
                v[key + ".radius"] = ("float", L["radius"])
            elif L["type"] == "falloff_point":
                v[key + ".position"] = ("point", L["position"])
                v[key + ".intensity"] = ("color", L["intensity"])
                v[key + ".power"] = ("float", L["power"])
            elif L["type"] == "sphere_light":
                r = L["radius"]
                v[key + ".to_world"] = ("transform", columns_matrix((r, 0, 0), (0, r, 0), (0, 0, r), L["position"]))
                v[key + ".emitter.radiance.value"] = ("color", L["radiance"])
            else:
                v[key + ".to_world"] = ("transform", L["to_world"])
                v[key + ".irradiance.value"] = ("color", L["irradiance"])
        for i, O in enumerate(plan["objects"]):
            key = "O%d" % i
            if O["shape"] == "box":
                v[key + ".vertex_positions"] = ("box", (O["center"], O["half"], O["transform"]))
            elif O["shape"] == "mesh":
                if O["transform"] is not None:
                    # the file's vertices (and normals) as loaded, moved per candidate
                    v[key + ".vertex_positions"] = ("mesh", (key, O["transform"]))
                    if key + ".vertex_normals" in self.params:
                        v[key + ".vertex_normals"] = ("mesh", (key, O["transform"]))
            else:
                v[key + ".to_world"] = ("transform", O["to_world"])
            v.update(self.bsdf_values(key, O["material"]))
        return v

    # --- parameter writes
    def convert(self, key, kind, value):
        mi = self.mi
        if kind == "float":
            return mi.Float(value)
        if kind == "color":
            return mi.Color3f(*value)
        if kind == "point":
            return mi.Point3f(*value)
        if kind == "vector":
            return mi.Vector3f(*value)
        if kind == "transform":
            return type(self.params[key])(mi.ScalarTransform4f([list(r) for r in value]))
        if kind == "mesh":
            return type(self.params[key])(self.posed(key, value[1]))
        if kind == "box":
            center, half, place = value
            unit = self.unit_cubes[key]
            pos = [center[k % 3] + half[k % 3] * unit[k] for k in range(len(unit))]
            if place is not None:
                pos = [x for k in range(0, len(pos), 3) for x in apply_point(place, pos[k:k + 3])]
            return type(self.params[key])(pos)
        raise AssertionError(kind)

    def posed(self, key, place):
        """A mesh's vertices (or normals) as the file gives them, moved by
        the object's transform (4x4 row-major): Mitsuba's own transform of a
        point, or of a normal by the inverse transpose, on the whole array."""
        mi, dr = self.mi, self.dr
        if mi.variant().startswith("scalar"):
            return self.posed_scalar(key, place)
        t = mi.Transform4f([list(r) for r in place])
        if key.endswith(".vertex_normals"):
            moved = dr.normalize(t @ dr.unravel(mi.Normal3f, self.mesh_files[key]))
        else:
            moved = t @ dr.unravel(mi.Point3f, self.mesh_files[key])
        return dr.ravel(moved)

    def posed_scalar(self, key, place):
        """`posed` for scalar variants, whose arrays are plain lists of floats."""
        flat = [float(x) for x in self.mesh_files[key]]
        triples = [flat[k:k + 3] for k in range(0, len(flat), 3)]
        if key.endswith(".vertex_normals"):
            cof = cofactor3(place)
            triples = [normalized(tuple(sum(cof[i][j] * n[j] for j in range(3)) for i in range(3))) for n in triples]
        else:
            triples = [apply_point(place, p) for p in triples]
        return [x for t in triples for x in t]

    def write_values(self, values, force):
        params = self.params
        changed = 0
        for key, (kind, value) in values.items():
            if not force and self.values.get(key) == value:
                continue
            if key not in params:
                raise SceneError("internal: Mitsuba parameter %r not found" % key)
            params[key] = self.convert(key, kind, value)
            self.values[key] = value
            changed += 1
        if changed:
            params.update()
        return changed

    def build(self, plan, signature):
        mi = self.mi
        self.scene = None
        self.params = None
        self.signature = None
        self.values = {}
        self.unit_cubes = {}
        try:
            # optimize=False: Mitsuba would otherwise merge shapes sharing an identical
            # BSDF into one mesh, and their parameters could no longer be updated
            scene = mi.load_dict(self.build_dict(plan), optimize=False)
        except Exception as e:  # Mitsuba reports bad values as RuntimeError
            raise SceneError("Mitsuba could not load the scene: %s" % str(e).strip())
        self.scene = scene
        self.params = mi.traverse(scene)
        self.mesh_files = {}
        for i, O in enumerate(plan["objects"]):
            if O["shape"] == "box":
                key = "O%d.vertex_positions" % i
                self.unit_cubes[key] = [float(x) for x in self.params[key]]
                if O["mapped"]:
                    normals = [float(x) for x in self.params["O%d.vertex_normals" % i]]
                    uv = box_texcoords(self.unit_cubes[key], normals)
                    tkey = "O%d.vertex_texcoords" % i
                    # applied by the update of write_values(force=True) below: the
                    # sensor is always among the values it writes
                    self.params[tkey] = type(self.params[tkey])(uv)
            elif O["shape"] == "mesh" and O["transform"] is not None:
                for part in ("vertex_positions", "vertex_normals"):
                    key = "O%d.%s" % (i, part)
                    if key in self.params:
                        self.mesh_files[key] = type(self.params[key])(self.params[key])
        self.write_values(self.plan_values(plan), force=True)
        self.frozen = self.freezable(plan)
        self.signature = signature
        self.rebuilds += 1

    def render(self, scene_json, output, seed, raw=False):
        """Draws one request; returns "raw" when it wrote raw pixels."""
        mi = self.mi
        timer = PhaseTimer()
        signature, plan = make_plan(scene_json)
        if self.mi.variant().startswith("scalar"):
            # scalar variants hold the own plug-ins' values as plain floats,
            # which mi.traverse cannot write: a new value is a new scene
            signature = (signature, repr([L for L in plan["lights"] if L["type"] in ("falloff_point", "sun")]),
                         repr([o["material"] for o in plan["objects"] if o["material"]["kind"][0] == "phong"]))
        if signature != self.signature or self.scene is None:
            self.build(plan, signature)
            timer.lap("build")
        else:
            self.write_values(self.plan_values(plan), force=False)
            timer.lap("update")
        img = self.draw(seed, plan["spp"])
        timer.lap("render")
        bmp = mi.Bitmap(img).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, srgb_gamma=True)
        timer.lap("srgb")
        data = raw_bytes(bmp) if raw else None
        if data is not None:
            wrote = jsonlines.write_raw(output, data)
            timer.lap("raw write")
            timer.report()
            return wrote
        out_dir = os.path.dirname(os.path.abspath(output))
        tmp = os.path.join(out_dir, ".%s.tmp%d.png" % (os.path.basename(output), os.getpid()))
        try:
            bmp.write(tmp, mi.Bitmap.FileFormat.PNG, 1)  # zlib level 1: fast
            os.replace(tmp, output)
        except Exception as e:
            try:
                os.unlink(tmp)
            except OSError:
                pass
            # the scene itself is fine: no rebuild needed
            raise SceneError("cannot write %s: %s" % (output, str(e).strip()))
        timer.lap("png write")
        timer.report()
        return None

    def draw(self, seed, spp):
        """The film of the loaded scene: replayed from a frozen recording
        when there is one (see ``freezable``), else traced anew."""
        mi = self.mi
        if self.frozen is not None:
            try:
                return self.frozen(self.scene, mi.UInt32(seed), spp)
            except RuntimeError as e:
                # this structure cannot be recorded: trace it every time
                sys.stderr.write("mitsuba_worker: frozen render unavailable, tracing (%s)\n"
                                 % str(e).strip().splitlines()[0])
                self.frozen = None
        return mi.render(self.scene, self.params, seed=seed, spp=spp)

    def freezable(self, plan):
        """A frozen render (``dr.freeze``) for this scene, or None. Tracing
        mi.render through Python (the scenefit_phong BSDF included) cost ~6 ms
        of a 16 ms render at 128x96; a recording replays the kernels with
        the new parameter values without tracing. Only JIT variants record;
        only perspective cameras are used (an orthographic camera keeps a
        value outside what a recording sees: recording fails). Renders
        are the same to the bit as traced ones (checked per parameter kind
        when this was written). SCENEFIT_MITSUBA_FREEZE=0 turns it off."""
        if not FREEZE or self.mi.variant().startswith("scalar") or not hasattr(self.dr, "freeze"):
            return None  # older Dr.Jit has no dr.freeze: trace every time
        if plan["camera"]["type"] != "perspective":
            return None
        mi = self.mi

        def render(scene, seed, spp):
            return mi.render(scene, seed=seed, spp=spp)

        # one recording per spp value is expected; a new structure is a new
        # scene and a new frozen function, so the old recordings go with it
        return self.dr.freeze(render, limit=4, warn_after=100)


def cofactor3(m):
    """The cofactor matrix of the linear part of a 4x4 row-major affine
    matrix: its inverse transpose times its determinant, which takes
    normals (up to length, and orientation when the determinant is < 0)."""
    a = [list(m[i][:3]) for i in range(3)]
    sign = 1.0 if (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
                   - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                   + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])) >= 0 else -1.0
    return [[sign * (a[(i + 1) % 3][(j + 1) % 3] * a[(i + 2) % 3][(j + 2) % 3]
                     - a[(i + 1) % 3][(j + 2) % 3] * a[(i + 2) % 3][(j + 1) % 3]) for j in range(3)]
            for i in range(3)]


def normalized(v):
    n = norm(v)
    return tuple(x / n for x in v) if n > 0 else v


class PhaseTimer:
    """Per-phase wall times of one request, printed to stderr when
    SCENEFIT_WORKER_DEBUG is set (the profile of docs/benchmarks-backends.md)."""

    def __init__(self):
        self.last = time.perf_counter()
        self.start = self.last
        self.cpu = time.process_time()
        self.phases = []

    def lap(self, name):
        if DEBUG:
            now = time.perf_counter()
            self.phases.append((name, now - self.last))
            self.last = now

    def report(self):
        if DEBUG:
            parts = " ".join("%s %.2f" % (n, 1000 * t) for n, t in self.phases)
            sys.stderr.write("mitsuba_worker: ms %s; total %.2f, cpu %.2f\n"
                             % (parts, 1000 * (time.perf_counter() - self.start),
                                1000 * (time.process_time() - self.cpu)))


def raw_bytes(bmp):
    """The 8-bit pixels of a Bitmap as bytes (rows top to bottom, as its
    PNG), or None when this Mitsuba does not expose them; ctypes reads the
    buffer Mitsuba describes by its array interface, without numpy."""
    import ctypes
    try:
        ai = bmp.__array_interface__
        size = bmp.width() * bmp.height() * bmp.channel_count()
        typestr = ai.get("typestr")
        if isinstance(typestr, bytes):
            typestr = typestr.decode("ascii", "replace")
        if typestr not in ("<u1", "|u1") or ai.get("strides") is not None:
            return None
        return ctypes.string_at(ai["data"][0], size)
    except (AttributeError, TypeError, KeyError):
        return None


# ---------------------------------------------------------------- main loop
def choose_variant(requested):
    if requested:
        if requested == "llvm_ad_rgb" and not os.environ.get("DRJIT_LIBLLVM_PATH") and os.path.exists(LLVM19):
            os.environ["DRJIT_LIBLLVM_PATH"] = LLVM19
        return requested
    if os.environ.get("DRJIT_LIBLLVM_PATH"):
        return "llvm_ad_rgb"
    if os.path.exists(LLVM19):
        os.environ["DRJIT_LIBLLVM_PATH"] = LLVM19
        return "llvm_ad_rgb"
    return "scalar_rgb"


def main(argv=None):
    ap = argparse.ArgumentParser(description="scenefit Mitsuba 3 worker (JSON lines on stdin/stdout)")
    ap.add_argument("--variant", choices=["llvm_ad_rgb", "scalar_rgb"], default=None,
                    help="Mitsuba variant (default: llvm_ad_rgb when libLLVM 19 is available, else scalar_rgb)")
    ap.add_argument("--threads", type=int, default=1, help="render threads (default 1)")
    args = ap.parse_args(argv)

    # Keep the protocol channel private: whatever Mitsuba/Dr.Jit/Python print goes to stderr.
    channel = jsonlines.Channel()

    variant = choose_variant(args.variant)
    import drjit as dr
    import mitsuba as mi
    try:
        mi.set_variant(variant)
        dr.eval(mi.Float(1.0) + 1.0)  # the LLVM backend fails here when libLLVM is unusable
    except Exception as e:
        if args.variant or variant == "scalar_rgb":
            raise
        sys.stderr.write("mitsuba_worker: variant %s unusable (%s); using scalar_rgb\n" % (variant, e))
        variant = "scalar_rgb"
        mi.set_variant(variant)
    if args.threads and args.threads > 0:
        dr.set_thread_count(args.threads)
    mi.set_log_level(mi.LogLevel.Warn)
    register_plugins(mi, dr)

    backend = MitsubaBackend(mi, dr)
    channel.ready("mitsuba %s %s" % (mi.__version__, variant))

    def render(scene, output, seed, raw):
        return backend.render(scene, output, seed & 0xFFFFFFFF, raw)

    def forget_scene():
        # the loaded scene may be half-updated: rebuild next time
        backend.signature = None

    channel.serve(render, on_error=forget_scene)
    return 0


if __name__ == "__main__":
    sys.exit(main())
