//! The linear UVLM of several lifting surfaces (docs/uvlm.md §13, §16): two half-wings meeting
//! at the root linearise to the one surface across the plane of symmetry (every matrix, the
//! moved-lattice evaluation, the gust input and the wake nodes' derivatives, through the ring
//! and node maps); a wing and a tail in its wake reproduce the time march's response to a
//! harmonic pitch of the wing, the tail's lift (which only the wing's wake and bound vortices
//! move) included; the stacked numbering and its errors.

use nalgebra::{Complex, DMatrix, DVector, Rotation3, Vector3};
use uvlm::samples::{SpanSpacing, rectangular_wing};
use uvlm::*;

type C = Complex<f64>;

/// Largest |a − b| over the largest |a|.
#[track_caller]
fn rel(a: &DMatrix<C>, b: &DMatrix<C>) -> f64 {
    assert_eq!(a.shape(), b.shape());
    let scale = a.iter().fold(0.0f64, |m, z| m.max(z.norm()));
    a.iter().zip(b.iter()).fold(0.0f64, |m, (x, y)| m.max((x - y).norm())) / scale
}

fn complex(m: &DMatrix<f64>) -> DMatrix<C> {
    m.map(C::from)
}

fn column(v: &[f64]) -> DMatrix<C> {
    DMatrix::from_iterator(v.len(), 1, v.iter().map(|x| C::from(*x)))
}

/// Stations pitched by `al` about the quarter chord (x = 0.25) and plunged by `h` (up), with the
/// velocities `(al_dot, h_dot)` (stream along +x, span along y).
fn moved(base: &[SpanStation], al: f64, h: f64, al_dot: f64, h_dot: f64) -> (Vec<SpanStation>, Vec<StationVelocity>) {
    let r = Rotation3::from_axis_angle(&Vector3::y_axis(), al);
    let st: Vec<SpanStation> = base
        .iter()
        .map(|s| {
            let qc = Vector3::new(0.25, s.origin.y, s.origin.z);
            SpanStation {
                origin: qc + r * (s.origin - qc) + Vector3::new(0.0, 0.0, h),
                frame: r.matrix() * s.frame,
                ..*s
            }
        })
        .collect();
    let om = Vector3::new(0.0, al_dot, 0.0);
    let vel = st
        .iter()
        .map(|s| StationVelocity {
            linear: om.cross(&(s.origin - Vector3::new(0.25, s.origin.y, s.origin.z))) + Vector3::new(0.0, 0.0, h_dot),
            angular: om,
        })
        .collect();
    (st, vel)
}

/// The maps from the two half-wings' stacked numbering (b) to the one surface's (a): rings
/// `Π` (n_rings × n_rings, `x_b = Π x_a`), nodal forces `P` (3·n_nodes,a × 3·n_nodes,b, summing
/// the two root nodes), trailing-edge node coordinates `T` (3·n_te,b × 3·n_te,a, a root node of
/// (a) moves both root nodes of (b)).
struct Maps {
    pi: DMatrix<C>,
    p: DMatrix<C>,
    t: DMatrix<C>,
}

fn maps(nh: usize, nc: usize) -> Maps {
    let n = 2 * nh;
    let nr = nc * n;
    let mut pi = DMatrix::zeros(nr, nr);
    for i in 0..nc {
        for j in 0..n {
            let rb = if j < nh { i * nh + j } else { nc * nh + i * nh + j - nh };
            pi[(rb, i * n + j)] = C::from(1.0);
        }
    }
    // Node (i, j') of a half-wing: left j = j', right j = nh + j'.
    let (nn_a, nn_h) = ((nc + 1) * (n + 1), (nc + 1) * (nh + 1));
    let mut p = DMatrix::zeros(3 * nn_a, 6 * nn_h);
    for (s, j0) in [(0, 0), (1, nh)] {
        for i in 0..=nc {
            for jj in 0..=nh {
                let (a, b) = (i * (n + 1) + j0 + jj, s * nn_h + i * (nh + 1) + jj);
                for c in 0..3 {
                    p[(3 * a + c, 3 * b + c)] = C::from(1.0);
                }
            }
        }
    }
    let mut t = DMatrix::zeros(6 * (nh + 1), 3 * (n + 1));
    for (s, j0) in [(0, 0), (1, nh)] {
        for jj in 0..=nh {
            for c in 0..3 {
                t[(3 * (s * (nh + 1) + jj) + c, 3 * (j0 + jj) + c)] = C::from(1.0);
            }
        }
    }
    Maps { pi, p, t }
}

