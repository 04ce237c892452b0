//! The active-set loop of the default `"auto"` factor update on a system of at least 20,000
//! equations eliminates the contact rows' equations last and solves every later active set
//! through the factor's trailing block (src/solver/low_rank.rs, `TrailingUpdate`): one sparse
//! factorization for the whole loop. Its answer is the one of the loop that factors every
//! matrix anew (`"refactor"`, AMD order) to round-off: the same active sets, iteration counts
//! and contact forces, displacements equal to 1e-11 of the largest, and the condition estimate
//! of the last matrix.

use contact_patch::io::scene::FactorUpdate;
use contact_patch::model::admit::load;
use contact_patch::solver::linear::Solution;
use contact_patch::solver::solve_static;
use std::path::Path;

fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
    let scale = b
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

/// The cross-check's block on a rigid line (tests/data/block-on-rigid-line-240x40.json, penalty
/// 1e5) refined to 250 x 42 Q4: 21,585 equations, 251 contact rows, about 100 of which change
/// in the first iteration (more than a Woodbury update may take).
#[test]
fn one_factorization_and_trailing_updates_give_the_refactored_answer() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text =
        std::fs::read_to_string(root.join("tests/data/block-on-rigid-line-240x40.json")).unwrap();
    let mut case: serde_json::Value = serde_json::from_str(&text).unwrap();
    let block = &mut case["bodies"][0]["mesh"]["block"];
    block["x"]["divisions"] = 250.into();
    block["y"]["divisions"] = 42.into();
    case["name"] = "block-on-rigid-line-250x42".into();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("block.json");
    std::fs::write(&path, serde_json::to_string(&case).unwrap()).unwrap();
    let model = load(&path).unwrap();
    assert_eq!(model.dof_count, 2 * 251 * 43);
    assert_eq!(model.solver.factor_update, FactorUpdate::Auto);
    let solve = |mode| -> Solution {
        let mut m = model.clone();
        m.solver.factor_update = mode;
        solve_static(&m, &mut |_| {}).unwrap()
    };
    let auto = solve(FactorUpdate::Auto);
    let refactored = solve(FactorUpdate::Refactor);
    let (ca, cr) = (
        auto.contact.as_ref().unwrap(),
        refactored.contact.as_ref().unwrap(),
    );
    let solvers: Vec<&str> = ca.history.iter().map(|r| r.linear_solver).collect();
    let changes: Vec<usize> = ca.history.iter().map(|r| r.status_changes).collect();
    eprintln!("status changes {changes:?}, solvers {solvers:?}");
    assert!(
        changes[0] > 64,
        "first set changes only {} rows",
        changes[0]
    );
    assert_eq!(solvers[0], "cholesky");
    assert!(
        solvers[1..]
            .iter()
            .all(|s| *s == "cholesky-trailing-update"),
        "{solvers:?}"
    );
    assert!(solvers.len() >= 3, "{solvers:?}");
    assert_eq!(ca.termination, cr.termination);
    assert_eq!(ca.iterations, cr.iterations);
    assert_eq!(ca.active, cr.active);
    let du = relative_difference(&auto.u, &refactored.u);
    let df = relative_difference(&ca.forces, &cr.forces);
    eprintln!("displacements differ by {du:.2e}, forces by {df:.2e}");
    assert!(du <= 1e-11, "displacements differ by {du:.2e}");
    assert!(df <= 1e-10, "contact forces differ by {df:.2e}");
    assert!(
        auto.relative_residual <= 1e-12,
        "{:.2e}",
        auto.relative_residual
    );
    let last = |s: &Solution| {
        s.contact
            .as_ref()
            .unwrap()
            .history
            .last()
            .unwrap()
            .condition_estimate
    };
    let (a, b) = (last(&auto).unwrap(), last(&refactored).unwrap());
    assert!(
        (a - b).abs() <= 1e-6 * b,
        "condition estimates {a:.6e} and {b:.6e}"
    );
}
