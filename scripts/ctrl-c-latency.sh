#!/usr/bin/env bash
# Measures how long a fit takes to stop after Ctrl-C (SIGINT) on a large
# image: a 4096x4096 copy of scenes/sphere_floor.json (16 samples, one
# bounce), interrupted at each of the given seconds after its start, then
# resumed once to show the checkpoint it left works. Prints one line per
# interrupt and the median; docs/reliability.md quotes it.
#
#   scripts/ctrl-c-latency.sh [SECONDS...]     (default: 2 5 8 11 14 17 20)
set -euo pipefail
bin=${SCENEFIT:-target/release/scenefit}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
times=("$@")
[ ${#times[@]} -gt 0 ] || times=(2 5 8 11 14 17 20)
sed 's/"width": 128/"width": 4096/; s/"height": 96/"height": 4096/' \
    scenes/sphere_floor.json >"$dir/s.json"
"$bin" render "$dir/s.json" -o "$dir/t.png" >/dev/null
lat=()
for t in "${times[@]}"; do
    rm -rf "$dir/run"
    "$bin" fit "$dir/s.json" --target "$dir/t.png" -o "$dir/run" \
        --population 8 --generations 50 -q >"$dir/log" 2>&1 &
    pid=$!
    sleep "$t"
    t0=$(date +%s.%N)
    kill -INT "$pid"
    rc=0
    wait "$pid" || rc=$?
    t1=$(date +%s.%N)
    s=$(echo "$t1 - $t0" | bc)
    lat+=("$s")
    printf 'SIGINT %2s s after the start: exit %s after %.2f s (%s)\n' "$t" "$rc" "$s" "$(tail -c 120 "$dir/log" | tr '\n' ' ')"
done
printf 'median %.2f s, max %.2f s over %d interrupts (load average %s)\n' \
    "$(printf '%s\n' "${lat[@]}" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')" \
    "$(printf '%s\n' "${lat[@]}" | sort -g | tail -1)" "${#lat[@]}" "$(cut -d' ' -f1 /proc/loadavg)"
"$bin" fit "$dir/s.json" --target "$dir/t.png" -o "$dir/run" --population 8 --generations 2 --resume -q \
    && echo "the last interrupted run resumed and finished (exit 0)"
