#!/usr/bin/env bash
# The accumulator benchmark in one run: CPU-time ratios (accumulator_bench), then the
# deterministic instruction counts per step of the ROM step, the former accumulator
# arithmetic and DamageAccumulator::step (valgrind --tool=callgrind, collection limited to
# each function).
# Usage: tools/accumulator_bench/run.sh [BUILD_DIR]   (default build/host)
set -euo pipefail
build="${1:-build/host}"
bench="$build/tools/accumulator_bench/accumulator_bench"
[[ -x "$bench" ]] || { echo "run.sh: $bench not built (cmake --build $build --target accumulator_bench)" >&2; exit 1; }
"$bench"
command -v valgrind >/dev/null || { echo "run.sh: valgrind not installed (tools/setup.sh)" >&2; exit 1; }
steps=25600
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
count() {  # $1 = part, $2 = function pattern
  valgrind --tool=callgrind --callgrind-out-file="$out/cg-$1" --toggle-collect="$2" \
    "$bench" --only "$1" --steps "$steps" >/dev/null 2>&1
  grep -E '^summary:|^totals:' "$out/cg-$1" | head -1 | awk '{print $2}'
}
rom=$(count rom 'model::dynamics::Rom::step*')
former=$(count former '*FormerAccumulator::step*')
acc=$(count accumulator 'model::fatigue::DamageAccumulator::step*')
echo "instructions per step (callgrind, $steps steps): ROM $((rom / steps)), accumulator former $((former / steps)), now $((acc / steps))"
echo "accumulator / ROM: former $(awk -v a="$former" -v b="$rom" 'BEGIN{printf "%.2f", a/b}') x, now $(awk -v a="$acc" -v b="$rom" 'BEGIN{printf "%.2f", a/b}') x"