/// The gust response of `lin` at `s`: the nodal forces per unit gust velocity, circulations
/// free (`δΓ = −N(s)⁻¹ r_gust`).
fn gust_forces(lin: &LinearUvlm, g: &LinearGust, s: C) -> DMatrix<C> {
    let r = DVector::from_vec(g.normalwash_at(s));
    let dgamma = -lin.normalwash_matrix(s).lu().solve(&r).unwrap();
    let f = lin.force_matrix(s) * dgamma + DVector::from_vec(g.force_at(s));
    DMatrix::from_column_slice(f.len(), 1, f.as_slice())
}

/// Two half-wings meeting at the root, linearised, equal the one surface across the plane of
/// symmetry linearised, through the ring and node maps, to 1e-10 of the largest entry: the
/// transfer matrices `A + Σ e^{−sτ}W E` and `F_Γ + sF_Γ̇ + Σ e^{−sτ}F E` at four complex `s`,
/// the reference forces, a moved lattice's residual and forces (pitch, plunge and their rates),
/// the gust input and the full gust response (circulations free) at those `s`, and the wake
/// nodes' derivatives (a root wake node of the one surface is the two half-wings' root nodes
/// moved together; 1e-8: a central difference of step 1e-5 of a row, whose round-off is
/// ε/1e-5 of the induced velocity). Without and with the trailing-edge segment's force and the
/// wake closure; AR-8 rectangular wing, 2 × 6 strips (cosine), 4 chordwise, α = 5°, a Scully
/// wake core, 12 rows of a quarter chord. Why they agree: docs/uvlm.md §16 (coincident root
/// filaments; only the order of the sums differs).
#[test]
fn two_half_wings_linearise_to_one_surface() {
    let (nh, nc) = (6, 4);
    let alpha = 5f64.to_radians();
    let half = rectangular_wing(0.0, 4.0, 1.0, nh, SpanSpacing::Cosine);
    let mut full: Vec<SpanStation> = half[1..]
        .iter()
        .rev()
        .map(|s| SpanStation { origin: [s.origin.x, -s.origin.y, s.origin.z].into(), ..*s })
        .collect();
    full.extend_from_slice(&half);
    let spec = LatticeSpec::new(nc);
    let lat = |st: &[SpanStation]| Lattice::from_stations(spec, st).unwrap();
    let m = maps(nh, nc);
    let (pi, pt) = (&m.pi, m.pi.transpose());
    for te_force in [false, true] {
        let mut p = UvlmParams::new(1.2, [10.0 * alpha.cos(), 0.0, 10.0 * alpha.sin()]);
        p.wake_core = CoreModel::Scully { fraction: 0.1 };
        p.te_segment_force = te_force;
        let wake = LinearWake::uniform(12, 0.25, te_force);
        let a = Uvlm::new(lat(&full), p.clone()).unwrap().linearise(&wake).unwrap();
        let b = Uvlm::with_surfaces(vec![lat(&full[..=nh]), lat(&full[nh..])], p).unwrap().linearise(&wake).unwrap();
        let what = format!("te_segment_force {te_force}");
        assert_eq!((b.n_surfaces(), b.n_rings(), b.n_te_nodes()), (2, a.n_rings(), a.n_te_nodes() + 1));
        let mut worst = std::collections::BTreeMap::<&str, f64>::new();
        let mut check = |x: f64, tol: f64, name: &'static str| {
            assert!(x < tol, "{what}: {name} differs by {x:.2e}");
            let w = worst.entry(name).or_insert(0.0);
            *w = w.max(x);
        };
        check(rel(&column(&a.reference_forces), &(&m.p * column(&b.reference_forces))), 1e-10, "reference forces");
        let g = [0.0, 0.3, 1.0];
        let (ga, gb) = (a.gust(g, [-1.0, 0.0, 0.0]).unwrap(), b.gust(g, [-1.0, 0.0, 0.0]).unwrap());
        for s in [C::new(0.0, 0.0), C::new(0.0, 2.0), C::new(-0.5, 6.0), C::new(1.0, 20.0)] {
            check(rel(&a.normalwash_matrix(s), &(&pt * b.normalwash_matrix(s) * pi)), 1e-10, "normalwash matrix");
            check(rel(&a.force_matrix(s), &(&m.p * b.force_matrix(s) * pi)), 1e-10, "force matrix");
            let gna = DMatrix::from_vec(a.n_rings(), 1, ga.normalwash_at(s));
            let gnb = DMatrix::from_vec(b.n_rings(), 1, gb.normalwash_at(s));
            check(rel(&gna, &(&pt * gnb)), 1e-10, "gust normalwash");
            let gfa = DMatrix::from_vec(a.n_force(), 1, ga.force_at(s));
            let gfb = DMatrix::from_vec(b.n_force(), 1, gb.force_at(s));
            check(rel(&gfa, &(&m.p * gfb)), 1e-10, "gust force input");
            check(rel(&gust_forces(&a, &ga, s), &(&m.p * gust_forces(&b, &gb, s))), 1e-10, "gust response");
        }
        // A moved lattice: pitch, plunge and their rates.
        let (st, vel) = moved(&full, 0.01, 0.02, 0.3, -0.2);
        let mut la = a.lattice().clone();
        la.update_stations(&st, Some(&vel)).unwrap();
        let (ra, fa) = a.evaluate(&la).unwrap();
        // (b)'s stations: the left half's, then the right half's (the root station twice).
        let mut lb = b.lattices().to_vec();
        let (st_b, vel_b) = ([&st[..=nh], &st[nh..]].concat(), [&vel[..=nh], &vel[nh..]].concat());
        b.move_lattices(&mut lb, &st_b, Some(&vel_b)).unwrap();
        let (rb, fb) = b.evaluate_surfaces(&lb).unwrap();
        check(rel(&column(&ra), &(&pt * column(&rb))), 1e-10, "moved residual");
        check(rel(&column(&fa), &(&m.p * column(&fb))), 1e-10, "moved forces");
        let (wa, wb) = (a.wake_node_derivatives(), b.wake_node_derivatives());
        for k in 0..wa.residual.len() {
            let (zra, zrb) = (complex(&wa.residual[k]), complex(&wb.residual[k]));
            check(rel(&zra, &(&pt * zrb * &m.t)), 1e-8, "wake node residual");
            let (zfa, zfb) = (complex(&wa.force[k]), complex(&wb.force[k]));
            check(rel(&zfa, &(&m.p * zfb * &m.t)), 1e-8, "wake node forces");
        }
        for (name, x) in worst {
            println!("{what}: {name}: largest relative difference {x:.1e}");
        }
    }
}

