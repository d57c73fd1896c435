#!/usr/bin/env python3
"""Write cases/horten_flying_wing.json and the full-span flights of cases/flight/ (level flight, the
doublet free and held, the 1-cos gust free and held; docs/trim.md sections 5 and 6): the Horten flying wing of Richards et al. (2016) as
SHARPy's hangar describes it (ImperialCollegeLondon/sharpy, cases/hangar/horten_wing.py with the
`Baseline` of cases/hangar/richards_wing.py; the trim of docs/source/content/example_notebooks/
linear_horten.ipynb: M = 4, N = 11, Msf = 5, 28 m/s, rho 1.02, sigma 1).

A half model (right wing) with a mirror plane at x = 0. Our axes: span +X, nose +Y, up +Z.
* centre section: 0.4125 m (half of 0.825 m), chord 1.0 m, beam at 0.33 chord;
* wing: 11 bodies (SHARPy's 11 elements, each its own constant section), beam swept 20 deg aft
  from y = 0.4125 to the tip at 10 m, chord 1.0 -> 0.25 m along the stream (SHARPy's
  aligned grid), beam at 0.33 chord, washout 0 -> -2 deg (nose down) at the tip;
* stiffness per element k (alpha_k = k/10): K_root (1 - alpha_k^2) + K_tip alpha_k^2, K_tip =
  0.25^2 K_root, K_root = diag(EA 1e6, GA 1e6, GA 1e6, GJ 4.24e5, EI_flap 3.84e5, EI_edge 2.46e7);
  the centre section has the root's;
* mass per element k: the thin-walled section at chord c_k = 1 - 0.75 alpha_k (a NACA 0012 skin
  1.905 mm thick and an I-spar 0.1 c wide and 0.12 c deep, 1.27 mm, aluminium 2770 kg/m^3),
  its mass and centre of mass computed here as SHARPy's hangar defines them, its rotary
  inertias about that centre from the same thin walls;
* point masses: half of the 15.29 kg fuselage at the centreline, a 5.244 kg engine at the end
  of the centre section, where the thrust acts forward;
* elevons on the outer 6 of the 11 wing elements, half the chord (2 of 4 panels);
* lattice: 4 chordwise panels, 2 spanwise panels per element, a 20-row wake of 0.25 m rows.
"""
import json
import math
import os

RHO_AL = 2770.0


def polyline_props(y, z, t):
    """Mass per length, centroid (length-weighted, as the hangar does) and the segment data."""
    segs = []
    for i in range(len(t)):
        dy, dz = y[i + 1] - y[i], z[i + 1] - z[i]
        length = math.hypot(dy, dz)
        segs.append((length, t[i], 0.5 * (y[i] + y[i + 1]), 0.5 * (z[i] + z[i + 1])))
    mass = sum(l * th for l, th, _, _ in segs) * RHO_AL
    ltot = sum(l for l, _, _, _ in segs)
    cy = sum(l * my for l, _, my, _ in segs) / ltot
    cz = sum(l * mz for l, _, _, mz in segs) / ltot
    return mass, (cy, cz), segs


def naca0012_skin(c):
    n = 100
    ys = [c * i / (n - 1) for i in range(n)]
    zs = [5 * 0.12 * (0.2969 * math.sqrt(x / c) - 0.1260 * x / c - 0.3516 * (x / c) ** 2
                      + 0.2843 * (x / c) ** 3 - 0.1015 * (x / c) ** 4) * c for x in ys]
    y = ys + ys[:-1][::-1]
    z = zs + [-v for v in zs[:-1][::-1]]
    y = [v - 0.25 * c for v in y]  # relative to the quarter chord, positive aft
    return y, z, [0.127e-2 * 1.5] * (len(y) - 1)


def i_spar(c):
    w, zm, t = 0.1 * c, 0.12 * c, 0.127e-2
    return ([-w / 2, w / 2, 0, 0, -w / 2, w / 2], [zm / 2, zm / 2, zm / 2, -zm / 2, -zm / 2, -zm / 2],
            [t, 0, t, 0, t])


def inertias(segs, cy, cz):
    """Rotary inertias per length about the section's centre of mass: I_yy from the z distances,
    I_zz from the chordwise ones, I_xx = I_yy + I_zz (a thin-walled section). The hangar's own
    I_xx, I_yy, I_zz (measured about other points and on a 1 m slice) are not consistent beam
    inertias (ANCF's slope inertias would be negative), so these replace them."""
    iyy = sum(l * th * RHO_AL * (mz - cz) ** 2 for l, th, _, mz in segs)
    izz = sum(l * th * RHO_AL * (my - cy) ** 2 for l, th, my, _ in segs)
    return iyy + izz, iyy, izz


