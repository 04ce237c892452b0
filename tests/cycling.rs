//! Active-set cycling and its remedy (`solver.cycling_remedy`, [`contact_patch::solver::active_set`]):
//! a shifted punch on a penalty interface in the current geometry, whose node at (4.5, 5) ends
//! at zero gap and zero force, cycles between two active sets. With the remedy the loop
//! converges to an answer that carries the punch's load (a closed form of the slave body's
//! equilibrium: the load 20); with the remedy off it stops with `active_set_cycling` naming
//! the node. And a Newton solve with Lagrange multipliers on a rigid circle in the current
//! geometry, whose row gains a gradient component as the normal turns, assembles its
//! multiplier's new entries instead of panicking.

use contact_patch::contact::state::Termination;
use contact_patch::run::run_case;
use std::path::{Path, PathBuf};

fn hard(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("cases/hard/{name}.json"))
}

fn slave_force_y(outcome: &contact_patch::run::Outcome) -> f64 {
    let state = outcome.solution.contact.as_ref().unwrap();
    // the y force on the slave body: each active row's force times its gradient's y terms on
    // the slave node, summed (B^T lambda on the slave's dofs)
    let forces = contact_patch::contact::forces::pair_forces(&outcome.model, state);
    forces[0].on_slave[1]
}

#[test]
fn the_hold_remedy_converges_where_the_set_cycled() {
    let out = run_case(&hard("active-set-cycling-remedy"), &mut |_| {}).unwrap();
    let state = out.solution.contact.as_ref().unwrap();
    assert_eq!(state.termination, Termination::Converged);
    // the cycle was seen once, then the remedy held the node
    assert_eq!(state.history.iter().filter(|r| r.repeated_set).count(), 1);
    assert!(state.history.iter().any(|r| r.cycling_remedy));
    let fy = slave_force_y(&out);
    assert!((fy - 20.0).abs() <= 1e-10 * 20.0, "force {fy}");
    assert!(out.solution.relative_residual <= 1e-12);
    let c = contact_patch::harness::stability::conditioning(&out.model, &out.solution);
    assert_eq!(c.repeated_active_sets, 1);
    assert!(c.cycling_remedy_iterations >= 1);
}

#[test]
fn with_the_remedy_off_the_cycle_is_a_named_stop() {
    let out = run_case(&hard("active-set-cycling-remedy-off"), &mut |_| {}).unwrap();
    let state = out.solution.contact.as_ref().unwrap();
    let Termination::ActiveSetCycling(msg) = &state.termination else {
        panic!("{:?}", state.termination);
    };
    assert!(
        msg.contains("(4.500000, 5.000000) of contact 'interface'"),
        "{msg}"
    );
    assert!(msg.contains("solver.cycling_remedy"), "{msg}");
    assert_eq!(state.iterations, 2);
    assert!(state.history.last().unwrap().repeated_set);
}

#[test]
fn a_newton_lagrange_row_on_a_rigid_circle_gains_its_coupling() {
    let dir = tempfile::tempdir().unwrap();
    let mut case: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("tests/defects/D22-coarse-cylinder-active-set-cycling.json"),
        )
        .unwrap(),
    )
    .unwrap();
    case["checks"] = serde_json::json!([]);
    case["solver"] = serde_json::json!({"scheme": "newton"});
    case["physics"] = serde_json::json!({"contact_geometry": "current"});
    let block = &mut case["bodies"][0];
    block["mesh"]["block"]["x"]["divisions"] = 4.into();
    block["mesh"]["block"]["y"]["divisions"] = 2.into();
    block["node_sets"]["bottom_left_corner"] = serde_json::json!({"point": [-4, 0]});
    case["supports"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({"body": "block", "set": "bottom_left_corner", "x": 0.0}));
    let file = dir.path().join("newton-circle.json");
    std::fs::write(&file, serde_json::to_string(&case).unwrap()).unwrap();
    let out = run_case(&file, &mut |_| {}).unwrap();
    let state = out.solution.contact.as_ref().unwrap();
    assert_eq!(state.termination, Termination::Converged);
    // the cylinder carries the load P = 4 (pressure 0.5 on a top of width 8)
    let fy = slave_force_y(&out);
    assert!((fy - 4.0).abs() <= 1e-10 * 4.0, "force {fy}");
}
