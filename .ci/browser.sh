#!/usr/bin/env bash
# The editor's end-to-end test in headless Chromium (examples/editor/e2e): installs
# Debian's chromium and the test's npm packages when absent, builds the editor, runs the
# test. Screenshots go to target/editor-e2e/. BENCH=200 adds the round-trip benchmark.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -x /usr/bin/chromium ]; then
    apt-get update -q
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q chromium
fi
command -v node >/dev/null || { apt-get update -q; DEBIAN_FRONTEND=noninteractive apt-get install -y -q nodejs npm; }
(cd examples/editor/e2e && npm ci --no-audit --no-fund --loglevel=error)
PROFILE_FLAG=()
TARGET="${CARGO_TARGET_DIR:-$PWD/target}"
BIN="$TARGET/debug/examples/editor"
if [ "${BENCH:-0}" != "0" ]; then
    PROFILE_FLAG=(--release)
    BIN="$TARGET/release/examples/editor"
fi
cargo build --quiet "${PROFILE_FLAG[@]}" --example editor
export EDITOR_BIN="$BIN"
export OUT="${OUT:-$TARGET/editor-e2e}"
node examples/editor/e2e/editor.test.mjs
