//! Numerical stability of a solved case: how well conditioned its systems were, whether its
//! equilibrium is at round-off, how much its active set chattered, and why an iterative method
//! stalled.
//!
//! * Conditioning: the estimated 1-norm condition number `kappa` of the last factored system
//!   (Hager-Higham, [`crate::solver::conditioning`]) and the digits it can cost,
//!   `log10(kappa)`.
//! * Equilibrium: the relative residual `max |K u - f - B^T lambda| / F` of the answer is at
//!   round-off when it is at most [`EQUILIBRIUM_ROUND_OFF`]. A penalty row's force
//!   `lambda = kappa A g` is computed from a gap `g = g0 + b . u` that is only known to about
//!   `eps |b| |u|` (the displacement is stored to `eps` relative), so the force cannot be
//!   better than `kappa A eps |b| |u|`: the penalty floor
//!   `max_i kappa_i A_i |b_i| eps max|u| / F` (`F` the largest applied or contact force), which names the penalty as the cause when it
//!   is above round-off and says how far to lower it.
//! * Chattering: the number of contact points that change status after an iteration, per
//!   iteration and summed over a load step (the history's `status_changes`), and the
//!   iterations whose active set repeated an earlier one (cycling, see
//!   [`crate::solver::active_set`]) or ran under the cycling remedy.
//! * Energy of a time integration: a warning when the total energy grew (the trapezoidal rule
//!   conserves it without contact; Hughes 1987, 9.1; contact only removes energy).
//! * A stalled Uzawa iteration (augmented Lagrangian) or perturbed-tangent iteration: each
//!   iteration reduces the penetration by about `1 / (1 + kappa A c)` with `c` the
//!   compliance of the bodies at the point (Bertsekas, *Constrained Optimization and Lagrange
//!   Multiplier Methods*, 1982, ch. 2; Laursen, *Computational Contact and Impact Mechanics*,
//!   2002, sec. 5.3), so a penalty far below the stiffness of the bodies, `E / h`, needs
//!   thousands of iterations; the diagnosis gives the measured rate and a penalty that works.
//! * A load step that has no equilibrium: a body without supports, pressed by its load onto
//!   flat rigid masters of one normal `n` with Coulomb friction, is in equilibrium only if the
//!   contact forces carry its load `F`; their tangential sum is at most `mu` times their
//!   normal sum (Coulomb at every point, `|sum lambda_t| <= sum |lambda_t| <= mu sum
//!   lambda_n`), so a load with `|F_t| > mu F_n` (`F_n = -F . n`, the part pressing the body
//!   on) or one that pulls the body off (`F_n <= 0`, `F != 0`) has none: the body slides (or
//!   flies) away and the slip grows without bound. A failed step is then named for that
//!   cause, not for Newton's iteration limit (a block on an incline pushed past
//!   `F / G = (tan a + mu) / (1 - mu tan a)`).

use crate::contact::enforcement::{method, Method};
use crate::contact::state::{ContactState, Termination};
use crate::model::space::SolidCell;
use crate::model::Model;
use crate::solver::conditioning::{lost_digits, EQUILIBRIUM_ROUND_OFF};
use crate::solver::linear::Solution;
use crate::solver::newton::Stability;
use serde::Serialize;

