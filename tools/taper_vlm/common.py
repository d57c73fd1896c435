"""Shared geometry, Glauert lifting line, and flexmb-style normalisation.

Wing: AR 8 on the full span, taper 0.4, straight unswept quarter-chord line, flat plate, 2 deg.
Half-span 4 (b = 8), root chord 2b/(AR (1+lam)) = 1.428571, tip 0.571429 (same as flexmb's test).
"""
import numpy as np

HALF = 4.0
TAPER = 0.4
AR = 8.0
ROOT = 2.0 * HALF / (4.0 * (1.0 + TAPER))
TIP = TAPER * ROOT
ALPHA_DEG = 2.0
ALPHA = np.radians(ALPHA_DEG)
AREA_HALF = HALF * (ROOT + TIP) / 2.0


def chord(y):
    return ROOT + (TIP - ROOT) * np.abs(y) / HALF


def glauert_coeffs(n=60, a0=2 * np.pi, alpha=ALPHA):
    """Odd-term Glauert lifting line, collocation theta_i = i pi/(2n) (same as flexmb)."""
    b = 2 * HALF
    th = np.arange(1, n + 1) * np.pi / (2 * n)
    mu = chord(HALF * np.cos(th)) * a0 / (4 * b)
    nk = 2 * np.arange(n) + 1
    M = np.sin(np.outer(th, nk)) * (np.sin(th)[:, None] + nk[None, :] * mu[:, None])
    r = mu * alpha * np.sin(th)
    return np.linalg.solve(M, r)


def llt_load(ys, A):
    """Lift per unit span (rho = V = 1): l = Gamma = 2 b sum A_n sin n theta."""
    b = 2 * HALF
    th = np.arccos(np.clip(np.asarray(ys) / HALF, -1, 1))
    nk = 2 * np.arange(len(A)) + 1
    return 2 * b * np.sin(np.outer(th, nk)) @ A


def llt_half_lift(A):
    # exact: L_total = rho V^2 pi b^2 A1 / 2 ... use it, half of total
    b = 2 * HALF
    return 0.5 * np.pi * b * b * A[0] / 2.0  # half-wing lift = (pi/4) b^2 A1


def llt_strip_means(edges, A, k=64):
    """Average of l(y) over each strip [edges[j], edges[j+1]] (64 midpoint samples like flexmb)."""
    out = []
    for a, c in zip(edges[:-1], edges[1:]):
        w = c - a
        ys = a + w * (np.arange(k) + 0.5) / k
        out.append(llt_load(ys, A).mean())
    return np.array(out)


def compare(centres, lhat_vlm, edges, n_terms=60, A=None):
    """flexmb's metric: (l_vlm/L_vlm - l_llt/L_llt) / (l_llt(first strip)/L_llt), per strip.
    Returns (llt normalised, diff in fraction of root value)."""
    if A is None:
        A = glauert_coeffs(n_terms)
    llt = llt_strip_means(edges, A) / llt_half_lift(A)
    # flexmb uses the first strip of *its* uniform 48 lattice as "peak"; we use the first strip of
    # each mesh; also report relative to the 48-uniform first strip for uniformity:
    peak48 = llt_strip_means(np.linspace(0, HALF, 49)[:2], A)[0] / llt_half_lift(A)
    return llt, (lhat_vlm - llt) / peak48
