//! The momentum projection (option `conserve_momentum`, docs/gebf.md §15.1).
//!
//! The equations of motion live in each body's moving frame, so generalized-α keeps neither
//! the linear nor the angular momentum exactly: both drift at the scheme's second order. With
//! the option on, every accepted step ends with the smallest change of the velocities, in the
//! kinetic-energy norm, that gives the momenta their balance over the step:
//!
//! ```text
//!   P_{n+1} = P_n + h/2 (W_n + W_{n+1})
//! ```
//!
//! with `P = (p, L)` the momenta about the global origin and `W_n` the resultant and moment of
//! the external loads at the end of step `n` (gravity, the nodal loads that step held, thrusts;
//! hinge springs and dampers are internal): the trapezoidal rule in which generalized-α at
//! ρ∞ = 1 balances the loads of each step's end. It is a projection method in the sense of Hairer, Lubich & Wanner,
//! *Geometric Numerical Integration* (2nd ed., Springer 2006, §IV.4), made mass-orthogonal as
//! Bayo & Ledesma project the velocities of constrained multibody systems (*Nonlinear
//! Dynamics* 9, 1996).
//!
//! **The correction is a rigid motion.** Minimising `½ δvᵀ M δv` subject to `J δv = ΔP` (`J` the
//! momentum map, linear in `v`) gives `M δv = Jᵀ c`. Since `J v = ∂T/∂(d, θ)` is the momentum map
//! of the rigid motions, `vᵀ M v_r(d, θ) = p·d + L·θ` for every `v`, i.e. `Jᵀ (d, θ) = M v_r(d,
//! θ)` with `v_r` the rigid velocity of translation rate `d` and rotation rate `θ` about the
//! origin. So `δv = v_r(c)`: every body's frame moves with the same rigid motion and the nodes
//! stay at rest in their frames, which keeps the joints' velocity rows. `c` solves the 6 × 6
//! system `K c = ΔP` with `K` the locked inertia (mass, first moment and inertia about the
//! origin), whose columns are the momenta of the six unit rigid motions.

use formulation::Momentum;
use nalgebra::{Matrix6, Vector6};

use crate::Model;
use crate::crv::V3;

/// The balance at one accepted step's end.
#[derive(Debug, Clone, Copy)]
struct Balance {
    /// Time, s.
    t: f64,
    /// The momenta at `t`.
    momentum: Vector6<f64>,
    /// The external loads' resultant and moment about the origin at `t`, with the loads that
    /// held then.
    wrench: Vector6<f64>,
}

/// Where the projection stands: the balances at the ends of the last two accepted steps (a
/// coupled march may redo a step from its start with other loads — a strong-coupling
/// sub-iteration — and the redone step starts from the older one).
#[derive(Debug, Clone, Default)]
pub(crate) struct MomentumHold {
    /// Oldest first; at most two.
    ends: Vec<Balance>,
    /// Scratch: a rigid velocity.
    rigid: Vec<f64>,
}

fn as_vector(m: &Momentum) -> Vector6<f64> {
    Vector6::new(m.linear.x, m.linear.y, m.linear.z, m.angular.x, m.angular.y, m.angular.z)
}

impl Model {
    /// The exact rigid velocity of the whole model with translation rate `d` and rotation rate
    /// `theta` about the global origin (global components), written into `v`: each frame moves
    /// with `v_A = C^{AG}(d + θ × r_A)`, `ω_A = C^{AG} θ`; the nodes rest in their frames.
    pub fn rigid_velocity(&self, q: &[f64], d: &V3, theta: &V3, v: &mut [f64]) {
        v.fill(0.0);
        for b in &self.bodies {
            let (r_a, chi) = b.frame_state(q);
            let c_ag = chi.to_rotation_matrix().transpose();
            let k = b.frame_dof();
            v[k..k + 3].copy_from_slice((c_ag * (d + theta.cross(&r_a))).as_slice());
            v[k + 3..k + 6].copy_from_slice((c_ag * theta).as_slice());
        }
    }

    /// Start the momentum projection from the state `(t, q, v)` (the march calls it after
    /// the initial accelerations and after every rebuild); without the option, nothing.
    pub fn hold_momentum(&mut self, t: f64, q: &[f64], v: &[f64]) {
        if !self.options().conserve_momentum {
            return;
        }
        let mut hold = self.momentum_hold.take().unwrap_or_default();
        hold.rigid.resize(genalpha::ConstrainedSystem::n_dof(self), 0.0);
        let k = self.locked_inertia(q, &mut hold.rigid);
        let wrench = self.external_wrench(t, q, &k, &mut hold.rigid);
        hold.ends.clear();
        hold.ends.push(Balance { t, momentum: as_vector(&self.momentum(q, v)), wrench });
        self.momentum_hold = Some(hold);
    }

