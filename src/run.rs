//! One run of one case: load and validate, solve, judge the checks, time every stage; a
//! contact solve that ended singular is a failed solve ([`Outcome::failed_solve`]).

use crate::error::Result;
use crate::harness::checks::{evaluate, warnings, CheckResult};
use crate::model::admit::load;
use crate::model::Model;
use crate::solver::linear::Solution;
use crate::solver::solve_static;
use std::path::Path;
use std::time::Instant;

/// Everything a run produced.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub model: Model,
    pub solution: Solution,
    pub checks: Vec<CheckResult>,
    /// What the run should say although no check failed (see [`crate::harness::checks::warnings`]).
    pub warnings: Vec<String>,
}

impl Outcome {
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| c.passed)
    }

    /// Why the contact solve could not be solved (its system was singular: the message names
    /// the place and the remedy), unless the case expects that ending (a `terminates_with`
    /// check). The command line reports it as a failed solve, exit 2, not as a failed check.
    pub fn failed_solve(&self) -> Option<&str> {
        let expected = self
            .model
            .checks
            .iter()
            .any(|c| matches!(c, crate::io::scene::Check::TerminatesWith { .. }));
        match &self.solution.contact.as_ref()?.termination {
            crate::contact::state::Termination::Singular(why) if !expected => Some(why),
            _ => None,
        }
    }
}

/// Run the case file at `path`; `progress` hears the name of each stage.
pub fn run_case(path: &Path, progress: &mut dyn FnMut(&str)) -> Result<Outcome> {
    let start = Instant::now();
    progress("meshing");
    let model = load(path)?;
    let mesh_time = start.elapsed().as_secs_f64();
    run_model(model, mesh_time, start, progress)
}

/// Solve an already built model (`mesh_time` and `start` feed the timing breakdown).
pub fn run_model(
    model: Model,
    mesh_time: f64,
    start: Instant,
    progress: &mut dyn FnMut(&str),
) -> Result<Outcome> {
    let mut solution = solve_static(&model, progress)?;
    crate::post::check_finite_stresses(&model, &solution.u)?;
    progress("checking");
    let checks = evaluate(&model, &solution);
    let warnings = model
        .warnings
        .iter()
        .cloned()
        .chain(warnings(&model, &solution))
        .collect();
    solution.timings.mesh = mesh_time;
    solution.timings.total = start.elapsed().as_secs_f64();
    Ok(Outcome {
        warnings,
        model,
        solution,
        checks,
    })
}
