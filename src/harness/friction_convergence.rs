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
//!
//! Newton's iterations per load step over every discretization and enforcement with friction
//! (issue 39): the slip patch A (every discretization and enforcement of its sweep) pressed,
//! dragged past the cone and dragged back past it (the step after a slip, where a trial force
//! on the cone to round-off used to start on the slip branch), and the friction block of
//! `tests/friction.rs` (Q4 and Q9 on a rigid line: pressed, slid by ten element lengths,
//! brought back through a step that sticks, slid back past its start) with every
//! enforcement. `--baseline BINARY` runs the same cases, written as case files, with another
//! build of the tool (`BINARY run CASE --out DIR`) and lists its iterations beside: the
//! before and after of a change.

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
    let load =
        json!([{"body": "block", "body_force": [(f * c - g * s) / area, -(g * c + f * s) / area]}]);
    block_on_rigid_line("incline", "Q4", 0.3, json!([]), load, 4)
}

/// A block `[0, 2] x [0, 1]` (E = 1000, Poisson's ratio `nu`) of `element` cells (4 x 2) on the
/// rigid line `y = 0`, its bottom the slave of a node-to-surface pair with Coulomb friction
/// (mu = 0.3, penalty 1e4), under `supports` and `loads`, in `steps` load steps (Newton).
fn block_on_rigid_line(
    name: &str,
    element: &str,
    nu: f64,
    supports: Value,
    loads: Value,
    steps: usize,
) -> Value {
    json!({
        "name": name,
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": 1000.0, "nu": nu}},
        "bodies": [{"name": "block", "material": "m",
            "mesh": {"block": {"element": element, "x": [0, 0.5, 1, 1.5, 2], "y": [0, 0.5, 1]}}}],
        "supports": supports,
        "loads": loads,
        "contact": [{
            "name": "base",
            "slave": {"body": "block", "set": "bottom"},
            "master": {"rigid": {"kind": "line", "point": [0.0, 0.0], "normal": [0.0, 1.0]}},
            "discretization": {"kind": "node_to_surface", "passes": 1},
            "enforcement": {"kind": "penalty", "kappa": 1e4},
            "interaction": {"coulomb": {"mu": 0.3}},
        }],
        "solver": {"scheme": "newton", "load_steps": steps},
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

/// The slip patch case `cases/friction/friction-A-slip.json` under `root` (the repository).
fn read_slip_patch(root: &Path) -> Result<Value> {
    let path = root.join("cases/friction/friction-A-slip.json");
    let text = std::fs::read_to_string(&path).map_err(|e| {
        crate::error::Error::invalid(
            path.display(),
            "file",
            format!("cannot read the slip patch case: {e}"),
            "run the command from the repository's root folder",
        )
    })?;
    serde_json::from_str(&text).map_err(|e| {
        crate::error::Error::invalid(
            path.display(),
            "file",
            format!("not JSON: {e}"),
            "regenerate it with python3 cases/friction/make_cases.py",
        )
    })
}

/// Run the study; `root` is the repository (for `cases/friction/friction-A-slip.json`).
pub fn study(root: &Path) -> Result<Vec<ConvergenceRun>> {
    let mut patch = read_slip_patch(root)?;
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

/// Newton's iterations per load step of one case of the sweep, and of the baseline build.
#[derive(Clone, Debug, Serialize)]
pub struct StepIterations {
    pub problem: String,
    pub discretization: String,
    pub enforcement: String,
    /// Iterations per step and how the solve ended (`converged`, or why not).
    pub iterations: Vec<usize>,
    pub termination: String,
    /// The same case run by the baseline build (`--baseline`), when one was given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub baseline: Option<(Vec<usize>, String)>,
}

/// The slip patch A dragged forward past the cone in step 2 and back past it in step 3 (the
/// exact field's shear reversed): the patch case with every load path extended.
fn reversed_slip_patch(patch: &Value) -> Value {
    let mut v = patch.clone();
    let extend = |parts: &mut Value| {
        for part in parts.as_array_mut().into_iter().flatten() {
            if let Some(path) = part.get_mut("path").and_then(Value::as_array_mut) {
                let last = path.last().and_then(Value::as_f64).unwrap_or(1.0);
                let first = path.first().and_then(Value::as_f64).unwrap_or(1.0);
                // a constant part (the pressure) stays, a ramped one (the drag) reverses
                path.push(json!(if first == last { last } else { -last }));
            }
        }
    };
    extend(&mut v["supports"]);
    extend(&mut v["loads"]);
    v["solver"]["load_steps"] = json!(3);
    v
}

/// The load path of the friction block ([`friction_block`]): (pressure factor, top slide) per
/// step: pressed, slid by ten element lengths (0.5 each), brought back by 0.0002 (inside the
/// elastic range), slid back past its start to -1.
pub fn friction_block_path() -> Vec<(f64, f64)> {
    let h = 0.5;
    let mut path = vec![(1.0, 0.0)];
    path.extend((1..=10).map(|k| (1.0, k as f64 * h)));
    path.push((1.0, 10.0 * h - 0.0002));
    path.extend((0..=4).rev().map(|k| (1.0, (2 * k) as f64 * h - 1.0)));
    path
}

/// The friction block (`tests/friction.rs`): a block `[0, 2] x [0, 1]` (E = 1000, `nu = 0`)
/// of `element` (Q4 or Q9, 4 x 2 cells) on a rigid line with Coulomb friction (mu = 0.3,
/// penalty 1e4), its top pressed by 10 times the first factor of `path` and moved along x by
/// the second.
pub fn friction_block(element: &str, path: &[(f64, f64)]) -> Value {
    let pressure: Vec<f64> = path.iter().map(|p| p.0).collect();
    let slide: Vec<f64> = path.iter().map(|p| p.1).collect();
    block_on_rigid_line(
        &format!("friction-block-{element}"),
        element,
        0.0,
        json!([{"body": "block", "set": "top", "x": 1.0, "path": slide}]),
        json!([{"body": "block", "set": "top", "pressure": 10.0, "path": pressure}]),
        path.len(),
    )
}

/// A short name of a discretization or enforcement of the sweep.
fn label(v: &Value) -> String {
    let kind = v["kind"].as_str().unwrap_or("?").to_string();
    let mut extra: Vec<String> = Vec::new();
    for key in ["passes", "multiplier", "update"] {
        if let Some(x) = v.get(key) {
            extra.push(x.to_string().trim_matches('"').to_string());
        }
    }
    if extra.is_empty() {
        kind
    } else {
        format!("{kind} ({})", extra.join(", "))
    }
}

/// The cases of the sweep: `(problem, discretization, enforcement, case)`; `reproducer`: the
/// case of defect N01 when found (an 8 x 4 block pressed, then moved at its top).
fn sweep_cases(patch: &Value, reproducer: Option<Value>) -> Vec<(String, String, String, Value)> {
    let mut cases = Vec::new();
    let sweep = &patch["sweep"];
    let mut base = reversed_slip_patch(patch);
    if let Some(o) = base.as_object_mut() {
        o.remove("sweep");
        o.remove("checks");
    }
    let enforcements: Vec<Value> = sweep["enforcements"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    for d in sweep["discretizations"].as_array().into_iter().flatten() {
        let mut case = base.clone();
        let pair = &mut case["contact"][0];
        pair["discretization"] = d["discretization"].clone();
        let swapped = d["slave"].as_str() == Some("foundation");
        if swapped {
            let slave = pair["slave"].clone();
            pair["slave"] = pair["master"].clone();
            pair["master"] = slave;
        }
        let discretization = format!(
            "{}{}",
            label(&d["discretization"]),
            if swapped { ", foundation slave" } else { "" }
        );
        for e in &enforcements {
            let mut c = case.clone();
            c["contact"][0]["enforcement"] = e.clone();
            cases.push((
                "slip patch A, dragged back".to_string(),
                discretization.clone(),
                label(e),
                c,
            ));
        }
    }
    let path = friction_block_path();
    let blocks = ["Q4", "Q9"].map(|e| (format!("friction block {e}"), friction_block(e, &path)));
    let n01 = reproducer.map(|v| ("defect N01 (8 x 4 block, 2 steps)".to_string(), v));
    for (problem, block) in blocks.into_iter().chain(n01) {
        for e in &enforcements {
            let mut c = block.clone();
            c["contact"][0]["enforcement"] = e.clone();
            cases.push((
                problem.clone(),
                label(&block["contact"][0]["discretization"]),
                label(e),
                c,
            ));
        }
    }
    cases
}

/// Iterations per step and how a contact solve ended, from a solution.
fn iterations_of(solution: &crate::solver::linear::Solution) -> (Vec<usize>, String) {
    let Some(state) = solution.contact.as_ref() else {
        return (Vec::new(), "no contact solve".into());
    };
    (
        state.steps.iter().map(|s| s.iterations).collect(),
        match &state.termination {
            Termination::Converged => "converged".into(),
            t => format!("{t:?}"),
        },
    )
}

/// Run `case` with the build `binary` (`binary run CASE --out DIR`, the case file and `DIR` in
/// the folder `work`): its iterations per step and termination from its `summary.json`, or
/// the first line of what it said when it wrote none.
fn baseline_iterations(
    binary: &Path,
    work: &Path,
    name: &str,
    case: &Value,
) -> Result<(Vec<usize>, String)> {
    let cannot = |what: &Path, e: std::io::Error| {
        crate::error::Error::invalid(
            what.display(),
            "file",
            format!("cannot write there: {e}"),
            "choose an output folder (--out) that can be written",
        )
    };
    std::fs::create_dir_all(work).map_err(|e| cannot(work, e))?;
    let file = work.join(format!("{name}.json"));
    std::fs::write(&file, case.to_string()).map_err(|e| cannot(&file, e))?;
    let out = work.join(name);
    let output = std::process::Command::new(binary)
        .arg("run")
        .arg(&file)
        .arg("--out")
        .arg(&out)
        .output()
        .map_err(|e| {
            crate::error::Error::invalid(
                binary.display(),
                "baseline",
                format!("cannot run the baseline build: {e}"),
                "give the path of a contact-patch executable (e.g. target/release/contact-patch of another checkout)",
            )
        })?;
    let summary: Option<Value> = std::fs::read_to_string(out.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    let Some(steps) = summary
        .as_ref()
        .and_then(|s| s["contact"]["steps"].as_array().cloned())
    else {
        let said = String::from_utf8_lossy(&output.stderr);
        let first = said.lines().next().unwrap_or("no summary.json");
        // without the case file's path
        let first = first
            .split_once(".json: ")
            .map_or(first, |(_, rest)| rest)
            .to_string();
        return Ok((Vec::new(), format!("no solution: {first}")));
    };
    let iterations = steps
        .iter()
        .map(|s| s["iterations"].as_u64().unwrap_or(0) as usize)
        .collect();
    let termination = summary.as_ref().map_or(String::new(), |s| {
        match s["contact"]["termination"].as_str().unwrap_or("?") {
            "Converged" => "converged".to_string(),
            t => t.to_string(),
        }
    });
    Ok((iterations, termination))
}

/// Run the sweep of iterations per step (`root`: the repository, for the slip patch case),
/// each case also with the build `baseline` when given (its case files and outputs in the
/// folder `work`).
pub fn step_iterations(
    root: &Path,
    baseline: Option<&Path>,
    work: &Path,
) -> Result<Vec<StepIterations>> {
    let patch = read_slip_patch(root)?;
    let reproducer = std::fs::read_to_string(
        root.join("tests/defects/s4/N01-friction-newton-after-slip-8x4-2steps.json"),
    )
    .ok()
    .and_then(|t| serde_json::from_str::<Value>(&t).ok())
    .map(|mut v| {
        if let Some(o) = v.as_object_mut() {
            o.remove("checks");
        }
        v
    });
    let mut rows = Vec::new();
    for (k, (problem, discretization, enforcement, case)) in
        sweep_cases(&patch, reproducer).into_iter().enumerate()
    {
        let first_line =
            |e: crate::error::Error| e.to_string().lines().next().unwrap_or_default().to_string();
        let (iterations, termination) =
            match parse(&case.to_string(), &problem).and_then(|c| Model::build(&c, &problem)) {
                Err(e) => (Vec::new(), format!("refused: {}", first_line(e))),
                Ok(model) => match crate::solver::solve_static(&model, &mut |_| {}) {
                    Ok(solution) => iterations_of(&solution),
                    Err(e) => (Vec::new(), format!("failed: {}", first_line(e))),
                },
            };
        let baseline = baseline
            .map(|b| baseline_iterations(b, work, &format!("case-{k}"), &case))
            .transpose()?;
        rows.push(StepIterations {
            problem,
            discretization,
            enforcement,
            iterations,
            termination,
            baseline,
        });
    }
    Ok(rows)
}

/// The Markdown table of [`step_iterations`].
pub fn step_iterations_report(rows: &[StepIterations], baseline: Option<&str>) -> String {
    let mut s = String::from(
        "\n## Newton's iterations per load step, every discretization and enforcement with friction\n\n\
         The slip patch A pressed, dragged past the cone (step 2) and dragged back past it (step 3);\n\
         the friction block (Q4 and Q9 on a rigid line) pressed, slid by ten element lengths, brought\n\
         back through a step that sticks and slid back past its start (17 steps); the case of defect\n\
         N01 (`tests/defects/s4/`, an 8 x 4 block pressed onto a rigid line and moved at its top). The\n\
         enforcement kinds and discretizations are those of the slip patch's sweep\n\
         (`cases/friction/friction-A-slip.json`); a combination the tool refuses says why.\n",
    );
    let cell = |iterations: &[usize], termination: &str| {
        let total: usize = iterations.iter().sum();
        let shown = if termination == "converged" {
            format!("{iterations:?} (total {total})")
        } else {
            format!("{iterations:?}: {termination}")
        };
        shown.replace('|', "/")
    };
    match baseline {
        Some(b) => {
            s += &format!(
                "Before: the same cases run by the build `{b}`; after: this build.\n\n\
                 | problem | discretization | enforcement | before | after |\n|---|---|---|---|---|\n"
            );
        }
        None => {
            s += "\n| problem | discretization | enforcement | iterations per step |\n|---|---|---|---|\n";
        }
    }
    for r in rows {
        let after = cell(&r.iterations, &r.termination);
        match &r.baseline {
            Some((iterations, termination)) => {
                s += &format!(
                    "| {} | {} | {} | {} | {after} |\n",
                    r.problem,
                    r.discretization,
                    r.enforcement,
                    cell(iterations, termination)
                );
            }
            None => {
                s += &format!(
                    "| {} | {} | {} | {after} |\n",
                    r.problem, r.discretization, r.enforcement
                );
            }
        }
    }
    s
}
