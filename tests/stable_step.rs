//! Time steps and energy of hard impacts ([`contact_patch::model::stable_step`],
//! [`contact_patch::harness::stability::energy_growth`]):
//!
//! * the element bound of the largest frequency is exact for one free dof (`omega = sqrt(k /
//!   m)`, the single-dof oscillator of tests/dynamics.rs) and, for the bar of
//!   `cases/dynamics`, at least the 1D bar's `2 c / h` (an upper bound);
//! * central difference above its limit `omega dt <= 2` is refused before the run, naming the
//!   field, where it blew up to an energy of 1e267 with exit 0 before;
//! * a high-speed impact with a moderate penalty keeps its total energy within a tenth of the
//!   initial kinetic energy, a stiff one gains energy and the run warns.

use contact_patch::harness::stability::energy_growth;
use contact_patch::model::stable_step::largest_frequency_bound;
use contact_patch::model::{parse, Model};
use contact_patch::run::run_case;
use serde_json::{json, Value};
use std::path::Path;

fn read(case: &str) -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(case);
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn run_value(v: &Value) -> contact_patch::error::Result<contact_patch::run::Outcome> {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("case.json");
    std::fs::write(&file, v.to_string()).unwrap();
    run_case(&file, &mut |_| {})
}

fn refusal(v: &Value) -> String {
    match run_value(v) {
        Ok(_) => panic!("the case was accepted"),
        Err(e) => e.to_string(),
    }
}

/// One Q4 unit square, every dof supported but `u_x` of its top-right node (tests/dynamics.rs).
fn oscillator(dt: f64) -> Value {
    json!({
        "name": "oscillator",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": 100.0, "nu": 0.25, "density": 2.0}},
        "bodies": [{"name": "square", "material": "m", "mesh": {"block": {"element": "Q4",
            "x": {"from": 0.0, "to": 1.0, "divisions": 1},
            "y": {"from": 0.0, "to": 1.0, "divisions": 1}}}}],
        "supports": [
            {"body": "square", "set": "all", "y": 0.0},
            {"body": "square", "set": "left", "x": 0.0},
            {"body": "square", "set": "bottom_right", "x": 0.0}
        ],
        "physics": {"dynamics": {"integrator": "central_difference", "dt": dt, "end_time": dt * 20.0,
            "mass": "lumped",
            "initial_velocity": [{"body": "square", "set": "top_right", "velocity": [0.3, 0.0]}]}}
    })
}

fn model_of(v: &Value) -> Model {
    Model::build(&parse(&v.to_string(), "case").unwrap(), "case").unwrap()
}

