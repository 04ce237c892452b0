//! One run of one case: load and validate, solve, judge the checks, time every stage; a
//! contact solve that ended singular is a failed solve ([`Outcome::failed_solve`]). One
//! [`Outcome`] for both dimensions (`D = 2` by default; a 3D case runs through
//! [`crate::run3d::run_case3`]); [`run_checked`] runs a case file of either dimension for the
//! harness commands that only need its verdicts.

use crate::error::Result;
use crate::fe::ElementKind;
use crate::harness::checks::{evaluate, warnings, CheckResult};
use crate::model::admit::load;
use crate::model::space::SolidCell;
use crate::model::Model;
use crate::solver::linear::Solution;
use crate::solver::solve_static;
use std::path::Path;
use std::time::Instant;

/// Everything a run produced.
#[derive(Clone, Debug)]
pub struct Outcome<const D: usize = 2, K: SolidCell<D> = ElementKind> {
    pub model: Model<D, K>,
    pub solution: Solution<D>,
    /// The declared checks, and a failing one of its own when the contact solve did not
    /// converge (unless the case states how it ends).
    pub checks: Vec<CheckResult>,
    /// What the run should say although no check failed (see [`crate::harness::checks::warnings`]).
    pub warnings: Vec<String>,
}

impl<const D: usize, K: SolidCell<D>> Outcome<D, K> {
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| c.passed)
    }

    /// Whether the contact solve converged (`true` without contact).
    pub fn converged(&self) -> bool {
        self.solution
            .contact
            .as_ref()
            .is_none_or(|c| c.termination == crate::contact::state::Termination::Converged)
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

    /// What a harness command reports of the run, whatever its dimension.
    pub fn verdicts(&self) -> Verdicts {
        Verdicts {
            name: self.model.name.clone(),
            checks: self.checks.clone(),
            warnings: self.warnings.clone(),
            seconds: self.solution.timings.total,
        }
    }
}

/// The verdicts of one run of a case of either dimension ([`run_checked`]).
#[derive(Clone, Debug)]
pub struct Verdicts {
    pub name: String,
    pub checks: Vec<CheckResult>,
    pub warnings: Vec<String>,
    /// The run's wall time, meshing to checks.
    pub seconds: f64,
}

/// Run the case file at `path`, 2D or 3D, for its verdicts.
pub fn run_checked(path: &Path, progress: &mut dyn FnMut(&str)) -> Result<Verdicts> {
    match crate::run3d::read_3d_case(path) {
        Some(case) => {
            progress("solving");
            crate::run3d::run_case3(&case, &path.display().to_string()).map(|o| o.verdicts())
        }
        None => run_case(path, progress).map(|o| o.verdicts()),
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
