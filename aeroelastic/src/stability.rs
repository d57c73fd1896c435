//! Linearised aeroelastic stability about a static equilibrium (docs/stability.md).
//!
//! At each airspeed of the case's `stability` block:
//!
//! 1. **Equilibrium**: the static aeroelastic equilibrium of [`crate::statics`] (or the
//!    undeformed reference configuration, `"about": "undeformed"`), with its multipliers.
//! 2. **Structure**: the generic linearisation `M, C, K` of `genalpha::analysis::linearise`
//!    about it (gravity, springs, dampers and the constraint forces' geometric stiffness), the
//!    constraints eliminated by the null-space basis, and a basis of its first `n_b` natural
//!    modes `Φ` (mass-normalised).
//! 3. **Aerodynamics**: the UVLM linearised about the steady solution on the equilibrium's
//!    lattice ([`uvlm::LinearUvlm`], Laplace domain, frozen wake, the wake's delays exact), coupled
//!    to the structure through the same seam as the time-domain coupling: the lattice follows the
//!    structure's stations, and the nodal forces are lumped to station loads and applied by the
//!    formulation's own `set_section_loads`. The geometric terms (how moving along a mode moves
//!    the lattice, its normals and its force arms, and how a formulation turns station loads into
//!    generalised forces at a moved state) are central differences along the modes.
//! 4. **Flutter equation** in the modal coordinates `η`:
//!
//!    $$ D(s)\,\eta = \Big[M s^2 + C s + K + G_x + s\,G_{\dot x}
//!    - T(s)\,N(s)^{-1}\big(R_x + s\,R_{\dot x}\big)\Big]\eta = 0 ,$$
//!
//!    `N(s) = A + Σ_k e^{−sτ_k} W_k E` the non-penetration operator, `T(s)` the generalised load
//!    of the circulations (Joukowski, unsteady term and wake). Its roots are found per mode by
//!    Newton's method on `(η, s)` (the p-method; no reduced-frequency approximation), continued
//!    over the airspeeds from the structural modes.
//! 5. **Flutter** where a root's real part changes sign (interpolated linearly between airspeeds);
//!    **divergence** where `det D(0)` (the static aeroelastic stiffness) changes sign: a real
//!    eigenvalue of `M⁻¹D(0)` passes through zero (located by bisection on the model).

use std::time::Instant;

use nalgebra::{Complex, DMatrix, DVector, Vector3};

use formulation::Structure;

use crate::aero::{AeroSettings, SectionLoad, StationMap, StationScratch, station_map, stations_at};
use crate::factory::{BuildModel, ForModel, dispatch};
use crate::polar_correction::StripPolars;
use crate::problem::{Formulation, Problem};

pub use crate::stability_settings::{
    About, AeroModel, MAX_LINEAR_WAKE_RINGS, MAX_STABILITY_POINTS, StabilitySettings, WakeSettings,
};

type C64 = Complex<f64>;

/// One root of the flutter equation at one airspeed.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Root {
    /// Index of the structural mode it was continued from (0 = lowest).
    pub mode: usize,
    /// Real part of s, 1/s.
    pub real: f64,
    /// Imaginary part of s, rad/s.
    pub imag: f64,
    /// Whether Newton's method converged.
    pub converged: bool,
}

impl Root {
    /// Damped frequency, Hz.
    pub fn frequency_hz(&self) -> f64 {
        self.imag / (2.0 * std::f64::consts::PI)
    }
    /// Damping ratio `−Re s / |s|`.
    pub fn damping_ratio(&self) -> f64 {
        let n = self.real.hypot(self.imag);
        if n > 0.0 { -self.real / n } else { 0.0 }
    }
}

/// One airspeed of a stability sweep.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct StabilityPoint {
    /// Airspeed, m/s.
    pub airspeed: f64,
    /// Fold angle of the equilibrium, degrees (NaN without a fold hinge).
    pub fold_deg: f64,
    /// Tracked roots, one per mode.
    pub roots: Vec<Root>,
    /// About a trim: the free aircraft's rigid-body roots (phugoid, short period, Dutch roll,
    /// roll subsidence, spiral; docs/stability.md §9). Empty otherwise.
    pub flight_roots: Vec<crate::flight_modes::FlightRoot>,
    /// Smallest real eigenvalue of `M⁻¹ D(0)` (rad²/s²): negative past divergence, and also
    /// where a complex pair of the non-symmetric static stiffness has split into two negative
    /// real eigenvalues without a static divergence (a swept-back wing, docs/stability.md §3).
    pub static_stiffness_min: f64,
    /// Structural natural frequencies about this equilibrium (no aerodynamics), rad/s.
    pub structural_rad_s: Vec<f64>,
    /// Why the point could not be analysed.
    pub error: Option<String>,
}

/// A formulation's stability sweep.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct StabilityOutput {
    /// Formulation.
    pub formulation: Formulation,
    /// One point per airspeed.
    pub points: Vec<StabilityPoint>,
    /// Flutter speed, m/s (the first crossing in the sweep), if any.
    pub flutter_speed: Option<f64>,
    /// Flutter frequency, rad/s.
    pub flutter_frequency_rad_s: Option<f64>,
    /// Mode that flutters.
    pub flutter_mode: Option<usize>,
    /// Divergence speed, m/s, if any.
    pub divergence_speed: Option<f64>,
    /// Tangent unknowns of the structure.
    pub n_dof: usize,
    /// Free motions (null space of the constraints).
    pub n_free: usize,
    /// Structural modes in the basis.
    pub n_basis: usize,
    /// Bound rings of the lattice.
    pub n_rings: usize,
    /// Wake rings of the frozen wake.
    pub n_wake_rings: usize,
    /// Evaluations of `D(s)` in the root searches.
    pub n_evaluations: usize,
    /// CPU time spent building the reduced models (equilibria excluded), s.
    pub build_s: f64,
    /// CPU time spent in the root searches, s.
    pub solve_s: f64,
    /// Wall time of the whole sweep, s.
    pub wall_s: f64,
    /// Mode shapes of the first airspeed's structure: per mode, the displacement of each
    /// station's axis point (x, y, z per station) and the station arclengths.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub shapes: Vec<ModeShape>,
    /// Why the sweep could not start.
    pub error: Option<String>,
}

/// Station displacements of one structural mode.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ModeShape {
    /// Natural frequency, rad/s.
    pub omega: f64,
    /// Wing arclength of each station, m.
    pub s: Vec<f64>,
    /// Displacement of each station's axis point, normalised to a largest component of 1.
    pub displacement: Vec<[f64; 3]>,
}

/// The flutter equation in modal coordinates at one airspeed.
pub struct Reduced {
    m: DMatrix<f64>,
    c: DMatrix<f64>,
    k: DMatrix<f64>,
    /// Aerodynamic parts of the stiffness and damping (geometric terms at fixed circulation).
    gx: DMatrix<f64>,
    gv: DMatrix<f64>,
    /// Airspeed ratio to the one the model was built at: at a fixed geometry every aerodynamic
    /// term scales exactly with a power of it (see [`Reduced::at_speed_ratio`]).
    ratio: f64,
    rx: DMatrix<f64>,
    rv: DMatrix<f64>,
    aic: DMatrix<C64>,
    w_rows: Vec<DMatrix<f64>>,
    delays: Vec<f64>,
    te_rings: Vec<usize>,
    t_gamma: DMatrix<f64>,
    t_gamma_dot: DMatrix<f64>,
    t_rows: Vec<DMatrix<f64>>,
    /// The frozen wake's nodes following the trailing edge's past motion (docs/stability.md
    /// §2.4): per wake row `k`, the residual (n_rings × n_b) and the generalised load (n_b × n_b)
    /// per modal coordinate of the trailing edge `τ_k` earlier. Empty without steady loading.
    wake_r: Vec<DMatrix<f64>>,
    wake_g: Vec<DMatrix<f64>>,
    /// Theodorsen strips instead of the lattice.
    strip: Option<Strips>,
    /// Structural natural frequencies, rad/s (all free motions).
    pub omega: Vec<f64>,
    /// Bound rings.
    pub n_rings: usize,
    /// Wake rings.
    pub n_wake_rings: usize,
    /// The modal basis `Φ` (tangent unknowns × basis modes).
    pub(crate) phi: DMatrix<f64>,
    /// Basis modes the tracked roots start after: a free aircraft's rigid-body modes, whose roots
    /// are found apart ([`crate::flight_modes`]).
    pub(crate) skip: usize,
}

/// Steps of [`Reduced::continuation_path`].
const CONTINUATION_STEPS: usize = 8;

/// The root of the conjugate pair in the upper half plane, with its vector (`D(s̄) = conj D(s)`:
/// the conjugate root's vector is the conjugate vector).
pub(crate) fn upper(s: C64, e: DVector<C64>) -> (C64, DVector<C64>) {
    if s.im < 0.0 { (s.conj(), e.map(|x| x.conj())) } else { (s, e) }
}

/// Largest distance between consecutive roots of a continuation path.
fn largest_step(path: &[(C64, DVector<C64>)]) -> f64 {
    path.windows(2).map(|w| (w[1].0 - w[0].0).norm()).fold(0.0, f64::max)
}

impl Reduced {
    /// The same model at `ratio` times the airspeed it was built at, the geometry (and the wake's
    /// row lengths) held: with the circulations `Γ₀ ∝ U`, `R_x`, `T_Γ`, `T_k` and `G_ẋ` scale with
    /// the ratio, `G_x` with its square, the delays with its inverse, and `R_ẋ`, `T_Γ̇` not at all;
    /// the wake nodes' terms scale as `R_x` (residual) and `G_x` (loads).
    pub fn at_speed_ratio(&mut self, ratio: f64) {
        self.ratio = ratio;
    }

    /// `D(s)` (n_b × n_b).
    pub fn d(&self, s: C64) -> DMatrix<C64> {
        let r = self.ratio;
        if let Some(st) = &self.strip {
            return self.m.map(|x| s * s * x) + self.c.map(|x| s * x) + self.k.map(C64::from)
                - st.generalised_force(s, r);
        }
        let delays: Vec<f64> = self.delays.iter().map(|t| t / r).collect();
        let n = uvlm::with_wake(&self.aic, &self.w_rows, &delays, &self.te_rings, s);
        let t0 = self.t_gamma.map(|x| C64::from(r * x)) + self.t_gamma_dot.map(|x| s * x);
        let mut t = uvlm::with_wake(&t0.map(|x| x / r), &self.t_rows, &delays, &self.te_rings, s);
        t *= C64::from(r);
        let mut rhs = self.rx.map(|x| C64::from(r * x)) + self.rv.map(|x| s * x);
        let mut wake_g = DMatrix::<C64>::zeros(self.m.nrows(), self.m.ncols());
        for ((wr, wg), tau) in self.wake_r.iter().zip(&self.wake_g).zip(&delays) {
            let e = (-s * tau).exp();
            rhs.zip_apply(wr, |a, b| *a += e * (r * b));
            wake_g.zip_apply(wg, |a, b| *a += e * (r * r * b));
        }
        let x = uvlm::solve_complex(&n, &rhs)
            .unwrap_or_else(|| DMatrix::from_element(rhs.nrows(), rhs.ncols(), C64::new(f64::NAN, 0.0)));
        self.m.map(|x| s * s * x)
            + (&self.c + &self.gv * r).map(|x| s * x)
            + (&self.k + &self.gx * (r * r)).map(C64::from)
            + wake_g
            - t * x
    }

