#!/usr/bin/env python3
"""Cost model of a dual-tree (fast-multipole-like) far-wake sum against the direct sum
(docs/uvlm.md §9, "Clusters of targets as well").

It answers one question before any code is written: with the evaluation points (collocation
points and segment midpoints) grouped into clusters as well as the wake's segments, how much of
the direct sum's work would an aggregation leave at the wake lengths the cases use?

Geometry: a flat lattice (span, chord, N spanwise x M chordwise panels) with its targets, and a
flat wake of straight segments (spanwise and streamwise edges of the ring rows), row spacing
V dt. Both sets are split by median bisection into binary trees down to a leaf size. A pair of
clusters is accepted when (rho_target + rho_source) / d < theta, and otherwise opened (the larger
cluster first); two leaves that are not accepted are summed directly.

Costs, in units of one point-segment pair of the direct kernel:
  direct pair 1; multipole-to-local translation 550 (Cartesian order 5 to order 5: 56 x 56 x 3
  products plus the derivative tensor to order 11, about 19 000 flops, against about 34 per
  pair); local evaluation 5 per target; moments 15 per segment (the tree rebuilt every step,
  as in a gust).

theta: the treecode of uvlm/src/treecode.rs accepts a cluster about six radii away at order 5 and
1e-6 |V|, theta = 1/6; 1/4 and 1/3 are shown for comparison (they would need a higher order, whose
translations cost more than the 550 assumed here).

No dependencies but numpy. Usage: python3 tools/fmm_cost_model.py
"""
import numpy as np


def lattice(span, chord, n_span, n_chord, rows, dx):
    ys = np.linspace(0.0, span, n_span + 1)
    xs = np.linspace(0.0, chord, n_chord + 1)
    dxc = xs[1] - xs[0]
    ym = 0.5 * (ys[1:] + ys[:-1])
    targets = []
    for i in range(n_chord):
        targets += [(xs[i] + 0.75 * dxc, y, 0.0) for y in ym]  # collocation points
        targets += [(xs[i] + 0.25 * dxc, y, 0.0) for y in ym]  # spanwise bound segments
        targets += [(xs[i] + 0.5 * dxc, y, 0.0) for y in ys]  # chordwise bound segments
    mids, half = [], []
    for k in range(rows):
        x = chord + k * dx
        mids += [(x, y, 0.0) for y in ym]
        half += [0.5 * (ys[1] - ys[0])] * n_span
        mids += [(x + 0.5 * dx, y, 0.0) for y in ys]
        half += [0.5 * dx] * (n_span + 1)
    return np.array(targets), np.array(mids), np.array(half)


def tree(points, leaf, half=None):
    nodes = []

    def build(idx):
        p = points[idx]
        lo, hi = p.min(0), p.max(0)
        c = 0.5 * (lo + hi)
        r = np.sqrt(((p - c) ** 2).sum(1)).max() + (half[idx].max() if half is not None else 0.0)
        me = len(nodes)
        nodes.append((idx, c, r, []))
        if len(idx) > leaf:
            order = idx[np.argsort(p[:, np.argmax(hi - lo)])]
            h = len(order) // 2
            nodes[me][3].extend([build(order[:h]), build(order[h:])])
        return me

    build(np.arange(len(points)))
    return nodes


def cost(targets, mids, half, theta, leaf_t, leaf_s, m2l=550.0, l2p=5.0, p2m=15.0):
    tn, sn = tree(targets, leaf_t), tree(mids, leaf_s, half)
    direct, n_m2l, with_local = 0, 0, set()
    stack = [(0, 0)]
    while stack:
        a, b = stack.pop()
        (ia, ca, ra, ka), (ib, cb, rb, kb) = tn[a], sn[b]
        d = np.linalg.norm(ca - cb)
        if d > 0.0 and (ra + rb) / d < theta:
            n_m2l += 1
            with_local.add(a)
        elif not ka and not kb:
            direct += len(ia) * len(ib)
        elif kb and (ra <= rb or not ka):
            stack += [(a, c) for c in kb]
        else:
            stack += [(c, b) for c in ka]
    n_l2p = sum(len(tn[a][0]) for a in with_local)
    full = len(targets) * len(mids)
    total = direct + n_m2l * m2l + n_l2p * l2p + len(mids) * p2m
    return direct / full, n_m2l, total / full


CASES = {
    # cases/healy_ffwt_gust.json: 0.5 m semi-span, chord 0.078 m, 44 x 4 panels, 60 rows at 20 m/s x 1 ms
    "Healy's wing (60 rows)": (0.5, 0.078, 44, 4, 60, 0.02),
    # cases/wing_aoa5.json: 16 m, chord 1 m, 32 x 4 panels, 40 rows at 25 m/s x 10 ms
    "paper's wing (40 rows)": (16.0, 1.0, 32, 4, 40, 0.25),
}

if __name__ == "__main__":
    for name, geometry in CASES.items():
        t, m, h = lattice(*geometry)
        print(f"{name}: {len(t)} targets, {len(m)} segments")
        for theta in (1 / 6, 1 / 4, 1 / 3):
            for leaf_t, leaf_s in ((8, 32), (16, 64), (32, 128), (64, 256)):
                frac, n_m2l, rel = cost(t, m, h, theta, leaf_t, leaf_s)
                print(
                    f"  theta {theta:.3f}  leaves {leaf_t:2d}/{leaf_s:3d}: pairs left {frac:.3f}, "
                    f"{n_m2l:5d} translations, cost {rel:.3f} of the direct sum"
                )
