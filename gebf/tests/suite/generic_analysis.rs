//! The integrator crate's generic linearisation and modes (`genalpha::analysis`) on a GEBF
//! cantilever, against the frequencies of `Model::linear_modes` as they were before that function
//! delegated to the generic code (null space from the eigenvectors of BᵀB), and
//! the damped (first-order, Schur) eigenvalues against the undamped ones.
use gebf::{Model, Options, samples};
use genalpha::ConstrainedSystem;
use genalpha::analysis::linearise;
use nalgebra::Vector3;

/// The first twelve circular frequencies (rad/s) of the 8-element, 5 m cantilever with the
/// paper's section (c = 1) from `Model::linear_modes` before it delegated to the generic code. The bending pairs are
/// degenerate (EI_yy = EI_zz); they split by up to 2e-7, old and new, within the eigensolver's
/// precision (see the test).
const BEFORE: [f64; 12] = [
    4.133684417529338e-1,
    4.13368528478194e-1,
    2.590973675621124e0,
    2.590973723607393e0,
    7.265735216715302e0,
    7.26573521846348e0,
    1.430730215679687e1,
    1.430730215915615e1,
    2.391040859661491e1,
    2.391040859803257e1,
    3.644472698494433e1,
    3.644472698787121e1,
];

fn worst_relative(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x / y - 1.0).abs()).fold(0.0, f64::max)
}

/// The attainable relative precision of a low frequency ω from a dense eigensolver is about
/// ε (ω_max/ω)² / 2, here 1.9e-6 for ω₁ (ω_max = 5.4e4 rad/s). Measured worst relative
/// differences: `linear_modes` and the generic modes 6.2e-8 from before; the damped
/// (state-space, Schur) eigenvalues 6.3e-7 from the undamped frequencies.
#[test]
fn generic_linearisation_matches_linear_modes() {
    let (b, j) = samples::cantilever(samples::paper_section(1.0), 5.0, 8);
    let model = Model::new(&b, &j, Vector3::zeros(), Options::default()).unwrap();
    let q = model.reference_coordinates();
    let now = model.linear_modes(&q).unwrap().omega;
    let lin = linearise(&model, 0.0, &q, &[], &vec![0.0; model.n_velocity_constraints()]).unwrap();
    assert!(lin.damping.amax() < 1e-12 * lin.stiffness.amax(), "no gyroscopic damping at rest");
    let natural = lin.natural_modes().unwrap().omega;
    let damped: Vec<f64> = lin.damped_modes(0).unwrap().iter().take(12).map(|m| m.damped_frequency()).collect();
    let (e_now, e_generic) = (worst_relative(&now[..12], &BEFORE), worst_relative(&natural[..12], &BEFORE));
    let e_damped = worst_relative(&damped, &natural[..12]);
    let split = (0..6).map(|p| (natural[2 * p + 1] / natural[2 * p] - 1.0).abs()).fold(0.0, f64::max);
    println!("highest frequency {:.3e} rad/s", natural.last().unwrap());
    println!(
        "worst relative difference from before: linear_modes {e_now:.1e}, generic {e_generic:.1e}; \
         damped vs undamped {e_damped:.1e}; largest split of a bending pair {split:.1e}"
    );
    assert!(e_now < 1e-6 && e_generic < 1e-6, "{e_now:e} {e_generic:e}");
    assert!(e_damped < 3e-6, "{e_damped:e}");
}