/// The half wing and the tail of [`wing_and_tail_match_time_marching`]: stations, lattices and
/// parameters.
struct WingTail {
    wing: Vec<SpanStation>,
    tail: Vec<SpanStation>,
    lats: Vec<Lattice>,
    params: UvlmParams,
}

/// AR-8 rectangular half wing (chord 1, 8 strips clustered at the tip, 4 chordwise, leading edge
/// on x = 0) and a rectangular tail (chord 0.5, half span 1.5, 4 × 4) whose leading edge is 3
/// chords behind the wing's, 0.1 chord above the wing's wake sheet (along the free stream from the
/// root trailing edge); α = 3° on both (free stream tilted), U = ρ = 1, a symmetry plane, `rows`
/// wake rows of U·dt = 0.25 shed by each surface.
fn wing_tail(rows: usize, te_segment_force: bool) -> WingTail {
    wing_tail_at(rows, te_segment_force, 3.0, 0.1)
}

fn wing_tail_at(rows: usize, te_segment_force: bool, alpha_deg: f64, h: f64) -> WingTail {
    let alpha = alpha_deg.to_radians();
    let wing = rectangular_wing(0.0, 4.0, 1.0, 8, SpanSpacing::HalfCosine);
    let z_tail = (3.0 - 1.0) * alpha.tan() + h;
    let tail: Vec<SpanStation> = rectangular_wing(0.0, 1.5, 0.5, 4, SpanSpacing::Uniform)
        .into_iter()
        .map(|s| SpanStation { origin: s.origin + Vector3::new(3.0, 0.0, z_tail), ..s })
        .collect();
    let spec = LatticeSpec::new(4);
    let lats = vec![Lattice::from_stations(spec, &wing).unwrap(), Lattice::from_stations(spec, &tail).unwrap()];
    let mut params = UvlmParams::new(1.0, [alpha.cos(), 0.0, alpha.sin()]);
    params.images = vec![ImagePlane::through_origin([0.0, 1.0, 0.0])];
    params.n_wake_rows = rows;
    params.te_segment_force = te_segment_force;
    WingTail { wing, tail, lats, params }
}

