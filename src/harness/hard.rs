//! The stability suite's report: every hard case (`cases/hard/`) with its method, its expected
//! and actual outcome, its iterations, the condition estimate of its last factored system
//! ([`crate::solver::conditioning`]), its equilibrium residual and its accuracy (the worst
//! ratio of a declared accuracy check's error to its tolerance), and whether it met every
//! expectation it states. A case meets its expectation when all its checks pass: its
//! `terminates_with` (converged, or a named stop whose message or diagnosis contains the
//! stated words) and its accuracy checks against closed forms.

use crate::contact::enforcement::method;
use crate::contact::state::Termination;
use crate::harness::stability::{conditioning, status_changes};
use crate::io::scene::{Check, DiscretizationSpec, MultiplierSpace, Scheme};
use crate::run::Outcome;
use serde::Serialize;

/// One hard case in the report.
#[derive(Clone, Debug, Serialize)]
pub struct HardCase {
    pub case: String,
    /// Discretization, enforcement (with kappa) and scheme of the first pair.
    pub method: String,
    /// The outcome the case expects (`converged` without a `terminates_with` check).
    pub expected: String,
    /// How the contact solve ended.
    pub outcome: String,
    pub iterations: usize,
    pub condition_estimate: Option<f64>,
    pub equilibrium_residual: f64,
    /// The worst `error / tol` over the declared accuracy checks (not `terminates_with`,
    /// `warns` or `status_changes`); `None` without one.
    pub accuracy: Option<f64>,
    /// Status changes: most after one iteration, most in one load step.
    pub status_changes: [usize; 2],
    /// Every check passed.
    pub met: bool,
    /// The run's warnings (diagnoses).
    pub warnings: Vec<String>,
    /// The case could not run: the error.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

fn termination_name(t: &Termination) -> &'static str {
    match t {
        Termination::Converged => "converged",
        Termination::IterationLimit => "iteration_limit",
        Termination::ActiveSetCycling(_) => "active_set_cycling",
        Termination::Singular(_) => "singular",
        Termination::WorkLimit(_) => "work_limit",
    }
}

/// The method of the first contact pair, in words.
fn method_of(outcome: &Outcome) -> String {
    let model = &outcome.model;
    let Some(pair) = model.contact.first() else {
        return "elasticity".into();
    };
    let disc = match &pair.discretization {
        DiscretizationSpec::NodeToNode => "node-to-node".to_string(),
        DiscretizationSpec::NodeToSurface { passes, .. } => format!("NTS {passes}-pass"),
        DiscretizationSpec::Mortar { multiplier } => match multiplier {
            MultiplierSpace::Standard => "mortar".to_string(),
            MultiplierSpace::Dual => "dual mortar".to_string(),
        },
    };
    let m = method(&pair.enforcement);
    let enforcement = format!("{:?}", pair.enforcement)
        .split([' ', '{'])
        .next()
        .unwrap_or_default()
        .to_string();
    let kappa = m
        .kappa()
        .map(|k| format!(" kappa {k:.1e}"))
        .unwrap_or_default();
    let scheme = if model.solver.scheme == Scheme::Newton {
        ", Newton"
    } else {
        ""
    };
    format!("{disc}, {enforcement}{kappa}{scheme}")
}

/// The report row of a run.
pub fn row(outcome: &Outcome) -> HardCase {
    let model = &outcome.model;
    let solution = &outcome.solution;
    let expected = model
        .checks
        .iter()
        .find_map(|c| match c {
            Check::TerminatesWith { reason, contains } => Some(match contains {
                Some(w) => format!("{reason:?} ({w:?})"),
                None => format!("{reason:?}"),
            }),
            _ => None,
        })
        .unwrap_or_else(|| "Converged".into());
    let state = solution.contact.as_ref();
    let accuracy_checks = model
        .checks
        .iter()
        .zip(&outcome.checks[outcome.checks.len() - model.checks.len()..]);
    let accuracy = accuracy_checks
        .filter(|(c, _)| {
            !matches!(
                c,
                Check::TerminatesWith { .. } | Check::Warns { .. } | Check::StatusChanges { .. }
            )
        })
        .map(|(_, r)| {
            if r.tol > 0.0 {
                r.error / r.tol
            } else if r.error == 0.0 {
                0.0
            } else {
                f64::INFINITY
            }
        })
        .reduce(f64::max);
    let c = conditioning(model, solution);
    HardCase {
        case: model.name.clone(),
        method: method_of(outcome),
        expected,
        outcome: state
            .map(|s| termination_name(&s.termination))
            .unwrap_or("no contact")
            .into(),
        iterations: state.map(|s| s.iterations).unwrap_or(0),
        condition_estimate: c.condition_estimate,
        equilibrium_residual: c.equilibrium_residual,
        accuracy,
        status_changes: state
            .map(|s| {
                let (a, b) = status_changes(s);
                [a, b]
            })
            .unwrap_or([0, 0]),
        met: outcome.passed(),
        warnings: outcome.warnings.clone(),
        error: None,
    }
}

/// The report row of a case that could not run.
pub fn error_row(case: &str, error: &str) -> HardCase {
    HardCase {
        case: case.into(),
        method: String::new(),
        expected: String::new(),
        outcome: "error".into(),
        iterations: 0,
        condition_estimate: None,
        equilibrium_residual: f64::NAN,
        accuracy: None,
        status_changes: [0, 0],
        met: false,
        warnings: Vec::new(),
        error: Some(error.into()),
    }
}

fn sci(v: Option<f64>) -> String {
    match v {
        Some(v) if v.is_finite() => format!("{v:.1e}"),
        Some(v) => format!("{v}"),
        None => "-".into(),
    }
}

/// The Markdown report: a table of every case and, below it, the diagnoses the runs gave.
pub fn markdown(rows: &[HardCase]) -> String {
    let met = rows.iter().filter(|r| r.met).count();
    let mut s = String::from("# Hard cases: numerical stability\n\n");
    s.push_str(&format!(
        "Written by `contact-patch hard` from `cases/hard/` (generated by `cases/hard/make_cases.py`). \
         {met} of {} cases meet the outcome they state. `cond` is the estimated 1-norm condition \
         number of the last factored system (Hager-Higham), `equilibrium` the relative residual \
         of the answer, `accuracy` the worst error / tolerance over the case's accuracy checks \
         (at most 1 when they pass), `status changes` the most after one iteration / in one step.\n\n",
        rows.len()
    ));
    s.push_str("| case | method | expected | outcome | iterations | cond | equilibrium | accuracy | status changes | met |\n");
    s.push_str("|---|---|---|---|---|---|---|---|---|---|\n");
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} / {} | {} |\n",
            r.case,
            r.method,
            r.expected.replace('|', "\\|"),
            r.outcome,
            r.iterations,
            sci(r.condition_estimate),
            sci(Some(r.equilibrium_residual)),
            sci(r.accuracy),
            r.status_changes[0],
            r.status_changes[1],
            if r.met { "yes" } else { "**no**" }
        ));
    }
    s.push_str("\n## Diagnoses\n\n");
    for r in rows {
        for w in r.warnings.iter().chain(&r.error) {
            s.push_str(&format!("- `{}`: {}\n", r.case, w.replace('\n', " ")));
        }
    }
    s
}
