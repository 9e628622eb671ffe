#!/usr/bin/env bash
# The whole test suite on a fresh Debian 12 machine (as root): installs what is
# missing, then builds and runs the tests natively, under AddressSanitizer +
# UndefinedBehaviorSanitizer, under ThreadSanitizer (the tests labelled `threaded`
# only), and cross-compiled for aarch64 under qemu-aarch64 (that tier includes the
# emulated-rig tests, label `rig`).
# Usage: bash tools/test.sh [preset ...]     (default: host asan tsan aarch64 fuzz)
set -euo pipefail
cd "$(dirname "$0")/.."

bash tools/setup.sh

presets=("$@")
[ ${#presets[@]} -gt 0 ] || presets=(host asan tsan aarch64 fuzz)
jobs=$(nproc)
passed=0
failed=0
status=0
for preset in "${presets[@]}"; do
  echo "=== ${preset}: configure + build"
  start=$(date +%s)
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset" -j "$jobs"
  echo "=== ${preset}: test"
  log=$(mktemp)
  if ctest --preset "$preset" -j "$jobs" 2>&1 | tee "$log"; then :; fi
  summary=$(grep -E '[0-9]+% tests passed, [0-9]+ tests? failed out of [0-9]+' "$log" | tail -1 || true)
  if [ -z "$summary" ]; then
    echo "=== ${preset}: ctest printed no summary" >&2
    status=1
  else
    total=$(sed -E 's/.* out of ([0-9]+).*/\1/' <<<"$summary")
    bad=$(sed -E 's/.* ([0-9]+) tests? failed.*/\1/' <<<"$summary")
    passed=$((passed + total - bad))
    failed=$((failed + bad))
    [ "$bad" -eq 0 ] || status=1
  fi
  rm -f "$log"
  echo "=== ${preset}: $(( $(date +%s) - start )) s"
done
echo "tests: ${passed} passed, ${failed} failed"
exit $status