/// The linear model's lift (z force) of each surface per unit pitch of the wing about its
/// quarter chord at `s`: the geometric and rate terms of the moved wing (central differences of
/// `evaluate_surfaces`, the tail held), and the wake nodes following the trailing edges' past
/// motion (`Σ_k e^{−sτ_k} Z_k X_te`, node (k, t) where trailing-edge node t was τ_k ago, as the
/// time march sheds them: the steady wake carries Γ₀ here).
struct LinearPitch {
    lin: LinearUvlm,
    rx: DVector<f64>,
    rv: DVector<f64>,
    fx: DVector<f64>,
    fv: DVector<f64>,
    wake_r: Vec<DVector<f64>>,
    wake_f: Vec<DVector<f64>>,
}

impl LinearPitch {
    fn new(wt: &WingTail, lin: LinearUvlm) -> Self {
        let eval = |al: f64, ad: f64| {
            let mut lats = lin.lattices().to_vec();
            let (st, vel) = moved(&wt.wing, al, 0.0, ad, 0.0);
            lats[0].update_stations(&st, Some(&vel)).unwrap();
            let (r, f) = lin.evaluate_surfaces(&lats).unwrap();
            let te: Vec<f64> = lats.iter().flat_map(|l| l.trailing_edge_nodes()).flatten().copied().collect();
            (DVector::from_vec(r), DVector::from_vec(f), DVector::from_vec(te))
        };
        let e = 1e-6;
        let ((r1, f1, t1), (r2, f2, t2)) = (eval(e, 0.0), eval(-e, 0.0));
        let (rx, fx, xte) = ((r1 - r2) / (2.0 * e), (f1 - f2) / (2.0 * e), (t1 - t2) / (2.0 * e));
        let ((r1, f1, _), (r2, f2, _)) = (eval(0.0, 1.0), eval(0.0, -1.0));
        let (rv, fv) = ((r1 - r2) * 0.5, (f1 - f2) * 0.5);
        let wd = lin.wake_node_derivatives();
        let wake_r = wd.residual.iter().map(|z| z * &xte).collect();
        let wake_f = wd.force.iter().map(|z| z * &xte).collect();
        Self { lin, rx, rv, fx, fv, wake_r, wake_f }
    }

    /// Lift (z force) of each surface per unit pitch at `s`, the circulations' rate in the
    /// unsteady load term at `s_rate` (`s` for the continuous model).
    fn lift(&self, s: C, s_rate: C) -> [C; 2] {
        let lin = &self.lin;
        let mut rhs: DVector<C> = self.rx.map(C::from) + self.rv.map(|x| s * x);
        let mut f: DVector<C> = self.fx.map(C::from) + self.fv.map(|x| s * x);
        for ((zr, zf), tau) in self.wake_r.iter().zip(&self.wake_f).zip(&lin.row_delays) {
            let e = (-s * tau).exp();
            rhs += zr.map(|x| e * x);
            f += zf.map(|x| e * x);
        }
        let dgamma = -lin.normalwash_matrix(s).lu().solve(&rhs).unwrap();
        let rate = lin.force_gamma_dot.map(|x| (s_rate - s) * x);
        f += (lin.force_matrix(s) + rate) * dgamma;
        [0, 1].map(|k| lin.blocks()[k].forces().skip(2).step_by(3).map(|i| f[i]).sum())
    }
}

