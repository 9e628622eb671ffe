#!/usr/bin/env bash
# The loop's timing benchmark (issue 13): `drivetwin run` on the simulated buses, on the live
# clock (--live-clock: absolute deadlines, missed periods skipped, as in the cabinet) at the full
# CMS rate with calibration running, beside cyclictest (Debian's rt-tests)
# with the same period and priority, measured in the same session (cyclictest, the twin,
# cyclictest again, the twin again, so that both see the same machine); then the
# instructions per cycle (callgrind), the portable figure for the ARM box.
#
# Usage: tools/rt_bench/run.sh [--seconds S] [--rounds R] [--build DIR] [--cpu N]
#   --seconds: length of each run (default 600 = the issue's 10 minutes); --rounds: how many
#   cyclictest + twin pairs (default 2); --cpu: pin both
#   the twin's RT thread and cyclictest's thread to CPU N (default: unpinned).
# Needs SCHED_FIFO (root or CAP_SYS_NICE / RLIMIT_RTPRIO ≥ 80); without it both run at normal
# priority and the report says so. The machine is shared: the load is printed before each run.
set -euo pipefail
seconds=600
rounds=2
build=build/host
cpu=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --rounds) rounds="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    --cpu) cpu="$2"; shift 2 ;;
    *) echo "run.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
here="$(cd "$(dirname "$0")" && pwd)"
bin="$build/app/drivetwin"
[[ -x "$bin" ]] || { echo "run.sh: $bin not built (cmake --build $build --target drivetwin)" >&2; exit 1; }
command -v cyclictest >/dev/null || { echo "run.sh: cyclictest not installed (rt-tests, tools/setup.sh)" >&2; exit 1; }
period_us=1000
prio=80
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
config="$out/twin-bench.toml"
sed "s|^state_dir = .*|state_dir = \"$out/state\"|; s|\.\./\.\./app/|$here/../../app/|" "$here/twin-bench.toml" > "$config"
if [[ -n "$cpu" ]]; then printf '[threads.rt_loop]\npolicy = "fifo"\npriority = 80\ncpu = %s\n' "$cpu" > "$out/pin.toml"; sed -i '/^\[threads.rt_loop\]/,$d' "$config"; cat "$out/pin.toml" >> "$config"; fi

# cyclictest: p50/p99/p99.9/max and wake-ups later than the period, from its histogram.
cyclic() {  # $1 = label
  echo "load before cyclictest $1: $(cut -d' ' -f1-3 /proc/loadavg)"
  local affinity=()
  [[ -n "$cpu" ]] && affinity=(-a "$cpu")
  cyclictest -m -q -p "$prio" -i "$period_us" -D "$seconds" -t 1 "${affinity[@]}" -h 20000 > "$out/cyclic-$1.txt" 2>&1 || true
  awk -v period="$period_us" '
    /^[0-9]/ { n[$1+0] = $2; total += $2; if ($1+0 > period) late += $2 }
    /# Histogram Overflows/ { over = $4; late += $4; total += $4 }
    /# Max Latencies/ { max = $4 + 0 }
    END {
      split("0.5 0.99 0.999", q, " "); split("p50 p99 p99.9", name, " ")
      for (k = 1; k <= 3; ++k) {
        rank = q[k] * total; seen = 0
        for (i = 0; i <= 20000; ++i) { seen += n[i]; if (seen >= rank) { v[k] = i; break } }
      }
      printf "cyclictest: %d wake-ups, latency p50 %d µs, p99 %d µs, p99.9 %d µs, max %d µs; late by more than the period: %d\n", total, v[1], v[2], v[3], max, late
    }' "$out/cyclic-$1.txt" | tee "$out/cyclic-$1.sum"
}
twin() {  # $1 = label
  echo "load before the twin $1: $(cut -d' ' -f1-3 /proc/loadavg)"
  "$bin" run --config "$config" --duration "$seconds" --live-clock --timing "$out/timing-$1.json" --json "$out/summary-$1.json" > "$out/twin-$1.log" 2>&1
  python3 - "$out/timing-$1.json" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))
l, c = t["latency_us"], t["cycle_us"]
print("twin:       %d cycles, latency p50 %.0f µs, p99 %.0f µs, p99.9 %.0f µs, max %.0f µs; late by more than the period: %d (overruns counted by the loop: %d)"
      % (t["cycles"], l["p50"], l["p99"], l["p99_9"], l["max"], t["late_by_more_than_period"], t["overruns"]))
print("            cycle time p50 %.1f µs, p99 %.1f µs, p99.9 %.1f µs, max %.1f µs; RT thread %.1f %% of one core%s"
      % (c["p50"], c["p99"], c["p99_9"], c["max"], 100 * t["rt_cpu_share"],
         ("; " + t["rt_thread_warning"]) if t["rt_thread_warning"] else ""))
PY
}
echo "drivetwin timing benchmark: period $period_us µs, priority $prio (SCHED_FIFO), $seconds s per run, $(nproc) CPUs${cpu:+, pinned to CPU $cpu}"
for round in $(seq 1 "$rounds"); do
  cyclic "$round"
  twin "$round"
done
python3 - "$out" "$rounds" <<'PY'
import json, re, sys, glob
out = sys.argv[1]
for r in map(str, range(1, int(sys.argv[2]) + 1)):
    s = open(f"{out}/cyclic-{r}.sum").read()
    cyc = dict(zip(("p50", "p99", "p99_9", "max"), map(float, re.findall(r"(?:p50|p99|p99\.9|max) (\d+) µs", s))))
    late_c = int(re.search(r"period: (\d+)", s).group(1))
    t = json.load(open(f"{out}/timing-{r}.json"))
    ratio = t["latency_us"]["p99_9"] / cyc["p99_9"] if cyc["p99_9"] > 0 else float("nan")
    print(f"round {r}: twin / cyclictest p99.9 latency = {ratio:.2f} (goal ≤ 2); late cycles {t['late_by_more_than_period']} vs cyclictest's late wake-ups {late_c} (goal: no more); RT thread {100*t['rt_cpu_share']:.1f} % of a core (goal < 15 %)")
PY
# Instructions per cycle: a stepped run of the same twin (as fast as it goes) under callgrind,
# counting Twin::cycle only.
if command -v valgrind >/dev/null; then
  cycles=2000
  valgrind --tool=callgrind --callgrind-out-file="$out/cg" --toggle-collect='app::loop::Twin::cycle*' \
    "$bin" run --config "$config" --duration "$(awk -v n=$cycles -v p=$period_us 'BEGIN{print n*p/1e6}')" --speed max \
    --state-dir "$out/state-cg" > "$out/cg.log" 2>&1 || true
  ir=$(grep -E '^summary:|^totals:' "$out/cg" | head -1 | awk '{print $2}')
  echo "instructions per cycle (callgrind, Twin::cycle, $cycles cycles at the full CMS rate): $((ir / cycles))"
fi