/// What `summary.json` says of the conditioning and the equilibrium of an answer.
#[derive(Clone, Debug, Serialize)]
pub struct Conditioning {
    /// Estimated 1-norm condition number of the last factored system (`None` without an
    /// estimate: no contact, or the active-set scheme's LU fallback).
    pub condition_estimate: Option<f64>,
    /// `log10` of the estimate.
    pub lost_digits: Option<f64>,
    /// The relative equilibrium residual of the answer.
    pub equilibrium_residual: f64,
    /// Whether it is at most [`EQUILIBRIUM_ROUND_OFF`].
    pub equilibrium_at_round_off: bool,
    /// The penalty floor of the equilibrium residual (penalty-type rows only, see the module).
    pub penalty_floor: Option<f64>,
    /// The most status changes after one iteration and in one load step (chattering).
    pub status_changes_per_iteration: usize,
    pub status_changes_per_step: usize,
    /// Iterations whose active set repeated an earlier one of their loop (cycling, active-set
    /// scheme), and iterations under the cycling remedy (`solver.cycling_remedy`); absent when
    /// zero.
    #[serde(skip_serializing_if = "is_zero")]
    pub repeated_active_sets: usize,
    #[serde(skip_serializing_if = "is_zero")]
    pub cycling_remedy_iterations: usize,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// The most status changes after one iteration, and summed over one load step.
pub fn status_changes<const D: usize>(state: &ContactState<D>) -> (usize, usize) {
    let per_iteration = state
        .history
        .iter()
        .map(|r| r.status_changes)
        .max()
        .unwrap_or(0);
    let mut per_step = std::collections::BTreeMap::new();
    for r in &state.history {
        *per_step.entry(r.step).or_insert(0) += r.status_changes;
    }
    (per_iteration, per_step.into_values().max().unwrap_or(0))
}

/// The penalty weight `kappa A` of a row of a penalty-type method (`None` for methods whose
/// force is a multiplier).
fn penalty_weight<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    row: &crate::contact::Constraint<D>,
) -> Option<f64> {
    match method(&model.contact[row.pair].enforcement).kernel() {
        Method::Regularized { .. } | Method::PerturbedLagrange { .. } => {
            method(&model.contact[row.pair].enforcement)
                .kappa()
                .map(|k| k * row.area)
        }
        _ => None,
    }
}

/// The penalty floor of the relative equilibrium residual (see the module), `None` without
/// penalty rows.
pub fn penalty_floor<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
) -> Option<f64> {
    let state = solution.contact.as_ref()?;
    let u = crate::solver::linear::max_abs(&solution.u);
    // the force scale of the relative residual: the largest applied or contact force
    let force = crate::solver::linear::max_abs(model.external_force.iter().chain(&state.forces))
        .max(f64::MIN_POSITIVE);
    state
        .rows
        .iter()
        .zip(&state.active)
        .filter(|(_, &a)| a)
        .filter_map(|(r, _)| {
            let w = penalty_weight(model, r)?;
            let b = r
                .coeffs
                .iter()
                .map(|c| c.abs())
                .sum::<f64>()
                .max(f64::MIN_POSITIVE);
            Some(w * b * f64::EPSILON * u / force)
        })
        .reduce(f64::max)
}

/// The conditioning and equilibrium of `solution`.
pub fn conditioning<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
) -> Conditioning {
    let condition_estimate = solution
        .contact
        .as_ref()
        .and_then(|c| c.history.last().and_then(|r| r.condition_estimate));
    let (per_iteration, per_step) = solution
        .contact
        .as_ref()
        .map(status_changes)
        .unwrap_or((0, 0));
    let residual = solution.relative_residual;
    let count = |f: fn(&crate::contact::state::IterationRecord) -> bool| {
        solution
            .contact
            .as_ref()
            .map(|c| c.history.iter().filter(|r| f(r)).count())
            .unwrap_or(0)
    };
    Conditioning {
        condition_estimate,
        lost_digits: condition_estimate.map(lost_digits),
        equilibrium_residual: residual,
        equilibrium_at_round_off: residual <= EQUILIBRIUM_ROUND_OFF,
        penalty_floor: penalty_floor(model, solution),
        status_changes_per_iteration: per_iteration,
        status_changes_per_step: per_step,
        repeated_active_sets: count(|r| r.repeated_set),
        cycling_remedy_iterations: count(|r| r.cycling_remedy),
    }
}

/// The largest penalty of a pair that keeps its floor at round-off: `kappa` scaled by
/// `EQUILIBRIUM_ROUND_OFF / floor`.
fn largest_sound_penalty<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    floor: f64,
) -> Option<(String, f64)> {
    model.contact.iter().find_map(|p| {
        let m = method(&p.enforcement);
        match m.kernel() {
            Method::Regularized { .. } | Method::PerturbedLagrange { .. } => m
                .kappa()
                .map(|k| (p.name.clone(), k * EQUILIBRIUM_ROUND_OFF / floor)),
            _ => None,
        }
    })
}

