//! The flared-hinge lattice of the paper's wing (semispan 16 m = 12 + 4, chord 1 m, 24 + 8
//! spanwise × 4 chordwise panels, flare 10°).

use approx::assert_relative_eq;
use uvlm::samples::FlaredWing;
use uvlm::*;

fn wing() -> FlaredWing {
    FlaredWing { aoa: 5f64.to_radians(), ..FlaredWing::default() }
}

/// Hinge-column nodes are one set of entries shared by the panels on both sides, lie on the
/// hinge axis, and are bitwise the same whatever the fold angle (they are driven by the inner
/// station only, so no gap can open).
#[test]
fn hinge_column_nodes_are_shared_and_on_axis() {
    let w = wing();
    let jh = w.n_inner;
    let axis = w.hinge_axis();
    let hinge_point = nalgebra::Vector3::new(w.inner_length, 0.0, 0.0);
    let reference = Lattice::from_stations(w.spec(), &w.stations(0.0)).unwrap();
    for fold in [-30.0, -10.0, 0.0, 10.0, 30.0f64] {
        let lat = Lattice::from_stations(w.spec(), &w.stations(fold.to_radians())).unwrap();
        assert_eq!(lat.hinge_column(), Some(jh));
        for i in 0..lat.n_chordwise() {
            let inner = lat.ring_corners(i, jh - 1);
            let outer = lat.ring_corners(i, jh);
            // B, C of the inner ring are A, D of the outer ring: the same node entries.
            assert_eq!(inner[1], outer[0]);
            assert_eq!(inner[2], outer[3]);
        }
        for i in 0..=lat.n_chordwise() {
            let k = lat.node_index(i, jh);
            assert_eq!(lat.ring_nodes()[k], reference.ring_nodes()[k], "hinge node {i} moved at fold {fold}°");
            assert_eq!(lat.grid_nodes()[k], reference.grid_nodes()[k]);
            let g = lat.ring_nodes()[k];
            let r = nalgebra::Vector3::new(g[0], g[1], g[2]) - hinge_point;
            assert!(r.cross(&axis).norm() <= 1e-14, "hinge node {i} off the axis by {:e}", r.cross(&axis).norm());
        }
    }
}

/// Column loads per unit span (normal force) for a steady solve.
fn column_normal_loads(w: &FlaredWing, fold: f64) -> (Vec<f64>, f64) {
    let st = w.stations(fold.to_radians());
    let lat = Lattice::from_stations(w.spec(), &st).unwrap();
    let mut u = Uvlm::new(lat, UvlmParams::new(0.0889, [0.0, -25.0, 0.0])).unwrap();
    let loads = u.solve_steady().unwrap();
    let origins: Vec<[f64; 3]> = st.iter().map(|s| s.origin.into()).collect();
    let (mut f, mut m) = (vec![[0.0; 3]; st.len()], vec![[0.0; 3]; st.len()]);
    loads.column_loads_inplace(&origins, &mut f, &mut m);
    // Interior columns carry half of two 0.5 m strips.
    let q = (0..st.len())
        .map(|j| {
            let n = st[j].frame.column(2);
            (f[j][0] * n[0] + f[j][1] * n[1] + f[j][2] * n[2]) / 0.5
        })
        .collect();
    (q, loads.total_force()[2])
}

/// Folding the outer part to ±30° keeps the lattice valid and the loads finite, with a monotone
/// transition across the hinge (the hinge column lies between the columns two stations inboard
/// and outboard: no spike from nearly coincident filaments). Flared folding lowers the tip's
/// incidence when folding up (Δα ≈ −θ·sinΛ), so the outer load drops for +30° and rises for −30°.
/// At zero fold the flared mesh gives the same lift as an unflared mesh of the same flat wing.
#[test]
fn folded_lattice_loads_finite_and_smooth() {
    let w = wing();
    let jh = w.n_inner;
    let (flat, lift_flat) = column_normal_loads(&w, 0.0);
    let (unflared, lift_unflared) = column_normal_loads(&FlaredWing { flare: 0.0, ..w }, 0.0);
    assert_relative_eq!(lift_flat, lift_unflared, max_relative = 1e-3);
    assert_relative_eq!(flat[jh], unflared[jh], max_relative = 0.01);
    for fold in [-30.0, 30.0f64] {
        let (q, lift) = column_normal_loads(&w, fold);
        assert!(q.iter().all(|x| x.is_finite()) && lift.is_finite());
        let (lo, hi) = (q[jh - 2].min(q[jh + 2]), q[jh - 2].max(q[jh + 2]));
        assert!(q[jh] >= lo && q[jh] <= hi, "fold {fold}: hinge column {} outside [{lo}, {hi}]", q[jh]);
        let outer: f64 = q[jh + 1..q.len() - 1].iter().sum();
        let outer_flat: f64 = flat[jh + 1..flat.len() - 1].iter().sum();
        if fold > 0.0 {
            assert!(outer < 0.5 * outer_flat);
        } else {
            assert!(outer > 1.2 * outer_flat);
        }
        println!("fold {fold}°: lift {lift:.2} N (flat {lift_flat:.2} N), columns 22..26: {:?}", &q[jh - 2..=jh + 2]);
    }
}

