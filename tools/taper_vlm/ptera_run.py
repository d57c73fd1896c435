"""Pterasoftware steady ring VLM of the AR-8, taper-0.4 wing (symmetric, meshed as one wing).
usage: python ptera_run.py NSPAN_HALF NCHORD SPANSPACING(uniform|cosine) CHORDSPACING(uniform|cosine)
writes results/ptera_<ns>_<nc>_<ss>_<cs>.npz with strip edges, centres, l(y)/L_half, CL_alpha."""
import sys, os, logging
import numpy as np
import pterasoftware as ps
from common import *

ns, nc, ss, cs = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3], sys.argv[4]
af = ps.geometry.airfoil.Airfoil(name="naca0012")  # symmetric: flat mean camber line
root = ps.geometry.wing_cross_section.WingCrossSection(
    airfoil=af, num_spanwise_panels=ns, chord=ROOT, control_surface_symmetry_type="symmetric", Lp_Wcsp_Lpp=(0.0, 0.0, 0.0),
    spanwise_spacing=ss)
tip = ps.geometry.wing_cross_section.WingCrossSection(
    airfoil=af, num_spanwise_panels=None, chord=TIP, control_surface_symmetry_type="symmetric",
    Lp_Wcsp_Lpp=(0.25 * (ROOT - TIP), HALF, 0.0))  # unswept quarter-chord line
wing = ps.geometry.wing.Wing(
    wing_cross_sections=[root, tip], name="w", symmetric=True,
    symmetryNormal_G=(0.0, 1.0, 0.0), symmetryPoint_G_Cg=(0.0, 0.0, 0.0),
    num_chordwise_panels=nc, chordwise_spacing=cs)
plane = ps.geometry.airplane.Airplane(wings=[wing], s_ref=2 * AREA_HALF, c_ref=AREA_HALF / HALF, b_ref=2 * HALF)
op = ps.operating_point.OperatingPoint(rho=1.0, vCg__E=1.0, alpha=ALPHA_DEG)
prob = ps.problems.SteadyProblem(airplanes=[plane], operating_point=op)
solver = ps.steady_ring_vortex_lattice_method.SteadyRingVortexLatticeMethodSolver(prob)
solver.run(calculate_streamlines=False)

w = plane.wings[0]
P = w.panels  # (nc, nspan_total)
# spanwise positions of the strips from the front vertices of the leading-edge row
yl = np.array([p.Flpp_G_Cg[1] for p in P[0]])
yr = np.array([p.Frpp_G_Cg[1] for p in P[0]])
Fw = np.array([[p.forces_W for p in row] for row in P])  # (nc, nsp, 3)
tot = Fw.sum(axis=(0, 1))
k = int(np.argmax(np.abs(tot)))
lift_strip = Fw[:, :, k].sum(axis=0) * np.sign(tot[k])
lo, hi = np.minimum(yl, yr), np.maximum(yl, yr)
mask = lo >= -1e-9  # right half only
lo, hi, ls = lo[mask], hi[mask], lift_strip[mask]
o = np.argsort(lo); lo, hi, ls = lo[o], hi[o], ls[o]
edges = np.append(lo, hi[-1])
Lhalf = ls.sum()
lhat = ls / (hi - lo) / Lhalf
cla = 2 * Lhalf / (0.5 * 2 * AREA_HALF * np.sin(ALPHA))
print(f"ptera ns={ns} nc={nc} span={ss} chord={cs}: forces_W total {tot}, lift comp {k}, CLa(sin) {cla:.4f} "
      f"(/alpha {2*Lhalf/(0.5*2*AREA_HALF*ALPHA):.4f}), half-lift {Lhalf:.6f}, tip edge {edges[-1]:.4f}")
os.makedirs("results", exist_ok=True)
np.savez(f"results/ptera_{ns}_{nc}_{ss}_{cs}.npz", edges=edges, centres=0.5 * (edges[:-1] + edges[1:]),
         lhat=lhat, cla=cla)
