//! The paper's five double-pendulum cases at the paper's settings (5 elements per body,
//! dt = 0.002 s, 2 s, generalized-α rho_inf = 0.8), each solved on the DAE and the ODE path.
use ancf::{Model, Options, SolvePath, samples};
use criterion::{Criterion, criterion_group, criterion_main};
use genalpha::IntegratorParams;

fn run(c: f64, beta: f64, path: SolvePath) -> f64 {
    let (bodies, joints, g) = samples::double_pendulum(c, beta, 5);
    let mut model = Model::new(&bodies, &joints, g, Options { path, ..Default::default() }).expect("valid case");
    let params = IntegratorParams::new(0.8, 0.002);
    let mut ga = model.integrator(params).expect("valid parameters");
    let mut s = model.initial_state();
    ga.initialize(&model, &mut s).expect("consistent start");
    for _ in 0..1000 {
        ga.step(&mut model, &mut s).expect("step converges");
    }
    model.tip_position(&s.q).z
}

fn bench(cr: &mut Criterion) {
    let mut group = cr.benchmark_group("double_pendulum");
    group.sample_size(10);
    for (c, beta) in samples::PAPER_CASES {
        for path in [SolvePath::Dae, SolvePath::Ode] {
            group.bench_function(format!("c{c}_beta{beta}_{path:?}"), |b| b.iter(|| run(c, beta, path)));
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
