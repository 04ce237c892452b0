//! Newton's method on a [`System`]: the residual `R(x)` and the tangent `K_T(x) = dR/dx` at the
//! current state, and one linear solve per iteration, `K_T(x_k) dx = -R(x_k)`,
//! `x_{k+1} = x_k + dx`.
//!
//! Contact makes `R` piecewise smooth (a row is active or not; later, sticks or slips). The
//! iteration is then the semi-smooth Newton method (Hintermüller, Ito & Kunisch, SIAM J. Optim.
//! 13 (2003) 865-888; for contact, Hüeber & Wohlmuth, CMAME 194 (2005) 3147-3166): the system
//! decides the status of every point from the current iterate inside [`System::evaluate`] and
//! gives the tangent of the branch it chose. An iteration has converged when the residual at
//! the iterate is below `tolerance` times the system's force scale and the status of no point
//! changed in that evaluation; a linear problem with a fixed status converges in one solve.
//! A residual that cannot reach the tolerance in floating point (terms far larger than the
//! loads cancel, as in a body `1e6` times stiffer than the other) counts as converged at its
//! round-off floor ([`Evaluation::residual_floor`]) once a step has moved the iterate by at
//! most [`SETTLED_STEP`] of its size.
//! Where the system asks for it ([`System::line_search`]), every Newton step is globalized by
//! a backtracking line search on the residual norm, monotone or not ([`ARMIJO`],
//! [`NONMONOTONE_WINDOW`]): the full step is taken unless it raises the residual above the
//! largest of the last few iterates', and the length taken is recorded with the iteration
//! (`step_length` in the history). Shortened steps that creep without progress
//! ([`line_search_stall`]) are met as a cycle is, by [`System::remedy_cycle`].
//! Augmented Lagrangian updates (Uzawa) are the system's business too:
//! [`System::augment`] runs between iterations and tells whether it moved a multiplier.
//!
//! Linear algebra sits behind one interface, [`LinearSolver`]: sparse Cholesky for a symmetric
//! tangent, sparse LU (its symbolic analysis reused) for an unsymmetric one or when Cholesky
//! meets a pivot that is not positive (a symmetric tangent made indefinite by a geometric
//! term); a factorization is reused when the tangent's values have not changed.

use super::constraints::ConstraintBuilder;
use super::sparse::{
    Cholesky, Factor, FactorError, GeneralPattern, Ldlt, LdltFactor, Lu, LuFactor,
    SymmetricPattern, WorkLimit,
};
use crate::contact::state::{IterationRecord, Termination};
use crate::error::Result;
use crate::solver::conditioning::{condition_estimate_general, condition_estimate_symmetric};
use std::time::Instant;

/// The tangent of one evaluation, on the system's pattern (both triangles).
pub struct Tangent {
    /// Values on [`LinearSolver::general`] (both triangles).
    pub values: Vec<f64>,
    /// Whether the values are symmetric (then Cholesky is tried first).
    pub symmetric: bool,
    /// The trailing unknowns that are (scaled) Lagrange multipliers: a symmetric tangent with
    /// multipliers is a saddle-point matrix, factored by `L D L^T` with negative pivots there.
    pub multipliers: usize,
    /// The stiffness scale of the saddle-point matrix (its pivots below `1e-13` of it count as
    /// zero).
    pub scale: f64,
    /// Constraint elimination: the saddle-point matrix is not factored; each active multiplier
    /// row `(j, o)` is solved for its owned unknown `o` instead (see
    /// `LinearSolver::solve_eliminating`). `None`: factor the matrix.
    pub elimination: Option<Vec<(usize, usize)>>,
    /// The displacement block carries second derivatives of contact gaps (`-force H`, finite
    /// kinematics) and may be indefinite: a saddle-point matrix whose `L D L^T` meets a pivot
    /// of the wrong sign is then factored by LU, as an indefinite symmetric matrix without
    /// multipliers is. `false`: such a pivot means dependent rows, and the solve ends there.
    pub indefinite_block: bool,
}

/// What an evaluation reports besides the residual and the tangent.
#[derive(Clone, Debug, Default)]
pub struct Evaluation {
    /// The force scale the residual is judged against (largest applied or contact force).
    pub force_scale: f64,
    /// Active points in this evaluation, and how many changed status against the last one.
    pub active: usize,
    pub status_changes: usize,
    /// Largest penetration of a contact point at the iterate.
    pub max_gap_violation: f64,
    /// Largest change of a point's force against the last evaluation.
    pub multiplier_change: f64,
    /// The round-off floor of the residual's evaluation (absolute, in the residual's max
    /// norm): [`ROUNDOFF_TERMS`] `eps max_i sum_j |a_ij x_j|` over the terms the system sums
    /// into row `i`. A residual at or below it cannot be reduced further in floating point; the
    /// iteration is then converged even when the relative tolerance is out of reach (a stiff
    /// body's `K x` cancels terms `1e6` times larger than the loads). Zero: no floor (only the
    /// relative tolerance counts).
    pub residual_floor: f64,
}

/// Iterations over which a cycle must hold before the iteration stops ([`cycle_period`]).
const CYCLE_ITERATIONS: usize = 6;

/// The period (1 or 2) of a cycle at the end of `history` (relative residual and status
/// changes of each iteration): in each of the last [`CYCLE_ITERATIONS`] iterations some point
/// changed status, and the residual equals (to 1e-9 of itself) the one `period` iterations
/// earlier. A semi-smooth Newton iteration whose sets flip back and forth repeats its iterates
/// and residuals exactly; one that makes progress does not repeat its residual.
fn cycle_period(history: &[(f64, usize)]) -> Option<usize> {
    let n = history.len();
    if n < CYCLE_ITERATIONS || history[n - CYCLE_ITERATIONS..].iter().any(|h| h.1 == 0) {
        return None;
    }
    (1..=2).find(|&p| {
        (n - CYCLE_ITERATIONS + p..n).all(|k| {
            let (a, b) = (history[k].0, history[k - p].0);
            a.is_finite() && (a - b).abs() <= 1e-9 * a.abs()
        })
    })
}

/// The share of its residual norm a line search must remove over [`CYCLE_ITERATIONS`]
/// iterations whose steps it all shortened ([`line_search_stall`]).
const STALL_CONTRACTION: f64 = 0.5;

/// Whether the line search stalls at the end of `history` (residual norm and step length of
/// each Newton iteration): in each of the last [`CYCLE_ITERATIONS`] iterations the full step
/// was shortened, and the residual norm fell by less than [`STALL_CONTRACTION`] over them. The
/// full steps would cycle there (a slip point swinging across its stick range, whose slip
/// branch has no tangential stiffness); the shortened ones creep along the branch's direction,
/// which the kink bends away from the solution. Measured on the sliding block of
/// `cases/dynamics` with mu = 3 and kappa = 1e6: 150 iterations, each halved to 1/16, the
/// residual norm between 2.08 and 2.10. It is met as a cycle is ([`System::remedy_cycle`]);
/// where the system has no remedy left, the iteration goes on (the 3D Cattaneo-Mindlin cases
/// creep through such a stretch and converge).
fn line_search_stall(history: &[(f64, f64)]) -> bool {
    let n = history.len();
    n > CYCLE_ITERATIONS
        && history[n - CYCLE_ITERATIONS..].iter().all(|h| h.1 < 1.0)
        && history[n - 1].0 > STALL_CONTRACTION * history[n - 1 - CYCLE_ITERATIONS].0
}

