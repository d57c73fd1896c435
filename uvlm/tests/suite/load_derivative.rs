//! The steady loads' analytic derivative with respect to the lattice's vertices
//! (`Uvlm::steady_load_derivative`, docs/uvlm.md §17) against central differences of steady
//! solves on a moved grid.

use nalgebra::{DMatrix, Vector3};
use uvlm::samples::{FlaredWing, SpanSpacing, rectangular_wing};
use uvlm::*;

/// Central differences (step `h`, m) of the nodal and strip forces with respect to every grid
/// coordinate, against the analytic derivative mapped to the grid (`D · T`); returns the largest
/// difference over the largest entry, for the nodal and the strip forces.
fn worst_against_differences(uv: &mut Uvlm, h: f64) -> (f64, f64) {
    let d = uv.steady_load_derivative().expect("derivative");
    let t = d.ring_from_grid();
    let (dn, ds) = (&d.d_nodal * &t, &d.d_strip * &t);
    // The derivative's own solution is the solver's.
    let loads = uv.solve_steady().expect("solve").clone();
    for (a, b) in d.nodal.iter().zip(&loads.nodal) {
        for q in 0..3 {
            assert!((a[q] - b[q]).abs() <= 1e-10 * (1.0 + b[q].abs()), "nodal force {a:?} vs {b:?}");
        }
    }
    let grid: Vec<[f64; 3]> = uv.lattice().grid_nodes().to_vec();
    let vel = vec![[0.0; 3]; grid.len()];
    let (nn, ns) = (dn.nrows(), ds.nrows());
    let mut fd_n = DMatrix::zeros(nn, 3 * grid.len());
    let mut fd_s = DMatrix::zeros(ns, 3 * grid.len());
    let mut eval = |g: &[[f64; 3]]| {
        uv.set_grid(g, &vel).expect("grid");
        let l = uv.solve_steady().expect("solve");
        (l.nodal.concat(), l.strip.concat())
    };
    for c in 0..3 * grid.len() {
        let mut g = grid.clone();
        g[c / 3][c % 3] += h;
        let (np, sp) = eval(&g);
        g[c / 3][c % 3] -= 2.0 * h;
        let (nm, sm) = eval(&g);
        for r in 0..nn {
            fd_n[(r, c)] = (np[r] - nm[r]) / (2.0 * h);
        }
        for r in 0..ns {
            fd_s[(r, c)] = (sp[r] - sm[r]) / (2.0 * h);
        }
    }
    eval(&grid);
    let rel = |a: &DMatrix<f64>, b: &DMatrix<f64>| (a - b).amax() / b.amax();
    (rel(&dn, &fd_n), rel(&ds, &fd_s))
}

/// A small lattice with every grid node moved off the plane by a fixed pseudo-random pattern.
fn rough_lattice(spec: LatticeSpec) -> Lattice {
    let st = rectangular_wing(0.3, 1.5, 0.4, 4, SpanSpacing::Cosine);
    let mut lat = Lattice::from_stations(spec, &st).expect("lattice");
    let g: Vec<[f64; 3]> = lat
        .grid_nodes()
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let s = (k as f64 * 1.618).sin();
            let c = (k as f64 * 2.414).cos();
            [p[0] + 0.02 * s, p[1] + 0.015 * c, p[2] + 0.03 * s * c]
        })
        .collect();
    lat.set_grid(&g, &vec![[0.0; 3]; g.len()]).expect("rough grid");
    lat
}

/// A rough 3 × 4 lattice at 6° (semi-infinite legs, 1e-6 m cut-off; and a finite wake of 5
/// chords with a fixed 2 mm Scully core beside an image plane at y = 0): the analytic derivative
/// of the nodal and strip forces equals central differences of step 1e-6 m within 1e-7 of the
/// largest entry (measured 3.5e-11 and 4.4e-9: the differences' truncation and rounding).
#[test]
fn load_derivative_matches_differences_on_a_rough_lattice() {
    let a = 6f64.to_radians();
    let v = [10.0 * a.cos(), 0.0, 10.0 * a.sin()];
    let plain = UvlmParams::new(1.2, v);
    let mut finite = UvlmParams::new(1.2, v);
    finite.steady_wake = SteadyWake::Finite { length: 2.0 };
    finite.bound_core = CoreModel::ScullyRadius { radius: 2e-3 };
    finite.images = vec![ImagePlane::through_origin([0.0, 1.0, 0.0])];
    for params in [plain, finite] {
        let mut uv = Uvlm::new(rough_lattice(LatticeSpec::new(3)), params).expect("solver");
        let (n, s) = worst_against_differences(&mut uv, 1e-6);
        println!("rough lattice: nodal {n:.2e}, strip {s:.2e}");
        assert!(n < 1e-7 && s < 1e-7, "nodal {n:.2e}, strip {s:.2e}");
    }
}

/// The flared folding wing of the samples (8 + 4 spanwise × 3 chordwise, 10° flare with a
/// blended column, tip folded 20°, 5° pitch, semi-infinite legs, the default 1e-6 m cut-off):
/// the derivative equals central differences of steps 1e-4 – 1e-7 m within 1e-8 of the largest
/// entry (measured 2.5e-9, 2.8e-11, 1.3e-10, 1.6e-9: truncation, then rounding). The load points
/// lie on the axis extensions of their row's segments (the inner wing's rows are straight), the
/// case where the axis cut-off made the loads jump (docs/uvlm.md §3): with it, steps 1e-5 – 1e-6
/// m missed by 6e-3 and 1.4e-6.
#[test]
fn load_derivative_matches_differences_on_a_folded_wing() {
    let w = FlaredWing {
        n_inner: 8,
        n_outer: 4,
        n_chordwise: 3,
        aoa: 5f64.to_radians(),
        blend_columns: 1,
        ..FlaredWing::default()
    };
    let lat = Lattice::from_stations(w.spec(), &w.stations(20f64.to_radians())).expect("lattice");
    let v = Vector3::new(0.0, -30.0, 0.0);
    let mut uv = Uvlm::new(lat, UvlmParams::new(1.225, [v.x, v.y, v.z])).expect("solver");
    for h in [1e-4, 1e-5, 1e-6, 1e-7] {
        let (n, s) = worst_against_differences(&mut uv, h);
        println!("folded wing, step {h:.0e} m: nodal {n:.2e}, strip {s:.2e}");
        assert!(n < 1e-8 && s < 1e-8, "step {h:.0e}: nodal {n:.2e}, strip {s:.2e}");
    }
}
