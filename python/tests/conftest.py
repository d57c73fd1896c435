"""Shared fixtures: the repository, the harness binary the CLI comparisons run."""

import os
import pathlib
import shutil

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
PENDULUM = ROOT / "cases" / "double_pendulum_c1_beta45.json"


@pytest.fixture(scope="session")
def harness_bin() -> pathlib.Path:
    """The `harness` binary: $FLEXMB_HARNESS, else target/release/harness (built by `cargo build
    --release -p harness`, or by the README's test command)."""
    p = pathlib.Path(os.environ.get("FLEXMB_HARNESS", ROOT / "target" / "release" / "harness"))
    if not p.is_file():
        msg = f"no harness binary at {p} (cargo build --release -p harness)"
        if os.environ.get("CI"):
            pytest.fail(msg + " (CI is set: the test must run)")
        pytest.skip(msg)
    return p


@pytest.fixture()
def tmp_out(tmp_path):
    yield tmp_path
    shutil.rmtree(tmp_path, ignore_errors=True)
