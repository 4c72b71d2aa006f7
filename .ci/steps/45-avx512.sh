#!/bin/sh
# CI step: the same bytes from an x86-64-v4 (AVX-512) build, where the CPU can
# run one: builds render with -DPRAST_MARCH=x86-64-v4 (build-v4/) and checks
# the same-bytes manifest with it. Skipped, saying so, on a CPU without
# AVX-512 (the build would not run there).
#   sh .ci/steps/45-avx512.sh            (from the top folder)
set -e
cd "$(dirname "$0")/../.."
for flag in avx512f avx512bw avx512cd avx512dq avx512vl; do
  if ! grep -qw "$flag" /proc/cpuinfo; then
    echo "avx512 step: skipped, this CPU has no $flag (an x86-64-v4 build would not run here)"
    exit 0
  fi
done
start=$(date +%s)
launcher=""
[ -n "$CMAKE_CXX_COMPILER_LAUNCHER" ] && launcher="-DCMAKE_CXX_COMPILER_LAUNCHER=$CMAKE_CXX_COMPILER_LAUNCHER"
cmake -S . -B build-v4 -DCMAKE_BUILD_TYPE=Release -DPRAST_MARCH=x86-64-v4 -DPRAST_TESTS=OFF -DPRAST_PYTHON=OFF \
  $launcher >/dev/null
cmake --build build-v4 -j2 --target render
built=$(date +%s)
python3 scripts/manifest.py check --render build-v4/render
echo "avx512 step: build $((built - start)) s, manifest $(($(date +%s) - built)) s"