    /// The part of `D(s)` at fixed circulations: `M s² + (C + G_ẋ) s + K + G_x` (UVLM models).
    pub(crate) fn structural(&self, s: C64) -> DMatrix<C64> {
        let r = self.ratio;
        self.m.map(|x| s * s * x)
            + (&self.c + &self.gv * r).map(|x| s * x)
            + (&self.k + &self.gx * (r * r)).map(C64::from)
    }

    /// Basis size.
    pub fn n_basis(&self) -> usize {
        self.m.nrows()
    }

    /// The longest delay of the frozen wake at the current speed ratio, s (0 without a wake).
    pub fn longest_delay(&self) -> f64 {
        self.delays.iter().fold(0.0, |a: f64, t| a.max(t / self.ratio))
    }

    /// Starting points of the root searches at the first airspeed: for each of the first `n`
    /// structural modes after the first `skip`, the eigenvalue nearest its structural one (`±iω`, or `+√(−ω²)` for an
    /// unstable static mode) of the quadratic problem `M s² + C s + K + Q(s₀)` with the aerodynamic
    /// part frozen at that structural value `s₀`, and the mode's unit vector.
    pub fn starts(&self, n: usize) -> Vec<(C64, DVector<C64>)> {
        let nb = self.n_basis();
        (self.skip..(self.skip + n).min(nb))
            .map(|m| {
                let w2 = self.omega[m].signum() * self.omega[m] * self.omega[m];
                let s0 = if w2 >= 0.0 { C64::new(0.0, w2.sqrt().max(1e-3)) } else { C64::new((-w2).sqrt(), 0.0) };
                let mut e = DVector::zeros(nb);
                e[m] = C64::new(1.0, 0.0);
                let frozen =
                    self.d(s0) - self.m.map(|x| s0 * s0 * x) - (&self.c + &self.gv * self.ratio).map(|x| s0 * x);
                // Companion form of M s² + C s + K_f: [0 I; −M⁻¹K_f −M⁻¹C].
                let Some(lu) = self.m.map(C64::from).lu().try_inverse() else { return (s0, e) };
                let cc = (&self.c + &self.gv * self.ratio).map(C64::from);
                let mut a = DMatrix::zeros(2 * nb, 2 * nb);
                for i in 0..nb {
                    a[(i, nb + i)] = C64::new(1.0, 0.0);
                }
                a.view_mut((nb, 0), (nb, nb)).copy_from(&(-(&lu * &frozen)));
                a.view_mut((nb, nb), (nb, nb)).copy_from(&(-(&lu * &cc)));
                let Some(ev) = bounded_eigenvalues(a) else { return (s0, e) };
                // Upper half plane only: a real `s₀` is equally far from both members of a
                // conjugate pair, and which one rounding picked must not matter.
                let best = ev
                    .iter()
                    .copied()
                    .filter(|x| x.im >= -1e-9 * x.norm())
                    .min_by(|x, y| (x - s0).norm().total_cmp(&(y - s0).norm()))
                    .unwrap_or(s0);
                // The structural mode's unit vector starts Newton's method and normalises it
                // (`eᴴη = 1`), which keeps it off a nearby root of another mode.
                (best, e)
            })
            .collect()
    }

    /// Smallest real eigenvalue of `M⁻¹ D(0)`.
    pub fn static_stiffness_min(&self) -> f64 {
        let d0 = self.d(C64::new(0.0, 0.0)).map(|x| x.re);
        let Some(a) = self.m.clone().lu().solve(&d0) else { return f64::NAN };
        if !a.iter().all(|x| x.is_finite()) {
            return f64::NAN;
        }
        let Some(ev) = nalgebra::Schur::try_new(a, f64::EPSILON, SCHUR_MAX_ITER).map(|t| t.complex_eigenvalues())
        else {
            return f64::NAN;
        };
        let scale = ev.iter().map(|x| x.norm()).fold(0.0, f64::max).max(1e-300);
        ev.iter().filter(|x| x.im.abs() <= 1e-9 * scale).map(|x| x.re).fold(f64::INFINITY, f64::min)
    }

    /// Sign of `det D(0)` (the static aeroelastic stiffness; `det M > 0`): +1 while every real
    /// eigenvalue of `M⁻¹D(0)` crossed zero an even number of times (a complex pair's product is
    /// positive), −1 past a static divergence, 0 when singular or not finite. From the LU
    /// factors' signs, which neither overflow nor underflow.
    pub fn static_sign(&self) -> f64 {
        let d0 = self.d(C64::new(0.0, 0.0)).map(|x| x.re);
        if !d0.iter().all(|x| x.is_finite()) {
            return 0.0;
        }
        let lu = d0.lu();
        let mut sign: f64 = lu.p().determinant();
        for x in lu.lu_internal().diagonal().iter() {
            if *x == 0.0 {
                return 0.0;
            }
            sign *= x.signum();
        }
        sign
    }

    /// The static divergence between the speed ratios `lo` and `hi` of this model, where
    /// `det D(0)` changes sign from positive to negative: bisection to 1e-12 of the ratio. About
    /// a fixed state `D(0) = K + r² B` exactly; about an equilibrium the geometry is this model's.
    /// `None` when `det D(0)` does not change sign from `lo` to `hi` on this model. The model is
    /// left at `hi`.
    pub fn static_crossing(&mut self, lo: f64, hi: f64) -> Option<f64> {
        self.at_speed_ratio(lo);
        let s_lo = self.static_sign();
        self.at_speed_ratio(hi);
        let s_hi = self.static_sign();
        if !(s_lo > 0.0 && s_hi < 0.0) {
            return None;
        }
        let (mut a, mut b) = (lo, hi);
        while b - a > 1e-12 * hi {
            let m = 0.5 * (a + b);
            self.at_speed_ratio(m);
            if self.static_sign() > 0.0 { a = m } else { b = m }
        }
        self.at_speed_ratio(hi);
        Some(0.5 * (a + b))
    }

    /// Mode `m` followed up from low speed: from its structural start at an eighth of the speed
    /// ratio `target` to `target` in eight equal steps, Newton at each; the roots (upper half
    /// plane) of the steps that converged, in order, ending at `target` when all did. The model
    /// is left at `target`. The fallback for a start that lands on another mode's root.
    pub fn continuation_path(&mut self, m: usize, target: f64, count: &mut usize) -> Vec<(C64, DVector<C64>)> {
        let mut path: Vec<(C64, DVector<C64>)> = Vec::with_capacity(CONTINUATION_STEPS);
        for k in 1..=CONTINUATION_STEPS {
            self.at_speed_ratio(target * k as f64 / CONTINUATION_STEPS as f64);
            let start = match path.last() {
                Some(x) => Some(x.clone()),
                None => self.starts(m + 1).pop(),
            };
            let Some((s0, e0)) = start else { break };
            match self.newton(s0, e0, count) {
                (s, e, true) => path.push(upper(s, e)),
                _ => break,
            }
        }
        self.at_speed_ratio(target);
        path
    }

    /// A root at the current speed ratio that `taken` does not claim, from the points of a
    /// continuation path that did not end on a root of its own: Newton from the last point as
    /// it is (a path cut short), then from the real parts of its points, last first (the mode's
    /// complex pair has split into two over-damped real roots, which a complex path cannot
    /// follow).
    pub fn restart_from_path(
        &self,
        path: &[(C64, DVector<C64>)],
        count: &mut usize,
        taken: impl Fn(C64) -> bool,
    ) -> Option<(C64, DVector<C64>)> {
        let last = path.last().map(|(s, e)| (*s, e.clone()));
        let reals = path.iter().rev().map(|(s, e)| (C64::new(s.re, 0.0), e.clone()));
        last.into_iter().chain(reals).find_map(|(s0, e0)| match self.newton(s0, e0, count) {
            (s, e, true) if !taken(C64::new(s.re, s.im.abs())) => Some(upper(s, e)),
            _ => None,
        })
    }

    /// Newton's method on `D(s) η = 0`, `cᴴ η = 1` from `(s, η)`; returns the root and its vector.
    /// `dD/ds` is a central difference, kept between iterations while they contract (a chord
    /// method: one evaluation of `D` per iteration) and refreshed when they do not.
    ///
    /// `D(s)` is real for real `s`, so from a real start with a real vector every iterate stays
    /// on the real axis and only a real root can be reached. A real start that does not converge
    /// there (the real pair of a statically unstable mode has met and turned complex) is retried
    /// from the start moved off the axis by its own size, `s₀(1 + i)`, with the same vector; so
    /// is one that converges on the real axis farther than half the start's size from it, and
    /// the root nearer the start is kept (the real iteration then jumped to another branch).
    pub fn newton(&self, s: C64, eta: DVector<C64>, count: &mut usize) -> (C64, DVector<C64>, bool) {
        let real_start = s.im == 0.0 && eta.iter().all(|x| x.im == 0.0);
        let e0 = if real_start { Some(eta.clone()) } else { None };
        let off_axis =
            |e0, count: &mut usize| newton_of(|x| self.d(x), C64::new(s.re, s.re.abs().max(1e-3)), e0, count);
        match (newton_of(|x| self.d(x), s, eta, count), e0) {
            ((_, _, false), Some(e0)) => off_axis(e0, count),
            // A real root far from the start may be another branch's (the mode's real pair has
            // met and turned complex, which the real axis cannot follow): the nearer of the two.
            ((r, e, true), Some(e0)) => {
                let far = (r - s).norm() > 0.5 * s.norm().max(1e-3);
                match far.then(|| off_axis(e0, count)) {
                    Some((r2, e2, true)) if (r2 - s).norm() < (r - s).norm() => (r2, e2, true),
                    _ => (r, e, true),
                }
            }
            (found, _) => found,
        }
    }
}

/// Newton's method on `d(s) η = 0`, `cᴴ η = 1` from `(s, η)`, as [`Reduced::newton`], for any
/// matrix function `d` of the basis' size.
pub(crate) fn newton_of(
    d_of: impl Fn(C64) -> DMatrix<C64>,
    mut s: C64,
    mut eta: DVector<C64>,
    count: &mut usize,
) -> (C64, DVector<C64>, bool) {
    let n = eta.len();
    let c = eta.clone() / C64::new(eta.norm_squared().max(1e-300), 0.0);
    let mut dp: Option<DMatrix<C64>> = None;
    let mut last_step = f64::INFINITY;
    for _ in 0..60 {
        let d = d_of(s);
        *count += 1;
        if dp.is_none() {
            let h = 1e-6 * (1.0 + s.norm());
            dp = Some((d_of(s + h) - d_of(s - h)) / C64::new(2.0 * h, 0.0));
            *count += 2;
        }
        let dpm = dp.as_ref().expect("set above");
        let mut j = DMatrix::zeros(n + 1, n + 1);
        j.view_mut((0, 0), (n, n)).copy_from(&d);
        j.view_mut((0, n), (n, 1)).copy_from(&(dpm * &eta));
        for i in 0..n {
            j[(n, i)] = c[i].conj();
        }
        let mut f = DVector::zeros(n + 1);
        f.rows_mut(0, n).copy_from(&(&d * &eta));
        f[n] = c.dotc(&eta) - C64::new(1.0, 0.0);
        let Some(dx) = j.lu().solve(&f) else { return (s, eta, false) };
        eta -= dx.rows(0, n);
        s -= dx[n];
        if !(s.re.is_finite() && s.im.is_finite()) {
            return (s, eta, false);
        }
        let step = dx[n].norm();
        if step <= 1e-10 * (1.0 + s.norm()) {
            return (s, eta, true);
        }
        if step > 0.5 * last_step {
            dp = None;
        }
        last_step = step;
    }
    (s, eta, false)
}

