#!/usr/bin/env bash
# The whole test suite on a fresh Debian 12 machine (as root): installs what is
# missing, then builds and runs the tests natively, under AddressSanitizer +
# UndefinedBehaviorSanitizer with the libFuzzer targets' bounded runs (label `fuzz`; the
# `fuzz` preset builds them alone, for local fuzzing), cross-compiled for aarch64 under
# qemu-aarch64 (that tier includes the emulated-rig tests, label `rig`), and under
# ThreadSanitizer (the tests labelled `threaded` only).
# Usage: bash tools/test.sh [preset ...]     (default: host asan aarch64 tsan)
#
# The tiers build one after another in the background, at low priority (nice 19), while
# the previous tier's tests run (docs/ci.md): ctest -j$(nproc) seldom keeps every core
# busy (qemu start-up, a long test alone at the end of a tier) and the builds take most
# of the time. The tests keep the CPU they had; each tier's build log, test output and
# summary are printed in tier order. TSan runs last, when nothing builds beside its
# threaded tests.
set -euo pipefail
cd "$(dirname "$0")/.."

t0=$(date +%s)
bash tools/setup.sh
echo "=== setup: $(($(date +%s) - t0)) s"

presets=("$@")
[ ${#presets[@]} -gt 0 ] || presets=(host asan aarch64 tsan)
jobs=$(nproc)
work=$(mktemp -d)

set -m # the builder in a process group of its own, so that the exit trap stops all of it
(
  renice -n 19 -p "$BASHPID" >/dev/null
  for preset in "${presets[@]}"; do
    start=$(date +%s)
    rc=0
    { cmake --preset "$preset" >/dev/null && cmake --build --preset "$preset" -j "$jobs"; } \
      >"$work/$preset.build" 2>&1 || rc=$?
    echo "$rc $(($(date +%s) - start))" >"$work/$preset.tmp"
    mv "$work/$preset.tmp" "$work/$preset.done"
  done
) &
builder=$!
set +m
trap 'kill -- -"$builder" 2>/dev/null || true; wait; rm -rf "$work"' EXIT

follow() { # log done-marker: prints the log as it grows, until the marker exists
  local off=0 size finished
  while :; do
    finished=0
    [ -e "$2" ] && finished=1
    size=$(stat -c %s "$1" 2>/dev/null || echo 0)
    if [ "$size" -gt "$off" ]; then
      tail -c +$((off + 1)) "$1" | head -c $((size - off))
      off=$size
    fi
    [ "$finished" -eq 1 ] && return 0
    if ! kill -0 "$builder" 2>/dev/null && [ ! -e "$2" ]; then
      echo "=== the background build stopped without finishing this tier" >&2
      return 1
    fi
    sleep 2
  done
}

passed=0
failed=0
status=0
broken=()
for preset in "${presets[@]}"; do
  echo "=== ${preset}: configure + build"
  rc=1
  build_s="?"
  if follow "$work/$preset.build" "$work/$preset.done"; then
    read -r rc build_s <"$work/$preset.done"
  fi
  if [ "$rc" -ne 0 ]; then
    echo "=== ${preset}: configure or build FAILED (exit ${rc}) after ${build_s} s" >&2
    broken+=("$preset")
    status=1
    continue
  fi
  echo "=== ${preset}: built in ${build_s} s"
  echo "=== ${preset}: test"
  start=$(date +%s)
  log=$work/$preset.test
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
  echo "=== ${preset}: tests in $(($(date +%s) - start)) s"
done
wait "$builder" || status=1
echo "tests: ${passed} passed, ${failed} failed"
[ ${#broken[@]} -eq 0 ] || echo "tiers that did not build: ${broken[*]}"
echo "total: $(($(date +%s) - t0)) s"
exit $status
