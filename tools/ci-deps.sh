#!/usr/bin/env bash
# Test dependencies outside cargo, for the browser test of the report, the VTK parse test, the
# SLURM job-array test and the Python package's tests (harness/tests/suite/browser.rs,
# harness/tests/suite/vtk_parse.rs, harness/tests/suite/slurm.rs, python/tests/):
#   * headless Chromium (Debian's `chromium` package), installed with apt-get when absent;
#   * SLURM and MUNGE (Debian's `slurm-wlm` and `munge`), installed with apt-get when absent (the
#     test starts its own one-node cluster; nothing is started here);
#   * a Python virtual environment in target/ci-venv with VTK's own reader (`vtk` from PyPI) and
#     what the `flexmb` package needs to build and be tested (maturin, numpy, pytest).
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

have_slurm() { for b in munged slurmctld slurmd sbatch sinfo; do command -v "$b" >/dev/null 2>&1 || [ -x "/usr/sbin/$b" ] || return 1; done; }
if ! have_slurm; then
    echo "ci-deps: installing slurm-wlm and munge (apt-get)"
    { as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge \
        || { as_root apt-get update -qq && as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge; }; } \
        >/dev/null || echo "ci-deps: could not install slurm-wlm and munge; the SLURM test will say so"
fi
have_slurm && echo "ci-deps: $(/usr/sbin/slurmctld -V 2>/dev/null || slurmctld -V)"

if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -c 'import vtk' >/dev/null 2>&1; then
    echo "ci-deps: creating $VENV with vtk"
    mkdir -p "$(dirname "$VENV")"
    python3 -m venv "$VENV" && "$VENV/bin/pip" install -q vtk \
        || echo "ci-deps: could not create $VENV with vtk; the VTK parse test will say so"
fi
[ -x "$VENV/bin/python" ] && "$VENV/bin/python" -c 'import vtk; print("ci-deps: python vtk", vtk.vtkVersion.GetVTKVersion())' 2>/dev/null
if [ -x "$VENV/bin/python" ] && ! "$VENV/bin/python" -c 'import maturin, numpy, pytest' >/dev/null 2>&1; then
    echo "ci-deps: adding maturin, numpy and pytest to $VENV"
    "$VENV/bin/pip" install -q maturin numpy pytest || echo "ci-deps: could not install maturin/numpy/pytest; the Python tests will fail"
fi
[ -x "$VENV/bin/python" ] && "$VENV/bin/python" -c 'import numpy, pytest; print("ci-deps: numpy", numpy.__version__, "pytest", pytest.__version__)' 2>/dev/null
exit 0
