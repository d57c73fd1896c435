//! The one conversion from a case file's types to the library's: [`Case::problem`].

use aeroelastic::Problem;

use super::{Case, Formulation, RunSpec, StaticSettings};

impl Case {
    /// The typed problem of this case for the analyses of [`aeroelastic`]: its structure, both
    /// formulations' settings and its aerodynamic, static, stability and gust settings (the
    /// references, gate, sweep, convergence study and VTK output stay with the case). Every
    /// flared hinge's joint is placed on its hinge line (`hinge_line_y`,
    /// [`Problem::with_hinge_lines`]).
    pub fn problem(&self) -> Problem {
        self.problem_as_written().with_hinge_lines()
    }

    /// The problem with the bodies as the case writes them (the hinge lines not yet placed).
    pub(crate) fn problem_as_written(&self) -> Problem {
        Problem {
            name: self.name.clone(),
            bodies: self.bodies.clone(),
            joints: self.joints.clone(),
            gravity: self.gravity,
            pitch_deg: self.pitch_deg,
            stiffness_scale: self.stiffness_scale,
            t_end: self.t_end,
            output_dt: self.output_dt,
            fold_joint: self.fold_joint.clone(),
            roll_joint: self.roll_joint.clone(),
            root_joint: self.root_joint.clone(),
            events: self.events.clone(),
            thrust: self.thrust.clone(),
            trim: self.trim.clone(),
            initial: self.initial,
            ancf: self.ancf.clone(),
            gebf: self.gebf.clone(),
            aero: self.aero.clone(),
            statics: self.statics.as_ref().map(StaticSettings::problem),
            stability: self.stability.clone(),
            gust: self.gust.clone(),
            polars: self.polars.clone(),
        }
    }
}

impl StaticSettings {
    /// The library's static settings (without the references, which only the report reads).
    pub fn problem(&self) -> aeroelastic::problem::StaticSettings {
        aeroelastic::problem::StaticSettings {
            airspeeds: self.airspeeds.clone(),
            point_loads: self.point_loads.clone(),
            load_factors: self.load_factors.clone(),
            wake: self.wake,
            sideslips_deg: self.sideslips_deg.clone(),
            difference_tangent: false,
        }
    }
}

impl RunSpec {
    /// The gust sweep of this run ([`aeroelastic::gust::run_sweep`]) with the formulations `fs`,
    /// each on its own case's problem.
    ///
    /// # Errors
    /// The sweep's message when it cannot start.
    pub fn gust_sweep(&self, fs: &[Formulation]) -> Result<aeroelastic::gust::GustSweepOutput, String> {
        let problems: Vec<(Formulation, Problem)> = fs.iter().map(|&f| (f, self.case(f).problem())).collect();
        let cases: Vec<(Formulation, &Problem)> = problems.iter().map(|(f, p)| (*f, p)).collect();
        aeroelastic::gust::run_sweep(&self.ancf.problem(), &cases)
    }
}
