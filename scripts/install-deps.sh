#!/bin/sh
# Installs the Debian 12 packages prast builds with (compiler, CMake, the
# header-only libraries, and zlib, libpng, libdeflate, libwebp and libdraco,
# linked statically;
# libmeshoptimizer only for the tests, which encode with it; pybind11, the
# Python headers and numpy for the Python module, pytest for its tests). Runs apt-get through sudo unless already root.
set -e
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
PACKAGES="
  build-essential
  cmake
  libglm-dev
  libtinyobjloader-dev
  libstb-dev
  doctest-dev
  libtinygltf-dev
  nlohmann-json3-dev
  libcli11-dev
  zlib1g-dev
  libpng-dev
  libedit-dev
  pkg-config
  libdraco-dev
  libwebp-dev
  libdeflate-dev
  libmeshoptimizer-dev
  pybind11-dev
  python3-dev
  python3-numpy
  python3-pytest
"
missing=""
for p in $PACKAGES; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "installing:$missing"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing
fi
