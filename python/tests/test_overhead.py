"""The Python call adds less than 5 % to a paper pendulum run (issue #24).

python/examples/overhead.py interleaves the Rust path the CLI takes (read, expand, run; timed
inside Rust) with the whole flexmb.run call and compares medians. A shared machine adds noise
to both sides: a measurement above the limit is repeated, at most three times in all."""

import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "examples"))

import overhead  # noqa: E402


def test_python_call_overhead_is_under_5_percent():
    seen = []
    for _ in range(3):
        rust, python, frac = overhead.measure("both", repeats=7)
        seen.append(f"Rust {1e3 * rust:.1f} ms, Python {1e3 * python:.1f} ms, {100 * frac:+.2f} %")
        if frac < 0.05:
            break
    print("; ".join(seen))
    assert frac < 0.05, seen
