//! Finite kinematics with frictionless contact between two deformable (neo-Hookean) bodies
//! along nodal normals: node-to-surface with **slave normals** in its two forms (the consistent
//! linearization over the slave node, its surface neighbours and the master facet, and the
//! seed's smooth-sliding form without the `delta xi` term, whose tangent is unsymmetric) and
//! **node-to-node** where the nodes stay matched (`contact::discretization::nodal_normal`).
//!
//! References, each independent of the solver: central differences of the Newton residual
//! (the tangent) and gaps measured afresh in the deformed configuration. The finite-strain
//! contact patch test of these rows is a row of `contact-patch finite-patch`
//! (tests/finite_contact.rs).

use contact_patch::contact::discretization::constraints;
use contact_patch::run::{run_case, Outcome};
use contact_patch::solver::contact_newton::Probe;
use serde_json::{json, Value};

mod finite_common;
use finite_common::{assert_closed_where_pressed, two_blocks, write, MATCHING, NON_MATCHING};

/// The slave-normal discretization of `form` (`consistent` or `smooth_sliding`).
fn slave_normals(form: &str, passes: u8) -> Value {
    json!({"kind": "node_to_surface", "passes": passes, "normal": "slave", "slave_normal_variation": form})
}

/// The Newton tangent of `case` against central differences of its residual at the state
/// `u = rigid (top block) + a wavy field`, multipliers compressive: the largest difference
/// relative to the largest tangent entry, the scale, the unknowns and whether the tangent was
/// flagged symmetric.
fn tangent_error(case: &Value, rigid: [f64; 2], wave_size: f64) -> (f64, f64, usize, bool) {
    let (_dir, path) = write(case);
    let model = contact_patch::model::admit::load(&path).unwrap();
    let mut u = vec![0.0; model.dof_count];
    for (b, body) in model.bodies.iter().enumerate() {
        for (n, p) in body.mesh.nodes.iter().enumerate() {
            let k = (b * 1000 + n) as f64;
            // a wavy field: the facets bend and turn, the slave normals are not
            // perpendicular to the master facets
            let wave = [
                wave_size * (1.3 * k).sin() + 1e-2 * p[0] * p[1],
                wave_size * (0.7 * k).cos() - 1e-2 * p[0] * p[0],
            ];
            let shift = if b == 1 { rigid } else { [0.0, 0.0] };
            for i in 0..2 {
                u[body.dof(n, i)] = shift[i] + wave[i];
            }
        }
    }
    let mut probe = Probe::new(&model, 0.0).unwrap();
    let mut x = probe.unknowns(&u);
    let displacements = x.len();
    x.resize(probe.unknown_count(), 0.0);
    for (j, v) in x.iter_mut().enumerate().skip(displacements) {
        *v = 1e-3 * (1.0 + 0.3 * (j as f64).sin());
    }
    // a first evaluation at x covers the rows found there; the tangent is taken at the second
    let n = probe.evaluate(&x).unwrap().residual.len();
    assert_eq!(n, x.len());
    let at = probe.evaluate(&x).unwrap();
    let (worst, scale) = finite_common::tangent_difference(&mut probe, &x, &at);
    (worst, scale, n, at.symmetric)
}

/// The whole Newton tangent (neo-Hookean solids, slave-normal rows with their normals'
/// variation) against central differences of the residual, at a state where the top block has
/// slid 0.45 (about a master facet: its slave nodes sit on other facets than in the reference
/// configuration, and the rows are searched afresh at every perturbed state), penetrates by
/// about 0.03, every node moved off equilibrium by up to 2e-3; both forms, one and two passes,
/// penalty and Lagrange rows (compressive multipliers), Q4 (straight facets) and Q9 (curved).
/// The largest difference relative to the largest tangent entry must be below 1e-7 (measured:
/// see the output). The smooth-sliding form's tangent is flagged unsymmetric (solved by LU),
/// the consistent one's symmetric.
#[test]
fn the_newton_tangent_with_slave_normals_is_the_difference_of_the_residual() {
    for element in ["Q4", "Q9"] {
        for form in ["consistent", "smooth_sliding"] {
            for (passes, enforcement) in [
                (1, json!({"kind": "penalty", "kappa": 1e4})),
                (1, json!({"kind": "lagrange"})),
                (2, json!({"kind": "penalty", "kappa": 1e4})),
            ] {
                let case = two_blocks(
                    element,
                    &NON_MATCHING,
                    slave_normals(form, passes),
                    enforcement.clone(),
                    (0.45, -0.03),
                    1,
                );
                let (worst, scale, n, symmetric) = tangent_error(&case, [0.45, -0.03], 2e-3);
                println!(
                    "{element} {form} {passes}-pass {}: {n} unknowns, tangent vs central difference {worst:.1e} of {scale:.3e}, symmetric {symmetric}",
                    enforcement["kind"]
                );
                assert!(worst < 1e-7, "{element} {form} {passes}: {worst:e}");
                assert_eq!(symmetric, form == "consistent", "{element} {form}");
            }
        }
    }
}

