//! 3D contact through the one (dimension-free) active-set solve: the contact patch test of a
//! punch pressed on a foundation of the same footprint (uniform `sigma_zz = -p` is exact),
//! with matching and non-matching interfaces, and a block pressed on a rigid plane.
//! Mortar (segment-based, standard and dual) passes on non-matching grids, as the seed's
//! 2D table says; node-to-surface one pass does not, two passes do.

use contact_patch::run::run_case3;
use contact_patch::run3d::Outcome3;
use serde_json::{json, Value};

const PRESSURE: f64 = 10.0;

/// The patch case: foundation [0, 2]^2 x [0, 1] on breaks `foundation` (x and y), punch
/// [0, 2]^2 x [1, 2] on breaks `punch`, pressure on the punch's top, supports that hold the
/// rigid motions without restraining the uniform strain.
fn patch(element: &str, foundation: &[f64], punch: &[f64], contact: Value) -> Value {
    patch_of([element, element], foundation, punch, contact)
}

/// [`patch`] with the foundation's and the punch's elements (in that order).
fn patch_of(elements: [&str; 2], foundation: &[f64], punch: &[f64], contact: Value) -> Value {
    json!({
        "name": "patch-3d",
        "materials": {"m": {"E": 1000.0, "nu": 0.3}},
        "bodies": [
            {"name": "foundation", "material": "m", "mesh": {"block3d": {"element": elements[0],
                "x": foundation, "y": foundation, "z": [0, 0.5, 1]}}},
            {"name": "punch", "material": "m", "mesh": {"block3d": {"element": elements[1],
                "x": punch, "y": punch, "z": [1, 1.5, 2]}}}
        ],
        "supports": [
            {"body": "foundation", "set": "bottom", "z": 0.0},
            {"body": "foundation", "set": "bottom_front_left", "x": 0.0, "y": 0.0},
            {"body": "foundation", "set": "bottom_front_right", "y": 0.0},
            {"body": "punch", "set": "top_front_left", "x": 0.0, "y": 0.0},
            {"body": "punch", "set": "top_front_right", "y": 0.0}
        ],
        "loads": [{"body": "punch", "set": "top", "pressure": PRESSURE}],
        "contact": [contact],
        "checks": [{"check": "uniform_stress_3d", "stress": [0, 0, -PRESSURE, 0, 0, 0], "tol": 1e-10}]
    })
}

fn pair(discretization: Value, enforcement: Value) -> Value {
    json!({"name": "interface", "slave": {"body": "punch", "set": "bottom"},
           "master": {"body": "foundation", "set": "top"},
           "discretization": discretization, "enforcement": enforcement})
}

fn run(case: &Value) -> Outcome3 {
    let parsed = contact_patch::model::parse(&case.to_string(), "contact3").unwrap();
    run_case3(&parsed, "contact3").unwrap_or_else(|e| panic!("{e}"))
}

fn stress_error(o: &Outcome3) -> f64 {
    assert!(
        o.converged(),
        "{:?}",
        o.solution.contact.as_ref().map(|c| &c.termination)
    );
    o.checks[0].error
}

const MATCHING: [f64; 3] = [0.0, 1.0, 2.0];
const NON_MATCHING: [f64; 4] = [0.0, 0.7, 1.4, 2.0];

#[test]
fn matching_interfaces_pass_with_every_node_based_discretization() {
    for (discretization, enforcement) in [
        (
            json!({"kind": "node_to_surface", "passes": 1}),
            json!({"kind": "lagrange"}),
        ),
        (
            json!({"kind": "node_to_surface", "passes": 1}),
            json!({"kind": "penalty", "kappa": 1e4}),
        ),
        (json!({"kind": "node_to_node"}), json!({"kind": "lagrange"})),
        (
            json!({"kind": "node_to_node"}),
            json!({"kind": "elimination"}),
        ),
    ] {
        let o = run(&patch(
            "Hex8",
            &MATCHING,
            &MATCHING,
            pair(discretization.clone(), enforcement.clone()),
        ));
        let e = stress_error(&o);
        assert!(e < 1e-12, "{discretization} {enforcement}: {e:e}");
        // every slave node is closed and carries the pressure times its area
        let state = o.solution.contact.as_ref().unwrap();
        assert!(state.active.iter().all(|&a| a), "{discretization}");
        let total: f64 = state.forces.iter().sum();
        assert!((total - PRESSURE * 4.0).abs() < 1e-10 * PRESSURE, "{total}");
    }
}

