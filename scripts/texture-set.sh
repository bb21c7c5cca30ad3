#!/usr/bin/env bash
# A generated set for the `albedo_map` effect in the object's frame
# (docs/results.md): a sphere printed with scenes/textured/checker.png,
# photographed 3 times, each with its own camera (known, in the shot's
# `set`) and its own light (unknown, fitted per photograph); the model
# knows neither the texture nor the colour. Renders the photographs,
# fits the set with a flat colour, diagnoses it, and renders the improved
# scene for the first camera.
#
#   bash scripts/texture-set.sh OUT [SHOTS]
set -euo pipefail
out=${1:?usage: texture-set.sh OUT [SHOTS]}
n=${2:-3}
bin=${SCENEFIT:-$(dirname "$0")/../target/release/scenefit}
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
cp "$root/scenes/textured/checker.png" "$out/checker.png"
scene() { # $1: the material's extra keys
cat <<JSON
{
  "format": "scenefit-scene/1",
  "image": {"width": 96, "height": 96},
  "camera": {"type": "perspective", "position": [0, 0.6, 4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 35},
  "ambient": [0.03, 0.03, 0.03],
  "lights": [{"name": "key", "type": "directional", "direction": [0.3, 0.5, 1], "intensity": 3}],
  "objects": [{"name": "ball", "shape": {"type": "sphere", "center": [0, 0, 0], "radius": 1},
    "material": {"color": [0.8, 0.7, 0.6], "specular": 0.1, "shininess": 40 $1}}],
  "free": [
    {"param": "lights.key.direction", "min": [-1, -0.2, 0], "max": [1, 1, 1], "per_shot": true},
    {"param": "objects.ball.material.color", "min": [0, 0, 0], "max": [1, 1, 1]}
  ]
}
JSON
}
scene ', "color_map": "checker.png"' > "$out/truth.json"
scene '' | sed 's/"color": \[0.8, 0.7, 0.6\]/"color": [0.5, 0.5, 0.5]/' > "$out/model.json"
shots=""
for i in $(seq 0 $((n - 1))); do
  # cameras 35 degrees apart about the vertical, lights from the left to the right
  cam=$(python3 -c "import math; a=math.radians(35*($i-($n-1)/2)); print(f'[{4*math.sin(a):.4f}, 0.6, {4*math.cos(a):.4f}]')")
  light=$(python3 -c "import math; a=math.radians(50*($i-($n-1)/2)); print(f'[{math.sin(a):.4f}, 0.5, {math.cos(a):.4f}]')")
  "$bin" render "$out/truth.json" -o "$out/s$i.png" --set "camera.position=$cam" --set "lights.key.direction=$light"
  shots="$shots${shots:+,}{\"name\": \"s$i\", \"target\": \"s$i.png\", \"set\": {\"camera.position\": $cam}}"
done
echo "{\"format\": \"scenefit-shots/1\", \"shots\": [$shots]}" > "$out/shots.json"
"$bin" fit "$out/model.json" --shots "$out/shots.json" -o "$out/fit" --strategy hybrid --quiet --overwrite
"$bin" diagnose "$out/fit" -o "$out/diag" --max-effects 1 --overwrite
"$bin" render "$out/diag/improved_scene.json" -o "$out/improved_s0.png" --set "camera.position=$(python3 -c "import math; a=math.radians(35*(0-($n-1)/2)); print(f'[{4*math.sin(a):.4f}, 0.6, {4*math.cos(a):.4f}]')")"