/// Two-dimensional Theodorsen strips at the lattice's stations (Bisplinghoff, Ashley & Halfman
/// §5-6), normal to the beam axis (docs/stability.md §4): per unit length of the axis, with `h`
/// the plunge (down), `θ` the section's pitch (nose up, about its own spanwise axis: torsion on a
/// swept wing) about the axis at `a` semichords aft of mid-chord, `b` the station's semichord
/// (normal to the axis), `U_n = U cos Λ` the free stream's component normal to the axis and
/// `α_n` the effective angle of attack in the normal plane (torsion and bending slope,
/// `α_n = θ − w′ tan Λ`),
///
/// `L = πρb²(ḧ + U_n α̇_n − baθ̈) + 2πρU_n b C W`,
/// `M = πρb²(baḧ + baU_n α̇_n − ½U_n b θ̇ − b²(⅛ + a²)θ̈) + 2πρU_n b²(a + ½) C W`,
/// `W = ḣ + U_n α_n + b(½ − a)θ̇`
///
/// (Theodorsen's with the downwash `ḣ + U_n α_n + (x − ba)θ̇` of a swept section, Barmby,
/// Cunningham & Garrick's without the spanwise derivatives of the twist and of the potential;
/// its static part is Diederich & Budiansky's `L = q c a cos²Λ (θ − w′ tan Λ)`), with R. T.
/// Jones' approximation `C(p) = 1 − 0.165 p/(p + 0.0455) − 0.335 p/(p + 0.3)`, `p = s b / U_n`,
/// valid for complex `s`. At Λ = 0, `α_n = θ` and `U_n = U`: Theodorsen's section. No tip loss.
pub struct Strips {
    /// Upward displacement of each station's axis along the lift direction per modal
    /// coordinate (stations × modes).
    z: DMatrix<f64>,
    /// Nose-up rotation `θ` of each station about its section's spanwise axis per modal
    /// coordinate (stations × modes): the pitch of the section, work-conjugate to `M`.
    theta: DMatrix<f64>,
    /// Effective angle of attack `α_n` of each station per modal coordinate (stations × modes):
    /// the rotation about the lateral axis (perpendicular to the stream, in the wing's plane)
    /// over `cos Λ`.
    alpha: DMatrix<f64>,
    /// Span width of each strip along the axis, m.
    width: Vec<f64>,
    /// Semichord of each strip, m.
    b: Vec<f64>,
    /// Axis position of each strip, semichords aft of mid-chord.
    a: Vec<f64>,
    /// `cos Λ` of each strip (1 unswept).
    cos_sweep: Vec<f64>,
    /// Lift slope of each strip over 2π: the section polar's `cl'` at the strip's effective
    /// incidence in the corrected steady state (1 without a polar).
    slope: Vec<f64>,
    rho: f64,
    speed: f64,
}

impl Strips {
    /// Generalised aerodynamic force (modes × modes) at `s`, airspeed `ratio` × the built one.
    fn generalised_force(&self, s: C64, ratio: f64) -> DMatrix<C64> {
        let rho = self.rho;
        let pi = std::f64::consts::PI;
        let nb = self.z.ncols();
        let mut q = DMatrix::zeros(nb, nb);
        for j in 0..self.width.len() {
            let (w, b, a) = (self.width[j], self.b[j], self.a[j]);
            // The circulatory lift's `2π`, the polar's slope with polars (`2π · 1` is exact).
            let two_pi = 2.0 * pi * self.slope[j];
            let u = self.speed * ratio * self.cos_sweep[j];
            let p = s * b / u;
            // Without normal flow (`U_n = 0`, a strip along the stream) the circulatory terms
            // vanish with `U_n`; `C` is then only kept finite.
            let c = if u != 0.0 {
                C64::new(1.0, 0.0) - 0.165 * p / (p + 0.0455) - 0.335 * p / (p + 0.3)
            } else {
                C64::new(1.0, 0.0)
            };
            for k in 0..nb {
                let h = C64::from(-self.z[(j, k)]);
                let th = C64::from(self.theta[(j, k)]);
                let al = C64::from(self.alpha[(j, k)]);
                let circ = c * (s * h + u * al + b * (0.5 - a) * s * th);
                let l = pi * rho * b * b * (s * s * h + u * s * al - b * a * s * s * th) + two_pi * rho * u * b * circ;
                // `baU_n α̇_n − ½U_n b θ̇` written as Theodorsen's `−U_n b(½ − a)θ̇` plus the
                // bending slope's part `baU_n(α̇_n − θ̇)`, which vanishes unswept.
                let m = pi
                    * rho
                    * b
                    * b
                    * (b * a * s * s * h - u * b * (0.5 - a) * s * th + b * a * u * s * (al - th)
                        - b * b * (0.125 + a * a) * s * s * th)
                    + two_pi * rho * u * b * b * (a + 0.5) * circ;
                for i in 0..nb {
                    q[(i, k)] += w * (l * self.z[(j, i)] + m * self.theta[(j, i)]);
                }
            }
        }
        q
    }
}

/// Generalised load `r(q, L) − r(q, 0)` of station loads `loads` at `q`; the model's refusal of
/// a load names its station.
///
/// `r` is affine in the loads, so the difference is taken with the loads scaled by
/// [`LOAD_SCALE`] and divided back: the internal forces common to both residuals (up to 1e5 N in
/// ANCF's axial terms at a 1 N load) then round at `2⁻²⁰` of their share, and the load part
/// keeps its own precision. The scale is a power of two, so the scaling itself is exact.
pub(crate) fn load_part<S: Structure>(
    model: &mut S,
    q: &[f64],
    loads: &[SectionLoad],
    zero: &[SectionLoad],
) -> Result<Vec<f64>, String> {
    let n = model.n_dof();
    let z = vec![0.0; n];
    let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
    let scaled: Vec<SectionLoad> = loads
        .iter()
        .map(|l| SectionLoad { force: l.force * LOAD_SCALE, moment: l.moment * LOAD_SCALE, ..*l })
        .collect();
    model.set_section_loads(&scaled).map_err(|e| e.to_string())?;
    model.residual_inplace(0.0, q, &z, &z, &mut a);
    model.set_section_loads(zero).map_err(|e| e.to_string())?;
    model.residual_inplace(0.0, q, &z, &z, &mut b);
    Ok(a.iter().zip(&b).map(|(x, y)| (x - y) / LOAD_SCALE).collect())
}

/// The factor of [`load_part`]'s scaled loads, `2²⁰`.
const LOAD_SCALE: f64 = 1_048_576.0;

/// Step of [`held_load_stiffness`]'s differences, m in the increment weights: the held loads'
/// generalised force is a smooth function of the coordinates (no lattice in it), so fourth-order
/// differences can take a step where their round-off is small.
const HELD_STEP: f64 = 1e-4;

/// Stiffness `∂(r(q, L₀) − r(q, 0))/∂q` of the steady station loads `L₀` of the lattice at `q`
/// (corrected by `polars`) held fixed (five-point central differences along the retraction);
/// `None` when they vanish.
fn held_load_stiffness<S: Structure>(
    model: &mut S,
    q: &[f64],
    (map, aero, polars): (&[StationMap], &AeroSettings, Option<&StripPolars>),
    zero: &[SectionLoad],
) -> Result<Option<DMatrix<f64>>, String> {
    let n = model.n_dof();
    let Some(l0) = steady_station_loads(&*model, q, map, aero, None, polars)? else { return Ok(None) };
    let mut k = DMatrix::zeros(n, n);
    let mut qq = vec![0.0; q.len()];
    let mut dq = vec![0.0; n];
    for j in 0..n {
        let h = HELD_STEP / model.increment_weight(j).max(1e-12);
        let mut at = |m: f64| -> Result<Vec<f64>, String> {
            dq.fill(0.0);
            dq[j] = m * h;
            model.retract_inplace(q, &dq, &mut qq);
            load_part(model, &qq, &l0, zero)
        };
        let (p1, m1, p2, m2) = (at(1.0)?, at(-1.0)?, at(2.0)?, at(-2.0)?);
        for i in 0..n {
            k[(i, j)] = (8.0 * (p1[i] - m1[i]) - (p2[i] - m2[i])) / (12.0 * h);
        }
    }
    Ok(Some(k))
}

/// The steady station loads of the lattice at `q` with `wake` (default: semi-infinite legs),
/// corrected by `polars` as the statics correct them (each strip in the free stream); `None`
/// when they vanish.
pub(crate) fn steady_station_loads<S: Structure>(
    model: &S,
    q: &[f64],
    map: &[StationMap],
    aero: &AeroSettings,
    wake: Option<uvlm::SteadyWake>,
    polars: Option<&StripPolars>,
) -> Result<Option<Vec<SectionLoad>>, String> {
    let zeros = vec![0.0; model.n_dof()];
    let mut scratch = crate::aero::StationScratch::default();
    let (mut stations, mut vel) = (Vec::new(), Vec::new());
    stations_at(model, q, &zeros, map, aero, None, &mut scratch, &mut stations, &mut vel);
    let mut params = aero.uvlm_params(aero.free_stream());
    if let Some(w) = wake {
        params.steady_wake = w;
    }
    let mut uv =
        crate::lifting::new_uvlm(map, aero, &stations, params).map_err(|e| format!("aerodynamic lattice: {e}"))?;
    let loads = uv.solve_steady().map_err(|e| format!("steady aerodynamics: {e}"))?;
    if loads.nodal.iter().flatten().all(|x| *x == 0.0) {
        return Ok(None);
    }
    let f: Vec<f64> = loads.nodal.iter().flatten().copied().collect();
    let origins: Vec<[f64; 3]> = stations.iter().map(|x| x.origin.into()).collect();
    let mut out = lump(map, aero, &loads.positions, &origins, &f);
    if let Some(p) = polars {
        let v = Vector3::from(aero.free_stream());
        p.correct(&stations, map, loads, |_, _| v, 1.0, &mut out, &mut Default::default())?;
    }
    Ok(Some(out))
}

/// Station loads of stacked nodal forces `f` at `positions`, lumped about `origins` (the
/// lattice's own lumping, [`uvlm::lump_columns`]), surface by surface: the nodes of the
/// surfaces' grids follow each other in surface order.
pub(crate) fn lump(
    map: &[StationMap],
    aero: &AeroSettings,
    positions: &[[f64; 3]],
    origins: &[[f64; 3]],
    f: &[f64],
) -> Vec<SectionLoad> {
    let nodal: Vec<[f64; 3]> = f.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let mut force = vec![[0.0; 3]; origins.len()];
    let mut moment = vec![[0.0; 3]; origins.len()];
    let ranges = crate::lifting::surface_ranges(map);
    if let [_] = ranges.as_slice() {
        uvlm::lump_columns(positions, &nodal, origins, &mut force, &mut moment);
    } else {
        let mut node0 = 0;
        for (k, r) in ranges.into_iter().enumerate() {
            let nodes = node0..node0 + (crate::lifting::n_chordwise_of(aero, k) + 1) * r.len();
            let (pos, nod) = (&positions[nodes.clone()], &nodal[nodes.clone()]);
            uvlm::lump_columns(pos, nod, &origins[r.clone()], &mut force[r.clone()], &mut moment[r]);
            node0 = nodes.end;
        }
    }
    map.iter()
        .zip(force.iter().zip(&moment))
        .map(|(m, (f, mo))| SectionLoad { body: m.body, s: m.s, force: Vector3::from(*f), moment: Vector3::from(*mo) })
        .collect()
}

/// Zero station loads at the stations of `map`.
pub(crate) fn zero_loads(map: &[StationMap]) -> Vec<SectionLoad> {
    map.iter()
        .map(|m| SectionLoad { body: m.body, s: m.s, force: Vector3::zeros(), moment: Vector3::zeros() })
        .collect()
}