#[test]
fn the_element_bound_is_exact_for_one_free_dof_and_bounds_the_bar() {
    // the oscillator: k = K_ii of the free dof, m = rho t A / 4 (HRZ)
    let model = model_of(&oscillator(0.01));
    let mut ke = [0.0; 64];
    let kind = contact_patch::fe::ElementKind::Q4;
    contact_patch::solid::element_stiffness(
        kind,
        &[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
        &model.bodies[0].material,
        1.0,
        &kind.stiffness_rule(),
        &mut ke,
    );
    let w = (ke[4 * 8 + 4] / 0.5).sqrt();
    let bound = largest_frequency_bound(&model, &[2.0]).unwrap();
    assert!(
        (bound.omega - w).abs() <= 1e-12 * w,
        "{} vs {w}",
        bound.omega
    );
    // the bar: E = 100, rho = 1, h = 0.05: the 1D bar's highest frequency 2 c / h = 400
    let bar = model_of(&read("cases/dynamics/bar-on-rigid-wall.json"));
    let bound = largest_frequency_bound(&bar, &[1.0]).unwrap();
    assert!(bound.omega >= 400.0 * (1.0 - 1e-12), "{}", bound.omega);
}

#[test]
fn central_difference_above_its_limit_is_refused_and_below_it_runs() {
    let model = model_of(&oscillator(0.01));
    let w = largest_frequency_bound(&model, &[2.0]).unwrap().omega;
    let refused = refusal(&oscillator(2.05 / w));
    assert!(refused.contains("physics.dynamics.dt"), "{refused}");
    assert!(refused.contains("above the stability limit"), "{refused}");
    assert!(run_value(&oscillator(1.95 / w)).is_ok());
    // the bar with a penalty wall, dt ten times the bar's limit h / c = 0.005
    let mut bar = read("cases/dynamics/bar-on-rigid-wall.json");
    bar["physics"]["dynamics"]["integrator"] = json!("central_difference");
    bar["physics"]["dynamics"]["dt"] = json!(0.05);
    bar["physics"]["dynamics"]["end_time"] = json!(10.0);
    bar["contact"][0]["enforcement"] = json!({"kind": "penalty", "kappa": 1e4});
    let refused = refusal(&bar);
    assert!(refused.contains("penalty contact rows"), "{refused}");
}

#[test]
fn a_high_speed_impact_keeps_its_energy_with_a_moderate_penalty_and_warns_with_a_stiff_one() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/hard");
    let soft = run_case(&dir.join("impact-high-speed-penalty-1e4.json"), &mut |_| {}).unwrap();
    let h = soft.solution.dynamics.as_ref().unwrap();
    let initial = h.steps[0].total;
    // the bar's initial kinetic energy m v^2 / 2 = 0.1 * 1 / 2
    assert!((initial - 0.05).abs() <= 1e-12);
    let most = h.steps.iter().map(|s| s.total).fold(f64::MIN, f64::max);
    assert!(most <= 1.1 * initial, "{most}");
    assert!(energy_growth(&soft.model, &soft.solution).is_none());
    let stiff = run_case(&dir.join("impact-high-speed-penalty-1e6.json"), &mut |_| {}).unwrap();
    let warning = energy_growth(&stiff.model, &stiff.solution).expect("a warning");
    assert!(warning.contains("contact_stabilized"), "{warning}");
}

/// Defect W06 (second report): the bar on a rigid wall with `impact: "contact_stabilized"`.
/// With a penalty (kappa = E / h) its total energy rose to 1.086 E0 during contact, without a
/// word, while the docs said the method never gains energy; and every contact-stabilized run
/// warned that equilibrium was not at round-off (relative residual 0.03 to 0.95), because the
/// final check applied `K d_{n+1} + M a = f + B^T lambda`, which the method's mean acceleration
/// and mean contact force do not satisfy (it holds at the mean displacement). Now the
/// residual is the method's own equation, at round-off for both, and the penalty run warns
/// that the energy bound needs exact constraints; the Lagrange control (W06b) gains nothing.
#[test]
fn contact_stabilized_newmark_is_judged_by_its_own_equation_and_names_an_inexact_constraint() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/defects/s4");
    let penalty = run_case(
        &dir.join("W06a-contact-stabilized-penalty-energy-gain.json"),
        &mut |_| {},
    )
    .unwrap();
    let lagrange = run_case(
        &dir.join("W06b-contact-stabilized-lagrange-control.json"),
        &mut |_| {},
    )
    .unwrap();
    for (name, o) in [("penalty", &penalty), ("lagrange", &lagrange)] {
        assert!(
            o.solution.relative_residual < 1e-12,
            "{name}: relative residual {}",
            o.solution.relative_residual
        );
        assert!(
            !o.warnings
                .iter()
                .any(|w| w.contains("equilibrium is not at round-off")),
            "{name}: {:?}",
            o.warnings
        );
    }
    let growth = |o: &contact_patch::run::Outcome| {
        let h = o.solution.dynamics.as_ref().unwrap();
        let most = h.steps.iter().map(|s| s.total).fold(f64::MIN, f64::max);
        most / h.steps[0].total - 1.0
    };
    assert!(growth(&lagrange).abs() < 1e-12, "{}", growth(&lagrange));
    assert!(energy_growth(&lagrange.model, &lagrange.solution).is_none());
    assert!(growth(&penalty) > 0.05, "{}", growth(&penalty));
    let warning = energy_growth(&penalty.model, &penalty.solution).expect("a warning");
    assert!(
        warning.contains("pair(s) 'wall' are enforced inexactly")
            && warning.contains("Lagrange multipliers"),
        "{warning}"
    );
    assert!(
        penalty.warnings.contains(&warning),
        "{:?}",
        penalty.warnings
    );
}
