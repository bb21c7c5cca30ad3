#!/usr/bin/env bash
# Kills a set fit N times at random moments with SIGKILL, resumes it after
# each kill, lets the last resume finish, and says whether the final
# result.json (parameters and deviation) is the one an uninterrupted run
# with the same seed gives.
#
#   scripts/kill-resume.sh N [DIR]
#
# N: kills (default 3). DIR: where the two runs go (default: a new
# temporary directory). SCENEFIT (default target/release/scenefit), SCENE,
# SHOTS, STRATEGY and SEED choose the fit (default: the DiLiGenT ball set,
# hybrid, seed 1); MIN_S and MAX_S bound the seconds before each kill
# (default 5 and 40).
set -euo pipefail

n=${1:-3}
dir=${2:-$(mktemp -d)}
bin=${SCENEFIT:-target/release/scenefit}
scene=${SCENE:-scenes/diligent_ball/scene.json}
shots=${SHOTS:-scenes/diligent_ball/shots24.json}
strategy=${STRATEGY:-hybrid}
seed=${SEED:-1}
min_s=${MIN_S:-5}
max_s=${MAX_S:-40}
fit=("$bin" fit "$scene" --shots "$shots" --strategy "$strategy" --seed "$seed" -q)

mkdir -p "$dir"
straight="$dir/straight"
killed="$dir/killed"
if [ ! -f "$straight/result.json" ]; then
    echo "uninterrupted run into $straight"
    "${fit[@]}" -o "$straight" --overwrite
fi

rm -rf "$killed"
resume=()
for i in $(seq 1 "$n"); do
    if [ -f "$killed/result.json" ]; then
        echo "the run finished before kill $i; raise MAX_S or lower N"
        break
    fi
    secs=$(( min_s + RANDOM % (max_s - min_s + 1) ))
    echo "kill $i of $n after $secs s"
    set +e
    # --foreground: timeout waits for the killed run to end (its lock
    # released) before the next one starts.
    timeout --foreground -s KILL "$secs" "${fit[@]}" -o "$killed" "${resume[@]}"
    rc=$?
    set -e
    if [ "$rc" -ne 137 ] && [ "$rc" -ne 0 ]; then
        echo "run $i exited with $rc (not killed, not finished)"
        exit 1
    fi
    resume=(--resume)
done
echo "final resume"
"${fit[@]}" -o "$killed" --resume

python3 - "$straight/result.json" "$killed/result.json" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
keys = ["params", "deviation", "shots"]
same = all(a.get(k) == b.get(k) for k in keys)
print("final result identical to the uninterrupted run:", "yes" if same else "NO")
if not same:
    for k in keys:
        if a.get(k) != b.get(k):
            print(f"  {k} differs:\n    {a.get(k)}\n    {b.get(k)}")
sys.exit(0 if same else 1)
PY