    /// The locked inertia at `q`: column `j` holds the momenta `(p, L)` of the unit rigid
    /// motion `j` (translations x, y, z, then rotations about x, y, z through the origin).
    fn locked_inertia(&self, q: &[f64], scratch: &mut [f64]) -> Matrix6<f64> {
        let mut k = Matrix6::zeros();
        for j in 0..6 {
            let mut unit = [V3::zeros(), V3::zeros()];
            unit[j / 3][j % 3] = 1.0;
            self.rigid_velocity(q, &unit[0], &unit[1], scratch);
            let m = self.momentum(q, scratch);
            k.fixed_view_mut::<3, 1>(0, j).copy_from(&m.linear);
            k.fixed_view_mut::<3, 1>(3, j).copy_from(&m.angular);
        }
        k
    }

    /// Resultant and moment about the origin of the external loads at `(t, q)`: gravity on the
    /// mass of the locked inertia `k` (its first moment `S` from `K`'s translation columns, whose
    /// angular parts are `S × e_j`), the nodal loads and the thrusts (their power on the six unit
    /// rigid motions).
    fn external_wrench(&self, t: f64, q: &[f64], k: &Matrix6<f64>, scratch: &mut [f64]) -> Vector6<f64> {
        let mass = k[(0, 0)];
        let first_moment = V3::new(k[(5, 1)], k[(3, 2)], k[(4, 0)]);
        let g = self.gravity * self.load_scale;
        let mut force = g * mass;
        let mut moment = first_moment.cross(&g);
        for (b, loads) in self.bodies.iter().zip(&self.loads) {
            let (r_a, chi) = b.frame_state(q);
            let c_ga = chi.to_rotation_matrix();
            for (i, l) in loads.iter().enumerate().filter(|(_, l)| !l.is_zero()) {
                let (ri, _) = b.node_state(q, i);
                let f = l.force * self.load_scale;
                force += f;
                moment += (r_a + c_ga * ri).cross(&f) + l.moment * self.load_scale;
            }
        }
        let mut w = Vector6::zeros();
        w.fixed_rows_mut::<3>(0).copy_from(&force);
        w.fixed_rows_mut::<3>(3).copy_from(&moment);
        if self.has_thrust() {
            for j in 0..6 {
                let mut unit = [V3::zeros(), V3::zeros()];
                unit[j / 3][j % 3] = 1.0;
                self.rigid_velocity(q, &unit[0], &unit[1], scratch);
                w[j] += self.thrust_power(t, q, scratch);
            }
        }
        w
    }

    /// The projection at the end of an accepted step `(t, q, v)` (module docs), from the last
    /// balance before `t`; without one (no hold, or every balance at or after `t`), it holds
    /// this state instead.
    pub(crate) fn project_momentum(&mut self, t: f64, q: &[f64], v: &mut [f64]) {
        let Some(mut hold) = self.momentum_hold.take() else {
            self.hold_momentum(t, q, v);
            return;
        };
        // A redone step: forget the ends at or after its own.
        let tiny = 1e-12 * t.abs().max(1.0);
        hold.ends.retain(|b| b.t < t - tiny);
        let Some(&start) = hold.ends.last() else {
            self.momentum_hold = Some(hold);
            self.hold_momentum(t, q, v);
            return;
        };
        let k = self.locked_inertia(q, &mut hold.rigid);
        let wrench = self.external_wrench(t, q, &k, &mut hold.rigid);
        let target = start.momentum + (start.wrench + wrench) * (0.5 * (t - start.t));
        if let Some(c) = k.lu().solve(&(target - as_vector(&self.momentum(q, v)))) {
            let (d, theta) = (c.fixed_rows::<3>(0).into_owned(), c.fixed_rows::<3>(3).into_owned());
            self.rigid_velocity(q, &d, &theta, &mut hold.rigid);
            for (vi, ri) in v.iter_mut().zip(&hold.rigid) {
                *vi += ri;
            }
        }
        if hold.ends.len() == 2 {
            hold.ends.remove(0);
        }
        hold.ends.push(Balance { t, momentum: as_vector(&self.momentum(q, v)), wrench });
        self.momentum_hold = Some(hold);
    }
}
