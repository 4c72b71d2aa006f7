#!/bin/sh
# CI step: the same bytes from Clang. Builds render with Debian's Clang 14
# (build-clang/, Debug: no optimisation, the other end from the GCC Release
# build the test command checks) and checks the same-bytes manifest with it
# (scripts/manifest.py, docs/conventions.md#same-bytes-everywhere): every
# render must give the PNG bytes the GCC build gives.
# Its build must be free of warnings as GCC's is.
#   sh .ci/steps/40-clang.sh            (from the top folder)
set -e
cd "$(dirname "$0")/../.."
start=$(date +%s)
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
if ! command -v clang++ >/dev/null; then
  echo "installing: clang"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq clang
fi
launcher=""
[ -n "$CMAKE_CXX_COMPILER_LAUNCHER" ] && launcher="-DCMAKE_CXX_COMPILER_LAUNCHER=$CMAKE_CXX_COMPILER_LAUNCHER"
CC=clang CXX=clang++ cmake -S . -B build-clang -DCMAKE_BUILD_TYPE=Debug -DPRAST_TESTS=OFF -DPRAST_PYTHON=OFF \
  $launcher >/dev/null
# Zero warnings from Clang too (-Wall -Wextra, as GCC's).
status=0
cmake --build build-clang -j2 --target render >build-clang/build.log 2>&1 || status=$?
cat build-clang/build.log
[ "$status" -eq 0 ] || exit "$status"
if grep -q "warning:" build-clang/build.log; then
  echo "clang step: the Clang build has warnings (above)"; exit 1
fi
built=$(date +%s)
build-clang/render --version
# The AVX-512 copies of the block loops and the fetch's VBMI copy share no
# code with the rest under Clang either (tests/check_isa.sh; the objects
# exist in x86-64-v3 builds).
isa_obj=$(find build-clang -name 'sample_lanes_avx512.cpp.o' | head -n 1)
vbmi_obj=$(find build-clang -name 'sample_lanes_vbmi.cpp.o' | head -n 1)
write_obj=$(find build-clang -name 'write_avx512.cpp.o' | head -n 1)
[ -z "$isa_obj" ] || sh tests/check_isa.sh "$isa_obj" "$vbmi_obj" "$write_obj"
python3 scripts/manifest.py check --render build-clang/render
echo "clang step: build $((built - start)) s, manifest $(($(date +%s) - built)) s"
