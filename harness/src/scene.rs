//! Building each formulation's model from a case, and the [`Structure`] impls that expose the
//! sensors of both through one interface.

use nalgebra::{Matrix3, Vector3};

use crate::Error;
use crate::aero::{AeroStructure, SectionLoad, simulate_aero, station_map};
use crate::case::{AncfPath, Case, Formulation};
use crate::run::{BeamGeometry, Energies, NoObserver, Observer, RunOutput, RunSettings, Structure, simulate};

/// `Structure` for a formulation's model: the integrator it runs with and its sensors. The
/// model itself goes to the integrator, so every optional method of `ConstrainedSystem` it
/// overrides (GEBF's fused residual-and-matrix pass, its declared matrix structure) is used.
macro_rules! structure {
    ($t:ty, $solver:ty, $make:expr, $geometry:expr) => {
        impl Structure for $t {
            type Solver = $solver;
            fn integrator(
                &self,
                params: genalpha::IntegratorParams,
            ) -> Result<genalpha::GenAlpha<$solver>, genalpha::Error> {
                let make: fn(&$t, genalpha::IntegratorParams) -> Result<genalpha::GenAlpha<$solver>, genalpha::Error> =
                    $make;
                make(self, params)
            }
            fn initial_state(&self) -> genalpha::State {
                <$t>::initial_state(self)
            }
            fn tip(&self, q: &[f64]) -> [f64; 3] {
                self.tip_position(q).into()
            }
            fn fold(&self, q: &[f64], joint: usize) -> f64 {
                self.fold_angle(q, joint).unwrap_or(f64::NAN)
            }
            fn energies(&self, q: &[f64], v: &[f64]) -> Energies {
                let e = <$t>::energies(self, q, v);
                Energies { kinetic: e.kinetic, elastic: e.elastic, potential: e.potential, spring: e.spring }
            }
            fn dissipation_power(&self, q: &[f64], v: &[f64]) -> f64 {
                <$t>::dissipation_power(self, q, v)
            }
            fn has_force_elements(&self) -> bool {
                <$t>::n_force_elements(self) > 0
            }
            fn constraint_residual(&self, q: &[f64]) -> f64 {
                <$t>::constraint_residual(self, q)
            }
            fn n_bodies(&self) -> usize {
                <$t>::n_bodies(self)
            }
            fn body_geometry(&self, q: &[f64], body: usize, out: &mut BeamGeometry) {
                out.clear();
                let geometry: fn(&$t, &[f64], usize, &mut BeamGeometry) = $geometry;
                geometry(self, q, body, out)
            }
        }
    };
}

// ANCF brings its skyline LU (banded, symmetric-structure); GEBF declares a block-banded
// structure that genalpha's default solver exploits.
structure!(ancf::Model, ancf::SkylineLu, |m, p| m.integrator(p), |m, q, body, out| {
    // The nodes of ANCF's two-node elements, equally spaced.
    let Some(spec) = m.body_spec(body) else { return };
    for k in 0..=spec.n_elements {
        let s = spec.length * k as f64 / spec.n_elements as f64;
        if let Ok((p, r)) = m.section_frame(q, body, s) {
            out.push(s, p, r);
        }
    }
});
structure!(gebf::Model, genalpha::DenseLu, |m, p| genalpha::GenAlpha::new(p, m), |m, q, body, out| {
    // Every node of the three-node elements, middle nodes included.
    for k in 0..m.n_nodes(body) {
        if let (Ok(s), Ok(p), Ok(r)) =
            (m.node_arc_length(body, k), m.node_position(q, body, k), m.node_frame(q, body, k))
        {
            out.push(s, p, r);
        }
    }
});

impl AeroStructure for ancf::Model {
    fn section_pose(&self, q: &[f64], body: usize, s: f64) -> (Vector3<f64>, Matrix3<f64>) {
        // The station list is validated against the case, so (body, s) is always in range.
        self.section_frame(q, body, s).unwrap_or((Vector3::from_element(f64::NAN), Matrix3::identity()))
    }
    fn set_section_loads(&mut self, loads: &[SectionLoad]) {
        let pl: Vec<ancf::PointLoad> = loads
            .iter()
            .map(|l| ancf::PointLoad { body: l.body, s: l.s, y: 0.0, z: 0.0, force: l.force, moment: l.moment })
            .collect();
        // Stations come from the validated case: in range by construction.
        let _ = self.set_point_loads(&pl);
    }
}