/// The warning for a converged answer whose equilibrium is not at round-off, with the
/// condition estimate and, when a penalty explains it, how far to lower the penalty.
pub fn equilibrium_warning<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
) -> Option<String> {
    let state = solution.contact.as_ref()?;
    if state.termination != Termination::Converged {
        return None;
    }
    let c = conditioning(model, solution);
    if c.equilibrium_at_round_off || !c.equilibrium_residual.is_finite() {
        return None;
    }
    let kappa = c
        .condition_estimate
        .map(|k| {
            format!(
                "; the last factored system has condition estimate {k:.2e} ({:.1} of 16 digits lost)",
                lost_digits(k)
            )
        })
        .unwrap_or_default();
    let cause = match c.penalty_floor {
        Some(floor) if floor > 0.1 * c.equilibrium_residual => {
            let lower = largest_sound_penalty(model, floor)
                .map(|(pair, k)| format!("lower kappa of '{pair}' to about {k:.1e} or below, "))
                .unwrap_or_default();
            format!(
                "the penalty forces kappa A g come from gaps known only to round-off of the displacement, which limits equilibrium to about {floor:.1e}: {lower}or use Lagrange multipliers or the augmented Lagrangian"
            )
        }
        _ => "the answer has lost digits to the conditioning of the system (a body held only by a very soft penalty, a nearly incompressible material, or moduli far apart make it ill conditioned): hold such a body with a support or a stiffer penalty, or judge equilibrium relative to the condition estimate (the `equilibrium` check with `per_condition`)".to_string(),
    };
    Some(format!(
        "equilibrium is not at round-off: relative residual {:.2e} (round-off is {EQUILIBRIUM_ROUND_OFF:.0e}){kappa}; {cause}",
        c.equilibrium_residual
    ))
}

/// Why a solve hit its iteration limit, and what would work: an augmented Lagrangian or
/// perturbed-tangent iteration with too small a penalty, or a Newton
/// residual that stagnates at the floor of too stiff a penalty; `None` for other stops.
pub fn stall_diagnosis<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
) -> Option<String> {
    let state = solution.contact.as_ref()?;
    if state.termination != Termination::IterationLimit {
        return None;
    }
    iterative_stall(model, state).or_else(|| {
        let floor = penalty_floor(model, solution)?;
        let last = state.history.last()?.residual;
        // the residual stays within a factor 100 of the floor: the penalty, not the iteration,
        // limits it
        (floor.is_finite() && last <= 100.0 * floor && last > EQUILIBRIUM_ROUND_OFF).then(|| {
            let lower = largest_sound_penalty(model, floor)
                .map(|(pair, k)| format!("lower kappa of '{pair}' to about {k:.1e} or below"))
                .unwrap_or_else(|| "lower the penalty".into());
            format!(
                "the residual stagnated at {last:.2e} after {} iterations: the penalty forces kappa A g come from gaps known only to round-off of the displacement, which limits the residual to about {floor:.1e}, above the solver's tolerance; {lower}, or use Lagrange multipliers",
                state.iterations
            )
        })
    })
}

