#!/usr/bin/env bash
# The whole test suite, on a fresh machine too: installs the renderers the
# backend tests drive (POV-Ray, Blender, LLVM 19, Mitsuba 3) and the browser
# the report test opens, when missing, then runs every test in release mode.
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-renderers.sh
if [ -f scripts/install-browser.sh ]; then
  bash scripts/install-browser.sh
fi

# Mitsuba's LLVM variant needs libLLVM-19.
if [ -z "${DRJIT_LIBLLVM_PATH:-}" ]; then
  for lib in /usr/lib/x86_64-linux-gnu/libLLVM-19.so /usr/lib/*/libLLVM-19.so*; do
    if [ -e "$lib" ]; then export DRJIT_LIBLLVM_PATH="$lib"; break; fi
  done
fi

# A single-node Slurm for tests/slurm.rs (needs root: CI runs as root),
# stopped when the tests end.
if [ "$(id -u)" = 0 ]; then
  bash scripts/slurm-local.sh start
  trap 'bash scripts/slurm-local.sh stop' EXIT
fi

cargo test --release "$@"
