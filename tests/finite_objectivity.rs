//! Objectivity of finite-strain contact (issue 12, "a contacting pair rotated rigidly through
//! 90 degrees in steps keeps zero stress and its contact forces rotate with it";
//! `shared/design/benchmarks.md` s. 7).
//!
//! Two neo-Hookean blocks in frictionless contact (node-to-surface, master normals, the top
//! block's bottom the slave, non-matching interface nodes), the base's bottom and the top
//! block's top driven by prescribed displacements: every supported node `X` follows
//! `x = c + R(theta) (X + d - c)` with `R(theta)` the rotation by `theta` about `c`, `d` the
//! press (zero on the base; `(0, -delta)` on the top block after the press). Each supported
//! node has its own support with its own load `path` (the case format's per-step factors),
//! since a rotation is not proportional in `theta`.
//!
//! References (closed forms, not our output): a rigid rotation `F = R` has the Cauchy stress
//! `sigma = (mu (F F^T - I) + lambda ln J I) / J = 0` for the neo-Hookean law, and a rotated
//! equilibrium state `x_theta = c + R (x_0 - c)` has Cauchy stress `R sigma_0 R^T` and nodal
//! contact forces `R f_0`, with `sigma_0`, `f_0` the unrotated pressed state of the same run.
//! The rigid masters of the case format (a line or a circle) are fixed in space; a block on a
//! rigid line cannot be rotated with its master, so that half of the item is not
//! tested here (the deformable pair is).

use contact_patch::contact::forces::pair_forces;
use contact_patch::model::Model;
use contact_patch::post::for_each_quadrature_stress;
use serde_json::{json, Value};

const E: f64 = 1000.0;
const NU: f64 = 0.3;
/// The centre of the rotation: off the mesh lines, so that no supported node has a zero
/// displacement component at 90 degrees (its load path's factors are divided by it).
const CENTRE: [f64; 2] = [1.13, 0.77];
/// Load steps of the rotation to 90 degrees.
const ROTATION_STEPS: usize = 24;

