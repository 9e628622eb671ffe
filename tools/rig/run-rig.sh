#!/usr/bin/env bash
# Boots the emulated aarch64 rig (tools/rig/README.md) and judges it: builds the
# image with build-rig.sh, boots Debian's arm64 kernel under qemu-system-aarch64
# (-M virt, TCG), streams the serial console, reads the guest's Modbus daemons
# from the host with mbpoll through QEMU's user-mode hostfwd, and exits 0 only if
# every RIG-RESULT is PASS or SKIP, at least one check ran, and the guest reached
# RIG-END and powered itself off before the timeout.
#
# Usage: run-rig.sh [--timeout SECONDS] [--no-build] [--list FILE] <aarch64-build-dir>
# Environment: DRIVETWIN_RIG_CACHE (see build-rig.sh), DRIVETWIN_RIG_SMP (vCPUs, default 2)
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
die() { echo "run-rig.sh: error: $*" >&2; exit 2; }

timeout_s=420
build=1
build_args=()
build_dir=""
while [ $# -gt 0 ]; do
  case "$1" in
    --timeout) [ $# -ge 2 ] || die "--timeout needs seconds"; timeout_s=$2; shift 2
               [[ "$timeout_s" =~ ^[0-9]+$ ]] && [ "$timeout_s" -gt 0 ] || die "--timeout '$timeout_s' is not a positive number of seconds" ;;
    --no-build) build=0; shift ;;
    --list) [ $# -ge 2 ] || die "--list needs a file"; build_args+=(--list "$2"); shift 2 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    -*) die "unknown option '$1' (see --help)" ;;
    *) [ -z "$build_dir" ] || die "more than one build directory given"; build_dir=$1; shift ;;
  esac
done
[ -n "$build_dir" ] || die "usage: run-rig.sh [--timeout S] [--no-build] [--list FILE] <aarch64-build-dir>"
command -v qemu-system-aarch64 >/dev/null || die "qemu-system-aarch64 not found: run tools/setup.sh (package qemu-system-arm)"

cache=${DRIVETWIN_RIG_CACHE:-$repo/build/rig}
t0=$(date +%s)
if [ $build = 1 ]; then
  bash "$here/build-rig.sh" "${build_args[@]}" "$build_dir" || die "building the rig failed"
fi
[ -f "$cache/Image" ] && [ -f "$cache/rig.cpio.gz" ] || die "no rig image in $cache (run build-rig.sh)"
t_built=$(date +%s)

