//! The penalty predictor of the Lagrange active set and the work limit of a contact loop
//! ([`contact_patch::solver::active_set`]).
//!
//! A Q4 block pressed onto a rigid cylinder with Lagrange multipliers
//! (`cases/hard/curved-master-cylinder.json`) starts from the three closest points; the block
//! then penetrates far beyond its contact zone and the next set closes every penetrating row.
//! Without the predictor the loop opened one row at each edge per iteration, so its iterations
//! grew with the mesh (27 at 1000 divisions along the contact, 106 at 5000). With it 16 times
//! the divisions take less than twice the iterations (12 at 100, 21 at 1600), and the loop
//! still ends at the Lagrange answer: the set is stable under the multiplier rule, the
//! cylinder carries the load P = 4 and the last iteration is a Lagrange one. A case whose loop would take more
//! iterations times dofs than `limits.iteration_dofs` stops with `work_limit` naming the limit,
//! and the command exits 1.

use contact_patch::contact::state::Termination;
use contact_patch::run::{run_case, Outcome};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn cylinder_case(divisions: usize) -> Value {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/hard/curved-master-cylinder.json"),
    )
    .unwrap();
    let mut case: Value = serde_json::from_str(&text).unwrap();
    case.as_object_mut().unwrap().remove("$schema");
    case["bodies"][0]["mesh"]["block"]["x"]["divisions"] = divisions.into();
    case
}

fn write(dir: &Path, name: &str, case: &Value) -> PathBuf {
    let file = dir.join(format!("{name}.json"));
    std::fs::write(&file, serde_json::to_string_pretty(case).unwrap()).unwrap();
    file
}

fn run(case: &Value, name: &str) -> Outcome {
    let dir = tempfile::tempdir().unwrap();
    run_case(&write(dir.path(), name, case), &mut |_| {}).unwrap()
}

/// The cylinder's force on the block: the load P = 4 (pressure 0.5 on a top of width 8).
fn slave_force_y(outcome: &Outcome) -> f64 {
    let state = outcome.solution.contact.as_ref().unwrap();
    contact_patch::contact::forces::pair_forces(&outcome.model, state)[0].on_slave[1]
}

#[test]
fn the_lagrange_iterations_do_not_grow_with_the_mesh() {
    let mut iterations = Vec::new();
    for divisions in [100, 1600] {
        let out = run(&cylinder_case(divisions), "cylinder");
        let state = out.solution.contact.as_ref().unwrap();
        assert_eq!(state.termination, Termination::Converged, "{divisions}");
        let history = &state.history;
        // the predictor ran, and the loop ended with a Lagrange solve whose set was stable
        assert!(
            history
                .iter()
                .any(|r| r.linear_solver == "penalty-predictor"),
            "{divisions}"
        );
        let last = history.last().unwrap();
        assert_eq!(last.linear_solver, "ldlt", "{divisions}");
        assert_eq!(last.status_changes, 0, "{divisions}");
        assert_eq!(state.iterations, history.len(), "{divisions}");
        // the contact zone lies within the block's bottom, well inside its half-width 4
        let active = state.active.iter().filter(|&&a| a).count();
        assert!(
            active > 10 && active < divisions / 2,
            "{divisions}: {active}"
        );
        let fy = slave_force_y(&out);
        assert!((fy - 4.0).abs() <= 1e-9 * 4.0, "{divisions}: force {fy}");
        iterations.push(state.iterations);
    }
    // 16 times the rows along the contact: without the predictor the count grew in proportion
    // (one row opened at each edge per iteration: 27 iterations at 1000 divisions, 47 at
    // 2000); with it, 12 at 100 divisions and 21 at 1600 when this was written
    assert!(
        iterations[1] < 2 * iterations[0] && iterations[1] <= 25,
        "iterations {iterations:?}"
    );
}

#[test]
fn the_work_limit_is_a_named_stop_with_a_way_out() {
    let mut case = cylinder_case(200);
    // 4,422 dofs: a limit of 3 iterations' worth
    case["limits"] = serde_json::json!({"iteration_dofs": 3 * 4422});
    let out = run(&case, "cylinder-limited");
    let state = out.solution.contact.as_ref().unwrap();
    assert_eq!(state.iterations, 3);
    let Termination::WorkLimit(msg) = &state.termination else {
        panic!("{:?}", state.termination);
    };
    assert!(msg.contains("after 3 iterations"), "{msg}");
    assert!(msg.contains("limits.iteration_dofs"), "{msg}");
    assert!(msg.contains("\"iteration_dofs\": N"), "{msg}");
    // the command says so and exits 1 (a failed run, not bad input)
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "cylinder-limited", &case);
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .arg("run")
        .arg(&file)
        .arg("--out")
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(1));
    let said = String::from_utf8_lossy(&output.stdout).to_string()
        + &String::from_utf8_lossy(&output.stderr);
    assert!(said.contains("limits.iteration_dofs"), "{said}");
    // without the limit the same case converges
    let out = run(&cylinder_case(200), "cylinder");
    assert_eq!(
        out.solution.contact.as_ref().unwrap().termination,
        Termination::Converged
    );
}

/// Found by the fuzz: `cases/contact/hertz-profile-dual-mortar.json` with its centre support
/// moved by 1e12 (absurd, and linearized contact rows that make no sense there) took 16 s of a
/// fuzz run's 20. The penalty predictor cycled with period 6 through 90 iterations, and the
/// Lagrange loop then ran 93 iterations of the minimum-norm Schur path (dependent rows), each
/// solving once per active row. Now a predictor level whose set comes back ends there, and the
/// Schur path's solves count against `limits.iteration_dofs`: the run stops with `work_limit`
/// after about 460 solves of 11,000 dofs (about 3 s, where it took 16 s).
#[test]
fn a_cycling_predictor_and_the_schur_path_stop_at_the_work_limit() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/contact/hertz-profile-dual-mortar.json"),
    )
    .unwrap();
    let mut case: Value = serde_json::from_str(&text).unwrap();
    case.as_object_mut().unwrap().remove("$schema");
    case["supports"][0]["x"] = 1e12.into();
    let o = run(&case, "moved-support");
    let contact = o.solution.contact.as_ref().unwrap();
    let Termination::WorkLimit(why) = &contact.termination else {
        panic!("{:?}", contact.termination);
    };
    assert!(
        why.contains("solves") && why.contains("limits.iteration_dofs"),
        "{why}"
    );
    let predictor = contact
        .history
        .iter()
        .filter(|h| h.linear_solver == "penalty-predictor")
        .count();
    let schur = contact
        .history
        .iter()
        .filter(|h| h.linear_solver == "schur-pseudo-inverse")
        .count();
    // before: 90 predictor iterations and 93 Schur iterations
    assert!(predictor < 60, "{predictor} predictor iterations");
    assert!(schur < 30, "{schur} Schur iterations");
}