def section(c):
    items = [polyline_props(*naca0012_skin(c)), polyline_props(*i_spar(c))]
    mass = sum(m for m, _, _ in items)
    cy = sum(m * cm[0] for m, cm, _ in items) / mass
    cz = sum(m * cm[1] for m, cm, _ in items) / mass
    i = [sum(v) for v in zip(*(inertias(s, cy, cz) for _, _, s in items))]
    return mass, cy, i


def main():
    n_el, span, half_fus, sweep = 11, 20.0, 0.4125, 20.0
    k_root = dict(ea=1e6, ga_y=1e6, ga_z=1e6, gj=4.24e5, ei_yy=3.84e5, ei_zz=2.46e7)
    taper = 0.25
    wing_dy = (span / 2 - half_fus) / n_el
    el_len = wing_dy / math.cos(math.radians(sweep))

    def sec(k):
        a = k / (n_el - 1)
        c = 1.0 - 0.75 * a
        m, cy, (ixx, iyy, izz) = section(c)
        # Centre of mass ahead of the beam (0.33 c from the leading edge), as the hangar places it.
        cg_fwd = -(cy + (0.25 - 0.33) * c)
        stiff = {key: v * ((1 - a * a) + taper ** 2 * a * a) for key, v in k_root.items()}
        return dict(mass=m, rho_ixx=ixx, rho_iyy=iyy, rho_izz=izz,
                    cg_offset=[cg_fwd, 0.0], **stiff)

    sw, cw = math.sin(math.radians(sweep)), math.cos(math.radians(sweep))
    fus = 150 / 9.81
    engine = dict(mass=51.445 / 9.81, inertia=[0.29547, 0.29322, 0.29547])
    # The free body: a 5 cm hub along the aircraft's axis, ending at the centreline, carrying the
    # fuselage's mass; both half-wings hang from its end (their root sections meet there).
    bodies = [dict(name="hub", start=[0, 0.05, 0], length=0.05, x_axis=[0, -1, 0], y_axis=[0, 0, 1],
                   section=dict(mass=0.01, rho_ixx=2e-6, rho_iyy=1e-6, rho_izz=1e-6, **k_root),
                   point_masses=[dict(at=0.05, mass=fus, inertia=[0.5 * fus, fus, fus])])]
    joints = [dict(type="free", name="flight", body="hub")]
    surfaces, controls, elevator = [], [], []
    for side, sign in (("r", 1.0), ("l", -1.0)):
        # The left half-wing runs along -X with its section z axis down: its nose-down twist and
        # trailing-edge-down deflection have the other sign.
        names = [f"centre_{side}"]
        bodies.append(dict(name=names[0], length=half_fus, x_axis=[sign, 0, 0], y_axis=[0, 1, 0], section=sec(0),
                           point_masses=[dict(at=half_fus, **engine)]))
        joints.append(dict(type="flared_hinge", name=f"root_{side}", parent="hub", child=names[0], flare_deg=0,
                           locked=True))
        chord, le = [[1.0, 1.0]], [[0.33, 0.33]]
        for k in range(n_el):
            name = f"{side}{k}"
            c0, c1 = 1.0 - 0.75 * k / n_el, 1.0 - 0.75 * (k + 1) / n_el
            bodies.append(dict(name=name, length=el_len, section=sec(k),
                               x_axis=[sign * cw, -sw, 0.0], y_axis=[sign * sw, cw, 0.0],
                               twist_deg=[-2.0 * sign * k / n_el, -2.0 * sign * (k + 1) / n_el]))
            joints.append(dict(type="flared_hinge", name=f"{names[-1]}_{name}", parent=names[-1], child=name,
                               flare_deg=0, locked=True))
            names.append(name)
            chord.append([c0, c1])
            le.append([0.33 * c0, 0.33 * c1])
            if k >= 5:
                controls.append(dict(name=f"elevon_{name}", body=name, span=[0.0, el_len], chord_fraction=0.5,
                                     deflection_deg=sign * 0.1814))
                elevator.append(f"elevon_{name}" if sign > 0 else dict(name=f"elevon_{name}", gain=-1.0))
        surfaces.append(dict(name=f"wing_{side}", bodies=names, chord=chord, le_offset=le, sections="streamwise",
                             panels_per_body=[2] * (n_el + 1)))
    case = dict(
        name="horten_flying_wing",
        description=(
            "The Horten flying wing of Richards, Yao, Herd, Hodges & Mardanpour (J. Aircraft 2016) as SHARPy's "
            "hangar models it (ImperialCollegeLondon/sharpy cases/hangar/horten_wing.py and richards_wing.py, "
            "Baseline; its trim in docs/source/content/example_notebooks/linear_horten.ipynb: alpha 4.5135 deg, "
            "elevon 0.1814 deg, thrust 5.4560 N per engine at 28 m/s, rho 1.02, from its start at 5.5129 N). Full span: a hub on the free joint "
            "carrying the fuselage mass, two half-wings of 12 bodies each: 20 m span, 20 deg beam sweep, root chord 1.0, taper 0.25, washout 2 deg, elevons on the outer 6/11 "
            "of each wing at half chord. Written by tools/horten_case.py; docs/trim.md."),
        bodies=bodies, joints=joints, gravity=[0, 0, -9.81],
        thrust=[dict(name=f"engine_{side}", body=f"centre_{side}", at=half_fus, direction=[0, 1, 0], magnitude=5.5129)
                for side in "rl"],
        t_end=10.0, output_dt=10 * 0.25 / 28, initial="trim",
        ancf=dict(elements_per_body=[1] + [2] * (2 * n_el + 2), dt=0.25 / 28, rho_inf=0.8),
        gebf=dict(elements_per_body=[1] * (2 * n_el + 3), dt=0.25 / 28, rho_inf=0.8),
        aero=dict(rho=1.02, v_inf=[0, -28.0, 0], n_chordwise=4, n_wake_rows=20, cutoff_radius=1e-3,
                  surfaces=surfaces,
                  control_surfaces=controls),
        trim=dict(elevator=elevator, alpha_deg=4.0,
                  wake=dict(row_length=0.25, rows=20)),
    )
    root = os.path.join(os.path.dirname(__file__), "..", "cases")
    flight = dict(case, name="horten_level_flight",
                  description=case["description"] + " Full span, for the time march from the trim (initial: trim): "
                  "level flight at 28 m/s for 10 s; the flight-dynamics roots about the trim at 28 and 30 m/s.",
                  stability=dict(airspeeds=[28.0, 30.0], modes=4, about="trim"))
    write(os.path.join(root, "flight", "horten_level_flight.json"), flight)
    write(os.path.join(root, "horten_flying_wing.json"), half_model(case))
    write(os.path.join(root, "flight", "horten_doublet.json"), doublet(flight))
    for held in (False, True):
        write(os.path.join(root, "flight", f"horten_gust{'_held' if held else ''}.json"), gust(flight, held))
    write(os.path.join(root, "flight", "horten_doublet_held.json"), doublet_held(flight))