/// Column `i` of the modal basis `phi`, and the step along it for central differences: the
/// largest coordinate moves by `1e-6 · length`.
pub(crate) fn mode_step(phi: &DMatrix<f64>, i: usize, length: f64) -> (Vec<f64>, f64) {
    let col: Vec<f64> = phi.column(i).iter().copied().collect();
    let big = col.iter().fold(0.0_f64, |a, x| a.max(x.abs())).max(1e-300);
    (col, 1e-6 * length / big)
}

/// The structural part of a reduction: the first basis modes and the modal matrices.
struct ModalBasis {
    /// The modes `Φ` (tangent unknowns × basis modes), mass-normalised.
    phi: DMatrix<f64>,
    /// `Φᵀ M Φ`, `Φᵀ C Φ` and `Φᵀ K Φ` of the unloaded structure.
    m: DMatrix<f64>,
    c: DMatrix<f64>,
    k: DMatrix<f64>,
    /// Natural frequencies of all free motions, rad/s.
    omega: Vec<f64>,
}

/// The first `nb` (at most the free motions) natural modes of `model` about `(q, λ, μ)` under
/// the steady station loads of the lattice held fixed, and the modal matrices of the unloaded
/// structure. With `n_rigid` rigid-body modes (a free aircraft), the first `n_rigid` are replaced
/// by the exact rigid-body motions, which the held loads and gravity otherwise mix with
/// elastic deformation.
fn modal_basis<S: Structure>(
    model: &mut S,
    q: &[f64],
    (lambda, mu): (&[f64], &[f64]),
    lattice: (&[StationMap], &AeroSettings, Option<&StripPolars>),
    zero_loads: &[SectionLoad],
    (nb, n_rigid): (usize, usize),
) -> Result<ModalBasis, String> {
    let mut lin =
        genalpha::analysis::linearise(&*model, 0.0, q, lambda, mu).map_err(|e| format!("linearisation: {e}"))?;
    // The structural modes are those of the structure under its equilibrium's steady station
    // loads held fixed (their stiffness as each formulation applies them), so that they describe a
    // state in equilibrium; the flutter equation itself takes every aerodynamic term from the
    // geometric differences (the held-load stiffness is part of them).
    let held = held_load_stiffness(model, q, lattice, zero_loads)?;
    if let Some(kl) = &held {
        lin.stiffness += kl;
        lin.reduced_stiffness = lin.null_space.transpose() * &lin.stiffness * &lin.null_space;
    }
    let modes = lin.natural_modes().map_err(|e| format!("natural modes: {e}"))?;
    if let Some(kl) = &held {
        // Back to the unloaded structure's stiffness for the flutter equation.
        lin.stiffness -= kl;
    }
    let nb = nb.min(lin.n_free());
    let mut phi = modes.shapes.columns(0, nb).into_owned();
    if n_rigid > 0 {
        crate::flight_modes::exact_rigid_modes(&*model, q, &lin, n_rigid, &mut phi)?;
    }
    let m = phi.transpose() * &lin.mass * &phi;
    let c = phi.transpose() * &lin.damping * &phi;
    let k = phi.transpose() * &lin.stiffness * &phi;
    Ok(ModalBasis { phi, m, c, k, omega: modes.omega.clone() })
}

/// The shapes of the basis modes for the report: the stations' displacement along each mode
/// (a forward difference of `1e-6` span), scaled to a largest component of 1.
fn mode_shapes<S: Structure>(
    model: &mut S,
    q: &[f64],
    stations: &[uvlm::SpanStation],
    basis: &ModalBasis,
    (map, aero, case): (&[StationMap], &AeroSettings, &Problem),
) -> Vec<ModeShape> {
    let zeros = vec![0.0; model.n_dof()];
    let mut scratch = StationScratch::default();
    let span = case.span().max(1e-3);
    let mut out = Vec::with_capacity(basis.phi.ncols());
    for i in 0..basis.phi.ncols() {
        let (col, eps) = mode_step(&basis.phi, i, span);
        let mut qp = vec![0.0; q.len()];
        let dq: Vec<f64> = col.iter().map(|x| eps * x).collect();
        model.retract_inplace(q, &dq, &mut qp);
        let (mut st2, mut v2) = (Vec::new(), Vec::new());
        stations_at(&*model, &qp, &zeros, map, aero, None, &mut scratch, &mut st2, &mut v2);
        let mut d: Vec<[f64; 3]> =
            st2.iter().zip(stations).map(|(a, b)| ((a.origin - b.origin) / eps).into()).collect();
        let dm = d.iter().flatten().fold(0.0_f64, |a, x| a.max(x.abs())).max(1e-300);
        d.iter_mut().flatten().for_each(|x| *x /= dm);
        out.push(ModeShape { omega: basis.omega[i], s: map.iter().map(|x| x.arc).collect(), displacement: d });
    }
    out
}

/// Theodorsen strips at the stations: each station's plunge, pitch and effective angle of attack
/// along each basis mode (central differences of the stations), and each strip's width, semichord,
/// axis position and sweep.
fn strip_model<S: Structure>(
    model: &mut S,
    q: &[f64],
    stations: &[uvlm::SpanStation],
    phi: &DMatrix<f64>,
    (map, aero, case): (&[StationMap], &AeroSettings, &Problem),
    slope: Vec<f64>,
) -> Strips {
    let zeros = vec![0.0; model.n_dof()];
    let mut scratch = StationScratch::default();
    let nb = phi.ncols();
    let stream = Vector3::from(aero.free_stream()).normalize();
    let lift = crate::statics::lift_direction(aero.free_stream());
    let ns = map.len();
    // Per station: the section's nose-up axis (the leading-edge direction turned towards the
    // lift: the beam axis of a planar wing) and its part perpendicular to the stream, the lateral
    // axis scaled by cos Λ (Λ the angle between the two, positive aft).
    let axes: Vec<(Vector3<f64>, Vector3<f64>)> = stations
        .iter()
        .map(|st| {
            let axis = st.frame.column(1).cross(&lift).normalize();
            (axis, axis - stream * axis.dot(&stream))
        })
        .collect();
    let (mut z, mut theta, mut alpha) = (DMatrix::zeros(ns, nb), DMatrix::zeros(ns, nb), DMatrix::zeros(ns, nb));
    let span_len = case.span().max(1e-3);
    for i in 0..nb {
        let (col, eps) = mode_step(phi, i, span_len);
        let mut pm = Vec::new();
        for sg in [1.0, -1.0] {
            let mut qq = vec![0.0; q.len()];
            let dq: Vec<f64> = col.iter().map(|x| sg * eps * x).collect();
            model.retract_inplace(q, &dq, &mut qq);
            let (mut s2, mut v2) = (Vec::new(), Vec::new());
            stations_at(&*model, &qq, &zeros, map, aero, None, &mut scratch, &mut s2, &mut v2);
            pm.push(s2);
        }
        for (j, (axis, lateral)) in axes.iter().enumerate() {
            let d = (pm[0][j].origin - pm[1][j].origin) / (2.0 * eps);
            let w = (pm[0][j].frame - pm[1][j].frame) * stations[j].frame.transpose() / (2.0 * eps);
            let rot = Vector3::new(w[(2, 1)] - w[(1, 2)], w[(0, 2)] - w[(2, 0)], w[(1, 0)] - w[(0, 1)]) * 0.5;
            z[(j, i)] = d.dot(&lift);
            theta[(j, i)] = rot.dot(axis);
            // The streamwise angle of attack `rot · e_lat` (torsion cos Λ and bending slope
            // −w′ sin Λ) over cos Λ: the normal section's `θ − w′ tan Λ`.
            // A section whose axis lies along the stream sees no normal flow (cos Λ = 0) and no
            // incidence.
            let cos2 = lateral.norm_squared();
            alpha[(j, i)] = if cos2 > 0.0 { rot.dot(lateral) / cos2 } else { 0.0 };
        }
    }
    // Each station's share of its lifting surface's span: half the way to each neighbour on the
    // same surface.
    let same = |j: usize, k: usize| map[j].lifting == map[k].lifting;
    let width = (0..ns)
        .map(|j| {
            let lo = if j > 0 && same(j, j - 1) { 0.5 * (map[j].arc - map[j - 1].arc) } else { 0.0 };
            let hi = if j + 1 < ns && same(j, j + 1) { 0.5 * (map[j + 1].arc - map[j].arc) } else { 0.0 };
            lo + hi
        })
        .collect();
    let b: Vec<f64> = stations.iter().map(|st| 0.5 * st.chord).collect();
    let a = stations.iter().zip(&b).map(|(st, b)| (st.le_offset - b) / b).collect();
    let cos_sweep = axes.iter().map(|(_, lateral)| lateral.norm()).collect();
    Strips { z, theta, alpha, width, b, a, cos_sweep, slope, rho: aero.rho, speed: aero.airspeed.unwrap_or(0.0) }
}

/// Each station's lift slope over 2π for the Theodorsen strips (docs/stability.md §4.2): the
/// mean of the polar's `cl'` over the lattice strips on either side of the station (strips
/// without a polar left out), each at its effective incidence in the corrected steady solution
/// of the lattice `la` (each strip in the free stream, as the statics' equilibrium); 1 where no
/// strip beside the station has a polar, and everywhere without `polars`.
fn strip_slopes(
    polars: Option<&StripPolars>,
    stations: &[uvlm::SpanStation],
    (map, aero): (&[StationMap], &AeroSettings),
    la: Option<&uvlm::LinearUvlm>,
) -> Result<Vec<f64>, String> {
    let ns = stations.len();
    let (Some(p), Some(la)) = (polars, la) else { return Ok(vec![1.0; ns]) };
    let strips: Vec<[f64; 3]> = la.reference_strips.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let v_inf = Vector3::from(aero.free_stream());
    let mut out = zero_loads(map);
    let mut report = crate::polar_correction::StripReport::default();
    p.correct_strips(stations, map, &strips, |_, _| v_inf, 1.0, &mut out, &mut report)?;
    let two_pi = 2.0 * std::f64::consts::PI;
    Ok((0..ns)
        .map(|j| {
            let beside = [j.checked_sub(1), Some(j)];
            let k: Vec<f64> = beside
                .iter()
                .flatten()
                .filter_map(|&i| report.cl_slope.get(i).copied())
                .filter(|x| x.is_finite())
                .collect();
            if k.is_empty() { 1.0 } else { k.iter().sum::<f64>() / (two_pi * k.len() as f64) }
        })
        .collect())
}

/// The load maps of a lattice `la` on `model` at `q`: the lumping `C_l` (6·stations × nodal
/// forces: a unit force on each lattice node lumped about `origins` into `[F, M]` per station)
/// and `H = Φᵀ P C_l` (basis modes × nodal forces), `P` the generalised load part per unit
/// station load, and `Φᵀ P` (basis modes × 6·stations). Both rely on the linearity of the load
/// part in the station loads and of the lumping in the nodal forces. Stability and the linear
/// gust response share it.
pub(crate) fn load_maps<S: Structure>(
    model: &mut S,
    q: &[f64],
    phi: &DMatrix<f64>,
    (map, aero): (&[StationMap], &AeroSettings),
    zero_loads: &[SectionLoad],
    la: &uvlm::LinearUvlm,
    origins: &[[f64; 3]],
) -> Result<[DMatrix<f64>; 3], String> {
    let (nf, ns) = (la.n_force(), map.len());
    let ref_pos: Vec<[f64; 3]> = la.lattices().iter().flat_map(|l| l.ring_nodes().iter().copied()).collect();
    let mut cl = DMatrix::zeros(6 * ns, nf);
    let mut unit = vec![0.0; nf];
    for a in 0..nf {
        unit.fill(0.0);
        unit[a] = 1.0;
        for (j, sl) in lump(map, aero, &ref_pos, origins, &unit).iter().enumerate() {
            for comp in 0..3 {
                cl[(6 * j + comp, a)] = sl.force[comp];
                cl[(6 * j + 3 + comp, a)] = sl.moment[comp];
            }
        }
    }
    let mut p = DMatrix::zeros(model.n_dof(), 6 * ns);
    for j in 0..ns {
        for comp in 0..6 {
            let mut l = zero_loads.to_vec();
            if comp < 3 {
                l[j].force[comp] = 1.0;
            } else {
                l[j].moment[comp - 3] = 1.0;
            }
            let g = load_part(model, q, &l, zero_loads)?;
            p.column_mut(6 * j + comp).copy_from_slice(&g);
        }
    }
    let phi_p = phi.transpose() * &p;
    let h = &phi_p * &cl;
    Ok([cl, h, phi_p])
}

/// The lattice of a linear UVLM moved with the structure, its reference circulations held: the
/// residual, nodal forces, station loads and trailing-edge nodes at a moved state (the geometric
/// terms of the stability reduction and of the linear gust response).
pub(crate) struct MovedLattice<'a> {
    la: &'a uvlm::LinearUvlm,
    /// The lattice of each surface.
    lats: Vec<uvlm::Lattice>,
    map: &'a [StationMap],
    aero: &'a AeroSettings,
    /// The section polars whose strip correction the loads get (docs/section_aero.md §7.7).
    polars: Option<&'a StripPolars>,
    scratch: StationScratch,
}

/// What [`MovedLattice::at`] evaluates.
pub(crate) struct Moved {
    /// Non-penetration residual (bound rings).
    pub residual: Vec<f64>,
    /// Stacked nodal forces.
    pub forces: Vec<f64>,
    /// The nodal forces lumped to station loads.
    pub loads: Vec<SectionLoad>,
    /// The section polars' change of the station loads (empty without polars).
    pub correction: Vec<SectionLoad>,
    /// Stacked trailing-edge node positions, surface after surface.
    pub te: Vec<f64>,
}

/// The polars' correction of the station loads at a state moved both ways along a direction
/// ([`MovedLattice::correction_pair`]).
pub(crate) struct CorrectionPair {
    /// The states moved forward and back (the reference state for a velocity).
    pub q_plus: Vec<f64>,
    pub q_minus: Vec<f64>,
    /// The corrections there.
    pub plus: Vec<SectionLoad>,
    pub minus: Vec<SectionLoad>,
    /// The step: the derivative is `(plus − minus) / (2 step)`.
    pub step: f64,
}

impl<'a> MovedLattice<'a> {
    /// The lattice of `la` on the stations of `map`, its loads corrected by `polars`.
    pub(crate) fn new(
        la: &'a uvlm::LinearUvlm,
        map: &'a [StationMap],
        aero: &'a AeroSettings,
        polars: Option<&'a StripPolars>,
    ) -> Self {
        Self { la, lats: la.lattices().to_vec(), map, aero, polars, scratch: StationScratch::default() }
    }

    /// Number of trailing-edge nodes of every surface.
    pub(crate) fn n_te_nodes(&self) -> usize {
        self.la.n_te_nodes()
    }

    /// The linear UVLM.
    pub(crate) fn linear(&self) -> &'a uvlm::LinearUvlm {
        self.la
    }

    /// The largest chord of the lattice, m (the scale of its finite-difference steps).
    pub(crate) fn chord(&self) -> f64 {
        self.aero.chord_extremes().1
    }

    /// The lattice moved to the stations of `model` at `(q, v)`, their velocities counted when
    /// `with_vel`.
    pub(crate) fn at<S: Structure + ?Sized>(
        &mut self,
        model: &S,
        q: &[f64],
        v: &[f64],
        with_vel: bool,
    ) -> Result<Moved, String> {
        let (mut st, mut ve) = (Vec::new(), Vec::new());
        stations_at(model, q, v, self.map, self.aero, None, &mut self.scratch, &mut st, &mut ve);
        let vel = if with_vel { Some(ve.as_slice()) } else { None };
        self.la.move_lattices(&mut self.lats, &st, vel).map_err(|e| format!("aerodynamic lattice: {e}"))?;
        let (residual, forces, strips) = match (self.polars, self.lats.as_slice()) {
            (None, [one]) => self.la.evaluate(one).map(|(r, f)| (r, f, Vec::new())),
            (None, all) => self.la.evaluate_surfaces(all).map(|(r, f)| (r, f, Vec::new())),
            (Some(_), all) => self.la.evaluate_with_strips(all),
        }
        .map_err(|e| e.to_string())?;
        let org: Vec<[f64; 3]> = st.iter().map(|x| x.origin.into()).collect();
        let positions: Vec<[f64; 3]> = self.lats.iter().flat_map(|l| l.ring_nodes().iter().copied()).collect();
        let loads = lump(self.map, self.aero, &positions, &org, &forces);
        let te = self.lats.iter().flat_map(|l| l.trailing_edge_nodes().iter().flatten().copied()).collect();
        let mut correction = Vec::new();
        if let Some(p) = self.polars {
            // Each strip's flow: the free stream less its motion (the mean of its two stations'
            // rigid-arm velocities at its quarter-chord midpoint), as the time march's.
            let v_inf = Vector3::from(self.aero.free_stream());
            let flow = |j: usize, x: Vector3<f64>| match vel {
                Some(v) => {
                    let at = |k: usize| v[k].linear + v[k].angular.cross(&(x - st[k].origin));
                    v_inf - 0.5 * (at(j) + at(j + 1))
                }
                None => v_inf,
            };
            let strip_forces: Vec<[f64; 3]> = strips.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            correction = zero_loads(self.map);
            p.correct_strips(&st, self.map, &strip_forces, flow, 1.0, &mut correction, &mut Default::default())?;
        }
        Ok(Moved { residual, forces, loads, correction, te })
    }

    /// The polars' correction of the station loads about `q` moved forward and back along `dir`,
    /// in position or (`velocity`) in velocity; `None` without polars. The step moves the
    /// coordinates by 1e-4 chord (in velocity: 1e-4 of the airspeed): the correction is a
    /// difference of nearly equal loads (zero for the lattice's own lift line), so the step is
    /// larger than the lattice's 1e-6 chord to keep its rounding (1e-14 of the loads) out of the
    /// derivative, and its truncation is of order 1e-8 (docs/section_aero.md §7.7).
    pub(crate) fn correction_pair<S: Structure + ?Sized>(
        &mut self,
        model: &S,
        q: &[f64],
        dir: &[f64],
        velocity: bool,
    ) -> Result<Option<CorrectionPair>, String> {
        if self.polars.is_none() {
            return Ok(None);
        }
        let big = dir.iter().fold(0.0_f64, |a, x| a.max(x.abs())).max(1e-300);
        let zeros = vec![0.0; dir.len()];
        if velocity {
            let step = 1e-4 * self.aero.speed() / big;
            let (vp, vm): (Vec<f64>, Vec<f64>) = dir.iter().map(|x| (step * x, -step * x)).unzip();
            let plus = self.at(model, q, &vp, true)?.correction;
            let minus = self.at(model, q, &vm, true)?.correction;
            return Ok(Some(CorrectionPair { q_plus: q.to_vec(), q_minus: q.to_vec(), plus, minus, step }));
        }
        let step = 1e-4 * self.chord().max(1e-3) / big;
        let (mut q_plus, mut q_minus) = (vec![0.0; q.len()], vec![0.0; q.len()]);
        let (dp, dm): (Vec<f64>, Vec<f64>) = dir.iter().map(|x| (step * x, -step * x)).unzip();
        model.retract_inplace(q, &dp, &mut q_plus);
        model.retract_inplace(q, &dm, &mut q_minus);
        let plus = self.at(model, &q_plus, &zeros, false)?.correction;
        let minus = self.at(model, &q_minus, &zeros, false)?.correction;
        Ok(Some(CorrectionPair { q_plus, q_minus, plus, minus, step }))
    }
}

/// The geometric terms along each basis mode at fixed circulation: the residual along the
/// position (`rx`) and velocity (`rv`), the modal load along them (`gx`, `gv`) and the
/// trailing-edge nodes along the position (`xte`).
struct Geometric {
    rx: DMatrix<f64>,
    rv: DMatrix<f64>,
    gx: DMatrix<f64>,
    gv: DMatrix<f64>,
    xte: DMatrix<f64>,
}

/// The step of [`geometric_terms`]' position differences: the largest coordinate moves by this
/// fraction of the chord. Fourth-order differences at `1e-4` and `4e-4` chord give every root of
/// the Healy wing to 1e-10 (truncation), and round 100 times less than second-order ones at
/// `1e-6`, which moved the soft fold roots by up to `5e-8` under a change of the equilibrium by
/// rounding (docs/stability.md §1).
const GEOMETRIC_STEP: f64 = 1e-4;

/// [`Geometric`] by fourth-order central differences along each mode of `phi` (a step of
/// [`GEOMETRIC_STEP`] chord).
fn geometric_terms<S: Structure>(
    model: &mut S,
    q: &[f64],
    phi: &DMatrix<f64>,
    moved: &mut MovedLattice<'_>,
    zero_loads: &[SectionLoad],
) -> Result<Geometric, String> {
    let (nr, nb) = (moved.la.n_rings(), phi.ncols());
    let zeros = vec![0.0; model.n_dof()];
    let span = moved.aero.chord_extremes().1.max(1e-3);
    let n_te = 3 * moved.n_te_nodes();
    let mut g = Geometric {
        rx: DMatrix::zeros(nr, nb),
        rv: DMatrix::zeros(nr, nb),
        gx: DMatrix::zeros(nb, nb),
        gv: DMatrix::zeros(nb, nb),
        xte: DMatrix::zeros(n_te, nb),
    };
    // Residual, generalised load part and trailing edge of the moved lattice.
    let eval = |moved: &mut MovedLattice<'_>, model: &mut S, qq: &[f64], vv: &[f64], with_vel: bool| {
        let m = moved.at(&*model, qq, vv, with_vel)?;
        let gl = load_part(model, qq, &m.loads, zero_loads)?;
        Ok::<_, String>((m.residual, gl, m.te))
    };
    // The polars' correction along a position or velocity, apart (its own step).
    let correction = |moved: &mut MovedLattice<'_>, model: &mut S, col: &[f64], velocity: bool| {
        let Some(c) = moved.correction_pair(&*model, q, col, velocity)? else { return Ok(None) };
        let g1 = DVector::from_vec(load_part(model, &c.q_plus, &c.plus, zero_loads)?);
        let g2 = DVector::from_vec(load_part(model, &c.q_minus, &c.minus, zero_loads)?);
        Ok::<_, String>(Some(phi.transpose() * (g1 - g2) / (2.0 * c.step)))
    };
    let mut qq = vec![0.0; q.len()];
    for i in 0..nb {
        let (col, eps) = mode_step(phi, i, GEOMETRIC_STEP / 1e-6 * span);
        // Fourth-order central differences: `(8 (f₁ − f₋₁) − (f₂ − f₋₂)) / 12ε`.
        let (mut rx, mut gx, mut xte) = (vec![0.0; nr], vec![0.0; model.n_dof()], vec![0.0; n_te]);
        for (k, w) in [(1.0, 8.0), (-1.0, -8.0), (2.0, -1.0), (-2.0, 1.0)] {
            let dq: Vec<f64> = col.iter().map(|x| k * eps * x).collect();
            model.retract_inplace(q, &dq, &mut qq);
            let (r, gl, te) = eval(moved, model, &qq, &zeros, false)?;
            let acc = |sum: &mut [f64], f: &[f64]| sum.iter_mut().zip(f).for_each(|(s, f)| *s += w * f);
            acc(&mut rx, &r);
            acc(&mut gx, &gl);
            acc(&mut xte, &te);
        }
        let d = 12.0 * eps;
        g.rx.set_column(i, &(DVector::from_vec(rx) / d));
        g.xte.set_column(i, &(DVector::from_vec(xte) / d));
        let mut gp = phi.transpose() * DVector::from_vec(gx) / d;
        if let Some(c) = correction(moved, model, &col, false)? {
            gp += c;
        }
        g.gx.set_column(i, &gp);
        // Velocity along the mode: the residual and the loads are linear in it.
        let (r1, g1, _) = eval(moved, model, q, &col, true)?;
        let neg: Vec<f64> = col.iter().map(|x| -x).collect();
        let (r2, g2, _) = eval(moved, model, q, &neg, true)?;
        for a in 0..nr {
            g.rv[(a, i)] = 0.5 * (r1[a] - r2[a]);
        }
        let mut gp = phi.transpose() * (DVector::from_vec(g1) - DVector::from_vec(g2)) * 0.5;
        if let Some(c) = correction(moved, model, &col, true)? {
            gp += c;
        }
        g.gv.set_column(i, &gp);
    }
    Ok(g)
}

