#!/usr/bin/env bash
# Oquendo et al.'s oedometric test at the paper's parameters, end to end and timed: the 280-grain
# scene and the 1200-grain one (pour, seating load, eight pressure steps, fits). Prints each
# run's line with its wall time and particle-steps/s, its Bauer fits and its e0 profile.
# Usage: bash benches/oedometer.sh [OUT_DIR]   (THREADS=N to change the thread count, default 2)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q
out=${1:-target/bench-oedometer}
for scene in oedometer oedometer_1200; do
  rm -rf "${out:?}/$scene"
  ./target/release/grains run "scenes/$scene.toml" --out "$out/$scene" --threads "${THREADS:-2}" 2>/dev/null |
    grep -E "^[a-z_0-9]+: [0-9]+ grains|Bauer's law|e0 profile"
done