/// The diagnosis of an augmented Lagrangian or perturbed-tangent iteration that reached its
/// limit: the measured contraction of the penetration and a penalty that works.
fn iterative_stall<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    state: &ContactState<D>,
) -> Option<String> {
    let (pair, kappa) = model.contact.iter().find_map(|p| {
        let m = method(&p.enforcement);
        match m.kernel() {
            Method::AugmentedLagrange { .. } | Method::PerturbedTangent { .. } => {
                m.kappa().map(|k| (p, k))
            }
            _ => None,
        }
    })?;
    // the stiffness of the bodies at the interface: the largest E over the smallest
    // tributary length of a row of the pair
    let youngs = model
        .bodies
        .iter()
        .map(|b| K::youngs_modulus(&b.material))
        .fold(0.0f64, f64::max);
    let h = state
        .rows
        .iter()
        .filter(|r| std::ptr::eq(&model.contact[r.pair], pair) && r.area > 0.0)
        .map(|r| r.area)
        .fold(f64::INFINITY, f64::min);
    let stiffness = if h.is_finite() { youngs / h } else { youngs };
    // the measured contraction of the penetration over the last iterations
    let gaps: Vec<f64> = state
        .history
        .iter()
        .map(|r| r.max_gap_violation)
        .filter(|g| *g > 0.0)
        .collect();
    let rate = if gaps.len() >= 11 {
        let (a, b) = (gaps[gaps.len() - 11], gaps[gaps.len() - 1]);
        Some((b / a).powf(0.1))
    } else {
        None
    };
    let measured = match rate {
        Some(r) if r.is_finite() && r > 0.0 && r < 1.0 => {
            let last = *gaps.last().expect("eleven gaps");
            let more = ((1e-15 * model.size() / last).ln() / r.ln()).ceil();
            format!(
                "the penetration fell by a factor {r:.4} per iteration over the last ten (about {more:.0} more iterations to reach round-off)"
            )
        }
        Some(r) if r.is_finite() => format!(
            "the penetration did not fall over the last ten iterations (factor {r:.4} per iteration)"
        ),
        _ => "the penetration did not settle".to_string(),
    };
    Some(format!(
        "contact '{}': the iteration stalled after {} iterations: {measured}; the penalty kappa = {kappa:.3e} is too small against the bodies' stiffness E / h = {stiffness:.3e}: try kappa >= {:.1e} (10 E / h), or raise solver.max_iterations",
        pair.name,
        state.iterations,
        10.0 * stiffness
    ))
}

/// The stability warnings of a run: equilibrium not at round-off, a stalled iteration, an
/// unstable equilibrium.
pub fn warnings<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
) -> Vec<String> {
    // a step without equilibrium explains any stall: no penalty or iteration count helps
    let no_equilibrium = friction_cannot_hold(model, solution);
    let stall = if no_equilibrium.is_some() {
        None
    } else {
        stall_diagnosis(model, solution)
    };
    equilibrium_warning(model, solution)
        .into_iter()
        .chain(no_equilibrium)
        .chain(stall)
        .chain(energy_growth(model, solution))
        .chain(unstable_equilibrium(solution))
        .collect()
}