/// The first harmonic of each surface's lift (z force) per unit pitch amplitude `da` of the
/// wing, marched with steps `dt` (a whole number per cycle) from the steady state (its finite
/// wake prefilled) over six cycles at reduced frequency `k` (b = ½), the last cycle analysed.
fn marched_lift(wt: &WingTail, k: f64, da: f64, dt: f64) -> [C; 2] {
    let mut u = Uvlm::with_surfaces(wt.lats.clone(), wt.params.clone()).unwrap();
    u.set_steady_wake(SteadyWake::Finite { length: wt.params.n_wake_rows as f64 * dt }).unwrap();
    u.solve_steady().unwrap();
    u.prefill_wake(dt).unwrap();
    let om = k / 0.5;
    // `dt` divides the period.
    let n_per = (2.0 * std::f64::consts::PI / om / dt).round() as usize;
    let mut acc = [C::new(0.0, 0.0); 2];
    for n in 1..=6 * n_per {
        let t = n as f64 * dt;
        let (st, vel) = moved(&wt.wing, da * (om * t).sin(), 0.0, da * om * (om * t).cos(), 0.0);
        u.update_stations_of(0, &st, Some(&vel)).unwrap();
        u.step(dt).unwrap();
        if n > 5 * n_per {
            for (s, a) in acc.iter_mut().enumerate() {
                let l = u.surface(s).unwrap().loads().total_force()[2];
                *a += C::new(2.0 * l * (om * t).sin(), 2.0 * l * (om * t).cos()) / n_per as f64;
            }
        }
    }
    acc.map(|a| a / da)
}

/// A wing and a tail in its wake: the linear model of the two surfaces is the time-marching
/// scheme's linearisation. Harmonic pitch of the wing about its quarter chord (amplitude 1e-4
/// rad, the tail held) about a loaded steady state (α = 3°), at k = 0.1, 0.3, 0.5, about four
/// steps per chord of travel (dt ≈ the wing's panel length / U, a whole number of steps per
/// cycle, and the linear wake's rows U·dt long to match). The first harmonic of the wing's lift
/// and of the tail's lift (which only the wing's wake and bound vortices move), as complex
/// ratios to the marched ones:
/// - with the rate of the unsteady load term ρ·A·n·dΓ/dt taken as the march takes it (the
///   second-order backward difference, symbol `(3 − 4z⁻¹ + z⁻²)/(2dt)`, `z = e^{s dt}`), the
///   linear model is the march's exact linearisation: within 1e-6 at every k (measured
///   7e-10 – 1.7e-7; at 1e-3 rad 3e-8 – 3e-6, the march's nonlinearity growing as the square
///   of the amplitude). The wake nodes' motion (`wake_node_derivatives`, the steady wake carrying Γ₀)
///   matters at that level: without it the wing's lift is 4e-4 off at k = 0.1;
/// - with the continuous `s` (the model the flutter and gust analyses use), within 0.5 % at
///   k ≤ 0.3 as the one-surface `linear_matches_time_marching` (measured: wing 0.014 / 0.36 %,
///   tail 0.007 / 0.19 %; 1.5 % and 0.9 % at k = 0.5): the backward difference's
///   (ω dt)²/3 on the apparent-mass term.
///
/// Without and with the trailing-edge segment's force. The wake rows must be the march's
/// U·dt: rows of 0.25 against a march at dt = 0.2493 put the wing's trailing vortex rows
/// 0.3 % of their distance elsewhere, which cost the tail, 0.1 chord above the sheet, 1 % of
/// its lift at k = 0.1.
#[test]
fn wing_and_tail_match_time_marching() {
    rayon::join(|| wing_and_tail_with(false), || wing_and_tail_with(true));
}

