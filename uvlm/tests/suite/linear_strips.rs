//! The strip forces of the linear UVLM (the per-panel-column forces of `Loads::strip`, which the
//! section polars' strip correction reads, docs/section_aero.md §7.5): every strip derivative
//! sums, surface by surface, to the nodal forces' derivative (the two split the same segment and
//! ring forces differently), and the moved lattice's strip forces are the nonlinear solver's.

use nalgebra::{Complex, DMatrix, Vector3};
use uvlm::samples::{SpanSpacing, rectangular_wing};
use uvlm::*;

type C = Complex<f64>;

/// Per surface, the sum over its strips (rows `3·te_columns`) and over its nodes (rows
/// `forces()`) of each column of `strips` and `nodal`, component by component: the largest
/// difference over the largest nodal sum.
fn sum_mismatch(lin: &LinearUvlm, strips: &DMatrix<C>, nodal: &DMatrix<C>) -> f64 {
    assert_eq!(strips.ncols(), nodal.ncols());
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    for b in lin.blocks() {
        for c in 0..nodal.ncols() {
            for q in 0..3 {
                let s: C = b.te_columns.clone().map(|j| strips[(3 * j + q, c)]).sum();
                let n: C = b.forces().step_by(3).map(|i| nodal[(i + q, c)]).sum();
                worst = worst.max((s - n).norm());
                scale = scale.max(n.norm());
            }
        }
    }
    worst / scale.max(1e-300)
}

fn complex(m: &DMatrix<f64>) -> DMatrix<C> {
    m.map(C::from)
}

fn column(v: &[f64]) -> DMatrix<C> {
    DMatrix::from_iterator(v.len(), 1, v.iter().map(|x| C::from(*x)))
}

/// A wing (8 strips, 4 chordwise) and a tail behind it, at 4°, with and without the
/// trailing-edge segment's force.
#[test]
fn strip_forces_sum_to_the_nodal_forces() {
    let alpha = 4f64.to_radians();
    let wing = rectangular_wing(0.0, 4.0, 1.0, 8, SpanSpacing::HalfCosine);
    let tail: Vec<SpanStation> = rectangular_wing(0.0, 1.5, 0.5, 4, SpanSpacing::Uniform)
        .into_iter()
        .map(|s| SpanStation { origin: s.origin + Vector3::new(3.0, 0.0, 0.25), ..s })
        .collect();
    let spec = LatticeSpec::new(4);
    let lats = vec![Lattice::from_stations(spec, &wing).unwrap(), Lattice::from_stations(spec, &tail).unwrap()];
    for te_force in [false, true] {
        let mut p = UvlmParams::new(1.2, [10.0 * alpha.cos(), 0.0, 10.0 * alpha.sin()]);
        p.images = vec![ImagePlane::through_origin([0.0, 1.0, 0.0])];
        p.te_segment_force = te_force;
        let wake = LinearWake::uniform(10, 0.25, te_force);
        let lin = Uvlm::with_surfaces(lats.clone(), p).unwrap().linearise(&wake).unwrap();
        assert_eq!(lin.strip_gamma.nrows(), 3 * 12);
        let mut worst = 0.0f64;
        let mut check = |x: f64, what: &str| {
            println!("te_segment_force {te_force}: {what}: {x:.1e}");
            assert!(x < 1e-12, "te_segment_force {te_force}: {what} differs by {x:.2e}");
            worst = worst.max(x);
        };
        check(sum_mismatch(&lin, &column(&lin.reference_strips), &column(&lin.reference_forces)), "reference");
        for s in [C::new(0.0, 0.0), C::new(-0.5, 6.0)] {
            check(sum_mismatch(&lin, &lin.strip_force_matrix(s), &lin.force_matrix(s)), "force matrix");
        }
        check(sum_mismatch(&lin, &complex(&lin.strip_gamma_dot), &complex(&lin.force_gamma_dot)), "unsteady term");
        let g = lin.gust([0.0, 0.2, 1.0], [-1.0, 0.0, 0.0]).unwrap();
        check(sum_mismatch(&lin, &complex(&g.strip_force), &complex(&g.force)), "gust input");
        let wd = lin.wake_node_derivatives();
        for k in [0, wd.force.len() - 1] {
            check(sum_mismatch(&lin, &complex(&wd.strip[k]), &complex(&wd.force[k])), "wake nodes");
        }
        // A moved lattice with velocities: the strip forces sum to the nodal ones, and at rest
        // they are the reference's.
        let mut moved = lin.lattices().to_vec();
        let (r0, f0, s0) = lin.evaluate_with_strips(&moved).unwrap();
        assert_eq!(
            (r0.len(), f0, s0.clone()),
            (lin.n_rings(), lin.reference_forces.clone(), lin.reference_strips.clone())
        );
        let st: Vec<SpanStation> = wing
            .iter()
            .chain(&tail)
            .map(|s| SpanStation { origin: s.origin + Vector3::new(0.0, 0.0, 0.01 * s.origin.y), ..*s })
            .collect();
        let vel: Vec<StationVelocity> = st
            .iter()
            .map(|s| StationVelocity { linear: Vector3::new(0.0, 0.0, 0.3 * s.origin.y), angular: Vector3::zeros() })
            .collect();
        lin.move_lattices(&mut moved, &st, Some(&vel)).unwrap();
        let (_, f1, s1) = lin.evaluate_with_strips(&moved).unwrap();
        check(sum_mismatch(&lin, &column(&s1), &column(&f1)), "moved lattice");
    }
}
