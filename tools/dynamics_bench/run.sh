#!/usr/bin/env bash
# The dynamics benchmark in one run: real-time factors and bytes (dynamics_bench),
# then the deterministic instruction count of Rom::step() per simulated second
# (valgrind --tool=callgrind, collection limited to Rom::step).
# Usage: tools/dynamics_bench/run.sh [BUILD_DIR]   (default build/host)
set -euo pipefail
build="${1:-build/host}"
bench="$build/tools/dynamics_bench/dynamics_bench"
[[ -x "$bench" ]] || { echo "run.sh: $bench not built (cmake --build $build --target dynamics_bench)" >&2; exit 1; }
"$bench"
command -v valgrind >/dev/null || { echo "run.sh: valgrind not installed (tools/setup.sh)" >&2; exit 1; }
steps=25600
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
valgrind --tool=callgrind --callgrind-out-file="$out/cg" --toggle-collect='model::dynamics::Rom::step*' \
  "$bench" --rom-only --rom-steps "$steps" >"$out/log" 2>&1
ir=$(grep -E '^summary:|^totals:' "$out/cg" | head -1 | awk '{print $2}')
echo "ROM instructions (callgrind, Rom::step only): $ir for $steps steps = 1 simulated s at 25600 Hz"
echo "ROM instructions per simulated second: $ir  ($((ir / steps)) per step)"
# valgrind's virtual CPU has no AVX-512, so the loader picks another kernel clone under it.
echo "(counted on the $(sed -n 's/.* kernel //p' "$out/log") kernel: the one the loader picks under valgrind)"