impl Reduced {
    /// The flutter equation of Theodorsen `strips` on the structure of `basis`.
    fn of_strips(basis: ModalBasis, strips: Strips) -> Self {
        let nb = basis.phi.ncols();
        let e = DMatrix::zeros(0, nb);
        Reduced {
            m: basis.m,
            c: basis.c,
            k: basis.k,
            gx: DMatrix::zeros(nb, nb),
            gv: DMatrix::zeros(nb, nb),
            ratio: 1.0,
            rx: e.clone(),
            rv: e,
            aic: DMatrix::zeros(0, 0),
            w_rows: Vec::new(),
            delays: Vec::new(),
            te_rings: Vec::new(),
            t_gamma: DMatrix::zeros(nb, 0),
            t_gamma_dot: DMatrix::zeros(nb, 0),
            t_rows: Vec::new(),
            wake_r: Vec::new(),
            wake_g: Vec::new(),
            strip: Some(strips),
            omega: basis.omega,
            n_rings: 0,
            n_wake_rings: 0,
            phi: basis.phi,
            skip: 0,
        }
    }
}

/// Build the flutter equation of `model` (no loads applied) about `(q, λ, μ)` at the airspeed of
/// `aero`, with `nb` basis modes (the first `n_rigid` the exact rigid-body motions of a free
/// aircraft): the structural basis, optionally the mode shapes for the
/// report, then either Theodorsen strips (`strip_case`) or the linear UVLM on the equilibrium's
/// lattice with its geometric terms along the modes and the wake nodes' motion, its loads
/// corrected by the section polars `polars` (docs/section_aero.md §7.7).
#[allow(clippy::too_many_arguments)] // model, state, multipliers, stations, settings, wake, basis, outputs
pub fn reduce<S: Structure>(
    mut model: S,
    q: &[f64],
    lambda: &[f64],
    mu: &[f64],
    (map, aero, polars): (&[StationMap], &AeroSettings, Option<&StripPolars>),
    wake: &uvlm::LinearWake,
    (nb, n_rigid): (usize, usize),
    shapes_out: Option<(&Problem, &mut Vec<ModeShape>)>,
    strip_case: Option<&Problem>,
) -> Result<Reduced, String> {
    let zero_loads = zero_loads(map);
    model.set_section_loads(&zero_loads).map_err(|e| e.to_string())?;
    let basis = modal_basis(&mut model, q, (lambda, mu), (map, aero, polars), &zero_loads, (nb, n_rigid))?;
    let zeros = vec![0.0; model.n_dof()];
    let mut scratch = StationScratch::default();
    let (mut stations, mut vel) = (Vec::new(), Vec::new());
    stations_at(&model, q, &zeros, map, aero, None, &mut scratch, &mut stations, &mut vel);
    if let Some((case, out)) = shapes_out {
        out.extend(mode_shapes(&mut model, q, &stations, &basis, (map, aero, case)));
    }
    let lattice = || -> Result<uvlm::LinearUvlm, String> {
        let mut uv = crate::lifting::new_uvlm(map, aero, &stations, aero.uvlm_params(aero.free_stream()))
            .map_err(|e| format!("aerodynamic lattice: {e}"))?;
        uv.linearise(wake).map_err(|e| format!("linear UVLM: {e}"))
    };
    if let Some(case) = strip_case {
        // With polars the strips' slopes are read at the lattice's corrected steady incidences.
        let la = if polars.is_some() { Some(lattice()?) } else { None };
        let slope = strip_slopes(polars, &stations, (map, aero), la.as_ref())?;
        let strips = strip_model(&mut model, q, &stations, &basis.phi, (map, aero, case), slope);
        return Ok(Reduced::of_strips(basis, strips));
    }
    let la = lattice()?;
    let origins: Vec<[f64; 3]> = stations.iter().map(|x| x.origin.into()).collect();
    let [_, h, phi_p] = load_maps(&mut model, q, &basis.phi, (map, aero), &zero_loads, &la, &origins)?;
    // The polars' correction of the circulations' loads: the generalised load per strip force.
    let hc = match polars {
        Some(p) => Some(&phi_p * reference_correction(p, &stations, map, aero, &la)?.load_per_strip_force(&stations)),
        None => None,
    };
    let mut moved = MovedLattice::new(&la, map, aero, polars);
    let geo = geometric_terms(&mut model, q, &basis.phi, &mut moved, &zero_loads)?;
    // The wake's nodes follow the trailing edge's past motion, as the time march sheds them:
    // node (k, j) is where trailing-edge node j was τ_k ago. They matter only where the steady
    // wake carries circulation (its trailing vortices), so an unloaded lattice skips them.
    let (mut wake_r, mut wake_g) = (Vec::new(), Vec::new());
    if la.te_rings.iter().any(|&r| la.gamma0()[r] != 0.0) {
        let wd = la.wake_node_derivatives();
        for (k, (zr, zf)) in wd.residual.iter().zip(&wd.force).enumerate() {
            wake_r.push(zr * &geo.xte);
            let mut g = &h * (zf * &geo.xte);
            if let Some(hc) = &hc {
                g += hc * (&wd.strip[k] * &geo.xte);
            }
            wake_g.push(g);
        }
    }
    // T(s)'s parts: the nodal forces' and, with polars, the strip forces' through the correction.
    let with_strips = |nodal: DMatrix<f64>, strips: &DMatrix<f64>| match &hc {
        Some(hc) => nodal + hc * strips,
        None => nodal,
    };
    let t_rows = la.force_row.iter().zip(&la.strip_row).map(|(f, sf)| with_strips(&h * f, sf)).collect();
    Ok(Reduced {
        m: basis.m,
        c: basis.c,
        k: basis.k,
        gx: geo.gx,
        gv: geo.gv,
        ratio: 1.0,
        rx: geo.rx,
        rv: geo.rv,
        aic: la.aic.map(C64::from),
        w_rows: la.row_normalwash.clone(),
        delays: la.row_delays.clone(),
        te_rings: la.te_rings.clone(),
        t_gamma: with_strips(&h * &la.force_gamma, &la.strip_gamma),
        t_gamma_dot: with_strips(&h * &la.force_gamma_dot, &la.strip_gamma_dot),
        t_rows,
        wake_r,
        wake_g,
        strip: None,
        omega: basis.omega,
        n_rings: la.n_rings(),
        n_wake_rings: wake.row_lengths.len() * la.te_rings.len(),
        phi: basis.phi,
        skip: 0,
    })
}

/// The polars' correction linearised about the reference state of the linear UVLM `la` on
/// `stations` (each strip in the free stream, as the statics' equilibrium).
pub(crate) fn reference_correction(
    polars: &StripPolars,
    stations: &[uvlm::SpanStation],
    map: &[StationMap],
    aero: &AeroSettings,
    la: &uvlm::LinearUvlm,
) -> Result<crate::polar_correction::LinearCorrection, String> {
    let strips: Vec<[f64; 3]> = la.reference_strips.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let v_inf = Vector3::from(aero.free_stream());
    polars.linearise(stations, map, &strips, |_, _| v_inf)
}

/// The linear wake of `case` at `airspeed`: the stability block's, or the time-marching one.
pub fn linear_wake(case: &Problem, f: Formulation, airspeed: f64) -> uvlm::LinearWake {
    let w = wake_settings(case, f, airspeed);
    uvlm::LinearWake::uniform(w.rows, w.row_length, w.closure)
}

/// The time march's wake at `airspeed` with formulation `f`: `aero.n_wake_rows` rows of
/// `airspeed·dt`, closed when `aero.wake_closure`.
pub fn march_wake(case: &Problem, f: Formulation, airspeed: f64) -> WakeSettings {
    let aero = case.aero.as_ref().expect("validated: needs aero");
    let dt = case.block(f).dt;
    WakeSettings { rows: aero.n_wake_rows, row_length: airspeed * dt, closure: aero.wake_closure }
}

/// The frozen wake of [`linear_wake`] as wake settings: the stability block's, or the time
/// march's (`aero.n_wake_rows` rows of `airspeed·dt`, closed when `aero.wake_closure`). The
/// equilibrium the analysis linearises about is that wake's steady state, as the time march's
/// equilibrium is (`static.wake`, docs/statics.md §1).
pub fn wake_settings(case: &Problem, f: Formulation, airspeed: f64) -> WakeSettings {
    case.stability.as_ref().and_then(|s| s.wake).unwrap_or_else(|| march_wake(case, f, airspeed))
}

/// A state a sweep linearises about.
#[derive(Clone)]
struct Equilibrium {
    /// Coordinates, holonomic and velocity multipliers.
    q: Vec<f64>,
    lambda: Vec<f64>,
    mu: Vec<f64>,
    /// Fold angle, degrees (NaN without a fold hinge).
    fold: f64,
    /// About a trim: the free aircraft's problem in body axes (flow and gravity turned by −α,
    /// elevator and thrust trimmed), which the point's model and lattice are built from.
    flight: Option<Box<Problem>>,
}

/// Thread CPU time where the platform has it (so that the cost of a sweep does not depend on
/// the machine's load), else wall time since the first call, s.
fn cpu_now() -> f64 {
    static START: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
    crate::clock::thread_cpu_s().unwrap_or_else(|| START.get_or_init(Instant::now).elapsed().as_secs_f64())
}

/// Run the stability sweep of `case` with formulation `f`.
pub fn run_stability(case: &Problem, f: Formulation) -> StabilityOutput {
    let t0 = Instant::now();
    // A strip tip loss is the statics' alone; the polars are applied (docs/section_aero.md §7.7).
    if let Err(e) = crate::section_polars::refuse_tip_loss(case, "stability analysis") {
        return empty_output(f, Some(e));
    }
    struct Sweep<'a>(&'a Problem, Formulation);
    impl ForModel for Sweep<'_> {
        type Output = StabilityOutput;
        fn run<M: BuildModel>(self) -> StabilityOutput {
            sweep(self.0, self.1, M::build)
        }
    }
    let mut out = dispatch(f, Sweep(case, f));
    out.wall_s = t0.elapsed().as_secs_f64();
    out
}

