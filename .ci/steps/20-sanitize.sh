#!/bin/sh
# CI step: the test suite (all but three tests, below) built with ASan and UBSan
# (PRAST_SANITIZE=ON), every report fatal. The libraries at -O1: -O0 makes
# the sanitized suite several times slower for nothing (the suite's own
# sources are at -O0, which compiles them three times faster: CMakeLists.txt);
# -g1 (line tables: reports still name file
# and line) compiles in half the time of -g. Reports inside
# Debian's stb_image 2.27 that are known and harmless are suppressed by
# tests/ubsan.supp (each entry says why); the ones that are not harmless are
# guarded before stb sees the data (scene/hdr_guard.h).
#   sh .ci/steps/20-sanitize.sh            (from the top folder; builds build-asan/)
set -e
cd "$(dirname "$0")/../.."
start=$(date +%s)
launcher=""
[ -n "$CMAKE_CXX_COMPILER_LAUNCHER" ] && launcher="-DCMAKE_CXX_COMPILER_LAUNCHER=$CMAKE_CXX_COMPILER_LAUNCHER"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g1 -O1" -DPRAST_SANITIZE=ON -DPRAST_PYTHON=OFF $launcher >/dev/null
# Only what the suite runs: the test binary and the executables it drives
# (the examples are built and tested by the Release run already).
cmake --build build-asan -j2 --target prast_tests render step prast-diff bench
built=$(date +%s)
export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1:check_initialization_order=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:suppressions=$PWD/tests/ubsan.supp"
# Every test but `examples` (an install and a consumer build: no code of ours
# runs there that the suite does not run), `docs` (the pages against what the
# programs print: the same sessions and renders the other suites run),
# `browser` (the page's behaviour in Chromium; every endpoint it calls, and
# every attack on them, is the `serve` test, which runs here) and
# `manifest_avx2` (the renders of `manifest` again with the eight-lane code,
# which `sample_lanes_avx2` already runs here against the scalar code).
ctest --test-dir build-asan -j2 --output-on-failure -E '^(examples|docs|browser|manifest_avx2)$'

echo "sanitize step: build $((built - start)) s, tests $(($(date +%s) - built)) s"
