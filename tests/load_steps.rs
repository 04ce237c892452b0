//! Load steps (`solver.load_steps`): the load applied in equal steps, each starting from the
//! last one's active set (and, in current geometry, its configuration). Frictionless contact
//! carries no history, so 1 and 10 steps must give the same answer; the steps are recorded.

mod common;

use contact_patch::model::{parse, Model};
use contact_patch::run::run_model;
use std::path::Path;

fn solve(case: &str, steps: usize) -> contact_patch::run::Outcome {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(case);
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    v["solver"] = serde_json::json!({ "load_steps": steps });
    let case = parse(&v.to_string(), case).unwrap();
    let model = Model::build(&case, "steps").unwrap();
    run_model(model, 0.0, std::time::Instant::now(), &mut |_| {}).unwrap()
}

#[test]
fn one_and_ten_load_steps_agree() {
    for (case, tol) in [
        ("cases/contact/signorini-block-on-rigid-line.json", 1e-12),
        ("cases/contact/block-on-rigid-cylinder-lagrange.json", 1e-12),
        (
            "cases/contact/block-on-rigid-cylinder-augmented-lagrange.json",
            1e-12,
        ),
        ("cases/patch/patch-B-nu0.3.json", 1e-12),
        ("cases/patch/patch-C-nu0.3.json", 1e-12),
        ("cases/tied/tied-C-shear.json", 1e-12),
        // the geometry updates stop at a relative change of 1e-12, so the two paths agree to
        // a few times that
        (
            "cases/contact/block-on-rigid-cylinder-finite-sliding.json",
            1e-11,
        ),
    ] {
        let one = solve(case, 1);
        let ten = solve(case, 10);
        let scale = one.solution.u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = one
            .solution
            .u
            .iter()
            .zip(&ten.solution.u)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            diff <= tol * scale,
            "{case}: 1 and 10 steps differ by {:e}",
            diff / scale
        );
        let steps = &ten.solution.contact.as_ref().unwrap().steps;
        assert_eq!(steps.len(), 10, "{case}");
        for (k, s) in steps.iter().enumerate() {
            assert_eq!(s.step, k + 1);
            assert!((s.load_factor - (k + 1) as f64 / 10.0).abs() < 1e-15);
            assert_eq!(
                s.termination,
                contact_patch::solver::active_set::Termination::Converged
            );
        }
        assert_eq!(one.passed(), ten.passed(), "{case}");
    }
}

#[test]
fn load_steps_and_limits_are_validated() {
    for (field, value) in [
        ("load_steps", 0),
        ("max_iterations", 0),
        ("load_steps", 1_000_000),
    ] {
        let text = std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("cases/contact/signorini-block-on-rigid-line.json"),
        )
        .unwrap();
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v["solver"] = serde_json::json!({ field: value });
        let case = parse(&v.to_string(), "case").unwrap();
        let e = Model::build(&case, "case").unwrap_err().to_string();
        assert!(e.contains(&format!("solver.{field}")), "{e}");
    }
}

#[test]
fn the_history_records_every_iteration() {
    let o = solve(
        "cases/contact/block-on-rigid-cylinder-augmented-lagrange.json",
        2,
    );
    let state = o.solution.contact.as_ref().unwrap();
    let h = &state.history;
    // every linear solve of both steps, numbered within its step
    let total: usize = state.steps.iter().map(|s| s.iterations).sum();
    assert_eq!(h.len(), total);
    for s in &state.steps {
        let of_step: Vec<_> = h.iter().filter(|r| r.step == s.step).collect();
        assert_eq!(of_step.len(), s.iterations);
        assert!(of_step
            .iter()
            .enumerate()
            .all(|(k, r)| r.iteration == k + 1));
        // the last iteration of a converged step changes no status and leaves no penetration
        let last = of_step.last().unwrap();
        assert_eq!(last.status_changes, 0);
        assert!(last.max_gap_violation <= 1e-12, "{last:?}");
    }
    // the first iteration of step 1 starts from the rows closed at zero displacement, so the
    // active set grows: the count that shows chattering is not zero there
    assert!(h[0].status_changes > 0);
    assert!(h
        .iter()
        .all(|r| r.residual <= 1e-10 && r.linear_solver == "cholesky"));
}

/// `contact-patch run` on `case` (a JSON value written to a scratch folder); the exit code and
/// `summary.json`.
fn run_json(case: &serde_json::Value) -> (i32, serde_json::Value) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("case.json");
    std::fs::write(&path, case.to_string()).unwrap();
    let out = dir.path().join("out");
    let output = common::run_case(&path, &out);
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap_or_else(|_| {
        panic!(
            "no summary.json: {}",
            String::from_utf8_lossy(&output.stderr)
        )
    });
    (
        output.status.code().unwrap(),
        serde_json::from_str(&summary).unwrap(),
    )
}

