#!/usr/bin/env bash
# Renders needed by `--strategy shade` and `--strategy hybrid` to reach a
# deviation of 0.1 % and 0.01 % on three scenes with a hidden truth
# (glossy_effects: the harder landscape of fresnel, a second specular lobe
# and the camera's response free besides the light and the colour), seeds
# 1..N. Prints one line per run, then a summary per scene, strategy and
# target (median and range over the runs that reached it, reached count).
#
# Usage: scripts/bench-hybrid.sh [SEEDS=10] [OUTDIR=/tmp/bench-hybrid]
# Env: SCENEFIT (binary; default target/release/scenefit), STRATEGIES,
#      SCENES, TARGETS (space-separated lists), JOBS (default 2),
#      FIRST_SEED (default 1: seeds FIRST_SEED..SEEDS, so that a long
#      bench can run one seed at a time).
set -euo pipefail
cd "$(dirname "$0")/.."
seeds=${1:-10}
out=${2:-/tmp/bench-hybrid}
bin=${SCENEFIT:-target/release/scenefit}
strategies=${STRATEGIES:-"shade hybrid"}
scenes=${SCENES:-"paper_box sphere_floor glossy_effects"}
targets=${TARGETS:-"0.1 0.01"}
jobs=${JOBS:-2}
first_seed=${FIRST_SEED:-1}
mkdir -p "$out"

# The hidden truths (inside each scene's free bounds).
truth_paper_box=(
  --set 'lights.led_left.position=[-0.042,0.132,0.05]'
  --set lights.led_left.intensity=0.014
  --set 'lights.led_right.position=[0.038,0.136,0.02]'
  --set lights.led_right.intensity=0.012
  --set 'objects.floor.material.color=[0.45,0.5,0.55]'
  --set objects.sphere.material.specular=0.25
  --set objects.sphere.material.shininess=50
  --set 'objects.sphere.material.color=[0.8,0.3,0.2]'
)
truth_sphere_floor=(
  --set 'lights.key.position=[1.4,3.6,2.5]'
  --set lights.key.intensity=14
  --set 'objects.ball.material.color=[0.3,0.6,0.8]'
)
truth_glossy_effects=(
  "${truth_sphere_floor[@]}"
  --set objects.ball.material.specular=0.4
  --set objects.ball.material.shininess=60
  --set objects.ball.material.fresnel=0.2
  --set objects.ball.material.specular2=0.3
  --set camera.response.gamma=1.3
  --set camera.response.black=0.02
)

echo "# $(date -u '+%Y-%m-%d %H:%M UTC'); load: $(uptime | sed 's/.*load average: //')"
results="$out/results.tsv"
: >"$results"
for scene in $scenes; do
  truth="truth_${scene}[@]"
  "$bin" render "scenes/$scene.json" -o "$out/$scene-target.png" "${!truth}" >/dev/null
  for strategy in $strategies; do
    for target in $targets; do
      for seed in $(seq "$first_seed" "$seeds"); do
        dir="$out/$scene-$strategy-$target-$seed"
        "$bin" fit "scenes/$scene.json" --target "$out/$scene-target.png" -o "$dir" \
          --overwrite --strategy "$strategy" --seed "$seed" \
          --target-deviation "$target" --generations 1000 --jobs "$jobs" >/dev/null 2>&1
        python3 - "$dir/result.json" "$scene" "$strategy" "$target" "$seed" >>"$results" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
reached = int(r["stop_reason"] == "target fitness reached")
dev = r["deviation"]["average"] if isinstance(r["deviation"], dict) else r["deviation"]
print("\t".join(sys.argv[2:6] + [str(r["evaluations"]), str(reached), f"{dev:.4f}"]))
PY
        tail -n 1 "$results"
      done
    done
  done
done

echo "# scene strategy target: median renders (range) of the runs that reached it, reached/runs"
python3 - "$results" <<'PY'
import statistics, sys
from collections import defaultdict
runs = defaultdict(list)
for line in open(sys.argv[1]):
    scene, strategy, target, seed, renders, reached, dev = line.split("\t")
    runs[(scene, strategy, target)].append((int(renders), int(reached)))
for (scene, strategy, target), rs in runs.items():
    ok = [n for n, r in rs if r]
    if ok:
        med = statistics.median(ok)
        print(f"{scene}\t{strategy}\t{target}%\t{med:,.0f} ({min(ok):,}-{max(ok):,})\t{len(ok)}/{len(rs)}")
    else:
        print(f"{scene}\t{strategy}\t{target}%\tnot reached\t0/{len(rs)}")
PY
