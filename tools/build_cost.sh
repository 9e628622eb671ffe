#!/usr/bin/env bash
# The CPU cost of a cold build of one preset, per compiler and linker run (docs/ci.md).
# Builds into build/cost-<preset> with no ccache, every compile and link timed by
# /usr/bin/time (user + system CPU seconds: on a shared machine these move far less than
# wall time), then prints the sum and the most expensive outputs.
#
#   bash tools/build_cost.sh <preset> [-j N]       cold build, writes build/cost-<preset>/cost.log
#   bash tools/build_cost.sh --tus <configured build dir> <target> <output regex> [-j N]
#       compiles again only the objects of <target> whose output matches (e.g. '^tests/'),
#       writes tus.log:
#       before/after figures of a change to some TUs, without rebuilding the libraries.
#   bash tools/build_cost.sh --sum <cost.log> [<build dir> <target>]
#       sums a cost.log; with a configured build dir and a target, only the outputs that
#       target needs in that build's current graph (what a change of targets removes).
set -euo pipefail

if [ "${1:-}" = "--exec" ]; then # the compiler/linker launcher
  shift
  out="?"
  prev=
  for a in "$@"; do
    [ "$prev" = "-o" ] && out=$a
    prev=$a
  done
  exec /usr/bin/time -a -o "$DRIVETWIN_COST_LOG" -f "%U %S %e $out" "$@"
fi

summarise() { # cost.log [outputs file]
  local rows
  rows=$(mktemp)
  awk -v only="${2:-}" -v rows="$rows" '
    BEGIN { if (only != "") while ((getline line < only) > 0) keep[line] = 1 }
    only != "" && !($4 in keep) { next }
    { cpu = $1 + $2; total += cpu; n++
      kind = ($4 ~ /\.o$/) ? "compile" : ($4 ~ /\.a$/) ? "archive" : "link"
      by[kind] += cpu; cnt[kind]++
      area = $4; sub(/\/.*/, "", area); byarea[area] += cpu
      print cpu, $4 > rows }
    END { printf "total %.0f s CPU in %d runs\n", total, n
          for (k in by) printf "  %-8s %6.0f s (%d)\n", k, by[k], cnt[k]
          for (a in byarea) printf "  %-8s %6.0f s\n", a "/", byarea[a] }' "$1"
  echo "  most expensive:"
  sort -rn "$rows" | head -15 | sed 's/^/    /'
  rm -f "$rows"
}

if [ "${1:-}" = "--tus" ]; then # <configured build dir> <target> <output regex> [-j N]
  # Compiles again, from the build's compile_commands.json and without ccache, each object
  # the target needs whose output path matches the regex (into a scratch dir: the build is
  # untouched; no library needs building first), timed like a cold build; writes
  # <build dir>/tus.log.
  dir=${2:?usage: build_cost.sh --tus <build dir> <target> <output regex> [-j N]}
  target=${3:?}
  regex=${4:?}
  tu_jobs=2
  [ "${5:-}" = "-j" ] && tu_jobs=${6:?}
  scratch=$(mktemp -d)
  log=$(cd "$dir" && pwd)/tus.log
  : >"$log"
  ninja -C "$dir" -t commands "$target" | grep -oE ' -o [^ ]+' | sed 's/^ -o //' | sort -u >"$scratch/outputs"
  python3 - "$dir/compile_commands.json" "$regex" "$scratch" <<'PY' |
import json, re, shlex, sys
entries, regex, scratch = json.load(open(sys.argv[1])), re.compile(sys.argv[2]), sys.argv[3]
wanted = set(open(scratch + "/outputs").read().split())
for i, e in enumerate(entries):
    out = re.search(r" -o (\S+)", e["command"]).group(1)
    if out not in wanted or not regex.search(out):
        continue
    cmd = re.sub(r"^\S*ccache ", "", e["command"])
    cmd = re.sub(r" -MD -MT \S+ -MF \S+", "", cmd).replace(" -o " + out, f" -o {scratch}/{i}.o")
    print(shlex.quote(f"cd {shlex.quote(e['directory'])} && {cmd}") + " " + shlex.quote(out))
PY
    CCACHE_DISABLE=1 xargs -P "$tu_jobs" -L 1 sh -c '/usr/bin/time -a -o "$0" -f "%U %S %e $2" sh -c "$1"' "$log"
  rm -rf "$scratch"
  summarise "$log"
  exit 0
fi

if [ "${1:-}" = "--sum" ]; then
  log=$2
  if [ $# -ge 4 ]; then
    outputs=$(mktemp)
    # Every output of every build edge the target needs (ninja -t commands gives the
    # commands; their -o arguments are the outputs, relative to the build dir).
    ninja -C "$3" -t commands "$4" | grep -oE ' -o [^ ]+' | sed 's/^ -o //' | sort -u >"$outputs"
    summarise "$log" "$outputs"
    rm -f "$outputs"
  else
    summarise "$log"
  fi
  exit 0
fi

preset=${1:?usage: build_cost.sh <preset> [-j N]}
jobs=2
[ "${2:-}" = "-j" ] && jobs=${3:?}
cd "$(dirname "$0")/.."
dir=build/cost-$preset
rm -rf "$dir"
export DRIVETWIN_COST_LOG=$PWD/$dir/cost.log CCACHE_DISABLE=1
self=$PWD/tools/build_cost.sh
launcher="$self;--exec"
cmake --preset "$preset" -B "$dir" -DCMAKE_CXX_COMPILER_LAUNCHER="$launcher" \
  -DCMAKE_CXX_LINKER_LAUNCHER="$launcher" >/dev/null
start=$(date +%s)
# The build preset's targets (tools/test.sh builds those), in this build dir.
targets=$(python3 -c "import json,sys; p=[b for b in json.load(open('CMakePresets.json'))['buildPresets'] if b['name']==sys.argv[1]]; print(' '.join(p[0].get('targets', ['all'])) if p else 'all')" "$preset")
# shellcheck disable=SC2086
cmake --build "$dir" -j "$jobs" --target $targets >/dev/null
echo "${preset}: cold build of ${targets} in $(($(date +%s) - start)) s wall at -j${jobs}"
summarise "$DRIVETWIN_COST_LOG"