/// Node-to-node at finite strain: the same check on blocks whose interface nodes match (the
/// top block's bottom nodes on the base's top nodes), moved by a wavy field that keeps every
/// slave node within a quarter facet of its master node: Q4 and Q9, penalty and Lagrange.
#[test]
fn the_newton_tangent_of_node_to_node_is_the_difference_of_the_residual() {
    for element in ["Q4", "Q9"] {
        for enforcement in [
            json!({"kind": "penalty", "kappa": 1e4}),
            json!({"kind": "lagrange"}),
        ] {
            let case = two_blocks(
                element,
                &MATCHING,
                json!({"kind": "node_to_node"}),
                enforcement.clone(),
                (0.0, -0.03),
                1,
            );
            let (worst, scale, n, symmetric) = tangent_error(&case, [0.02, -0.03], 2e-3);
            println!(
                "node-to-node {element} {}: {n} unknowns, tangent vs central difference {worst:.1e} of {scale:.3e}",
                enforcement["kind"]
            );
            assert!(worst < 1e-7, "{element}: {worst:e}");
            assert!(symmetric);
        }
    }
}

/// Node-to-node needs nodes that stay matched: a slave node that slides by more than half a
/// master facet is refused with the reason (each load step fails and is cut until the solve
/// gives up, naming the node); a reference mesh whose nodes do not match is refused before any
/// solve.
#[test]
fn node_to_node_refuses_nodes_that_no_longer_match() {
    let case = two_blocks(
        "Q4",
        &MATCHING,
        json!({"kind": "node_to_node"}),
        json!({"kind": "lagrange"}),
        (0.4, -0.05),
        2,
    );
    let (_dir, path) = write(&case);
    let err = run_case(&path, &mut |_| {}).unwrap_err().to_string();
    assert!(
        err.contains("no longer match") && err.contains("node_to_surface"),
        "{err}"
    );
    let case = two_blocks(
        "Q4",
        &NON_MATCHING,
        json!({"kind": "node_to_node"}),
        json!({"kind": "lagrange"}),
        (0.0, -0.05),
        2,
    );
    let (_dir, path) = write(&case);
    let err = run_case(&path, &mut |_| {}).unwrap_err().to_string();
    assert!(err.contains("do not match"), "{err}");
}

/// `r_{k+1} / r_k^2` and `r_{k+1} / r_k` over consecutive iterations of one load step with
/// `1e-12 < r_k < 1e-3` (the asymptotic range above the solver's round-off floor): how many
/// pairs, the largest quadratic ratio and the largest linear ratio.
fn rates(o: &Outcome) -> (usize, f64, f64) {
    const FLOOR: f64 = contact_patch::solver::contact_newton::FINITE_RESIDUAL_TOLERANCE;
    let history = &o.solution.finite.as_ref().unwrap().history;
    let (mut seen, mut quadratic, mut linear) = (0, 0.0f64, 0.0f64);
    for w in history.windows(2) {
        if w[0].step == w[1].step && w[0].residual < 1e-3 && w[0].residual > FLOOR {
            seen += 1;
            if w[1].residual > FLOOR {
                quadratic = quadratic.max(w[1].residual / (w[0].residual * w[0].residual));
            }
            linear = linear.max(w[1].residual / w[0].residual);
        }
    }
    (seen, quadratic, linear)
}

fn residuals(o: &Outcome) -> Vec<String> {
    o.solution
        .finite
        .as_ref()
        .unwrap()
        .history
        .iter()
        .map(|h| format!("{}:{:.1e}", h.step, h.residual))
        .collect()
}

/// The top block pressed into the base by 0.1 and slid by 0.9 (nearly two master facets) in 6
/// load steps, slave normals with Lagrange multipliers, Q4 and Q9: the consistent form
/// converges quadratically in every step (`r_{k+1} <= 100 r_k^2` once `r_k < 1e-3`), and after
/// the slide no slave node penetrates and every node carrying force has zero gap, measured
/// afresh along the slave normals in the deformed configuration (below 1e-10 of the size).
/// The smooth-sliding form: its tangent is the exact derivative of its own residual (the
/// central-difference test above), so Newton converges quadratically on it too; measured and
/// asserted the same way (see the output).
#[test]
fn a_block_slid_with_slave_normals_converges_quadratically() {
    for element in ["Q4", "Q9"] {
        for form in ["consistent", "smooth_sliding"] {
            let case = two_blocks(
                element,
                &NON_MATCHING,
                slave_normals(form, 1),
                json!({"kind": "lagrange"}),
                (0.9, -0.1),
                6,
            );
            let (_dir, path) = write(&case);
            let o = run_case(&path, &mut |_| {}).unwrap();
            assert!(o.passed(), "{element} {form}: {:?}", o.checks);
            let (seen, quadratic, linear) = rates(&o);
            let history = o.solution.finite.as_ref().unwrap();
            println!(
                "{element} {form}: {} attempts, {} cuts, {seen} pairs in the asymptotic range, largest r_k+1 / r_k^2 {quadratic:.2e}, largest r_k+1 / r_k {linear:.2e}, residuals {:?}",
                history.steps.len(),
                history.cuts,
                residuals(&o)
            );
            assert!(seen >= 6, "{element} {form}: too few iterations to judge");
            assert!(quadratic <= 100.0, "{element} {form}: {quadratic:e}");
            // measure afresh at X + u
            let mut moved = o.model.clone();
            for b in &mut moved.bodies {
                let off = b.dof_offset;
                for (n, p) in b.mesh.nodes.iter_mut().enumerate() {
                    p[0] += o.solution.u[off + 2 * n];
                    p[1] += o.solution.u[off + 2 * n + 1];
                }
            }
            let rows = constraints(&moved, &moved.contact[0]).unwrap();
            assert_closed_where_pressed(&o, &rows);
        }
    }
}

