#!/usr/bin/env bash
# The quick tier, for the edit–test loop: the unit tests and every
# integration test binary not named in scripts/slow-tests.txt, in release
# mode, installing nothing (tests that need a renderer skip without one
# outside CI). The README's `bash scripts/test.sh` stays the whole suite and
# is what CI runs. A new tests/*.rs file is quick until it is listed as slow.
set -euo pipefail
cd "$(dirname "$0")/.."

slow=$(grep -v '^\s*#' scripts/slow-tests.txt | awk '{print $1}' | grep -v '^$' || true)
args=(--lib --bins)
for f in tests/*.rs; do
  name=$(basename "$f" .rs)
  if ! grep -qx "$name" <<<"$slow"; then
    args+=(--test "$name")
  fi
done
cargo test --release "${args[@]}" "$@"