fn empty_output(f: Formulation, err: Option<String>) -> StabilityOutput {
    StabilityOutput {
        formulation: f,
        points: Vec::new(),
        flutter_speed: None,
        flutter_frequency_rad_s: None,
        flutter_mode: None,
        divergence_speed: None,
        n_dof: 0,
        n_free: 0,
        n_basis: 0,
        n_rings: 0,
        n_wake_rings: 0,
        n_evaluations: 0,
        build_s: 0.0,
        solve_s: 0.0,
        wall_s: 0.0,
        shapes: Vec::new(),
        error: err,
    }
}

/// The stability sweep of `case` with the models of `build`: the equilibria, then per airspeed
/// the reduced model ([`reduce`], built once about a fixed state) and its roots, continued from
/// the previous airspeed's; then the flutter and divergence speeds.
fn sweep<S: Structure>(
    case: &Problem,
    f: Formulation,
    build: fn(&Problem) -> Result<S, crate::Error>,
) -> StabilityOutput {
    let (Some(aero), Some(st)) = (case.aero.as_ref(), case.stability.as_ref()) else {
        return empty_output(f, Some("the case has no `aero` and `stability` blocks".into()));
    };
    let map = match station_map(case, aero) {
        Ok(m) => m,
        Err(e) => return empty_output(f, Some(e)),
    };
    let states = match equilibria(case, f, st, build) {
        Ok(s) => s,
        Err(e) => return empty_output(f, Some(e)),
    };
    let mut out = empty_output(f, None);
    let nb_req = st.basis_modes.unwrap_or((2 * st.modes).max(20));
    // About a trim the free aircraft's rigid-body modes join the basis, and their roots are found
    // apart from the tracked elastic ones (`crate::flight_modes`).
    let n_rigid = if st.about == About::Trim { crate::flight_modes::n_rigid(case) } else { 0 };
    // About a fixed state with a wake of fixed row lengths, the model is built once and scaled
    // with the airspeed (exact, see `Reduced::at_speed_ratio`).
    // With section polars the slopes follow each airspeed's Reynolds numbers: rebuilt at every one.
    let polars = match StripPolars::of(case) {
        Ok(p) => p,
        Err(e) => return empty_output(f, Some(e)),
    };
    let fixed =
        st.about == About::Undeformed && (st.wake.is_some() || st.aerodynamics == AeroModel::Strip) && polars.is_none();
    let mut cache: Option<(f64, Reduced)> = None;
    let mut tracked: Option<Vec<(C64, DVector<C64>)>> = None;
    let mut prev: Option<Vec<(C64, DVector<C64>)>> = None;
    // The last analysed airspeed, its static stiffness and the sign of `det D(0)` there.
    let mut last_static: Option<(f64, f64, f64)> = None;
    for (i, &u) in st.airspeeds.iter().enumerate() {
        let point = |roots: Vec<Root>, smin: f64, omega: Vec<f64>, fold: f64, error: Option<String>| StabilityPoint {
            airspeed: u,
            fold_deg: fold,
            roots,
            flight_roots: Vec::new(),
            static_stiffness_min: smin,
            structural_rad_s: omega,
            error,
        };
        let state = match &states[i] {
            Ok(s) => s,
            Err(e) => {
                out.points.push(point(Vec::new(), f64::NAN, Vec::new(), f64::NAN, Some(e.clone())));
                continue;
            }
        };
        // About a trim the point's own problem: the free aircraft in its body axes.
        let (problem, a) = match state.flight.as_deref() {
            Some(p) => (p, p.aero.clone().unwrap_or_else(|| aero.clone())),
            None => (case, AeroSettings { airspeed: Some(u), ..aero.clone() }),
        };
        if !(fixed && cache.is_some()) {
            let model = match build(problem) {
                Ok(m) => m,
                Err(e) => return empty_output(f, Some(e.to_string())),
            };
            out.n_dof = model.n_dof();
            let tb = cpu_now();
            let wake = linear_wake(case, f, u);
            let shapes = if i == 0 { Some((case, &mut out.shapes)) } else { None };
            let strip = (st.aerodynamics == AeroModel::Strip).then_some(case);
            let nb = nb_req + n_rigid;
            let reduced = reduce(
                model,
                &state.q,
                &state.lambda,
                &state.mu,
                (&map, &a, polars.as_ref()),
                &wake,
                (nb, n_rigid),
                shapes,
                strip,
            )
            .and_then(|r| crate::flight_modes::skip_rigid(r, n_rigid));
            match reduced {
                Ok(r) => cache = Some((u, r)),
                Err(e) => {
                    out.points.push(point(Vec::new(), f64::NAN, Vec::new(), state.fold, Some(e)));
                    cache = None;
                    continue;
                }
            }
            out.build_s += cpu_now() - tb;
        }
        let Some((u0, red)) = cache.as_mut() else { continue };
        let target = u / *u0;
        let nmodes = st.modes.min(red.n_basis() - red.skip);
        let first =
            if tracked.is_none() { Some(first_starts(red, nmodes, target, &mut out.n_evaluations)) } else { None };
        red.at_speed_ratio(target);
        out.n_free = red.omega.len();
        out.n_basis = red.n_basis();
        out.n_rings = red.n_rings;
        out.n_wake_rings = red.n_wake_rings;
        let ts = cpu_now();
        let starts: Vec<(C64, DVector<C64>)> = match (&tracked, &prev) {
            _ if first.is_some() => first.unwrap_or_default(),
            (Some(t), Some(p)) if t.len() == nmodes => extrapolated_starts(t, p, &st.airspeeds, i),
            (Some(t), _) if t.len() == nmodes => t.clone(),
            _ => red.starts(nmodes),
        };
        let found = roots_from(red, starts, target, &mut out.n_evaluations);
        let mut roots = Vec::with_capacity(nmodes);
        let mut next = Vec::with_capacity(nmodes);
        for (m, (s, e, ok)) in found.into_iter().enumerate() {
            roots.push(Root { mode: m, real: s.re, imag: s.im, converged: ok });
            next.push((s, e));
        }
        let smin = red.static_stiffness_min();
        let sign = red.static_sign();
        if let Some((u_a, smin_a, sign_a)) = last_static
            && out.divergence_speed.is_none()
            && sign_a > 0.0
            && sign < 0.0
        {
            out.divergence_speed = Some(divergence_in(red, *u0, (u_a, smin_a), (u, smin)));
        }
        last_static = Some((u, smin, sign));
        out.solve_s += cpu_now() - ts;
        prev = tracked.take();
        tracked = Some(next);
        let omega = red.omega.iter().take(nb_req + n_rigid).copied().collect();
        let mut pt = point(roots, smin, omega, state.fold, None);
        if state.flight.is_some() {
            let ts = cpu_now();
            let motion = build(problem)
                .map(|m| crate::flight_modes::StationMotion::new(&m, &state.q, &red.phi, (&map, &a, problem)));
            match motion {
                Ok(m) => pt.flight_roots = crate::flight_modes::flight_roots(red, n_rigid, &m, &mut out.n_evaluations),
                Err(e) => pt.error = Some(e.to_string()),
            }
            out.solve_s += cpu_now() - ts;
        }
        out.points.push(pt);
    }
    flutter_speed(&mut out);
    out
}

/// The divergence speed between two analysed airspeeds `a` and `b` (with their smallest real
/// static eigenvalues) where `det D(0)` changed sign from positive to negative: the crossing on
/// `red`, the model of `b` built at `u0` (exact about a fixed state); failing that, where the
/// smallest real eigenvalue of `M⁻¹D(0)` changes sign, interpolated linearly; failing that, the
/// bracket's middle.
fn divergence_in(red: &mut Reduced, u0: f64, (ua, smin_a): (f64, f64), (ub, smin_b): (f64, f64)) -> f64 {
    if let Some(r) = red.static_crossing(ua / u0, ub / u0) {
        return u0 * r;
    }
    if smin_a > 0.0 && smin_b <= 0.0 {
        return ua + smin_a / (smin_a - smin_b) * (ub - ua);
    }
    0.5 * (ua + ub)
}

/// The states a sweep linearises about, one per airspeed of `st`: the undeformed state, or the
/// static aeroelastic equilibria (one static sweep per wake; see [`wake_settings`]). An error
/// that stops the whole sweep is `Err`; a point without an equilibrium is an `Err` in the list.
fn equilibria<S: Structure>(
    case: &Problem,
    f: Formulation,
    st: &StabilitySettings,
    build: fn(&Problem) -> Result<S, crate::Error>,
) -> Result<Vec<Result<Equilibrium, String>>, String> {
    Ok(match st.about {
        About::Undeformed => {
            let model = build(case).map_err(|e| e.to_string())?;
            let q = model.initial_state().q;
            let (nh, nv) = (model.n_holonomic(), model.n_velocity_constraints());
            let fold = case.fold_joint_index().map_or(f64::NAN, |j| model.fold(&q, j).to_degrees());
            let state = Equilibrium { q, lambda: vec![0.0; nh], mu: vec![0.0; nv], fold, flight: None };
            st.airspeeds.iter().map(|_| Ok(state.clone())).collect()
        }
        About::Equilibrium => {
            // Each equilibrium is the steady state of the frozen wake linearised about it. The
            // time march's default wake has rows of U·dt, so without closure its length changes
            // with the airspeed: one static solve per airspeed then.
            let wakes: Vec<WakeSettings> = st.airspeeds.iter().map(|&u| wake_settings(case, f, u)).collect();
            let groups: Vec<(Vec<f64>, WakeSettings)> = if wakes.iter().all(|w| w.closure || *w == wakes[0]) {
                vec![(st.airspeeds.clone(), wakes[0])]
            } else {
                st.airspeeds.iter().zip(&wakes).map(|(&u, &w)| (vec![u], w)).collect()
            };
            let mut states = Vec::with_capacity(st.airspeeds.len());
            for (airspeeds, wake) in groups {
                let mut c = case.clone();
                c.statics = Some(crate::problem::StaticSettings::at(airspeeds, Some(wake)));
                let so = crate::statics::run_static(&c, f);
                if let Some(e) = so.error {
                    return Err(e);
                }
                states.extend(so.points.into_iter().map(|p| match (p.state, p.error) {
                    (Some((q, lambda, mu)), None) => Ok(Equilibrium { q, lambda, mu, fold: p.fold_deg, flight: None }),
                    (_, e) => Err(e.unwrap_or_else(|| "no equilibrium".into())),
                }));
            }
            states
        }
        About::Trim => st.airspeeds.iter().map(|&u| trimmed(case, f, u, build)).collect(),
    })
}

/// The trimmed free aircraft at airspeed `u` (the case's `trim` with the analysis's frozen wake),
/// with the multipliers of its start from rest.
fn trimmed<S: Structure>(
    case: &Problem,
    f: Formulation,
    u: f64,
    build: fn(&Problem) -> Result<S, crate::Error>,
) -> Result<Equilibrium, String> {
    let mut c = case.clone();
    // The free aircraft, whatever the case's march starts from (`trim_held` would hold it).
    c.initial = crate::trim::Initial::Reference;
    let (Some(aero), Some(t)) = (c.aero.as_mut(), case.trim.as_ref()) else {
        return Err("stability.about: \"trim\" needs `aero` and `trim`".into());
    };
    aero.airspeed = Some(u);
    let map = station_map(&c, c.aero.as_ref().expect("set above"))?;
    let wake = wake_settings(&c, f, u);
    let mut t = t.clone();
    t.wake = Some(wake);
    let out = crate::trim::run_trim(&c, f, &t);
    if let Some(e) = out.error {
        return Err(format!("the trim at {u} m/s: {e}"));
    }
    let flight = crate::trim::flight_problem(&c, &out);
    let aero = flight.aero.as_ref().ok_or("no aero")?;
    let mut model = build(&flight).map_err(|e| e.to_string())?;
    if let Some(loads) = steady_station_loads(&model, &out.q, &map, aero, Some(wake.steady_wake()), None)? {
        model.set_section_loads(&loads).map_err(|e| e.to_string())?;
    }
    let (lambda, mu) = crate::flight_modes::rest_multipliers(&model, &out.q)?;
    let fold = flight.fold_joint_index().map_or(f64::NAN, |j| model.fold(&out.q, j).to_degrees());
    Ok(Equilibrium { q: out.q, lambda, mu, fold, flight: Some(Box::new(flight)) })
}

