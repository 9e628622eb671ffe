#!/usr/bin/env bash
# Builds the emulated aarch64 rig (tools/rig/README.md) from Debian packages only:
#   - Debian 12's arm64 kernel (linux-image-<abi>-arm64), uncompressed Image + .ko modules
#   - gpio-sim + irq_sim built out of tree from linux-source-6.1 against Debian's
#     linux-headers for that kernel (Debian's config leaves CONFIG_GPIO_SIM unset)
#   - busybox-static, can-utils and gpiod for arm64, plus the arm64 shared libraries
#     they and the cross-built test binaries link (host multiarch :arm64 packages)
#   - the cross-built rig_* test binaries and rigd_* daemons of an aarch64 build
# into <cache>/rig.cpio.gz and <cache>/Image.
#
# Usage: build-rig.sh [--list FILE] <aarch64-build-dir>
#   --list FILE   text file with one path per line of the rig_*/rigd_* binaries to
#                 include (tests/rig writes it at configure time); without it the
#                 build directory is searched for executables named rig_* / rigd_*.
# Environment:
#   DRIVETWIN_RIG_CACHE       cache directory (default: <repo>/build/rig)
#   DRIVETWIN_RIG_KERNEL_ABI  e.g. 6.1.0-56-arm64 (default: the cache's kernel, else
#                             what Debian's linux-image-arm64 meta-package depends on)
# Idempotent: downloads and the module build are cached; the initramfs is re-packed
# on every run (a few seconds) so that freshly built test binaries are picked up.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
die() { echo "build-rig.sh: error: $*" >&2; exit 1; }
log() { echo "build-rig.sh: $*"; }

list_file=""
build_dir=""
while [ $# -gt 0 ]; do
  case "$1" in
    --list) [ $# -ge 2 ] || die "--list needs a file"; list_file=$2; shift 2 ;;
    -h|--help) sed -n '2,22p' "$0"; exit 0 ;;
    -*) die "unknown option '$1' (see --help)" ;;
    *) [ -z "$build_dir" ] || die "more than one build directory given ('$build_dir', '$1')"
       build_dir=$1; shift ;;
  esac
done
[ -n "$build_dir" ] || die "usage: build-rig.sh [--list FILE] <aarch64-build-dir>"
[ -d "$build_dir" ] || die "build directory '$build_dir' does not exist (configure the aarch64 preset first)"
build_dir=$(cd "$build_dir" && pwd)

cache=${DRIVETWIN_RIG_CACHE:-$repo/build/rig}
mkdir -p "$cache"
cache=$(cd "$cache" && pwd)
debs=$cache/debs
kroot=$cache/kroot
mkdir -p "$debs"

for tool in apt-get dpkg-deb depmod modprobe cpio gzip xz make aarch64-linux-gnu-gcc aarch64-linux-gnu-readelf; do
  command -v "$tool" >/dev/null || die "'$tool' not found: run tools/setup.sh (as root)"
done

# One build at a time per cache (two ctest runs, or ctest and a hand-run).
exec 9>"$cache/.lock"
flock 9

# --- which kernel --------------------------------------------------------------
abi=${DRIVETWIN_RIG_KERNEL_ABI:-}
if [ -z "$abi" ] && [ -f "$cache/kernel-abi" ]; then
  abi=$(cat "$cache/kernel-abi")
fi
if [ -z "$abi" ]; then
  dep=$(apt-cache depends linux-image-arm64:arm64 2>/dev/null | awk '/Depends: linux-image-/ {print $2; exit}')
  [ -n "$dep" ] || die "apt knows no linux-image-arm64:arm64; enable arm64 (dpkg --add-architecture arm64 && apt-get update, as tools/setup.sh does)"
  abi=${dep#linux-image-}
  abi=${abi%:arm64}
fi
case "$abi" in
  6.1.*-arm64) ;;
  *) die "kernel ABI '$abi' is not a Debian 12 6.1 arm64 kernel (expected e.g. 6.1.0-56-arm64)" ;;
