#!/usr/bin/env bash
# The main job on the built-in default data, on a fresh Debian 12 machine (as root):
# installs what is missing, builds the host preset and runs `drivetwin demo`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
cmake --preset host >/dev/null
cmake --build --preset host -j "$(nproc)" --target drivetwin
exec ./build/host/app/drivetwin demo "$@"
