//! Helpers shared by the finite-strain tests (tests/finite_contact.rs, tests/finite_mortar.rs,
//! tests/finite_slave_normals.rs, tests/finite3d.rs, tests/finite3d_mortar.rs): the two-block
//! scene they slide, a scratch folder for its case file, the check of the gaps measured afresh
//! after a slide, and in 3D rotations, the neo-Hookean bar's lateral stretch and the turned,
//! squeezed pair of the objectivity tests.

#![allow(dead_code)] // not every test binary that includes this module uses every helper

use contact_patch::contact::Constraint;
use contact_patch::run::Outcome;
use serde_json::{json, Value};

pub const E: f64 = 1000.0;
pub const NU: f64 = 0.3;

/// The Lamé constants `(lambda, mu)` of `E`, `NU` (plane strain).
pub fn lame() -> (f64, f64) {
    (
        E * NU / ((1.0 + NU) * (1.0 - 2.0 * NU)),
        E / (2.0 * (1.0 + NU)),
    )
}

/// Write `case` as `case.json` in a fresh scratch folder (kept alive by the returned guard).
pub fn write(case: &Value) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("case.json");
    std::fs::write(&path, serde_json::to_string_pretty(case).unwrap()).unwrap();
    (dir, path)
}

/// The top block's nodes: non-matching (master facets 0.5 long, slave nodes 0.4 apart).
pub const NON_MATCHING: [f64; 4] = [0.5, 0.9, 1.3, 1.7];
/// The top block as wide as the base, its bottom nodes on the base's top nodes (node-to-node
/// pairs every node of both surfaces).
pub const MATCHING: [f64; 7] = [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0];

/// A base block `[0, 3] x [0, 1]` and a top block over `top_x` x `[1, 1.8]` of `element`,
/// neo-Hookean; the base's bottom clamped, the top block's top moved by `(slide, press)` in
/// `steps` load steps; the top block's bottom (slave) against the base's top (master) with
/// `discretization` and `enforcement`, in the current configuration, Newton.
pub fn two_blocks(
    element: &str,
    top_x: &[f64],
    discretization: Value,
    enforcement: Value,
    (slide, press): (f64, f64),
    steps: usize,
) -> Value {
    json!({
        "name": "two-blocks",
        "description": "two neo-Hookean blocks in frictionless contact, finite kinematics",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": E, "nu": NU, "model": "neo_hookean"}},
        "bodies": [
            {"name": "base", "material": "m", "mesh": {"block": {
                "element": element, "x": [0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0], "y": [0, 0.5, 1]}}},
            {"name": "top", "material": "m", "mesh": {"block": {
                "element": element, "x": top_x, "y": [1, 1.4, 1.8]}}}
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
            "discretization": discretization,
            "enforcement": enforcement
        }],
        "checks": [{"check": "force_balance", "tol": 1e-9}]
    })
}

/// The rows `rows`, built afresh in the deformed configuration of the solved `o` (Lagrange
/// multipliers): no gap below `-1e-10` of the model's size (no penetration), and every row
/// whose slave node carries a force has a zero gap to `1e-10` of the size.
pub fn assert_closed_where_pressed(o: &Outcome, rows: &[Constraint]) {
    let state = o.solution.contact.as_ref().unwrap();
    let size = o.model.size();
    for r in rows {
        assert!(r.g0 >= -1e-10 * size, "penetration {}", r.g0);
        let k = state
            .rows
            .iter()
            .position(|q| q.slave_node == r.slave_node)
            .unwrap();
        if state.forces[k] > 1e-12 {
            assert!(r.g0.abs() <= 1e-10 * size, "gap {} under force", r.g0);
        }
    }
}

