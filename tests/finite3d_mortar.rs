//! Node-to-node and mortar contact between two deformable 3D bodies at finite strain (total
//! Lagrangian neo-Hookean Hex8 blocks, frictionless, the rows searched afresh in the current
//! configuration at every Newton iterate, each row's gap with its exact gradient and Hessian:
//! `contact::discretization::nodal_normal3` and `mortar3_linearization`).
//!
//! References, each independent of the rows' code: central differences of the whole Newton
//! residual (the tangent); the homogeneous uniaxial state of the two-block patch test (closed
//! form, `sigma_xx = 0`); the rotated problem (objectivity: `u_R = R u`); translation and
//! rotation invariance of the gap (linear and angular momentum of the rows); the small-strain
//! mortar rows of `mortar3` at the reference configuration.

use contact_patch::model::Model3;
use contact_patch::run::run_case3;
use contact_patch::run3d::{build3, Outcome3};
use contact_patch::solid::lame;
use contact_patch::solver::linear::Solution;
use nalgebra::{Matrix3, Vector3};
use serde_json::{json, Value};

mod finite_common;
use finite_common::{lateral_stretch, rotation, to_matrix, E, NU};

fn parse(case: &Value) -> contact_patch::io::scene::Case {
    contact_patch::model::parse(&case.to_string(), "finite3d_mortar").unwrap()
}

fn run(case: &Value) -> Outcome3 {
    run_case3(&parse(case), "finite3d_mortar").unwrap_or_else(|e| panic!("{e}"))
}

/// The residual history `step:residual`.
fn residuals(solution: &Solution<3>) -> Vec<String> {
    let finite = solution.finite.as_ref().unwrap();
    finite
        .history
        .iter()
        .map(|h| format!("{}:{:.1e}", h.step, h.residual))
        .collect()
}

/// A base block `[0, 1]^2 x [0, 1]` (Hex8 on breaks `base` in x and y) and a punch
/// `[0, 1]^2 x [1, 2]` on breaks `punch`, neo-Hookean; the base's bottom held in z (x and y at
/// two corners), the punch's top moved down by `press` (held in x and y at two corners, where
/// the homogeneous state does not move them); the punch's bottom (slave) against the base's
/// top (master) with `discretization` and `enforcement`, in `steps` load steps.
fn stacked(
    base: &[f64],
    punch: &[f64],
    discretization: Value,
    enforcement: Value,
    press: f64,
    steps: usize,
) -> Value {
    json!({
        "name": "stacked-3d",
        "materials": {"rubber": {"E": E, "nu": NU, "model": "neo_hookean"}},
        "bodies": [
            {"name": "base", "material": "rubber", "mesh": {"block3d": {
                "element": "Hex8", "x": base, "y": base, "z": [0, 0.5, 1]}}},
            {"name": "punch", "material": "rubber", "mesh": {"block3d": {
                "element": "Hex8", "x": punch, "y": punch, "z": [1, 1.5, 2]}}}
        ],
        "physics": {"kinematics": "finite", "contact_geometry": "current"},
        "solver": {"scheme": "newton", "load_steps": steps},
        "supports": [
            {"body": "base", "set": "bottom", "z": 0.0},
            {"body": "base", "set": "bottom_front_left", "x": 0.0, "y": 0.0},
            {"body": "base", "set": "bottom_front_right", "y": 0.0},
            {"body": "punch", "set": "top", "z": press},
            {"body": "punch", "set": "top_front_left", "x": 0.0, "y": 0.0},
            {"body": "punch", "set": "top_front_right", "y": 0.0}
        ],
        "contact": [{
            "name": "interface", "slave": {"body": "punch", "set": "bottom"},
            "master": {"body": "base", "set": "top"},
            "discretization": discretization,
            "enforcement": enforcement
        }]
    })
}

const MATCHING: [f64; 3] = [0.0, 0.5, 1.0];
/// The punch's nodes off the base's (a non-matching interface; no slave node on a master
/// node or edge).
const OFFSET: [f64; 4] = [0.0, 0.3, 0.7, 1.0];

fn node_to_node() -> Value {
    json!({"kind": "node_to_node"})
}

/// The Cauchy stress at every stiffness quadrature point of every body.
fn all_stresses(o: &Outcome3) -> Vec<[f64; 6]> {
    o.model
        .bodies
        .iter()
        .flat_map(|b| contact_patch::run3d::body_stresses(b, &o.solution.u))
        .map(|(_, s)| s)
        .collect()
}

/// The largest difference of the stresses from `expected`, relative to its largest component.
fn stress_error(stresses: &[[f64; 6]], expected: &[f64; 6]) -> f64 {
    let scale = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    stresses
        .iter()
        .flat_map(|s| (0..6).map(move |i| (s[i] - expected[i]).abs()))
        .fold(0.0, f64::max)
        / scale
}

/// The uniaxial Cauchy stress of the blocks compressed by 20 %: `[0, 0, sigma_zz, 0, 0, 0]`.
fn uniaxial_stress() -> [f64; 6] {
    let (_, mu) = lame(E, NU);
    let b = lateral_stretch(0.8);
    [0.0, 0.0, mu * (0.64 - b * b) / (0.8 * b * b), 0.0, 0.0, 0.0]
}

/// The two-block contact patch test with `discretization` on `punch` breaks: both blocks
/// compressed by 20 % (4 load steps, Lagrange multipliers), the stress of every quadrature
/// point of both bodies against the uniaxial closed form; returns the relative error.
fn patch_test(discretization: Value, punch: &[f64], label: &str) -> f64 {
    let expected = uniaxial_stress();
    let o = run(&stacked(
        &MATCHING,
        punch,
        discretization,
        json!({"kind": "lagrange"}),
        -0.4,
        4,
    ));
    assert!(o.converged(), "{label}");
    let error = stress_error(&all_stresses(&o), &expected);
    println!(
        "{label}: stress error {error:.1e} of sigma_zz {:.4}, residuals {:?}",
        expected[2],
        residuals(&o.solution)
    );
    error
}

/// The node-to-node two-block patch test at finite strain (matching Hex8 grids, 20 %
/// compression, Lagrange multipliers): the uniform uniaxial Cauchy stress at every quadrature
/// point of both bodies to 1e-10 of `sigma_zz`.
#[test]
fn node_to_node_passes_the_two_block_patch_test() {
    let error = patch_test(node_to_node(), &MATCHING, "node-to-node matching");
    assert!(error < 1e-10, "{error:e}");
}

/// The state of the tangent checks: the base's top centre node raised by 0.1 (a pyramid: the
/// master normals vary from node to node), the punch's bottom pressed in by `press` (the gaps
/// nonzero, so the normals' variation enters the rows), every node moved off by a wavy field.
fn tangent_state(model: &Model3, press: f64) -> Vec<f64> {
    let mut u = vec![0.0; model.dof_count];
    for (b, body) in model.bodies.iter().enumerate() {
        for (n, p) in body.mesh.nodes.iter().enumerate() {
            let k = (b * 1000 + n) as f64;
            let mut shift = [
                1e-3 * (1.3 * k).sin(),
                1e-3 * (0.7 * k).cos(),
                1e-3 * (0.9 * k).sin() + 5e-3 * p[0] * p[1],
            ];
            if b == 0 && (p[0] - 0.5).abs() < 1e-12 && (p[1] - 0.5).abs() < 1e-12 && p[2] == 1.0 {
                shift[2] += 0.1;
            }
            if b == 1 {
                shift[2] += press;
            }
            for i in 0..3 {
                u[body.dof(n, i)] = shift[i];
            }
        }
    }
    u
}

/// The whole Newton system's tangent (neo-Hookean solids plus the contact rows with their
/// gaps' Hessians) against central differences of its residual at `u`, every row active with
/// a compressive force (Lagrange multipliers, or Uzawa multipliers of the augmented
/// Lagrangian), and the penalty: the largest difference relative to the largest entry.
fn tangent_check(case: &Value, u: &[f64], label: &str) -> f64 {
    let model = build3(&parse(case), "finite3d_mortar").unwrap_or_else(|e| panic!("{e}"));
    let rows = finite_common::rows_at3(&model, u);
    assert!(rows.iter().all(|r| r.hessian.is_some()));
    let n_rows = rows.len();
    let (worst, scale) = finite_common::tangent_difference_with_rows3(&model, u, rows);
    println!("{label}: {n_rows} rows, tangent vs central difference {worst:.1e} of {scale:.3e}");
    worst
}

/// The Newton tangent with node-to-node rows (the master's nodal normal varied) is the
/// central difference of the residual to 1e-7 of its largest entry: Lagrange multipliers, the
/// augmented Lagrangian and the penalty, at a penetrating state on a pyramid-shaped master.
#[test]
fn the_newton_tangent_with_node_to_node_rows_is_the_difference_of_the_residual() {
    for enforcement in [
        json!({"kind": "lagrange"}),
        json!({"kind": "augmented_lagrange", "kappa": 1e4}),
        json!({"kind": "penalty", "kappa": 1e4}),
    ] {
        let case = stacked(
            &MATCHING,
            &MATCHING,
            node_to_node(),
            enforcement.clone(),
            0.0,
            1,
        );
        let model = build3(&parse(&case), "finite3d_mortar").unwrap();
        let u = tangent_state(&model, -0.02);
        let worst = tangent_check(&case, &u, &format!("node-to-node {}", enforcement["kind"]));
        assert!(worst < 1e-7, "{}: {worst:e}", enforcement["kind"]);
    }
}

/// The stacked pair (Hex8 base on [`MATCHING`], punch on `punch`) with `discretization`, the
/// base's bottom and the punch's top clamped and carried by `x = A X`, `A = diag(1, 1, 0.85)`
/// (a 15 % compression between clamped faces: the blocks bulge), the whole problem turned
/// rigidly by `r` (reference positions `X -> r X`, the faces carried by `r A r^T`), Lagrange
/// multipliers, 4 load steps.
fn clamped(discretization: Value, punch: &[f64], r: &Matrix3<f64>) -> (Model3, Solution<3>) {
    let mut case = stacked(
        &MATCHING,
        punch,
        discretization,
        json!({"kind": "lagrange"}),
        0.0,
        4,
    );
    case["supports"] = json!([
        {"body": "base", "set": "bottom", "x": 0.0, "y": 0.0, "z": 0.0},
        {"body": "punch", "set": "top", "x": 0.0, "y": 0.0, "z": 0.0}
    ]);
    let model = build3(&parse(&case), "finite3d_mortar").unwrap();
    finite_common::turned_and_squeezed(model, r)
}

/// Objectivity: the clamped, bulging pair ([`clamped`]) turned rigidly by 60 degrees about
/// `(1, 2, 3)` gives `u_R = R u` (1e-8 of the largest displacement) and `sigma_R = R sigma R^T`
/// at every quadrature point (1e-8 of the largest component). Returns the two errors.
fn rotation_errors(discretization: Value, punch: &[f64], label: &str) -> (f64, f64) {
    let r = rotation([1.0, 2.0, 3.0], std::f64::consts::FRAC_PI_3);
    let (model, plain) = clamped(discretization.clone(), punch, &Matrix3::identity());
    let (rotated, turned) = clamped(discretization, punch, &r);
    let scale_u = plain.u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst_u = 0.0f64;
    for body in &model.bodies {
        for n in 0..body.mesh.nodes.len() {
            let u1 = Vector3::from_fn(|i, _| plain.u[body.dof(n, i)]);
            let u2 = Vector3::from_fn(|i, _| turned.u[body.dof(n, i)]);
            worst_u = worst_u.max((r * u1 - u2).abs().max());
        }
    }
    let stresses = |m: &Model3, u: &[f64]| -> Vec<[f64; 6]> {
        m.bodies
            .iter()
            .flat_map(|b| contact_patch::run3d::body_stresses(b, u))
            .map(|(_, s)| s)
            .collect()
    };
    let (s1, s2) = (stresses(&model, &plain.u), stresses(&rotated, &turned.u));
    let scale_s = s1.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst_s = s1
        .iter()
        .zip(&s2)
        .map(|(a, b)| {
            (r * to_matrix(*a) * r.transpose() - to_matrix(*b))
                .abs()
                .max()
        })
        .fold(0.0, f64::max);
    println!(
        "{label} turned 60 deg: |u_R - R u| {:.1e} of {scale_u:.3}, |sigma_R - R sigma R^T| {:.1e} of {scale_s:.1}",
        worst_u / scale_u,
        worst_s / scale_s
    );
    assert!(scale_u > 0.1, "a real compression");
    (worst_u / scale_u, worst_s / scale_s)
}

