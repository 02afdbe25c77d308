#!/usr/bin/env bash
# Library code must run on wasm32-unknown-unknown, where `Instant::now()` and
# `SystemTime::now()` panic at run time: only src/clock.rs (which reads no clock there)
# may name std's clocks; the pipeline's `Instant` is the clock module's. Tests, benches
# and examples may use std's.
set -euo pipefail
cd "$(dirname "$0")/.."
hits=$(grep -rnE 'std::time::(Instant|SystemTime)|std::time::\{[^}]*(Instant|SystemTime)|time::(Instant|SystemTime)::now' \
    src crates/*/src --include='*.rs' \
    | grep -v '^src/clock.rs:' \
    | grep -vE '/(tests?|benches)(/|\.rs:)|proptests\.rs:|testing\.rs:' || true)
if [ -n "$hits" ]; then
    echo "portable: clock calls in library code (use polis' clock module or cfg them out):"
    echo "$hits"
    exit 1
fi
echo "portable: no clock calls in library code outside src/clock.rs"
