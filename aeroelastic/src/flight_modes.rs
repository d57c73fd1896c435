//! The flight-dynamics roots of a free aircraft about its trim (`"about": "trim"`,
//! docs/stability.md §9).
//!
//! About the trimmed state the free aircraft's flutter equation `D(s) η = 0` has, besides the
//! elastic roots, the roots of its six rigid-body motions: the phugoid and the short period
//! (symmetric), the Dutch roll, the roll subsidence and the spiral (antisymmetric), and four
//! neutral roots at `s = 0` (position in three directions and heading). They are found from the
//! quasi-steady quadratic `D₀ + D₁ s + D₂ s²` (Taylor coefficients of `D` at `s = 0`), whose
//! eigenvalues with a mostly rigid eigenvector start Newton's method on the full `D(s)`, and named
//! by the symmetry of their motion about the aircraft's plane of symmetry.

use nalgebra::{Complex, DMatrix, DVector, Vector3};

use formulation::Structure;

use crate::aero::{AeroSettings, StationMap, stations_at};
use crate::problem::Problem;
use crate::stability::Reduced;

type C64 = Complex<f64>;

/// A rigid-body root of a free aircraft about its trim.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct FlightRoot {
    /// `phugoid`, `short_period`, `dutch_roll`, `roll_subsidence`, `spiral`, or `longitudinal`,
    /// `lateral` and `rigid` for a root the names above do not fit (see docs/stability.md §9).
    pub name: String,
    /// Real part of s, 1/s.
    pub real: f64,
    /// Imaginary part of s, rad/s (≥ 0).
    pub imag: f64,
    /// Share of the motion's station displacements that is symmetric about the plane of symmetry
    /// (1 symmetric, 0 antisymmetric; NaN without a plane of symmetry).
    pub symmetric: f64,
    /// Share of the root's modal kinetic energy in the rigid-body basis modes.
    pub rigid: f64,
}

impl FlightRoot {
    /// Period of an oscillatory root, s (infinite for a real root).
    pub fn period_s(&self) -> f64 {
        if self.imag > 0.0 { 2.0 * std::f64::consts::PI / self.imag } else { f64::INFINITY }
    }
    /// Damping ratio `−Re s / |s|`.
    pub fn damping_ratio(&self) -> f64 {
        let n = self.real.hypot(self.imag);
        if n > 0.0 { -self.real / n } else { 0.0 }
    }
    /// Time to halve (`Re s < 0`) or to double (`Re s > 0`) the amplitude, s.
    pub fn time_to_half_or_double_s(&self) -> f64 {
        std::f64::consts::LN_2 / self.real.abs()
    }
}

/// Rigid-body motions of a structure with `n_free_joints` free joints.
pub(crate) fn n_rigid(p: &Problem) -> usize {
    6 * p.joints.iter().filter(|j| matches!(j, crate::problem::Joint::Free { .. })).count()
}

/// A root at `|s|` below this (1/s) is neutral: a position or the heading, which the
/// linearisation holds at `s = 0` to its difference quotients' accuracy.
pub const NEUTRAL: f64 = 1e-4;

/// The share of a root's modal kinetic energy in the rigid-body modes above which it is a
/// flight-dynamics root. The Horten wing's are above 0.998; the wake's heavily damped lag roots
/// that Newton's method reaches from rigid starts are below 0.85.
pub const RIGID: f64 = 0.9;

/// Multipliers `(λ, μ)` of the free `model` at rest at `q` under its station loads (already
/// set): the consistent ones of a start from rest, `[M Gᵀ; G 0] [v̇; ν] = [−r; 0]`, which are the
/// static multipliers where the trim's net load vanishes and leave its small remainder as a
/// rigid-body acceleration.
///
/// # Errors
/// The matrix is singular.
pub(crate) fn rest_multipliers<S: Structure>(model: &S, q: &[f64]) -> Result<(Vec<f64>, Vec<f64>), String> {
    let (n, nh, nv) = (model.n_dof(), model.n_holonomic(), model.n_velocity_constraints());
    let zeros = vec![0.0; n];
    let mut a = genalpha::DenseMatrix::zeros(n + nh + nv, n + nh + nv);
    model.iteration_matrix_inplace(0.0, q, &zeros, &zeros, 1.0, 0.0, 0.0, &mut a.block(0, 0, n, n));
    let mut g = genalpha::DenseMatrix::zeros(nh + nv, n);
    model.phi_q_inplace(0.0, q, &mut g.block(0, 0, nh, n));
    model.psi_v_inplace(0.0, q, &mut g.block(nh, 0, nv, n));
    let mut big = DMatrix::zeros(n + nh + nv, n + nh + nv);
    for j in 0..n {
        for i in 0..n {
            big[(i, j)] = a.get(i, j);
        }
        for i in 0..nh + nv {
            big[(n + i, j)] = g.get(i, j);
            big[(j, n + i)] = g.get(i, j);
        }
    }
    let mut r = vec![0.0; n];
    model.residual_inplace(0.0, q, &zeros, &zeros, &mut r);
    let mut rhs = DVector::zeros(n + nh + nv);
    rhs.rows_mut(0, n).copy_from(&DVector::from_iterator(n, r.iter().map(|x| -x)));
    let x = big.lu().solve(&rhs).ok_or("the trimmed aircraft's multipliers: singular matrix")?;
    Ok((x.rows(n, nh).iter().copied().collect(), x.rows(n + nh, nv).iter().copied().collect()))
}

/// How the stations move along each basis mode, and which station mirrors which.
pub(crate) struct StationMotion {
    /// Displacement of each station's axis point per modal coordinate (3 rows per station).
    x: DMatrix<f64>,
    /// The station each station mirrors to about the plane of symmetry; `None` when the
    /// stations are not symmetric.
    mirror: Option<Vec<usize>>,
    /// The plane of symmetry's normal (the free body's spanwise axis at the trim).
    normal: Vector3<f64>,
}

impl StationMotion {
    /// The station motion of `model` about `q` along the columns of `phi` (central differences of
    /// `1e-6` span), and the stations' mirror images about the plane of symmetry: through the free
    /// body's root point, holding the free stream and gravity.
    pub(crate) fn new<S: Structure>(
        model: &S,
        q: &[f64],
        phi: &DMatrix<f64>,
        (map, aero, p): (&[StationMap], &AeroSettings, &Problem),
    ) -> Self {
        let zeros = vec![0.0; model.n_dof()];
        let mut scratch = crate::aero::StationScratch::default();
        let (mut st0, mut vel) = (Vec::new(), Vec::new());
        stations_at(model, q, &zeros, map, aero, None, &mut scratch, &mut st0, &mut vel);
        let span = p.span().max(1e-3);
        let ns = st0.len();
        let mut x = DMatrix::zeros(3 * ns, phi.ncols());
        let (mut qp, mut qm) = (vec![0.0; q.len()], vec![0.0; q.len()]);
        let (mut sp, mut sm) = (Vec::new(), Vec::new());
        for i in 0..phi.ncols() {
            let (col, eps) = crate::stability::mode_step(phi, i, span);
            let dq: Vec<f64> = col.iter().map(|c| eps * c).collect();
            model.retract_inplace(q, &dq, &mut qp);
            let dq: Vec<f64> = col.iter().map(|c| -eps * c).collect();
            model.retract_inplace(q, &dq, &mut qm);
            stations_at(model, &qp, &zeros, map, aero, None, &mut scratch, &mut sp, &mut vel);
            stations_at(model, &qm, &zeros, map, aero, None, &mut scratch, &mut sm, &mut vel);
            for (k, (a, b)) in sp.iter().zip(&sm).enumerate() {
                let d = (a.origin - b.origin) / (2.0 * eps);
                for c in 0..3 {
                    x[(3 * k + c, i)] = d[c];
                }
            }
        }
        let free = p
            .joints
            .iter()
            .find_map(|j| match j {
                crate::problem::Joint::Free { body, .. } => p.body_index(body),
                _ => None,
            })
            .unwrap_or(0);
        let (root, _) = model.section_pose(q, free, 0.0);
        // The plane of symmetry holds the flight path and the weight.
        let stream = Vector3::from(aero.free_stream());
        let normal = stream.cross(&Vector3::from(p.gravity.unwrap_or([0.0; 3])));
        let Some(normal) = normal.try_normalize(1e-12 * stream.norm().max(1e-300)) else {
            return Self { x, mirror: None, normal: Vector3::x() };
        };
        let reflect = |v: Vector3<f64>| v - 2.0 * normal * normal.dot(&(v - root));
        let tol = 1e-4 * span;
        let mirror: Option<Vec<usize>> = st0
            .iter()
            .map(|a| {
                let image = reflect(a.origin);
                st0.iter()
                    .enumerate()
                    .map(|(j, b)| (j, (b.origin - image).norm()))
                    .min_by(|u, v| u.1.total_cmp(&v.1))
                    .filter(|(_, d)| *d <= tol)
                    .map(|(j, _)| j)
            })
            .collect();
        Self { x, mirror, normal }
    }

    /// The symmetric share of the station displacements of the modal vector `eta`.
    fn symmetric_share(&self, eta: &DVector<C64>) -> f64 {
        let Some(mirror) = &self.mirror else { return f64::NAN };
        let u = self.x.map(C64::from) * eta;
        let at = |k: usize| Vector3::new(u[3 * k], u[3 * k + 1], u[3 * k + 2]);
        let n = self.normal.map(C64::from);
        let (mut sym, mut all) = (0.0, 0.0);
        for (k, &j) in mirror.iter().enumerate() {
            let uk = at(k);
            let uj = at(j);
            // The mirror image of j's displacement: its component along the normal reversed.
            let image = uj - n * (n.dot(&uj) * C64::new(2.0, 0.0));
            let s = (uk + image) * C64::new(0.5, 0.0);
            sym += s.norm_squared();
            all += uk.norm_squared();
        }
        if all > 0.0 { sym / all } else { f64::NAN }
    }
}

/// Share of the modal kinetic energy of `eta` (mass-normalised basis) in its first `n` modes.
fn rigid_share(eta: &DVector<C64>, n: usize) -> f64 {
    let all = eta.norm_squared();
    if all > 0.0 { eta.rows(0, n.min(eta.len())).norm_squared() / all } else { 0.0 }
}

/// The null vector of `a` (its right singular vector of the smallest singular value).
fn null_vector(a: &DMatrix<C64>) -> Option<DVector<C64>> {
    let svd = a.clone().try_svd(false, true, f64::EPSILON, 10_000)?;
    let v_t = svd.v_t?;
    let k = svd.singular_values.iamin();
    Some(v_t.row(k).adjoint())
}

/// Translations among the rigid-body basis modes: the first three ([`exact_rigid_modes`] puts
/// them first).
const TRANSLATIONS: usize = 3;

/// `D(s)` with its translation columns replaced by `(D(s) − D(0)) t / s`: the aircraft's
/// translations in velocity form. Translation invariance makes `D(0) t = 0` for a translation
/// `t` (to the difference quotients' rounding, which subtracting `D(0) t` removes), so this
/// divides out the three neutral position roots at `s = 0`, and with them the defective double
/// root of heading and sideways position, which any rounding splits into a pair `±√ε` that hides
/// the spiral. `d0` is `D(0)`.
fn velocity_form(red: &Reduced, d0: &DMatrix<C64>, s: C64) -> DMatrix<C64> {
    let mut d = red.d(s);
    for c in 0..TRANSLATIONS {
        for i in 0..d.nrows() {
            d[(i, c)] = (d[(i, c)] - d0[(i, c)]) / s;
        }
    }
    d
}

/// The rigid-body roots of `red` (about a trim, its first `n_rigid` basis modes the exact
/// rigid-body motions), each refined by Newton's method and named by its motion's symmetry.
///
/// Starts: the eigenvalues of the quadratic `D₀ + D₁ s + D₂ s²` fitted to the velocity form at
/// `s = ±ε, ±2ε` (ε a tenth of the inverse of the wake's longest delay) whose null vector is
/// mostly rigid. Roots within [`NEUTRAL`] of zero (the heading) are left out.
pub(crate) fn flight_roots(
    red: &Reduced,
    n_rigid: usize,
    motion: &StationMotion,
    n_evaluations: &mut usize,
) -> Vec<FlightRoot> {
    let nb = red.n_basis();
    let eps = 0.1 / red.longest_delay().max(1e-3);
    let zero = red.d(C64::new(0.0, 0.0));
    let at = |x: f64| velocity_form(red, &zero, C64::new(x, 0.0)).map(|z| z.re);
    let (p1, m1, p2, m2) = (at(eps), at(-eps), at(2.0 * eps), at(-2.0 * eps));
    *n_evaluations += 5;
    // Even and odd parts: e(x) = D₀ + D₂x² + O(x⁴), o(x) = D₁x + O(x³); Richardson on both.
    let (e1, e2) = ((&p1 + &m1) * 0.5, (&p2 + &m2) * 0.5);
    let (o1, o2) = ((&p1 - &m1) * 0.5, (&p2 - &m2) * 0.5);
    let d0 = (&e1 * 4.0 - &e2) / 3.0;
    let d2 = (&e2 - &e1) / (3.0 * eps * eps);
    let d1 = (&o1 * 8.0 - &o2) / (6.0 * eps);
    let Some(inv2) = d2.clone().try_inverse() else { return Vec::new() };
    let mut a = DMatrix::<C64>::zeros(2 * nb, 2 * nb);
    for i in 0..nb {
        a[(i, nb + i)] = C64::new(1.0, 0.0);
    }
    a.view_mut((nb, 0), (nb, nb)).copy_from(&(-(&inv2 * &d0)).map(C64::from));
    a.view_mut((nb, nb), (nb, nb)).copy_from(&(-(&inv2 * &d1)).map(C64::from));
    let Some(ev) = crate::stability::bounded_eigenvalues(a) else { return Vec::new() };
    let mut found: Vec<(C64, DVector<C64>)> = Vec::new();
    for s0 in ev.iter().copied().filter(|s| s.im >= -1e-9 * s.norm() && s.norm() >= NEUTRAL) {
        let q = d0.map(C64::from) + d1.map(|x| s0 * x) + d2.map(|x| s0 * s0 * x);
        let Some(e0) = null_vector(&q) else { continue };
        if rigid_share(&e0, n_rigid) < 0.5 {
            continue;
        }
        let (s, mut e) = match crate::stability::newton_of(|x| velocity_form(red, &zero, x), s0, e0, n_evaluations) {
            (s, e, true) => crate::stability::upper(s, e),
            _ => continue,
        };
        if s.norm() < NEUTRAL {
            continue;
        }
        // Back to displacements: a translation's coordinate is its velocity over s.
        for c in 0..TRANSLATIONS {
            e[c] /= s;
        }
        // Newton may leave a rigid start for an elastic root: keep the rigid roots.
        if rigid_share(&e, n_rigid) < RIGID || found.iter().any(|f| crate::stability::same_root(f.0, s)) {
            continue;
        }
        found.push((s, e));
    }
    let mut roots: Vec<FlightRoot> = found
        .into_iter()
        .map(|(s, e)| FlightRoot {
            name: String::new(),
            real: s.re,
            imag: if s.im.abs() <= 1e-9 * s.norm() { 0.0 } else { s.im },
            symmetric: motion.symmetric_share(&e),
            rigid: rigid_share(&e, n_rigid),
        })
        .collect();
    name_roots(&mut roots);
    roots
}

/// Names the roots: symmetric oscillations by frequency `phugoid`, `short_period`, then
/// `longitudinal`; antisymmetric ones `dutch_roll`, then `lateral`; antisymmetric real roots the
/// fastest decaying `roll_subsidence`, the slowest `spiral`, others `lateral`; symmetric real
/// roots `longitudinal`; without a plane of symmetry `rigid`. Sorted by the names' order, then by
/// `|s|`.
fn name_roots(roots: &mut [FlightRoot]) {
    roots.sort_by(|a, b| a.real.hypot(a.imag).total_cmp(&b.real.hypot(b.imag)));
    let sym = |r: &FlightRoot| r.symmetric >= 0.5;
    let anti = |r: &FlightRoot| r.symmetric < 0.5;
    let (mut n_long, mut n_dutch) = (0, 0);
    for r in roots.iter_mut() {
        r.name = if r.symmetric.is_nan() {
            "rigid".into()
        } else if sym(r) && r.imag > 0.0 {
            n_long += 1;
            match n_long {
                1 => "phugoid".into(),
                2 => "short_period".into(),
                _ => "longitudinal".into(),
            }
        } else if sym(r) {
            "longitudinal".into()
        } else if r.imag > 0.0 {
            n_dutch += 1;
            if n_dutch == 1 { "dutch_roll".into() } else { "lateral".into() }
        } else {
            "lateral".into()
        };
    }
    let reals: Vec<usize> = (0..roots.len()).filter(|&i| anti(&roots[i]) && roots[i].imag == 0.0).collect();
    if let Some(&fast) =
        reals.iter().filter(|&&i| roots[i].real < 0.0).min_by(|&&a, &&b| roots[a].real.total_cmp(&roots[b].real))
    {
        roots[fast].name = "roll_subsidence".into();
    }
    if let Some(&slow) = reals
        .iter()
        .filter(|&&i| roots[i].name == "lateral")
        .min_by(|&&a, &&b| roots[a].real.abs().total_cmp(&roots[b].real.abs()))
    {
        roots[slow].name = "spiral".into();
    }
    const ORDER: [&str; 8] =
        ["phugoid", "short_period", "longitudinal", "dutch_roll", "roll_subsidence", "spiral", "lateral", "rigid"];
    roots.sort_by_key(|r| ORDER.iter().position(|n| *n == r.name).unwrap_or(ORDER.len()));
}

