//! What a contact solve found and how it got there: the rows with their forces, gaps and
//! active set, the termination, and the record of its load steps, geometry updates and
//! iterations. Plain data, written by [`crate::solver::active_set`] and read by the checks, the harness and
//! the output (`summary.json`).

use super::friction::{FrictionSummary, Status};
use super::Constraint;

/// Why the active-set loop stopped.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    Converged,
    IterationLimit,
    /// The active set repeated (a cycle) and the remedy was off or did not help: the points
    /// that flip-flopped and what to change.
    ActiveSetCycling(String),
    /// The linear system could not be solved (the message says why).
    Singular(String),
    /// The iterations reached the work limit of the case (`limits.iteration_dofs`) before the
    /// set settled (the message says how far it got and what to change).
    WorkLimit(String),
}

/// What the contact solve found.
#[derive(Clone, Debug)]
pub struct ContactState<const D: usize = 2> {
    pub rows: Vec<Constraint<D>>,
    pub active: Vec<bool>,
    /// Contact force of each row (zero when inactive).
    pub forces: Vec<f64>,
    pub gaps: Vec<f64>,
    pub termination: Termination,
    /// Linear solves performed (Newton iterations, inner and outer).
    pub iterations: usize,
    /// Number of dependent rows among the active constraints (rank deficiency of `B B^T`):
    /// computed for Lagrange multipliers and elimination (multiplier systems) up to
    /// [`crate::solver::active_set::DENSE_MULTIPLIER_LIMIT`] active rows, for the other
    /// methods up to [`crate::solver::active_set::RANK_CHECK_LIMIT`] (it costs `O(m^3)`);
    /// `None` when not measured.
    pub rank_deficiency: Option<usize>,
    /// The linear solver of the last iteration: `cholesky` (penalty-type, perturbed tangent,
    /// augmented Lagrangian, elimination), `ldlt` (Lagrange, independent rows), `lu` (Lagrange,
    /// when LDL^T refuses) or `schur-pseudo-inverse` (Lagrange, dependent rows).
    pub linear_solver: &'static str,
    /// Evaluations of the contact geometry (1 in the reference configuration).
    pub geometry_updates: usize,
    /// The displacement the rows were linearized at (`None`: the reference configuration).
    pub configuration: Option<Vec<f64>>,
    /// Slave nodes that left the master surface during the geometry updates.
    pub departures: Vec<Departure>,
    /// The load steps so far (the last one is this state's).
    pub steps: Vec<StepRecord>,
    /// Every iteration of every geometry update of every load step.
    pub history: Vec<IterationRecord>,
    /// Relative change of the displacement at each geometry update of the last step (current
    /// geometry): how the geometry iteration converged.
    pub geometry_changes: Vec<f64>,
    /// Per row: its frictional state (Coulomb pairs; `None` for frictionless and tied rows).
    pub friction: Vec<Option<super::friction::FrictionPoint>>,
}

impl<const D: usize> ContactState<D> {
    /// The committed slip and the forces of every frictional point at the end of this state's
    /// step: the history the next load step starts from.
    pub(crate) fn friction_history(
        &self,
    ) -> std::collections::HashMap<crate::contact::RowKey, crate::contact::friction::Committed>
    {
        committed_history(&self.rows, &self.friction)
    }

    /// The frictional totals (tangential force, stick/slip/open counts, dissipation, the
    /// largest cone ratio) of pair `pair`, or of all pairs for `None`; `None` when no row of
    /// them is frictional.
    pub fn friction_summary(&self, pair: Option<usize>) -> Option<FrictionSummary> {
        let mut out = FrictionSummary {
            tangential_force: vec![0.0; D],
            open: 0,
            stick: 0,
            slip: 0,
            dissipation: 0.0,
            max_cone_ratio: 0.0,
        };
        let mut any = false;
        for (r, f) in self.rows.iter().zip(&self.friction) {
            let (Some(f), true) = (f, pair.is_none_or(|p| p == r.pair)) else {
                continue;
            };
            any = true;
            for (t, &component) in r.tangents.iter().zip(&f.force) {
                for k in 0..D {
                    out.tangential_force[k] += component * t.direction[k];
                }
            }
            match f.status {
                Status::Open => out.open += 1,
                Status::Stick => out.stick += 1,
                Status::Slip => out.slip += 1,
            }
            out.dissipation += f.dissipation;
            let magnitude = f.force_length();
            if f.status != Status::Open && magnitude != 0.0 {
                out.max_cone_ratio = out
                    .max_cone_ratio
                    .max(magnitude / (f.mu * f.normal_force.max(0.0)));
            }
        }
        any.then_some(out)
    }
}