/// How many unit round-offs of the summed terms' magnitude make the floor of a residual's
/// evaluation: a sum of `m` terms errs by up to `m eps` of their magnitude (Higham, Accuracy
/// and Stability of Numerical Algorithms, 2nd ed. 2002, sec. 3.1), typically by about
/// `sqrt(m) eps`; a Q4 row sums 18 stiffness terms, and the iterate itself is rounded to
/// `eps`. On `cases/hard/stiffness-ratio-1e6` (Newton) the residual stalls at 0.1 to 0.8 of
/// `eps` times the magnitude.
pub const ROUNDOFF_TERMS: f64 = 16.0;

/// The residual's round-off floor ends the iteration only after a step that moved the iterate by
/// at most this fraction of its largest entry (max norms): Newton has settled, and the residual
/// stalls because of round-off, not because the iterate is far off.
pub const SETTLED_STEP: f64 = 1e-6;

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, a| m.max(a.abs()))
}

/// A nonlinear problem in `n` unknowns with a fixed sparsity pattern.
pub trait System {
    /// The pattern of the tangent (upper triangle). An evaluation may grow it (a contact point
    /// that slides onto new master nodes): [`System::pattern_version`] then changes, and the
    /// driver analyses the new pattern and evaluates again (that evaluation's output is unused).
    fn pattern(&self) -> &SymmetricPattern;
    /// Changes whenever [`System::pattern`] does.
    fn pattern_version(&self) -> usize {
        0
    }
    /// The unknowns `x` of the previous pattern carried to the current one (a system whose
    /// unknowns change with its pattern, e.g. the multipliers of rows that appeared).
    fn carry(&mut self, x: &[f64]) -> Vec<f64> {
        x.to_vec()
    }
    /// Residual `R(x)` into `residual` and the tangent at `x` on `general` (both triangles of
    /// [`System::pattern`]); the status of every point is decided here.
    fn evaluate(
        &mut self,
        x: &[f64],
        general: &GeneralPattern,
        residual: &mut [f64],
        tangent: &mut Tangent,
    ) -> Result<Evaluation>;
    /// What unknown `k` is, for messages.
    fn describe_unknown(&self, k: usize) -> String {
        format!("unknown {k}")
    }
    /// Between iterations, after the iterate `x` (`converged`: the residual test passed):
    /// update augmentations; `true` if anything moved (then the iteration has not converged).
    fn augment(&mut self, _x: &[f64], _converged: bool) -> bool {
        false
    }
    /// When the iteration cycles (`cycle_period`): change what steers the path without
    /// changing the solution, and say what was changed (`None`: nothing left to change; the
    /// solve then stops with [`Termination::ActiveSetCycling`]).
    fn remedy_cycle(&mut self) -> Option<String> {
        None
    }
    /// Whether every Newton step is globalized by the backtracking line search on the residual
    /// norm ([`ARMIJO`], [`SHORTEST_STEP`]), and over how many accepted iterates its reference
    /// is the largest residual norm (1: monotone; [`NONMONOTONE_WINDOW`]). `None`: full steps.
    fn line_search(&self) -> Option<usize> {
        None
    }
    /// What else may help when the iteration cycles with nothing left to change (appended to
    /// the [`Termination::ActiveSetCycling`] message after `; `), for the kind of rows this
    /// system has. `None`: only the general advice ([`System::smaller_increment`]).
    fn cycle_advice(&self) -> Option<String> {
        None
    }
    /// How this system's increment is made smaller, the general advice after a cycle: the
    /// load steps of a static solve (the default), the time step of a dynamic one.
    fn smaller_increment(&self) -> &'static str {
        "apply the load in more load steps (solver.load_steps)"
    }
}

/// The sufficient decrease of the backtracking line search (Armijo's rule on the merit
/// `f(x) = |R(x)|_2^2 / 2`), non-monotone (Grippo, Lampariello & Lucidi, SIAM J. Numer. Anal.
/// 23 (1986) 707-716): a step of length `alpha` along the Newton direction `dx` is taken when
/// `|R(x + alpha dx)|_2 <= (1 - ARMIJO alpha) max_j |R(x_j)|_2` over the last `w` accepted
/// iterates `x_j` (the step's start among them; `w` the system's window,
/// [`System::line_search`]: 1 is Armijo's monotone rule), else `alpha` is halved. With the (semi-smooth) tangent `J` of the branch at `x`, `J dx = -R`, the
/// directional derivative of `f` along `dx` is `R^T J dx = -|R|^2 < 0` where no point changes
/// branch within the step, so a short enough step decreases the merit (at a kink the branch's
/// tangent may not see, the search can stall: then [`SHORTEST_STEP`] is taken; Pang, Math.
/// Oper. Res. 15 (1990) 311-341, for B-differentiable equations; applied to frictional
/// contact by Christensen, Klarbring, Pang & Strömberg, Int. J. Numer. Meth. Engng. 42 (1998)
/// 145-173, sec. 4; Nocedal & Wright, Numerical Optimization, 2nd ed. 2006, sec. 3.1 and
/// 11.2). Near a solution the full step decreases the residual quadratically and is always
/// taken: the line search changes neither the answer (the residual is unchanged) nor the
/// quadratic convergence.
pub const ARMIJO: f64 = 1e-4;

/// The accepted iterates whose largest residual norm a step is measured against ([`ARMIJO`]).
/// A semi-smooth Newton iteration that changes a point's status may raise the residual for one
/// iteration on its way to the answer, and the start of a load step (the new load unbalanced)
/// usually has the largest residual of the solve: against the largest of the last few, such a
/// step is taken in full, and only a step that sends the iterate farther off than any of them
/// is shortened (the friction drag reversed in `cases/hard/friction-stick-slip-reversal`: a
/// full step raised the residual from 8.3 to 558, 3.6 times the step's first, and the
/// iteration settled into a cycle).
pub const NONMONOTONE_WINDOW: usize = 5;

/// The shortest step of the line search: at `alpha` below it the step is taken as it is (the
/// iteration then goes on as plain Newton, ending by its own tests).
pub const SHORTEST_STEP: f64 = 1.0 / 1024.0;

/// A Newton step under test by the line search: the iterate it starts from, its direction,
/// the residual norm it is measured against, and the length tried.
struct TrialStep {
    start: Vec<f64>,
    direction: Vec<f64>,
    merit: f64,
    length: f64,
}

fn euclidean(v: &[f64]) -> f64 {
    v.iter().map(|a| a * a).sum::<f64>().sqrt()
}

/// Limits and tolerance of one Newton solve.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    pub max_iterations: usize,
    /// Residual tolerance relative to [`Evaluation::force_scale`].
    pub tolerance: f64,
    /// The most memory and operations one factorization of the tangent may take.
    pub factor_limit: WorkLimit,
    /// The most Newton iterations times unknowns of this solve (`limits.iteration_dofs`): the
    /// solve takes at most `iteration_dofs / unknowns` iterations (at least one) and, when that
    /// is below `max_iterations` and reached, ends with [`Termination::WorkLimit`].
    pub iteration_dofs: u64,
}

/// How a Newton solve ended.
pub struct Outcome {
    pub termination: Termination,
    /// Linear solves performed.
    pub iterations: usize,
    pub history: Vec<IterationRecord>,
    /// Seconds spent factoring, and the solver of the last solve.
    pub factorization_seconds: f64,
    pub linear_solver: &'static str,
}

/// Run Newton's method on `system` from `x` (overwritten with the last iterate).
pub fn solve(system: &mut dyn System, x: &mut Vec<f64>, settings: Settings) -> Result<Outcome> {
    let mut linear = LinearSolver::new(system.pattern(), settings.factor_limit);
    solve_with(system, x, settings, &mut linear)
}

/// [`solve`] with a linear solver built on `system.pattern()` by the caller, whose last
/// factorization is reused while the tangent is unchanged (a sequence of solves of one system,
/// e.g. the steps of a time integration; a new pattern replaces it).
pub fn solve_with(
    system: &mut dyn System,
    x: &mut Vec<f64>,
    settings: Settings,
    linear: &mut LinearSolver,
) -> Result<Outcome> {
    let n = x.len();
    let affordable = (settings.iteration_dofs / n.max(1) as u64).max(1) as usize;
    let max_iterations = settings.max_iterations.min(affordable);
    // factoring seconds the solver had before this solve
    let mut base_seconds = linear.seconds;
    let mut version = system.pattern_version();
    let mut residual = vec![0.0; n];
    let mut history = Vec::new();
    let mut solves = 0;
    let mut start = Instant::now();
    let (mut augmented, mut augmentations) = (false, 0);
    // whether the last step moved the iterate by at most SETTLED_STEP of its size
    let mut settled = false;
    // factoring time and solver name of the linear solvers of earlier patterns
    let mut earlier_seconds = 0.0;
    let mut last_solver = "none";
    // relative residual and status changes of each Newton iteration (cycle detection)
    let mut changing: Vec<(f64, usize)> = Vec::new();
    // what the system changed to leave a cycle ([`System::remedy_cycle`])
    let mut remedies: Vec<String> = Vec::new();
    // the Newton step under test by the line search ([`System::line_search`])
    let mut trial: Option<TrialStep> = None;
    // the residual norms of the accepted iterates (the line search's reference), and the
    // length of the step that reached the current iterate
    let mut merits: Vec<f64> = Vec::new();
    let mut step_length = 1.0;
    // the residual norm and step length of each Newton iteration (stall detection)
    let mut searched: Vec<(f64, f64)> = Vec::new();
    let termination = loop {
        if system.pattern_version() != version {
            // a new pattern carries the iterate to new unknowns: the step is taken as it is
            trial = None;
            earlier_seconds += linear.seconds - base_seconds;
            // the last factorization's inertia stays the verdict of the iterates it solved for
            let inertia = linear.last_inertia;
            *linear = LinearSolver::new(system.pattern(), settings.factor_limit);
            linear.last_inertia = inertia;
            base_seconds = 0.0;
            version = system.pattern_version();
            *x = system.carry(x);
            residual = vec![0.0; x.len()];
            settled = false;
        }
        let mut tangent = Tangent {
            values: vec![0.0; linear.general.nnz()],
            symmetric: true,
            multipliers: 0,
            scale: 1.0,
            elimination: None,
            indefinite_block: false,
        };
        let eval = system.evaluate(x, &linear.general, &mut residual, &mut tangent)?;
        if system.pattern_version() != version {
            // the evaluation grew the pattern: analyse it and evaluate again
            continue;
        }
        let norm = residual.iter().fold(0.0f64, |m, v| {
            if v.is_nan() || v.abs() > m {
                v.abs()
            } else {
                m
            }
        });
        let relative = norm / eval.force_scale.max(f64::MIN_POSITIVE);
        let merit = euclidean(&residual);
        if let Some(t) = trial.as_mut() {
            // (a residual that is not finite fails the test and shortens the step too)
            let decreased = merit <= (1.0 - ARMIJO * t.length) * t.merit;
            if !decreased && t.length / 2.0 >= SHORTEST_STEP {
                t.length /= 2.0;
                for ((a, s), d) in x.iter_mut().zip(&t.start).zip(&t.direction) {
                    *a = s + t.length * d;
                }
                settled = t.length * max_abs(&t.direction) <= SETTLED_STEP * max_abs(x);
                continue;
            }
            step_length = t.length;
            trial = None;
        }
        merits.push(merit);
        // at the round-off floor only once Newton has settled: a wild iterate (a sliding body
        // sent far by one step) has a large floor of its own, and is not an answer
        let small = relative <= settings.tolerance || (settled && norm <= eval.residual_floor);
        if solves > 0 && !augmented {
            history.push(IterationRecord {
                step: 0,
                geometry_update: 0,
                iteration: solves,
                residual: relative,
                active: eval.active,
                status_changes: eval.status_changes,
                max_gap_violation: eval.max_gap_violation,
                multiplier_change: eval.multiplier_change,
                linear_solver: last_solver,
                condition_estimate: linear.last_condition,
                seconds: start.elapsed().as_secs_f64(),
                repeated_set: false,
                cycling_remedy: false,
                stability: None,
                step_length,
            });
            start = Instant::now();
        }
        // an augmentation (Uzawa) moves multipliers: the next evaluation does not augment again
        // and is always followed by a Newton step
        let converged = small && eval.status_changes == 0 && !augmented;
        if solves > 0 && !augmented {
            changing.push((relative, eval.status_changes));
            searched.push((merit, step_length));
            if line_search_stall(&searched) {
                // shortened steps creeping along a kink: what steers the path may change (a
                // solve the system has nothing for goes on to its own limit)
                if let Some(what) = system.remedy_cycle() {
                    remedies.push(what);
                    changing.clear();
                    searched.clear();
                }
            }
            if let Some(period) = cycle_period(&changing) {
                if let Some(what) = system.remedy_cycle() {
                    // a new path from this iterate: the cycle must show itself again
                    remedies.push(what);
                    changing.clear();
                    searched.clear();
                } else {
                    let tried = if remedies.is_empty() {
                        String::new()
                    } else {
                        format!(" (after {})", remedies.join(", then "))
                    };
                    let advice = system
                        .cycle_advice()
                        .map(|a| format!("; {a}"))
                        .unwrap_or_default();
                    break Termination::ActiveSetCycling(format!(
                        "Newton iteration {solves} repeats the residual {relative:.3e} of iteration {} while {} contact point(s) change status at every iteration (open, closed, stick or slip){tried}: the semi-smooth Newton iteration cycles between sets, none of which is the solution; {}{advice}",
                        solves - period,
                        eval.status_changes,
                        system.smaller_increment()
                    ));
                }
            }
        }
        if solves > 0 && !augmented && system.augment(x, converged) {
            augmented = true;
            augmentations += 1;
            if augmentations > settings.max_iterations {
                break Termination::IterationLimit;
            }
            continue;
        }
        augmented = false;
        if converged {
            if let Some(last) = history.last_mut() {
                last.stability = linear.stability_at(&tangent);
            }
            break Termination::Converged;
        }
        if !relative.is_finite() {
            break Termination::Singular(format!(
                "the residual of Newton iteration {solves} is not finite"
            ));
        }
        if solves >= max_iterations {
            if max_iterations < settings.max_iterations {
                break Termination::WorkLimit(format!(
                    "Newton had not converged after {solves} iterations (relative residual {relative:.2e}): {solves} iterations of {n} unknowns reach the work limit of {} iteration-dofs (limits.iteration_dofs); raise \"limits\": {{\"iteration_dofs\": N}} if the machine has the time, use a coarser mesh, or apply the load in more load steps (solver.load_steps)",
                    settings.iteration_dofs
                ));
            }
            break Termination::IterationLimit;
        }
        residual.iter_mut().for_each(|v| *v = -*v);
        if let Err(e) = linear.solve(&tangent, &mut residual) {
            let why = match e {
                FactorError::ZeroPivot { equation, .. } => format!(
                    "a zero pivot at {} (the matrix is singular)",
                    system.describe_unknown(equation)
                ),
                FactorError::NotPositiveDefinite { equation } => format!(
                    "a pivot that is not positive at {}",
                    system.describe_unknown(equation)
                ),
                FactorError::TooLarge { work, limit } => format!(
                    "{}; {}",
                    work.refusal(&limit),
                    crate::solver::sparse::TOO_LARGE_HINT
                ),
                FactorError::Other(why) => why,
            };
            break Termination::Singular(format!(
                "the tangent of Newton iteration {} could not be factored: {why}",
                solves + 1
            ));
        }
        step_length = 1.0;
        if let Some(window) = system.line_search() {
            let reference = merits[merits.len().saturating_sub(window.max(1))..]
                .iter()
                .fold(merit, |m, &v| m.max(v));
            trial = Some(TrialStep {
                start: x.clone(),
                direction: residual.clone(),
                merit: reference,
                length: 1.0,
            });
        }
        x.iter_mut().zip(&residual).for_each(|(a, d)| *a += d);
        settled = max_abs(&residual) <= SETTLED_STEP * max_abs(x);
        last_solver = linear.last_solver;
        solves += 1;
    };
    Ok(Outcome {
        termination,
        iterations: solves,
        history,
        factorization_seconds: earlier_seconds + linear.seconds - base_seconds,
        linear_solver: last_solver,
    })
}

