#!/bin/sh
# Fuzzes every input parser of prast with libFuzzer: the OBJ+MTL loader, the
# glTF/.glb loader, the PNG, JPEG and Radiance HDR decoders, render's command
# line and the stepper's command interpreter, each for SECONDS (default 60),
# one after the other.
#
#   scripts/fuzz.sh SECONDS [HARNESS...]     HARNESS: obj gltf meshopt webp png jpeg hdr cli step
#
# Builds build-fuzz/ with clang (apt-get install clang libclang-rt-14-dev),
# writes the project's seed corpora (fuzz/make_seeds.cpp) to build-fuzz/seeds,
# adds tests/fuzz-regressions/HARNESS as seeds, keeps the growing corpus in
# build-fuzz/corpus/HARNESS and any crash, hang (-timeout, 10 s) or allocation
# over 2 GB (-rss_limit_mb) in build-fuzz/findings/HARNESS. The last line of
# each harness's log (build-fuzz/fuzz-HARNESS.log) gives executions and
# coverage (cov: edges, ft: features). Exit status 1 when a harness found
# something. FUZZ_TIMEOUT (seconds, default 10) is the per-input hang limit:
# raise it on a machine shared with other jobs, where a slow input is not a hang.
set -e
cd "$(dirname "$0")/.."
seconds=${1:-60}
[ $# -gt 0 ] && shift
harnesses=${*:-obj gltf meshopt webp png jpeg hdr cli step}
out="$PWD/build-fuzz"  # absolute: fuzz_step works in a folder of its own
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}"
if [ ! -f $out/CMakeCache.txt ]; then
  launcher=""
  command -v ccache >/dev/null && launcher=-DCMAKE_CXX_COMPILER_LAUNCHER=ccache
  CC=clang CXX=clang++ cmake -S . -B $out -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPRAST_FUZZ=ON -DPRAST_TESTS=OFF $launcher >/dev/null
fi
targets="fuzz_make_seeds"
for h in $harnesses; do targets="$targets fuzz_$h"; done
# shellcheck disable=SC2086
cmake --build $out -j2 --target $targets
$out/fuzz/fuzz_make_seeds $out/seeds

# UBSan stops at the first report, except the documented ones inside Debian's
# stb_image (tests/ubsan.supp).
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:suppressions=$PWD/tests/ubsan.supp"
status=0
for h in $harnesses; do
  mkdir -p $out/corpus/$h $out/findings/$h
  extra=""
  [ -d tests/fuzz-regressions/$h ] && extra="$PWD/tests/fuzz-regressions/$h"
  echo "==== fuzz_$h for $seconds s"
  # shellcheck disable=SC2086
  if ! $out/fuzz/fuzz_$h -max_total_time="$seconds" -timeout="${FUZZ_TIMEOUT:-10}" -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix=$out/findings/$h/ $out/corpus/$h $out/seeds/$h $extra >$out/fuzz-$h.log 2>&1; then
    status=1
    echo "fuzz_$h: FINDING, see $out/fuzz-$h.log and $out/findings/$h/"
  fi
  grep -E "^#[0-9]+.*(DONE|pulse|NEW|REDUCE)" $out/fuzz-$h.log | tail -1
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb" $out/fuzz-$h.log || true
done
exit $status
