//! The static solve under finite kinematics (`physics.kinematics: "finite"`): load steps of
//! Newton's method on the total-Lagrangian equilibrium `f_int(u) = lambda f_ext` (with the
//! prescribed values times the load factor too), each step cut in half when Newton fails.
//!
//! **Residual and tangent.** The solids' part of the Newton system
//! ([`crate::solver::contact_newton`]) is `R(u) = f_int(u) - f_ext` and `K_T(u)`, assembled by
//! [`crate::solver::finite_assembly`] from the hyperelastic kernels of
//! [`crate::solid_finite`] (material + geometric part, the consistent tangent, so Newton
//! converges quadratically). Contact rows against rigid masters are
//! added by the contact system unchanged: in the current geometry their gap and normal are
//! functions of `x = X + u`, searched again at every Newton iterate, and the circle's (2D) or
//! sphere's (3D) second derivative of the gap enters the tangent. The driver is generic over
//! the dimension: 3D cases ([`crate::run3d`]) run it with the same kernels,
//! generic over the dimension.
//!
//! **Load stepping with automatic cuts.** Step `k` of `n` drives the load factor to `k / n`
//! (load paths at their own factors, [`crate::model::Model::at_load`]). When Newton fails on a
//! step (iteration limit, a tangent that cannot be factored, or an element inverted at an
//! iterate: `det F <= 0` at a quadrature point, named with its body and cell), the step is
//! retried from the last converged state with half the load increment, at most
//! [`MAX_STEP_CUTS`] times in the whole solve; after a converged step the increment doubles again, up to
//! the nominal `1 / n`. Every attempt, converged or cut with its reason, is recorded in the
//! history ([`FiniteHistory`], `summary.json`'s `finite`). When the cuts are spent the run
//! stops with an error naming the step, the load factor and the last reason.
//!
//! **Friction history.** Coulomb friction is path dependent: each accepted step commits every
//! frictional point's plastic slip and forces ([`crate::contact::friction::Committed`]), and
//! the next step (or a cut retry of it) starts from them, as the small-strain load steps of
//! [`crate::solver::active_set::solve`] do. (Under finite kinematics friction is solved against
//! a flat rigid master only, whose tangents do not turn: see
//! [`crate::model::coulomb_obstacle`].)

use super::active_set::{active_keys, StepRecord};
use super::contact_newton::solve_step;
pub use super::history::{FiniteHistory, FiniteStep};
use super::linear::Solution;
use crate::contact::friction::Committed;
use crate::contact::state::{IterationRecord, Termination};
use crate::contact::RowKey;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::solver::contact_newton::NewtonDimension;
use std::collections::{HashMap, HashSet};

/// The most cuts of load increments in one solve (each halves the increment; the smallest
/// increment is `2^-MAX_STEP_CUTS` of the nominal one). A bound on the whole solve, not on
/// cuts in a row: with the increment doubling after each converged step, a limit per row
/// would let a load that approaches an unreachable state (an element about to invert) take
/// ever smaller steps without end.
pub const MAX_STEP_CUTS: usize = 10;

/// Solve `model` (finite kinematics) in load steps with automatic cuts.
pub fn solve<const D: usize, K: NewtonDimension<D>>(
    model: &Model<D, K>,
    progress: &mut dyn FnMut(&str),
) -> Result<Solution<D>> {
    solve_observed(model, progress, &mut |_, _| {})
}