/// Node-to-node: the clamped pair turned by 60 degrees gives the turned answer (1e-8).
#[test]
fn a_large_rotation_of_the_node_to_node_pair_rotates_the_answer() {
    let (u, s) = rotation_errors(node_to_node(), &MATCHING, "node-to-node");
    assert!(u < 1e-8 && s < 1e-8, "{u:e} {s:e}");
}

/// Node-to-node on interfaces that do not match in the reference configuration is refused
/// before the solve, with the reason.
#[test]
fn node_to_node_on_non_matching_interfaces_is_refused() {
    let case = stacked(
        &MATCHING,
        &OFFSET,
        node_to_node(),
        json!({"kind": "lagrange"}),
        -0.4,
        4,
    );
    let err = build3(&parse(&case), "finite3d_mortar")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("contact[0] 'interface'.discretization") && err.contains("do not match"),
        "{err}"
    );
}

// ---------------------------------------------------------------------------------------------
// Mortar (segment-based, standard and dual multipliers)

fn mortar(multiplier: &str) -> Value {
    json!({"kind": "mortar", "multiplier": multiplier})
}

/// The mortar two-block patch test at finite strain (matching Hex8 grids, 20 % compression,
/// Lagrange multipliers), standard and dual multipliers: the uniform uniaxial Cauchy stress at
/// every quadrature point of both bodies to 1e-10 of `sigma_zz`.
#[test]
fn mortar_passes_the_two_block_patch_test() {
    for multiplier in ["standard", "dual"] {
        let label = format!("mortar {multiplier} matching");
        let error = patch_test(mortar(multiplier), &MATCHING, &label);
        assert!(error < 1e-10, "{label}: {error:e}");
    }
}

/// The mortar two-block patch test on a non-matching interface (the punch's nodes on
/// [`OFFSET`], off the base's nodes and edges), standard and dual multipliers: the uniform
/// uniaxial Cauchy stress to 1e-10 of `sigma_zz`.
#[test]
fn mortar_passes_the_non_matching_two_block_patch_test() {
    for multiplier in ["standard", "dual"] {
        let label = format!("mortar {multiplier} non-matching");
        let error = patch_test(mortar(multiplier), &OFFSET, &label);
        assert!(error < 1e-10, "{label}: {error:e}");
    }
}

/// Mortar on Tri6 facets (Tet10 bodies) under finite kinematics is refused before the solve,
/// with the reason: the rows are built (`mortar3_linearization`'s unit tests), but Newton on
/// the Tet10 two-block patch test leaves the uniform state.
#[test]
fn mortar_on_tri6_facets_is_refused() {
    let mut case = stacked(
        &MATCHING,
        &MATCHING,
        mortar("standard"),
        json!({"kind": "lagrange"}),
        -0.4,
        4,
    );
    for b in 0..2 {
        case["bodies"][b]["mesh"]["block3d"]["element"] = json!("Tet10");
    }
    let err = build3(&parse(&case), "finite3d_mortar")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("contact[0] 'interface'.discretization")
            && err.contains("Tri6")
            && err.contains("not built"),
        "{err}"
    );
}