fn rotate(theta: f64, v: [f64; 2]) -> [f64; 2] {
    let (s, c) = theta.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

/// Displacement of a supported node `x` at load step `k` (1-based) of `press_steps` steps of
/// the press `press` (its displacement, added linearly) followed by `rotation_steps` equal
/// steps of rotation to 90 degrees.
fn driven(
    x: [f64; 2],
    press: [f64; 2],
    k: usize,
    press_steps: usize,
    rotation_steps: usize,
) -> [f64; 2] {
    if k <= press_steps {
        let s = k as f64 / press_steps as f64;
        return [s * press[0], s * press[1]];
    }
    let theta = std::f64::consts::FRAC_PI_2 * (k - press_steps) as f64 / rotation_steps as f64;
    let arm = [x[0] + press[0] - CENTRE[0], x[1] + press[1] - CENTRE[1]];
    let r = rotate(theta, arm);
    [CENTRE[0] + r[0] - x[0], CENTRE[1] + r[1] - x[1]]
}

/// The two-block case on `element`, with enforcement `enforcement`, the top pressed by
/// `delta` in `press_steps` steps (none when `delta == 0`) and then rotated by `taken` of
/// `rotation_steps` equal steps to 90 degrees (to `90 taken / rotation_steps` degrees).
fn rotated_pair(
    element: &str,
    enforcement: &Value,
    delta: f64,
    press_steps: usize,
    taken: usize,
    rotation_steps: usize,
) -> Value {
    let base_x = [0.0, 0.5, 1.0, 1.5, 2.0];
    let top_x = [0.42, 0.82, 1.22, 1.62];
    let steps = press_steps + taken;
    let mut node_sets = [serde_json::Map::new(), serde_json::Map::new()];
    let mut supports = Vec::new();
    let quadratic = element == "Q9";
    let along = |xs: &[f64]| -> Vec<f64> {
        let mut out = Vec::new();
        for w in xs.windows(2) {
            out.push(w[0]);
            if quadratic {
                out.push(0.5 * (w[0] + w[1]));
            }
        }
        out.push(*xs.last().unwrap());
        out
    };
    for (b, (xs, y, press)) in [
        (&base_x[..], 0.0, [0.0, 0.0]),
        (&top_x[..], 1.8, [0.0, -delta]),
    ]
    .into_iter()
    .enumerate()
    {
        let body = ["base", "top"][b];
        for (i, x) in along(xs).into_iter().enumerate() {
            let set = format!("driven{i}");
            node_sets[b].insert(set.clone(), json!({"point": [x, y]}));
            let last = driven([x, y], press, steps, press_steps, rotation_steps);
            for (component, name) in ["x", "y"].into_iter().enumerate() {
                let values: Vec<f64> = (1..=steps)
                    .map(|k| driven([x, y], press, k, press_steps, rotation_steps)[component])
                    .collect();
                if values.iter().all(|v| *v == 0.0) {
                    supports.push(json!({"body": body, "set": set, name: 0.0}));
                    continue;
                }
                // the path's factors are divided by the last value
                assert!(
                    last[component].abs() > 1e-4,
                    "a zero displacement at the last step"
                );
                let path: Vec<f64> = values.iter().map(|v| v / last[component]).collect();
                supports
                    .push(json!({"body": body, "set": set, name: last[component], "path": path}));
            }
        }
    }
    json!({
        "name": "rotated-pair",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": E, "nu": NU, "model": "neo_hookean"}},
        "bodies": [
            {"name": "base", "material": "m", "node_sets": node_sets[0],
             "mesh": {"block": {"element": element, "x": base_x, "y": [0.0, 0.5, 1.0]}}},
            {"name": "top", "material": "m", "node_sets": node_sets[1],
             "mesh": {"block": {"element": element, "x": top_x, "y": [1.0, 1.4, 1.8]}}}
        ],
        "physics": {"kinematics": "finite", "contact_geometry": "current"},
        "solver": {"scheme": "newton", "load_steps": steps},
        "supports": supports,
        "loads": [],
        "contact": [{
            "name": "interface",
            "slave": {"body": "top", "set": "bottom"},
            "master": {"body": "base", "set": "top"},
            "discretization": {"kind": "node_to_surface", "passes": 1},
            "enforcement": enforcement
        }]
    })
}

/// What the last load step of a case converged to: the Cauchy stress at every quadrature
/// point of both bodies, and the nodal contact force of every node of the pair
/// (`(body, node) -> f_a`), with the net force on the slave body.
struct FinalState {
    stresses: Vec<[f64; 3]>,
    nodal: Vec<((usize, usize), [f64; 2])>,
    on_slave: [f64; 2],
}

/// Solve the case in its load steps (the solver may cut a step; the last state is the whole
/// path's end either way: a frictionless elastic path has no history).
fn solve_final(case: &Value) -> FinalState {
    let parsed = contact_patch::model::parse(&case.to_string(), "rotated-pair").unwrap();
    let model = Model::build(&parsed, "rotated-pair").unwrap();
    let solution = contact_patch::solver::finite::solve(&model, &mut |_| {}).unwrap();
    let mut stresses = Vec::new();
    for body in &model.bodies {
        for_each_quadrature_stress(body, &solution.u, |_, _, s| stresses.push(s));
    }
    let state = solution.contact.as_ref().unwrap();
    let forces = &pair_forces(&model, state)[0];
    let mut nodal: Vec<_> = forces
        .nodes
        .iter()
        .map(|n| ((n.body, n.node), n.force))
        .collect();
    nodal.sort_by_key(|(k, _)| *k);
    FinalState {
        stresses,
        nodal,
        on_slave: forces.on_slave,
    }
}

fn enforcements() -> [Value; 2] {
    [
        json!({"kind": "lagrange"}),
        json!({"kind": "penalty", "kappa": 1e5}),
    ]
}

/// The pair touching without a press (every interface row closed at zero gap), rotated by
/// 90 degrees in 24 steps of 3.75 degrees (each angle solved from the start in its own steps):
/// at every step the Cauchy stress at every quadrature point of both bodies is zero to
/// round-off (below 1e-10 E; measured: see the output) and so is the contact force on the top
/// block. Lagrange multipliers on Q4 and Q9. Not included: the penalty, whose rows at exactly
/// zero gap open and close with the round-off of the gap (Q4 at 3.75 degrees: Newton did not
/// converge in 200 iterations and the ten cuts of the load increment were spent): a
/// chattering failure at a zero gap, not a stress or force off zero. The pressed test below
/// covers the penalty.
#[test]
fn an_unpressed_pair_rotated_rigidly_keeps_zero_stress_at_every_step() {
    for (element, enforcement) in [
        ("Q4", json!({"kind": "lagrange"})),
        ("Q9", json!({"kind": "lagrange"})),
    ] {
        {
            let mut worst = 0.0f64;
            for taken in 1..=ROTATION_STEPS {
                let s = solve_final(&rotated_pair(
                    element,
                    &enforcement,
                    0.0,
                    0,
                    taken,
                    ROTATION_STEPS,
                ));
                let stress = s
                    .stresses
                    .iter()
                    .flatten()
                    .fold(0.0f64, |m, v| m.max(v.abs()));
                let force = s.on_slave[0].abs().max(s.on_slave[1].abs());
                println!(
                    "{element} {}: {:.1} degrees: max |sigma| / E = {:.1e}, |force on top| / E = {:.1e}",
                    enforcement["kind"],
                    90.0 * taken as f64 / ROTATION_STEPS as f64,
                    stress / E,
                    force / E
                );
                worst = worst.max(stress / E).max(force / E);
            }
            assert!(
                worst < 1e-10,
                "{element} {}: {worst:e}",
                enforcement["kind"]
            );
        }
    }
}

/// The pair pressed by 0.05 (about 6 % of the top block's height) in 2 steps, then rotated to
/// 90 degrees in 24 steps of 3.75 degrees (each angle solved from the start; with steps of 7.5
/// degrees the Q9 Lagrange pair at 45 degrees inverted an element in Newton's iterates and
/// spent its cuts): at every rotated step the Cauchy stress at every quadrature point is
/// `R sigma_0 R^T` and every nodal contact force (slave and master nodes) is `R f_0`, with
/// `sigma_0`, `f_0` those of the pressed, unrotated step; compared relative to the largest
/// stress and nodal force of the pressed state (below 1e-9: the Newton tolerance is 1e-12 of
/// the residual; measured: see the output). The press is not trivial: the contact force is
/// compressive and of the order of E times the strain.
#[test]
fn a_pressed_pair_rotated_rigidly_rotates_its_stress_and_contact_forces() {
    for element in ["Q4", "Q9"] {
        for enforcement in enforcements() {
            let pressed = solve_final(&rotated_pair(
                element,
                &enforcement,
                0.05,
                2,
                0,
                ROTATION_STEPS,
            ));
            let pressed = &pressed;
            let stress_scale = pressed
                .stresses
                .iter()
                .flatten()
                .fold(0.0f64, |m, v| m.max(v.abs()));
            let force_scale = pressed
                .nodal
                .iter()
                .fold(0.0f64, |m, (_, f)| m.max(f[0].abs()).max(f[1].abs()));
            // pressed: the top block is pushed down, the interface carries about E * strain * width
            assert!(
                pressed.on_slave[1] > 0.01 * E,
                "{element}: force {:?}",
                pressed.on_slave
            );
            assert!(force_scale > 0.0 && stress_scale > 0.01 * E);
            let mut worst = (0.0f64, 0.0f64);
            for taken in 1..=ROTATION_STEPS {
                let s = &solve_final(&rotated_pair(
                    element,
                    &enforcement,
                    0.05,
                    2,
                    taken,
                    ROTATION_STEPS,
                ));
                let theta = std::f64::consts::FRAC_PI_2 * taken as f64 / ROTATION_STEPS as f64;
                let (sn, cs) = theta.sin_cos();
                let mut stress_error = 0.0f64;
                for (s0, s1) in pressed.stresses.iter().zip(&s.stresses) {
                    // R sigma R^T for sigma = [[xx, xy], [xy, yy]]
                    let (xx, yy, xy) = (s0[0], s0[1], s0[2]);
                    let rotated = [
                        cs * cs * xx - 2.0 * sn * cs * xy + sn * sn * yy,
                        sn * sn * xx + 2.0 * sn * cs * xy + cs * cs * yy,
                        sn * cs * (xx - yy) + (cs * cs - sn * sn) * xy,
                    ];
                    for i in 0..3 {
                        stress_error = stress_error.max((s1[i] - rotated[i]).abs());
                    }
                }
                assert_eq!(s.nodal.len(), pressed.nodal.len());
                let mut force_error = 0.0f64;
                for ((k0, f0), (k1, f1)) in pressed.nodal.iter().zip(&s.nodal) {
                    assert_eq!(k0, k1);
                    let rotated = rotate(theta, *f0);
                    force_error = force_error
                        .max((f1[0] - rotated[0]).abs())
                        .max((f1[1] - rotated[1]).abs());
                }
                let net = rotate(theta, pressed.on_slave);
                force_error = force_error
                    .max((s.on_slave[0] - net[0]).abs())
                    .max((s.on_slave[1] - net[1]).abs());
                println!(
                    "{element} {}: {:.0} degrees: stress vs R sigma_0 R^T {:.1e}, nodal contact forces vs R f_0 {:.1e} (net force on top {:?})",
                    enforcement["kind"],
                    theta.to_degrees(),
                    stress_error / stress_scale,
                    force_error / force_scale,
                    s.on_slave
                );
                worst = (
                    worst.0.max(stress_error / stress_scale),
                    worst.1.max(force_error / force_scale),
                );
            }
            assert!(
                worst.0 < 1e-9 && worst.1 < 1e-9,
                "{element} {}: {worst:?}",
                enforcement["kind"]
            );
        }
    }
}
