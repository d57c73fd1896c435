//! The linearised gust response (docs/gust.md §7): the flutter equation of the stability
//! analysis ([`crate::stability`], docs/stability.md) driven by a frozen gust, solved in the
//! frequency domain and brought back to time.
//!
//! About the static aeroelastic equilibrium of the case's hinge state, in the modal coordinates
//! `η` of the stability analysis,
//!
//! $$ D_w(s)\,\eta = -H\,\big[g(s) - F(s)\,N(s)^{-1} r_g(s)\big]\,\hat w(s) ,$$
//!
//! `N(s)` and `F(s)` the linear UVLM's normalwash and force operators, `r_g(s)` and `g(s)` the
//! gust's normalwash at the collocation points and its Joukowski force at the segment midpoints,
//! each point delayed by its distance behind the gust's front ([`uvlm::LinearUvlm::gust`]), `H`
//! the generalised load of a unit nodal force and `ŵ(s)` the Laplace transform of the gust
//! velocity at the front's reference point.
//!
//! **The wake's motion.** `D_w(s)` is the stability analysis's `D(s)` plus, optionally
//! (`wake_motion`), the terms of the wake nodes' motion, as the time march moves them: node
//! `(k, j)` is where trailing-edge node `j` was `τ_k` ago, `δx_{k,j}(s) = e^{−sτ_k} δx_TE,j(s)`,
//! and it has drifted with the gust since, by `τ_k` times the gust velocity the trailing edge saw
//! then (the gust is frozen in the air that carries the node). Both act through the steady
//! wake's trailing vortices ([`uvlm::LinearUvlm::wake_node_derivatives`]). Without them (the
//! stability analysis's frozen wake, whose first row alone follows the trailing edge) the paper's
//! wing misses its peak fold by 10 % (docs/gust.md §7).
//!
//! The outputs are the time march's ([`crate::gust::gust_history`]): the free-body root bending
//! moment, root torque and hinge moment of [`crate::loads::LoadModel`], the fold angle and the
//! lift, each linearised about the equilibrium (central differences of the same routines along
//! each mode, its velocity and its acceleration, and exact derivatives in the station loads).
//!
//! Back to time: the response is sampled on the time march's steps over a period `T` of twice
//! the run, and inverted along `Re s = σ` (an exponential window: `y(t) = e^{σt} ·
//! DFT⁻¹[Y(σ + iω_k) ŵ(σ + iω_k)]`), so that what the periodic inverse folds back from later
//! periods is weighted by `e^{−σT}` (1e-8) and a lightly damped mode needs no long padding. The
//! transfer is exact for complex `s`, so the shift costs nothing in accuracy.

use nalgebra::{Complex, DMatrix, DVector, Vector3};

use formulation::Structure;

use crate::aero::{SectionLoad, station_map, stations_at};
use crate::factory::{BuildModel, ForModel, dispatch};
use crate::gust::Increments;
use crate::polar_correction::{LinearCorrection, StripPolars};
use crate::problem::{Formulation, Problem};
use crate::stability::{
    MovedLattice, linear_wake, load_maps, lump, mode_step, reduce, reference_correction, zero_loads,
};

type C64 = Complex<f64>;

/// A linearised gust response: the increments of the time march's outputs at its output times.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearGustHistory {
    /// The increments (as the time march's [`crate::gust::GustHistory`]).
    pub increments: Increments,
    /// Structural modes in the basis.
    pub n_basis: usize,
    /// Frequencies at which the transfer was evaluated.
    pub n_frequencies: usize,
    /// Rows of the frozen wake (of length `U·dt` unless the case's `stability.wake` says otherwise).
    pub n_wake_rows: usize,
}

/// Outputs, in the order of [`Increments`]' series.
const N_OUT: usize = 5;

/// The linearised response of `case` (its `aero.gust`, the hinge state already applied) with
/// formulation `f`, about its static equilibrium at the case's airspeed, over `[0, t_end]` at
/// the case's output times; `basis_modes` structural modes (default: `stability.basis_modes`,
/// else 30, at most the free motions). The frozen wake is the stability analysis's
/// ([`linear_wake`]): by default the time march's, `aero.n_wake_rows` rows of `U·dt`;
/// `wake_motion` adds the motion of its nodes with the trailing edge's past and the gust (see the
/// module docs; `false` is the stability analysis's model).
///
/// # Errors
/// A case without `aero` or `aero.gust`, a failed equilibrium, or a failed reduction.
pub fn linear_gust_history(
    case: &Problem,
    f: Formulation,
    basis_modes: Option<usize>,
    wake_motion: bool,
) -> Result<LinearGustHistory, String> {
    struct Run<'a>(&'a Problem, Formulation, Option<usize>, bool);
    impl ForModel for Run<'_> {
        type Output = Result<LinearGustHistory, String>;
        fn run<M: BuildModel>(self) -> Self::Output {
            run(self.0, self.1, M::build, self.2, self.3)
        }
    }
    dispatch(f, Run(case, f, basis_modes, wake_motion))
}

fn run<S: Structure>(
    case: &Problem,
    f: Formulation,
    build: fn(&Problem) -> Result<S, crate::Error>,
    basis_modes: Option<usize>,
    wake_motion: bool,
) -> Result<LinearGustHistory, String> {
    let aero = case.aero.as_ref().ok_or("the case has no `aero` block")?;
    crate::section_polars::refuse_tip_loss(case, "linear gust model")?;
    let polars = StripPolars::of(case)?;
    let spec = aero.gust.as_ref().ok_or("the case has no `aero.gust`")?;
    let map = station_map(case, aero)?;
    let v_inf = aero.free_stream();
    let u = Vector3::from(v_inf).norm();
    // The equilibrium with its multipliers, the steady state of the linearised frozen wake.
    let p = crate::statics::equilibrium_at(case, f, crate::stability::wake_settings(case, f, u))
        .map_err(|e| format!("static equilibrium: {e}"))?;
    let (q, lam, mu) = p.state.ok_or("static equilibrium: no state")?;
    let settings = crate::factory::settings(case, f);
    let wake = linear_wake(case, f, u);
    let nb_req = basis_modes.or(case.stability.as_ref().and_then(|s| s.basis_modes)).unwrap_or(30);
    let lattice = (map.as_slice(), aero, polars.as_ref());
    let red = reduce(build(case).map_err(|e| e.to_string())?, &q, &lam, &mu, lattice, &wake, (nb_req, 0), None, None)?;
    let nb = red.phi.ncols();
    let mut model = build(case).map_err(|e| e.to_string())?;
    let zero_loads = zero_loads(&map);
    model.set_section_loads(&zero_loads).map_err(|e| e.to_string())?;

    // The linear UVLM on the equilibrium's lattice and the gust's input to it.
    let zeros = vec![0.0; model.n_dof()];
    let mut scratch = crate::aero::StationScratch::default();
    let (mut stations, mut vel) = (Vec::new(), Vec::new());
    stations_at(&model, &q, &zeros, &map, aero, None, &mut scratch, &mut stations, &mut vel);
    let mut uv = crate::lifting::new_uvlm(&map, aero, &stations, aero.uvlm_params(v_inf))
        .map_err(|e| format!("aerodynamic lattice: {e}"))?;
    let la = uv.linearise(&wake).map_err(|e| format!("linear UVLM: {e}"))?;
    let front = crate::gust::gust_front(spec, aero, &stations)?;
    let gust_dir = Vector3::from(spec.direction()).normalize();
    let lg = la.gust(gust_dir.into(), front).map_err(|e| format!("linear gust: {e}"))?;
    let steady = uv.solve_steady().map_err(|e| format!("steady aerodynamics: {e}"))?;
    let origins: Vec<[f64; 3]> = stations.iter().map(|x| x.origin.into()).collect();
    let f0: Vec<f64> = steady.nodal.iter().flatten().copied().collect();
    let mut l0 = lump(&map, aero, &steady.positions, &origins, &f0);
    if let Some(p) = &polars {
        p.correct(&stations, &map, steady, |_, _| Vector3::from(v_inf), 1.0, &mut l0, &mut Default::default())?;
    }

    let [cl, h, phi_p] = load_maps(&mut model, &q, &red.phi, (&map, aero), &zero_loads, &la, &origins)?;
    let mut outputs = Outputs { lm: settings.loads.as_ref(), fold: settings.fold_joint, ls: Default::default() };
    let mut moved = MovedLattice::new(&la, &map, aero, polars.as_ref());
    let d = mode_derivatives(&model, &q, &red.phi, &mut moved, &mut outputs, &l0)?;
    let yl = output_per_station_load(&model, &q, &mut outputs, &l0);
    let (nr, nf) = (la.n_rings(), la.n_force());
    let mut parts = Parts {
        rx: d.rx,
        rv: d.rv,
        fx: d.fx,
        fv: d.fv,
        lx: d.lx,
        lv: d.lv,
        yx: d.yx,
        yv: d.yv,
        ya: d.ya,
        yl,
        h: h.map(C64::from),
        cl: cl.map(C64::from),
        lift: DMatrix::zeros(1, nf),
        row_delays: la.row_delays.clone(),
        rw: Vec::new(),
        fw: Vec::new(),
        drift_delays: Vec::new(),
        drift_r: DMatrix::zeros(nr, 0),
        drift_f: DMatrix::zeros(nf, 0),
        strips: None,
    };
    if let Some(p) = &polars {
        let lc = reference_correction(p, &stations, &map, aero, &la)?;
        parts.strips = Some(StripParts::new(&lc, &stations, &phi_p, (v_inf, u), front, gust_dir));
    }
    if wake_motion {
        add_wake_motion(&mut parts, &la, &d.xte, (v_inf, u), front, gust_dir);
    }
    parts.lift = lift_row(nf, v_inf).map(C64::from);
    let field = crate::gust::disturbance(spec, aero, &stations, 2.0 * settings.t_end, 0.0)?;
    let model_parts = Model { red: &red, la: &la, lg: &lg, parts: &parts };
    let increments = synthesise(&*field, front, gust_dir, &settings, &model_parts)?;
    let n = 2 * n_run(&settings).max(8);
    Ok(LinearGustHistory { increments, n_basis: nb, n_frequencies: n / 2 + 1, n_wake_rows: wake.row_lengths.len() })
}

