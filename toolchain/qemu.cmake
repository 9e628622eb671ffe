# Runs cross-built aarch64 binaries on the host: ctest and gtest discovery use
# this emulator for every target binary.
find_program(DRIVETWIN_QEMU_AARCH64 qemu-aarch64 REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR ${DRIVETWIN_QEMU_AARCH64})
