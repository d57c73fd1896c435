//! The five paper double-pendulum cases at the paper's settings (5 three-node elements per
//! body, dt = 0.002, 2 s, rho_inf = 0.8, default Newton settings), single thread. One iteration
//! is one full run: model set-up, consistent start and 1000 steps, reading the tip sensor every
//! step (energies are not evaluated). Target: median below 100 ms per case.

use criterion::{Criterion, criterion_group, criterion_main};
use gebf::{Model, Options, samples, simulate};
use genalpha::IntegratorParams;
use std::hint::black_box;
use std::time::Duration;

fn run_case(c: f64, beta: f64) -> f64 {
    let (b, j, g) = samples::double_pendulum(c, beta, 5);
    let mut m = Model::new(&b, &j, g, Options::default()).expect("valid case");
    let mut z = 0.0;
    simulate::run(&mut m, IntegratorParams::new(0.8, 0.002), 2.0, |m, s, _| z += m.tip_position(&s.q).z)
        .expect("case reaches 2 s");
    z
}

fn paper_cases(cr: &mut Criterion) {
    let mut group = cr.benchmark_group("gebf_double_pendulum");
    group.sample_size(10).measurement_time(Duration::from_secs(8)).warm_up_time(Duration::from_secs(1));
    for (c, beta) in samples::PAPER_CASES {
        group.bench_function(format!("c{c}_beta{beta}"), |b| b.iter(|| black_box(run_case(c, beta))));
    }
    group.finish();
}

criterion_group!(benches, paper_cases);
criterion_main!(benches);