/// Station loads stacked as `[F, M]` per station.
fn flat(l: &[SectionLoad]) -> Vec<f64> {
    l.iter().flat_map(|x| [x.force.x, x.force.y, x.force.z, x.moment.x, x.moment.y, x.moment.z]).collect()
}

/// `(a − b)·k`.
fn diff(a: &[f64], b: &[f64], k: f64) -> DVector<f64> {
    DVector::from_iterator(a.len(), a.iter().zip(b).map(|(x, y)| (x - y) * k))
}

/// The outputs of [`Increments`] at a state (the lift, linear in the nodal forces, is 0 here):
/// root bending moment, root torque and hinge moment of the load model, and the fold angle.
struct Outputs<'a> {
    lm: Option<&'a crate::loads::LoadModel>,
    fold: Option<usize>,
    ls: crate::loads::LoadScratch,
}

impl Outputs<'_> {
    /// The outputs of `model` at `q` moving with `motion` (velocity, acceleration) under `loads`.
    fn at<S: Structure>(
        &mut self,
        model: &S,
        q: &[f64],
        motion: (&[f64], &[f64]),
        loads: &[SectionLoad],
    ) -> [f64; N_OUT] {
        let w = self.lm.map(|lm| lm.evaluate(model, q, Some(motion), loads, &mut self.ls));
        let fold_deg = self.fold.map_or(f64::NAN, |j| model.fold(q, j).to_degrees());
        match w {
            Some(w) => [w.root_bending_moment, w.root_torque, w.hinge_moment, fold_deg, 0.0],
            None => [f64::NAN, f64::NAN, f64::NAN, fold_deg, 0.0],
        }
    }
}

/// The geometric terms and the outputs along each basis mode (central differences of a step of
/// `1e-6` chord along its position, and along its velocity and acceleration): residual, station
/// loads and nodal forces of the moved lattice with the reference circulations held (as the
/// stability reduction's), the trailing edge's motion, and the outputs under the steady loads
/// `l0`.
struct ModeDerivatives {
    rx: DMatrix<f64>,
    rv: DMatrix<f64>,
    lx: DMatrix<f64>,
    lv: DMatrix<f64>,
    fx: DMatrix<f64>,
    fv: DMatrix<f64>,
    xte: DMatrix<f64>,
    yx: DMatrix<f64>,
    yv: DMatrix<f64>,
    ya: DMatrix<f64>,
}

