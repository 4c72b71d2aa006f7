#!/bin/sh
# The stepper's web page in a real browser: headless Chromium driven by
# Selenium (tests/browser/test_step_page.py, CTest `browser`). Installs the
# Debian packages it needs, then runs it; here it may not be skipped.
set -e
cd "$(dirname "$0")/../.."
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
missing=""
for p in chromium chromium-driver python3-selenium; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "installing:$missing"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing
fi
PRAST_BROWSER_REQUIRED=1 ctest --test-dir build -R '^browser$' --output-on-failure
