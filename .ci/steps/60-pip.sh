#!/bin/sh
# CI step: the Python module as pip installs it, offline, with Debian's
# setuptools: `pip install --no-build-isolation --no-index .` into a fresh
# venv (which sees Debian's numpy and pytest), then the pytest example with
# that venv's Python, and its render against the same-bytes manifest.
#   sh .ci/steps/60-pip.sh            (from the top folder)
set -e
cd "$(dirname "$0")/../.."
start=$(date +%s)
sh scripts/install-packages.sh python3-venv python3-pip python3-setuptools python3-wheel
venv=$(mktemp -d)
trap 'rm -rf "$venv"' EXIT
/usr/bin/python3 -m venv --system-site-packages "$venv"
CMAKE_BUILD_PARALLEL_LEVEL=2 "$venv/bin/pip" install --no-build-isolation --no-index -q .
cd "$venv"
"$venv/bin/python" -c "import prast; assert prast.__file__.startswith('$venv'), prast.__file__; print('prast', prast.__version__, 'from', prast.__file__)"
"$venv/bin/python" -m pytest -q -p no:cacheprovider "$OLDPWD/examples/python-pixel-test"
"$venv/bin/python" - "$OLDPWD" <<'PY'
import hashlib, os, sys
top = sys.argv[1]
sys.path.insert(0, os.path.join(top, "scripts"))
import manifest, prast
want = manifest.read_hashes()
for name in ("builtin-msaa4", "view-normal", "sphere-env"):
    args = dict(manifest.read_scenes())[name]
    resolved, _ = manifest.resolve(args, ".")
    prast.write_png("m.png", prast.render_args(resolved))
    got = hashlib.sha256(open("m.png", "rb").read()).hexdigest()
    assert got == want[name][0], "%s: %s, the manifest has %s" % (name, got, want[name][0])
    print("pip-installed prast.render_args():", name, "matches the manifest")
PY
echo "pip step: $(($(date +%s) - start)) s"
