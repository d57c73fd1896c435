//! The external-flow seam: a disturbance field is evaluated where and when the solver needs the
//! free stream, a zero disturbance changes nothing (bit for bit), and a uniform one is a change of
//! free stream.

use approx::assert_relative_eq;
use uvlm::samples::{FlaredWing, SpanSpacing, rectangular_wing};
use uvlm::*;

/// Every number the solver exposes after a step, as bit patterns: Γ, dΓ/dt, nodal and strip
/// loads, total force, wake nodes and circulations, and the velocity at a field point.
fn snapshot(u: &Uvlm) -> Vec<u64> {
    let l = u.loads();
    let w = u.wake();
    let mut s: Vec<u64> = u.gamma().iter().chain(u.gamma_dot()).map(|x| x.to_bits()).collect();
    s.extend(l.nodal.iter().chain(&l.strip).flatten().map(|x| x.to_bits()));
    s.extend(l.total_force().iter().map(|x| x.to_bits()));
    for r in 0..w.n_rows() {
        s.extend((0..=w.n_spanwise()).flat_map(|j| w.node(r, j)).map(|x| x.to_bits()));
        s.extend((0..w.n_spanwise()).map(|j| w.gamma(r, j).to_bits()));
    }
    s.extend(u.velocity_at([3.0, 0.7, 0.2]).map(|x| x.to_bits()));
    s
}

/// The small flared wing used below (6 + 2 spanwise panels, 4 chordwise).
fn small_wing() -> FlaredWing {
    FlaredWing {
        aoa: 5f64.to_radians(),
        n_inner: 6,
        n_outer: 2,
        inner_length: 3.0,
        outer_length: 1.0,
        ..FlaredWing::default()
    }
}

/// Run `n_steps` of a folding, heaving flared wing; every third step is sub-iterated (a solve at
/// a wrong guess first). Calls `check` after each step.
fn run_moving_wing(u: &mut Uvlm, wing: &FlaredWing, n_steps: usize, mut check: impl FnMut(usize, &Uvlm)) {
    for k in 1..=n_steps {
        let fold = 0.3 * (0.4 * k as f64).sin();
        let st = wing.stations(fold);
        let vel =
            vec![
                StationVelocity { linear: [0.0, 0.0, 0.1 * (k as f64).cos()].into(), angular: [0.01, 0.0, 0.0].into() };
                st.len()
            ];
        if k % 3 == 0 {
            u.advance_wake(0.01).unwrap();
            u.update_stations(&wing.stations(fold + 0.05), Some(&vel)).unwrap();
            u.solve_step().unwrap();
            u.update_stations(&st, Some(&vel)).unwrap();
            u.solve_step().unwrap();
            u.commit_step().unwrap();
        } else {
            u.update_stations(&st, Some(&vel)).unwrap();
            u.step(0.01).unwrap();
        }
        check(k, u);
    }
}

/// Parameter variants: prescribed wake; free wake with a Scully wake core and a symmetry plane;
/// wake closure with the trailing-edge segment force.
fn variants() -> Vec<UvlmParams> {
    let base = || {
        let mut p = UvlmParams::new(0.0889, [0.0, -25.0, 0.0]);
        p.parallel = Parallel::Off;
        p.n_wake_rows = 4; // truncation within the run
        p
    };
    let mut free = base();
    free.wake_convection = WakeConvection::Free;
    free.wake_core = CoreModel::Scully { fraction: 0.1 };
    free.images = vec![ImagePlane::through_origin([1.0, 0.0, 0.0])];
    let mut closed = base();
    closed.wake_closure = true;
    closed.te_segment_force = true;
    vec![base(), free, closed]
}

/// (a) A disturbance that is zero everywhere (a `Uniform` zero field, or a closure) gives bitwise
/// the results of no disturbance, step after step: impulsive and prefilled starts, steady solve,
/// sub-iterated steps, wake truncation, all wake variants. (The solver adds `+0.0` to the free
/// stream, which is exact for the non-negative-zero components used here.)
#[test]
fn zero_disturbance_is_bitwise_none() {
    let wing = small_wing();
    for p in variants() {
        for prefill in [false, true] {
            let zeros: [Box<dyn FlowField>; 2] =
                [Box::new(Uniform([0.0; 3])), Box::new(|_x: [f64; 3], t: f64| [0.0, 0.0 * t, 0.0])];
            for zero in zeros {
                let lat = Lattice::from_stations(wing.spec(), &wing.stations(0.0)).unwrap();
                let mut none = Uvlm::new(lat.clone(), p.clone()).unwrap();
                let mut with = Uvlm::new(lat, p.clone()).unwrap();
                with.set_disturbance(Some(zero));
                if prefill {
                    none.solve_steady().unwrap();
                    with.solve_steady().unwrap();
                    assert_eq!(snapshot(&none), snapshot(&with), "steady solve");
                    none.prefill_wake(0.01).unwrap();
                    with.prefill_wake(0.01).unwrap();
                }
                let mut reference = Vec::new();
                run_moving_wing(&mut none, &wing, 8, |_, u| reference.push(snapshot(u)));
                run_moving_wing(&mut with, &wing, 8, |k, u| {
                    assert_eq!(reference[k - 1], snapshot(u), "step {k}, {p:?}, prefill {prefill}");
                });
                assert_eq!(none.time(), with.time());
            }
        }
    }
}

