//! Shared helpers of the integration tests: reference data and a recorded run.
#![allow(dead_code)] // each test file uses a different subset

use ancf::{Model, Options, samples};
use genalpha::IntegratorParams;
use nalgebra::Vector3;

/// `(t, tip)` rows of a reference CSV in `cases/reference/` (columns t, tip_x, tip_y, tip_z, …).
pub fn reference(rel_path: &str) -> Vec<(f64, Vector3<f64>)> {
    let path = format!("{}/../cases/reference/{rel_path}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with('t'))
        .map(|l| {
            let v: Vec<f64> = l.split(',').take(4).map(|x| x.trim().parse().expect("a number")).collect();
            (v[0], Vector3::new(v[1], v[2], v[3]))
        })
        .collect()
}

/// Linear interpolation of a reference curve at `t`.
pub fn interpolate(r: &[(f64, Vector3<f64>)], t: f64) -> Vector3<f64> {
    let i = r.partition_point(|p| p.0 <= t).clamp(1, r.len() - 1);
    let (a, b) = (&r[i - 1], &r[i]);
    let w = (t - a.0) / (b.0 - a.0);
    a.1 + (b.1 - a.1) * w
}

/// Integrator settings of these tests: the defaults, including the RADAU5-style convergence
/// estimate. (It once broke the β = 45° runs at c = 1 and c = 0.1 at t ≈ 1.43 s: after a step
/// back to an earlier iterate the increment history was reset so that the contraction ratio
/// read 0 and the estimate accepted an iterate whose next update had just diverged. The
/// estimate now needs two increments of the current sequence; these runs are its regression
/// test.)
pub fn params(rho_inf: f64, dt: f64) -> IntegratorParams {
    IntegratorParams::new(rho_inf, dt)
}

/// One recorded output step.
#[derive(Debug, Clone, Copy)]
pub struct Record {
    pub t: f64,
    pub tip: Vector3<f64>,
    pub fold: f64,
    pub kinetic: f64,
    pub total: f64,
    pub residual: f64,
}

/// Run the paper's double pendulum for 2 s and record every step.
pub fn run_pendulum(c: f64, beta_deg: f64, n_el: usize, dt: f64, rho_inf: f64, options: Options) -> Vec<Record> {
    let (bodies, joints, g) = samples::double_pendulum(c, beta_deg, n_el);
    let mut model = Model::new(&bodies, &joints, g, options).expect("valid scene");
    let mut ga = model.integrator(params(rho_inf, dt)).expect("valid parameters");
    let mut s = model.initial_state();
    ga.initialize(&model, &mut s).expect("consistent start");
    let n = (2.0 / dt).round() as usize;
    let mut out = Vec::with_capacity(n + 1);
    let record = |model: &Model, s: &genalpha::State| {
        let e = model.energies(&s.q, &s.v);
        Record {
            t: s.t,
            tip: model.tip_position(&s.q),
            fold: model.fold_angle(&s.q, 1).expect("joint 1 is a flared hinge"),
            kinetic: e.kinetic,
            total: e.total(),
            residual: model.constraint_residual(&s.q),
        }
    };
    out.push(record(&model, &s));
    for _ in 0..n {
        ga.step(&mut model, &mut s).unwrap_or_else(|e| panic!("c {c} beta {beta_deg}: {e}"));
        out.push(record(&model, &s));
    }
    out
}

/// Largest tip distance from a reference curve (interpolated at the run's times, shifted by
/// `shift` s), with the time it occurs.
pub fn max_tip_error(run: &[Record], reference: &[(f64, Vector3<f64>)], shift: f64) -> (f64, f64) {
    run.iter()
        .filter(|r| r.t - shift >= 0.0 && r.t - shift <= reference.last().expect("non-empty").0)
        .map(|r| ((r.tip - interpolate(reference, r.t - shift)).norm(), r.t))
        .fold((0.0, 0.0), |m, x| if x.0 > m.0 { x } else { m })
}

/// Energy drift max |E − E(0)| over the run, divided by its peak kinetic energy.
pub fn energy_drift(run: &[Record]) -> f64 {
    let e0 = run[0].total;
    let t_max = run.iter().map(|r| r.kinetic).fold(0.0, f64::max);
    run.iter().map(|r| (r.total - e0).abs()).fold(0.0, f64::max) / t_max
}
