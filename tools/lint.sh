#!/usr/bin/env bash
# Checks that the project's C++ follows .clang-format and .clang-tidy.
# Usage: bash tools/lint.sh format          every .cpp/.hpp under app hal model tests tools (fast; in ctest)
#        bash tools/lint.sh fix             reformat them in place
#        bash tools/lint.sh tidy BUILD [FILE ...]
#                                           clang-tidy with BUILD's compile_commands.json on the given
#                                           sources (default: every .cpp; slow, ~10 s a file, not in CI)
set -euo pipefail
cd "$(dirname "$0")/.."
mode="${1:-format}"
sources() { find app hal model tests tools -name '*.cpp' -o -name '*.hpp' | grep -v '/corpus/' | sort; }
case "$mode" in
  format)
    command -v clang-format >/dev/null || { echo "lint.sh: clang-format not installed (tools/setup.sh)" >&2; exit 1; }
    sources | xargs clang-format --dry-run --Werror
    echo "lint.sh: $(sources | wc -l) files follow .clang-format"
    ;;
  fix)
    sources | xargs clang-format -i
    ;;
  tidy)
    build="${2:?usage: lint.sh tidy BUILD_DIR [FILE ...]}"
    shift 2
    files=("$@")
    [ ${#files[@]} -gt 0 ] || mapfile -t files < <(find app hal model tools -name '*.cpp' | sort)
    clang-tidy -p "$build" --quiet --warnings-as-errors='*' "${files[@]}"
    ;;
  *) echo "lint.sh: unknown mode '$mode' (format | fix | tidy)" >&2; exit 2 ;;
esac
