#!/usr/bin/env bash
# One scene drawn by every backend through the CLI, each render's
# deviation from the built-in tracer's (docs/results.md, "The maps the
# diagnosis wrote, drawn by every backend"): e.g. a diagnosis's
# improved_scene.json with the maps it wrote. The tracer with 4x4
# supersampling and the sampling backends with 64 samples per pixel, so
# that edges and noise do not hide what a backend draws otherwise. A
# backend that refuses the scene prints its one-line reason.
#
#   bash scripts/backends-draw.sh SCENE OUT [--set PARAM=JSON ...]
set -uo pipefail
scene=${1:?usage: backends-draw.sh SCENE OUT [--set PARAM=JSON ...]}
out=${2:?usage: backends-draw.sh SCENE OUT [--set PARAM=JSON ...]}
shift 2
bin=${SCENEFIT:-$(dirname "$0")/../target/release/scenefit}
here=$(dirname "$0")
mkdir -p "$out"
for r in phong blender mitsuba povray; do
  start=$(date +%s.%N)
  if ! "$bin" render "$scene" -o "$out/$r.png" --renderer "$r" \
      --set render.antialias=4 --set render.samples=64 "$@" 2>"$out/$r.err"; then
    echo "$r: refused or failed: $(head -1 "$out/$r.err")"
    continue
  fi
  took=$(python3 -c "import time; print(f'{time.time() - $start:.2f}')")
  if [ "$r" = phong ]; then
    echo "phong: $out/phong.png ($took s)"
  else
    echo "$r vs phong: $(python3 "$here/image-deviation.py" "$out/phong.png" "$out/$r.png") ($took s)"
  fi
done