fn wing_and_tail_with(te_segment_force: bool) {
    let rows = 48;
    let wt = wing_tail(rows, te_segment_force);
    for k in [0.1, 0.3, 0.5] {
        let om = k / 0.5;
        let n_per = (2.0 * std::f64::consts::PI / om / 0.25).round() as usize;
        let dt = 2.0 * std::f64::consts::PI / om / n_per as f64;
        let mut u = Uvlm::with_surfaces(wt.lats.clone(), wt.params.clone()).unwrap();
        let lp = LinearPitch::new(&wt, u.linearise(&LinearWake::uniform(rows, dt, false)).unwrap());
        let s = C::new(0.0, om);
        let z = (s * dt).exp();
        let bdf2 = (3.0 - 4.0 / z + 1.0 / (z * z)) / (2.0 * dt);
        let (lc, ld) = (lp.lift(s, s), lp.lift(s, bdf2));
        let lm = marched_lift(&wt, k, 1e-4, dt);
        for (i, name) in [(0, "wing"), (1, "tail")] {
            let (ec, ed) = ((lc[i] / lm[i] - 1.0).norm(), (ld[i] / lm[i] - 1.0).norm());
            println!(
                "TE force {te_segment_force}, k = {k}: {name} lift marching {:.5}, linear |ratio − 1| {ec:.2e}, with the march's rate {ed:.2e}",
                lm[i]
            );
            assert!(ed < 1e-6, "TE force {te_segment_force}, k = {k}, {name}: {} vs {}", ld[i], lm[i]);
            if k <= 0.3 {
                assert!(ec < 5e-3, "TE force {te_segment_force}, k = {k}, {name}: {} vs {}", lc[i], lm[i]);
            }
        }
    }
}

/// The stacked numbering of a wing and a tail: each surface's block, the global trailing-edge
/// rings, the reference state as `evaluate_surfaces` of the reference lattices (bit for bit: the
/// same sets, points and sums), the blocks of the transfer and gust matrices; and the errors as
/// values (an unknown surface, the one-surface `evaluate` on two, a wrong number or shape of
/// lattices, a moving lattice of either surface).
#[test]
fn stacked_numbering_and_errors() {
    let wt = wing_tail(6, true);
    let mut u = Uvlm::with_surfaces(wt.lats.clone(), wt.params.clone()).unwrap();
    let lin = u.linearise(&LinearWake::uniform(6, 0.25, false)).unwrap();
    // Wing 8 × 4 rings, 9 × 5 nodes; tail 4 × 4 rings, 5 × 5 nodes; load segments per surface
    // M·N + M·(N + 1) + N (the trailing-edge segments carry loads here).
    let expect = [
        SurfaceBlock { rings: 0..32, nodes: 0..45, te_columns: 0..8, te_nodes: 0..9, midpoints: 0..76 },
        SurfaceBlock { rings: 32..48, nodes: 45..70, te_columns: 8..12, te_nodes: 9..14, midpoints: 76..116 },
    ];
    assert_eq!(lin.blocks(), &expect);
    assert_eq!(lin.block(1).unwrap(), &expect[1]);
    assert_eq!(lin.block(2).unwrap_err(), UvlmError::UnknownSurface { surface: 2, n_surfaces: 2 });
    assert_eq!(expect[1].forces(), 135..210);
    assert_eq!((lin.n_surfaces(), lin.n_rings(), lin.n_force(), lin.n_te_nodes()), (2, 48, 210, 14));
    for (b, s) in lin.blocks().iter().zip(u.surfaces()) {
        assert_eq!(b.rings, s.rings());
    }
    let te: Vec<usize> = (0..8).map(|j| 24 + j).chain((0..4).map(|j| 32 + 12 + j)).collect();
    assert_eq!(lin.te_rings, te);
    assert_eq!(lin.gamma0(), u.gamma());
    let (r, f) = lin.evaluate_surfaces(lin.lattices()).unwrap();
    assert_eq!((r, f), (lin.reference_residual.clone(), lin.reference_forces.clone()));
    let s = C::new(0.1, 1.0);
    assert_eq!(lin.normalwash_matrix(s).shape(), (48, 48));
    assert_eq!(lin.force_matrix(s).shape(), (210, 48));
    assert!(lin.row_normalwash.iter().chain(&lin.force_row).all(|m| m.ncols() == 12));
    let g = lin.gust([0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]).unwrap();
    assert_eq!((g.force.shape(), g.midpoint_delays.len(), g.normalwash.len()), ((210, 116), 116, 48));
    // A tail midpoint loads the tail only.
    assert!(g.force.view((0, 76), (135, 40)).iter().all(|x| *x == 0.0));
    assert!(g.force.view((135, 76), (75, 40)).iter().any(|x| *x != 0.0));
    let wd = lin.wake_node_derivatives();
    assert_eq!((wd.residual.len(), wd.residual[0].shape(), wd.force[0].shape()), (6, (48, 42), (210, 42)));
    // Errors.
    let wing_lat = lin.lattice().clone();
    assert_eq!(lin.evaluate(&wing_lat).unwrap_err(), UvlmError::SeveralSurfaces { call: "evaluate", n_surfaces: 2 });
    assert_eq!(
        lin.evaluate_surfaces(std::slice::from_ref(&wing_lat)).unwrap_err(),
        UvlmError::LengthMismatch { what: "lattices", expected: 2, got: 1 }
    );
    assert_eq!(
        lin.evaluate_surfaces(&[wing_lat.clone(), wing_lat]).unwrap_err(),
        UvlmError::InSurface {
            surface: 1,
            source: Box::new(UvlmError::LengthMismatch { what: "lattice rings", expected: 16, got: 32 })
        }
    );
    let mut lats = lin.lattices().to_vec();
    let both = [wt.wing.clone(), wt.tail.clone()].concat();
    assert_eq!(
        lin.move_lattices(&mut lats, &both[1..], None).unwrap_err(),
        UvlmError::LengthMismatch { what: "stations", expected: 14, got: 13 }
    );
    assert_eq!(
        lin.move_lattices(&mut lats, &both, Some(&[StationVelocity::default(); 9])).unwrap_err(),
        UvlmError::LengthMismatch { what: "station velocities", expected: 14, got: 9 }
    );
    let mut bad = both.clone();
    bad[11].chord = -1.0;
    assert!(matches!(lin.move_lattices(&mut lats, &bad, None), Err(UvlmError::InSurface { surface: 1, .. })));
    lin.move_lattices(&mut lats, &both, None).unwrap();
    assert_eq!(lin.evaluate_surfaces(&lats).unwrap().1, lin.reference_forces);
    // The tail (the second surface) moving.
    let vel = vec![StationVelocity { linear: [0.0, 0.0, 0.1].into(), ..Default::default() }; 5];
    u.update_stations_of(1, &wt.tail, Some(&vel)).unwrap();
    let moving = u.linearise(&LinearWake::uniform(6, 0.25, false)).unwrap_err();
    assert_eq!(moving, UvlmError::InvalidParameter { field: "lattice velocity", value: 1.0 });
}

