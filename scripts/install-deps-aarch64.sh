#!/bin/sh
# Installs what the aarch64 cross build (cmake/toolchain-aarch64.cmake) needs
# on a Debian 12 amd64 host: the cross compiler and qemu-user from the host's
# own packages, and the arm64 static libraries prast links (zlib, libpng,
# libwebp, libdeflate, libdraco; libedit for step) unpacked into a sysroot folder, by default
# /opt/prast-aarch64-sysroot (PRAST_AARCH64_SYSROOT overrides it; pass the
# same to the toolchain). Idempotent. Runs apt-get through sudo unless root.
#
# Why a sysroot and not `apt-get install libpng-dev:arm64`: these -dev
# packages are Multi-Arch: same, so dpkg co-installs them only at exactly the
# amd64 version. When the archive no longer carries the host's version (a
# security update the host has not taken), apt would upgrade or remove the
# host's packages to match. Unpacking the arm64 .debs leaves every host
# package as it is. What matters in the sysroot are the arm64 libraries: the
# headers of Multi-Arch: same packages are the same files on both
# architectures, and the header-only libraries (glm, stb, tinygltf, ...) are
# the host's.
set -e
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
SYSROOT="${PRAST_AARCH64_SYSROOT:-/opt/prast-aarch64-sysroot}"

# Host (amd64) tools; the arm64 C and C++ runtimes (libc6-dev-arm64-cross,
# libstdc++-12-dev-arm64-cross, with libc.a for a -static link) come with the
# cross compiler.
HOST_PACKAGES="g++-aarch64-linux-gnu qemu-user"
sh "$(dirname "$0")/install-packages.sh" $HOST_PACKAGES

# arm64 package lists, for `apt-get download`; adding the architecture
# installs nothing.
if ! dpkg --print-foreign-architectures | grep -qx arm64; then
  $SUDO dpkg --add-architecture arm64
fi
if ! apt-cache show libpng-dev:arm64 >/dev/null 2>&1; then
  $SUDO apt-get update -qq
fi

# The arm64 version of each library: the host's own one when the archive
# still has it (same deflate, so the same PNG bytes), else the newest.
# libdraco7 (the shared library, unused) only because draco's CMake package
# checks that every file it names exists. libedit and what it links (tinfo,
# libbsd, libmd) for step's prompt: configuring needs them even when only
# render is built.
ARM64_PACKAGES="zlib1g-dev libpng-dev libwebp-dev libdeflate-dev libturbojpeg0-dev libdraco-dev libdraco7
  libedit-dev libncurses-dev libbsd-dev libmd-dev"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# apt downloads as its _apt user when run as root.
[ "$(id -u)" -ne 0 ] || ! id _apt >/dev/null 2>&1 || chown _apt "$tmp"
$SUDO mkdir -p "$SYSROOT/.debs"
for p in $ARM64_PACKAGES; do
  host_ver=$(dpkg-query -W -f='${Version}' "$p" 2>/dev/null || true)
  ver=""
  if [ -n "$host_ver" ] && apt-cache madison "$p:arm64" | awk -F'|' '{gsub(/ /,"",$2); print $2}' | grep -qxF "$host_ver"; then
    ver="$host_ver"
  else
    ver=$(apt-cache policy "$p:arm64" | awk '/Candidate:/ {print $2}')
  fi
  if [ -z "$ver" ] || [ "$ver" = "(none)" ]; then
    echo "no arm64 version of $p in the package lists" >&2
    exit 1
  fi
  stamp="$SYSROOT/.debs/$p:arm64=$(echo "$ver" | tr ':' '_')"
  [ -e "$stamp" ] && continue
  echo "unpacking $p:arm64 $ver into $SYSROOT"
  (cd "$tmp" && rm -f ./*.deb && apt-get download -qq "$p:arm64=$ver" && $SUDO dpkg-deb -x ./*.deb "$SYSROOT")
  # Another version unpacked before: its stamp goes, its files were overwritten.
  $SUDO rm -f "$SYSROOT/.debs/$p:arm64="*
  $SUDO touch "$stamp"
done

# draco's CMake package names its library by absolute path
# (/usr/lib/aarch64-linux-gnu/libdraco.a); inside the sysroot it must name
# the sysroot's file. Its include directory stays /usr/include (the same
# headers as the host's).
draco_cmake="$SYSROOT/usr/lib/aarch64-linux-gnu/cmake/draco"
if grep -q '"/usr/lib/aarch64-linux-gnu/' "$draco_cmake"/*.cmake; then
  $SUDO sed -i "s#\"/usr/lib/aarch64-linux-gnu/#\"$SYSROOT/usr/lib/aarch64-linux-gnu/#g" "$draco_cmake"/*.cmake
fi
for f in libz.a libpng16.a libwebp.a libdraco.a libedit.a libtinfo.a libbsd.a libmd.a; do
  [ -e "$SYSROOT/usr/lib/aarch64-linux-gnu/$f" ] || { echo "missing $SYSROOT/usr/lib/aarch64-linux-gnu/$f" >&2; exit 1; }
done
echo "arm64 sysroot ready: $SYSROOT"
