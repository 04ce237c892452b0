//! Concentrated forces (`loads[].force` at every node of a node set): a block under the nodal
//! forces that are consistent with a uniform pressure (for Q4, `p h / 2` at the end nodes of a
//! side and `p h` inside) must deform exactly as under the pressure itself; a force load without
//! a node set, on a set that does not exist, or not finite, is refused with the reason.

use contact_patch::model::{parse, Model};
use contact_patch::run::{run_model, Outcome};
use serde_json::{json, Value};

fn block(loads: Value) -> Value {
    let mut sets = serde_json::Map::new();
    for (k, x) in [0.0, 0.5, 1.0, 1.5, 2.0].iter().enumerate() {
        sets.insert(format!("top{k}"), json!({"point": [x, 1.0]}));
    }
    json!({
        "name": "block",
        "materials": {"steel": {"E": 1000.0, "nu": 0.3}},
        "bodies": [{"name": "b", "material": "steel",
            "mesh": {"block": {"element": "Q4", "x": [0, 0.5, 1, 1.5, 2], "y": [0, 0.5, 1]}},
            "node_sets": sets}],
        "supports": [{"body": "b", "set": "bottom", "y": 0.0},
                     {"body": "b", "set": "bottom_left", "x": 0.0}],
        "loads": loads,
        "checks": [{"check": "uniform_stress", "stress": [0.0, -3.0, 0.0], "tol": 1e-12}]
    })
}

fn solve(v: &Value) -> contact_patch::Result<Outcome> {
    let model = Model::build(&parse(&v.to_string(), "block")?, "block")?;
    run_model(model, 0.0, std::time::Instant::now(), &mut |_| {})
}

#[test]
fn nodal_forces_consistent_with_a_pressure_give_its_exact_uniform_stress() {
    let p = 3.0;
    let h = 0.5;
    let pressure = solve(&block(json!([{"body": "b", "set": "top", "pressure": p}]))).unwrap();
    let forces: Vec<Value> = (0..5)
        .map(|k| {
            let share = if k == 0 || k == 4 { h / 2.0 } else { h };
            json!({"body": "b", "set": format!("top{k}"), "force": [0.0, -p * share]})
        })
        .collect();
    let point = solve(&block(Value::Array(forces))).unwrap();
    assert!(pressure.passed() && point.passed(), "{:?}", point.checks);
    let scale = pressure
        .solution
        .u
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = pressure
        .solution
        .u
        .iter()
        .zip(&point.solution.u)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(diff <= 1e-13 * scale, "{}", diff / scale);
    // a force on one node only is not uniform: the check fails
    let one = solve(&block(
        json!([{"body": "b", "set": "top2", "force": [0.0, -6.0]}]),
    ))
    .unwrap();
    assert!(!one.passed());
}

#[test]
fn bad_force_loads_are_refused_with_the_reason() {
    for (load, expect) in [
        (
            json!({"body": "b", "force": [0.0, -1.0]}),
            "needs a node \"set\"",
        ),
        (
            json!({"body": "b", "set": "nowhere", "force": [0.0, -1.0]}),
            "nowhere",
        ),
        (
            json!({"body": "b", "set": "top0", "force": [0.0, -1.0], "pressure": 1.0}),
            "exactly one of",
        ),
    ] {
        let msg = solve(&block(json!([load]))).err().unwrap().to_string();
        assert!(msg.contains(expect), "{msg}");
        assert!(msg.contains("loads[0]"), "{msg}");
    }
    // a non-finite force cannot be written in JSON; an overflowing one parses as infinite
    let text = block(json!([{"body": "b", "set": "top0", "force": [0.0, -1.0]}]))
        .to_string()
        .replace("-1.0]", "-1e999]");
    let err = parse(&text, "block")
        .and_then(|c| Model::build(&c, "block"))
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("finite") || err.contains("number"), "{err}");
}
