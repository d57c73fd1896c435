//! No `n²` buffer for a banded problem: the integrator's dense iteration matrix is allocated only
//! when a matrix has to take the dense path (#19).

use ancf::{Model, Options, Scene, samples};
use genalpha::IntegratorParams;

/// The paper's flared pendulum at 5 and at 200 elements per body: with the model's skyline solver
/// the start and 50 steps never allocate the integrator's dense `n × n` matrix (the skyline
/// storage takes every matrix, the mass matrix of the consistent start included).
#[test]
fn banded_runs_hold_no_dense_matrix() {
    for n_el in [5, 200] {
        let (b, j, g) = samples::double_pendulum(1.0, 45.0, n_el);
        let mut m = Model::from_scene(&Scene::new(b, j, g), Options::default()).unwrap();
        let mut ga = m.integrator(IntegratorParams::new(0.8, 0.002)).unwrap();
        let mut s = m.initial_state();
        ga.initialize(&m, &mut s).unwrap();
        for _ in 0..50 {
            ga.step(&mut m, &mut s).unwrap();
        }
        println!("{n_el} el/body: dense matrix held: {}", ga.holds_dense_matrix());
        assert!(!ga.holds_dense_matrix(), "{n_el} elements per body");
    }
}
