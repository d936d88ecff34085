#!/usr/bin/env bash
# The ceiling of the step as built: `grains bench` on the dense bed, interleaved, for the build
# and for HEAD with `benches/ceiling.patch`, whose lane kernel computes no contact law (each
# touching pair's forces, torques and spring are its loaded inputs times zero) while the touch
# test, the lane fill, the owner sums, the partners' shares, the reports, the springs written
# back, the gather, the walls, the kicks and the drifts run as they are. The difference is what
# the law's arithmetic costs; the patched figure is the most the step could reach by making
# that arithmetic cheaper. The patched bed, held by nothing, sinks (Z falls from about 4.65 to
# 4.05 over 1,000 steps), so it does a little less work than the real one, and its runs are kept
# short: 10^7 particle-steps each (1,000 steps at 10^4 grains; longer ones overfill the
# neighbour lists).
#
#   benches/ceiling.sh [SIZES] [THREADS] [ROUNDS]    defaults: 10000 1 3
#
# The real build is the working tree's (target/release); the patched one is committed HEAD's,
# built in a git worktree into target/ceiling (a target folder of its own: one shared with the
# project's build would leave the patched library in place of the real one; the first run
# builds the dependencies there too, some minutes). Commit first for a like-for-like pair.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
SIZES=${1:-10000}
THREADS=${2:-1}
ROUNDS=${3:-3}
TREE=$(mktemp -d)
cleanup() { git -C "$ROOT" worktree remove --force "$TREE" 2>/dev/null || rm -rf "$TREE"; }
trap cleanup EXIT
git -C "$ROOT" worktree add --quiet --detach "$TREE" HEAD
if ! git -C "$TREE" apply "$ROOT/benches/ceiling.patch"; then
  echo "error: benches/ceiling.patch no longer applies to src/cpu/lanes.rs; fix: redo its one change (the call of contact_force in the lane loop replaced by inputs times zero) and regenerate it with git diff" >&2
  exit 1
fi
cargo build --release --quiet --manifest-path "$ROOT/Cargo.toml"
cargo build --release --quiet --manifest-path "$TREE/Cargo.toml" --target-dir "$ROOT/target/ceiling"
LOG=$(mktemp)
trap 'cleanup; rm -f "$LOG"' EXIT
# The bench's table rows of binary $1, labelled $2; its progress goes to $LOG, shown if it fails.
run() {
  local table
  if ! table=$("$1" bench --part throughput --sizes "$SIZES" --threads "$THREADS" --precision f64 --repeats 3 --work 1e7 2>"$LOG"); then
    echo "error: the $2 build's bench failed:" >&2
    tail -n 3 "$LOG" >&2
    exit 1
  fi
  grep -E '^cpu ' <<<"$table" | awk -v who="$2" '{printf "%-8s %3s thr %8s grains %10s particle-steps/s %7s ns/p-step  Z = %s\n", who, $3, $5, $6, $8, $9}'
}
for _ in $(seq "$ROUNDS"); do
  run "$ROOT/target/release/grains" real
  run "$ROOT/target/ceiling/release/grains" "no law"
done
