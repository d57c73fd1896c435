"""AeroSandbox VortexLatticeMethod (horseshoe VLM) of the AR-8, taper-0.4 wing, symmetric full span.
usage: python asb_run.py NSPAN_HALF NCHORD SPANSPACING(uniform|cosine) CHORDSPACING(uniform|cosine)"""
import sys, os
import numpy as onp
import aerosandbox as asb
import aerosandbox.numpy as anp
from common import *

ns, nc, ss, cs = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3], sys.argv[4]
fn = {"uniform": anp.linspace, "cosine": anp.cosspace}
af = asb.Airfoil("naca0012")
wing = asb.Wing(name="w", symmetric=True, xsecs=[
    asb.WingXSec(xyz_le=[0, 0, 0], chord=ROOT, airfoil=af),
    asb.WingXSec(xyz_le=[0.25 * (ROOT - TIP), HALF, 0], chord=TIP, airfoil=af)])
plane = asb.Airplane(wings=[wing], s_ref=2 * AREA_HALF, c_ref=AREA_HALF / HALF, b_ref=2 * HALF)
op = asb.OperatingPoint(velocity=1.0, alpha=ALPHA_DEG, atmosphere=asb.Atmosphere(altitude=0))
vlm = asb.VortexLatticeMethod(plane, op, spanwise_resolution=ns, spanwise_spacing_function=fn[ss],
                              chordwise_resolution=nc, chordwise_spacing_function=fn[cs])
res = vlm.run()
F = onp.asarray(vlm.forces_geometry)
lift_p = -F[:, 0] * onp.sin(ALPHA) + F[:, 2] * onp.cos(ALPHA)
yl = onp.asarray(vlm.front_left_vertices)[:, 1]; yr = onp.asarray(vlm.front_right_vertices)[:, 1]
lo, hi = onp.round(onp.minimum(yl, yr), 12), onp.round(onp.maximum(yl, yr), 12)
keys = sorted(set(zip(lo, hi)))
keys = [k for k in keys if k[0] >= -1e-9]
ls = onp.array([lift_p[(lo == a) & (hi == b)].sum() for a, b in keys])
edges = onp.array([k[0] for k in keys] + [keys[-1][1]])
Lhalf = ls.sum()
rho = op.atmosphere.density()
lhat = ls / onp.diff(edges) / Lhalf
cla = 2 * Lhalf / (0.5 * rho * 2 * AREA_HALF * onp.sin(ALPHA))
print(f"asb ns={ns} nc={nc} span={ss} chord={cs}: CL {res['CL']:.6f} -> CLa(sin) {res['CL']/onp.sin(ALPHA):.4f}, "
      f"strip-sum CLa {cla:.4f}, strips {len(ls)}")
os.makedirs("results", exist_ok=True)
onp.savez(f"results/asb_{ns}_{nc}_{ss}_{cs}.npz", edges=edges, centres=0.5 * (edges[:-1] + edges[1:]), lhat=lhat, cla=cla)