fn reproducer(name: &str) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(common::defect(name)).unwrap()).unwrap()
}

/// The vertical reaction of the support set `set`.
fn reaction_y(summary: &serde_json::Value, set: &str) -> f64 {
    summary["reactions"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["set"] == set)
        .unwrap_or_else(|| panic!("no reaction of {set}: {summary}"))["y"]
        .as_f64()
        .unwrap()
}

/// Defect W01 (second report): the path was ignored with one load step (the contact driver
/// scaled the model only for more than one step) and in every run without contact (the
/// elastic solve never scaled it): exit 0 with half the load. The path is the load history in
/// every run: one step or many, with or without contact, 2D and 3D, small and finite strain.
#[test]
fn the_load_path_is_the_load_history_in_every_run() {
    // W01a: pressure 1 on [0, 2], path [2.0], one step: the floor carries 4 (the control W01b,
    // two steps with [2, 2], gave 4 before the fix too)
    for name in ["W01a", "W01b"] {
        let (code, summary) = run_json(&reproducer(name));
        assert_eq!(code, 0, "{name}");
        let force = summary["contact"]["pairs"][0]["normal_force"]
            .as_f64()
            .unwrap();
        assert!((force - 4.0).abs() < 1e-12, "{name}: normal force {force}");
    }
    // W01c: no contact pair, path [0.5, 2.0] over two steps: the reaction is 2 (was 1); the
    // same with one step and path [2.0], and with three steps ending at 2
    let mut case = reproducer("W01c");
    for (steps, path) in [
        (2, vec![0.5, 2.0]),
        (1, vec![2.0]),
        (3, vec![1.0, 0.0, 2.0]),
    ] {
        case["solver"]["load_steps"] = steps.into();
        case["loads"][0]["path"] = path.clone().into();
        let (code, summary) = run_json(&case);
        assert_eq!(code, 0);
        let r = reaction_y(&summary, "bottom");
        assert!((r - 2.0).abs() < 1e-12, "{steps} steps, path {path:?}: {r}");
    }
    // a support's path: the top pulled up by 0.01 with path [3.0] in one step moves it 0.03
    let mut pulled = reproducer("W01c");
    pulled["loads"] = serde_json::json!([]);
    pulled["solver"]["load_steps"] = 1.into();
    pulled["supports"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({"body": "b", "set": "top", "y": 0.01, "path": [3.0]}));
    let (_, summary) = run_json(&pulled);
    let stretched = reaction_y(&summary, "top");
    pulled["supports"][1]["path"] = serde_json::json!(null);
    pulled["supports"][1]["y"] = 0.03.into();
    let (_, summary) = run_json(&pulled);
    let direct = reaction_y(&summary, "top");
    assert!(
        direct.abs() > 1.0 && (stretched - direct).abs() < 1e-12 * direct.abs(),
        "a support's path in one step: {stretched} against {direct}"
    );
    // 3D small strain (elastic): the Hex8 patch under pressure 2 with path [2.0], one step, and
    // [0.5, 2.0], two steps: sigma_zz = -4
    let patch: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/3d/patch-hex8.json"),
        )
        .unwrap(),
    )
    .unwrap();
    for (steps, path) in [(1, vec![2.0]), (2, vec![0.5, 2.0])] {
        let mut case = patch.clone();
        case["solver"] = serde_json::json!({ "load_steps": steps });
        case["loads"][0]["path"] = path.clone().into();
        case["checks"][0]["stress"] = serde_json::json!([0, 0, -4, 0, 0, 0]);
        let (code, summary) = run_json(&case);
        assert_eq!(code, 0, "3D, path {path:?}: {summary}");
        assert_eq!(summary["passed"], true, "3D, path {path:?}");
    }
    // finite strain (one step, no contact): the path's factor applies as in small strain
    let mut finite = reproducer("W01c");
    finite["physics"] = serde_json::json!({ "kinematics": "finite" });
    finite["materials"]["m"]["model"] = "neo_hookean".into();
    finite["solver"]["load_steps"] = 1.into();
    finite["loads"][0]["path"] = serde_json::json!([2.0]);
    let (code, summary) = run_json(&finite);
    assert_eq!(code, 0, "finite: {summary}");
    let on_path = reaction_y(&summary, "bottom");
    finite["loads"][0]["path"] = serde_json::json!(null);
    finite["loads"][0]["pressure"] = 2.0.into();
    let (_, summary) = run_json(&finite);
    let direct = reaction_y(&summary, "bottom");
    assert!(
        direct > 1.9 && (on_path - direct).abs() < 1e-12 * direct,
        "finite strain, path [2.0]: {on_path} against pressure 2: {direct}"
    );
}
