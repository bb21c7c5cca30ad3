#!/usr/bin/env bash
# Installs headless Chromium (Debian's `chromium` package) for the report
# test (tests/report_browser.rs), when it is missing. Idempotent.
set -euo pipefail

if command -v chromium >/dev/null 2>&1; then
  echo "chromium: $(command -v chromium)"
  exit 0
fi
sudo_cmd=""
[ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
echo "installing chromium from Debian"
$sudo_cmd apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq chromium >/dev/null
echo "chromium: $(command -v chromium)"