esac
image=$kroot/boot/vmlinuz-$abi
headers=$kroot/usr/src/linux-headers-$abi
moddir=$kroot/lib/modules/$abi

# apt-get download <pkg>=<version> into debs/, once. The file name is recorded so
# that a later run needs no apt at all.
fetch() {  # fetch <name> <arch-qualified package> [version]
  local name=$1 pkg=$2 ver=${3:-} spec
  if [ -f "$debs/$name.path" ] && [ -f "$(cat "$debs/$name.path")" ]; then
    return 0
  fi
  spec=$pkg
  [ -z "$ver" ] || spec="$pkg=$ver"
  log "downloading $spec"
  (cd "$debs" && apt-get download -q "$spec" 2>&1 | grep -v -e 'unsandboxed' -e '^Get:' -e '^Fetched' || true)
  local base=${pkg%%:*}
  local f
  f=$(ls -t "$debs/${base}_"*.deb 2>/dev/null | head -1 || true)
  [ -n "$f" ] || die "apt-get download $spec produced no .deb in $debs (network? apt-get update?)"
  echo "$f" > "$debs/$name.path"
}
deb_of() { cat "$debs/$1.path"; }

# --- kernel, headers, kbuild, source -------------------------------------------
if [ ! -f "$cache/kernel.done" ] || [ "$(cat "$cache/kernel-abi" 2>/dev/null)" != "$abi" ]; then
  rm -rf "$kroot" "$cache/kernel.done" "$cache/modules.done" "$debs"/*.path
  kver=$(apt-cache policy "linux-image-$abi:arm64" 2>/dev/null | awk '/Candidate:/ {print $2; exit}')
  [ "$kver" != "(none)" ] || kver=""
  [ -n "$kver" ] || die "apt knows no linux-image-$abi:arm64 (apt-get update? set DRIVETWIN_RIG_KERNEL_ABI?)"
  common=${abi%-arm64}-common
  fetch image   "linux-image-$abi:arm64" "$kver"
  fetch headers "linux-headers-$abi:arm64" "$kver"
  fetch common  "linux-headers-$common" "$kver"
  fetch kbuild  "linux-kbuild-6.1" "$kver"
  fetch source  "linux-source-6.1" "$kver"
  mkdir -p "$kroot"
  for p in image headers common kbuild; do
    dpkg-deb -x "$(deb_of $p)" "$kroot"
  done
  [ -f "$image" ] || die "linux-image-$abi has no /boot/vmlinuz-$abi"
  # The headers' Makefile includes the -common tree by its absolute /usr/src path;
  # point it at our extracted copy (the scripts/ symlinks are relative and land in
  # the extracted linux-kbuild-6.1).
  sed -i "s|^include /usr/src/|include $kroot/usr/src/|" "$headers/Makefile"
  log "extracting gpio-sim and irq_sim from linux-source-6.1"
  rm -rf "$cache/src"
  mkdir -p "$cache/src"
  # tar stops reading at the last wanted member (--occurrence), which closes the
  # pipe early: the pipeline's status is not meaningful, the files' presence is.
  (set +o pipefail
   dpkg-deb --fsys-tarfile "$(deb_of source)" 2>/dev/null \
     | tar -xO ./usr/src/linux-source-6.1.tar.xz \
     | xz -dc \
     | tar -x -C "$cache/src" --occurrence=1 \
         linux-source-6.1/drivers/gpio/gpio-sim.c \
         linux-source-6.1/drivers/gpio/gpiolib.h \
         linux-source-6.1/kernel/irq/irq_sim.c 2>/dev/null) || true
  for f in drivers/gpio/gpio-sim.c drivers/gpio/gpiolib.h kernel/irq/irq_sim.c; do
    [ -f "$cache/src/linux-source-6.1/$f" ] || die "linux-source-6.1 has no $f"
  done
  echo "$abi" > "$cache/kernel-abi"
  touch "$cache/kernel.done"
fi
cp -f "$image" "$cache/Image"

# --- gpio-sim + irq_sim, out of tree ---------------------------------------------
if [ ! -f "$cache/modules.done" ]; then
  log "building gpio-sim.ko and irq_sim.ko for $abi"
  mod=$cache/mod
  rm -rf "$mod"
  mkdir -p "$mod"
  s=$cache/src/linux-source-6.1
  cp "$s/drivers/gpio/gpio-sim.c" "$s/drivers/gpio/gpiolib.h" "$s/kernel/irq/irq_sim.c" "$mod/"
  # irq_sim calls the un-exported irq_to_desc(); generic_handle_irq() is exported
  # and runs the same flow handler (handle_simple_irq, set by irq_sim's domain map).
  grep -q 'handle_simple_irq(irq_to_desc(irqnum));' "$mod/irq_sim.c" \
    || die "irq_sim.c in linux-source-6.1 changed: the irq_to_desc patch no longer applies"
  sed -i 's/handle_simple_irq(irq_to_desc(irqnum));/generic_handle_irq(irqnum);/' "$mod/irq_sim.c"
  # Built in, irq_sim needs no module boilerplate; as a module it must declare a licence.
  printf '\n#include <linux/module.h>\nMODULE_LICENSE("GPL");\nMODULE_DESCRIPTION("irq_sim, built out of tree for the drivetwin rig");\n' >> "$mod/irq_sim.c"
  echo 'obj-m := irq_sim.o gpio-sim.o' > "$mod/Kbuild"
  make -s -C "$headers" M="$mod" ARCH=arm64 CROSS_COMPILE=aarch64-linux-gnu- modules \
    > "$mod/build.log" 2>&1 || { cat "$mod/build.log" >&2; die "building gpio-sim failed (log above)"; }
  if grep -E 'WARNING|ERROR' "$mod/build.log" >&2; then
    die "modpost complained while building gpio-sim (above)"
  fi
  mkdir -p "$moddir/extra"
  cp "$mod/gpio-sim.ko" "$mod/irq_sim.ko" "$moddir/extra/"
  depmod -b "$kroot" "$abi"
  touch "$cache/modules.done"
fi

# --- arm64 user land --------------------------------------------------------------
ul=$cache/userland
if [ ! -f "$cache/userland.done" ]; then
  rm -rf "$ul"
  mkdir -p "$ul"
  fetch busybox "busybox-static:arm64"
  fetch canutils "can-utils:arm64"
  fetch gpiod "gpiod:arm64"
  for p in busybox canutils gpiod; do
    dpkg-deb -x "$(deb_of $p)" "$ul"
  done
  touch "$cache/userland.done"
fi

# --- the binaries under test ----------------------------------------------------------
bins=()
if [ -n "$list_file" ]; then
  [ -f "$list_file" ] || die "binary list '$list_file' does not exist"
  while IFS= read -r line; do
    [ -n "$line" ] || continue
    [ -x "$line" ] || die "$list_file lists '$line', which is not built (build the rig_* targets first)"
    bins+=("$line")
  done < "$list_file"
else
  while IFS= read -r f; do bins+=("$f"); done < <(
    find "$build_dir" -path '*/CMakeFiles' -prune -o -type f \( -name 'rig_*' -o -name 'rigd_*' \) -perm -u+x -print | sort)