/// Why a static load step that did not converge has no equilibrium at all (see the module
/// notes): a body without supports whose contact pairs are all slave sides on flat rigid
/// masters of one normal, with Coulomb friction, loaded in that step beyond what the friction
/// can hold (`|F_t| > mu F_n`, [`NO_HOLD_MARGIN`]) or pulled off the masters. `None` for a
/// converged solve or any other cause.
pub fn friction_cannot_hold<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
) -> Option<String> {
    use crate::io::scene::{Interaction, RigidSurface};
    use crate::model::MasterSide;
    let state = solution.contact.as_ref()?;
    if state.termination == Termination::Converged || solution.dynamics.is_some() {
        return None;
    }
    let step = state.steps.last()?.step;
    let n = model.solver.load_steps.max(step);
    let at = model.at_step(step, n);
    model.bodies.iter().enumerate().find_map(|(b, body)| {
        let dofs = body.dof_offset..body.dof_offset + D * body.mesh.nodes.len();
        if dofs.clone().any(|d| model.prescribed.get(d).is_some_and(Option::is_some)) {
            return None;
        }
        // the pairs that hold the body: each a slave side on a flat rigid master with friction
        let mut holding = model.contact.iter().filter(|p| {
            p.slave.0 == b || matches!(&p.master, MasterSide::Body { body: m, .. } if *m == b)
        });
        let mut normal: Option<[f64; D]> = None;
        let mut mu = 0.0f64;
        let mut names = Vec::new();
        let all_held = holding.all(|p| {
            let (MasterSide::Rigid(surface), Interaction::Coulomb { mu: m, .. }) =
                (&p.master, &p.interaction)
            else {
                return false;
            };
            let direction: Vec<f64> = match surface {
                RigidSurface::Line { normal, .. } => normal.to_vec(),
                RigidSurface::Plane { normal, .. } => normal.to_vec(),
                _ => return false,
            };
            if direction.len() != D || p.slave.0 != b {
                return false;
            }
            let length = direction.iter().map(|v| v * v).sum::<f64>().sqrt();
            let unit: [f64; D] = std::array::from_fn(|i| direction[i] / length);
            let same = normal.is_none_or(|n0| {
                n0.iter().zip(&unit).map(|(a, c)| a * c).sum::<f64>() >= 1.0 - 1e-12
            });
            normal.get_or_insert(unit);
            mu = mu.max(*m);
            names.push(format!("'{}'", p.name));
            same
        });
        let normal = normal?;
        if !all_held {
            return None;
        }
        let mut load = [0.0; D];
        for d in dofs {
            load[(d - body.dof_offset) % D] += at.external_force.get(d).copied().unwrap_or(0.0);
        }
        let size = load.iter().map(|v| v * v).sum::<f64>().sqrt();
        let along: f64 = load.iter().zip(&normal).map(|(a, c)| a * c).sum();
        let pressing = -along;
        let tangential = load
            .iter()
            .zip(&normal)
            .map(|(a, c)| (a - along * c).powi(2))
            .sum::<f64>()
            .sqrt();
        let body_name = &body.name;
        let pairs = names.join(", ");
        if size > 0.0 && pressing <= NO_HOLD_MARGIN * size {
            return Some(format!(
                "load step {step} has no equilibrium: its load on body '{body_name}' (resultant {size:.4e}) does not press the body onto its masters {pairs} (normal part {pressing:.4e}) and nothing else holds it, so it moves away without bound; support the body or load it towards the masters"
            ));
        }
        (tangential > mu * pressing * (1.0 + NO_HOLD_MARGIN)).then(|| {
            format!(
                "load step {step} has no equilibrium: the frictional forces cannot hold the load, and the slip grows without bound: the load on body '{body_name}' pushes it along its masters {pairs} with {tangential:.6e}, more than mu = {mu} times the {pressing:.6e} that presses it on (mu F_n = {:.6e}, ratio {:.6}); keep the tangential load at or below mu times the normal load, raise mu, or support the body",
                mu * pressing,
                tangential / (mu * pressing).max(f64::MIN_POSITIVE)
            )
        })
    })
}

/// The relative margin by which a load must exceed the friction's hold (`|F_t| > mu F_n (1 +
/// margin)`) before a failed step is said to have no equilibrium: the round-off of the load's
/// resultant, summed from the nodal forces.
pub const NO_HOLD_MARGIN: f64 = 1e-9;

/// A warning when a finite-kinematics solve converged to a state that is not a stable
/// equilibrium: the last Newton iteration of the last load step records
/// [`Stability::Unstable`] (the tangent is not positive definite on the kernel of the active
/// contact rows, [`crate::solver::newton::LinearSolver::stability_at`]). Such a state balances
/// the loads but the slightest disturbance leaves it (a structure that buckles, a contact that
/// slides away): a real body would not stay there, and Newton reaches it only when nothing
/// disturbs the iterates (a symmetric mesh and load). The earlier load steps whose state was
/// already unstable are named with the load factor where it was first seen.
pub fn unstable_equilibrium<const D: usize>(solution: &Solution<D>) -> Option<String> {
    let finite = solution.finite.as_deref()?;
    let last = finite.history.last()?;
    if last.stability != Some(Stability::Unstable) {
        return None;
    }
    let load_factor = |attempt: usize| {
        finite
            .steps
            .iter()
            .find(|s| s.attempt == attempt)
            .map_or(f64::NAN, |s| s.to)
    };
    let first = finite
        .history
        .iter()
        .filter(|r| r.stability == Some(Stability::Unstable))
        .map(|r| r.step)
        .find(|&attempt| {
            // from the first unstable accepted step on
            finite
                .steps
                .iter()
                .any(|s| s.attempt == attempt && s.accepted)
        })
        .unwrap_or(last.step);
    Some(format!(
        "the state the solve converged to is not a stable equilibrium: the Newton tangent there is not positive definite on the kernel of the active contact rows (first seen at load factor {:.4}, the end of load step {first}): the loads are balanced, but the slightest disturbance leaves this state (the structure buckles, or a body slides away on its contact), and a real body would not stay in it; hold the modes the supports leave free (symmetry planes, more supports), or apply less load",
        load_factor(first)
    ))
}

