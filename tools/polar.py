#!/usr/bin/env python3
"""Write a section polar CSV with NeuralFoil, for the aerofoil crate (docs/section_aero.md).

The file has the columns ``re, alpha_deg, cl, cd, cm`` (one table per Reynolds number, in
increasing Re, incidences increasing within each), preceded by ``#`` comment lines that record
the provenance: tool and version, the command, the date, NeuralFoil's settings and, per Reynolds
number, its smallest ``analysis_confidence`` over the incidences written.

NeuralFoil (Sharpe & Hansman, PyPI ``neuralfoil``) is a physics-informed neural network trained
on XFOIL; ``cm`` is about the quarter chord, nose up positive, ``cd`` the profile drag.

Needs ``pip install neuralfoil`` (it brings AeroSandbox, which names the sections: NACA 4- and
5-digit names such as ``naca0015`` and the UIUC database names it ships), e.g. in a venv:

    python3 -m venv .venv && .venv/bin/pip install neuralfoil==0.3.3
    .venv/bin/python tools/polar.py naca0015 --re 0.5e5 1e5 2e5 -o cases/polars/naca0015_neuralfoil.csv

Exit status 2 for bad input (an unknown section, a bad range), naming it.
"""

import argparse
import datetime
import sys

import numpy as np


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("section", help="section name as AeroSandbox knows it, e.g. naca0015")
    p.add_argument("--re", type=float, nargs="+", required=True, help="Reynolds numbers")
    p.add_argument(
        "--alpha",
        type=float,
        nargs=3,
        default=[-20.0, 20.0, 0.5],
        metavar=("MIN", "MAX", "STEP"),
        help="incidence range and step, degrees (default -20 20 0.5)",
    )
    p.add_argument("--n-crit", type=float, default=9.0, help="e^N transition criterion (default 9)")
    p.add_argument("--model-size", default="xlarge", help="NeuralFoil network size (default xlarge)")
    p.add_argument("-o", "--output", required=True, help="CSV file to write")
    return p.parse_args(argv)


def fail(message):
    print(f"polar.py: {message}", file=sys.stderr)
    sys.exit(2)


def incidences(lo, hi, step):
    if not (step > 0 and hi > lo):
        fail(f"--alpha: need MIN < MAX and STEP > 0, got {lo} {hi} {step}")
    n = int(round((hi - lo) / step))
    if abs(lo + n * step - hi) > 1e-9 * max(1.0, abs(hi)):
        fail(f"--alpha: STEP {step} does not divide [{lo}, {hi}]")
    return lo + step * np.arange(n + 1)


def main(argv):
    args = parse_args(argv)
    import aerosandbox as asb
    import neuralfoil as nf

    res = sorted(args.re)
    if any(r <= 0 for r in res) or len(set(res)) != len(res):
        fail(f"--re: need distinct positive Reynolds numbers, got {args.re}")
    alpha = incidences(*args.alpha)
    try:
        airfoil = asb.Airfoil(args.section)
        if airfoil.coordinates is None or len(airfoil.coordinates) == 0:
            raise ValueError("no coordinates")
    except Exception as e:  # AeroSandbox raises several types for an unknown name
        fail(f"unknown section `{args.section}` ({e})")

    rows, confidence = [], []
    for re in res:
        out = nf.get_aero_from_airfoil(
            airfoil, alpha=alpha, Re=re, n_crit=args.n_crit, model_size=args.model_size
        )
        confidence.append(float(np.min(out["analysis_confidence"])))
        for a, cl, cd, cm in zip(alpha, out["CL"], out["CD"], out["CM"]):
            rows.append((re, a, cl, cd, cm))

    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    command = "python tools/polar.py " + " ".join(argv)
    with open(args.output, "w") as f:
        f.write(f"# section {args.section}: polar from NeuralFoil {nf.__version__}")
        f.write(f" (AeroSandbox {asb.__version__}, NumPy {np.__version__})\n")
        f.write(f"# model_size {args.model_size}, n_crit {args.n_crit}, free transition; {now}\n")
        f.write(f"# command: {command}\n")
        f.write("# cm about the quarter chord, nose up; cd profile drag\n")
        for re, c in zip(res, confidence):
            f.write(f"# Re {re:.4e}: smallest analysis_confidence {c:.3f}\n")
        f.write("re,alpha_deg,cl,cd,cm\n")
        for re, a, cl, cd, cm in rows:
            f.write(f"{re:.6e},{a:.4f},{cl:.6f},{cd:.6f},{cm:.6f}\n")
    print(f"wrote {args.output}: {len(res)} Reynolds numbers x {len(alpha)} incidences")


if __name__ == "__main__":
    main(sys.argv[1:])
