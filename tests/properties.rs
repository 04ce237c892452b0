//! Property-based tests (proptest), bounded so that they stay within seconds:
//! * any contact scene drawn from a family of hard ones (a Q4 or Q9 block on a rigid line or a
//!   rigid circle, Young's modulus from 1e-3 to 1e12, nu up to 0.4999, every enforcement
//!   method with kappa from 1e-6 to 1e12 times E / h, a gap or an initial penetration, a load
//!   or none) gives a result or one clear error, never a panic; and a converged answer whose
//!   equilibrium is not at round-off is never silent: the run warns, naming the residual;
//! * any case text in which one field is replaced by an arbitrary JSON value is either refused
//!   with an error that names where, or runs; never a panic.

use contact_patch::model::{parse, Model};
use contact_patch::run::run_model;
use proptest::prelude::*;
use serde_json::{json, Value};
use std::time::Instant;

fn enforcement(kind: usize, kappa: f64) -> Value {
    match kind {
        0 => json!({"kind": "lagrange"}),
        1 => json!({"kind": "penalty", "kappa": kappa}),
        2 => json!({"kind": "perturbed_lagrange", "kappa": kappa}),
        3 => json!({"kind": "augmented_lagrange", "kappa": kappa, "update": "per_iteration"}),
        4 => json!({"kind": "augmented_lagrange", "kappa": kappa, "update": "outer_loop"}),
        5 => json!({"kind": "perturbed_tangent", "kappa": kappa}),
        _ => json!({"kind": "elimination"}),
    }
}

#[allow(clippy::too_many_arguments)]
fn scene(
    q9: bool,
    divisions: usize,
    youngs: f64,
    nu: f64,
    method: usize,
    kappa_over_e_h: f64,
    offset: f64,
    pressure: f64,
    circle: bool,
) -> Value {
    let h = 3.0 / divisions as f64;
    let master = if circle {
        json!({"rigid": {"kind": "circle", "centre": [1.5, offset - 20.0], "radius": 20.0}})
    } else {
        json!({"rigid": {"kind": "line", "point": [0.0, offset], "normal": [0.0, 1.0]}})
    };
    json!({
        "name": "property",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": youngs, "nu": nu}},
        "bodies": [{"name": "block", "material": "m", "mesh": {"block": {
            "element": if q9 { "Q9" } else { "Q4" },
            "x": {"from": 0.0, "to": 3.0, "divisions": divisions},
            "y": {"from": 0.0, "to": 2.0, "divisions": divisions}}}}],
        "supports": [{"body": "block", "set": "bottom_left", "x": 0.0}],
        "loads": [{"body": "block", "set": "top", "pressure": pressure * youngs}],
        "contact": [{"name": "ground", "slave": {"body": "block", "set": "bottom"},
            "master": master,
            "discretization": {"kind": "node_to_surface", "passes": 1},
            "enforcement": enforcement(method, kappa_over_e_h * youngs / h)}],
        "checks": [{"check": "force_balance", "tol": 1e-12}]
    })
}

/// Run a scene: `Ok(warnings, residual, converged)` or the error's text.
fn run(v: &Value) -> Result<(Vec<String>, f64, bool), String> {
    let case = parse(&v.to_string(), "property.json").map_err(|e| e.to_string())?;
    let model = Model::build(&case, "property.json").map_err(|e| e.to_string())?;
    let o = run_model(model, 0.0, Instant::now(), &mut |_| {}).map_err(|e| e.to_string())?;
    let converged =
        o.solution.contact.as_ref().is_some_and(|c| {
            c.termination == contact_patch::contact::state::Termination::Converged
        });
    Ok((o.warnings, o.solution.relative_residual, converged))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn hard_scenes_end_in_an_answer_or_one_clear_error(
        q9 in any::<bool>(),
        divisions in 1usize..5,
        log_e in -3.0f64..12.0,
        nu in prop_oneof![Just(0.0), Just(0.3), Just(0.4999), 0.0f64..0.49],
        method in 0usize..7,
        log_kappa in -6.0f64..12.0,
        offset in prop_oneof![Just(0.0), -1e-3f64..1e-3],
        pressure in prop_oneof![Just(0.0), 1e-4f64..1e-2],
        circle in any::<bool>(),
    ) {
        let v = scene(q9, divisions, 10f64.powf(log_e), nu, method, 10f64.powf(log_kappa), offset, pressure, circle);
        let result = std::panic::catch_unwind(|| run(&v));
        prop_assert!(result.is_ok(), "panic on {v}");
        match result.unwrap() {
            Ok((warnings, residual, converged)) => {
                if converged && residual > 1e-12 {
                    prop_assert!(
                        warnings.iter().any(|w| w.contains("equilibrium is not at round-off")),
                        "silent converged answer with residual {residual:e}: {v}"
                    );
                }
            }
            // one error, with a hint
            Err(e) => prop_assert!(e.contains("hint:"), "{e}"),
        }
    }

    #[test]
    fn a_field_replaced_by_any_value_is_refused_clearly_or_runs(
        field in 0usize..8,
        replacement in prop_oneof![
            Just(Value::Null),
            any::<f64>().prop_map(|x| json!(x)),
            any::<i64>().prop_map(|x| json!(x)),
            "[a-z_ ]{0,12}".prop_map(Value::String),
            Just(json!([])),
            Just(json!({})),
            Just(json!([1e308, -1e308])),
        ],
    ) {
        let mut v = scene(false, 2, 1000.0, 0.3, 1, 10.0, 0.0, 1e-3, false);
        let slot = match field {
            0 => &mut v["materials"]["m"]["E"],
            1 => &mut v["materials"]["m"]["nu"],
            2 => &mut v["bodies"][0]["mesh"]["block"]["x"]["divisions"],
            3 => &mut v["contact"][0]["enforcement"]["kappa"],
            4 => &mut v["contact"][0]["master"]["rigid"]["normal"],
            5 => &mut v["loads"][0]["pressure"],
            6 => &mut v["checks"][0]["tol"],
            _ => &mut v["analysis"]["thickness"],
        };
        *slot = replacement;
        let result = std::panic::catch_unwind(|| run(&v));
        prop_assert!(result.is_ok(), "panic on {v}");
        if let Err(e) = result.unwrap() {
            prop_assert!(e.contains("property.json"), "the error does not say where: {e}");
        }
    }
}
