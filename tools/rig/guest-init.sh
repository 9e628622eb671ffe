#!/bin/busybox sh
# /init of the rig's initramfs (tools/rig/README.md is the contract this implements).
# Runs as PID 1 in the emulated aarch64 guest: sets up vcan and gpio-sim, runs the
# rig's own shell-level checks and every /rig/tests/rig_* binary, prints one
# RIG-RESULT line per check on the serial console, then powers the machine off.
# It must never exit (PID 1 exiting panics the kernel): everything ends in poweroff.

/bin/busybox mkdir -p /proc /sys /dev /tmp /run /usr/bin /usr/sbin /sbin
/bin/busybox mount -t devtmpfs devtmpfs /dev
exec 0</dev/console 1>/dev/console 2>&1
/bin/busybox --install -s /bin
export PATH=/usr/bin:/usr/sbin:/bin:/sbin
export LD_LIBRARY_PATH=/lib/aarch64-linux-gnu
export HOME=/tmp
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t tmpfs tmpfs /tmp
mount -t tmpfs tmpfs /run

passed=0
failed=0
skipped=0
result() {  # result <name> PASS|FAIL|SKIP <detail...>
  name=$1; verdict=$2; shift 2
  echo "RIG-RESULT $name $verdict $*"
  case "$verdict" in
    PASS) passed=$((passed + 1)) ;;
    SKIP) skipped=$((skipped + 1)) ;;
    *) failed=$((failed + 1)) ;;
  esac
}
finish() {
  echo "RIG-SUMMARY passed=$passed failed=$failed skipped=$skipped uptime_s=$(cut -d' ' -f1 /proc/uptime)"
  echo "RIG-END"
  sync
  poweroff -f
  sleep 10
  echo "RIG-ERROR poweroff did not stop the machine"
  while true; do sleep 60; done
}
check() {  # check <name> <command...>: PASS when the command exits 0; its output is shown
  name=$1; shift
  out=$("$@" 2>&1)
  rc=$?
  [ -z "$out" ] || echo "$out" | sed 's/^/  | /'
  if [ $rc = 0 ]; then result "shell:$name" PASS
  else result "shell:$name" FAIL "exit $rc"; fi
}

echo "RIG-BEGIN uptime_s=$(cut -d' ' -f1 /proc/uptime) $(cat /rig/build-info | tr '\n' ' ')"
dmesg -n 1 2>/dev/null

# --- kernel modules ---------------------------------------------------------------
mods_ok=1
while read -r ko; do
  if ! out=$(insmod "$ko" 2>&1); then
    echo "  | insmod $ko: $out"
    mods_ok=0
  fi
done < /rig/modules.list
if [ $mods_ok = 1 ]; then result shell:modules PASS "$(wc -l < /rig/modules.list) loaded"
else result shell:modules FAIL "an insmod failed (above)"; fi
mount -t configfs configfs /sys/kernel/config || echo "  | configfs mount failed"

# --- CAN: vcan0 (CAN FD capable, mtu 72) and vcan1 (classic, mtu 16) ---------------------
can_setup() {
  ip link add dev vcan0 type vcan && ip link set vcan0 mtu 72 && ip link set vcan0 up &&
  ip link add dev vcan1 type vcan && ip link set vcan1 mtu 16 && ip link set vcan1 up
}
check can-setup can_setup
check vcan0-is-fd-capable-and-up sh -c 'ip link show vcan0 | grep -q "mtu 72" && ip link show vcan0 | grep -q "UP"'
check vcan1-is-classic-and-up sh -c 'ip link show vcan1 | grep -q "mtu 16" && ip link show vcan1 | grep -q "UP"'

# cansend -> candump: the exact bytes come back (classic and FD). candump prints the
# FD flags nibble: cansend asked for BRS (0x1), the 6.1 kernel adds CANFD_FDF (0x4).
can_roundtrip() {
  candump -L -n 2 vcan0 > /tmp/rt.log &
  dump=$!
  sleep 0.3
  cansend vcan0 5A1#1122334455667788
  cansend vcan0 1F334455##1000102030405060708090A0B0C0D0E0F
  ( sleep 10; kill $dump 2>/dev/null ) &
  wait $dump
  cat /tmp/rt.log
  grep -q ' vcan0 5A1#1122334455667788$' /tmp/rt.log &&
  grep -q ' vcan0 1F334455##5000102030405060708090A0B0C0D0E0F$' /tmp/rt.log
}
check cansend-candump-roundtrip-classic-and-fd can_roundtrip