/// (b) A uniform, constant disturbance `w` is a change of free stream: unsteady steps with
/// `V∞ = V`, disturbance `w` match `V∞ = V + w` without one, with the prescribed and the free
/// wake (the wake convects with `V + w` in both, because a prescribed wake follows the external
/// flow). Tolerance 1e-12 relative to the largest value: the two runs form the same sums in the
/// same order (`(V + w) + u_ind`), so they agree bit for bit today; the margin allows a
/// reassociation (round-off 1e-16 per operation, amplified by the AIC's condition number ~1e2
/// and the steps). Not covered, by design: steady solves and the wake closure, whose
/// semi-infinite legs follow the direction of `V∞` only, so there the two runs differ.
#[test]
fn uniform_disturbance_is_a_change_of_free_stream() {
    let wing = small_wing();
    let (v, w) = ([0.0, -25.0, 0.0], [0.4, -0.3, 1.5]);
    let shifted = [v[0] + w[0], v[1] + w[1], v[2] + w[2]];
    for convection in [WakeConvection::Prescribed, WakeConvection::Free] {
        let params = |v_inf| {
            let mut p = UvlmParams::new(0.0889, v_inf);
            p.parallel = Parallel::Off;
            p.n_wake_rows = 6;
            p.wake_convection = convection;
            p.wake_core = CoreModel::Scully { fraction: 0.1 };
            p
        };
        let lat = Lattice::from_stations(wing.spec(), &wing.stations(0.0)).unwrap();
        let mut a = Uvlm::new(lat.clone(), params(shifted)).unwrap();
        let mut b = Uvlm::new(lat, params(v)).unwrap();
        b.set_disturbance(Some(Box::new(Uniform(w))));
        let mut reference = Vec::new();
        run_moving_wing(&mut a, &wing, 10, |_, u| reference.push((u.gamma().to_vec(), u.loads().clone())));
        run_moving_wing(&mut b, &wing, 10, |k, u| {
            let (g, l) = &reference[k - 1];
            let g_max = g.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for (x, y) in g.iter().zip(u.gamma()) {
                assert_relative_eq!(*x, *y, epsilon = 1e-12 * g_max);
            }
            let f_max = l.nodal.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
            for (x, y) in l.nodal.iter().flatten().zip(u.loads().nodal.iter().flatten()) {
                assert_relative_eq!(*x, *y, epsilon = 1e-12 * f_max);
            }
            let (fa, fb) = (l.total_force(), u.loads().total_force());
            for q in 0..3 {
                assert_relative_eq!(fa[q], fb[q], epsilon = 1e-12 * f_max);
            }
        });
    }
}

/// Flat rectangular wing (chord 1, span 4, LE on x = 0, z = 0 plane, 4 × 4 panels), stream
/// along +x at 5° incidence.
fn flat_wing(v_inf: [f64; 3]) -> Uvlm {
    let st = rectangular_wing(0.0, 4.0, 1.0, 4, SpanSpacing::Uniform);
    let lat = Lattice::from_stations(LatticeSpec::new(4), &st).unwrap();
    let mut p = UvlmParams::new(1.2, v_inf);
    p.parallel = Parallel::Off;
    Uvlm::new(lat, p).unwrap()
}

fn stream(alpha_deg: f64) -> [f64; 3] {
    let a = alpha_deg.to_radians();
    [10.0 * a.cos(), 0.0, 10.0 * a.sin()]
}

