//! The time loop does not allocate: once the wake buffer is full and every work buffer has
//! reached its size, `update_stations` + `step` perform no heap allocation (counting allocator;
//! prescribed and free wake, with a symmetry plane, without and with a disturbance field, with the
//! refined solves of the influence matrix; single thread, and threaded on a rayon pool of two with the wake summed directly and through the
//! treecode).

use uvlm::samples::FlaredWing;
use uvlm::*;

#[test]
fn step_does_not_allocate() {
    for (convection, disturbed, refined) in [
        (WakeConvection::Prescribed, false, false),
        (WakeConvection::Free, false, false),
        (WakeConvection::Prescribed, true, false),
        (WakeConvection::Free, true, false),
        (WakeConvection::Prescribed, false, true),
    ] {
        let wing = FlaredWing { aoa: 5f64.to_radians(), ..FlaredWing::default() };
        let stations: Vec<Vec<SpanStation>> = (0..8).map(|k| wing.stations(0.02 * k as f64)).collect();
        let vel = vec![StationVelocity::default(); stations[0].len()];
        let lat = Lattice::from_stations(wing.spec(), &stations[0]).unwrap();
        let mut p = UvlmParams::new(0.0889, [0.0, -25.0, 0.0]);
        p.parallel = Parallel::Off;
        p.n_wake_rows = 6;
        p.wake_convection = convection;
        p.wake_core = CoreModel::Scully { fraction: 0.1 };
        p.images = vec![ImagePlane::through_origin([1.0, 0.0, 0.0])];
        p.aic_refinement = refined;
        let mut u = Uvlm::new(lat, p).unwrap();
        if disturbed {
            // A travelling vertical gust: evaluated at every point, every step.
            u.set_disturbance(Some(Box::new(|x: [f64; 3], t: f64| [0.0, 0.0, (x[1] + 25.0 * t).sin()])));
        }
        for k in 0..8 {
            u.update_stations(&stations[k % 8], Some(&vel)).unwrap();
            u.step(0.01).unwrap();
        }
        let ((), allocations) = alloc_count::count(|| {
            for k in 0..8 {
                u.update_stations(&stations[7 - k], Some(&vel)).unwrap();
                u.step(0.01).unwrap();
            }
        });
        assert_eq!(
            allocations, 0,
            "{convection:?}, disturbed {disturbed}, refined {refined}: {allocations} allocations in 8 steps"
        );
        if refined {
            assert!(u.stats().n_refined_solves > 0, "{:?}", u.stats());
        }
    }
}

/// The threaded evaluations (blocks of points in chunks, each with its own entry of the solver's
/// workspace) allocate nothing once warm. The counter sees the thread that calls `step` (a
/// worker of the pool, which also runs chunks); the other worker's chunks only use the same
/// workspace entries.
#[test]
fn threaded_step_does_not_allocate() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    for (convection, aggregation) in [
        (WakeConvection::Prescribed, WakeAggregation::off()),
        (WakeConvection::Free, WakeAggregation::off()),
        (WakeConvection::Prescribed, WakeAggregation::treecode()),
        (WakeConvection::Free, WakeAggregation::treecode()),
    ] {
        let wing = FlaredWing { aoa: 5f64.to_radians(), ..FlaredWing::default() };
        let stations: Vec<Vec<SpanStation>> = (0..8).map(|k| wing.stations(0.02 * k as f64)).collect();
        let lat = Lattice::from_stations(wing.spec(), &stations[0]).unwrap();
        let n_col = lat.n_rings();
        let mut p = UvlmParams::new(0.0889, [0.0, -25.0, 0.0]);
        p.parallel = Parallel::Auto;
        p.n_wake_rows = 40;
        p.wake_convection = convection;
        p.wake_aggregation = aggregation;
        p.images = vec![ImagePlane::through_origin([1.0, 0.0, 0.0])];
        let mut u = Uvlm::new(lat, p).unwrap();
        let allocations = pool.install(|| {
            for k in 0..48 {
                u.update_stations(&stations[k % 8], None).unwrap();
                u.step(0.01).unwrap();
            }
            // The wake (40 rows of 32 rings, mirrored: ≥ 5000 filaments) at the collocation
            // points alone is above the threaded threshold of two threads.
            assert!(n_col * 5000 >= 2 * PARALLEL_MIN_PAIRS);
            let ((), allocations) = alloc_count::count(|| {
                for k in 0..8 {
                    u.update_stations(&stations[7 - k], None).unwrap();
                    u.step(0.01).unwrap();
                }
            });
            allocations
        });
        assert_eq!(allocations, 0, "{convection:?}, {aggregation:?}: {allocations} allocations in 8 threaded steps");
    }
}

