//! A rotational spring and damper across a hinge (docs/gebf.md §13).
//!
//! **Angle.** Each free hinge has a relative rotation `R_rel` whose ideal form is a rotation by
//! θ about a fixed measurement axis `a'`, written in a frame `X` in which `a'` is constant:
//!
//! * flared hinge: `R_rel = C^{BnG} C^{GAc} (C^{BnAc}_0)ᵀ` in the parent's end section `B_n`,
//!   `a' = −a_B` (θ is the fold angle of conventions.md §4);
//! * ground hinge: `R_rel = (C^{GA}_0)ᵀ C^{GA}` in the reference body frame, `a'` the hinge axis
//!   in A (θ is the body's rotation about its axis, right-handed).
//!
//! With `n₁ ⟂ a'`, `n₂ = a' × n₁` and `u = R_rel n₁`, `θ_p = atan2(n₂·u, n₁·u)`. It is a smooth
//! function of the coordinates except where `u ∥ a'` (90° of axis misalignment). To pass ±180°
//! the model keeps the last accepted angle `θ_last` of every hinge (updated in `post_step`) and
//! uses the unwrapped angle `θ = θ_last + wrap(θ_p − θ_last)`, `wrap` to (−π, π]: inside a step
//! θ changes by far less than π, so θ is smooth there and continuous from step to step.
//!
//! **Variation.** Every tangent perturbation rotates `R_rel` on the left, `δR_rel = δφ̃ R_rel`,
//! with `δφ = Φ δq` (components of X):
//!
//! * flared: `δφ = C_n C_pc δθ_c − C_n δθ_p − T(ψ_n) δψ_n` (the same combination as the hinge's
//!   angular rows, `Φ v = ω_rel`);
//! * ground: `δφ = R_rel δθ_A`.
//!
//! With `P = I − a'a'ᵀ`, `s = uᵀPu` and `g = (a' × u)/s`, `δθ = g·δu = g·(δφ × u) = w·δφ`,
//! `w = u × g` (equal to `a'` when the joint holds exactly), so `θ_q = Φᵀ w` and
//! `θ̇ = w·(Φ v)`: the exact rate of the θ above, so the spring's power is exactly
//! `d/dt ½k(θ−θ₀)²`.
//!
//! **Forces.** From `δW = −(k(θ−θ₀) + c θ̇) δθ` the residual gains `+M Φᵀ w` with
//! `M = k(θ−θ₀) + c θ̇`. Its tangent at the columns j of the blocks of Φ:
//!
//! * `c_c`: `c (Φ_iᵀ w)(Φ_jᵀ w)ᵀ`;
//! * `c_k`: `∂(Φᵀ m)/∂q` at fixed `m = M w` (as the joint's constraint-force tangent)
//!   `+ (Φ_iᵀ w) ∂M/∂q_j + M Φ_iᵀ G Φ_j`, with `∂w/∂q_j = G Φ_j`, `G = −(∂w/∂u) ũ` and
//!   `∂M/∂q_j = k Φ_jᵀ w + c (Φ_jᵀ Gᵀ (Φ v) + (∂(Φ v)/∂q_j)ᵀ w)`.

use crate::body::Body;
use crate::crv::{M3, Tangent, V3, rotation_matrix, skew};
use crate::joint::Joint;
use genalpha::MatView;
use std::f64::consts::{PI, TAU};

/// A hinge spring and damper (internal form of `scene::ForceElement::HingeSpring`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct HingeSpring {
    /// The joint (a ground hinge or a free flared hinge).
    pub joint: usize,
    /// k, N·m/rad.
    pub stiffness: f64,
    /// c, N·m·s/rad.
    pub damping: f64,
    /// θ₀, rad.
    pub rest: f64,
}

/// `x` wrapped to (−π, π].
pub(crate) fn wrap(x: f64) -> f64 {
    let y = x - TAU * (x / TAU).round();
    if y <= -PI { y + TAU } else { y }
}

/// The unwrapped angle nearest to `last`: `last + wrap(principal − last)`.
pub(crate) fn unwrap(principal: f64, last: f64) -> f64 {
    last + wrap(principal - last)
}