# Free host ports for the forwards (guest 1502..1509: Modbus daemons, one port each
# in name order; 1599: "host done").
port_free() { ! (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }
pick_port() {
  local p
  for _ in $(seq 50); do
    p=$((20000 + RANDOM % 40000))
    if port_free "$p"; then echo "$p"; return 0; fi
  done
  die "no free TCP port found on 127.0.0.1"
}
declare -A host_port=()
fwd=""
for gp in $(seq 1502 1509); do
  host_port[$gp]=$(pick_port)
  fwd+=",hostfwd=tcp:127.0.0.1:${host_port[$gp]}-:$gp"
done
hp_done=$(pick_port)
fwd+=",hostfwd=tcp:127.0.0.1:$hp_done-:1599"

log=$cache/console.log
: > "$log"
qemu-system-aarch64 \
  -M virt -cpu cortex-a57 -accel tcg -smp "${DRIVETWIN_RIG_SMP:-2}" -m 1024 \
  -nodefaults -display none -monitor none -no-reboot \
  -serial "file:$log" \
  -kernel "$cache/Image" -initrd "$cache/rig.cpio.gz" \
  -append "console=ttyAMA0 rdinit=/init quiet loglevel=3 panic=-1" \
  -netdev "user,id=n0$fwd" \
  -device virtio-net-pci,netdev=n0,romfile= \
  > "$cache/qemu.log" 2>&1 &
qpid=$!
rm -f "$cache/timed-out"
# Watchdog: polls once a second so that it ends soon after QEMU does (ctest waits
# for every process holding its output pipe).
( for _ in $(seq "$timeout_s"); do sleep 1; kill -0 $qpid 2>/dev/null || exit 0; done
  echo timeout > "$cache/timed-out"; kill $qpid ) >/dev/null 2>&1 &
watchdog=$!
trap 'kill $qpid $watchdog 2>/dev/null || true' EXIT

host_pass=0
host_fail=0
host_failures=()
host_result() {  # host_result <name> PASS|FAIL <detail>
  echo "RIG-RESULT host:$1 $2 ${*:3}"
  if [ "$2" = PASS ]; then host_pass=$((host_pass + 1)); else
    host_fail=$((host_fail + 1)); host_failures+=("RIG-RESULT host:$1 $2 ${*:3}"); fi
}
declare -A daemon_ready=()
# A daemon's line: RIG-READY modbus <name> port=<guest port> ref=<first register, 1-based> values=<v1,v2,...>
# The host reads those holding registers with Debian's mbpoll and compares.
modbus_check() {
  local name=$1 gport=$2 ref=$3 values=$4 hp out got
  hp=${host_port[$gport]:-}
  if [ -z "$hp" ]; then host_result "mbpoll-$name" FAIL "guest port $gport is not forwarded (1502..1509 are)"; return; fi
  local count
  count=$(tr ',' '\n' <<<"$values" | wc -l)
  if ! out=$(timeout 20 mbpoll -m tcp -p "$hp" -a 1 -t 4 -r "$ref" -c "$count" -1 -o 5 127.0.0.1 2>&1); then
    echo "$out" | sed 's/^/  | /'
    host_result "mbpoll-$name" FAIL "mbpoll failed against guest port $gport (host $hp)"
    return
  fi
  got=$(sed -n 's/^\[[0-9]*\]:[[:space:]]*\(-\?[0-9]*\).*/\1/p' <<<"$out" | paste -sd, -)
  if [ "$got" = "$values" ]; then
    host_result "mbpoll-$name" PASS "holding registers $ref..: $got"
  else
    echo "$out" | sed 's/^/  | /'
    host_result "mbpoll-$name" FAIL "expected $values, read $got"
  fi
}

end_seen=0
while IFS= read -r line; do
  line=${line%$'\r'}
  echo "$line"
  case "$line" in
    "RIG-READY modbus "*)
      read -r _ _ name gport ref values <<<"$line"
      daemon_ready[$name]=1
      modbus_check "$name" "${gport#port=}" "${ref#ref=}" "${values#values=}" ;;
    "RIG-DAEMON "*)
      read -r _ name _ <<<"$line"
      daemon_ready[$name]=${daemon_ready[$name]:-0} ;;
    RIG-WAIT-HOST)
      for name in "${!daemon_ready[@]}"; do
        [ "${daemon_ready[$name]}" = 1 ] || host_result "mbpoll-$name" FAIL "daemon never printed RIG-READY"
      done
      (exec 3<>"/dev/tcp/127.0.0.1/$hp_done" && echo "done: host checks finished" >&3) 2>/dev/null \
        || echo "run-rig.sh: could not signal the guest (it waits 90 s)" ;;
    RIG-END) end_seen=1 ;;
  esac
done < <(tail -n +1 -F --pid=$qpid "$log" 2>/dev/null)
wait $qpid 2>/dev/null || true
kill $watchdog 2>/dev/null || true
t_end=$(date +%s)

# Judge from the whole console (the stream above may have dropped nothing, but the
# file is the record).
tr -d '\r' < "$log" > "$cache/console.txt"
g_pass=$(grep -c '^RIG-RESULT [^ ]* PASS' "$cache/console.txt" || true)
g_fail=$(grep -c '^RIG-RESULT [^ ]* FAIL' "$cache/console.txt" || true)
g_skip=$(grep -c '^RIG-RESULT [^ ]* SKIP' "$cache/console.txt" || true)
grep -q '^RIG-END$' "$cache/console.txt" && end_seen=1

status=0
echo "run-rig.sh: build $((t_built - t0)) s, boot+run $((t_end - t_built)) s; guest: $g_pass passed, $g_fail failed, $g_skip skipped; host: $host_pass passed, $host_fail failed"
if [ -f "$cache/timed-out" ]; then
  echo "run-rig.sh: FAIL: the guest did not power off within $timeout_s s (console: $log)"; status=1
elif [ $end_seen = 0 ]; then
  echo "run-rig.sh: FAIL: the guest stopped without RIG-END (kernel panic or init died; console: $log, qemu: $cache/qemu.log)"
  sed 's/^/  qemu | /' "$cache/qemu.log"; status=1
fi
if [ $((g_pass + g_fail + host_pass + host_fail)) -eq 0 ]; then
  echo "run-rig.sh: FAIL: no check reported a result"; status=1
fi
if [ $((g_fail + host_fail)) -gt 0 ]; then
  echo "run-rig.sh: FAIL: failed checks:"
  grep '^RIG-RESULT [^ ]* FAIL' "$cache/console.txt" | sed 's/^/  /' || true
  for f in "${host_failures[@]}"; do echo "  $f"; done
  status=1
fi
[ $status = 0 ] && echo "run-rig.sh: PASS"
exit $status