FREE_VS_HELD = (" The root loads are measured at the right wing's root joint (root_joint: root_r), in body axes; "
                "docs/trim.md section 6 compares the free aircraft with the held one.")


def gust(flight, held):
    """The full-span aircraft trimmed at 30 m/s through a 1-cos vertical gust (H 5 m, 3 m/s peak),
    free or held at its hub from the same trimmed state (initial: trim_held), 1.5 s: the gust load
    peaks within its first 0.4 s."""
    case = doublet(flight)
    for cs in case["aero"]["control_surfaces"]:
        cs["deflection_deg"] = cs["deflection_deg"][0][1]
    name = "horten_gust_held" if held else "horten_gust"
    case["name"] = name
    what = ("held at its hub (the free joint a clamp) from the trimmed state (initial: trim_held)" if held
            else "free, from the trim (initial: trim)")
    case["description"] = flight["description"].replace(
        " Full span, for the time march from the trim (initial: trim): level flight at 28 m/s for 10 s.",
        f" Full span, trimmed at 30 m/s and {what}, through a 1-cos vertical gust (gradient 5 m, 3 m/s) for 1.5 s."
        + FREE_VS_HELD)
    dt = case["ancf"]["dt"]
    case["t_end"] = round(1.5 / dt) * dt
    case["output_dt"] = dt
    case["root_joint"] = "root_r"
    case["aero"]["gust"] = dict(kind="one_minus_cosine", gradient_m=5.0, velocity=3.0)
    if held:
        case["initial"] = "trim_held"
    return reorder(case)


def doublet_held(flight):
    """The doublet of `doublet` on the aircraft held at its hub (initial: trim_held), 3 s: the elevons'
    load on the wing without the aircraft's response."""
    case = doublet(flight)
    case["name"] = "horten_doublet_held"
    case["description"] = flight["description"].replace(
        " Full span, for the time march from the trim (initial: trim): level flight at 28 m/s for 10 s.",
        " Full span, trimmed at 30 m/s and held at its hub (the free joint a clamp) from the trimmed state "
        "(initial: trim_held), a 1 deg elevator doublet at 0.5-0.9 s, 3 s." + FREE_VS_HELD)
    dt = case["ancf"]["dt"]
    case["t_end"] = round(3.0 / dt) * dt
    case["output_dt"] = dt
    case["root_joint"] = "root_r"
    case["initial"] = "trim_held"
    return reorder(case)