/// Each surface's lift (z force) per unit gust velocity of the linear model at `s` (the
/// unsteady load term's rate at `s_rate`): the gust input of every surface (`LinearUvlm::gust`,
/// each point delayed behind the front) and the wakes' drift with the gust (node (k, t) left
/// trailing-edge node t τ_k ago and has since moved τ_k·w·d with the gust it travels with, so
/// its displacement is `τ_k d ŵ e^{−s(τ_k + τ_t)}`, τ_t the trailing-edge node's own delay).
fn gust_lift(lin: &LinearUvlm, d: [f64; 3], front: [f64; 3], s: C, s_rate: C) -> [C; 2] {
    let g = lin.gust(d, front).unwrap();
    let wd = lin.wake_node_derivatives();
    let v = lin.params().v_inf;
    let u = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let te_delay: Vec<f64> = lin
        .lattices()
        .iter()
        .flat_map(|l| l.trailing_edge_nodes())
        .map(|x| (0..3).map(|q| v[q] / u * (x[q] - front[q])).sum::<f64>() / u)
        .collect();
    let mut rhs = DVector::from_vec(g.normalwash_at(s));
    let mut f = DVector::from_vec(g.force_at(s));
    for (k, &tau) in lin.row_delays.iter().enumerate() {
        for (t, &te_tau) in te_delay.iter().enumerate() {
            let c = (-s * (tau + te_tau)).exp() * tau;
            for (a, &da) in d.iter().enumerate() {
                rhs += wd.residual[k].column(3 * t + a).map(|x| c * da * x);
                f += wd.force[k].column(3 * t + a).map(|x| c * da * x);
            }
        }
    }
    let dgamma = -lin.normalwash_matrix(s).lu().solve(&rhs).unwrap();
    let rate = lin.force_gamma_dot.map(|x| (s_rate - s) * x);
    f += (lin.force_matrix(s) + rate) * dgamma;
    [0, 1].map(|k| lin.blocks()[k].forces().skip(2).step_by(3).map(|i| f[i]).sum())
}