/// The relative rotation of a free hinge at one configuration.
#[allow(clippy::large_enum_variant)] // a temporary on the stack per evaluation, never stored
pub(crate) enum HingeGeometry {
    /// Ground hinge of the body whose frame rotations start at tangent index `f`.
    Ground { f: usize, r_rel: M3 },
    /// Flared hinge: parent end node ψ at `nd`, frame rotations of parent and child at `fp`,
    /// `fc`; `C_n = C^{BnAp}`, `C_pc = C^{ApAc}`.
    Flared { nd: usize, fp: usize, fc: usize, tg: Tangent, cn: M3, cpc: M3 },
}

/// The principal angle and its gradient with respect to `u`.
pub(crate) struct HingeAngle {
    /// `atan2(n₂·u, n₁·u)`, rad in (−π, π].
    pub principal: f64,
    /// `w = u × g`: `δθ = w·δφ`.
    pub w: V3,
    /// `∂w/∂q_j = G Φ_j`.
    pub g: M3,
}

impl HingeGeometry {
    /// The geometry of joint `joint` at `q`, with `u = R_rel n₁`, the measurement axis `a'` and
    /// `n₁`, `n₂`; `None` for a joint without a free rotation.
    pub fn new(joint: &Joint, bodies: &[Body], q: &[f64]) -> Option<(Self, V3, [V3; 3])> {
        match joint {
            Joint::Ground(h) => {
                let b = &bodies[h.body];
                let (_, chi) = b.frame_state(q);
                let r_rel = b.frame.transpose() * chi.to_rotation_matrix();
                let u = r_rel * h.n[0];
                Some((HingeGeometry::Ground { f: b.frame_dof() + 3, r_rel }, u, [h.axis_a, h.n[0], h.n[1]]))
            }
            Joint::Flared(h) if h.n_ang == 2 => {
                let (bp, bc) = (&bodies[h.parent], &bodies[h.child]);
                let node = bp.n_nodes() - 1;
                let (_, psi_n) = bp.node_state(q, node);
                let (_, chi_p) = bp.frame_state(q);
                let (_, chi_c) = bc.frame_state(q);
                let cn = rotation_matrix(&psi_n).transpose();
                let cpc = chi_p.to_rotation_matrix().transpose() * chi_c.to_rotation_matrix();
                // As FlaredHinge::fold_angle: R_rel in B_n, a' = −a_B, n₁ = z, n₂ = a' × n₁.
                let r = cn * cpc * h.rel0.transpose();
                let a = -h.a_b;
                let n1 = V3::z();
                let n2 = a.cross(&n1);
                let u = r * n1;
                let nd = bp.node_dof(node).expect("end node is never the clamped node 0") + 3;
                let geo = HingeGeometry::Flared {
                    nd,
                    fp: bp.frame_dof() + 3,
                    fc: bc.frame_dof() + 3,
                    tg: Tangent::new(&psi_n),
                    cn,
                    cpc,
                };
                Some((geo, u, [a, n1, n2]))
            }
            _ => None,
        }
    }

    /// The blocks of Φ: (first tangent column, 3×3 block); the unused ones are zero.
    pub fn phi(&self) -> [(usize, M3); 3] {
        match self {
            HingeGeometry::Ground { f, r_rel } => [(*f, *r_rel), (*f, M3::zeros()), (*f, M3::zeros())],
            HingeGeometry::Flared { nd, fp, fc, tg, cn, cpc } => [(*fc, cn * cpc), (*fp, -cn), (*nd, -tg.t)],
        }
    }

    /// The relative angular velocity `Φ v` (components of X).
    pub fn rate(&self, v: &[f64]) -> V3 {
        self.phi().iter().map(|(c, p)| p * V3::new(v[*c], v[c + 1], v[c + 2])).sum()
    }

