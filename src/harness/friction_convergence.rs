//! Newton's residual histories with the frictional tangents (issue 10, "Newton with the
//! consistent unsymmetric tangent converges quadratically; with the symmetrized one it
//! converges, more slowly"): `reports/friction-convergence.md` and `.json`, written by
//! `contact-patch friction-convergence`.
//!
//! Two problems, each solved with the penalty and the augmented Lagrangian (Uzawa update per
//! iteration) as normal law and every `solver.friction_tangent` that applies:
//!
//! * the **slip patch** `cases/friction/friction-A-slip.json` (mesh A, node-to-surface, the
//!   punch top dragged past the cone in the second load step: every point slips with
//!   `|lambda_t| = mu lambda_n`);
//! * the **incline** of `shared/design/benchmarks.md` s. 4: a block on a rigid line under its
//!   weight `G` and a push `F = 0.98 F_limit` (`tan a = 0.1`, `mu = 0.3`, `F_limit / G =
//!   (tan a + mu) / (1 - mu tan a) = 0.412371`), four load steps.
//!
//! Tangents: `consistent` (the exact derivative of the return map: unsymmetric in slip, LU),
//! `symmetrized` (the slip coupling `s mu w_n b_t b_n^T` dropped: not the derivative),
//! `laursen_simo` (augmented Lagrangian only: the slip force `s mu lambda_bar_n` held fixed in
//! each Newton pass, so its exact tangent is symmetric; Laursen & Simo 1993). The residual is
//! `max |R| / max(|f|, |contact force|)`; Newton stops below `1e-10` with no status change. With
//! the penalty law and fixed branches the residual is piecewise affine in the reference
//! geometry, so the consistent tangent lands on the solution in one step once the branches
//! have settled (quadratic convergence in its extreme form), while the symmetrized one
//! contracts linearly. The augmented Lagrangian's histories interleave Newton passes with
//! Uzawa updates (each update raises the residual again; the count of iterations includes
//! every pass).

use crate::contact::state::IterationRecord;
use crate::error::Result;
use crate::model::{parse, Model};
use crate::solver::active_set::Termination;
use serde::Serialize;
use serde_json::{json, Value};
use std::path::Path;

/// One solve of the study.
#[derive(Clone, Debug, Serialize)]
pub struct ConvergenceRun {
    pub problem: String,
    pub enforcement: String,
    pub tangent: String,
    pub termination: String,
    /// Newton iterations (linear solves) per load step.
    pub iterations: Vec<usize>,
    /// The relative residual after every iteration of the last load step.
    pub last_step_residuals: Vec<f64>,
    /// Status changes after every iteration of the last load step.
    pub last_step_status_changes: Vec<usize>,
}

/// The incline of `benchmarks.md` s. 4 at `F / G = ratio * F_limit / G`.
fn incline(ratio: f64) -> Value {
    let (tan_a, mu, g, area): (f64, f64, f64, f64) = (0.1, 0.3, 10.0, 2.0);
    let limit = (tan_a + mu) / (1.0 - mu * tan_a);
    let (s, c) = (
        tan_a / (1.0 + tan_a * tan_a).sqrt(),
        1.0 / (1.0 + tan_a * tan_a).sqrt(),
    );
    let f = ratio * limit * g;
    json!({
        "name": "incline",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": 1000.0, "nu": 0.3}},
        "bodies": [{"name": "block", "material": "m",
            "mesh": {"block": {"element": "Q4", "x": [0, 0.5, 1, 1.5, 2], "y": [0, 0.5, 1]}}}],
        "supports": [],
        "loads": [{"body": "block", "body_force": [(f * c - g * s) / area, -(g * c + f * s) / area]}],
        "contact": [{
            "name": "base",
            "slave": {"body": "block", "set": "bottom"},
            "master": {"rigid": {"kind": "line", "point": [0.0, 0.0], "normal": [0.0, 1.0]}},
            "discretization": {"kind": "node_to_surface", "passes": 1},
            "enforcement": {"kind": "penalty", "kappa": 1e4},
            "interaction": {"coulomb": {"mu": mu}},
        }],
        "solver": {"scheme": "newton", "load_steps": 4},
    })
}

