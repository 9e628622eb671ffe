# Cross-compiling drivetwin for the nacelle box: aarch64 Linux, Debian 12.
#
# Compiler: Debian's g++-aarch64-linux-gnu. Libraries: Debian's :arm64 packages
# installed through multiarch (tools/setup.sh), so they live in
# /usr/lib/aarch64-linux-gnu beside the host's and share /usr/include.
# Test binaries run under plain qemu-aarch64, which finds the multiarch
# /lib/ld-linux-aarch64.so.1 and libc6:arm64. Do NOT add "-L /usr/aarch64-linux-gnu":
# mixing that cross sysroot's loader with the multiarch libc hangs threaded programs.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)

# Search libraries and packages only in the target's multiarch directories;
# programs (code generators, etc.) come from the host.
set(CMAKE_FIND_ROOT_PATH /usr/lib/aarch64-linux-gnu)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)
set(CMAKE_IGNORE_PATH /usr/lib/x86_64-linux-gnu /usr/lib/x86_64-linux-gnu/cmake)

# pkg-config must report the arm64 libraries, not the host's.
set(ENV{PKG_CONFIG_LIBDIR} "/usr/lib/aarch64-linux-gnu/pkgconfig:/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_PATH} "")

include(${CMAKE_CURRENT_LIST_DIR}/qemu.cmake)
