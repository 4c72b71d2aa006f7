#!/bin/sh
# The Python module as a user gets it (the CTest test `python`): installs the
# build into a scratch prefix, then runs the module's tests (python/tests)
# and the pytest example (examples/python-pixel-test) against that install,
# with Debian's python3 and python3-pytest. Exit 77 (CTest: skipped) when
# pytest is missing, saying so.
#   sh scripts/check-python.sh [BUILD_DIR]      (default: build)
set -e
build=$(cd "${1:-build}" && pwd)
top=$(cd "$(dirname "$0")/.." && pwd)
python=${PRAST_PYTHON_EXE:-/usr/bin/python3}
if ! "$python" -c "import pytest" 2>/dev/null; then
  echo "skipped: $python has no pytest (apt-get install python3-pytest)"
  exit 77
fi
prefix=$build/python-check
rm -rf "$prefix"
cmake --install "$build" --prefix "$prefix" >"$build/python-check.log"
site=$(find "$prefix" -name __init__.py -path '*/prast/*' | head -n 1)
[ -n "$site" ] || { echo "the install has no prast package"; exit 1; }
site=$(dirname "$(dirname "$site")")
echo "prast installed in $site"
export PYTHONPATH="$site" PRAST_SOURCE_DIR="$top" PRAST_RENDER="$build/render" PRAST_DIFF="$build/prast-diff"
# Not the source tree's python/prast: the installed one.
cd "$build"
"$python" -c "import prast, sys; assert prast.__file__.startswith('$site'), prast.__file__; print('prast', prast.__version__, 'from', prast.__file__)"
"$python" -m pytest -q -p no:cacheprovider "$top/python/tests" "$top/examples/python-pixel-test"