/// Why the smooth-sliding form needs its unsymmetric tangent: Newton iterations on its residual
/// (penalty, the block slid by 0.9 and pressed by 0.1, Q4) from the converged state with every
/// free displacement moved by up to 1e-3, once with the exact tangent (the probe's) and once
/// with its symmetric part `(K + K^T) / 2` (what a symmetric solver would factor), each step
/// solved densely (LU). The exact tangent converges quadratically (`r_{k+1} <= 100 r_k^2` in
/// the relative residual; measured 1, 2.7e-3, 3.7e-8, 1.0e-13); the symmetric part only
/// linearly: its ratios `r_{k+1} / r_k` stay between 1e-3 and 0.9 (measured: alternating near
/// 0.03 and 0.43, 11 iterations to 5.8e-12). The consistent form's tangent is symmetric, so
/// the two coincide there.
#[test]
fn the_smooth_sliding_form_converges_linearly_with_a_symmetric_tangent() {
    let slide = |steps: usize| {
        two_blocks(
            "Q4",
            &NON_MATCHING,
            slave_normals("smooth_sliding", 1),
            json!({"kind": "penalty", "kappa": 1e4}),
            (0.9, -0.1),
            steps,
        )
    };
    let (_dir, path) = write(&slide(6));
    let solved = run_case(&path, &mut |_| {}).unwrap();
    // the same case in one load step: the probe's system at the full load
    let (_dir1, path1) = write(&slide(1));
    let model = contact_patch::model::admit::load(&path1).unwrap();
    let mut probe = Probe::new(&model, 0.0).unwrap();
    let start: Vec<f64> = probe
        .unknowns(&solved.solution.u)
        .iter()
        .enumerate()
        .map(|(i, v)| v + 1e-3 * (1.7 * i as f64).sin())
        .collect();
    let n = start.len();
    assert_eq!(n, probe.unknown_count(), "penalty rows add no unknowns");
    let norm = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>().sqrt();
    let mut histories = Vec::new();
    for symmetric in [false, true] {
        let mut x = start.clone();
        probe.evaluate(&x).unwrap();
        let mut history = Vec::new();
        let mut r0 = None;
        for _ in 0..12 {
            let at = probe.evaluate(&x).unwrap();
            let r = norm(&at.residual);
            let r0 = *r0.get_or_insert(r);
            history.push(r / r0);
            // the round-off floor of the relative residual (the solver's tolerance)
            if r / r0 < 1e-12 {
                break;
            }
            let k = nalgebra::DMatrix::from_fn(n, n, |i, j| {
                if symmetric {
                    0.5 * (at.tangent[i][j] + at.tangent[j][i])
                } else {
                    at.tangent[i][j]
                }
            });
            let step = k
                .lu()
                .solve(&nalgebra::DVector::from_column_slice(&at.residual))
                .unwrap();
            x.iter_mut().zip(step.iter()).for_each(|(v, d)| *v -= d);
        }
        println!(
            "smooth sliding, {} tangent: relative residuals {:?}",
            if symmetric {
                "symmetric part of the"
            } else {
                "exact"
            },
            history
                .iter()
                .map(|r| format!("{r:.1e}"))
                .collect::<Vec<_>>()
        );
        histories.push(history);
    }
    let exact = &histories[0];
    assert!(*exact.last().unwrap() < 1e-12, "{exact:?}");
    for w in exact.windows(2) {
        if w[0] < 1e-2 && w[0] > 1e-12 {
            assert!(w[1] <= 100.0 * w[0] * w[0] + 1e-12, "{exact:?}");
        }
    }
    let symmetric = &histories[1];
    let ratios: Vec<f64> = symmetric.windows(2).map(|w| w[1] / w[0]).collect();
    println!("symmetric part: ratios r_k+1 / r_k {ratios:?}");
    // linear: every ratio after the first two within [1e-3, 0.9], and more iterations than the
    // exact tangent needed
    assert!(symmetric.len() > exact.len(), "{symmetric:?}");
    for r in &ratios[2..] {
        assert!((1e-3..=0.9).contains(r), "{ratios:?}");
    }
}