/// The committed slip and the forces of every frictional point of `rows` (`friction` aligned
/// with them) at the end of a step, by point.
pub(crate) fn committed_history<const D: usize>(
    rows: &[crate::contact::Constraint<D>],
    friction: &[Option<crate::contact::friction::FrictionPoint>],
) -> std::collections::HashMap<crate::contact::RowKey, crate::contact::friction::Committed> {
    rows.iter()
        .zip(friction)
        .filter_map(|(r, f)| {
            f.map(|f| {
                (
                    crate::contact::row_key(r),
                    crate::contact::friction::Committed {
                        slip: f.plastic_slip,
                        normal_force: f.normal_force,
                        tangential_force: f.force,
                        start_slip: f.slip,
                    },
                )
            })
        })
        .collect()
}

/// One converged (or stopped) load step.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct StepRecord {
    pub step: usize,
    pub load_factor: f64,
    pub termination: Termination,
    /// Linear solves of the step's active-set loop (its last geometry update).
    pub iterations: usize,
    pub geometry_updates: usize,
    /// Relative change of the displacement at each geometry update (current geometry; empty in
    /// the reference configuration): quadratic decay where the rows provide their second
    /// derivative (Newton), linear where the geometry is a fixed point.
    pub geometry_changes: Vec<f64>,
    /// Coulomb pairs: the step's frictional totals over all pairs (stick/slip/open counts,
    /// dissipation, largest `|lambda_t| / (mu lambda_n)`); `None` without friction.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction: Option<super::friction::FrictionSummary>,
}

/// A slave node that was in contact at one geometry update and found no master facet at a
/// later one (it slid past the end of the master surface): it carries no contact force.
#[derive(Clone, Debug, PartialEq)]
pub struct Departure {
    pub pair: usize,
    pub body: usize,
    pub node: usize,
    /// Where it was when it left (current configuration of that update), `[x, y]` or `[x, y,
    /// z]`.
    pub point: Vec<f64>,
    pub update: usize,
}

/// Whether a converged state is a stable equilibrium: its tangent positive definite on the
/// kernel of its active contact rows (for the Lagrangian of the Lagrange multipliers, the
/// second-order condition of a minimum of the energy subject to the active rows), or not: a
/// direction along which the energy does not rise, where the slightest disturbance leaves the
/// state (a structure that buckles, a contact that slides away). See
/// [`crate::solver::newton::LinearSolver::stability_at`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stability {
    Stable,
    Unstable,
}

/// What one iteration of the active-set loop did (the solve's history, in `summary.json`).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct IterationRecord {
    /// Load step and geometry update (1-based) the iteration belongs to.
    pub step: usize,
    pub geometry_update: usize,
    pub iteration: usize,
    /// `max |K u - f - B^T lambda|` over the free equations, relative to the largest of
    /// `|f|` and `|B^T lambda|`.
    pub residual: f64,
    /// Active rows during the iteration, and how many changed status after it (the count that
    /// exposes chattering).
    pub active: usize,
    pub status_changes: usize,
    /// Largest penetration `-g` of a contact row after the iteration.
    pub max_gap_violation: f64,
    /// Largest change of a row force from the previous iteration (the first iteration of a
    /// geometry update or step counts from zero).
    pub multiplier_change: f64,
    pub linear_solver: &'static str,
    /// Estimated 1-norm condition number of the last system factored for this iteration
    /// ([`crate::solver::conditioning`]); `None` when the solver has no estimate (the active-set
    /// scheme's LU fallback and pseudo-inverse).
    pub condition_estimate: Option<f64>,
    pub seconds: f64,
    /// The active set this iteration chose had been chosen before in the same loop (a cycle;
    /// active-set scheme).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub repeated_set: bool,
    /// The cycling remedy (`solver.cycling_remedy`) was in force in this iteration.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub cycling_remedy: bool,
    /// On the last iteration of a converged Newton solve with a symmetric tangent: whether the
    /// state it converged to is a stable equilibrium ([`crate::solver::newton::Stability`]);
    /// absent elsewhere.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stability: Option<Stability>,
    /// The length of the Newton step that reached this iterate, as a share of the full step:
    /// below 1 where the line search shortened it ([`crate::solver::newton::ARMIJO`]); 1 for a
    /// full step and for a scheme without line search (absent from the output then).
    #[serde(skip_serializing_if = "is_full_step")]
    pub step_length: f64,
}

fn is_full_step(length: &f64) -> bool {
    *length == 1.0
}