/// [`ModeDerivatives`] of `model` about `q` along the modes `phi`.
fn mode_derivatives<S: Structure>(
    model: &S,
    q: &[f64],
    phi: &DMatrix<f64>,
    moved: &mut MovedLattice<'_>,
    outputs: &mut Outputs<'_>,
    l0: &[SectionLoad],
) -> Result<ModeDerivatives, String> {
    let (la, chord) = (moved.linear(), moved.chord());
    let (nr, nf, ns, nb) = (la.n_rings(), la.n_force(), l0.len(), phi.ncols());
    let n_te = la.n_te_nodes();
    let zeros = vec![0.0; model.n_dof()];
    let mut d = ModeDerivatives {
        rx: DMatrix::zeros(nr, nb),
        rv: DMatrix::zeros(nr, nb),
        lx: DMatrix::zeros(6 * ns, nb),
        lv: DMatrix::zeros(6 * ns, nb),
        fx: DMatrix::zeros(nf, nb),
        fv: DMatrix::zeros(nf, nb),
        xte: DMatrix::zeros(3 * n_te, nb),
        yx: DMatrix::zeros(N_OUT, nb),
        yv: DMatrix::zeros(N_OUT, nb),
        ya: DMatrix::zeros(N_OUT, nb),
    };
    let eval = |moved: &mut MovedLattice<'_>, qq: &[f64], vv: &[f64], with_vel: bool| -> Result<_, String> {
        let m = moved.at(model, qq, vv, with_vel)?;
        Ok((m.residual, flat(&m.loads), m.forces, m.te))
    };
    // The polars' correction of the station loads along a position or velocity, apart (its own
    // step; the stations' loads, so no change of their application).
    let correction = |moved: &mut MovedLattice<'_>, col: &[f64], velocity: bool| -> Result<_, String> {
        Ok(moved.correction_pair(model, q, col, velocity)?.map(|c| diff(&flat(&c.plus), &flat(&c.minus), 0.5 / c.step)))
    };
    let span = chord.max(1e-3);
    let (mut qp, mut qm) = (vec![0.0; q.len()], vec![0.0; q.len()]);
    for i in 0..nb {
        let (col, eps) = mode_step(phi, i, span);
        let neg: Vec<f64> = col.iter().map(|x| -x).collect();
        let dq: Vec<f64> = col.iter().map(|x| eps * x).collect();
        model.retract_inplace(q, &dq, &mut qp);
        let dq: Vec<f64> = col.iter().map(|x| -eps * x).collect();
        model.retract_inplace(q, &dq, &mut qm);
        let (r1, l1, f1, te1) = eval(moved, &qp, &zeros, false)?;
        let (r2, l2, f2, te2) = eval(moved, &qm, &zeros, false)?;
        d.rx.set_column(i, &diff(&r1, &r2, 0.5 / eps));
        d.lx.set_column(i, &diff(&l1, &l2, 0.5 / eps));
        if let Some(c) = correction(moved, &col, false)? {
            let lx = d.lx.column(i) + c;
            d.lx.set_column(i, &lx);
        }
        d.fx.set_column(i, &diff(&f1, &f2, 0.5 / eps));
        d.xte.set_column(i, &diff(&te1, &te2, 0.5 / eps));
        let (r1, l1, f1, _) = eval(moved, q, &col, true)?;
        let (r2, l2, f2, _) = eval(moved, q, &neg, true)?;
        d.rv.set_column(i, &diff(&r1, &r2, 0.5));
        d.lv.set_column(i, &diff(&l1, &l2, 0.5));
        if let Some(c) = correction(moved, &col, true)? {
            let lv = d.lv.column(i) + c;
            d.lv.set_column(i, &lv);
        }
        d.fv.set_column(i, &diff(&f1, &f2, 0.5));
        let (y1, y2) = (outputs.at(model, &qp, (&zeros, &zeros), l0), outputs.at(model, &qm, (&zeros, &zeros), l0));
        d.yx.set_column(i, &diff(&y1, &y2, 0.5 / eps));
        let (y1, y2) = (outputs.at(model, q, (&col, &zeros), l0), outputs.at(model, q, (&neg, &zeros), l0));
        d.yv.set_column(i, &diff(&y1, &y2, 0.5));
        let (y1, y2) = (outputs.at(model, q, (&zeros, &col), l0), outputs.at(model, q, (&zeros, &neg), l0));
        d.ya.set_column(i, &diff(&y1, &y2, 0.5));
    }
    Ok(d)
}

