//! A method per pair: two blocks, each on its own rigid line, one pair enforced by penalty and
//! one by the augmented Lagrangian, solved together. The bodies do not interact, so each must
//! come out as its pair's method gives it alone: the penalty block sinks by `p / kappa` with
//! an exact uniform stress, the augmented Lagrangian block closes its gap. In the active-set
//! scheme, methods that need a loop of their own (Lagrange multipliers with penalty) are
//! refused with a reason; the Newton scheme (`solver.scheme: "newton"`) solves Lagrange
//! multiplier pairs and penalty pairs together.

use contact_patch::model::{parse, Model};
use contact_patch::run::{run_model, Outcome};
use serde_json::{json, Value};
use std::path::Path;

fn two_blocks(first: Value, second: Value) -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("cases/contact/signorini-block-on-rigid-line.json");
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let mut block2 = v["bodies"][0].clone();
    block2["name"] = "block2".into();
    block2["mesh"]["block"]["x"] = json!([5, 5.7, 6.5, 7.2, 8]);
    v["bodies"].as_array_mut().unwrap().push(block2);
    v["supports"] = json!([
        {"body": "block", "set": "bottom_left", "x": 0.0},
        {"body": "block2", "set": "bottom_left", "x": 0.0}
    ]);
    v["loads"] = json!([
        {"body": "block", "set": "top", "pressure": 5.0},
        {"body": "block2", "set": "top", "pressure": 5.0}
    ]);
    let mut pair2 = v["contact"][0].clone();
    pair2["name"] = "ground2".into();
    pair2["slave"]["body"] = "block2".into();
    v["contact"][0]["enforcement"] = first;
    pair2["enforcement"] = second;
    v["contact"].as_array_mut().unwrap().push(pair2);
    v["checks"] = json!([{"check": "uniform_stress", "stress": [0.0, -5.0, 0.0], "tol": 1e-10}]);
    v
}

fn solve(v: &Value) -> contact_patch::Result<Outcome> {
    let model = Model::build(&parse(&v.to_string(), "two blocks").unwrap(), "two blocks")?;
    run_model(model, 0.0, std::time::Instant::now(), &mut |_| {})
}

fn penetration(o: &Outcome, pair: usize) -> f64 {
    let state = o.solution.contact.as_ref().unwrap();
    contact_patch::contact::forces::pair_forces(&o.model, state)[pair]
        .penetration
        .depth
}

/// Each block of `mixed` moves as it does when both pairs use its pair's method (`methods[b]`
/// for block `b`), to 1e-12.
fn assert_each_block_as_alone(mixed: &Outcome, methods: [Value; 2]) {
    for (body, both) in methods.into_iter().enumerate() {
        let alone = solve(&two_blocks(both.clone(), both)).unwrap();
        let b = &mixed.model.bodies[body];
        let range = b.dof_offset..b.dof_offset + b.dof_count();
        let scale = alone.solution.u[range.clone()]
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = mixed.solution.u[range.clone()]
            .iter()
            .zip(&alone.solution.u[range])
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(diff <= 1e-12 * scale, "body {body}: {}", diff / scale);
    }
}

#[test]
fn penalty_and_augmented_lagrange_pairs_solve_together() {
    let kappa = 1e4;
    let penalty = json!({"kind": "penalty", "kappa": kappa});
    let augmented = json!({"kind": "augmented_lagrange", "kappa": kappa});
    let mixed = solve(&two_blocks(penalty.clone(), augmented.clone())).unwrap();
    let state = mixed.solution.contact.as_ref().unwrap();
    assert_eq!(
        state.termination,
        contact_patch::solver::active_set::Termination::Converged
    );
    assert!(mixed.passed(), "{:?}", mixed.checks);
    // the penalty pair sinks by p / kappa, the augmented Lagrangian one closes its gap
    let sunk = penetration(&mixed, 0);
    assert!(
        (sunk - 5.0 / kappa).abs() <= 1e-10 * sunk,
        "penalty penetration {sunk}"
    );
    assert!(
        penetration(&mixed, 1) <= 1e-12,
        "{}",
        penetration(&mixed, 1)
    );
    // each block as its method gives it alone
    assert_each_block_as_alone(&mixed, [penalty.clone(), augmented.clone()]);
    // the pairs' methods are the ones reported
    let names: Vec<&str> = mixed
        .model
        .contact
        .iter()
        .map(|p| contact_patch::contact::enforcement::method(&p.enforcement).name())
        .collect();
    assert_eq!(names, ["penalty", "augmented_lagrange"]);
}

#[test]
fn methods_that_need_their_own_loop_are_refused_with_the_reason() {
    let e = solve(&two_blocks(
        json!({"kind": "lagrange"}),
        json!({"kind": "penalty", "kappa": 1e4}),
    ))
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("contact[1] 'ground2'.enforcement") && e.contains("cannot be combined"),
        "{e}"
    );
    // different penalties in one family are fine
    let o = solve(&two_blocks(
        json!({"kind": "perturbed_lagrange", "kappa": 1e3}),
        json!({"kind": "penalty", "kappa": 1e5}),
    ))
    .unwrap();
    assert!(
        (penetration(&o, 0) - 5e-3).abs() <= 1e-12,
        "{}",
        penetration(&o, 0)
    );
    assert!(
        (penetration(&o, 1) - 5e-5).abs() <= 1e-14,
        "{}",
        penetration(&o, 1)
    );
}

#[test]
fn the_newton_scheme_solves_a_lagrange_pair_with_a_penalty_pair() {
    let kappa = 1e4;
    let lagrange = json!({"kind": "lagrange"});
    let penalty = json!({"kind": "penalty", "kappa": kappa});
    let newton = |v: Value| {
        let mut v = v;
        v["solver"] = json!({"scheme": "newton"});
        v
    };
    let mixed = solve(&newton(two_blocks(lagrange.clone(), penalty.clone()))).unwrap();
    let state = mixed.solution.contact.as_ref().unwrap();
    assert_eq!(
        state.termination,
        contact_patch::solver::active_set::Termination::Converged
    );
    assert!(mixed.passed(), "{:?}", mixed.checks);
    assert!(
        penetration(&mixed, 0) <= 1e-12,
        "Lagrange penetration {}",
        penetration(&mixed, 0)
    );
    let sunk = penetration(&mixed, 1);
    assert!(
        (sunk - 5.0 / kappa).abs() <= 1e-10 * sunk,
        "penalty penetration {sunk}"
    );
    // each block as its method gives it alone, in the active-set scheme
    assert_each_block_as_alone(&mixed, [lagrange, penalty]);
    // the linear solver of a saddle-point system with multipliers
    assert_eq!(state.linear_solver, "ldlt");
}
