//! The active-set loop with low-rank (Woodbury) updates of the last factorization
//! (`solver.factor_update: "low_rank"`, src/solver/low_rank.rs) gives the answer of the loop
//! that factors every matrix anew (`"refactor"`) to round-off: the same active sets, iteration
//! counts and contact forces, displacements equal to 1e-11 of the largest, and the condition
//! estimate of the last matrix. Checked on every penalty-family contact case of the catalogue
//! and the cross-check, on a block whose first iterations change more rows than an update may
//! (so the loop falls back to factoring and then updates again), and on the default `"auto"`
//! mode, which below 20,000 equations must stay bit-identical to refactoring.

use contact_patch::io::scene::FactorUpdate;
use contact_patch::model::admit::load;
use contact_patch::model::Model;
use contact_patch::solver::linear::Solution;
use contact_patch::solver::solve_static;
use std::path::Path;

fn case(name: &str) -> Model {
    load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(name)).unwrap()
}

fn solve(model: &Model, mode: FactorUpdate) -> Solution {
    let mut model = model.clone();
    model.solver.factor_update = mode;
    solve_static(&model, &mut |_| {}).unwrap()
}

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

/// Compares the two modes; returns how many iterations used an update.
fn same_answer(name: &str, model: &Model) -> usize {
    let updated = solve(model, FactorUpdate::LowRank);
    let refactored = solve(model, FactorUpdate::Refactor);
    let (cu, cr) = (
        updated.contact.as_ref().unwrap(),
        refactored.contact.as_ref().unwrap(),
    );
    assert_eq!(cu.termination, cr.termination, "{name}: termination");
    assert_eq!(cu.iterations, cr.iterations, "{name}: iterations");
    assert_eq!(cu.active, cr.active, "{name}: active set");
    let du = relative_difference(&updated.u, &refactored.u);
    eprintln!("{name}: displacements differ by {du:.2e}");
    assert!(du <= 1e-11, "{name}: displacements differ by {du:.2e}");
    let df = relative_difference(&cu.forces, &cr.forces);
    assert!(df <= 1e-10, "{name}: contact forces differ by {df:.2e}");
    assert!(
        updated.relative_residual <= 1e-12,
        "{name}: residual {:.2e}",
        updated.relative_residual
    );
    let last = |s: &Solution| {
        s.contact
            .as_ref()
            .unwrap()
            .history
            .last()
            .and_then(|r| r.condition_estimate)
    };
    match (last(&updated), last(&refactored)) {
        (Some(a), Some(b)) => assert!(
            (a - b).abs() <= 1e-6 * b,
            "{name}: condition estimates {a:.6e} and {b:.6e}"
        ),
        (a, b) => assert_eq!(a.is_some(), b.is_some(), "{name}: condition estimate"),
    }
    cu.history
        .iter()
        .filter(|r| r.linear_solver == "cholesky-low-rank-update")
        .count()
}

/// Every contact case of the catalogue and the cross-check whose pairs use a method of the
/// penalty family (penalty, perturbed Lagrangian, augmented Lagrangian, perturbed tangent),
/// and the Lagrange and elimination cases, whose penalty predictor is updated too.
#[test]
fn the_update_gives_the_refactored_answer_on_the_contact_cases() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut names = Vec::new();
    for dir in ["cases/contact", "crosscheck/cases/contact", "cases/patch"] {
        for entry in std::fs::read_dir(root.join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "json") {
                names.push(path.strip_prefix(root).unwrap().to_path_buf());
            }
        }
    }
    names.sort();
    let mut solved = 0;
    let mut updates = 0;
    for name in &names {
        let Ok(model) = load(&root.join(name)) else {
            continue;
        };
        if model.contact.is_empty()
            || model.solver.scheme != contact_patch::io::scene::Scheme::ActiveSet
            || model.physics.kinematics == contact_patch::io::scene::Kinematics::Finite
        {
            continue;
        }
        // the refactoring loop must solve it (a case may be meant to fail)
        let mut reference = model.clone();
        reference.solver.factor_update = FactorUpdate::Refactor;
        if solve_static(&reference, &mut |_| {}).is_err() {
            continue;
        }
        updates += same_answer(&name.display().to_string(), &model);
        solved += 1;
    }
    eprintln!("{solved} cases, {updates} iterations solved with a low-rank update");
    assert!(solved >= 20, "only {solved} cases solved");
    assert!(updates > 0, "no iteration used an update");
}

/// The cross-check's block on a rigid line refined to 240 x 40 Q4 (19,762 dofs) with a penalty
/// of 1e5 (`tests/data/block-on-rigid-line-240x40.json`): its first iterations change more rows
/// than an update may take (64), so the loop factors, and then updates while few rows change;
/// the answer is the refactored one.
#[test]
fn many_changed_rows_fall_back_to_a_factorization() {
    let model = case("tests/data/block-on-rigid-line-240x40.json");
    assert_eq!(model.dof_count, 2 * 241 * 41);
    let updated = solve(&model, FactorUpdate::LowRank);
    let history = &updated.contact.as_ref().unwrap().history;
    let changes: Vec<usize> = history.iter().map(|r| r.status_changes).collect();
    let solvers: Vec<&str> = history.iter().map(|r| r.linear_solver).collect();
    eprintln!("status changes {changes:?}, solvers {solvers:?}");
    assert!(
        changes[0] > 64,
        "the first set changes {} rows, not more than an update may take",
        changes[0]
    );
    assert_eq!(solvers[1], "cholesky", "iteration 2 must refactor");
    assert!(solvers.contains(&"cholesky-low-rank-update"));
    same_answer("block 240 x 40", &model);
}

/// Below 20,000 equations the default mode factors every matrix: bit-identical to refactoring.
#[test]
fn the_default_mode_is_bit_identical_on_small_systems() {
    let model = case("crosscheck/cases/contact/signorini-flat-penalty-q4.json");
    assert_eq!(model.solver.factor_update, FactorUpdate::Auto);
    let auto = solve(&model, FactorUpdate::Auto);
    let refactored = solve(&model, FactorUpdate::Refactor);
    assert_eq!(auto.u, refactored.u);
    let (a, r) = (
        auto.contact.as_ref().unwrap(),
        refactored.contact.as_ref().unwrap(),
    );
    assert_eq!(a.forces, r.forces);
    let estimates = |s: &[contact_patch::solver::active_set::IterationRecord]| {
        s.iter().map(|r| r.condition_estimate).collect::<Vec<_>>()
    };
    assert_eq!(estimates(&a.history), estimates(&r.history));
}