# cangen -> candump: every generated frame arrives (incrementing payload, fixed id).
cangen_count() {
  n=200
  candump -L -n $n vcan0 > /tmp/gen.log &
  dump=$!
  sleep 0.3
  cangen vcan0 -f -I 2A0 -L 64 -D i -g 1 -n $n
  ( sleep 20; kill $dump 2>/dev/null ) &
  wait $dump
  got=$(grep -c ' vcan0 2A0##' /tmp/gen.log)
  echo "cangen sent $n CAN FD frames, candump saw $got"
  [ "$got" = "$n" ]
}
check cangen-candump-200-fd-frames cangen_count

# A CAN FD frame cannot go out on a classic-only interface.
# cansend checks the interface's mtu itself and says so; the kernel's own refusal
# (EINVAL from raw_sendmsg) is checked by rig_selfcheck.
check classic-vcan1-rejects-fd-frames sh -c '
  out=$(cansend vcan1 123##1AABB 2>&1) && exit 1
  echo "$out"; echo "$out" | grep -q "not CAN FD capable"'

# --- GPIO: a gpio-sim chip with named lines ------------------------------------------------
gpio_setup() {
  d=/sys/kernel/config/gpio-sim/drivetwin
  mkdir $d && mkdir $d/bank0 || return 1
  echo 8 > $d/bank0/num_lines
  i=0
  for name in keyphasor watchdog alarm_relay rig_selftest spare4 spare5 spare6 spare7; do
    mkdir $d/bank0/line$i && echo $name > $d/bank0/line$i/name || return 1
    i=$((i + 1))
  done
  echo 1 > $d/live
  [ "$(cat $d/live)" = 1 ]
}
check gpio-sim-chip-live gpio_setup
gs_dev=$(cat /sys/kernel/config/gpio-sim/drivetwin/dev_name 2>/dev/null)
gs_chip=$(cat /sys/kernel/config/gpio-sim/drivetwin/bank0/chip_name 2>/dev/null)
gs_dir=/sys/devices/platform/$gs_dev/$gs_chip
echo "  | gpio-sim: device $gs_dev chip $gs_chip"
gpiodetect | sed 's/^/  | /'

check gpiofind-names-the-contract-lines sh -c '
  [ "$(gpiofind keyphasor)" = "'"$gs_chip"' 0" ] &&
  [ "$(gpiofind watchdog)" = "'"$gs_chip"' 1" ] &&
  [ "$(gpiofind alarm_relay)" = "'"$gs_chip"' 2" ]'

# Input: the simulator pull is what gpioget reads.
gpio_input() {
  echo pull-up > $gs_dir/sim_gpio3/pull && a=$(gpioget $gs_chip 3) &&
  echo pull-down > $gs_dir/sim_gpio3/pull && b=$(gpioget $gs_chip 3) &&
  echo "pull-up -> $a, pull-down -> $b" && [ "$a" = 1 ] && [ "$b" = 0 ]
}
check gpioget-reads-the-simulated-pull gpio_input

# Edges: gpiomon sees every toggle of the pull, in order.
gpio_edges() {
  gpiomon -n 6 $gs_chip 3 > /tmp/mon.log &
  mon=$!
  sleep 0.5
  for i in 1 2 3; do
    echo pull-up > $gs_dir/sim_gpio3/pull; sleep 0.05
    echo pull-down > $gs_dir/sim_gpio3/pull; sleep 0.05
  done
  ( sleep 10; kill $mon 2>/dev/null ) &
  wait $mon
  cat /tmp/mon.log
  [ "$(grep -c RISING /tmp/mon.log)" = 3 ] && [ "$(grep -c FALLING /tmp/mon.log)" = 3 ] &&
  [ "$(awk '{print $1}' /tmp/mon.log | tr '\n' ' ')" = "event: event: event: event: event: event: " ] &&
  [ "$(grep -o 'RISING\|FALLING' /tmp/mon.log | tr '\n' ' ')" = "RISING FALLING RISING FALLING RISING FALLING " ]
}
check gpiomon-sees-three-rising-and-three-falling-edges gpio_edges

# Output: what gpioset drives is what the simulator side reads.
gpio_output() {
  gpioset --mode=signal $gs_chip 3=1 &
  set1=$!
  sleep 0.5
  v1=$(cat $gs_dir/sim_gpio3/value)
  kill $set1; wait $set1 2>/dev/null
  gpioset --mode=signal $gs_chip 3=0 &
  set0=$!
  sleep 0.5
  v0=$(cat $gs_dir/sim_gpio3/value)
  kill $set0; wait $set0 2>/dev/null
  echo "driven 1 -> $v1, driven 0 -> $v0"
  [ "$v1" = 1 ] && [ "$v0" = 0 ]
}
check gpioset-output-read-back-on-the-simulator-side gpio_output
echo pull-down > $gs_dir/sim_gpio3/pull 2>/dev/null

# --- network (for Modbus from the host) -------------------------------------------------------
net_setup() {
  ip link set lo up && ip link set eth0 up &&
  ip addr add 10.0.2.15/24 dev eth0 && ip route add default via 10.0.2.2
}
check network-eth0-up net_setup

# --- environment of the binaries (the contract) ---------------------------------------------
export DRIVETWIN_RIG=1
export DRIVETWIN_RIG_CAN=vcan0
export DRIVETWIN_RIG_CAN_CLASSIC=vcan1
export DRIVETWIN_RIG_GPIOCHIP=/dev/$gs_chip
export DRIVETWIN_RIG_GPIOCHIP_NAME=$gs_chip
export DRIVETWIN_RIG_GPIOCHIP_LABEL=$(cat /sys/bus/gpio/devices/$gs_chip/label 2>/dev/null || echo "$gs_dev-node0")
export DRIVETWIN_RIG_KEYPHASOR_LINE=0
export DRIVETWIN_RIG_WATCHDOG_LINE=1
export DRIVETWIN_RIG_ALARM_LINE=2
export DRIVETWIN_RIG_SELFTEST_LINE=3
export DRIVETWIN_RIG_GPIOSIM_DIR=$gs_dir

# --- daemons (Modbus servers the host reads with mbpoll) ------------------------------------
port=1502
daemons=""
for d in /rig/daemons/rigd_*; do
  [ -x "$d" ] || continue
  n=$(basename "$d")
  echo "RIG-DAEMON $n port=$port"
  (cd /tmp && DRIVETWIN_RIG_MODBUS_PORT=$port exec "$d") > /tmp/$n.out 2>&1 &
  daemons="$daemons $!"
  # Relay its RIG-READY line from here, before any test binary writes to the
  # console, so that the host never sees it interleaved with other output.
  i=0
  while [ $i -lt 150 ] && ! grep -q '^RIG-READY ' /tmp/$n.out; do sleep 0.1; i=$((i + 1)); done
  grep '^RIG-READY ' /tmp/$n.out | head -1
  grep -v '^RIG-READY ' /tmp/$n.out | sed "s/^/  | $n: /"
  port=$((port + 1))
done

# --- the test binaries ---------------------------------------------------------------------------
ran=0
for t in /rig/tests/rig_*; do
  [ -x "$t" ] || continue
  ran=$((ran + 1))
  n=$(basename "$t")
  echo "RIG-RUN bin:$n"
  rm -f /tmp/$n.rc
  ( cd /tmp && timeout -s KILL 120 "$t" --gtest_color=no 2>&1; echo $? > /tmp/$n.rc ) | tee /tmp/$n.log
  rc=$(cat /tmp/$n.rc 2>/dev/null || echo 255)
  # GoogleTest's summary: "[==========] N tests from M test suites ran." and
  # "[  SKIPPED ] K tests, listed below:". A binary whose every test skipped inside
  # the rig proved nothing: that is SKIP, not PASS.
  total=$(sed -n 's/^\[==========\] \([0-9]*\) tests\{0,1\} from .* ran\..*/\1/p' /tmp/$n.log | tail -1)
  skips=$(sed -n 's/^\[  SKIPPED \] \([0-9]*\) tests\{0,1\}, listed below.*/\1/p' /tmp/$n.log | tail -1)
  total=${total:-0}; skips=${skips:-0}
  if [ "$rc" = 0 ] && [ "$total" -gt 0 ] && [ "$skips" = "$total" ]; then result "bin:$n" SKIP "all $total tests skipped"
  elif [ "$rc" = 0 ] && [ "$total" -gt 0 ]; then result "bin:$n" PASS "$((total - skips)) of $total tests ran and passed, $skips skipped"
  elif [ "$rc" = 0 ]; then result "bin:$n" FAIL "exit 0 but no GoogleTest summary (ran no tests?)"
  elif [ "$rc" = 137 ]; then result "bin:$n" FAIL "killed after 120 s"
  else result "bin:$n" FAIL "exit $rc"; fi
  echo pull-down > $gs_dir/sim_gpio0/pull 2>/dev/null
done
[ $ran -gt 0 ] || echo "  | no rig_* test binaries in this image"

# --- wait for the host's checks of the daemons, then stop them ---------------------------------
if [ -n "$daemons" ]; then
  # The host connects to forwarded port 1599 and sends one line when it is done.
  # QEMU's forward accepts the host's connection even when nothing listens in the
  # guest, so the listener must be up before the host is told to connect.
  timeout 90 nc -l -p 1599 > /tmp/host-done 2>/dev/null &
  listener=$!
  sleep 1
  echo "RIG-WAIT-HOST"
  wait $listener
  if [ -s /tmp/host-done ]; then
    echo "  | host: $(cat /tmp/host-done)"
  else
    echo "  | host never signalled (90 s)"
  fi
  for p in $daemons; do
    kill "$p" 2>/dev/null
  done
fi

finish
