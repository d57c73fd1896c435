"""What the Python call adds to a paper pendulum run (issue #24: less than 5 %).

Interleaves, `repeats` times, (a) the Rust path the CLI takes — read the case file, expand it,
run the formulation(s) — timed inside Rust with no Python object built (flexmb._core.native_seconds),
and (b) the whole Python call flexmb.run(...) timed with time.perf_counter, including the argument
handling, the GIL hand-offs and the NumPy arrays. Prints the medians and the overhead
(median(b) - median(a)) / median(a).

    python python/examples/overhead.py [repeats]
"""

import os
import statistics
import sys
import time

import flexmb
from flexmb import _core

HERE = os.path.dirname(os.path.abspath(__file__))
CASE = os.path.join(HERE, "..", "..", "cases", "double_pendulum_c1_beta45.json")
FORMS = {"ancf": ["ancf"], "gebf": ["gebf"], "both": ["ancf", "gebf"]}


def measure(formulation: str, repeats: int = 9):
    """(median Rust s, median Python s, overhead fraction) over interleaved repeats."""
    native, python = [], []
    flexmb.run(CASE, formulation)  # warm-up: page cache, thread pool
    for _ in range(repeats):
        native.append(_core.native_seconds(CASE, True, "", FORMS[formulation], []))
        t0 = time.perf_counter()
        flexmb.run(CASE, formulation)
        python.append(time.perf_counter() - t0)
    a, b = statistics.median(native), statistics.median(python)
    return a, b, (b - a) / a


def main(repeats: int = 9):
    for f in ("gebf", "ancf", "both"):
        a, b, o = measure(f, repeats)
        print(f"{f:>4}: Rust {1e3 * a:7.1f} ms, Python call {1e3 * b:7.1f} ms (medians of {repeats}): overhead {100 * o:+.2f} %")


if __name__ == "__main__":
    main(*(int(x) for x in sys.argv[1:]))