/// [`solve`], calling `on_step(load_factor, solution)` after every accepted load step with the
/// state it converged to (displacements, reactions, the contact rows and forces of that step,
/// and its Newton residual history in `contact.history`), for studies that follow a load path
/// (`harness::finite_sliding`, `tests/finite_objectivity.rs`).
pub fn solve_observed<const D: usize, K: NewtonDimension<D>>(
    model: &Model<D, K>,
    progress: &mut dyn FnMut(&str),
    on_step: &mut dyn FnMut(f64, &Solution<D>),
) -> Result<Solution<D>> {
    let n = model.solver.load_steps;
    let nominal = 1.0;
    let (mut done, mut increment) = (0.0f64, nominal);
    let mut previous: Option<HashSet<RowKey>> = None;
    let mut start: Option<Vec<f64>> = None;
    let mut record = FiniteHistory::default();
    let mut records: Vec<StepRecord> = Vec::new();
    let mut contact_history: Vec<IterationRecord> = Vec::new();
    // the committed plastic slip of every frictional point at the last accepted step: a cut
    // step starts again from it
    let mut friction: HashMap<RowKey, Committed> = HashMap::new();
    let mut timings = crate::solver::linear::Timings::default();
    loop {
        let target = if done + increment >= n as f64 {
            n as f64
        } else {
            done + increment
        };
        let attempt = record.steps.len() + 1;
        let at = model.at_load(target, n);
        let mut solution = solve_step(
            &at,
            previous.clone(),
            start.clone(),
            friction.clone(),
            progress,
        )?;
        timings.accumulate(&solution.timings);
        let state = solution.contact.as_mut().expect("a Newton solve");
        let converged = state.termination == Termination::Converged;
        let (from, to) = (done / n as f64, target / n as f64);
        for r in &mut state.history {
            r.step = attempt;
        }
        record.history.extend(state.history.iter().cloned());
        let why = match &state.termination {
            Termination::Converged => None,
            Termination::IterationLimit => Some(format!(
                "Newton did not converge in {} iterations: {}",
                model.solver.max_iterations,
                why_not_converged(&state.history)
            )),
            Termination::Singular(why) => Some(why.clone()),
            other => Some(format!("{other:?}")),
        };
        record.steps.push(FiniteStep {
            attempt,
            from,
            to,
            termination: state.termination.clone(),
            iterations: state.iterations,
            accepted: converged,
            cut_because: why.clone(),
        });
        if !converged {
            let why = why.expect("a failed step has a reason");
            if record.cuts >= MAX_STEP_CUTS {
                return Err(Error::Solver {
                    path: model.source.clone(),
                    problem: format!(
                        "load step {attempt} (load factor {from} to {to}) failed, and the {MAX_STEP_CUTS} cuts of the load increment a solve may take are spent: {why}"
                    ),
                    hint: "apply the load in more steps (solver.load_steps), raise solver.max_iterations, or check that the load does not turn an element inside out (a softer support, a finer mesh)".into(),
                });
            }
            record.cuts += 1;
            increment *= 0.5;
            continue;
        }
        on_step(to, &solution);
        let state = solution.contact.as_mut().expect("a Newton solve");
        records.push(StepRecord {
            step: records.len() + 1,
            load_factor: to,
            termination: Termination::Converged,
            iterations: state.iterations,
            geometry_updates: state.geometry_updates,
            geometry_changes: std::mem::take(&mut state.geometry_changes),
            friction: state.friction_summary(None),
        });
        contact_history.append(&mut state.history);
        done = target;
        if done >= n as f64 {
            state.steps = records;
            state.history = contact_history;
            solution.timings = timings;
            if model.contact.is_empty() {
                solution.contact = None;
            }
            solution.finite = Some(Box::new(record));
            return Ok(solution);
        }
        previous = Some(active_keys(state));
        friction = state.friction_history();
        start = Some(solution.u);
        increment = (increment * 2.0).min(nominal);
    }
}

/// How many of the last iterations [`why_not_converged`] looks at.
const LAST_ITERATIONS: usize = 20;

/// What the residual history of a load step that ran out of Newton iterations shows, for its
/// failure message: rows still opening and closing in the last [`LAST_ITERATIONS`]
/// iterations (the active set cycles), or a residual that stalled (the last residual within a
/// decade of the best one: Newton has reached what the evaluation of the residual resolves,
/// e.g. a penalty far stiffer than the bodies), or one that did not settle (its first, best
/// and last values).
fn why_not_converged(history: &[IterationRecord]) -> String {
    let (Some(first), Some(last)) = (history.first(), history.last()) else {
        return "no iteration was recorded".into();
    };
    let best = history
        .iter()
        .map(|h| h.residual)
        .fold(f64::INFINITY, f64::min);
    let recent = &history[history.len().saturating_sub(LAST_ITERATIONS)..];
    let changing = recent.iter().filter(|h| h.status_changes > 0).count();
    if changing > 0 {
        return format!(
            "the active set was still changing ({changing} of the last {} iterations opened or closed a contact row; relative residual {:.1e}, best {best:.1e}): rows at the edge of the contact open and close in turn",
            recent.len(),
            last.residual
        );
    }
    if last.residual <= 10.0 * best {
        return format!(
            "the relative residual stalled at {:.1e} (best {best:.1e}, from {:.1e}) with a fixed active set: Newton reached what the residual resolves, above the tolerance (a penalty far stiffer than the bodies lifts that floor: a smaller kappa, or Lagrange multipliers, which reach the tolerance on the same rigid sphere)",
            last.residual, first.residual
        );
    }
    format!(
        "the relative residual went from {:.1e} to {:.1e} (best {best:.1e}) with a fixed active set",
        first.residual, last.residual
    )
}
