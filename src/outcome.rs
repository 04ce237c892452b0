//! What a run of a case produced, in either dimension: the model, the solution, the verdicts
//! of its checks and its warnings ([`Outcome`]), and the part of it a harness command reports
//! ([`Verdicts`]). Plain data below the runners ([`crate::run`] for 2D, [`crate::run3d`] for
//! 3D), which both build it.

use crate::fe::ElementKind;
use crate::harness::checks::CheckResult;
use crate::model::space::SolidCell;
use crate::model::Model;
use crate::solver::linear::Solution;

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
    /// Whether the case passes: no check fails it ([`CheckResult::fails_the_case`]: a check
    /// the case expects to fail may fail, and must).
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| !c.fails_the_case())
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
