//! Every Newton iteration of one run: the tool behind the convergence diagnoses in the README
//! (where a formulation spends its iterations and factorisations, and on which unknown).
//!
//! `cargo run --release -p perf --example newton_trace -- <case.json> <ancf|gebf> [path=value ...]`
//!
//! Writes CSV to stdout, one row per Newton solve (failed attempts that were retried in halves
//! included): `t, h, iter, factorized, residual_norm, phi_norm, psi_norm, increment_norm,
//! worst_unknown` (see `genalpha::IterationRecord`; converged at increment_norm ≤ 1, or on the
//! contraction estimate). A summary per quarter of the run goes to stderr. The unknowns are
//! the model's tangent indices: ANCF 12 per node (r, r_x, r_y, r_z) body after body; GEBF per
//! body 6 per node from node 1 (R, ψ), then the frame (v_A, ω_A). Cases without aerodynamics
//! only; overrides as `harness run --set` (e.g. `gebf.newton.broyden=false`).
use anyhow::{Context, Result, bail};
use genalpha::{GenAlpha, IterationRecord};
use harness::case::{CaseFile, Formulation, Override};
use harness::scene::{BuildModel, ForModel, dispatch, settings};

/// One run of a formulation's model with Newton's trace on ([`dispatch`] picks the model type).
struct Trace {
    problem: aeroelastic::Problem,
    run: harness::run::RunSettings,
}

impl ForModel for Trace {
    type Output = Result<Vec<IterationRecord>>;
    fn run<M: BuildModel>(self) -> Self::Output {
        let sys = &mut M::build(&self.problem)?;
        let (params, t_end) = (self.run.params, self.run.t_end);
        let mut ga: GenAlpha<M::Solver> = sys.integrator(params)?;
        let mut s = sys.initial_state();
        ga.initialize(sys, &mut s)?;
        ga.set_trace(true);
        let n_steps = (t_end / params.dt - 1e-9).ceil() as usize;
        for k in 1..=n_steps {
            if let Err(e) = ga.step(sys, &mut s) {
                eprintln!("step {k}: {e}");
                break;
            }
        }
        Ok(ga.take_trace())
    }
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [file, formulation, rest @ ..] = args.as_slice() else {
        bail!("usage: newton_trace <case.json> <ancf|gebf> [path=value ...]");
    };
    let overrides = rest.iter().map(|s| s.parse::<Override>()).collect::<Result<Vec<_>, _>>()?;
    let runs = CaseFile::read(file.as_ref())?.expand(&overrides)?;
    let spec = runs.first().context("the case expands into no run")?;
    let Some(f) = Formulation::from_name(formulation) else {
        bail!("formulation `{formulation}`: expected one of {:?}", Formulation::ALL.map(Formulation::as_str));
    };
    let case = spec.case(f);
    if case.aero.is_some() {
        bail!("{}: cases with aerodynamics are not traced", spec.name);
    }
    let records = dispatch(f, Trace { problem: case.problem(), run: settings(case, f) })?;
    println!("t,h,iter,factorized,residual_norm,phi_norm,psi_norm,increment_norm,worst_unknown");
    for r in &records {
        println!(
            "{:.6},{:.3e},{},{},{:.3e},{:.3e},{:.3e},{:.3e},{}",
            r.t,
            r.h,
            r.iter,
            r.factorized as u8,
            r.residual_norm,
            r.phi_norm,
            r.psi_norm,
            r.increment_norm,
            r.worst_unknown
        );
    }
    // Per quarter of the run: attempts, solves, factorisations, the most frequent worst unknown.
    let quarter = case.t_end / 4.0;
    eprintln!("{} {formulation}: window, attempts, solves, factorisations, most frequent worst unknown", spec.name);
    for q in 0..4 {
        let (a, b) = (q as f64 * quarter, (q + 1) as f64 * quarter);
        let w: Vec<&IterationRecord> = records.iter().filter(|r| r.t > a + 1e-12 && r.t <= b + 1e-12).collect();
        let mut counts = std::collections::BTreeMap::new();
        w.iter().for_each(|r| *counts.entry(r.worst_unknown).or_insert(0usize) += 1);
        let top = counts.iter().max_by_key(|(_, c)| **c).map_or(0, |(u, _)| *u);
        eprintln!(
            "  ({a:.2}, {b:.2}] s: {} attempts, {} solves, {} factorisations, unknown {top}",
            w.iter().filter(|r| r.iter == 1).count(),
            w.len(),
            w.iter().filter(|r| r.factorized).count()
        );
    }
    Ok(())
}
