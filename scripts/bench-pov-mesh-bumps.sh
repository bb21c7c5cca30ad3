#!/usr/bin/env bash
# What a normal map on a mesh costs POV-Ray (src/render/pov_mesh_bumps.rs:
# the mesh cut finer, each corner the map's normal): `scenefit render
# --renderer povray` of a 40 x 40 grid mesh (3,200 triangles) facing the
# camera, without and with scenes/textured/bumps.png at scale 16 (1,024
# texels across: the cut is held at its budget, MAX_TRIANGLES), RUNS times
# each; prints the median wall time and the largest resident memory of
# scenefit (GNU time's %M), and the deviation of POV-Ray's render from the
# built-in tracer's. Take figures with the 1-minute load below 0.3.
#
#   bash scripts/bench-pov-mesh-bumps.sh
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${RUNS:-5}
cargo build --release >&2
ROOT=$PWD
S=$ROOT/target/release/scenefit
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cp scenes/textured/bumps.png "$W/"
python3 - "$W" <<'PY'
import json, sys
w, n = sys.argv[1], 40
lines = []
for j in range(n + 1):
    for i in range(n + 1):
        lines.append(f"v {-0.9 + 1.8 * i / n} {-0.9 + 1.8 * j / n} 0\nvt {i / n} {j / n}")
for j in range(n):
    for i in range(n):
        a = j * (n + 1) + i + 1
        b, c, d = a + 1, a + n + 2, a + n + 1
        lines.append(f"f {a}/{a} {b}/{b} {c}/{c}\nf {a}/{a} {c}/{c} {d}/{d}")
open(f"{w}/grid.obj", "w").write("\n".join(lines) + "\n")
material = {"color": [0.6, 0.6, 0.6], "specular": 0.3, "shininess": 20}
scene = {"format": "scenefit-scene/1", "image": {"width": 128, "height": 128},
         "camera": {"type": "perspective", "position": [0, 0, 3], "look_at": [0, 0, 0], "fov_y_deg": 40},
         "render": {"samples": 64, "indirect": False, "antialias": 4},
         "lights": [{"name": "key", "type": "point", "position": [0.8, 0.6, 2.0], "intensity": 6.0}],
         "objects": [{"name": "sheet", "shape": {"type": "mesh", "file": "grid.obj"}, "material": material}]}
json.dump(scene, open(f"{w}/plain.json", "w"))
material["normal_map"] = {"file": "bumps.png", "scale": [16, 16]}
json.dump(scene, open(f"{w}/mapped.json", "w"))
PY
cd "$W"
for f in plain mapped; do
  for _ in $(seq "$RUNS"); do
    /usr/bin/time -f "%e %M" -a -o "$f.times" "$S" render "$f.json" -o "$f.png" --renderer povray
  done
  python3 - "$f" <<'PY'
import statistics, sys
rows = [l.split() for l in open(f"{sys.argv[1]}.times")]
secs = statistics.median(float(r[0]) for r in rows)
rss = max(int(r[1]) for r in rows) / 1024
print(f"{sys.argv[1]}: median {secs:.2f} s over {len(rows)} renders, largest resident memory {rss:.0f} MB")
PY
done
"$S" render mapped.json -o phong.png
python3 "$ROOT/scripts/image-deviation.py" phong.png mapped.png
