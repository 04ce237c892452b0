//! Finite kinematics with frictionless mortar contact (standard and dual multipliers, Line2
//! and Line3 facets) between two deformable neo-Hookean bodies, in the current configuration,
//! searched again at every Newton iterate, with the exact gradient and second derivative of
//! every row's weighted gap (`contact::discretization::mortar_linearization`: segments,
//! projections and nodal normals varied).
//!
//! References, each independent of the solver: central differences of the Newton residual
//! (the tangent), the translation invariance of the gap (force balance: the sum of the nodal
//! contact forces over both bodies is zero when the slave surface is covered), and gaps
//! measured afresh in the deformed configuration. The finite-strain contact patch test of
//! mortar is a row of `contact-patch finite-patch` (tests/finite_contact.rs).

use contact_patch::contact::discretization::constraints;
use contact_patch::run::{run_case, Outcome};
use contact_patch::solver::contact_newton::Probe;
use serde_json::{json, Value};

mod finite_common;
use finite_common::{assert_closed_where_pressed, write, NON_MATCHING};

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
    finite_common::two_blocks(
        element,
        &NON_MATCHING,
        json!({"kind": "mortar", "multiplier": multiplier}),
        enforcement,
        (slide, press),
        steps,
    )
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
                let (worst, scale) = finite_common::tangent_difference(&mut probe, &x, &at);
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

/// Once the relative residual is below 1e-3, each is below `C r^2` of the last one in the
/// same load step (or below the solver's tolerance 1e-12, the round-off floor), `C = 1000`: a
/// linear rate `c` would give `r_{k+1} / r_k^2 = c / r_k`, `1e5 c` at 1e-5. (tests/
/// finite_contact.rs takes `C = 100` for node-to-surface; the mortar rows' Hessian jumps where
/// a segment end crosses a master node between iterates, and Q9 pairs measured up to 150 in the
/// asymptotic range, e.g. `4.5e-5 -> 2.1e-7 -> 6e-14`.) Returns how many pairs were judged and the
/// largest `r_{k+1} / r_k^2` seen.
const QUADRATIC: f64 = 1000.0;

fn quadratic_ratios(o: &Outcome) -> (usize, f64) {
    const FLOOR: f64 = contact_patch::solver::contact_newton::FINITE_RESIDUAL_TOLERANCE;
    let history = &o.solution.finite.as_ref().unwrap().history;
    let mut seen = 0;
    let mut largest = 0.0f64;
    for w in history.windows(2) {
        if w[0].step == w[1].step && w[0].residual < 1e-3 && w[0].residual > FLOOR {
            seen += 1;
            if w[1].residual > FLOOR {
                largest = largest.max(w[1].residual / (w[0].residual * w[0].residual));
            }
            assert!(
                w[1].residual <= QUADRATIC * w[0].residual * w[0].residual + FLOOR,
                "step {}: residual {} after {} is not quadratic: {:?}",
                w[0].step,
                w[1].residual,
                w[0].residual,
                history
                    .iter()
                    .map(|h| (h.step, h.residual))
                    .collect::<Vec<_>>()
            );
        }
    }
    (seen, largest)
}

/// The model with every node moved to `X + u`.
fn deformed(o: &Outcome) -> contact_patch::model::Model {
    let mut moved = o.model.clone();
    for b in &mut moved.bodies {
        let off = b.dof_offset;
        for (n, p) in b.mesh.nodes.iter_mut().enumerate() {
            p[0] += o.solution.u[off + 2 * n];
            p[1] += o.solution.u[off + 2 * n + 1];
        }
    }
    moved
}