/// The outputs per unit station load (outputs × 6·stations), by central differences of unit
/// loads about the steady loads `l0` at `q`.
fn output_per_station_load<S: Structure>(
    model: &S,
    q: &[f64],
    outputs: &mut Outputs<'_>,
    l0: &[SectionLoad],
) -> DMatrix<f64> {
    let zeros = vec![0.0; model.n_dof()];
    let ns = l0.len();
    let mut yl = DMatrix::zeros(N_OUT, 6 * ns);
    for j in 0..6 * ns {
        let (mut lp, mut lmn) = (l0.to_vec(), l0.to_vec());
        let comp = j % 6;
        for (l, sg) in [(&mut lp, 1.0), (&mut lmn, -1.0)] {
            if comp < 3 {
                l[j / 6].force[comp] += sg;
            } else {
                l[j / 6].moment[comp - 3] += sg;
            }
        }
        let (y1, y2) = (outputs.at(model, q, (&zeros, &zeros), &lp), outputs.at(model, q, (&zeros, &zeros), &lmn));
        for o in 0..N_OUT {
            yl[(o, j)] = 0.5 * (y1[o] - y2[o]);
        }
    }
    yl
}

/// The wake's nodes in [`Parts`]: where the trailing edge was (the structure's motion, `xte`
/// along each mode), drifted by the gust (direction `gust_dir`, front `front`) in the free
/// stream `(v_inf, u)`; the trailing-edge nodes of every surface, stacked.
fn add_wake_motion(
    parts: &mut Parts,
    la: &uvlm::LinearUvlm,
    xte: &DMatrix<f64>,
    (v_inf, u): ([f64; 3], f64),
    front: [f64; 3],
    gust_dir: Vector3<f64>,
) {
    let (nr, nf) = (la.n_rings(), la.n_force());
    let n_te = la.n_te_nodes();
    let wd = la.wake_node_derivatives();
    let te_nodes: Vec<[f64; 3]> = la.lattices().iter().flat_map(|l| l.trailing_edge_nodes().iter().copied()).collect();
    let vh = Vector3::from(v_inf) / u;
    let te_delay: Vec<f64> = te_nodes.iter().map(|x| vh.dot(&(Vector3::from(*x) - Vector3::from(front))) / u).collect();
    let n_rows = wd.residual.len();
    let (mut dr, mut df) = (DMatrix::zeros(nr, n_rows * n_te), DMatrix::zeros(nf, n_rows * n_te));
    let n_s = if parts.strips.is_some() { wd.strip.first().map_or(0, DMatrix::nrows) } else { 0 };
    let mut ds = DMatrix::zeros(n_s, n_rows * n_te);
    for k in 0..n_rows {
        parts.rw.push(&wd.residual[k] * xte);
        parts.fw.push(&wd.force[k] * xte);
        if let Some(sp) = parts.strips.as_mut() {
            sp.sw.push(&wd.strip[k] * xte);
        }
        let tau = la.row_delays[k];
        for (j, &te_tau) in te_delay.iter().enumerate() {
            let c = k * n_te + j;
            for a in 0..3 {
                let g = tau * gust_dir[a];
                for r in 0..nr {
                    dr[(r, c)] += g * wd.residual[k][(r, 3 * j + a)];
                }
                for r in 0..nf {
                    df[(r, c)] += g * wd.force[k][(r, 3 * j + a)];
                }
                for r in 0..n_s {
                    ds[(r, c)] += g * wd.strip[k][(r, 3 * j + a)];
                }
            }
            parts.drift_delays.push(tau + te_tau);
        }
    }
    parts.drift_r = dr;
    parts.drift_f = df;
    if let Some(sp) = parts.strips.as_mut() {
        sp.drift = ds;
    }
}

/// The lift of the nodal forces (`nf` components) as a row: their total along the lift
/// direction of the free stream `v_inf` (uvlm::lift_drag_of, linear).
fn lift_row(nf: usize, v_inf: [f64; 3]) -> DMatrix<f64> {
    let n_nodes = nf / 3;
    let mut lift_row = DMatrix::zeros(1, nf);
    for k in 0..n_nodes {
        for c in 0..3 {
            let mut e = [0.0; 3];
            e[c] = 1.0;
            lift_row[(0, 3 * k + c)] = uvlm::lift_drag_of(e, v_inf, [1.0, 0.0, 0.0]).0;
        }
    }
    lift_row
}

/// Steps of the time march over `[0, t_end]`.
fn n_run(settings: &crate::run::RunSettings) -> usize {
    settings.n_steps()
}

