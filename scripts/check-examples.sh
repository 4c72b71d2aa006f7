#!/bin/sh
# prast as a library (the CTest test `examples`, so CI runs it in the README's
# test command). Installs the build into a temporary prefix,
# then configures, builds and runs both examples/ projects against it with
# find_package(prast) alone (CMAKE_PREFIX_PATH), and checks that the
# consumers compile with our determinism flags and without our warning flags.
#   sh scripts/check-examples.sh [BUILD_DIR]      (default: build; from the top folder)
# CTest sets PRAST_EXAMPLES_DIR: then the
# prefix and the example builds go to fixed folders under it (wiped first,
# kept afterwards), so that a compiler launcher such as ccache
# (CMAKE_CXX_COMPILER_LAUNCHER in the environment) finds its cache again.
set -e
build=$(cd "${1:-build}" && pwd)
top=$(cd "$(dirname "$0")/.." && pwd)
if [ -n "$PRAST_EXAMPLES_DIR" ]; then
  rm -rf "$PRAST_EXAMPLES_DIR"
  mkdir -p "$PRAST_EXAMPLES_DIR/prefix" "$PRAST_EXAMPLES_DIR/work"
  prefix=$PRAST_EXAMPLES_DIR/prefix
  work=$PRAST_EXAMPLES_DIR/work
else
  prefix=$(mktemp -d)
  work=$(mktemp -d)
  trap 'rm -rf "$prefix" "$work"' EXIT
fi

cmake --install "$build" --prefix "$prefix" >"$work/install.log"
echo "installed into $prefix: $(cd "$prefix" && find . -type f | wc -l) files"
"$prefix/bin/prast-diff" --version

for ex in triangle pixel-test; do
  cmake -S "$top/examples/$ex" -B "$work/$ex" -DCMAKE_PREFIX_PATH="$prefix" \
        -DCMAKE_EXPORT_COMPILE_COMMANDS=ON >"$work/$ex-configure.log" || { cat "$work/$ex-configure.log"; exit 1; }
  cmake --build "$work/$ex" -j2
  # What a consumer compiles with: our -ffp-contract=off and -march, not our
  # warnings or vectorisation-only flags (the examples add their own -Wall).
  grep -q -- '-ffp-contract=off' "$work/$ex/compile_commands.json" ||
    { echo "$ex: -ffp-contract=off did not reach the consumer"; exit 1; }
  if grep -q -- '-fno-math-errno' "$work/$ex/compile_commands.json"; then
    echo "$ex: prast's private flags leaked into the consumer"; exit 1
  fi
done

"$work/triangle/triangle" "$work/triangle.png"
"$work/pixel-test/pixel_test" "$prefix/share/prast/assets/textured-sphere/sphere.gltf" \
    "$top/examples/pixel-test/golden/textured_sphere.png" "$work"
ctest --test-dir "$work/pixel-test" --output-on-failure >"$work/ctest.log" || { cat "$work/ctest.log"; exit 1; }
echo "examples: ok"
