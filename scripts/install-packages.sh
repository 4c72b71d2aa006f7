#!/bin/sh
# Installs those of the Debian packages named that are not installed yet,
# saying which ("installing: ..."), through sudo unless root; nothing, and no
# apt-get update, when all are there. install-deps.sh, install-deps-aarch64.sh
# and the CI steps install their packages through it.
#   sh scripts/install-packages.sh PACKAGE...
set -e
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
missing=""
for p in "$@"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -n "$missing" ] || exit 0
echo "installing:$missing"
$SUDO apt-get update -qq
# shellcheck disable=SC2086
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing
