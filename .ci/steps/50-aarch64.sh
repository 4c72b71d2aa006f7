#!/bin/sh
# CI step: the same bytes on aarch64. Cross-builds render for aarch64
# (cmake/toolchain-aarch64.cmake; scripts/install-deps-aarch64.sh installs
# the cross compiler and qemu-user and unpacks the arm64 libraries into a
# sysroot, leaving the host's packages alone) and checks the same-bytes
# manifest with it under qemu-user: every render must give the PNG bytes of
# the x86-64 builds (docs/conventions.md#same-bytes-everywhere).
#   sh .ci/steps/50-aarch64.sh            (from the top folder; builds build-aarch64/)
set -e
cd "$(dirname "$0")/../.."
start=$(date +%s)
sh scripts/install-deps-aarch64.sh
launcher=""
[ -n "$CMAKE_CXX_COMPILER_LAUNCHER" ] && launcher="-DCMAKE_CXX_COMPILER_LAUNCHER=$CMAKE_CXX_COMPILER_LAUNCHER"
cmake -S . -B build-aarch64 -DCMAKE_TOOLCHAIN_FILE=cmake/toolchain-aarch64.cmake -DCMAKE_BUILD_TYPE=Release \
  -DPRAST_TESTS=OFF $launcher >/dev/null
cmake --build build-aarch64 -j2 --target render
built=$(date +%s)
qemu-aarch64 build-aarch64/render --version
python3 scripts/manifest.py check --render "qemu-aarch64 build-aarch64/render"
echo "aarch64 step: deps and build $((built - start)) s, manifest under qemu $(($(date +%s) - built)) s"
