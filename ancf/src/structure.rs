//! [`formulation::Structure`] for the ANCF model: what the analyses need from it.

use formulation::{BeamGeometry, Energies, LoadError, Momentum, SectionLoad, SectionMotion, SectionState, Structure};
use genalpha::{GenAlpha, IntegratorParams, State};
use nalgebra::{Matrix3, Vector3};

use crate::{Model, PointLoad, SkylineLu};

impl Structure for Model {
    /// ANCF brings its skyline LU (banded, symmetric structure).
    type Solver = SkylineLu;
    fn integrator(&self, params: IntegratorParams) -> Result<GenAlpha<SkylineLu>, genalpha::Error> {
        Model::integrator(self, params)
    }
    fn initial_state(&self) -> State {
        Model::initial_state(self)
    }
    fn carry_state(&self, old: &Self, q: &[f64], v: &[f64]) -> Result<(Vec<f64>, Vec<f64>), String> {
        Model::carry_state(self, old, q, v).map_err(|e| e.to_string())
    }
    fn tip(&self, q: &[f64]) -> [f64; 3] {
        self.tip_position(q).into()
    }
    fn fold(&self, q: &[f64], joint: usize) -> f64 {
        self.fold_angle(q, joint).unwrap_or(f64::NAN)
    }
    fn hinge_rate(&self, q: &[f64], v: &[f64], joint: usize) -> f64 {
        Model::hinge_rate(self, q, v, joint).unwrap_or(f64::NAN)
    }
    fn energies(&self, q: &[f64], v: &[f64]) -> Energies {
        Model::energies(self, q, v)
    }
    fn momentum(&self, q: &[f64], v: &[f64]) -> Momentum {
        Model::momentum(self, q, v)
    }
    fn dissipation_power(&self, q: &[f64], v: &[f64]) -> f64 {
        Model::dissipation_power(self, q, v)
    }
    fn has_force_elements(&self) -> bool {
        self.n_force_elements() > 0
    }
    fn external_power(&self, t: f64, q: &[f64], v: &[f64]) -> f64 {
        self.thrust_power(t, q, v)
    }
    fn has_external_power(&self) -> bool {
        self.has_thrust()
    }
    fn constraint_residual(&self, q: &[f64]) -> f64 {
        Model::constraint_residual(self, q)
    }
    fn n_bodies(&self) -> usize {
        Model::n_bodies(self)
    }
    fn body_length(&self, body: usize) -> Option<f64> {
        self.body_spec(body).map(|b| b.length)
    }
    /// The nodes of ANCF's two-node elements, equally spaced.
    fn body_geometry(&self, q: &[f64], body: usize, out: &mut BeamGeometry) {
        out.clear();
        let Some(spec) = self.body_spec(body) else { return };
        for k in 0..=spec.n_elements {
            let s = spec.length * k as f64 / spec.n_elements as f64;
            if let Ok((p, r)) = self.section_frame(q, body, s) {
                out.push(s, p, r);
            }
        }
    }
    /// Exact rates: ANCF's points and slopes are linear in the coordinates.
    fn section_states(&self, q: &[f64], v: &[f64], at: &[(usize, f64)], out: &mut Vec<SectionState>) -> bool {
        Model::section_states(self, q, v, at, out).is_ok()
    }
    /// Exact accelerations, for the same reason.
    fn section_motions(
        &self,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        at: &[(usize, f64)],
        out: &mut Vec<SectionMotion>,
    ) -> bool {
        Model::section_motions(self, q, v, a, at, out).is_ok()
    }
    fn section_pose(&self, q: &[f64], body: usize, s: f64) -> (Vector3<f64>, Matrix3<f64>) {
        self.section_frame(q, body, s).unwrap_or((Vector3::from_element(f64::NAN), Matrix3::identity()))
    }
    /// Each station's force and moment as a [`PointLoad`] on the beam axis.
    fn apply_section_loads(&mut self, loads: &[SectionLoad]) -> Result<(), LoadError> {
        let pl: Vec<PointLoad> = loads
            .iter()
            .map(|l| PointLoad { body: l.body, s: l.s, y: 0.0, z: 0.0, force: l.force, moment: l.moment })
            .collect();
        // `check_section_loads` applies `check_station`'s tests (finite, body, 1e-12 range).
        self.set_point_loads(&pl).map_err(|e| LoadError::Model(e.to_string()))
    }
}
