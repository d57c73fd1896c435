//! The integrator crate's generic linearisation and modes (`genalpha::analysis`) on an ANCF
//! cantilever, against the frequencies of `Model::linear_modes` as they were before that function
//! delegated to the generic code (ANCF reduction basis `B`), and against each
//! other through the model's two integrator forms: the DAE form (joints as holonomic rows,
//! eliminated by an SVD null space) and the ODE form (joints eliminated by the reduction, no
//! constraint rows).
use ancf::{Model, Options, SolvePath, samples};
use genalpha::ConstrainedSystem;
use genalpha::analysis::linearise;
use nalgebra::Vector3;

/// The first ten circular frequencies (rad/s) of the 8-element cantilever below from
/// `Model::linear_modes` on the reduction basis, as computed when it delegated its eigenproblem
/// to the generic code (recomputed for the element of docs/ancf.md §3; a clamped cantilever has
/// no joint ties).
const BEFORE: [f64; 10] = [
    17.579519032596657,
    27.794218534833732,
    110.15609585257795,
    174.1107445531797,
    308.5183072959826,
    487.4321012509978,
    605.3647704440679,
    955.953293987641,
    1003.963419611802,
    1508.5614059566697,
];

/// L = 2 m, 8 elements, the section of `tests/suite/modal.rs`.
fn cantilever(path: SolvePath) -> Model {
    let mut sec = samples::paper_section(1.0);
    (sec.mass, sec.rho_ixx, sec.rho_iyy, sec.rho_izz) = (2.0, 4e-5, 1e-5, 3e-5);
    (sec.ea, sec.ga_y, sec.ga_z, sec.gj, sec.ei_yy, sec.ei_zz) = (4e7, 1.5e7, 1.5e7, 300.0, 800.0, 2000.0);
    let (b, j) = samples::cantilever(sec, 2.0, 8);
    Model::new(&b, &j, Vector3::zeros(), Options { path, ..Options::default() }).unwrap()
}

fn worst_relative(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x / y - 1.0).abs()).fold(0.0, f64::max)
}

/// The attainable relative precision of a low frequency ω from a dense eigensolver is about
/// ε (ω_max/ω)² / 2, here 4.6e-6 for ω₁ (the cross-section penalty modes reach ω_max = 3.6e6
/// rad/s): the old and the new computation agree within it. Measured worst relative differences
/// from before: `linear_modes` 1.7e-7, generic DAE form 1.7e-7, ODE form 8.8e-8, damped
/// (state-space, Schur) 3.3e-7.
#[test]
fn generic_linearisation_matches_linear_modes() {
    let dae = cantilever(SolvePath::Dae);
    let now: Vec<f64> = dae.linear_modes(dae.reference_coordinates()).unwrap().iter().map(|m| m.omega).collect();
    let e_now = worst_relative(&now[..10], &BEFORE);

    // the model as the integrator sees it, in both forms
    let generic = |model: &Model| {
        let q = model.initial_state().q;
        let lambda = vec![0.0; model.n_holonomic()];
        linearise(model, 0.0, &q, &lambda, &[]).unwrap()
    };
    let lin_dae = generic(&dae);
    let ode = cantilever(SolvePath::Ode);
    let lin_ode = generic(&ode);
    assert_eq!(lin_dae.n_free(), ode.n_dof());
    assert_eq!(lin_ode.n_free(), ode.n_dof(), "no constraint rows in the ODE form");
    let w_dae = lin_dae.natural_modes().unwrap().omega;
    let w_ode = lin_ode.natural_modes().unwrap().omega;
    let (e_dae, e_ode) = (worst_relative(&w_dae[..10], &BEFORE), worst_relative(&w_ode[..10], &BEFORE));

    // the first-order (damped) form with C = 0: s = ±iω
    let damped = lin_ode.damped_modes(0).unwrap();
    let w_damped: Vec<f64> = damped.iter().take(10).map(|m| m.damped_frequency()).collect();
    let e_damped = worst_relative(&w_damped, &BEFORE);
    assert!(damped.iter().take(10).all(|m| m.eigenvalue.re.abs() < 1e-6 * m.frequency()));
    println!("highest frequency {:.3e} rad/s", w_dae.last().unwrap());
    println!(
        "worst relative difference from before: linear_modes {e_now:.1e}, DAE {e_dae:.1e}, ODE {e_ode:.1e}, damped {e_damped:.1e}"
    );
    assert!(e_now < 1e-6 && e_dae < 1e-6 && e_ode < 1e-6, "{e_now:e} {e_dae:e} {e_ode:e}");
    assert!(e_damped < 2e-6, "{e_damped:e}");
}