def reorder(case):
    """`root_joint` after `joints` (where the case-file reference lists it), the rest in order."""
    out = {}
    for k, v in case.items():
        if k != "root_joint":
            out[k] = v
        if k == "joints":
            out["root_joint"] = case["root_joint"]
    return out


def doublet(flight):
    """The full-span aircraft at 30 m/s, trimmed, with a 1 deg elevator doublet (0.5-0.9 s) on top
    of the trim, flown 60 s: the phugoid of docs/trim.md section 5."""
    case = json.loads(json.dumps(flight))
    case["name"] = "horten_doublet"
    case["description"] = flight["description"].replace(
        "level flight at 28 m/s for 10 s; the flight-dynamics roots about the trim at 28 and 30 m/s.",
        "at 30 m/s, a 1 deg elevator doublet at 0.5-0.9 s, flown 60 s (the phugoid).")
    del case["stability"]
    dt = 0.25 / 30
    case["aero"]["v_inf"] = [0, -30.0, 0]
    for blk in ("ancf", "gebf"):
        case[blk]["dt"] = dt
    case["t_end"] = round(60 / dt) * dt
    case["output_dt"] = 10 * dt
    for cs in case["aero"]["control_surfaces"]:
        g = 1.0 if cs["body"].startswith("r") else -1.0
        d = cs["deflection_deg"]
        cs["deflection_deg"] = [[0, d], [0.5, d], [0.6, d + g], [0.8, d - g], [0.9, d]]
    return case


def half_model(full):
    """The right half of `full` with a mirror plane at x = 0 (the trim of a symmetric aircraft):
    its centre section on the free joint, with half the fuselage's mass at the centreline."""
    case = json.loads(json.dumps(full))
    hub = case["bodies"][0]
    fus = hub["point_masses"][0]
    keep = [b for b in case["bodies"] if b["name"] == "centre_r" or b["name"].startswith("r")]
    names = {b["name"] for b in keep}
    keep[0]["start"] = [0.0, 0.0, 0.0]
    keep[0]["point_masses"].insert(0, dict(at=0.0, mass=fus["mass"] / 2, inertia=[v / 2 for v in fus["inertia"]]))
    case["bodies"] = keep
    case["joints"] = [dict(type="free", name="flight", body="centre_r")] + [
        j for j in case["joints"] if j.get("child") in names and j.get("parent") in names]
    case["thrust"] = [t for t in case["thrust"] if t["body"] in names]
    for blk in ("ancf", "gebf"):
        case[blk]["elements_per_body"] = case[blk]["elements_per_body"][1:1 + len(keep)]
    aero = case["aero"]
    # SHARPy's vortex core. The full span needs a larger one: its two half-wings' root columns
    # lie on each other at the hub, and ANCF's difference quotients of the lattice's loads move
    # one by 1e-6 m against the other (docs/trim.md section 5).
    aero["cutoff_radius"] = 1e-6
    aero["images"] = [dict(point=[0, 0, 0], normal=[1, 0, 0])]
    aero["surfaces"] = [sf for sf in aero["surfaces"] if sf["bodies"][0] in names]
    aero["control_surfaces"] = [c for c in aero["control_surfaces"] if c["body"] in names]
    case["trim"]["elevator"] = [e for e in case["trim"]["elevator"] if isinstance(e, str)]
    # A free half model is not a symmetric aircraft in a time march (nothing keeps it symmetric):
    # its march is a short drop from the reference; the flight is cases/flight/horten_level_flight.json.
    case.pop("initial")
    case["t_end"] = 0.25 / 28 * 6
    case["output_dt"] = 0.25 / 28
    case["description"] = full["description"].replace(
        "Full span: a hub on the free joint carrying the fuselage mass, two half-wings of 12 bodies each",
        "Half model with a mirror plane at x = 0 (the right half-wing of 12 bodies, its centre section on the "
        "free joint with half the fuselage mass)") + " The time march is a 54 ms drop from the reference."
    return case


def write(path, case):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        json.dump(case, f, indent=2)
        f.write("\n")
    bodies = case["bodies"]
    mass = sum(b["section"]["mass"] * b["length"] + sum(p["mass"] for p in b.get("point_masses", [])) for b in bodies)
    print(f"wrote {path}: {len(bodies)} bodies, mass {mass:.3f} kg")


if __name__ == "__main__":
    main()
