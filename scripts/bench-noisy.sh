#!/usr/bin/env bash
# The hybrid's local phase on a sampling (noisy) renderer: `--strategy
# hybrid` (SHADE, then Levenberg–Marquardt steps whose renders share one
# sampler seed: common random numbers) against `--strategy shade` (the
# global phase alone: the local phase skipped), the same budget of
# renders, seeds 1..N. The target is the same renderer's render of a
# hidden truth with another sampler seed, so the deviation cannot reach 0:
# the script also prints that floor (the truth rendered with a third seed
# against the target).
#
# Prints one line per run (renderer, strategy, seed, then the best
# deviation after each budget in BUDGETS renders, from progress.txt), then
# the median per renderer, strategy and budget.
#
# Usage: scripts/bench-noisy.sh [SEEDS=3] [OUTDIR=/tmp/bench-noisy]
# Env: SCENEFIT (binary; default target/release/scenefit), RENDERERS
#      (default "mitsuba blender"), BUDGETS (default "1000 2000 4000 8000";
#      progress.txt has a line every 10 generations, 400 renders of
#      SHADE), SAMPLES (default 16), RADIUS (default 0), JOBS (default 2),
#      LIMIT (seconds a run may take, default 3600: a run stopped by it
#      still counts up to the budgets its progress.txt reached).
set -euo pipefail
cd "$(dirname "$0")/.."
seeds=${1:-3}
out=${2:-/tmp/bench-noisy}
bin=${SCENEFIT:-target/release/scenefit}
renderers=${RENDERERS:-"mitsuba blender"}
budgets=${BUDGETS:-"1000 2000 4000 8000"}
jobs=${JOBS:-2}
if [ -z "${DRJIT_LIBLLVM_PATH:-}" ] && [ -e /usr/lib/x86_64-linux-gnu/libLLVM-19.so ]; then
  export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so
fi
mkdir -p "$out"

# sphere_floor at its 128x96, SAMPLES samples (default 16) per pixel,
# direct light only, the key light a sphere of RADIUS (default 0: a point
# light, whose direct light leaves only the pixels' antialiasing to
# sample; a radius makes soft shadows that the samples estimate); the
# truth of scripts/bench-hybrid.sh.
samples=${SAMPLES:-16}
radius=${RADIUS:-0}
truth=(
  --set 'lights.key.position=[1.4,3.6,2.5]'
  --set lights.key.intensity=14
  --set 'objects.ball.material.color=[0.3,0.6,0.8]'
)
scene="$out/scene.json"
python3 - "$scene" "$samples" "$radius" <<'PY'
import json, sys
s = json.load(open("scenes/sphere_floor.json"))
s["render"] = {"samples": int(sys.argv[2]), "indirect": False}
s["lights"][0]["radius"] = float(sys.argv[3])
json.dump(s, open(sys.argv[1], "w"), indent=1)
PY

largest=$(echo "$budgets" | tr ' ' '\n' | sort -n | tail -n 1)
echo "# $(date -u '+%Y-%m-%d %H:%M UTC'); load: $(uptime | sed 's/.*load average: //')"
echo "# renderer strategy seed: best deviation (%) after $budgets renders"
results="$out/results.tsv"
: >"$results"
for renderer in $renderers; do
  "$bin" render "$scene" --renderer "$renderer" -o "$out/$renderer-target.png" --seed 7 "${truth[@]}" >/dev/null
  # The floor: the truth itself rendered with the fit's sampler seeds
  # (its only free value pinned to the truth's), against the target.
  python3 - "$scene" "$out/floor.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["lights"][0].update(position=[1.4, 3.6, 2.5], intensity=14)
s["objects"][0]["material"]["color"] = [0.3, 0.6, 0.8]
s["free"] = [{"param": "lights.key.intensity", "min": 13.9999, "max": 14.0001}]
json.dump(s, open(sys.argv[2], "w"), indent=1)
PY
  "$bin" fit "$out/floor.json" --renderer "$renderer" --target "$out/$renderer-target.png" \
    -o "$out/$renderer-floor" --overwrite --strategy shade --population 4 --generations 1 \
    --jobs "$jobs" >/dev/null 2>&1
  floor=$(python3 -c 'import json,sys; print("%.4f" % json.load(open(sys.argv[1]))["deviation"]["average"])' \
    "$out/$renderer-floor/result.json")
  echo "# $renderer: the truth against the target (another sampler seed): $floor %"
  for strategy in shade hybrid; do
    for seed in $(seq 1 "$seeds"); do
      dir="$out/$renderer-$strategy-$seed"
      # Enough generations for the largest budget (a local batch of the
      # hybrid is 1 or 2P+1 renders, not a population); the budget is cut
      # from progress.txt afterwards.
      case $strategy in
        shade) generations=$((largest / 40 + 10)) ;;
        *) generations=$((largest / 8)) ;;
      esac
      timeout "${LIMIT:-3600}" "$bin" fit "$scene" --renderer "$renderer" --target "$out/$renderer-target.png" \
        -o "$dir" --overwrite --strategy "$strategy" --seed "$seed" --jobs "$jobs" \
        --population 40 --generations "$generations" >/dev/null 2>&1 || true
      python3 - "$dir/progress.txt" "$renderer" "$strategy" "$seed" "$budgets" >>"$results" <<'PY'
import sys
path, renderer, strategy, seed, budgets = sys.argv[1:6]
rows = []
for line in open(path):
    if line.startswith("#"):
        continue
    f = line.split()
    rows.append((int(f[1]), float(f[2])))
out = []
for b in map(int, budgets.split()):
    seen = [d for n, d in rows if n <= b]
    out.append(f"{min(seen):.4f}" if seen else "-")
print("\t".join([renderer, strategy, seed] + out + [f"({rows[-1][0]} renders)"]))
PY
      tail -n 1 "$results"
    done
  done
done

echo "# renderer strategy: median best deviation (%) after $budgets renders"
python3 - "$results" <<'PY'
import statistics, sys
from collections import defaultdict
runs = defaultdict(list)
for line in open(sys.argv[1]):
    f = line.rstrip("\n").split("\t")
    runs[(f[0], f[1])].append([x for x in f[3:] if not x.startswith("(")])
for (renderer, strategy), rs in runs.items():
    cols = []
    for i in range(len(rs[0])):
        vals = [float(r[i]) for r in rs if r[i] != "-"]
        cols.append(f"{statistics.median(vals):.4f}" if vals else "-")
    print("\t".join([renderer, strategy] + cols))
PY
