#!/usr/bin/env bash
# Installs the physically based renderers scenefit's tests drive, when missing:
# POV-Ray, Blender (Cycles) and LLVM 19 from Debian, Mitsuba 3 from PyPI.
# Idempotent: does nothing for what is already there.
set -euo pipefail

need_apt=()
command -v povray >/dev/null 2>&1 || need_apt+=(povray)
command -v blender >/dev/null 2>&1 || need_apt+=(blender)
ls /usr/lib/x86_64-linux-gnu/libLLVM-19.so* >/dev/null 2>&1 || ls /usr/lib/*/libLLVM-19.so* >/dev/null 2>&1 || need_apt+=(libllvm19)

if [ ${#need_apt[@]} -gt 0 ]; then
  echo "installing from Debian: ${need_apt[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${need_apt[@]}" >/dev/null
fi

if ! python3 -c 'import mitsuba' >/dev/null 2>&1; then
  echo "installing mitsuba from PyPI"
  python3 -m pip install -q mitsuba
fi
echo "renderers: povray=$(command -v povray) blender=$(command -v blender) mitsuba=$(python3 -c 'import mitsuba; print(mitsuba.__version__)')"
