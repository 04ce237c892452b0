//! Load steps (`solver.load_steps`): the load applied in equal steps, each starting from the
//! last one's active set (and, in current geometry, its configuration). Frictionless contact
//! carries no history, so 1 and 10 steps must give the same answer; the steps are recorded.

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
