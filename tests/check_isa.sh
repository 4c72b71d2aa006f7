#!/bin/sh
# The `isa` test: the objects compiled for AVX-512
# (shading/sample_lanes_avx512.cpp, raster/write_avx512.cpp) and for AVX-512
# with VBMI (shading/sample_lanes_vbmi.cpp) define only their entry points and
# templates tagged for them (or, for the first, on 16 lanes), which no other
# object instantiates, so the linker can never pick such a copy of an inline
# function that code for a CPU without those instructions calls.
#   sh tests/check_isa.sh OBJECT...   (the prast_raster and prast_shading objects; others are skipped)
set -e
avx512="" vbmi="" write=""
for o in "$@"; do
  case "$o" in
    *sample_lanes_avx512.cpp.o) avx512="$o" ;;
    *sample_lanes_vbmi.cpp.o) vbmi="$o" ;;
    *write_avx512.cpp.o) write="$o" ;;
  esac
done
[ -n "$avx512" ] || { echo "isa: no sample_lanes_avx512 object among the arguments"; exit 1; }
[ -n "$vbmi" ] || { echo "isa: no sample_lanes_vbmi object among the arguments"; exit 1; }
[ -n "$write" ] || { echo "isa: no write_avx512 object among the arguments"; exit 1; }
list="${TMPDIR:-/tmp}/isa-symbols.$$"
trap 'rm -f "$list"' EXIT
# Code other objects can bind to: global (T), weak (W) and indirect (i)
# functions. Local symbols (t) and data are no hazard.
# check OBJECT ENTRY PATTERN...: ENTRY defined, every symbol matches a PATTERN.
check() {
  obj=$1 entry=$2
  shift 2
  nm -C --defined-only "$obj" | awk '$2 ~ /^[TWi]$/' > "$list"
  grep -q "$entry" "$list" || { echo "isa: $obj lacks its entry point $entry"; exit 1; }
  bad=$(grep -v "$@" "$list" || true)
  if [ -n "$bad" ]; then
    echo "isa: $obj defines code other files may share (it would run its instructions on any CPU):"
    echo "$bad"
    exit 1
  fi
  echo "isa: $(basename "$obj"): $(wc -l < "$list") symbols, all its own"
}
check "$avx512" fetch_unorm8_lanes16_avx512 -e 'fetch_unorm8_lanes16_avx512' -e 'prepare_trilinear_lanes16_avx512' \
  -e 'sample_material_lanes16_avx512' -e 'shade_block_lanes16_avx512' -e 'Simd<16>' -e 'IsaAvx512'
check "$vbmi" fetch_unorm8_lanes16_vbmi -e 'fetch_unorm8_lanes16_vbmi' -e 'IsaAvx512Vbmi'
check "$write" write_planes_avx512 -e 'write_planes_avx512'