/// Impossible folds are rejected by the mesher with a clear error (the outer part folded back
/// onto the inner one), and a NaN station is named.
#[test]
fn mesher_rejects_impossible_folds() {
    let w = wing();
    let err = Lattice::from_stations(w.spec(), &w.stations(170f64.to_radians())).unwrap_err();
    assert!(
        matches!(
            err,
            UvlmError::FoldedPanels { .. } | UvlmError::NonMonotoneColumns { .. } | UvlmError::SkewedPanel { .. }
        ),
        "{err}"
    );
    let mut st = w.stations(0.0);
    st[7].chord = f64::NAN;
    let err = Lattice::from_stations(w.spec(), &st).unwrap_err();
    assert!(matches!(err, UvlmError::InvalidStation { station: 7, field: "chord", .. }), "{err}");
}

/// The coupling transfer: column loads sum to the total force and their moments about the
/// station origins plus origin × force give the total moment.
#[test]
fn column_loads_conserve_force_and_moment() {
    let w = wing();
    let st = w.stations(0.3);
    let lat = Lattice::from_stations(w.spec(), &st).unwrap();
    let mut u = Uvlm::new(lat, UvlmParams::new(0.0889, [0.0, -25.0, 0.0])).unwrap();
    u.step(0.01).unwrap();
    u.step(0.01).unwrap();
    let loads = u.loads();
    let origins: Vec<[f64; 3]> = st.iter().map(|s| s.origin.into()).collect();
    let (mut f, mut m) = (vec![[0.0; 3]; st.len()], vec![[0.0; 3]; st.len()]);
    loads.column_loads_inplace(&origins, &mut f, &mut m);
    let total = loads.total_force();
    let m0 = loads.moment_about([0.0; 3]);
    for q in 0..3 {
        let sf: f64 = f.iter().map(|v| v[q]).sum();
        assert_relative_eq!(sf, total[q], max_relative = 1e-12, epsilon = 1e-9);
    }
    let mut mm = [0.0; 3];
    for ((o, fj), mj) in origins.iter().zip(&f).zip(&m) {
        let c = [o[1] * fj[2] - o[2] * fj[1], o[2] * fj[0] - o[0] * fj[2], o[0] * fj[1] - o[1] * fj[0]];
        for q in 0..3 {
            mm[q] += mj[q] + c[q];
        }
    }
    for q in 0..3 {
        assert_relative_eq!(mm[q], m0[q], max_relative = 1e-10, epsilon = 1e-8);
    }
}

/// On a fine spanwise mesh (panel width 1/16 m < tanβ·c/2 = 0.088 m) a single slanted column
/// crosses its neighbours: the mesher rejects it. Blending the slant over the neighbouring columns
/// gives a valid lattice whose lift equals that of the unflared mesh of the same flat wing.
#[test]
fn fine_mesh_needs_blended_slant() {
    let fine = FlaredWing { n_inner: 192, n_outer: 64, ..wing() };
    let err = Lattice::from_stations(fine.spec(), &fine.stations(0.0)).unwrap_err();
    assert!(
        matches!(
            err,
            UvlmError::SkewedPanel { .. } | UvlmError::NonMonotoneColumns { .. } | UvlmError::DegeneratePanel { .. }
        ),
        "{err}"
    );
    let blended = FlaredWing { blend_columns: 4, ..fine };
    let lift = |w: &FlaredWing, fold: f64| {
        let lat = Lattice::from_stations(w.spec(), &w.stations(fold)).unwrap();
        let mut u = Uvlm::new(lat, UvlmParams::new(0.0889, [0.0, -25.0, 0.0])).unwrap();
        u.solve_steady().unwrap().total_force()[2]
    };
    let unflared = FlaredWing { flare: 0.0, ..fine };
    assert_relative_eq!(lift(&blended, 0.0), lift(&unflared, 0.0), max_relative = 1e-3);
    assert!(lift(&blended, 0.5).is_finite());
}
