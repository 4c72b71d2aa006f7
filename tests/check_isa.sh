#!/bin/sh
# The `isa` test: the object compiled for AVX-512
# (shading/sample_lanes_avx512.cpp) defines only its entry points and
# templates on 16 lanes or tagged IsaAvx512, which no other object
# instantiates, so the linker can never pick an AVX-512 copy of an inline
# function that code for any CPU calls.
#   sh tests/check_isa.sh OBJECT...   (the prast_shading objects; others are skipped)
set -e
obj=""
for o in "$@"; do
  case "$o" in *sample_lanes_avx512.cpp.o) obj="$o" ;; esac
done
[ -n "$obj" ] || { echo "isa: no sample_lanes_avx512 object among the arguments"; exit 1; }
# Code other objects can bind to: global (T), weak (W) and indirect (i)
# functions. Local symbols (t) and data are no hazard.
nm -C --defined-only "$obj" | awk '$2 ~ /^[TWi]$/' > "${TMPDIR:-/tmp}/isa-symbols.$$"
trap 'rm -f "${TMPDIR:-/tmp}/isa-symbols.$$"' EXIT
grep -q 'fetch_unorm8_lanes16_avx512' "${TMPDIR:-/tmp}/isa-symbols.$$" || { echo "isa: $obj lacks its entry point"; exit 1; }
bad=$(grep -v -e 'fetch_unorm8_lanes16_avx512' -e 'prepare_trilinear_lanes16_avx512' -e 'sample_material_lanes16_avx512' \
  -e 'shade_block_lanes16_avx512' \
  -e 'fetch_unorm8_lanes<16, 16, [1-4]>' -e 'Simd<16>' -e 'IsaAvx512' \
  "${TMPDIR:-/tmp}/isa-symbols.$$" || true)
if [ -n "$bad" ]; then
  echo "isa: $obj defines code other files may share (it would run AVX-512 on any CPU):"
  echo "$bad"
  exit 1
fi
echo "isa: $(wc -l < "${TMPDIR:-/tmp}/isa-symbols.$$") symbols, all AVX-512-only"
