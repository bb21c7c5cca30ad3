#!/usr/bin/env bash
# Renders per second and CPU per render of each external backend inside a
# fit (examples/backend_speed.rs), as the table of
# docs/benchmarks-backends.md: one row per backend, each taken once the
# 1-minute load average is below MAX_LOAD (default 0.3; it waits up to
# IDLE_WAIT seconds, default 600, then measures anyway and the row shows
# the load). Take figures on an otherwise idle machine.
#
#   bash scripts/bench-backends.sh [mitsuba] [blender] [povray]
#
# Environment: POPULATION and GENERATIONS override each backend's budget
# (a quick check that the script works: POPULATION=8 GENERATIONS=1).
set -euo pipefail
cd "$(dirname "$0")/.."

MAX_LOAD=${MAX_LOAD:-0.3}
IDLE_WAIT=${IDLE_WAIT:-600}
if [ -z "${DRJIT_LIBLLVM_PATH:-}" ] && [ -e /usr/lib/x86_64-linux-gnu/libLLVM-19.so ]; then
  export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so
fi

cargo build --release --example backend_speed >&2
BIN=target/release/examples/backend_speed

# waits until the 1-minute load average is below MAX_LOAD (or IDLE_WAIT s)
wait_idle() {
  local waited=0
  while awk -v max="$MAX_LOAD" '{exit !($1 >= max)}' /proc/loadavg && [ "$waited" -lt "$IDLE_WAIT" ]; do
    sleep 10
    waited=$((waited + 10))
  done
}

# backend population generations extra-arguments...
bench() {
  local name=$1 pop=${POPULATION:-$2} gens=${GENERATIONS:-$3}
  shift 3
  wait_idle
  "$BIN" "$name" --population "$pop" --generations "$gens" --direct "$@" | tail -n 1
}

backends=("$@")
[ ${#backends[@]} -eq 0 ] && backends=(mitsuba blender povray)

echo "| backend | mode | load | renders/s | CPU per render: renderer | scenefit | pool idle | no render in flight |"
echo "|---|---|---|---|---|---|---|---|"
for b in "${backends[@]}"; do
  case "$b" in
    mitsuba) bench mitsuba 80 6 ;;
    blender) bench blender 40 2 ;;
    povray) bench povray 80 3 --jobs 128 ;;
    *) echo "unknown backend $b (mitsuba, blender or povray)" >&2; exit 2 ;;
  esac
done
