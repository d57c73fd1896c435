//! A case's runs: its problem ([`Case::problem`]) built and integrated by
//! [`aeroelastic::factory`], the one place that picks a formulation's model type.

pub use aeroelastic::factory::{BuildModel, ForModel, dispatch, predictor};

use aeroelastic::run::{Observer, RunOutput, RunSettings};

use crate::Error;
use crate::{Case, Formulation};

/// The integrator parameters, end time and output interval of formulation `f` of a case.
pub fn settings(case: &Case, f: Formulation) -> RunSettings {
    aeroelastic::factory::settings(&case.problem(), f)
}

/// Build the ANCF model of a case (DAE or ODE path as the case says).
pub fn build_ancf(case: &Case) -> Result<ancf::Model, Error> {
    Ok(aeroelastic::factory::build_ancf(&case.problem())?)
}

/// Build the GEBF model of a case.
pub fn build_gebf(case: &Case) -> Result<gebf::Model, Error> {
    Ok(aeroelastic::factory::build_gebf(&case.problem())?)
}

/// Build and integrate formulation `f` of `case`. Never panics on bad input: a model that cannot
/// be built gives a failed [`RunOutput`] with the reason.
pub fn run_formulation(case: &Case, f: Formulation) -> RunOutput {
    aeroelastic::factory::run_formulation(&case.problem(), f)
}

/// As [`run_formulation`], handing every output step's geometry to `observer`.
pub fn run_formulation_observed(case: &Case, f: Formulation, observer: &mut dyn Observer) -> RunOutput {
    aeroelastic::factory::run_formulation_observed(&case.problem(), f, observer)
}
