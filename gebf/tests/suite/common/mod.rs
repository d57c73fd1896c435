//! Shared helpers of the integration tests: reference CSV loading and tip comparisons.
#![allow(dead_code)] // each test file uses a subset

use gebf::{Model, Options, samples, simulate};
use genalpha::IntegratorParams;
use nalgebra::Vector3;
use std::path::PathBuf;

/// Path of a file under `cases/reference/`.
pub fn reference_path(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..").join("cases").join("reference").join(rel)
}

/// (t, tip) rows of a reference CSV (lines starting with `#` are metadata).
pub fn load_tip(rel: &str) -> Vec<(f64, Vector3<f64>)> {
    let text = std::fs::read_to_string(reference_path(rel)).expect("reference file");
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).expect("column");
    let (ct, cx, cy, cz) = (col("t"), col("tip_x"), col("tip_y"), col("tip_z"));
    lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.trim().parse().expect("number")).collect();
            (v[ct], Vector3::new(v[cx], v[cy], v[cz]))
        })
        .collect()
}

/// Linear interpolation of a (t, x) series at `t` (None outside).
pub fn interp(series: &[(f64, Vector3<f64>)], t: f64) -> Option<Vector3<f64>> {
    let i = series.partition_point(|(ti, _)| *ti < t);
    if i == 0 {
        return ((series[0].0 - t).abs() < 1e-12).then_some(series[0].1);
    }
    if i >= series.len() {
        return None;
    }
    let (t0, a) = series[i - 1];
    let (t1, b) = series[i];
    let w = (t - t0) / (t1 - t0);
    Some(a * (1.0 - w) + b * w)
}

/// Max and RMS of |ours(t) − reference(t + shift)| over our samples, m.
pub fn tip_difference(ours: &[(f64, Vector3<f64>)], reference: &[(f64, Vector3<f64>)], shift: f64) -> (f64, f64) {
    let mut max: f64 = 0.0;
    let mut sum = 0.0;
    let mut n = 0;
    for (t, p) in ours {
        if let Some(r) = interp(reference, t + shift) {
            let d = (p - r).norm();
            max = max.max(d);
            sum += d * d;
            n += 1;
        }
    }
    (max, (sum / n.max(1) as f64).sqrt())
}

/// One paper case at the paper's settings (5 elements per body, dt 0.002, 2 s), recording
/// (t, tip), fold angles and the model.
pub struct Run {
    pub tip: Vec<(f64, Vector3<f64>)>,
    pub fold: Vec<f64>,
    pub energy: Vec<gebf::Energies>,
    pub residual: Vec<f64>,
    pub stats: genalpha::Stats,
}

pub fn run_paper_case(c: f64, beta_deg: f64, rho_inf: f64, stabilization: bool) -> Run {
    run_paper_case_dt(c, beta_deg, rho_inf, stabilization, 0.002)
}

/// A paper case (5 elements per body, 2 s) at time step `dt`.
pub fn run_paper_case_dt(c: f64, beta_deg: f64, rho_inf: f64, stabilization: bool, dt: f64) -> Run {
    run_paper_case_with(c, beta_deg, stabilization, IntegratorParams::new(rho_inf, dt))
}

/// A paper case (5 elements per body, 2 s) with the given integrator parameters.
pub fn run_paper_case_with(c: f64, beta_deg: f64, stabilization: bool, params: IntegratorParams) -> Run {
    let (b, j, g) = samples::double_pendulum(c, beta_deg, 5);
    let mut m = Model::new(&b, &j, g, Options { stabilization, ..Options::default() }).unwrap();
    let mut r =
        Run { tip: Vec::new(), fold: Vec::new(), energy: Vec::new(), residual: Vec::new(), stats: Default::default() };
    let (_, stats) = simulate::run(&mut m, params, 2.0, |m, s, _| {
        r.tip.push((s.t, m.tip_position(&s.q)));
        r.fold.push(m.fold_angle(&s.q, 1).unwrap());
        r.energy.push(m.energies(&s.q, &s.v));
        r.residual.push(m.constraint_residual(&s.q));
    })
    .unwrap_or_else(|e| panic!("c = {c}, beta = {beta_deg}: {e}"));
    r.stats = stats;
    r
}