/// (c) The disturbance is evaluated at each point where the free stream enters. A streamwise
/// gust `u` behind the plane x = 0.5 (mid-chord) on a flat wing is tangent to the wing (d·n = 0
/// exactly), so the circulations are bitwise unchanged, and only the Joukowski force
/// ρΓ(V + d + u_ind − ẋ)×l of the spanwise segments whose *midpoints* lie behind the plane
/// changes (for chordwise segments d × l = 0): lattice node rows 0 and 1 (x = 0.0625, 0.3125; the
/// ring lattice is shifted a quarter panel) and the trailing-edge row 4 (x = 1.0625, no spanwise
/// force) keep their loads bit for bit, rows 2 and 3 (x = 0.5625, 0.8125) gain ρ·u·Γ_s·Δy along
/// z. Checked for a steady solve and for the first (impulsive) unsteady step. (At that step the
/// rings are fore-aft symmetric, Γ_row2 = Γ_row1 up to round-off, so only row 3 visibly changes.)
#[test]
fn disturbance_is_evaluated_at_each_point() {
    let (u_gust, x_plane, rho) = (2.0, 0.5, 1.2);
    for steady in [true, false] {
        let mut calm = flat_wing(stream(5.0));
        let mut gust = flat_wing(stream(5.0));
        gust.set_disturbance(Some(Box::new(
            move |x: [f64; 3], _t: f64| {
                if x[0] > x_plane { [u_gust, 0.0, 0.0] } else { [0.0; 3] }
            },
        )));
        if steady {
            calm.solve_steady().unwrap();
            gust.solve_steady().unwrap();
        } else {
            calm.step(0.025).unwrap();
            gust.step(0.025).unwrap();
        }
        assert_eq!(calm.gamma(), gust.gamma());
        let lat = calm.lattice();
        let (m, n) = (lat.n_chordwise(), lat.n_spanwise());
        let (lc, lg) = (calm.loads(), gust.loads());
        for i in 0..=m {
            for j in 0..=n {
                let k = lat.node_index(i, j);
                let x = lat.ring_nodes()[k][0];
                if i == 2 || i == 3 {
                    assert!(x > x_plane);
                    if steady || i == 3 {
                        assert_ne!(lc.nodal[k][2], lg.nodal[k][2], "node ({i}, {j}) at x = {x}, steady {steady}");
                    }
                } else {
                    assert_eq!(lc.nodal[k], lg.nodal[k], "node ({i}, {j}) at x = {x}, steady {steady}");
                }
            }
        }
        // The increment is exactly the gust's share of the bound-vortex force: per spanwise
        // segment of rows 2 and 3, ρ·u·(Γ_i − Γ_{i−1})·Δy (net strength of the shared edge), which
        // sums over the two rows to ρ·u·Σ_j (Γ_{3,j} − Γ_{1,j})·Δy_j, Δy = 1 m.
        let g = calm.gamma();
        let expected: f64 = (0..n).map(|j| rho * u_gust * (g[lat.ring_index(3, j)] - g[lat.ring_index(1, j)])).sum();
        let got = lg.total_force()[2] - lc.total_force()[2];
        assert_relative_eq!(got.abs(), expected.abs(), max_relative = 1e-12);
        assert!(expected.abs() > 1e-2 * lc.total_force()[2].abs(), "steady {steady}: {expected}");
    }
}

/// (c) … and at the solver's time. An upwash ramp `w = a·t` on the flat wing, clock started at
/// t₀ = 0.3 s: the first step solves at t₀ + dt, so its circulations and loads are those of a
/// constant upwash a·(t₀ + dt); the wake convects with the flow at the start of the step, so the
/// shed row sits at the trailing edge + (V + a·t₀ ẑ)·dt; the clock then reads t₀ + dt.
#[test]
fn disturbance_is_evaluated_at_the_solver_time() {
    let (a, t0, dt) = (4.0, 0.3, 0.025);
    let v = stream(3.0);
    let mut ramp = flat_wing(v);
    ramp.set_time(t0).unwrap();
    ramp.set_disturbance(Some(Box::new(move |_x: [f64; 3], t: f64| [0.0, 0.0, a * t])));
    let te: Vec<[f64; 3]> = {
        let lat = ramp.lattice();
        (0..=lat.n_spanwise()).map(|j| lat.ring_nodes()[lat.node_index(lat.n_chordwise(), j)]).collect()
    };
    ramp.step(dt).unwrap();
    assert_eq!(ramp.time(), t0 + dt);
    let mut steady_upwash = flat_wing(v);
    steady_upwash.set_disturbance(Some(Box::new(Uniform([0.0, 0.0, a * (t0 + dt)]))));
    steady_upwash.step(dt).unwrap();
    assert_eq!(ramp.gamma(), steady_upwash.gamma());
    assert_eq!(ramp.loads().total_force(), steady_upwash.loads().total_force());
    for (j, p) in te.iter().enumerate() {
        let expected = [p[0] + v[0] * dt, p[1] + v[1] * dt, p[2] + (v[2] + a * t0) * dt];
        let got = ramp.wake().node(0, j);
        for q in 0..3 {
            assert_relative_eq!(got[q], expected[q], epsilon = 1e-15);
        }
    }
    // velocity_at reads the flow at the time of the last solve.
    let far = [50.0, 2.0, 30.0];
    assert_relative_eq!(ramp.velocity_at(far)[2], v[2] + a * (t0 + dt), max_relative = 1e-3);
    // The clock is set only between steps.
    ramp.advance_wake(dt).unwrap();
    assert!(matches!(ramp.set_time(0.0), Err(UvlmError::StepOrder { call: "set_time", .. })));
    assert!(matches!(flat_wing(v).set_time(f64::NAN), Err(UvlmError::InvalidParameter { field: "t", .. })));
}