/// A moving control surface (an aileron on inner stations 16..=22, deflection and rate changing
/// every step) and its hinge moment allocate nothing either.
#[test]
fn flapped_step_does_not_allocate() {
    let wing = FlaredWing { aoa: 5f64.to_radians(), ..FlaredWing::default() };
    let stations: Vec<Vec<SpanStation>> = (0..8)
        .map(|k| {
            let (delta, rate) = (0.1 * (k as f64).sin(), 10.0 * (k as f64).cos());
            let mut st = wing.stations(0.02 * k as f64);
            for s in &mut st[16..=22] {
                s.flap = Some(StationFlap { rate, ..StationFlap::new(0.25, delta) });
            }
            st
        })
        .collect();
    let vel = vec![StationVelocity::default(); stations[0].len()];
    let lat = Lattice::from_stations(wing.spec(), &stations[0]).unwrap();
    let mut p = UvlmParams::new(0.0889, [0.0, -25.0, 0.0]);
    p.parallel = Parallel::Off;
    p.n_wake_rows = 6;
    p.images = vec![ImagePlane::through_origin([1.0, 0.0, 0.0])];
    let mut u = Uvlm::new(lat, p).unwrap();
    for st in &stations {
        u.update_stations(st, Some(&vel)).unwrap();
        u.step(0.01).unwrap();
    }
    let (h, allocations) = alloc_count::count(|| {
        let mut h = 0.0;
        for k in 0..8 {
            u.update_stations(&stations[7 - k], Some(&vel)).unwrap();
            u.step(0.01).unwrap();
            h += u.hinge_moment(16..=22).unwrap();
        }
        h
    });
    assert!(h.is_finite() && h != 0.0);
    assert_eq!(allocations, 0, "{allocations} allocations in 8 flapped steps");
}

/// Two surfaces in one system (the paper's wing and a tail behind it with an elevator), free
/// wake, disturbance, sub-iterated steps with `update_stations_of`, per-surface hinge moments:
/// no allocation once warm.
#[test]
fn two_surface_step_does_not_allocate() {
    let wing = FlaredWing { aoa: 5f64.to_radians(), ..FlaredWing::default() };
    let tail = |k: usize| -> Vec<SpanStation> {
        (0..=4)
            .map(|j| {
                let mut s = wing.stations(0.0)[j];
                s.origin += nalgebra::Vector3::new(0.0, -5.0, 0.5);
                s.flap = Some(StationFlap::new(0.3, 0.05 * (k as f64).sin()));
                s
            })
            .collect()
    };
    let stations: Vec<Vec<SpanStation>> = (0..8).map(|k| wing.stations(0.02 * k as f64)).collect();
    let tails: Vec<Vec<SpanStation>> = (0..8).map(tail).collect();
    let (vw, vt) = (vec![StationVelocity::default(); stations[0].len()], vec![StationVelocity::default(); 5]);
    let lats = vec![
        Lattice::from_stations(wing.spec(), &stations[0]).unwrap(),
        Lattice::from_stations(LatticeSpec::new(4), &tails[0]).unwrap(),
    ];
    let mut p = UvlmParams::new(0.0889, [0.0, -25.0, 0.0]);
    p.parallel = Parallel::Off;
    p.n_wake_rows = 6;
    p.wake_convection = WakeConvection::Free;
    p.wake_core = CoreModel::Scully { fraction: 0.1 };
    p.images = vec![ImagePlane::through_origin([1.0, 0.0, 0.0])];
    let mut u = Uvlm::with_surfaces(lats, p).unwrap();
    u.set_disturbance(Some(Box::new(|x: [f64; 3], t: f64| [0.0, 0.0, (x[1] + 25.0 * t).sin()])));
    let run = |u: &mut Uvlm, k: usize| {
        u.advance_wake(0.01).unwrap();
        for _ in 0..2 {
            u.update_stations_of(0, &stations[k], Some(&vw)).unwrap();
            u.update_stations_of(1, &tails[k], Some(&vt)).unwrap();
            u.solve_step().unwrap();
        }
        u.commit_step().unwrap();
        u.hinge_moment_of(1, 0..=4).unwrap()
    };
    for k in 0..8 {
        run(&mut u, k);
    }
    let (h, allocations) = alloc_count::count(|| (0..8).map(|k| run(&mut u, 7 - k)).sum::<f64>());
    assert!(h.is_finite());
    assert_eq!(allocations, 0, "{allocations} allocations in 8 two-surface steps");
}