pub use crate::contact::state::Stability;

/// The weight `t` of the active rows' `rho B_A^T B_A` added to the displacement block to test
/// it on their kernel ([`LinearSolver::stability_at`]): a direction outside the kernel with a
/// negative stiffness above `t rho |B_A v|^2` would be counted as unstable (the displacement
/// block's negative parts, the geometric terms of stress and contact forces, are small against
/// `rho`, the largest diagonal of the stiffness).
pub const FINSLER_WEIGHT: f64 = 1e4;

enum Factorization {
    Cholesky(Factor),
    Ldlt(LdltFactor),
    Lu(Box<LuFactor>),
}

impl Factorization {
    fn solve_in_place(&self, b: &mut [f64]) {
        match self {
            Factorization::Cholesky(f) => f.solve_in_place(b),
            Factorization::Ldlt(f) => f.solve_in_place(b),
            Factorization::Lu(f) => f.solve_in_place(b),
        }
    }
}

/// Cholesky, `L D L^T` with pivot signs and LU behind one interface, on one pattern analysed
/// once per solver kind; the last factorization is reused while the tangent's values do not
/// change.
pub struct LinearSolver {
    /// The most memory and operations one factorization may take.
    limit: WorkLimit,
    symmetric: SymmetricPattern,
    pub general: GeneralPattern,
    cholesky: Option<Cholesky>,
    /// With the number of leading (displacement) unknowns it was analysed for.
    ldlt: Option<(usize, Ldlt)>,
    lu: Option<Lu>,
    last: Option<(Vec<f64>, Factorization)>,
    /// Numeric factorizations done, and solves that reused the last one.
    pub factorizations: usize,
    pub reused: usize,
    pub seconds: f64,
    pub last_solver: &'static str,
    /// Estimated 1-norm condition number of the last factorization (Cholesky, LDL^T, and LU
    /// with its transpose solves), see [`crate::solver::conditioning`].
    pub last_condition: Option<f64>,
    /// Whether the last factored tangent, symmetric, had the inertia of a stable equilibrium
    /// (Cholesky, or `L D L^T` with one negative pivot per multiplier: `Some(true)`) or not
    /// (`Some(false)`: it went to LU); `None` for an unsymmetric tangent, constraint
    /// elimination, or an LU taken for another reason.
    last_inertia: Option<bool>,
}

impl LinearSolver {
    pub fn new(pattern: &SymmetricPattern, limit: WorkLimit) -> LinearSolver {
        LinearSolver {
            limit,
            symmetric: pattern.clone(),
            general: GeneralPattern::from_symmetric(pattern),
            cholesky: None,
            ldlt: None,
            lu: None,
            last: None,
            factorizations: 0,
            reused: 0,
            seconds: 0.0,
            last_solver: "none",
            last_condition: None,
            last_inertia: None,
        }
    }

    /// Overwrite `b` with `K_T^-1 b`.
    pub fn solve(
        &mut self,
        tangent: &Tangent,
        b: &mut [f64],
    ) -> std::result::Result<(), FactorError> {
        if let Some(rows) = &tangent.elimination {
            let t = Instant::now();
            let solved = self.solve_eliminating(tangent, rows, b);
            self.seconds += t.elapsed().as_secs_f64();
            self.factorizations += 1;
            self.last = None;
            return solved;
        }
        if let Some((values, f)) = &self.last {
            if *values == tangent.values {
                self.reused += 1;
                f.solve_in_place(b);
                return Ok(());
            }
        }
        let t = Instant::now();
        let factor = self.factor(tangent);
        self.seconds += t.elapsed().as_secs_f64();
        let factor = factor?;
        factor.solve_in_place(b);
        self.factorizations += 1;
        self.last = Some((tangent.values.clone(), factor));
        Ok(())
    }