    /// `∂(Φ v)/∂q` at fixed `v`, per block of Φ (same columns as [`phi`](Self::phi)).
    pub fn rate_q(&self, v: &[f64]) -> [M3; 3] {
        let at = |c: usize| V3::new(v[c], v[c + 1], v[c + 2]);
        match self {
            HingeGeometry::Ground { f, r_rel } => [-(r_rel * skew(&at(*f))), M3::zeros(), M3::zeros()],
            HingeGeometry::Flared { nd, fp, fc, tg, cn, cpc } => {
                let (wc, wp, psid) = (at(*fc), at(*fp), at(*nd));
                let y = cpc * wc;
                let t = tg.t;
                [-(cn * cpc * skew(&wc)), cn * skew(&y), skew(&(cn * y)) * t - tg.jac(&psid) - skew(&(cn * wp)) * t]
            }
        }
    }

    /// Add `s ∂(Φᵀ m)/∂q` at fixed `m`.
    pub fn add_force_tangent(&self, m: &V3, s: f64, k: &mut MatView<'_>) {
        let mut k = k.scaled(s);
        match self {
            HingeGeometry::Ground { f, r_rel } => k.add_block::<3, 3>(*f, *f, &skew(&(r_rel.transpose() * m))),
            HingeGeometry::Flared { nd, fp, fc, tg, cn, cpc } => {
                let (nd, fp, fc) = (*nd, *fp, *fc);
                let t = tg.t;
                let u = cn.transpose() * m;
                let mt = skew(m);
                // child rows C_pcᵀ C_nᵀ m
                k.add_block::<3, 3>(fc, nd, &(-(cpc.transpose() * cn.transpose() * mt * t)));
                k.add_block::<3, 3>(fc, fp, &(-(cpc.transpose() * skew(&u))));
                k.add_block::<3, 3>(fc, fc, &skew(&(cpc.transpose() * u)));
                // parent node rows −T_nᵀ m
                k.add_block::<3, 3>(nd, nd, &(-tg.jac_t(m)));
                // parent frame rows −C_nᵀ m
                k.add_block::<3, 3>(fp, nd, &(cn.transpose() * mt * t));
            }
        }
    }
}

impl HingeAngle {
    /// The principal angle of `u` about `a` from `n1` towards `n2 = a × n1`, its gradient `w`
    /// and `G = −(∂w/∂u) ũ`.
    pub fn new(u: &V3, [a, n1, n2]: &[V3; 3]) -> Self {
        let (x, y) = (n1.dot(u), n2.dot(u));
        let principal = y.atan2(x);
        let s = x * x + y * y;
        let pu = n1 * x + n2 * y;
        let g = a.cross(u) / s;
        let w = u.cross(&g);
        let dg_du = (skew(a) - g * pu.transpose() * 2.0) / s;
        let dw_du = skew(u) * dg_du - skew(&g);
        Self { principal, w, g: -(dw_du * skew(u)) }
    }
}

impl HingeSpring {
    /// Spring energy `½ k (θ − θ₀)²`, J, at the unwrapped angle θ.
    pub fn energy(&self, theta: f64) -> f64 {
        0.5 * self.stiffness * (theta - self.rest).powi(2)
    }

