//! Checks written once for every formulation, generic over the formulation trait
//! ([`BuildModel`], [`formulation::Structure`]): each runs for every model of
//! [`Formulation::ALL`] through the factory's [`dispatch`], so a third formulation is checked by
//! implementing the trait.

use aeroelastic::factory::{BuildModel, ForModel, dispatch};
use aeroelastic::problem::Formulation;
use genalpha::analysis::{NaturalModes, linearise};
use scene::samples::{free_hinge_tip_inertia, free_hinge_wing};

/// The natural modes of a model of `scene` at rest in its reference configuration (zero joint
/// multipliers), by the integrator crate's generic linearisation.
struct RestModes<'a>(&'a scene::Scene);

impl ForModel for RestModes<'_> {
    type Output = NaturalModes;
    fn run<M: BuildModel>(self) -> NaturalModes {
        let model = M::from_scene(self.0).unwrap();
        let q = model.initial_state().q;
        let (lambda, mu) = (vec![0.0; model.n_holonomic()], vec![0.0; model.n_velocity_constraints()]);
        linearise(&model, 0.0, &q, &lambda, &mu).unwrap().natural_modes().unwrap()
    }
}

/// The fold mode of a free flared hinge (issue 38): the Healy-like wing of
/// [`free_hinge_wing`] at rest, no gravity, no flow. Its lowest mode is the tip turning about the
/// hinge axis at `ω = √(k/J)`, `J` the tip's moment of inertia about that axis, at flares 0°,
/// 10°, 20° and 30° and springs of 1e-4 N·m/rad (Healy's; 0.035–0.039 Hz) and 1e-2
/// (0.35–0.39 Hz): within 2 % for every formulation. The rigid-tip estimate holds because the
/// fold frequency lies far below every elastic one (the first bending is 5.6 Hz): the elastic
/// motion the tip's inertia forces lowers `ω` by about `(ω/ω_bending)²`, 4e-5 at k = 1e-4 and
/// 4e-3 at 1e-2. The second mode must lie more than ten times above the fold's.
///
/// Measured errors: ANCF −3.7e-5 … +6.6e-5 at k = 1e-4; GEBF −6.6e-3 … +6.8e-3 there, a
/// rounding floor that scales with the near-rigid shear (GA = 1e9 N; −1.5e-4 … +3.1e-4 at 1e8,
/// −4e-5 … −8e-5 at 1e7 and 1e6), not the eigensolver's; both −4.2e-3 … −5.7e-3 at k = 1e-2
/// (the elastic lowering).
#[test]
fn fold_mode_of_a_free_flared_hinge_is_sqrt_k_over_j() {
    for f in Formulation::ALL {
        for k in [1e-4, 1e-2] {
            for flare in [0.0, 10.0, 20.0, 30.0] {
                let modes = dispatch(f, RestModes(&free_hinge_wing(flare, k)));
                let expected = (k / free_hinge_tip_inertia(flare)).sqrt();
                let (fold, next) = (modes.omega[0], modes.omega[1]);
                let err = fold / expected - 1.0;
                println!(
                    "{f} k {k:e}, flare {flare}: fold {:.6} Hz, sqrt(k/J) {:.6} Hz, error {err:+.2e}; next {:.3} Hz",
                    fold / std::f64::consts::TAU,
                    expected / std::f64::consts::TAU,
                    next / std::f64::consts::TAU
                );
                assert!(err.abs() < 0.02, "{f} k {k:e}, flare {flare}: fold {fold} rad/s against {expected}");
                assert!(next > 10.0 * expected, "{f} k {k:e}, flare {flare}: second mode {next}");
            }
        }
    }
}