/// The Newton tangent of `probe` at `x` (its evaluation `at`) against central differences of
/// the residual (step `1e-7`): the largest difference relative to the largest tangent entry,
/// and that entry.
pub fn tangent_difference<const D: usize, K>(
    probe: &mut contact_patch::solver::contact_newton::Probe<'_, D, K>,
    x: &[f64],
    at: &contact_patch::solver::contact_newton::ProbeEvaluation,
) -> (f64, f64)
where
    K: contact_patch::solver::contact_newton::NewtonDimension<D>,
{
    let n = x.len();
    let scale = at
        .tangent
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let h = 1e-7;
    let mut worst = 0.0f64;
    for j in 0..n {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
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
    (worst, scale)
}

/// The rows of `model`'s first contact pair (3D) found and built at the positions `X + u`.
pub fn rows_at3(
    model: &contact_patch::model::Model3,
    u: &[f64],
) -> Vec<contact_patch::contact::Constraint<3>> {
    let mut moved = model.clone();
    for body in &mut moved.bodies {
        let offset = body.dof_offset;
        for (n, p) in body.mesh.nodes.iter_mut().enumerate() {
            for (i, x) in p.iter_mut().enumerate() {
                *x += u[offset + 3 * n + i];
            }
        }
    }
    contact_patch::contact::discretization::pair3::pair_rows(&moved, &moved.contact[0])
        .unwrap_or_else(|e| panic!("{e}"))
}

/// The whole Newton system of `model` (3D) at `u` with `rows` all active and the compressive
/// forces `2 + sin i` (Lagrange multipliers, or Uzawa multipliers of the augmented
/// Lagrangian; the penalty's rows act by their gaps): its tangent against central differences
/// of its residual ([`tangent_difference`]), the largest difference relative to the largest
/// entry, and that entry.
pub fn tangent_difference_with_rows3(
    model: &contact_patch::model::Model3,
    u: &[f64],
    rows: Vec<contact_patch::contact::Constraint<3>>,
) -> (f64, f64) {
    use contact_patch::contact::state::{ContactState, Termination};
    let n_rows = rows.len();
    let state = ContactState {
        rows,
        active: vec![true; n_rows],
        forces: (0..n_rows).map(|i| 2.0 + (i as f64).sin()).collect(),
        gaps: vec![0.0; n_rows],
        termination: Termination::Converged,
        iterations: 0,
        rank_deficiency: None,
        linear_solver: "",
        geometry_updates: 0,
        configuration: None,
        departures: Vec::new(),
        steps: Vec::new(),
        history: Vec::new(),
        geometry_changes: Vec::new(),
        friction: vec![None; n_rows],
    };
    let mut probe = contact_patch::solver::contact_newton::Probe::new(model, 0.0).unwrap();
    let x = probe.unknowns_at(u, &state);
    // a first evaluation at x covers the rows found there; the tangent is the second's
    probe.evaluate(&x).unwrap();
    let at = probe.evaluate(&x).unwrap();
    tangent_difference(&mut probe, &x, &at)
}

/// The rotation by `angle` about `axis`.
pub fn rotation(axis: [f64; 3], angle: f64) -> nalgebra::Matrix3<f64> {
    nalgebra::Rotation3::from_axis_angle(
        &nalgebra::Unit::new_normalize(nalgebra::Vector3::from(axis)),
        angle,
    )
    .into_inner()
}

/// The symmetric matrix of a Voigt vector `[xx, yy, zz, yz, xz, xy]`.
pub fn to_matrix(s: [f64; 6]) -> nalgebra::Matrix3<f64> {
    nalgebra::Matrix3::new(s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2])
}

/// The lateral stretch `b` of a neo-Hookean bar (`E`, `NU`) stretched by `a` with free lateral
/// faces: `sigma_xx = (mu (b^2 - 1) + lambda ln(a b^2)) / J = 0`, by bisection.
pub fn lateral_stretch(a: f64) -> f64 {
    let (lambda, mu) = contact_patch::solid::lame(E, NU);
    let (mut lo, mut hi) = (0.1, 3.0);
    for _ in 0..200 {
        let m = 0.5 * (lo + hi);
        if mu * (m * m - 1.0) + lambda * (a * m * m).ln() > 0.0 {
            hi = m;
        } else {
            lo = m;
        }
    }
    0.5 * (lo + hi)
}

/// The pair of `model` (base, then punch) turned by `r` and squeezed: every node turned, and
/// `A x - x` with `A = R diag(1, 1, 0.85) R^T` prescribed on the base's `bottom` and the
/// punch's `top`; solved by the finite-strain Newton scheme.
pub fn turned_and_squeezed(
    mut model: contact_patch::model::Model3,
    r: &nalgebra::Matrix3<f64>,
) -> (
    contact_patch::model::Model3,
    contact_patch::solver::linear::Solution<3>,
) {
    use nalgebra::{Matrix3, Vector3};
    for body in &mut model.bodies {
        for p in &mut body.mesh.nodes {
            let turned = r * Vector3::from(*p);
            *p = [turned[0], turned[1], turned[2]];
        }
    }
    let a = r * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 0.85)) * r.transpose();
    for (b, set) in [(0, "bottom"), (1, "top")] {
        let body = &model.bodies[b];
        let moves: Vec<(usize, f64)> = body.mesh.node_sets[set]
            .iter()
            .flat_map(|&n| {
                let x = Vector3::from(body.mesh.nodes[n]);
                let u = a * x - x;
                (0..3).map(move |i| (body.dof(n, i), u[i]))
            })
            .collect();
        for (d, v) in moves {
            model.prescribed[d] = Some(v);
        }
    }
    let solution =
        contact_patch::solver::finite::solve(&model, &mut |_| {}).unwrap_or_else(|e| panic!("{e}"));
    (model, solution)
}