/// The Newton tangent with mortar rows (the weighted gap's Hessian: auxiliary planes,
/// clipping, projections, dual coefficients and nodal normals varied) is the central
/// difference of the residual to 1e-6 of its largest entry: a one-cell punch over the four
/// facets of a pyramid-shaped master (every slave facet cut by the master's edges), pressed
/// in, every node moved off by a wavy field; standard multipliers with Lagrange rows (the dual
/// rows' Hessians are checked against differences in the row's unit tests).
#[test]
fn the_newton_tangent_with_mortar_rows_is_the_difference_of_the_residual() {
    let (multiplier, enforcement) = ("standard", json!({"kind": "lagrange"}));
    let mut case = stacked(
        &MATCHING,
        &[0.2, 0.8],
        mortar(multiplier),
        enforcement.clone(),
        0.0,
        1,
    );
    case["bodies"][1]["mesh"]["block3d"]["z"] = json!([1, 1.5]);
    let model = build3(&parse(&case), "finite3d_mortar").unwrap();
    let u = tangent_state(&model, -0.02);
    let label = format!("mortar {multiplier} {}", enforcement["kind"]);
    let worst = tangent_check(&case, &u, &label);
    assert!(worst < 1e-6, "{label}: {worst:e}");
}

/// Mortar: the clamped, bulging pair (matching interface) turned by 60 degrees gives the
/// turned answer (1e-8), standard multipliers.
#[test]
fn a_large_rotation_of_the_mortar_pair_rotates_the_answer() {
    let multiplier = "standard";
    let (u, s) = rotation_errors(
        mortar(multiplier),
        &MATCHING,
        &format!("mortar {multiplier}"),
    );
    assert!(u < 1e-8 && s < 1e-8, "{multiplier}: {u:e} {s:e}");
}

/// The small-load limit: at the reference configuration (flat, coincident, non-matching
/// interface) the finite-strain mortar rows are the small-strain ones of `mortar3` (the
/// variations of the weights, normals and segments multiply the gap, which is zero there):
/// the same gaps and coefficients to 1e-12 of the largest, standard and dual.
#[test]
fn at_the_reference_configuration_the_mortar_rows_are_the_small_strain_rows() {
    use contact_patch::contact::discretization::pair3::pair_rows;
    use std::collections::BTreeMap;
    for multiplier in ["standard", "dual"] {
        let finite_case = stacked(
            &MATCHING,
            &OFFSET,
            mortar(multiplier),
            json!({"kind": "lagrange"}),
            -0.4,
            4,
        );
        let mut small_case = finite_case.clone();
        small_case["physics"] = json!({});
        small_case["solver"] = json!({});
        small_case["materials"]["rubber"]["model"] = json!("linear_elastic");
        let finite = build3(&parse(&finite_case), "finite3d_mortar").unwrap();
        let small = build3(&parse(&small_case), "finite3d_mortar").unwrap();
        let rows_finite = pair_rows(&finite, &finite.contact[0]).unwrap();
        let rows_small = pair_rows(&small, &small.contact[0]).unwrap();
        assert_eq!(rows_finite.len(), rows_small.len());
        let mut worst = 0.0f64;
        let mut scale = 0.0f64;
        for (a, b) in rows_finite.iter().zip(&rows_small) {
            assert_eq!(a.slave_node, b.slave_node);
            assert!(a.hessian.is_some() && b.hessian.is_none());
            let dense = |r: &contact_patch::contact::Constraint<3>| -> BTreeMap<usize, f64> {
                r.dofs
                    .iter()
                    .copied()
                    .zip(r.coeffs.iter().copied())
                    .collect()
            };
            let (da, db) = (dense(a), dense(b));
            for (d, &c) in da.iter().chain(db.iter()) {
                scale = scale.max(c.abs());
                worst = worst.max((da.get(d).unwrap_or(&0.0) - db.get(d).unwrap_or(&0.0)).abs());
            }
            worst = worst.max((a.g0 - b.g0).abs());
        }
        println!(
            "mortar {multiplier}: {} rows, finite vs small-strain rows at the reference {:.1e}",
            rows_finite.len(),
            worst / scale
        );
        assert!(worst < 1e-12 * scale, "{multiplier}: {worst:e}");
    }
}