/// `red` with its first `n_rigid` basis modes set apart as the rigid-body modes (the tracked
/// roots start after them).
///
/// # Errors
/// The rigid-body modes are not separated from the elastic ones: the slowest of the first
/// `n_rigid` natural frequencies is above a tenth of the next.
pub(crate) fn skip_rigid(mut red: Reduced, n_rigid: usize) -> Result<Reduced, String> {
    if n_rigid == 0 {
        return Ok(red);
    }
    let w = &red.omega;
    if w.len() <= n_rigid || red.n_basis() <= n_rigid {
        return Err(format!("the basis has no elastic mode after the {n_rigid} rigid-body modes"));
    }
    if w[n_rigid - 1].abs() > 0.1 * w[n_rigid].abs() {
        return Err(format!(
            "the free aircraft's rigid-body modes are not separated from its elastic ones: natural \
             frequencies {:.4} and {:.4} rad/s",
            w[n_rigid - 1],
            w[n_rigid]
        ));
    }
    red.skip = n_rigid;
    Ok(red)
}

/// Replace the first `n_rigid` columns of the mass-normalised basis `phi` by the exact rigid-body
/// motions of `model` at `q`, and make the other columns mass-orthogonal to them.
///
/// A rigid motion (velocity `d` of every point plus a rotation `θ` about the origin) is the
/// velocity whose kinetic-energy inner product with any admissible velocity `v` is the rigid
/// motion's Noether charge, `vᵀ M v_r = p(v)·d + L(v)·θ`, `p` and `L` the formulation's own
/// momentum map (`Structure::momentum`, linear in `v`). In the constraints' null space `N`:
/// `v_r = N (NᵀMN)⁻¹ Nᵀ Jᵀ (d, θ)`, `J` the momentum map's matrix. This holds for any
/// formulation without knowing its coordinates; the natural modes under the held loads and
/// gravity are not rigid (gravity does not turn with the aircraft, so they mix a rotation with
/// elastic deformation, and the neutral roots would move off zero).
///
/// # Errors
/// Not one free body (`n_rigid` other than 6), or a singular reduced mass matrix.
pub(crate) fn exact_rigid_modes<S: Structure>(
    model: &S,
    q: &[f64],
    lin: &genalpha::analysis::Linearisation,
    n_rigid: usize,
    phi: &mut DMatrix<f64>,
) -> Result<(), String> {
    if n_rigid != 6 || phi.ncols() <= n_rigid {
        return Err(format!("stability about a trim needs one free body ({n_rigid} rigid-body motions)"));
    }
    let n = model.n_dof();
    let mut j = DMatrix::zeros(n, 6);
    let mut e = vec![0.0; n];
    for i in 0..n {
        e[i] = 1.0;
        let m = model.momentum(q, &e);
        e[i] = 0.0;
        for k in 0..3 {
            j[(i, k)] = m.linear[k];
            j[(i, 3 + k)] = m.angular[k];
        }
    }
    let nn = &lin.null_space;
    let reduced = nn.transpose() * &lin.mass * nn;
    let chol = reduced.cholesky().ok_or("the free aircraft's reduced mass matrix is not positive definite")?;
    let mut r = nn * chol.solve(&(nn.transpose() * j));
    // Mass-orthonormal: R ← R L⁻ᵀ with RᵀMR = L Lᵀ.
    let g = r.transpose() * &lin.mass * &r;
    let lg = g.cholesky().ok_or("the rigid-body motions are not independent")?.l();
    let inv = lg.transpose().try_inverse().ok_or("the rigid-body motions are not independent")?;
    r = &r * inv;
    let mr = &lin.mass * &r;
    for c in 0..phi.ncols() {
        if c < n_rigid {
            phi.set_column(c, &r.column(c));
            continue;
        }
        let mut v = phi.column(c).into_owned();
        v -= &r * (mr.transpose() * &v);
        let norm = v.dot(&(&lin.mass * &v)).max(1e-300).sqrt();
        phi.set_column(c, &(v / norm));
    }
    Ok(())
}
