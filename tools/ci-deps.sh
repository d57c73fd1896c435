#!/usr/bin/env bash
# Test dependencies outside cargo, for the browser test of the report and the VTK parse test
# (harness/tests/suite/browser.rs, harness/tests/suite/vtk_parse.rs):
#   * headless Chromium (Debian's `chromium` package), installed with apt-get when absent;
#   * a Python virtual environment with VTK's own reader (`vtk` from PyPI) in target/ci-venv.
# Idempotent: does nothing that is already done. Run as root (CI is) or with sudo available.
# Prints what it could not do and exits 0, so that the tests themselves say what they skip; under
# CI (CI=true) a missing dependency makes those tests fail instead of skip.
set -uo pipefail
cd "$(dirname "$0")/.."
VENV="${FLEXMB_TEST_VENV:-target/ci-venv}"

as_root() {
    if [ "$(id -u)" = 0 ]; then "$@"; elif command -v sudo >/dev/null; then sudo "$@"; else return 1; fi
}

if ! command -v chromium >/dev/null 2>&1; then
    echo "ci-deps: installing chromium (apt-get)"
    as_root apt-get update -qq && as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium \
        || echo "ci-deps: could not install chromium; the browser test will say so"
fi
command -v chromium >/dev/null 2>&1 && echo "ci-deps: $(chromium --version 2>/dev/null | tail -n 1)"

if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -c 'import vtk' >/dev/null 2>&1; then
    echo "ci-deps: creating $VENV with vtk"
    mkdir -p "$(dirname "$VENV")"
    python3 -m venv "$VENV" && "$VENV/bin/pip" install -q vtk \
        || echo "ci-deps: could not create $VENV with vtk; the VTK parse test will say so"
fi
[ -x "$VENV/bin/python" ] && "$VENV/bin/python" -c 'import vtk; print("ci-deps: python vtk", vtk.vtkVersion.GetVTKVersion())' 2>/dev/null
exit 0