/// Share of the largest energy of a time integration by which the total energy may grow
/// before the run warns (see [`energy_growth`]).
pub const ENERGY_GROWTH_SHARE: f64 = 0.1;

/// The same share for the contact-stabilized Newmark method, whose discrete energy does not
/// grow when the constraints hold exactly (round-off: its Lagrange runs gain about 1e-14).
pub const STABILIZED_ENERGY_GROWTH_SHARE: f64 = 1e-8;

/// A warning when the total energy of a time integration (kinetic + strain + penalty
/// contact + load potential, conserved by the trapezoidal rule without contact) grew by more
/// than [`ENERGY_GROWTH_SHARE`] of the largest energy of the run: the integration added
/// energy (a stiff penalty struck with a penetration per step the step cannot resolve, or an
/// explicit step near its limit). Contact and numerical damping only remove energy. With
/// `impact: "contact_stabilized"` the bound is [`STABILIZED_ENERGY_GROWTH_SHARE`]: Deuflhard,
/// Krause & Ertel's energy bound holds for constraints that hold exactly (Lagrange
/// multipliers, elimination); a penalty's penetration stores and returns energy that the
/// projection onto the admissible set does not see, and the run says so when it gains.
pub fn energy_growth<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
) -> Option<String> {
    let h = solution.dynamics.as_ref()?;
    let first = h.steps.first()?;
    let scale = h
        .steps
        .iter()
        .map(|s| {
            s.kinetic
                .abs()
                .max(s.strain.abs())
                .max(s.contact_energy.abs())
                .max(s.load_potential.abs())
        })
        .fold(0.0f64, f64::max);
    let stabilized = model
        .dynamics
        .as_ref()
        .is_some_and(|d| d.impact == crate::io::scene::ImpactTreatment::ContactStabilized);
    let share = if stabilized {
        STABILIZED_ENERGY_GROWTH_SHARE
    } else {
        ENERGY_GROWTH_SHARE
    };
    let most = h.steps.iter().max_by(|a, b| a.total.total_cmp(&b.total))?;
    (most.total - first.total > share * scale).then(|| {
        let grew = format!(
            "the total energy grew from {:.4e} to {:.4e} (step {}, t = {:.4e}, {:.3e} of the largest energy of the run)",
            first.total,
            most.total,
            most.step,
            most.time,
            (most.total - first.total) / scale
        );
        if stabilized {
            let inexact: Vec<&str> = model
                .contact
                .iter()
                .filter(|p| {
                    !matches!(
                        crate::contact::enforcement::method(&p.enforcement).kernel().family(),
                        crate::contact::enforcement::Family::LagrangeMultipliers
                            | crate::contact::enforcement::Family::Elimination
                    )
                })
                .map(|p| p.name.as_str())
                .collect();
            format!(
                "{grew}: the contact-stabilized method keeps the energy from growing only where the constraints hold exactly; {} enforced inexactly (a penalty's penetration stores and returns energy the projection does not see); use Lagrange multipliers for an energy that does not grow",
                if inexact.is_empty() {
                    "no pair is".to_string()
                } else {
                    format!("pair(s) '{}' are", inexact.join("', '"))
                }
            )
        } else {
            format!(
                "{grew}, more than {ENERGY_GROWTH_SHARE} of it: the integration added energy (a penalty much stiffer than the bodies struck with a penetration per step that the step cannot resolve, or an explicit step near its stability limit); use \"impact\": \"contact_stabilized\", a smaller dt or a softer penalty"
            )
        }
    })
}
