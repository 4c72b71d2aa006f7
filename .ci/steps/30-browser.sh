#!/bin/sh
# The stepper's web page in a real browser: headless Chromium driven by
# Selenium (tests/browser/test_step_page.py, CTest `browser`). Installs the
# Debian packages it needs, then runs it; here it may not be skipped.
set -e
cd "$(dirname "$0")/../.."
sh scripts/install-packages.sh chromium chromium-driver python3-selenium
PRAST_BROWSER_REQUIRED=1 ctest --test-dir build -R '^browser$' --output-on-failure