/// The wing and tail of [`wing_and_tail_match_time_marching`] in a sinusoidal vertical gust
/// filling all space, convected with the free stream (reaching the tail about three chords
/// after the wing), marched from the steady state with steps `dt` dividing the period, and the
/// linear model with the same wake rows: the first harmonic of each surface's lift per unit
/// gust velocity. With the march's backward-difference rate in the unsteady load term the two
/// agree within 1e-6 at k = 0.1 and 0.3 (measured 2e-9 – 1.1e-7 at a gust of 1e-4 U; the rest
/// is the march's nonlinearity, it grows as the gust's square: 1e-5 at 1e-3 U); with the
/// continuous `s` within 0.5 % (measured: wing 0.014 / 0.35 %, tail 0.007 / 0.19 %). Without the
/// wakes' drift with the gust the wing's lift would be 5e-4 off at k = 0.1.
#[test]
fn wing_and_tail_gust_response_matches_time_marching() {
    let rows = 48;
    let wt = wing_tail(rows, false);
    let (d, front, w0) = ([0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], 1e-4);
    for k in [0.1, 0.3] {
        let om = k / 0.5;
        let n_per = (2.0 * std::f64::consts::PI / om / 0.25).round() as usize;
        let dt = 2.0 * std::f64::consts::PI / om / n_per as f64;
        let mut u = Uvlm::with_surfaces(wt.lats.clone(), wt.params.clone()).unwrap();
        let lin = u.linearise(&LinearWake::uniform(rows, dt, false)).unwrap();
        let s = C::new(0.0, om);
        let z = (s * dt).exp();
        let bdf2 = (3.0 - 4.0 / z + 1.0 / (z * z)) / (2.0 * dt);
        let (lc, ld) = (gust_lift(&lin, d, front, s, s), gust_lift(&lin, d, front, s, bdf2));
        // The march: steady state, its wake prefilled, then the gust.
        let p = &wt.params;
        u.set_steady_wake(SteadyWake::Finite { length: rows as f64 * dt }).unwrap();
        u.solve_steady().unwrap();
        u.prefill_wake(dt).unwrap();
        let conv = gust::Convection::new(p.v_inf, front, 0.0).unwrap();
        let wavelength = 2.0 * std::f64::consts::PI / om;
        u.set_disturbance(Some(Box::new(Sinusoidal::new(conv, w0, wavelength, None, true, d).unwrap())));
        let mut lm = [C::new(0.0, 0.0); 2];
        for n in 1..=6 * n_per {
            let t = n as f64 * dt;
            u.step(dt).unwrap();
            if n > 5 * n_per {
                for (i, a) in lm.iter_mut().enumerate() {
                    let l = u.surface(i).unwrap().loads().total_force()[2];
                    *a += C::new(2.0 * l * (om * t).sin(), 2.0 * l * (om * t).cos()) / (n_per as f64 * w0);
                }
            }
        }
        for (i, name) in [(0, "wing"), (1, "tail")] {
            let (ec, ed) = ((lc[i] / lm[i] - 1.0).norm(), (ld[i] / lm[i] - 1.0).norm());
            println!(
                "gust, k = {k}: {name} lift marching {:.5}, linear |ratio − 1| {ec:.2e}, with the march's rate {ed:.2e}",
                lm[i]
            );
            assert!(ed < 1e-6, "gust, k = {k}, {name}: {} vs {}", ld[i], lm[i]);
            assert!(ec < 5e-3, "gust, k = {k}, {name}: {} vs {}", lc[i], lm[i]);
        }
    }
}