/// Newton iterations per load step of the stacked pair (standard mortar, Lagrange, 20 %
/// compression, 4 load steps) with the base on `base` breaks and the punch on `punch`.
fn iterations_per_step(base: &[f64], punch: &[f64]) -> Vec<usize> {
    let o = run(&stacked(
        base,
        punch,
        mortar("standard"),
        json!({"kind": "lagrange"}),
        -0.4,
        4,
    ));
    assert!(o.converged());
    let finite = o.solution.finite.as_ref().unwrap();
    let mut counts = vec![0; 4];
    for h in &finite.history {
        counts[h.step - 1] += 1;
    }
    println!(
        "base {base:?}, punch {punch:?}: Newton iterations per step {counts:?}, residuals {:?}",
        residuals(&o.solution)
    );
    counts
}

/// Newton converges quadratically on the finite mortar patch test where the punch's and the
/// base's outer edges lie on the same lines (matching grids, or the punch's nodes on
/// [`OFFSET`]) as it does with the base wider than the punch (its outer edges over the base's
/// interior; not a homogeneous state): at most 6 iterations a load step. With clipping
/// decisions at round-off size (`mortar3::CLIP_TOLERANCE = 1e-12`) the flush edges made the
/// iterates wander at relative residuals 1e-9 to 1e-7: [5, 41, 23, 37] and [18, 11, 14, 28]
/// iterations, against [4, 5, 5, 5] with the wider base.
#[test]
fn newton_converges_quadratically_where_the_blocks_outer_faces_are_flush() {
    let wider = [-0.5, 0.0, 0.5, 1.0, 1.5];
    for (base, punch) in [
        (&wider[..], &OFFSET[..]),
        (&MATCHING, &MATCHING),
        (&MATCHING, &OFFSET),
    ] {
        let counts = iterations_per_step(base, punch);
        assert!(
            counts.iter().all(|&n| n <= 6),
            "base {base:?}, punch {punch:?}: {counts:?}"
        );
    }
}

/// A punch overhanging the base on every side (the slave surface's outer facets half off the
/// master, its edge nodes over nothing), standard mortar, Lagrange, 20 % compression: the
/// solve converges (with cuts where a step's Newton leaves the cone of convergence) and the
/// force the punch's top takes balances the base bottom's to 1e-9. With round-off clipping
/// decisions this solve had not finished after 11 minutes.
#[test]
fn a_punch_overhanging_the_base_is_solved() {
    let o = run(&stacked(
        &MATCHING,
        &[-0.25, 0.3, 0.7, 1.25],
        mortar("standard"),
        json!({"kind": "lagrange"}),
        -0.4,
        4,
    ));
    assert!(o.converged());
    let force_at = |b: usize, z: f64| -> f64 {
        let body = &o.model.bodies[b];
        (0..body.mesh.nodes.len())
            .filter(|&n| body.mesh.nodes[n][2] == z)
            .map(|n| o.solution.reactions[body.dof(n, 2)])
            .sum()
    };
    // the reactions on the supports: the base's bottom pushes up, the punch's top down
    let (base, punch) = (force_at(0, 0.0), force_at(1, 2.0));
    let finite = o.solution.finite.as_ref().unwrap();
    println!(
        "overhanging punch: base {base:.9}, punch {punch:.9}, {} Newton iterations, residuals {:?}",
        finite.history.len(),
        residuals(&o.solution)
    );
    assert!(base > 0.0 && punch < 0.0, "{base} {punch}");
    assert!((base + punch).abs() < 1e-9 * base, "{base} {punch}");
}
