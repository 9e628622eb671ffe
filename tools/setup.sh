#!/usr/bin/env bash
# Installs everything drivetwin needs on a fresh Debian 12 machine (run as root).
# Idempotent: packages already present are not touched and nothing is printed
# beyond one line when there is nothing to do.
set -euo pipefail

if [ "$(id -u)" -ne 0 ]; then
  echo "setup.sh: run as root (it calls apt-get)" >&2
  exit 1
fi

# Host toolchain, libraries and test tools.
host_pkgs=(
  build-essential cmake ninja-build pkg-config file git
  g++ clang libclang-rt-14-dev clang-format clang-tidy
  googletest libgtest-dev libgmock-dev libbenchmark-dev valgrind
  libeigen3-dev libtomlplusplus-dev nlohmann-json3-dev libcli11-dev
  libkissfft-dev libboost-dev libcpp-httplib-dev libmatio-dev libpagmo-dev
  libmodbus-dev libgpiod-dev mbpoll
  # trends database (app/trends: embedded SQLite, WAL) and its command-line reader
  libsqlite3-dev sqlite3
  # the timing benchmark's reference (cyclictest at the loop's period and priority)
  rt-tests
  qemu-user g++-aarch64-linux-gnu
  # emulated aarch64 rig (tools/rig): the arm64 .debs it boots are fetched by build-rig.sh
  qemu-system-arm cpio kmod xz-utils
)
# Target (aarch64) libraries through multiarch: the cross build links these and
# qemu-aarch64 runs the test binaries against the multiarch libc6:arm64.
arm64_pkgs=(
  libc6:arm64 libstdc++6:arm64 libgcc-s1:arm64
  libgtest-dev:arm64 libgmock-dev:arm64
  libtomlplusplus-dev:arm64 libkissfft-dev:arm64
  libmodbus-dev:arm64 libgpiod-dev:arm64
  libsqlite3-dev:arm64
)

if ! dpkg --print-foreign-architectures | grep -qx arm64; then
  dpkg --add-architecture arm64
  need_update=1
fi

missing=()
for p in "${host_pkgs[@]}" "${arm64_pkgs[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Abbrev}' "$p" 2>/dev/null || true)
  [ "${status:0:2}" = "ii" ] || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup.sh: all ${#host_pkgs[@]} host and ${#arm64_pkgs[@]} arm64 packages present"
  exit 0
fi

echo "setup.sh: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup.sh: done"