/// The top block pressed into the base by 0.1 and slid by 0.9 (nearly two master facets) in 6
/// load steps, mortar with standard and dual multipliers, Q4 and Q9: with Lagrange multipliers
/// Newton converges quadratically in every step (`r_{k+1} <= 1000 r_k^2` once `r_k < 1e-3`;
/// measured: see the output), every slave node's row ends over other master nodes than it
/// started on, and, the rows measured afresh in the deformed configuration, no weighted gap
/// is negative (below 1e-10 of the size) and every row carrying force has zero weighted gap;
/// the contact force balances the top's reaction. The penalty (`kappa = 1e4`) converges too,
/// its rate judged the same way (at `kappa = 1e5` a Q9 step cycled between open and closed
/// points and its cuts were spent); the augmented Lagrangian (Uzawa update per iteration)
/// converges, its rate printed.
#[test]
fn a_block_slid_over_a_deformable_base_with_mortar_converges_quadratically() {
    for element in ["Q4", "Q9"] {
        for multiplier in ["standard", "dual"] {
            for enforcement in [
                json!({"kind": "lagrange"}),
                json!({"kind": "penalty", "kappa": 1e4}),
                json!({"kind": "augmented_lagrange", "kappa": 1e4, "update": "per_iteration"}),
            ] {
                let kind = enforcement["kind"].as_str().unwrap();
                let case = two_blocks(element, multiplier, enforcement.clone(), 0.9, -0.1, 6);
                let (_dir, path) = write(&case);
                let o = run_case(&path, &mut |_| {}).unwrap();
                assert!(o.passed(), "{element} {multiplier} {kind}: {:?}", o.checks);
                // the augmented Lagrangian's Uzawa update after every iteration moves the
                // residual itself: its rate is printed, not judged
                let (seen, largest) = if kind == "augmented_lagrange" {
                    (0, f64::NAN)
                } else {
                    quadratic_ratios(&o)
                };
                let history = o.solution.finite.as_ref().unwrap();
                println!(
                    "{element} {multiplier} {kind}: {} attempts, {} cuts, largest r_k+1 / r_k^2 {largest:.2e} over {seen} pairs, residuals {:?}",
                    history.steps.len(),
                    history.cuts,
                    history.history.iter().map(|h| format!("{}:{:.1e}", h.step, h.residual)).collect::<Vec<_>>()
                );
                if kind != "augmented_lagrange" {
                    assert!(
                        seen >= 6,
                        "{element} {multiplier}: too few iterations to judge"
                    );
                    assert!(largest <= QUADRATIC);
                }
                let moved = deformed(&o);
                let rows = constraints(&moved, &moved.contact[0]).unwrap();
                let reference = constraints(&o.model, &o.model.contact[0]).unwrap();
                let base = &o.model.bodies[0];
                let master_dofs = |r: &contact_patch::contact::Constraint| {
                    let mut d: Vec<usize> = r
                        .dofs
                        .iter()
                        .copied()
                        .filter(|&d| d < base.dof_offset + 2 * base.mesh.nodes.len())
                        .collect();
                    d.sort();
                    d
                };
                for r in &rows {
                    let r0 = reference
                        .iter()
                        .find(|q| q.slave_node == r.slave_node)
                        .unwrap();
                    assert_ne!(master_dofs(r), master_dofs(r0), "the row slid on");
                }
                if kind == "lagrange" {
                    assert_closed_where_pressed(&o, &rows);
                }
            }
        }
    }
}

/// Linear and angular momentum of the mortar forces at finite strain: the top block slid 0.9
/// and pressed 0.1 over the base (its slave facets covered by the master), solved with
/// Lagrange multipliers. The nodal contact forces `sum_j lambda_j b_j` (the exact gradients,
/// in the deformed configuration) sum to zero over both bodies, and so does their moment
/// about the origin (the weighted gap is invariant under rigid translations and rotations of
/// both bodies), to 1e-12 of the total normal force; the force on the slave body is equal and
/// opposite to the force on the master body.
#[test]
fn mortar_forces_balance_at_finite_strain() {
    for element in ["Q4", "Q9"] {
        for multiplier in ["standard", "dual"] {
            let case = two_blocks(
                element,
                multiplier,
                json!({"kind": "lagrange"}),
                0.9,
                -0.1,
                6,
            );
            let (_dir, path) = write(&case);
            let o = run_case(&path, &mut |_| {}).unwrap();
            let state = o.solution.contact.as_ref().unwrap();
            let moved = deformed(&o);
            let mut force = [[0.0f64; 2]; 2];
            let mut moment = 0.0f64;
            let mut total = 0.0f64;
            for (r, &lambda) in state.rows.iter().zip(&state.forces) {
                total += lambda.abs();
                for (&d, &c) in r.dofs.iter().zip(&r.coeffs) {
                    let body = moved
                        .bodies
                        .iter()
                        .position(|b| {
                            d >= b.dof_offset && d < b.dof_offset + 2 * b.mesh.nodes.len()
                        })
                        .unwrap();
                    let b = &moved.bodies[body];
                    let (node, i) = ((d - b.dof_offset) / 2, (d - b.dof_offset) % 2);
                    let f = lambda * c;
                    force[body][i] += f;
                    let x = b.mesh.nodes[node];
                    moment += if i == 0 { -x[1] * f } else { x[0] * f };
                }
            }
            let linear = (force[0][0] + force[1][0]).hypot(force[0][1] + force[1][1]);
            println!(
                "{element} {multiplier}: total force {total:.6e}, on the slave {:?}, on the master {:?}, sum {linear:.1e}, moment {moment:.1e}",
                force[1], force[0]
            );
            assert!(total > 1.0);
            assert!(linear <= 1e-12 * total, "{linear:e}");
            assert!(moment.abs() <= 1e-12 * total * o.model.size(), "{moment:e}");
        }
    }
}