fi
for b in "${bins[@]}"; do
  file -b "$b" | grep -q 'ARM aarch64' || die "'$b' is not an aarch64 executable (wrong build directory?)"
done

# --- initramfs ------------------------------------------------------------------------
stage=$cache/initramfs
rm -rf "$stage"
mkdir -p "$stage"/{bin,sbin,usr/bin,usr/sbin,lib/aarch64-linux-gnu,proc,sys,dev,tmp,run,etc,rig/tests,rig/daemons}
cp "$ul/bin/busybox" "$stage/bin/busybox"
cp "$ul"/usr/bin/* "$stage/usr/bin/"
cp "$here/guest-init.sh" "$stage/init"
chmod 755 "$stage/init"
for b in "${bins[@]}"; do
  case "$(basename "$b")" in
    rigd_*) cp "$b" "$stage/rig/daemons/" ;;
    *) cp "$b" "$stage/rig/tests/" ;;
  esac
done

# Kernel modules in load order, dependencies first, resolved on the host.
mods=(vcan can-raw configfs gpio-sim virtio_pci virtio_net)
: > "$stage/rig/modules.list"
for m in "${mods[@]}"; do
  modprobe -d "$kroot" -S "$abi" --show-depends "$m" | awk '$1 == "insmod" {print $2}'
done | awk '!seen[$0]++' | while IFS= read -r ko; do
  rel=${ko#"$kroot"/}
  mkdir -p "$stage/$(dirname "$rel")"
  cp "$ko" "$stage/$rel"
  echo "/$rel" >> "$stage/rig/modules.list"
done
[ -s "$stage/rig/modules.list" ] || die "no kernel modules resolved (depmod on $kroot failed?)"

# Shared libraries: the closure of DT_NEEDED over every dynamic ELF in the image,
# taken from the host's multiarch arm64 libraries (tools/setup.sh installs them),
# then from the extracted .debs.
libdirs=(/lib/aarch64-linux-gnu /usr/lib/aarch64-linux-gnu "$ul/lib/aarch64-linux-gnu" "$ul/usr/lib/aarch64-linux-gnu")
declare -A have=()
need_libs() {  # need_libs <elf>
  local elf=$1 soname d found
  while IFS= read -r soname; do
    [ -n "${have[$soname]:-}" ] && continue
    found=""
    for d in "${libdirs[@]}"; do
      if [ -e "$d/$soname" ]; then found=$d/$soname; break; fi
    done
    [ -n "$found" ] || die "'$(basename "$elf")' needs $soname, found in none of: ${libdirs[*]} (install its :arm64 package via tools/setup.sh)"
    have[$soname]=1
    cp -L "$found" "$stage/lib/aarch64-linux-gnu/$soname"
    need_libs "$stage/lib/aarch64-linux-gnu/$soname"
  done < <(aarch64-linux-gnu-readelf -d "$elf" 2>/dev/null | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p')
}
while IFS= read -r elf; do
  need_libs "$elf"
done < <(find "$stage/usr/bin" "$stage/rig" -type f -perm -u+x)
loader=""
for d in /lib /usr/lib /lib/aarch64-linux-gnu /usr/lib/aarch64-linux-gnu; do
  if [ -e "$d/ld-linux-aarch64.so.1" ]; then loader=$d/ld-linux-aarch64.so.1; break; fi
done
[ -n "$loader" ] || die "no ld-linux-aarch64.so.1 on the host: install libc6:arm64 (tools/setup.sh)"
cp -L "$loader" "$stage/lib/aarch64-linux-gnu/ld-linux-aarch64.so.1"
ln -sf aarch64-linux-gnu/ld-linux-aarch64.so.1 "$stage/lib/ld-linux-aarch64.so.1"

# The test binaries find fixtures at the compile-time DRIVETWIN_FIXTURES_DIR: mirror
# the checkout's tests/fixtures at the same absolute path (bounded in size).
fixtures=$repo/tests/fixtures
if [ -d "$fixtures" ]; then
  kb=$(du -sk "$fixtures" | cut -f1)
  if [ "$kb" -le 65536 ]; then
    mkdir -p "$stage$fixtures"
    cp -a "$fixtures/." "$stage$fixtures/"
  else
    log "warning: tests/fixtures is ${kb} KiB (> 64 MiB), not mirrored into the guest"
  fi
fi

printf '%s\n' "abi=$abi" "built=$(date -u +%Y-%m-%dT%H:%M:%SZ)" > "$stage/rig/build-info"
(cd "$stage" && find . -print0 | LC_ALL=C sort -z | cpio --null -o -H newc --quiet) | gzip -1 > "$cache/rig.cpio.gz.tmp"
mv "$cache/rig.cpio.gz.tmp" "$cache/rig.cpio.gz"
log "kernel $abi; ${#bins[@]} binaries (${bins[*]##*/}); initramfs $(du -h "$cache/rig.cpio.gz" | cut -f1) at $cache/rig.cpio.gz"