/// Solve `case` with the enforcement `enforcement` and the tangent `tangent`.
fn solve(problem: &str, case: &Value, enforcement: &str, tangent: &str) -> Result<ConvergenceRun> {
    let mut v = case.clone();
    v["contact"][0]["enforcement"] = json!({"kind": enforcement, "kappa": 1e4});
    v["solver"]["friction_tangent"] = json!(tangent);
    let parsed = parse(&v.to_string(), problem)?;
    let model = Model::build(&parsed, problem)?;
    let solution = match crate::solver::solve_static(&model, &mut |_| {}) {
        Ok(s) => s,
        // a diverged iteration (e.g. a block held by friction alone sliding away under a
        // tangent that is not the derivative) is recorded, not hidden
        Err(e) => {
            return Ok(ConvergenceRun {
                problem: problem.into(),
                enforcement: enforcement.into(),
                tangent: tangent.into(),
                termination: format!(
                    "no solution: {}",
                    e.to_string().lines().next().unwrap_or_default()
                ),
                iterations: Vec::new(),
                last_step_residuals: Vec::new(),
                last_step_status_changes: Vec::new(),
            })
        }
    };
    let state = solution.contact.as_ref().expect("a contact solve");
    let last = state.steps.len();
    let history: Vec<&IterationRecord> = state.history.iter().filter(|h| h.step == last).collect();
    Ok(ConvergenceRun {
        problem: problem.into(),
        enforcement: enforcement.into(),
        tangent: tangent.into(),
        termination: match &state.termination {
            Termination::Converged => "converged".into(),
            Termination::Singular(why) => format!("singular: {why}"),
            t => format!("{t:?}"),
        },
        iterations: state.steps.iter().map(|s| s.iterations).collect(),
        last_step_residuals: history.iter().map(|h| h.residual).collect(),
        last_step_status_changes: history.iter().map(|h| h.status_changes).collect(),
    })
}

/// Run the study; `root` is the repository (for `cases/friction/friction-A-slip.json`).
pub fn study(root: &Path) -> Result<Vec<ConvergenceRun>> {
    let path = root.join("cases/friction/friction-A-slip.json");
    let text = std::fs::read_to_string(&path).map_err(|e| {
        crate::error::Error::invalid(
            path.display(),
            "file",
            format!("cannot read the slip patch case: {e}"),
            "run the command from the repository's root folder",
        )
    })?;
    let mut patch: Value = serde_json::from_str(&text).map_err(|e| {
        crate::error::Error::invalid(
            path.display(),
            "file",
            format!("not JSON: {e}"),
            "regenerate it with python3 cases/friction/make_cases.py",
        )
    })?;
    if let Some(o) = patch.as_object_mut() {
        o.remove("sweep");
    }
    let mut runs = Vec::new();
    for (problem, case) in [
        ("slip patch A", patch),
        ("incline F = 0.98 F_limit", incline(0.98)),
    ] {
        for (enforcement, tangents) in [
            ("penalty", &["consistent", "symmetrized"][..]),
            (
                "augmented_lagrange",
                &["consistent", "symmetrized", "laursen_simo"][..],
            ),
        ] {
            for tangent in tangents {
                runs.push(solve(problem, &case, enforcement, tangent)?);
            }
        }
    }
    Ok(runs)
}

/// The Markdown report of the study.
pub fn report(runs: &[ConvergenceRun]) -> String {
    let mut s = String::from(
        "# Newton's convergence with the frictional tangents\n\n\
         Generated by `contact-patch friction-convergence` (do not edit by hand); see\n\
         `src/harness/friction_convergence.rs` for the problems. `consistent`: the exact\n\
         (unsymmetric in slip) tangent, LU; `symmetrized`: the slip coupling dropped;\n\
         `laursen_simo`: the augmented Lagrangian's slip force bounded by the normal multiplier held\n\
         fixed in each Newton pass (a symmetric exact tangent). Residuals are relative; the\n\
         augmented Lagrangian's histories include the passes after each Uzawa update.\n\n\
         | problem | normal law | tangent | termination | iterations per step | residuals of the last step (status changes) |\n\
         |---|---|---|---|---|---|\n",
    );
    for r in runs {
        let residuals: Vec<String> = r
            .last_step_residuals
            .iter()
            .zip(&r.last_step_status_changes)
            .map(|(v, c)| format!("{v:.1e} ({c})"))
            .collect();
        s += &format!(
            "| {} | {} | {} | {} | {:?} | {} |\n",
            r.problem,
            r.enforcement,
            r.tangent,
            r.termination.replace('|', "/"),
            r.iterations,
            residuals.join(", ")
        );
    }
    s
}
