"""The paper's flared double pendulum (c = 1, beta = 45 deg) with both formulations, from Python.

Runs cases/double_pendulum_c1_beta45.json with ANCF and GEBF (the two in parallel, as
`harness run` runs them) and prints the largest ANCF-GEBF tip distance, the same number (computed
by the same Rust function on the same values) that `harness run` prints as "max tip difference
ANCF-GEBF" and writes to summary.json as tip_difference.all.max.

    python python/examples/pendulum.py [path/to/double_pendulum_c1_beta45.json]
"""

import os
import sys
import time

import flexmb

HERE = os.path.dirname(os.path.abspath(__file__))
CASE = os.path.join(HERE, "..", "..", "cases", "double_pendulum_c1_beta45.json")


def main(case: str = CASE) -> float:
    t0 = time.perf_counter()
    r = flexmb.run(case, formulation="both")
    wall = time.perf_counter() - t0
    for f in ("ancf", "gebf"):
        cols = r[f]
        print(
            f"{f}: {len(cols['t'])} rows to t = {cols['t'][-1]:.3f} s, tip at the end "
            f"({cols['tip_x'][-1]:+.6f}, {cols['tip_y'][-1]:+.6f}, {cols['tip_z'][-1]:+.6f}) m, "
            f"{cols['newton_iterations'][1:].mean():.2f} Newton/step"
        )
    _, d = flexmb.tip_difference(r["ancf"], r["gebf"])
    print(f"max tip difference ANCF-GEBF {1e3 * d.max():.3f} mm ({float(d.max())!r} m); both runs in {wall:.3f} s")
    return float(d.max())


if __name__ == "__main__":
    main(*sys.argv[1:])