#[test]
fn mortar_passes_on_non_matching_interfaces_where_one_pass_node_to_surface_fails() {
    for element in ["Hex8", "Tet4"] {
        for (multiplier, enforcement) in [
            ("standard", json!({"kind": "lagrange"})),
            ("dual", json!({"kind": "lagrange"})),
            ("dual", json!({"kind": "penalty", "kappa": 1e4})),
        ] {
            let c = pair(
                json!({"kind": "mortar", "multiplier": multiplier}),
                enforcement.clone(),
            );
            let e = stress_error(&run(&patch(element, &MATCHING, &NON_MATCHING, c)));
            assert!(e < 1e-12, "{element} {multiplier} {enforcement}: {e:e}");
        }
    }
    let one = pair(
        json!({"kind": "node_to_surface", "passes": 1}),
        json!({"kind": "lagrange"}),
    );
    let e = stress_error(&run(&patch("Hex8", &MATCHING, &NON_MATCHING, one)));
    assert!(
        e > 1e-2,
        "one pass on a non-matching interface is not exact: {e:e}"
    );
    let two = pair(
        json!({"kind": "node_to_surface", "passes": 2}),
        json!({"kind": "lagrange"}),
    );
    let e = stress_error(&run(&patch("Hex8", &MATCHING, &NON_MATCHING, two)));
    assert!(e < 1e-12, "two passes: {e:e}");
}

#[test]
fn mortar_on_tri6_facets_passes_the_patch_test() {
    // Tet10 bodies (Tri6 facets, multipliers on the modified basis) on Tet10 matching and
    // non-matching, on Hex8 and Hex27 foundations, and a Hex8 punch on a Tet10 foundation
    let mut worst = 0.0f64;
    for (elements, punch) in [
        (["Tet10", "Tet10"], &MATCHING[..]),
        (["Tet10", "Tet10"], &NON_MATCHING[..]),
        (["Hex8", "Tet10"], &NON_MATCHING[..]),
        (["Hex27", "Tet10"], &NON_MATCHING[..]),
        (["Tet10", "Hex8"], &NON_MATCHING[..]),
    ] {
        for multiplier in ["standard", "dual"] {
            let c = pair(
                json!({"kind": "mortar", "multiplier": multiplier}),
                json!({"kind": "lagrange"}),
            );
            let e = stress_error(&run(&patch_of(elements, &MATCHING, punch, c)));
            worst = worst.max(e);
            assert!(e < 1e-10, "{elements:?} {punch:?} {multiplier}: {e:e}");
        }
    }
    println!("largest stress error (relative to p): {worst:e}");
}

#[test]
fn a_block_on_a_rigid_plane_carries_the_pressure() {
    let mut case = patch("Hex8", &MATCHING, &NON_MATCHING, json!({}));
    // the punch alone, pressed on the plane z = 1 (the foundation's top)
    case["bodies"] = json!([case["bodies"][1].clone()]);
    case["supports"] = json!([
        {"body": "punch", "set": "top_front_left", "x": 0.0, "y": 0.0},
        {"body": "punch", "set": "top_front_right", "y": 0.0}
    ]);
    for enforcement in [
        json!({"kind": "lagrange"}),
        json!({"kind": "augmented_lagrange", "kappa": 1e4}),
    ] {
        case["contact"] = json!([{"name": "ground", "slave": {"body": "punch", "set": "bottom"},
            "master": {"rigid": {"kind": "plane", "point": [0, 0, 1], "normal": [0, 0, 1]}},
            "discretization": {"kind": "node_to_surface", "passes": 1}, "enforcement": enforcement}]);
        let o = run(&case);
        let e = stress_error(&o);
        assert!(e < 1e-12, "{enforcement}: {e:e}");
        let state = o.solution.contact.as_ref().unwrap();
        let fz: f64 = state
            .rows
            .iter()
            .zip(&state.forces)
            .map(|(r, f)| f * r.normal[2])
            .sum();
        assert!((fz - PRESSURE * 4.0).abs() < 1e-9 * PRESSURE, "{fz}");
    }
}

#[test]
fn a_block_lifted_off_a_rigid_plane_opens_every_row() {
    let mut case = patch("Hex8", &MATCHING, &MATCHING, json!({}));
    case["bodies"] = json!([case["bodies"][1].clone()]);
    case["supports"] = json!([
        {"body": "punch", "set": "top", "x": 0.0, "y": 0.0, "z": 0.01}
    ]);
    case["loads"] = json!([]);
    case["checks"] =
        json!([{"check": "uniform_stress_3d", "stress": [0, 0, 0, 0, 0, 0], "tol": 1e-10}]);
    case["contact"] = json!([{"name": "ground", "slave": {"body": "punch", "set": "bottom"},
        "master": {"rigid": {"kind": "plane", "point": [0, 0, 1], "normal": [0, 0, 1]}},
        "discretization": {"kind": "node_to_surface", "passes": 1}, "enforcement": {"kind": "lagrange"}}]);
    let o = run(&case);
    let state = o.solution.contact.as_ref().unwrap();
    assert!(o.converged());
    assert!(
        state.active.iter().all(|&a| !a),
        "a lifted block touches nothing"
    );
    assert!(o.checks[0].error < 1e-12);
}