    /// Whether the state whose symmetric `tangent` this is (Newton has converged there) is a
    /// stable equilibrium. A tangent like the last one factored by Cholesky or by `L D L^T`
    /// with the saddle-point inertia is stable (the last factorization is of the previous
    /// iterate, whose tangent differs from this one by the last Newton step). Otherwise this
    /// tangent is tested: without multipliers it is stable when it is positive definite
    /// (Cholesky); with multipliers `[[A, C], [C^T, D]]` (the active rows' columns `C = -rho
    /// B_A^T` with a zero diagonal, the inactive ones `D = -rho`), when `A` is positive
    /// definite on the kernel of the active rows, which by Finsler's lemma is when `A + t rho
    /// B_A^T B_A` is positive definite for some `t`, tried at [`FINSLER_WEIGHT`]: a direction
    /// of non-positive stiffness inside the kernel makes it fail at every `t`, one outside is
    /// lifted by `t`. `None` for an unsymmetric tangent, constraint elimination, or a test that
    /// cannot be made (a tangent too large to factor).
    pub fn stability_at(&mut self, tangent: &Tangent) -> Option<Stability> {
        if !tangent.symmetric || tangent.elimination.is_some() {
            return None;
        }
        if self.last_inertia? {
            return Some(Stability::Stable);
        }
        let p = &self.symmetric;
        let mut upper = self.general.upper_values(&tangent.values, p.nnz());
        let leading = self.general.n - tangent.multipliers;
        let block = if tangent.multipliers == 0 {
            p.clone()
        } else {
            let weight = FINSLER_WEIGHT / tangent.scale;
            for j in leading..self.general.n {
                let column = p.col_ptr[j]..p.col_ptr[j + 1];
                let diagonal = p.position(j, j).map_or(0.0, |k| upper[k]);
                if diagonal != 0.0 {
                    continue;
                }
                let coupling: Vec<(usize, f64)> = column
                    .filter(|&k| p.row_idx[k] < leading && upper[k] != 0.0)
                    .map(|k| (p.row_idx[k], upper[k]))
                    .collect();
                for (a, &(ea, ca)) in coupling.iter().enumerate() {
                    for &(eb, cb) in &coupling[a..] {
                        let k = p.position(ea, eb)?;
                        upper[k] += weight * ca * cb;
                    }
                }
            }
            let end = p.col_ptr[leading];
            upper.truncate(end);
            SymmetricPattern {
                n: leading,
                col_ptr: p.col_ptr[..=leading].to_vec(),
                row_idx: p.row_idx[..end].to_vec(),
            }
        };
        let cholesky = Cholesky::analyse(&block, &self.limit).ok()?;
        match cholesky.factor(&block, &upper) {
            Ok(_) => Some(Stability::Stable),
            Err(FactorError::NotPositiveDefinite { .. } | FactorError::ZeroPivot { .. }) => {
                Some(Stability::Unstable)
            }
            Err(_) => None,
        }
    }

    /// Constraint elimination of the saddle-point system `[[A, C], [C^T, D]] [dx; dmu] = [b_u;
    /// b_mu]` (`C = -rho B^T`, `D` the diagonal `-rho` of the inactive multipliers, zero on
    /// the active ones): each active row `j`, `sum_k C_kj dx_k = b_j`, is solved for its owned
    /// unknown `o` (a free slave dof that no other row touches),
    /// `dx_o = (b_j - sum_{k != o} C_kj dx_k) / C_oj`, which makes `dx = T y + t`; the reduced
    /// `T^T A T y = T^T (b_u - A t)` is factored by Cholesky (the multiplier columns drop out:
    /// `T^T C_A = 0`); the multiplier follows from the owned equation,
    /// `dmu_j = (b_o - (A dx)_o) / C_oj`, and an inactive one from its diagonal. The step is
    /// the one `L D L^T` gives (the same linear system), reached without multipliers in the
    /// factored matrix, as in the active-set scheme's elimination.
    fn solve_eliminating(
        &mut self,
        tangent: &Tangent,
        rows: &[(usize, usize)],
        b: &mut [f64],
    ) -> std::result::Result<(), FactorError> {
        let n = self.general.n;
        let leading = n - tangent.multipliers;
        let p = &self.symmetric;
        let upper = self.general.upper_values(&tangent.values, p.nnz());
        // the displacement block: the first `leading` columns of the upper triangle (the
        // multipliers are numbered last)
        let end = p.col_ptr[leading];
        let block = SymmetricPattern {
            n: leading,
            col_ptr: p.col_ptr[..=leading].to_vec(),
            row_idx: p.row_idx[..end].to_vec(),
        };
        let a = &upper[..end];
        let cannot = |why: String| FactorError::Other(format!("constraint elimination: {why}"));
        let mut builder = ConstraintBuilder::new(leading);
        let mut owner_coefficient = vec![None; n];
        for &(j, o) in rows {
            let column = p.col_ptr[j]..p.col_ptr[j + 1];
            let terms: Vec<(usize, f64)> = column
                .filter(|&k| p.row_idx[k] < leading && upper[k] != 0.0)
                .map(|k| (p.row_idx[k], upper[k]))
                .collect();
            let Some(&(_, c_o)) = terms.iter().find(|t| t.0 == o) else {
                return Err(cannot(format!(
                    "the row of unknown {j} does not touch its owned unknown {o}"
                )));
            };
            let masters: Vec<(usize, f64)> = terms
                .iter()
                .filter(|t| t.0 != o)
                .map(|&(k, c)| (k, -c / c_o))
                .collect();
            builder
                .constrain(o, &masters, b[j] / c_o)
                .map_err(|e| cannot(e.to_string()))?;
            owner_coefficient[j] = Some((o, c_o));
        }
        let constraints = builder.close().map_err(|e| cannot(e.to_string()))?;
        let reduction = constraints.reduction(&block);
        let values = reduction.matrix(a);
        let mut y = reduction.rhs(a, &b[..leading]);
        let free = constraints.free_dofs();
        let f = Cholesky::analyse(&reduction.pattern, &self.limit)?
            .factor(&reduction.pattern, &values)
            .map_err(|e| e.map_equation(|q| free[q]))?;
        self.last_solver = "elimination";
        self.last_condition = Some(condition_estimate_symmetric(
            &reduction.pattern,
            &values,
            |v| f.solve_in_place(v),
        ));
        f.solve_in_place(&mut y);
        let dx = constraints.expand(&y);
        let mut a_dx = vec![0.0; leading];
        block.mul(a, &dx, &mut a_dx);
        for j in leading..n {
            b[j] = match owner_coefficient[j] {
                Some((o, c_o)) => (b[o] - a_dx[o]) / c_o,
                None => {
                    let diagonal = p.position(j, j).map_or(0.0, |k| upper[k]);
                    let coupled = (p.col_ptr[j]..p.col_ptr[j + 1])
                        .any(|k| p.row_idx[k] != j && upper[k] != 0.0);
                    if diagonal == 0.0 || coupled {
                        return Err(cannot(format!(
                            "the multiplier {j} is coupled to other unknowns but has no owned dof to be solved for"
                        )));
                    }
                    b[j] / diagonal
                }
            };
        }
        b[..leading].copy_from_slice(&dx);
        Ok(())
    }