/// The linear model whose transfer [`transfer`] evaluates.
struct Model<'a> {
    red: &'a crate::stability::Reduced,
    la: &'a uvlm::LinearUvlm,
    lg: &'a uvlm::LinearGust,
    parts: &'a Parts,
}

/// The time history of the outputs at the run's output times, by the inverse Fourier transform
/// on a contour shifted by `σ`: the gust `field` sampled at `front` along `gust_dir` on the time
/// march's steps over twice its duration, windowed by `e^{−σt}`, each frequency's response from
/// [`transfer`].
fn synthesise(
    field: &dyn uvlm::FlowField,
    front: [f64; 3],
    gust_dir: Vector3<f64>,
    settings: &crate::run::RunSettings,
    model: &Model<'_>,
) -> Result<Increments, String> {
    // The gust at the front's reference point, sampled on the time march's steps over T = 2 t_end.
    let dt = settings.params.dt;
    let n_run = n_run(settings);
    let n = 2 * n_run.max(8);
    let period = n as f64 * dt;
    let sigma = 18.4 / period;
    let gust: Vec<f64> = (0..n).map(|k| Vector3::from(field.velocity(front, k as f64 * dt)).dot(&gust_dir)).collect();
    let every = settings.output_every();
    let out_steps: Vec<usize> = (0..=n_run).filter(|k| k % every == 0 || *k == n_run).collect();
    let mut acc = vec![[0.0; N_OUT]; out_steps.len()];
    for k in 0..=n / 2 {
        let omega = 2.0 * std::f64::consts::PI * k as f64 / period;
        let s = C64::new(sigma, omega);
        // ŵ on the shifted contour (the DFT of the windowed samples; dt cancels in the inverse).
        let w_hat: C64 = gust
            .iter()
            .enumerate()
            .map(|(m, g)| {
                let t = m as f64 * dt;
                C64::from(g * (-sigma * t).exp()) * C64::new(0.0, -omega * t).exp()
            })
            .sum();
        if w_hat.norm() == 0.0 {
            continue;
        }
        let y = transfer(s, model.red, model.la, model.lg, model.parts)?;
        let weight = if k == 0 || 2 * k == n { 1.0 } else { 2.0 };
        for (row, &step) in acc.iter_mut().zip(&out_steps) {
            let t = step as f64 * dt;
            let e = C64::new(0.0, omega * t).exp() * w_hat;
            for o in 0..N_OUT {
                row[o] += weight * (y[o] * e).re;
            }
        }
    }
    let scale: Vec<f64> = out_steps.iter().map(|&k| (sigma * k as f64 * dt).exp() / n as f64).collect();
    let series = |o: usize| acc.iter().zip(&scale).map(|(r, sc)| r[o] * sc).collect::<Vec<f64>>();
    Ok(Increments {
        t: out_steps.iter().map(|&k| k as f64 * dt).collect(),
        delta_root_bending_moment: series(0),
        delta_root_torque: series(1),
        delta_hinge_moment: series(2),
        delta_fold_deg: series(3),
        delta_lift: series(4),
    })
}

/// The pieces of the reduced model besides `D(s)` and the linear UVLM.
struct Parts {
    /// Residual, nodal forces and station loads along each mode's position and velocity.
    rx: DMatrix<f64>,
    rv: DMatrix<f64>,
    fx: DMatrix<f64>,
    fv: DMatrix<f64>,
    lx: DMatrix<f64>,
    lv: DMatrix<f64>,
    /// Outputs along each mode's position, velocity, acceleration, and per unit station load.
    yx: DMatrix<f64>,
    yv: DMatrix<f64>,
    ya: DMatrix<f64>,
    yl: DMatrix<f64>,
    /// `H = Φᵀ P C_l`, the lumping `C_l`, and the lift per unit nodal force.
    h: DMatrix<C64>,
    cl: DMatrix<C64>,
    lift: DMatrix<C64>,
    /// Wake rows following the trailing edge's past motion: delays and, per row, residual and
    /// nodal forces per mode (empty without the wake's motion).
    row_delays: Vec<f64>,
    rw: Vec<DMatrix<f64>>,
    fw: Vec<DMatrix<f64>>,
    /// The gust's drift of the wake nodes: per node, its delay, residual and nodal forces per
    /// unit gust velocity.
    drift_delays: Vec<f64>,
    drift_r: DMatrix<f64>,
    drift_f: DMatrix<f64>,
    /// The section polars' correction (none without polars).
    strips: Option<StripParts>,
}