/// Element of a GEBF body holding arclength `s`: its three node indices and the quadratic
/// Lagrange weights of `s`.
fn gebf_element(model: &gebf::Model, body: usize, s: f64) -> Option<([usize; 3], [f64; 3])> {
    let n = model.n_nodes(body);
    let arc = |k: usize| model.node_arc_length(body, k).ok();
    let n_el = (n - 1) / 2;
    for e in 0..n_el {
        let (s0, s1, s2) = (arc(2 * e)?, arc(2 * e + 1)?, arc(2 * e + 2)?);
        if s <= s2 + 1e-12 || e + 1 == n_el {
            let w = [
                (s - s1) * (s - s2) / ((s0 - s1) * (s0 - s2)),
                (s - s0) * (s - s2) / ((s1 - s0) * (s1 - s2)),
                (s - s0) * (s - s1) / ((s2 - s0) * (s2 - s1)),
            ];
            return Some(([2 * e, 2 * e + 1, 2 * e + 2], w));
        }
    }
    None
}

/// Rotation vector of a rotation matrix. Through the quaternion (Shepperd's method), accurate at
/// every angle: an `acos` of the trace returns NaN when rounding pushes it past 3 for the tiny
/// relative rotations of a stiff wing.
fn log_so3(r: &Matrix3<f64>) -> Vector3<f64> {
    gebf::crv::from_rotation_matrix(r)
}

impl AeroStructure for gebf::Model {
    /// Quadratic interpolation of the element's nodal positions, and of the nodal rotations
    /// relative to the middle node (objective).
    fn section_pose(&self, q: &[f64], body: usize, s: f64) -> (Vector3<f64>, Matrix3<f64>) {
        let m = self;
        let Some((nodes, w)) = gebf_element(m, body, s) else {
            return (Vector3::from_element(f64::NAN), Matrix3::identity());
        };
        let pos = |k| m.node_position(q, body, k).unwrap_or_else(|_| Vector3::from_element(f64::NAN));
        let frm = |k| m.node_frame(q, body, k).unwrap_or_else(|_| Matrix3::from_element(f64::NAN));
        let p = pos(nodes[0]) * w[0] + pos(nodes[1]) * w[1] + pos(nodes[2]) * w[2];
        let r1 = frm(nodes[1]);
        let phi = log_so3(&(r1.transpose() * frm(nodes[0]))) * w[0] + log_so3(&(r1.transpose() * frm(nodes[2]))) * w[2];
        let r = r1 * nalgebra::Rotation3::new(phi).into_inner();
        (p, r)
    }
    /// Consistent nodal loads: the quadratic weights distribute each station's force and moment.
    fn set_section_loads(&mut self, loads: &[SectionLoad]) {
        self.clear_nodal_loads();
        for l in loads {
            let Some((nodes, w)) = gebf_element(self, l.body, l.s) else { continue };
            for (k, wk) in nodes.iter().zip(w) {
                let old = self
                    .nodal_load(l.body, *k)
                    .unwrap_or(gebf::NodalLoad { force: Vector3::zeros(), moment: Vector3::zeros() });
                let new = gebf::NodalLoad { force: old.force + wk * l.force, moment: old.moment + wk * l.moment };
                let _ = self.set_nodal_load(l.body, *k, new);
            }
        }
    }
}