/// The starts of the first airspeed's roots (at speed ratio `target`), continued from a quarter
/// of it, where the structural modes are still near their aerodynamically coupled roots (the
/// model scaled at its geometry: exact about a fixed state, a starting guess otherwise).
fn first_starts(red: &mut Reduced, nmodes: usize, target: f64, n_evaluations: &mut usize) -> Vec<(C64, DVector<C64>)> {
    red.at_speed_ratio(0.25 * target);
    let mut guess = red.starts(nmodes);
    for frac in [0.5, 0.75] {
        red.at_speed_ratio(frac * target);
        guess = guess
            .into_iter()
            .map(|(s, e)| match red.newton(s, e.clone(), n_evaluations) {
                (s2, e2, true) => upper(s2, e2),
                _ => (s, e),
            })
            .collect();
    }
    guess
}

/// Starts at airspeed `i` of `airspeeds`: the roots of the last airspeed (`tracked`), linearly
/// extrapolated in airspeed from the one before (`prev`).
fn extrapolated_starts(
    tracked: &[(C64, DVector<C64>)],
    prev: &[(C64, DVector<C64>)],
    airspeeds: &[f64],
    i: usize,
) -> Vec<(C64, DVector<C64>)> {
    let du = airspeeds[i] - airspeeds[i - 1];
    tracked
        .iter()
        .zip(prev)
        .map(|((s1, e1), (s0, _))| {
            let back = airspeeds[i - 1] - airspeeds[i.saturating_sub(2)];
            let slope = if back > 0.0 { (s1 - s0) / back } else { C64::new(0.0, 0.0) };
            (s1 + slope * du, e1.clone())
        })
        .collect()
}

/// Whether two roots are one.
pub(crate) fn same_root(a: C64, b: C64) -> bool {
    (a - b).norm() <= 1e-6 * (1.0 + a.norm())
}

/// The roots (with their vectors and whether they converged) at speed ratio `target`, by
/// Newton's method from `starts`, the doubtful ones followed up from low speed
/// ([`follow_suspects`]); of starts that still share a root, the later one is not converged.
fn roots_from(
    red: &mut Reduced,
    starts: Vec<(C64, DVector<C64>)>,
    target: f64,
    n_evaluations: &mut usize,
) -> Vec<(C64, DVector<C64>, bool)> {
    let mut found: Vec<(C64, DVector<C64>, bool)> = starts
        .into_iter()
        .map(|(s0, e0)| match red.newton(s0, e0.clone(), n_evaluations) {
            (s, e, true) => {
                let (s, e) = upper(s, e);
                (s, e, true)
            }
            _ => (s0, e0, false),
        })
        .collect();
    follow_suspects(red, &mut found, target, n_evaluations);
    // Starts that still share a root: the later one is not a root of its own.
    for m in 0..found.len() {
        if found[m].2 && (0..m).any(|j| found[j].2 && same_root(found[j].0, found[m].0)) {
            found[m].2 = false;
        }
    }
    found
}

/// Starts that do not converge, or that land on one root (a strongly damped mode can jump to a
/// neighbour's root): follow each of those modes up from low speed instead, by continuation to
/// the speed ratio `target`, where it is near its structural root. A path's end is the mode's
/// root unless a mode that was not in doubt holds it, or another path ends there too with
/// smaller steps (the smoother path keeps the root: the other jumped branches); those restart
/// from their paths.
fn follow_suspects(red: &mut Reduced, found: &mut [(C64, DVector<C64>, bool)], target: f64, n_evaluations: &mut usize) {
    let suspects: Vec<usize> = (0..found.len())
        .filter(|&m| !found[m].2 || (0..found.len()).any(|j| j != m && found[j].2 && same_root(found[j].0, found[m].0)))
        .collect();
    if suspects.is_empty() {
        return;
    }
    // The roots the suspects' own starts converged to (a root two starts share among them).
    let first: Vec<(C64, DVector<C64>, bool)> = suspects.iter().map(|&m| found[m].clone()).collect();
    for &m in &suspects {
        found[m].2 = false;
    }
    let paths: Vec<Vec<(C64, DVector<C64>)>> =
        suspects.iter().map(|&m| red.continuation_path(m, target, n_evaluations)).collect();
    // Each path's end at the full speed ratio (None for a path cut short).
    let ends: Vec<Option<C64>> =
        paths.iter().map(|p| p.last().filter(|_| p.len() == CONTINUATION_STEPS).map(|x| x.0)).collect();
    let mut pending = Vec::new();
    for (i, &m) in suspects.iter().enumerate() {
        let keeps = ends[i].is_some_and(|r| {
            !found.iter().any(|f| f.2 && same_root(f.0, r))
                && !(0..suspects.len()).any(|k| {
                    k != i
                        && ends[k].is_some_and(|rk| same_root(rk, r))
                        && (largest_step(&paths[k]), k) < (largest_step(&paths[i]), i)
                })
        });
        match paths[i].last() {
            Some((s, e)) if keeps => found[m] = (*s, e.clone(), true),
            _ => pending.push(i),
        }
    }
    for i in pending {
        let m = suspects[i];
        // A root that this mode's start converged to and no mode holds now is the mode's: its
        // path lost it (a real path cannot follow a statically unstable mode's real pair once
        // the pair has met and turned complex, and jumps to another branch).
        let (s1, e1, ok1) = &first[i];
        if *ok1 && !found.iter().any(|f| f.2 && same_root(f.0, *s1)) {
            found[m] = (*s1, e1.clone(), true);
            continue;
        }
        let claimed = |s: C64| found.iter().any(|f| f.2 && same_root(f.0, s));
        if let Some((s, e)) = red.restart_from_path(&paths[i], n_evaluations, claimed) {
            found[m] = (s, e, true);
        }
    }
}

/// The flutter speed, frequency and mode of a sweep's points: the first sign change of a
/// converged root's real part from negative to positive, interpolated linearly.
fn flutter_speed(out: &mut StabilityOutput) {
    // Flutter: the first sign change of a root's real part from negative to positive.
    for w in out.points.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        if out.flutter_speed.is_some() {
            break;
        }
        let mut best: Option<(f64, f64, usize)> = None;
        for (ra, rb) in a.roots.iter().zip(&b.roots) {
            if ra.converged && rb.converged && ra.real < 0.0 && rb.real >= 0.0 && ra.imag > 1e-6 {
                let t = ra.real / (ra.real - rb.real);
                let v = a.airspeed + t * (b.airspeed - a.airspeed);
                let om = ra.imag + t * (rb.imag - ra.imag);
                if best.is_none_or(|(bv, _, _)| v < bv) {
                    best = Some((v, om, ra.mode));
                }
            }
        }
        if let Some((v, om, m)) = best {
            out.flutter_speed = Some(v);
            out.flutter_frequency_rad_s = Some(om);
            out.flutter_mode = Some(m);
        }
    }
}

/// Iteration bound of the Schur decompositions: nalgebra's plain `eigenvalues()` iterates
/// without bound and never returns on a matrix with a non-finite entry (fuzz: airspeed 1e300
/// made the dynamic pressure infinite and `harness stability` spun for ever).
const SCHUR_MAX_ITER: usize = 10_000;

/// Eigenvalues of `a`, or `None` when `a` has a non-finite entry or the Schur iteration does not
/// converge within [`SCHUR_MAX_ITER`] sweeps.
pub(crate) fn bounded_eigenvalues(a: DMatrix<C64>) -> Option<DVector<C64>> {
    if !a.iter().all(|x| x.re.is_finite() && x.im.is_finite()) {
        return None;
    }
    nalgebra::Schur::try_new(a, f64::EPSILON, SCHUR_MAX_ITER).and_then(|t| t.eigenvalues())
}

/// The static aerodynamic stiffness of the flutter equation about the static equilibrium at the
/// case's airspeed, `D(0) − K` in `nb` basis modes (`linear`), next to central differences along
/// each mode of the generalised steady loads as the statics apply them (the lattice's steady
/// solution in the analysis' wake, corrected by the section polars with
/// [`StripPolars::correct`]; `differences`): the check of the linearised loads and of the
/// polars' slopes in them (docs/section_aero.md §7.7). Modes × modes, `(linear, differences)`.
///
/// # Errors
/// A case without `aero`, a failed equilibrium, reduction or steady solve.
pub fn static_stiffness_check(case: &Problem, f: Formulation, nb: usize) -> Result<[DMatrix<f64>; 2], String> {
    struct Check<'a>(&'a Problem, Formulation, usize);
    impl ForModel for Check<'_> {
        type Output = Result<[DMatrix<f64>; 2], String>;
        fn run<M: BuildModel>(self) -> Self::Output {
            stiffness_check(self.0, self.1, M::build, self.2)
        }
    }
    dispatch(f, Check(case, f, nb))
}

fn stiffness_check<S: Structure>(
    case: &Problem,
    f: Formulation,
    build: fn(&Problem) -> Result<S, crate::Error>,
    nb: usize,
) -> Result<[DMatrix<f64>; 2], String> {
    let aero = case.aero.as_ref().ok_or("the case has no `aero` block")?;
    let map = station_map(case, aero)?;
    let u = aero.speed();
    let ws = wake_settings(case, f, u);
    let p = crate::statics::equilibrium_at(case, f, ws)?;
    let (q, lambda, mu) = p.state.ok_or("no equilibrium state")?;
    let polars = StripPolars::of(case)?;
    let model = build(case).map_err(|e| e.to_string())?;
    let lattice = (map.as_slice(), aero, polars.as_ref());
    let red = reduce(model, &q, &lambda, &mu, lattice, &linear_wake(case, f, u), (nb, 0), None, None)?;
    let linear = red.d(C64::new(0.0, 0.0)).map(|z| z.re) - &red.k;
    let mut model = build(case).map_err(|e| e.to_string())?;
    let zero = zero_loads(&map);
    let span = aero.chord_extremes().1.max(1e-3);
    let mut diff = DMatrix::zeros(red.phi.ncols(), red.phi.ncols());
    for i in 0..red.phi.ncols() {
        let (col, eps) = mode_step(&red.phi, i, span);
        let mut g = Vec::new();
        for sg in [1.0, -1.0] {
            let dq: Vec<f64> = col.iter().map(|x| sg * eps * x).collect();
            let mut qq = vec![0.0; q.len()];
            model.retract_inplace(&q, &dq, &mut qq);
            let loads = steady_station_loads(&model, &qq, &map, aero, Some(ws.steady_wake()), polars.as_ref())?
                .unwrap_or_else(|| zero.clone());
            g.push(DVector::from_vec(load_part(&mut model, &qq, &loads, &zero)?));
        }
        diff.set_column(i, &(red.phi.transpose() * (&g[0] - &g[1]) / (2.0 * eps)));
    }
    Ok([linear, diff])
}