/// The section polars' strip correction in the linear gust model (docs/section_aero.md §7.7):
/// the strip forces of the circulations, of the gust at fixed circulations and of the wake's
/// motion change the station loads through each strip's lattice-force Jacobian (`K_c`), and the
/// gust's velocity at each strip's quarter-chord midpoint changes its flow (`K_u`).
struct StripParts {
    /// `Φᵀ P` (modes × 6·stations).
    phi_p: DMatrix<C64>,
    /// `K_c` (6·stations × 3·strips) and `Φᵀ P K_c`.
    kc: DMatrix<C64>,
    hc: DMatrix<C64>,
    /// Station loads per unit gust velocity at each strip (6·stations × strips), and each
    /// strip's delay behind the gust's front.
    flow: DMatrix<f64>,
    flow_delays: Vec<f64>,
    /// The wake's motion: per row, strip forces per mode; the gust's drift of its nodes, strip
    /// forces per unit gust velocity (columns as `Parts::drift_f`).
    sw: Vec<DMatrix<f64>>,
    drift: DMatrix<f64>,
    /// The lift per station load (1 × 6·stations).
    lift: DMatrix<C64>,
}

impl StripParts {
    /// The parts of the linearised correction `lc` on `stations`, the gust along `gust_dir` with
    /// its front at `front` in the free stream `(v_inf, u)`.
    fn new(
        lc: &LinearCorrection,
        stations: &[uvlm::SpanStation],
        phi_p: &DMatrix<f64>,
        (v_inf, u): ([f64; 3], f64),
        front: [f64; 3],
        gust_dir: Vector3<f64>,
    ) -> Self {
        let kc = lc.load_per_strip_force(stations);
        let per_flow = lc.load_per_strip_flow(stations);
        let vh = Vector3::from(v_inf) / u;
        let points = lc.points();
        let mut flow = DMatrix::zeros(per_flow.nrows(), points.len());
        let mut flow_delays = vec![0.0; points.len()];
        for (i, p) in points.iter().enumerate() {
            let Some(p) = p else { continue };
            flow.set_column(i, &(per_flow.columns(3 * i, 3) * gust_dir));
            flow_delays[i] = vh.dot(&(p - Vector3::from(front))) / u;
        }
        let ns = stations.len();
        let mut lift = DMatrix::zeros(1, 6 * ns);
        for k in 0..ns {
            for c in 0..3 {
                let mut e = [0.0; 3];
                e[c] = 1.0;
                lift[(0, 6 * k + c)] = C64::from(uvlm::lift_drag_of(e, v_inf, [1.0, 0.0, 0.0]).0);
            }
        }
        Self {
            hc: (phi_p * &kc).map(C64::from),
            phi_p: phi_p.map(C64::from),
            kc: kc.map(C64::from),
            flow,
            flow_delays,
            sw: Vec::new(),
            drift: DMatrix::zeros(0, 0),
            lift,
        }
    }
}

/// `Σ_k e^{−s τ_k} M_k`.
fn delayed_sum(s: C64, delays: &[f64], m: &[DMatrix<f64>], rows: usize, cols: usize) -> DMatrix<C64> {
    let mut out = DMatrix::zeros(rows, cols);
    for (mk, &tau) in m.iter().zip(delays) {
        let e = (-s * tau).exp();
        out.zip_apply(mk, |a, b| *a += e * b);
    }
    out
}

/// `Σ_c e^{−s τ_c} m[:, c]`.
fn delayed_columns(s: C64, delays: &[f64], m: &DMatrix<f64>) -> DVector<C64> {
    let e: DVector<C64> = DVector::from_iterator(delays.len(), delays.iter().map(|tau| (-s * tau).exp()));
    m.map(C64::from) * e
}

