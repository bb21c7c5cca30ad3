#!/usr/bin/env bash
# The diagnosis on the generated trap sets of issue 32 (tests/common/traps.rs):
# N sets of a matte sphere whose files hold linear or gamma 1.8/2.2 values
# (nothing declared: camera_response must be accepted and kept, no
# area_light/second_light), and N of a real broad lobe in sRGB files (no
# response may be taken). Each set is fitted (`fit --shots`), diagnosed, and
# fitted again with the files' encoding declared (the reference light error).
#
#   bash scripts/diagnose-traps.sh [N=10] [OUT=/tmp/diagnose-traps] [SCENEFIT=target/release/scenefit]
#
# Prints one line per set and the summary: sets that accept and keep the
# response, false area_light/second_light, the median light error after the
# diagnosis against the declared fit's, and the wall time.
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-10}
out=$(realpath -m "${2:-/tmp/diagnose-traps}")
bin=$(realpath "${3:-target/release/scenefit}")
root=$(pwd)
started=$(date +%s)
TRAPS_DIR="$out" TRAPS_N="$n" cargo test --release --test diagnose_traps -q -- --ignored write_trap_sets >/dev/null
err() { python3 "$root/scripts/light-error.py" "$1" lights.txt | awk 'NR == 1 {print $2}'; }
: >"$out/summary.tsv"
for kind in trap lobe; do
  for ((i = 0; i < n; i++)); do
    d="$out/$kind$i"
    cd "$d"
    t0=$(date +%s)
    "$bin" fit scene.json --shots shots.json -o fit --strategy hybrid --quiet >/dev/null
    "$bin" diagnose fit -o diag >/dev/null
    t1=$(date +%s)
    if [ "$kind" = trap ]; then
      "$bin" fit declared.json --shots shots.json -o declared --strategy hybrid --quiet >/dev/null
      ref=$(err declared/result.json)
    else
      ref=$(err fit/result.json)
    fi
    accepted=$(python3 -c 'import json,sys; print(",".join(json.load(open("diag/diagnosis.json"))["accepted"]) or "-")')
    line="$kind$i	$(err fit/result.json)	$(err diag/diagnosis.json)	$ref	$accepted	$((t1 - t0))"
    echo "$line" | tee -a "$out/summary.tsv"
    cd "$root"
  done
done
python3 - "$out/summary.tsv" "$started" <<'PY'
import statistics, sys, time
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.strip()]
traps = [r for r in rows if r[0].startswith("trap")]
lobes = [r for r in rows if r[0].startswith("lobe")]
has = lambda r, e: e in r[4].split(",")
kept = sum(has(r, "camera_response") for r in traps)
false_light = [r[0] for r in rows if has(r, "area_light") or has(r, "second_light")]
lobe_resp = [r[0] for r in lobes if has(r, "camera_response")]
after = statistics.median(float(r[2]) for r in traps) if traps else float("nan")
ref = statistics.median(float(r[3]) for r in traps) if traps else float("nan")
print(f"columns: set, light error after fit, after diagnose, declared fit (lobe: after fit), accepted, fit+diagnose s")
print(f"traps: camera_response accepted and kept in {kept} of {len(traps)}")
print(f"false area_light/second_light: {false_light or 'none'}")
print(f"lobe sets taking camera_response: {lobe_resp or 'none'} of {len(lobes)}")
print(f"median light error after diagnose {after:.2f} deg, declared fit {ref:.2f} deg, ratio {after / ref:.2f}")
print(f"wall {time.time() - float(sys.argv[2]):.0f} s")
PY
