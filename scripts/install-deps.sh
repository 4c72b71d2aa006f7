#!/bin/sh
# Installs the Debian 12 packages prast builds with (compiler, CMake, the
# header-only libraries, and zlib, libpng, libdeflate, libturbojpeg, libwebp
# and libdraco, linked statically; libmeshoptimizer only for the tests, which
# encode with it; pybind11, the Python headers and numpy for the Python
# module, pytest for its tests), those not installed yet
# (scripts/install-packages.sh: apt-get through sudo unless already root).
set -e
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
  libturbojpeg0-dev
  libmeshoptimizer-dev
  pybind11-dev
  python3-dev
  python3-numpy
  python3-pytest
"
sh "$(dirname "$0")/install-packages.sh" $PACKAGES