/// The outputs per unit `ŵ(s)` at `s`.
fn transfer(
    s: C64,
    red: &crate::stability::Reduced,
    la: &uvlm::LinearUvlm,
    lg: &uvlm::LinearGust,
    p: &Parts,
) -> Result<[C64; N_OUT], String> {
    let nb = p.rx.ncols();
    let (nr, nf) = (p.rx.nrows(), p.fx.nrows());
    // Wake nodes following the trailing edge: extra residual and forces per mode.
    let r_w = delayed_sum(s, &p.row_delays, &p.rw, nr, nb);
    let f_w = delayed_sum(s, &p.row_delays, &p.fw, nf, nb);
    let mut rhs = DMatrix::zeros(nr, nb + 1);
    rhs.view_mut((0, 0), (nr, nb)).copy_from(&(p.rx.map(C64::from) + p.rv.map(|x| s * x) + &r_w));
    let mut r_g = DVector::from_vec(lg.normalwash_at(s));
    let mut f_g = DVector::from_vec(lg.force_at(s));
    if !p.drift_delays.is_empty() {
        r_g += delayed_columns(s, &p.drift_delays, &p.drift_r);
        f_g += delayed_columns(s, &p.drift_delays, &p.drift_f);
    }
    rhs.set_column(nb, &r_g);
    let x =
        uvlm::solve_complex(&la.normalwash_matrix(s), &rhs).ok_or("the linear UVLM's normalwash matrix is singular")?;
    // Nodal forces of the circulations (δΓ = −N⁻¹ r) per η and per ŵ.
    let fgam = -(la.force_matrix(s) * &x);
    let f_eta_circ = fgam.columns(0, nb).into_owned();
    let f_wg = fgam.column(nb) + f_g;
    // D(s): the stability analysis's, −T N⁻¹ (R_x + s R_ẋ) being H times the circulations'
    // forces, plus the wake's motion (its residual in `f_eta_circ`, its forces `f_w`).
    let mut d = red.structural(s) + &p.h * (&f_eta_circ + &f_w);
    let mut rhs = -(&p.h * &f_wg);
    let strips = p.strips.as_ref().map(|sp| strip_terms(s, la, lg, p, sp, &x));
    if let (Some(sp), Some((s_eta, s_wg, u_g))) = (&p.strips, &strips) {
        d += &sp.hc * s_eta;
        rhs -= &sp.hc * s_wg + &sp.phi_p * u_g;
    }
    let eta = d.lu().solve(&rhs).ok_or("the flutter matrix is singular")?;
    let f_eta_geo = p.fx.map(C64::from) + p.fv.map(|x| s * x) + &f_w;
    let nodal = &f_eta_circ * &eta + &f_wg + &f_eta_geo * &eta;
    let mut station =
        &p.cl * (&f_eta_circ * &eta + &f_wg + &f_w * &eta) + (p.lx.map(C64::from) + p.lv.map(|x| s * x)) * &eta;
    if let (Some(sp), Some((s_eta, s_wg, u_g))) = (&p.strips, &strips) {
        station += &sp.kc * (s_eta * &eta + s_wg) + u_g;
    }
    let y =
        (p.yx.map(C64::from) + p.yv.map(|x| s * x) + p.ya.map(|x| s * s * x)) * &eta + p.yl.map(C64::from) * &station;
    // With polars the lift of the corrected station loads (the nodal forces' total without).
    let l = match &p.strips {
        Some(sp) => (&sp.lift * &station)[0],
        None => (&p.lift * nodal)[0],
    };
    Ok([y[0], y[1], y[2], y[3], l])
}

/// The strip forces of the polars' correction at `s` (`x` the circulations' solve per mode and
/// per `ŵ`, `δΓ = −x`): per mode (circulations and the wake's motion), per `ŵ` (circulations,
/// the gust at fixed circulations and its drift of the wake), and the station loads of the gust's
/// velocity at the strips per `ŵ`.
fn strip_terms(
    s: C64,
    la: &uvlm::LinearUvlm,
    lg: &uvlm::LinearGust,
    p: &Parts,
    sp: &StripParts,
    x: &DMatrix<C64>,
) -> (DMatrix<C64>, DVector<C64>, DVector<C64>) {
    let nb = x.ncols() - 1;
    let sgam = -(la.strip_force_matrix(s) * x);
    let mut s_eta = sgam.columns(0, nb).into_owned();
    if !sp.sw.is_empty() {
        s_eta += delayed_sum(s, &p.row_delays, &sp.sw, s_eta.nrows(), nb);
    }
    let mut s_wg = sgam.column(nb) + DVector::from_vec(lg.strip_force_at(s));
    if !p.drift_delays.is_empty() {
        s_wg += delayed_columns(s, &p.drift_delays, &sp.drift);
    }
    (s_eta, s_wg, delayed_columns(s, &sp.flow_delays, &sp.flow))
}
