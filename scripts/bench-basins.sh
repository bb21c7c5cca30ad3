#!/usr/bin/env bash
# Sharp landscapes (tests/data/basins/): a glossy-to-mirror dark sphere
# under one directional light, a point light seen only as its highlight in
# a mirror floor, a thin rod's shadow. Each target is the scene's own
# render (its hidden truth is the scene's values); each fit starts from a
# uniform random population over the scene's free bounds. Per scene,
# strategy and seed: the renders until the run stopped (the target
# deviation reached, or the budget used up), whether it reached the
# target, and the fitted light's angle from the truth (a direction; a
# point light's position seen from the origin). Then per scene and
# strategy: how many runs ended with the light within 1 degree, and the
# median renders (range).
#
# Usage: scripts/bench-basins.sh [SEEDS=20] [OUTDIR=/tmp/bench-basins]
# Env: SCENEFIT (binary; default target/release/scenefit), STRATEGIES
#      (default "shade hybrid"), SCENES (default "glossy_sphere
#      mirror_light thin_shadow"), TARGET (a deviation in % that ends a run;
#      default none: every run spends its budget),
#      GENERATIONS (default 500: the paper's budget, 40,080 renders for
#      SHADE), JOBS (default 2), FIRST_SEED (default 1).
set -euo pipefail
cd "$(dirname "$0")/.."
seeds=${1:-20}
out=${2:-/tmp/bench-basins}
bin=${SCENEFIT:-target/release/scenefit}
strategies=${STRATEGIES:-"shade hybrid"}
scenes=${SCENES:-"glossy_sphere mirror_light thin_shadow"}
target=${TARGET:-}
generations=${GENERATIONS:-500}
jobs=${JOBS:-2}
first_seed=${FIRST_SEED:-1}
mkdir -p "$out"

stop=()
[ -n "$target" ] && stop=(--target-deviation "$target")

echo "# $(date -u '+%Y-%m-%d %H:%M UTC'); load: $(uptime | sed 's/.*load average: //')"
results="$out/results.tsv"
: >"$results"
for scene in $scenes; do
  file="tests/data/basins/$scene.json"
  "$bin" render "$file" -o "$out/$scene-target.png" >/dev/null
  for strategy in $strategies; do
    for seed in $(seq "$first_seed" "$seeds"); do
      dir="$out/$scene-$strategy-$seed"
      "$bin" fit "$file" --target "$out/$scene-target.png" -o "$dir" \
        --overwrite --strategy "$strategy" --seed "$seed" \
        "${stop[@]}" --generations "$generations" --jobs "$jobs" >/dev/null 2>&1
      python3 - "$dir" "$file" "$scene" "$strategy" "$seed" >>"$results" <<'PY'
import json, math, sys
r = json.load(open(sys.argv[1] + "/result.json"))
truth = json.load(open(sys.argv[2]))
light = truth["lights"][0]
key = "direction" if light["type"] == "directional" else "position"
name = f"lights.{light['name']}.{key}"
unit = lambda v: [x / math.sqrt(sum(y * y for y in v)) for x in v]
def off(params):
    cos = sum(a * b for a, b in zip(unit(params[name]), unit(light[key])))
    return math.degrees(math.acos(max(-1.0, min(1.0, cos))))
angle = off(r["params"])
# Renders to the true basin: the first progress line (every 10
# generations) from which the best stays within 1 degree; the run's
# renders if it ends outside.
basin = r["evaluations"]
for line in reversed(open(sys.argv[1] + "/progress.txt").read().splitlines()[1:]):
    fields = line.split(" ", 6)
    if off(json.loads(fields[6])) > 1.0 or angle > 1.0:
        break
    basin = int(fields[1])
reached = int(r["stop_reason"] == "target fitness reached")
alts = len(r.get("alternatives") or [])
dev = r["deviation"]["average"]
print("\t".join(sys.argv[3:6] + [str(basin), str(reached), f"{dev:.4f}", f"{angle:.2f}", str(alts), str(r["evaluations"])]))
PY
      tail -n 1 "$results"
    done
  done
done

echo "# scene strategy: light within 1 deg at the end / runs; median renders to the true basin (range; a run that ends outside counts its budget); median final angle, median deviation"
python3 - "$results" <<'PY'
import statistics, sys
from collections import defaultdict
runs = defaultdict(list)
for line in open(sys.argv[1]):
    scene, strategy, seed, renders, reached, dev, angle, alts, total = line.split("\t")
    runs[(scene, strategy)].append((int(renders), float(dev), float(angle), int(alts)))
for (scene, strategy), rs in runs.items():
    n = [r[0] for r in rs]
    basin = sum(r[2] <= 1.0 for r in rs)
    med = statistics.median(n)
    angle = statistics.median(r[2] for r in rs)
    dev = statistics.median(r[1] for r in rs)
    alts = sum(r[3] > 0 for r in rs)
    print(f"{scene}\t{strategy}\t{basin}/{len(rs)} within 1 deg\t{med:,.0f} ({min(n):,}-{max(n):,})\t"
          f"{angle:.2f} deg\t{dev:.4f} %\talternatives in {alts}")
PY