    fn factor(&mut self, tangent: &Tangent) -> std::result::Result<Factorization, FactorError> {
        self.last_inertia = None;
        if tangent.symmetric && tangent.multipliers > 0 {
            let n = self.general.n;
            let leading = n - tangent.multipliers;
            if self.ldlt.as_ref().is_none_or(|(l, _)| *l != leading) {
                self.ldlt = Some((
                    leading,
                    Ldlt::analyse(&self.symmetric, leading, &self.limit)?,
                ));
            }
            let upper = self
                .general
                .upper_values(&tangent.values, self.symmetric.nnz());
            let signs: Vec<i8> = (0..n).map(|i| if i < leading { 1 } else { -1 }).collect();
            let (_, ldlt) = self.ldlt.as_ref().expect("analysed");
            let scale = tangent.scale;
            match ldlt.factor(&self.symmetric, &upper, &signs, 1e-13 * scale, scale) {
                Ok(f) => {
                    self.last_solver = "ldlt";
                    self.last_inertia = Some(true);
                    self.last_condition =
                        Some(condition_estimate_symmetric(&self.symmetric, &upper, |b| {
                            f.solve_in_place(b)
                        }));
                    return Ok(Factorization::Ldlt(f));
                }
                // an indefinite displacement block (finite kinematics: the gap's second
                // derivative times a contact force) gives pivots of the wrong sign, and
                // regularizing them may overflow the factor; LU below, which has no expected
                // inertia
                Err(FactorError::ZeroPivot { .. }) if tangent.indefinite_block => {
                    self.last_inertia = Some(false);
                }
                // singular: dependent rows (two passes), a body the active rows leave free
                Err(e @ FactorError::ZeroPivot { .. }) => return Err(e),
                // LU below
                Err(_) => {}
            }
        } else if tangent.symmetric {
            if self.cholesky.is_none() {
                self.cholesky = Some(Cholesky::analyse(&self.symmetric, &self.limit)?);
            }
            let upper = self
                .general
                .upper_values(&tangent.values, self.symmetric.nnz());
            let chol = self.cholesky.as_ref().expect("analysed");
            match chol.factor(&self.symmetric, &upper) {
                Ok(f) => {
                    self.last_solver = "cholesky";
                    self.last_inertia = Some(true);
                    self.last_condition =
                        Some(condition_estimate_symmetric(&self.symmetric, &upper, |b| {
                            f.solve_in_place(b)
                        }));
                    return Ok(Factorization::Cholesky(f));
                }
                // indefinite (a geometric term): LU below; a zero pivot is singular either way
                Err(FactorError::NotPositiveDefinite { .. }) => {
                    self.last_inertia = Some(false);
                }
                Err(e) => return Err(e),
            }
        }
        if self.lu.is_none() {
            self.lu = Some(Lu::analyse(&self.general, &self.limit)?);
        }
        let f = self
            .lu
            .as_ref()
            .expect("analysed")
            .factor(&self.general, &tangent.values)?;
        self.last_solver = "lu";
        self.last_condition = Some(condition_estimate_general(
            &self.general.col_ptr,
            &tangent.values,
            |b, transpose| {
                if transpose {
                    f.solve_transpose_in_place(b)
                } else {
                    f.solve_in_place(b)
                }
            },
        ));
        Ok(Factorization::Lu(Box::new(f)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::sparse::PatternBuilder;
    use crate::solver::sparse::UNLIMITED;

    /// `R(x) = A x + c x^3 - f` on a tridiagonal `A`: Newton converges quadratically from zero.
    struct Cubic {
        pattern: SymmetricPattern,
        c: f64,
        f: Vec<f64>,
        unsymmetric: f64,
    }

    impl System for Cubic {
        fn pattern(&self) -> &SymmetricPattern {
            &self.pattern
        }
        fn evaluate(
            &mut self,
            x: &[f64],
            general: &GeneralPattern,
            residual: &mut [f64],
            tangent: &mut Tangent,
        ) -> Result<Evaluation> {
            let n = x.len();
            tangent.symmetric = self.unsymmetric == 0.0;
            for i in 0..n {
                let mut r = 4.0 * x[i] + self.c * x[i].powi(3) - self.f[i];
                let d = general.position(i, i).unwrap();
                tangent.values[d] = 4.0 + 3.0 * self.c * x[i] * x[i];
                if i > 0 {
                    r -= x[i - 1];
                    tangent.values[general.position(i, i - 1).unwrap()] = -1.0;
                }
                if i + 1 < n {
                    r -= (1.0 + self.unsymmetric) * x[i + 1];
                    tangent.values[general.position(i, i + 1).unwrap()] = -1.0 - self.unsymmetric;
                }
                residual[i] = r;
            }
            Ok(Evaluation {
                force_scale: self.f.iter().fold(0.0, |m: f64, v| m.max(v.abs())),
                ..Evaluation::default()
            })
        }
    }

    /// [`Cubic`] with the round-off floor of its residual: `ROUNDOFF_TERMS eps` times the
    /// largest row sum of `|4 x_i| + |c x_i^3| + |f_i| + |x_(i-1)| + |x_(i+1)|`.
    struct FlooredCubic(Cubic);

    impl System for FlooredCubic {
        fn pattern(&self) -> &SymmetricPattern {
            &self.0.pattern
        }
        fn evaluate(
            &mut self,
            x: &[f64],
            general: &GeneralPattern,
            residual: &mut [f64],
            tangent: &mut Tangent,
        ) -> Result<Evaluation> {
            let mut eval = self.0.evaluate(x, general, residual, tangent)?;
            let n = x.len();
            let magnitude = (0..n)
                .map(|i| {
                    4.0 * x[i].abs()
                        + (self.0.c * x[i].powi(3)).abs()
                        + self.0.f[i].abs()
                        + if i > 0 { x[i - 1].abs() } else { 0.0 }
                        + if i + 1 < n { x[i + 1].abs() } else { 0.0 }
                })
                .fold(0.0f64, f64::max);
            eval.residual_floor = ROUNDOFF_TERMS * f64::EPSILON * magnitude;
            Ok(eval)
        }
    }

    #[test]
    fn a_tolerance_below_round_off_ends_at_the_residual_floor_not_at_the_limit() {
        let settings = Settings {
            max_iterations: 50,
            // below what f64 can give: only the floor can end the iteration
            tolerance: 1e-30,
            factor_limit: UNLIMITED,
            iteration_dofs: u64::MAX,
        };
        let mut x = vec![0.0; 20];
        let plain = solve(&mut cubic(20, 0.5, 0.0), &mut x, settings).unwrap();
        assert_eq!(plain.termination, Termination::IterationLimit);
        let mut s = FlooredCubic(cubic(20, 0.5, 0.0));
        let mut x = vec![0.0; 20];
        let out = solve(&mut s, &mut x, settings).unwrap();
        assert_eq!(out.termination, Termination::Converged);
        assert!(out.iterations < 10, "{} iterations", out.iterations);
        // the answer solves the system to round-off: recompute its residual independently
        let n = x.len();
        for i in 0..n {
            let mut r = 4.0 * x[i] + 0.5 * x[i].powi(3) - (1.0 + i as f64);
            if i > 0 {
                r -= x[i - 1];
            }
            if i + 1 < n {
                r -= x[i + 1];
            }
            assert!(
                r.abs() <= 1e-12 * (1.0 + i as f64),
                "row {i}: residual {r:e}"
            );
        }
    }

    /// `R(x) = atan(x)` in one unknown, the classic cycle of Newton's method: from the root
    /// `x_c` of `2 x = (1 + x^2) atan(x)` (1.3917...) the full step goes to `-x_c` and back.
    /// The sign of `x` stands for a point's status (a flip is a status change), so the cycle
    /// detector sees it; `search` is what [`System::line_search`] answers.
    struct Arctan {
        pattern: SymmetricPattern,
        search: bool,
        last_sign: Option<bool>,
    }

    impl System for Arctan {
        fn pattern(&self) -> &SymmetricPattern {
            &self.pattern
        }
        fn evaluate(
            &mut self,
            x: &[f64],
            general: &GeneralPattern,
            residual: &mut [f64],
            tangent: &mut Tangent,
        ) -> Result<Evaluation> {
            residual[0] = x[0].atan();
            tangent.values[general.position(0, 0).unwrap()] = 1.0 / (1.0 + x[0] * x[0]);
            let sign = x[0] > 0.0;
            let changed = self.last_sign.is_some_and(|s| s != sign);
            self.last_sign = Some(sign);
            Ok(Evaluation {
                force_scale: 1.0,
                status_changes: usize::from(changed),
                ..Evaluation::default()
            })
        }
        fn line_search(&self) -> Option<usize> {
            self.search.then_some(NONMONOTONE_WINDOW)
        }
    }

    #[test]
    fn the_line_search_leaves_the_newton_cycle_of_the_arctangent_and_converges() {
        // x_c by Newton on h(x) = (1 + x^2) atan(x) - 2 x, h' = 2 x atan(x) - 1: full steps
        // from x_c go to -x_c and back
        let mut x_c = 1.4f64;
        for _ in 0..50 {
            x_c -= ((1.0 + x_c * x_c) * x_c.atan() - 2.0 * x_c) / (2.0 * x_c * x_c.atan() - 1.0);
        }
        let settings = Settings {
            max_iterations: 50,
            tolerance: 1e-12,
            factor_limit: UNLIMITED,
            iteration_dofs: u64::MAX,
        };
        let arctan = |search| Arctan {
            pattern: PatternBuilder::new(1).build(),
            search,
            last_sign: None,
        };
        let mut x = vec![x_c];
        let plain = solve(&mut arctan(false), &mut x, settings).unwrap();
        let Termination::ActiveSetCycling(why) = &plain.termination else {
            panic!("{:?}", plain.termination)
        };
        // the advice of a system without friction rows: no remedy for other kinds of rows
        // and of a static solve: load steps, not a time step it does not have
        assert!(why.contains("more load steps"), "{why}");
        assert!(!why.contains("time step"), "{why}");
        assert!(!why.contains("friction"), "{why}");
        let mut x = vec![x_c];
        let searched = solve(&mut arctan(true), &mut x, settings).unwrap();
        assert_eq!(searched.termination, Termination::Converged);
        assert!(x[0].abs() <= 1e-12, "{}", x[0]);
        // the full step does not decrease |atan x| (it lands on -x_c): it is shortened
        let lengths: Vec<f64> = searched.history.iter().map(|r| r.step_length).collect();
        // (half of it lands on the root)
        assert!(lengths[0] < 1.0, "{lengths:?}");
        assert!(searched.iterations <= 8, "{}", searched.iterations);
    }

    fn cubic(n: usize, c: f64, unsymmetric: f64) -> Cubic {
        let mut b = PatternBuilder::new(n);
        for i in 0..n - 1 {
            b.add_block(&[i, i + 1]);
        }
        Cubic {
            pattern: b.build(),
            c,
            f: (0..n).map(|i| 1.0 + i as f64).collect(),
            unsymmetric,
        }
    }

    #[test]
    fn newton_converges_quadratically_on_a_cubic_system() {
        for (unsymmetric, solver) in [(0.0, "cholesky"), (0.5, "lu")] {
            let mut s = cubic(20, 0.5, unsymmetric);
            let mut x = vec![0.0; 20];
            let out = solve(
                &mut s,
                &mut x,
                Settings {
                    max_iterations: 30,
                    tolerance: 1e-14,
                    factor_limit: UNLIMITED,
                    iteration_dofs: u64::MAX,
                },
            )
            .unwrap();
            assert_eq!(out.termination, Termination::Converged);
            assert_eq!(out.linear_solver, solver);
            let r: Vec<f64> = out.history.iter().map(|h| h.residual).collect();
            // quadratic: once below 1e-2, each residual is below a constant times the square
            // of the last
            let asymptotic: Vec<&[f64]> = r.windows(2).filter(|w| w[0] < 1e-2).collect();
            assert!(!asymptotic.is_empty(), "{r:?}");
            for w in asymptotic {
                assert!(w[1] <= 10.0 * w[0] * w[0] + 1e-15, "{r:?}");
            }
            // the answer satisfies the equations
            let mut res = vec![0.0; 20];
            let general = GeneralPattern::from_symmetric(&s.pattern);
            let mut t = Tangent {
                values: vec![0.0; general.nnz()],
                symmetric: true,
                multipliers: 0,
                scale: 1.0,
                elimination: None,
                indefinite_block: false,
            };
            s.evaluate(&x, &general, &mut res, &mut t).unwrap();
            assert!(res.iter().all(|v| v.abs() < 1e-12), "{res:?}");
        }
    }

    #[test]
    fn a_linear_system_takes_one_solve_and_an_unchanged_tangent_is_not_refactored() {
        let mut s = cubic(10, 0.0, 0.0);
        let mut x = vec![0.0; 10];
        let settings = Settings {
            max_iterations: 10,
            tolerance: 1e-13,
            factor_limit: UNLIMITED,
            iteration_dofs: u64::MAX,
        };
        let out = solve(&mut s, &mut x, settings).unwrap();
        assert_eq!(out.termination, Termination::Converged);
        assert_eq!(out.iterations, 1);
        let mut linear = LinearSolver::new(&s.pattern, UNLIMITED);
        let general = linear.general.clone();
        let mut t = Tangent {
            values: vec![0.0; general.nnz()],
            symmetric: true,
            multipliers: 0,
            scale: 1.0,
            elimination: None,
            indefinite_block: false,
        };
        let mut r = vec![0.0; 10];
        s.evaluate(&x, &general, &mut r, &mut t).unwrap();
        let mut b = vec![1.0; 10];
        linear.solve(&t, &mut b).unwrap();
        linear.solve(&t, &mut b).unwrap();
        assert_eq!((linear.factorizations, linear.reused), (1, 1));
    }

    /// The dense symmetric `values` (row-major, `n x n`) as a tangent on a full pattern, solved
    /// once (which records the factorization's inertia), and the stability verdict on it.
    fn verdict(n: usize, values: &[f64], multipliers: usize) -> (Option<Stability>, &'static str) {
        let pattern = SymmetricPattern {
            n,
            col_ptr: (0..=n).map(|j| j * (j + 1) / 2).collect(),
            row_idx: (0..n).flat_map(|j| 0..=j).collect(),
        };
        let mut linear = LinearSolver::new(&pattern, UNLIMITED);
        let general = linear.general.clone();
        let mut upper = vec![0.0; pattern.nnz()];
        for j in 0..n {
            for i in 0..=j {
                upper[pattern.position(i, j).unwrap()] = values[i * n + j];
            }
        }
        let tangent = Tangent {
            values: general.symmetric_values(&upper),
            symmetric: true,
            multipliers,
            scale: 1.0,
            elimination: None,
            indefinite_block: true,
        };
        let mut b = vec![1.0; n];
        linear.solve(&tangent, &mut b).unwrap();
        (linear.stability_at(&tangent), linear.last_solver)
    }

    /// The stability verdict on small tangents whose answer is known: without multipliers,
    /// stable exactly when positive definite; with a Lagrange multiplier row `b` (the saddle
    /// point `[[A + rho b b^T, -rho b], [-rho b^T, 0]]`, `rho = 1`), when `A` is positive on
    /// the kernel of `b`. `A = diag(1, -1)` is stable when the row holds the second unknown
    /// (its negative direction is not in the kernel; the augmented block `diag(1, 0)` fails
    /// the `L D L^T` inertia, so the verdict comes from the test at the Finsler weight) and
    /// unstable when the row holds the first.
    #[test]
    fn the_stability_verdict_is_the_sign_of_the_stiffness_on_the_rows_kernel() {
        // no multipliers
        assert_eq!(
            verdict(2, &[2.0, 1.0, 1.0, 2.0], 0),
            (Some(Stability::Stable), "cholesky")
        );
        assert_eq!(
            verdict(2, &[1.0, 0.0, 0.0, -1.0], 0),
            (Some(Stability::Unstable), "lu")
        );
        // a row on the second unknown: A + b b^T = diag(1, 0)
        #[rustfmt::skip]
        let held_second = [
            1.0, 0.0, 0.0,
            0.0, 0.0, -1.0,
            0.0, -1.0, 0.0,
        ];
        assert_eq!(verdict(3, &held_second, 1), (Some(Stability::Stable), "lu"));
        // a row on the first unknown: A + b b^T = diag(2, -1)
        #[rustfmt::skip]
        let held_first = [
            2.0, 0.0, -1.0,
            0.0, -1.0, 0.0,
            -1.0, 0.0, 0.0,
        ];
        assert_eq!(
            verdict(3, &held_first, 1),
            (Some(Stability::Unstable), "lu")
        );
        // positive definite with its row: L D L^T with the saddle-point inertia
        #[rustfmt::skip]
        let stable = [
            2.0, 0.0, -1.0,
            0.0, 1.0, 0.0,
            -1.0, 0.0, 0.0,
        ];
        assert_eq!(verdict(3, &stable, 1), (Some(Stability::Stable), "ldlt"));
    }

    #[test]
    fn the_iteration_limit_is_a_termination_not_an_error() {
        let mut s = cubic(10, 50.0, 0.0);
        let mut x = vec![0.0; 10];
        let out = solve(
            &mut s,
            &mut x,
            Settings {
                max_iterations: 2,
                tolerance: 1e-14,
                factor_limit: UNLIMITED,
                iteration_dofs: u64::MAX,
            },
        )
        .unwrap();
        assert_eq!(out.termination, Termination::IterationLimit);
        assert_eq!(out.iterations, 2);
    }

    #[test]
    fn a_cycle_is_a_residual_that_repeats_while_statuses_change() {
        // period 2: the residual alternates, points flip at every iteration
        let two: Vec<(f64, usize)> = (0..8)
            .map(|k| (if k % 2 == 0 { 1.3e-2 } else { 2.7e-3 }, 12))
            .collect();
        assert_eq!(cycle_period(&two), Some(2));
        // period 1: the same residual each time
        assert_eq!(cycle_period(&[(5e-3, 3); 6]), Some(1));
        // one iteration too few, or an iteration that changed no status: no verdict
        assert_eq!(cycle_period(&two[..5]), None);
        let mut calm = two.clone();
        calm[5].1 = 0;
        assert_eq!(cycle_period(&calm), None);
        // a converging iteration changes its residual
        let converging: Vec<(f64, usize)> = (0..8).map(|k| (0.5f64.powi(k), 2)).collect();
        assert_eq!(cycle_period(&converging), None);
        // a residual that differs by more than 1e-9 of itself is not a repeat
        let drifting: Vec<(f64, usize)> = (0..8).map(|k| (1.0 + 1e-8 * k as f64, 4)).collect();
        assert_eq!(cycle_period(&drifting), None);
    }

    #[test]
    fn the_work_limit_stops_before_the_iteration_limit_and_names_itself() {
        // 10 unknowns and 35 iteration-dofs: 3 iterations, below the iteration limit of 20
        let mut s = cubic(10, 50.0, 0.0);
        let mut x = vec![0.0; 10];
        let settings = Settings {
            max_iterations: 20,
            tolerance: 1e-14,
            factor_limit: UNLIMITED,
            iteration_dofs: 35,
        };
        let out = solve(&mut s, &mut x, settings).unwrap();
        assert_eq!(out.iterations, 3);
        let Termination::WorkLimit(msg) = &out.termination else {
            panic!("{:?}", out.termination);
        };
        assert!(msg.contains("after 3 iterations"), "{msg}");
        assert!(msg.contains("limits.iteration_dofs"), "{msg}");
        // with room for the iterations it needs, the same solve converges
        let mut x = vec![0.0; 10];
        let roomy = Settings {
            iteration_dofs: 10 * 20,
            ..settings
        };
        let out = solve(&mut s, &mut x, roomy).unwrap();
        assert_eq!(out.termination, Termination::Converged);
    }
}
