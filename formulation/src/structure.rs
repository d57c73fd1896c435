//! The formulation trait.

use genalpha::{ConstrainedSystem, GenAlpha, IntegratorParams, LinearSolver, State};
use nalgebra::{Matrix3, Vector3};

use crate::{BeamGeometry, Energies, LoadError, Momentum, SectionLoad, check_section_loads};

/// A section's pose and rates: axis point (m), section frame (columns x, y, z), the point's
/// velocity (m/s) and the frame's angular velocity (rad/s), all global.
pub type SectionState = (Vector3<f64>, Matrix3<f64>, Vector3<f64>, Vector3<f64>);

/// A section's pose, rates and accelerations, all global.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SectionMotion {
    /// Axis point, m.
    pub p: Vector3<f64>,
    /// Section frame (columns x, y, z).
    pub r: Matrix3<f64>,
    /// Velocity of the axis point, m/s.
    pub vel: Vector3<f64>,
    /// Angular velocity of the frame, rad/s.
    pub omega: Vector3<f64>,
    /// Acceleration of the axis point, m/s².
    pub acc: Vector3<f64>,
    /// Angular acceleration of the frame, rad/s².
    pub alpha: Vector3<f64>,
}

/// What the analyses need from a structural model beyond the integrator's trait: the integrator
/// it runs with, its state at rest, its sensors, the pose of a section and the section loads of
/// the aerodynamic coupling, its geometry for output, and the statics hook. Implemented by
/// `ancf::Model` and `gebf::Model` in their own crates; every analysis is generic over it.
///
/// The model itself goes to the integrator, so every optional method of [`ConstrainedSystem`]
/// it overrides (a fused residual-and-matrix pass, a declared matrix structure) is used.
///
/// # Example: a rigid rod on a torsion spring
///
/// One coordinate θ, the rod's rotation about the ground's z axis; the residual is
/// $J\ddot\theta + k\theta - M_z = 0$ with $J = m L^2 / 3$, where $M_z$ sums the section
/// loads' moments about z (their forces are left out to keep the example short).
///
/// ```
/// use formulation::{BeamGeometry, Energies, LoadError, Momentum, SectionLoad, Structure};
/// use genalpha::{ConstrainedSystem, DenseLu, GenAlpha, IntegratorParams, MatView, State};
/// use nalgebra::{Matrix3, Rotation3, Vector3};
///
/// struct Rod { mass: f64, length: f64, k: f64, m_z: f64 }
///
/// impl Rod {
///     fn inertia(&self) -> f64 { self.mass * self.length * self.length / 3.0 }
///     fn frame(&self, q: &[f64]) -> Matrix3<f64> { *Rotation3::from_axis_angle(&Vector3::z_axis(), q[0]).matrix() }
/// }
///
/// impl ConstrainedSystem for Rod {
///     fn n_coords(&self) -> usize { 1 }
///     fn n_dof(&self) -> usize { 1 }
///     fn residual_inplace(&self, _t: f64, q: &[f64], _v: &[f64], a: &[f64], r: &mut [f64]) {
///         r[0] = self.inertia() * a[0] + self.k * q[0] - self.m_z;
///     }
///     fn iteration_matrix_inplace(&self, _t: f64, _q: &[f64], _v: &[f64], _a: &[f64],
///                                 c_m: f64, _c_c: f64, c_k: f64, k: &mut MatView<'_>) {
///         k.add(0, 0, c_m * self.inertia() + c_k * self.k);
///     }
/// }
///
/// impl Structure for Rod {
///     type Solver = DenseLu;
///     fn integrator(&self, p: IntegratorParams) -> Result<GenAlpha<DenseLu>, genalpha::Error> {
///         GenAlpha::new(p, self)
///     }
///     fn initial_state(&self) -> State { State::at_rest(self, 0.0, vec![0.0]) }
///     fn tip(&self, q: &[f64]) -> [f64; 3] { (self.frame(q) * Vector3::new(self.length, 0.0, 0.0)).into() }
///     fn fold(&self, _q: &[f64], _joint: usize) -> f64 { f64::NAN }
///     fn hinge_rate(&self, _q: &[f64], v: &[f64], _joint: usize) -> f64 { v[0] }
///     fn energies(&self, q: &[f64], v: &[f64]) -> Energies {
///         Energies { kinetic: 0.5 * self.inertia() * v[0] * v[0], spring: 0.5 * self.k * q[0] * q[0], ..Default::default() }
///     }
///     fn momentum(&self, q: &[f64], v: &[f64]) -> Momentum {
///         // The centre moves on a circle; about the pivot, L = J θ̇ (J about the rod's end).
///         let centre = self.frame(q) * Vector3::new(0.5 * self.length, 0.0, 0.0);
///         let linear = Vector3::z().cross(&centre) * (self.mass * v[0]);
///         Momentum { linear, angular: Vector3::new(0.0, 0.0, self.inertia() * v[0]) }
///     }
///     fn dissipation_power(&self, _q: &[f64], _v: &[f64]) -> f64 { 0.0 }
///     fn has_force_elements(&self) -> bool { true }
///     fn constraint_residual(&self, _q: &[f64]) -> f64 { 0.0 }
///     fn n_bodies(&self) -> usize { 1 }
///     fn body_length(&self, body: usize) -> Option<f64> { (body == 0).then_some(self.length) }
///     fn body_geometry(&self, q: &[f64], _body: usize, out: &mut BeamGeometry) {
///         out.clear();
///         for s in [0.0, self.length] { let (p, r) = self.section_pose(q, 0, s); out.push(s, p, r); }
///     }
///     fn section_pose(&self, q: &[f64], _body: usize, s: f64) -> (Vector3<f64>, Matrix3<f64>) {
///         let r = self.frame(q);
///         (r * Vector3::new(s, 0.0, 0.0), r)
///     }
///     fn apply_section_loads(&mut self, loads: &[SectionLoad]) -> Result<(), LoadError> {
///         self.m_z = loads.iter().map(|l| l.moment.z).sum();
///         Ok(())
///     }
/// }
///
/// let mut rod = Rod { mass: 3.0, length: 2.0, k: 40.0, m_z: 0.0 };
/// // 1 N·m about z at the tip: the spring balances it at θ = M/k.
/// let load = SectionLoad { body: 0, s: 2.0, force: Vector3::zeros(), moment: Vector3::new(0.0, 0.0, 1.0) };
/// rod.set_section_loads(&[load]).unwrap();
/// assert_eq!(rod.m_z, 1.0);
/// // A non-finite load is refused, naming the station, and the model keeps its loads.
/// let bad = SectionLoad { force: Vector3::new(f64::NAN, 0.0, 0.0), ..load };
/// let err = rod.set_section_loads(&[load, bad]).unwrap_err();
/// assert!(err.to_string().contains("station 1"), "{err}");
/// assert_eq!(rod.m_z, 1.0);
/// // Integrate: the period of the free oscillation about the loaded equilibrium is 2π √(J/k).
/// let mut ga = rod.integrator(IntegratorParams::new(1.0, 1e-3)).unwrap();
/// let mut s = rod.initial_state();
/// ga.initialize(&rod, &mut s).unwrap();
/// let period = 2.0 * std::f64::consts::PI * (rod.inertia() / rod.k).sqrt();
/// while s.t < 0.5 * period - 1e-9 { ga.step(&mut rod, &mut s).unwrap(); }
/// // Half a period after starting at rest at θ = 0, the rod is at 2 M/k.
/// approx::assert_relative_eq!(s.q[0], 2.0 / rod.k, max_relative = 1e-3);
/// assert_eq!(rod.n_unknowns(), 1);
/// ```
pub trait Structure: ConstrainedSystem {
    /// The linear solver the formulation integrates best with.
    type Solver: LinearSolver;
    /// A generalized-α integrator with that solver.
    fn integrator(&self, params: IntegratorParams) -> Result<GenAlpha<Self::Solver>, genalpha::Error>;
    /// Reference configuration at rest.
    fn initial_state(&self) -> State;
    /// Tip position (centroid of the last body's free end), m.
    fn tip(&self, q: &[f64]) -> [f64; 3];
    /// Fold angle of flared hinge `joint`, rad (NaN when it is not one).
    fn fold(&self, q: &[f64], joint: usize) -> f64;
    /// Rate of the hinge angle of `joint`, rad/s, a ground hinge (the body's rotation about the
    /// axis, right-hand rule) or a free flared hinge (the fold rate), as the hinge springs measure
    /// it; NaN for another joint. The roll rate of a roll rig.
    fn hinge_rate(&self, q: &[f64], v: &[f64], joint: usize) -> f64;
    /// Energies at coordinates `q` and velocities `v`.
    fn energies(&self, q: &[f64], v: &[f64]) -> Energies;
    /// Linear momentum and angular momentum about the global origin at coordinates `q` and
    /// velocities `v`, evaluated with the model's own mass distribution (the quadrature of its
    /// kinetic energy), so that they are the momenta its equations of motion balance.
    fn momentum(&self, q: &[f64], v: &[f64]) -> Momentum;
    /// Power dissipated by the force elements' dampers, W (≥ 0).
    fn dissipation_power(&self, q: &[f64], v: &[f64]) -> f64;
    /// Whether the model has force elements (the spring and dissipated-work columns).
    fn has_force_elements(&self) -> bool;
    /// The power of the external follower forces (thrusts) `Σ F · ṗ` at time `t`, coordinates
    /// `q` and velocities `v`, W: what the energy balance integrates as their work. Default 0.
    fn external_power(&self, _t: f64, _q: &[f64], _v: &[f64]) -> f64 {
        0.0
    }
    /// Whether the model has thrusts (the `thrust_work` column). Default: none.
    fn has_external_power(&self) -> bool {
        false
    }
    /// Position-level joint violation (gap in m and axis misalignment in rad, Euclidean norm).
    fn constraint_residual(&self, q: &[f64]) -> f64;
    /// Number of bodies.
    fn n_bodies(&self) -> usize;
    /// Length of body `body` in the reference configuration, m (`None`: no such body).
    fn body_length(&self, body: usize) -> Option<f64>;
    /// Positions and section frames of body `body`'s nodes, written into `out` (cleared first).
    fn body_geometry(&self, q: &[f64], body: usize, out: &mut BeamGeometry);
    /// Axis point (m) and section frame (columns x, y, z, orthonormal) of `body` at arclength
    /// `s`. For a station outside the model: a NaN point and the identity.
    fn section_pose(&self, q: &[f64], body: usize, s: f64) -> (Vector3<f64>, Matrix3<f64>);
    /// [`section_pose`](Self::section_pose) of each `(body, s)` of `at`, in order, into `out`
    /// (cleared first). Default: one call each; a formulation whose pose interpolates shared
    /// element quantities computes them once per element for consecutive stations on it.
    fn section_poses(&self, q: &[f64], at: &[(usize, f64)], out: &mut Vec<(Vector3<f64>, Matrix3<f64>)>) {
        out.clear();
        out.extend(at.iter().map(|&(body, s)| self.section_pose(q, body, s)));
    }
    /// Pose and rates of each `(body, s)` of `at`, in order, into `out` (cleared first): axis
    /// point (m), section frame, the point's velocity (m/s) and the frame's angular velocity
    /// (rad/s, global), at coordinates `q` and velocities `v`. Returns false when the
    /// formulation has no exact rates (the default) or cannot give them (a station outside the
    /// model), and `out` is then not to be read: the caller differences
    /// [`section_poses`](Self::section_poses) along the retraction.
    fn section_states(&self, _q: &[f64], _v: &[f64], _at: &[(usize, f64)], _out: &mut Vec<SectionState>) -> bool {
        false
    }
    /// Pose, rates and accelerations of each `(body, s)` of `at`, in order, into `out` (cleared
    /// first), at coordinates `q`, velocities `v` and their rates `a` (`v̇`). Returns false when
    /// the formulation has none exact (the default) or cannot give them, and `out` is then not to
    /// be read: the caller differences poses along the trajectory.
    fn section_motions(
        &self,
        _q: &[f64],
        _v: &[f64],
        _a: &[f64],
        _at: &[(usize, f64)],
        _out: &mut Vec<SectionMotion>,
    ) -> bool {
        false
    }
    /// Replace all external section loads by `loads`, which [`check_section_loads`] has
    /// accepted; an error here ([`LoadError::Model`]) is the model's own refusal of a value
    /// that passed the check. Called through [`set_section_loads`](Self::set_section_loads).
    fn apply_section_loads(&mut self, loads: &[SectionLoad]) -> Result<(), LoadError>;
    /// Replace all external section loads, after checking them with [`check_section_loads`]
    /// against this model's bodies: on a non-finite value, a missing body or an arclength
    /// outside its body the loads are refused with the station named, and the model keeps its
    /// previous loads — the same for every formulation.
    fn set_section_loads(&mut self, loads: &[SectionLoad]) -> Result<(), LoadError> {
        check_section_loads(loads, |b| self.body_length(b))?;
        self.apply_section_loads(loads)
    }
    /// A march starts (or restarts after a model change) from the state `(t, q, v)`: a
    /// formulation that carries a quantity across steps, such as GEBF's momentum projection,
    /// takes it from here. Called after the initial accelerations. Default: nothing.
    fn start_march(&mut self, _t: f64, _q: &[f64], _v: &[f64]) {}
    /// The state `(q, v)` of `old` — this formulation's model of the same bodies before a joint
    /// changed state (a hinge event) — in this model's coordinates and velocities. Where the
    /// two do not share their layout, the velocities come out admissible for this model, closest
    /// to `v` in kinetic energy (ANCF's ODE path). Default: `(q, v)` unchanged, refused when
    /// the sizes differ.
    ///
    /// # Errors
    /// A message when the state cannot be carried over.
    fn carry_state(&self, _old: &Self, q: &[f64], v: &[f64]) -> Result<(Vec<f64>, Vec<f64>), String>
    where
        Self: Sized,
    {
        if self.n_coords() != q.len() || self.n_dof() != v.len() {
            return Err(format!(
                "the new model has {} coordinates and {} velocities, not {} and {}",
                self.n_coords(),
                self.n_dof(),
                q.len(),
                v.len()
            ));
        }
        Ok((q.to_vec(), v.to_vec()))
    }
    /// Bring stored coordinates back to their canonical branch without changing the
    /// configuration, after every Newton update of a static solve (GEBF: rotation vectors past
    /// π and the joints' position projection). Default: nothing.
    fn normalise(&self, _q: &mut [f64]) {}
    /// The integrator's unknowns: tangent dimension plus constraint rows.
    fn n_unknowns(&self) -> usize {
        self.n_dof() + self.n_holonomic() + self.n_velocity_constraints()
    }
}