    /// Add the spring's generalised force `+M Φᵀ w` to `r` and/or its tangent
    /// `c_c ∂/∂v + c_k ∂/∂q` to `k` (`theta_last`: the last accepted angle, for the unwrapping).
    #[allow(clippy::too_many_arguments)] // the state, the two outputs and the two coefficients
    pub fn add(
        &self,
        joint: &Joint,
        bodies: &[Body],
        theta_last: f64,
        q: &[f64],
        v: &[f64],
        r: Option<&mut [f64]>,
        matrix: Option<(f64, f64, &mut MatView<'_>)>,
    ) {
        let Some((geo, u, axes)) = HingeGeometry::new(joint, bodies, q) else { return };
        let ang = HingeAngle::new(&u, &axes);
        let theta = unwrap(ang.principal, theta_last);
        let om = geo.rate(v);
        let (k, c) = (self.stiffness, self.damping);
        let moment = k * (theta - self.rest) + c * ang.w.dot(&om);
        let phi = geo.phi();
        let n_blocks = if matches!(geo, HingeGeometry::Ground { .. }) { 1 } else { 3 };
        let jw: [V3; 3] = std::array::from_fn(|i| phi[i].1.transpose() * ang.w);
        if let Some(r) = r {
            for ((col, _), x) in phi.iter().zip(&jw).take(n_blocks) {
                for d in 0..3 {
                    r[col + d] += moment * x[d];
                }
            }
        }
        let Some((c_c, c_k, mat)) = matrix else { return };
        if c_c != 0.0 && c != 0.0 {
            for i in 0..n_blocks {
                for j in 0..n_blocks {
                    mat.add_block::<3, 3>(phi[i].0, phi[j].0, &(jw[i] * jw[j].transpose() * (c_c * c)));
                }
            }
        }
        if c_k != 0.0 {
            geo.add_force_tangent(&(ang.w * moment), c_k, mat);
            let rate_q = geo.rate_q(v);
            let gt_om = ang.g.transpose() * om;
            for j in 0..n_blocks {
                let (cj, pj) = &phi[j];
                let dm = jw[j] * k + (pj.transpose() * gt_om + rate_q[j].transpose() * ang.w) * c;
                let dw = ang.g * pj * moment;
                for i in 0..n_blocks {
                    let (ci, pi) = &phi[i];
                    mat.add_block::<3, 3>(*ci, *cj, &((jw[i] * dm.transpose() + pi.transpose() * dw) * c_k));
                }
            }
        }
    }

    /// `θ` (unwrapped against `theta_last`) and `θ̇` at `(q, v)`.
    pub fn angle_and_rate(joint: &Joint, bodies: &[Body], theta_last: f64, q: &[f64], v: &[f64]) -> Option<(f64, f64)> {
        let (geo, u, axes) = HingeGeometry::new(joint, bodies, q)?;
        let ang = HingeAngle::new(&u, &axes);
        Some((unwrap(ang.principal, theta_last), ang.w.dot(&geo.rate(v))))
    }
}

/// The principal angle of a free hinge at `q` (None for other joints).
pub(crate) fn principal_angle(joint: &Joint, bodies: &[Body], q: &[f64]) -> Option<f64> {
    let (_, u, [_, n1, n2]) = HingeGeometry::new(joint, bodies, q)?;
    Some(n2.dot(&u).atan2(n1.dot(&u)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_and_unwrap() {
        assert!((wrap(3.0 * PI) - PI).abs() < 1e-15);
        assert!((wrap(-PI) - PI).abs() < 1e-15);
        assert!((wrap(0.3) - 0.3).abs() < 1e-16);
        // just past +180° from just below it: continuous
        let last = PI - 0.01;
        let principal = -PI + 0.02;
        assert!((unwrap(principal, last) - (PI + 0.02)).abs() < 1e-14);
        // several turns
        assert!((unwrap(0.1, 4.0 * PI) - (4.0 * PI + 0.1)).abs() < 1e-14);
    }

    #[test]
    fn angle_gradient_matches_finite_differences() {
        let a = V3::new(0.3, -0.5, 0.8).normalize();
        let n1 = crate::ground_hinge::perpendicular_pair(&a)[0];
        let n2 = a.cross(&n1);
        let axes = [a, n1, n2];
        let u = V3::new(0.4, 0.7, -0.2);
        let ang = HingeAngle::new(&u, &axes);
        let h = 1e-6;
        for j in 0..3 {
            let e = V3::ith(j, h);
            // δθ along δu = δφ × u for δφ = e_j h: w_j
            let up = rotation_matrix(&e) * u;
            let um = rotation_matrix(&(-e)) * u;
            let fd = (HingeAngle::new(&up, &axes).principal - HingeAngle::new(&um, &axes).principal) / (2.0 * h);
            assert!((fd - ang.w[j]).abs() < 1e-8, "w[{j}]: {fd} vs {}", ang.w[j]);
            // ∂w/∂φ_j = G e_j
            let fdw = (HingeAngle::new(&up, &axes).w - HingeAngle::new(&um, &axes).w) / (2.0 * h);
            assert!((fdw - ang.g.column(j)).amax() < 1e-7, "G column {j}");
        }
    }
}