/// The integrator parameters, end time and output interval of formulation `f` of a case.
pub fn settings(case: &Case, f: Formulation) -> RunSettings {
    use genalpha::Predictor::{ConstantAcceleration, ExtrapolatedAcceleration};
    // GEBF starts Newton from extrapolated accelerations: its residual is quadratic in the
    // floating frames' angular velocities (Coriolis and centrifugal terms of the beam in a frame
    // spinning at up to 30 rad/s in the c = 0.01 case). ANCF's inertia is linear.
    let (dt, rho, newton, predictor, form) = match f {
        Formulation::Ancf => (case.ancf.dt, case.ancf.rho_inf, case.ancf.newton, ConstantAcceleration, case.ancf.form),
        Formulation::Gebf => {
            (case.gebf.dt, case.gebf.rho_inf, case.gebf.newton, ExtrapolatedAcceleration, case.gebf.form)
        }
    };
    let mut params = genalpha::IntegratorParams::new(rho, dt);
    params.newton = newton.to_params(predictor);
    // Both formulations default to the Arnold–Brüls form. GEBF's energy at rho_inf = 1 is better
    // in the Chung–Hulbert form (the implicit midpoint rule: the β = 45° pendulum's energy error
    // is 1.6e-4 of the peak kinetic energy instead of 1.35e-3), which costs 2 % more work on the
    // c = 1 pendulums and 8–13 % on the soft ones (more Newton iterations where the tip twists,
    // and B at two states), so a case opts in with `gebf.form`. Not even at rho_inf = 1, where
    // it needs fewer Newton iterations on the paper cases: over the stress matrix's 72 GEBF
    // cells at rho_inf = 1 (c × β × dt) it reaches the end at fixed steps in 46 against 51 (it
    // fails on soft tips at 2–5 × dt, where step control then recovers them), although its
    // energy error is 2–100 times smaller in most cells.
    params.form = form.to_form();
    // Wing loads are recorded with aerodynamics (the pendulums' outputs stay as they were).
    let loads = if case.aero.is_some() { crate::loads::LoadModel::new(case, f) } else { None };
    RunSettings { params, t_end: case.t_end, output_dt: case.output_dt, fold_joint: case.fold_joint_index(), loads }
}

/// Build the ANCF model of a case (DAE or ODE path as the case says).
pub fn build_ancf(case: &Case) -> Result<ancf::Model, Error> {
    let path = match case.ancf.path {
        AncfPath::Dae => ancf::SolvePath::Dae,
        AncfPath::Ode => ancf::SolvePath::Ode,
    };
    ancf::Model::from_scene(&case.scene(Formulation::Ancf), ancf::Options { path, ..Default::default() })
        .map_err(|e| Error::Model { formulation: Formulation::Ancf, msg: e.to_string() })
}

/// Build the GEBF model of a case.
pub fn build_gebf(case: &Case) -> Result<gebf::Model, Error> {
    let options = gebf::Options { stabilization: case.gebf.stabilization, ..Default::default() };
    gebf::Model::from_scene(&case.scene(Formulation::Gebf), options)
        .map_err(|e| Error::Model { formulation: Formulation::Gebf, msg: e.to_string() })
}

/// Build and integrate formulation `f` of `case`. Never panics on bad input: a model that cannot
/// be built gives a failed [`RunOutput`] with the reason.
pub fn run_formulation(case: &Case, f: Formulation) -> RunOutput {
    run_formulation_observed(case, f, &mut NoObserver)
}

/// As [`run_formulation`], handing every output step's geometry to `observer`.
pub fn run_formulation_observed(case: &Case, f: Formulation, observer: &mut dyn Observer) -> RunOutput {
    let s = settings(case, f);
    let built = match (&case.aero, f) {
        (None, Formulation::Ancf) => build_ancf(case).map(|mut model| simulate(f, &mut model, &s, observer)),
        (None, Formulation::Gebf) => build_gebf(case).map(|mut model| simulate(f, &mut model, &s, observer)),
        (Some(aero), _) => match station_map(case, aero) {
            Err(msg) => Err(Error::Model { formulation: f, msg }),
            Ok(map) => match f {
                Formulation::Ancf => {
                    build_ancf(case).map(|mut model| simulate_aero(f, &mut model, &s, aero, &map, observer))
                }
                Formulation::Gebf => {
                    build_gebf(case).map(|mut model| simulate_aero(f, &mut model, &s, aero, &map, observer))
                }
            },
        },
    };
    built.unwrap_or_else(|e| RunOutput::failed(f, e.to_string()))
}
