//! CG preconditioned by smoothed-aggregation AMG (`solver.linear_solver: "cg_amg"`,
//! src/solver/amg.rs, src/solver/iterative.rs) against the direct solver.
//!
//! * The answers agree to the accuracy the tolerance implies: `||u_cg - u|| / ||u|| <=
//!   kappa_1(K) ||b - K u_cg|| / ||b||` (the 2-norm condition number of a symmetric matrix is
//!   at most its 1-norm one, estimated by `solver::conditioning`), on 2D Q4, Q9, T3, T6 and
//!   3D Hex8, Tet4 elasticity and on penalty and augmented Lagrangian contact (same active set,
//!   same iteration count).
//! * The V-cycle is symmetric (`x . M y = y . M x` to round-off) and positive definite.
//! * Iteration counts stay bounded under refinement (three levels, within a factor 1.5).
//! * What CG cannot solve is refused with the reason; a solve that misses its tolerance is an
//!   error (`not converged`).

use contact_patch::model::{parse, Model, Model3};
use contact_patch::solver::conditioning::condition_estimate_symmetric;
use contact_patch::solver::iterative::AmgSolver;
use contact_patch::solver::linear::{assemble, solve_elastic, Solution};
use contact_patch::solver::solve_static;
use contact_patch::solver::sparse::{Cholesky, UNLIMITED};
use serde_json::{json, Value};

fn model_of(case: &Value) -> Model {
    let text = case.to_string();
    Model::build(&parse(&text, "test").unwrap(), "test").unwrap()
}

fn model3_of(case: &Value) -> Model3 {
    let text = case.to_string();
    contact_patch::run3d::build3(&parse(&text, "test").unwrap(), "test").unwrap()
}

/// A plane-strain block clamped at its bottom under its weight and a pressure on its right:
/// a field that no element reproduces exactly.
fn elastic_case(element: &str, nx: usize, ny: usize) -> Value {
    json!({
        "name": format!("amg-{element}"),
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": 1000.0, "nu": 0.3}},
        "bodies": [{"name": "b", "material": "m", "mesh": {"block": {"element": element,
            "x": {"from": 0, "to": 2, "divisions": nx},
            "y": {"from": 0, "to": 1, "divisions": ny}}}}],
        "supports": [{"body": "b", "set": "bottom", "x": 0.0, "y": 0.0}],
        "loads": [{"body": "b", "body_force": [0.5, -2.0]},
                  {"body": "b", "set": "right", "pressure": 3.0}],
    })
}

fn elastic_case3(element: &str, n: usize) -> Value {
    json!({
        "name": format!("amg-{element}"),
        "materials": {"m": {"E": 200.0, "nu": 0.3}},
        "bodies": [{"name": "b", "material": "m", "mesh": {"block3d": {"element": element,
            "x": {"from": 0, "to": 2, "divisions": 2 * n},
            "y": {"from": 0, "to": 1, "divisions": n},
            "z": {"from": 0, "to": 1, "divisions": n}}}}],
        "supports": [{"body": "b", "set": "bottom", "x": 0.0, "y": 0.0, "z": 0.0}],
        "loads": [{"body": "b", "set": "top", "pressure": 2.0},
                  {"body": "b", "set": "right", "pressure": 1.0}],
    })
}

fn with_cg(case: &Value, tolerance: f64) -> Value {
    let mut case = case.clone();
    case["solver"]["linear_solver"] = json!("cg_amg");
    case["solver"]["linear_tolerance"] = json!(tolerance);
    case
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The 1-norm condition estimate of the model's stiffness `K_ff`.
fn condition<const D: usize, K: contact_patch::model::space::SolidCell<D>>(
    model: &contact_patch::model::Model<D, K>,
) -> f64 {
    let sys = assemble(model, &[]);
    let factor = Cholesky::analyse(&sys.pattern, &UNLIMITED)
        .unwrap()
        .factor(&sys.pattern, &sys.k)
        .unwrap();
    condition_estimate_symmetric(&sys.pattern, &sys.k, |b| factor.solve_in_place(b))
}

/// `u_cg` against `u` within the accuracy the reached residual implies; returns the
/// relative difference and the bound.
fn compare<const D: usize>(
    name: &str,
    cg: &Solution<D>,
    direct: &Solution<D>,
    kappa: f64,
) -> (f64, f64) {
    let record = cg.iterative.as_ref().expect("the CG record");
    assert!(
        direct.iterative.is_none(),
        "{name}: the direct run has no CG record"
    );
    let difference: Vec<f64> = cg.u.iter().zip(&direct.u).map(|(a, b)| a - b).collect();
    let relative = norm(&difference) / norm(&direct.u);
    // the direct answer has its own error, about kappa * 1e-16
    let bound = kappa * record.relative_residual + kappa * 1e-15;
    eprintln!(
        "{name}: {} equations, {} CG iterations, levels {:?}, residual {:.2e}, kappa {:.2e}: difference {relative:.2e} <= {bound:.2e}",
        cg.equations, record.iterations, record.levels, record.relative_residual, kappa
    );
    assert!(
        record.relative_residual <= record.tolerance,
        "{name}: residual"
    );
    assert!(
        relative <= bound,
        "{name}: difference {relative:.3e} above {bound:.3e}"
    );
    (relative, bound)
}

#[test]
fn elastic_answers_agree_with_the_direct_solver_2d() {
    for (element, nx, ny) in [
        ("Q4", 80, 40),
        ("Q9", 40, 20),
        ("T3", 80, 40),
        ("T6", 40, 20),
    ] {
        let case = elastic_case(element, nx, ny);
        let direct = solve_static(&model_of(&case), &mut |_| {}).unwrap();
        let model = model_of(&with_cg(&case, 1e-10));
        let cg = solve_static(&model, &mut |_| {}).unwrap();
        let record = cg.iterative.as_ref().unwrap();
        assert!(
            record.levels.len() >= 2,
            "{element}: the hierarchy has coarse levels"
        );
        compare(element, &cg, &direct, condition(&model));
    }
}

#[test]
fn elastic_answers_agree_with_the_direct_solver_3d() {
    for (element, n) in [("Hex8", 10), ("Tet4", 8)] {
        let case = elastic_case3(element, n);
        let model = model3_of(&case);
        let direct = solve_elastic(&model, &mut |_| {}).unwrap();
        let model = model3_of(&with_cg(&case, 1e-10));
        let cg = solve_elastic(&model, &mut |_| {}).unwrap();
        let record = cg.iterative.as_ref().unwrap();
        assert!(
            record.levels.len() >= 2,
            "{element}: the hierarchy has coarse levels"
        );
        compare(element, &cg, &direct, condition(&model));
    }
}

/// The cross-check's flat penalty block (node-to-surface, rigid line, partial load: it lifts
/// off), refined; and its augmented Lagrangian twin.
fn contact_case(nx: usize, ny: usize, enforcement: Option<Value>) -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/crosscheck/cases/contact/signorini-flat-penalty-q4.json"
    );
    let mut case: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let mesh = &mut case["bodies"][0]["mesh"]["block"];
    mesh["x"]["divisions"] = json!(nx);
    mesh["y"]["divisions"] = json!(ny);
    if let Some(e) = enforcement {
        case["contact"][0]["enforcement"] = e;
    }
    case
}

#[test]
fn penalty_contact_agrees_with_the_direct_solver() {
    let augmented = json!({"kind": "augmented_lagrange", "kappa": 1000.0});
    for (name, enforcement) in [("penalty", None), ("augmented Lagrangian", Some(augmented))] {
        let case = contact_case(120, 20, enforcement);
        let direct_model = model_of(&case);
        let direct = solve_static(&direct_model, &mut |_| {}).unwrap();
        let model = model_of(&with_cg(&case, 1e-11));
        let cg = solve_static(&model, &mut |_| {}).unwrap();
        let (cd, cc) = (
            direct.contact.as_ref().unwrap(),
            cg.contact.as_ref().unwrap(),
        );
        assert_eq!(cc.termination, cd.termination, "{name}: termination");
        assert_eq!(cc.active, cd.active, "{name}: the same active set");
        // the augmented Lagrangian stops when its multipliers settle, which the iterate's
        // accuracy may move by an iteration or two: its count is reported, not compared
        if name == "penalty" {
            assert_eq!(cc.iterations, cd.iterations, "{name}: the same iterations");
        }
        assert!(cc.history.iter().all(|r| r.linear_solver == "cg-amg"));
        let record = cg.iterative.as_ref().unwrap();
        assert_eq!(
            record.solves, cc.iterations,
            "{name}: one CG solve per iteration"
        );
        // the condition number of the last matrix, K plus the active rows' penalty
        let kappa = cd
            .history
            .last()
            .and_then(|r| r.condition_estimate)
            .expect("the direct loop estimates its last matrix");
        let bound = kappa * record.worst_relative_residual + kappa * 1e-15;
        let difference: Vec<f64> = cg.u.iter().zip(&direct.u).map(|(a, b)| a - b).collect();
        let relative = norm(&difference) / norm(&direct.u);
        eprintln!(
            "{name}: {} iterations (direct {}), {} CG iterations, {} setups, {} finest-level updates, difference {relative:.2e} <= {bound:.2e}",
            cc.iterations, cd.iterations, record.iterations, record.setups, record.finest_updates
        );
        assert!(
            relative <= bound,
            "{name}: difference {relative:.3e} above {bound:.3e}"
        );
        let forces: Vec<f64> = cc
            .forces
            .iter()
            .zip(&cd.forces)
            .map(|(a, b)| a - b)
            .collect();
        assert!(
            norm(&forces) <= bound * norm(&cd.forces) * 10.0,
            "{name}: forces"
        );
    }
}

/// `x . M y` and `y . M x` for pseudo-random `x`, `y`, and `x . M x`.
#[test]
fn the_v_cycle_is_symmetric_and_positive_definite() {
    for case in [elastic_case("Q4", 60, 30), elastic_case("Q9", 30, 15)] {
        let model = model_of(&with_cg(&case, 1e-10));
        let sys = assemble(&model, &[]);
        let mut amg = AmgSolver::new(&model, sys.constraints.free_dofs());
        let mut x0 = vec![0.0; sys.n];
        amg.solve(&sys.pattern, &sys.k, &sys.rhs, &mut x0).unwrap();
        let hierarchy = amg.hierarchy().expect("built");
        assert!(hierarchy.level_count() >= 2);
        let mut seed = 12345u64;
        let mut random = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for _ in 0..5 {
            let x: Vec<f64> = (0..sys.n).map(|_| random()).collect();
            let y: Vec<f64> = (0..sys.n).map(|_| random()).collect();
            let (mut mx, mut my) = (vec![0.0; sys.n], vec![0.0; sys.n]);
            hierarchy.apply(&x, &mut mx);
            hierarchy.apply(&y, &mut my);
            let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p * q).sum::<f64>();
            let (xmy, ymx) = (dot(&x, &my), dot(&y, &mx));
            let scale = norm(&x) * norm(&my);
            assert!(
                (xmy - ymx).abs() <= 1e-12 * scale,
                "x.My = {xmy:.15e}, y.Mx = {ymx:.15e}"
            );
            assert!(dot(&x, &mx) > 0.0, "x.Mx = {}", dot(&x, &mx));
        }
    }
}

#[test]
fn iterations_stay_bounded_under_refinement() {
    for element in ["Q4", "Q9"] {
        let counts: Vec<usize> = [40, 80, 160]
            .iter()
            .map(|&n| {
                let n = if element == "Q9" { n / 2 } else { n };
                let model = model_of(&with_cg(&elastic_case(element, 2 * n, n), 1e-10));
                let cg = solve_static(&model, &mut |_| {}).unwrap();
                let r = cg.iterative.unwrap();
                assert!(r.levels.len() >= 2, "{element}: a multigrid hierarchy");
                eprintln!(
                    "{element} {}: {} iterations, levels {:?}",
                    cg.equations, r.iterations, r.levels
                );
                r.iterations
            })
            .collect();
        let (least, most) = (*counts.iter().min().unwrap(), *counts.iter().max().unwrap());
        assert!(
            most as f64 <= 1.5 * least as f64,
            "{element}: iterations {counts:?} grow with the mesh"
        );
    }
}

#[test]
fn a_solve_that_misses_its_tolerance_is_an_error() {
    let mut case = with_cg(&elastic_case("Q4", 80, 40), 1e-12);
    case["solver"]["linear_max_iterations"] = json!(2);
    let e = solve_static(&model_of(&case), &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("not converged"), "{e}");
    assert!(e.contains("linear_max_iterations"), "{e}");
}

#[test]
fn what_cg_cannot_solve_is_refused_with_the_reason() {
    let refused = |case: Value, why: &str| {
        let text = case.to_string();
        let e = match Model::build(&parse(&text, "test").unwrap(), "test") {
            Err(e) => e.to_string(),
            Ok(model) => solve_static(&model, &mut |_| {}).unwrap_err().to_string(),
        };
        assert!(e.contains("is not built for") && e.contains(why), "{e}");
        assert!(e.contains("\"linear_solver\": \"direct\""), "{e}");
    };
    let lagrange = json!({"kind": "lagrange"});
    refused(
        with_cg(&contact_case(12, 4, Some(lagrange)), 1e-10),
        "Lagrange multipliers",
    );
    let elimination = json!({"kind": "elimination"});
    refused(
        with_cg(&contact_case(12, 4, Some(elimination)), 1e-10),
        "elimination",
    );
    let mut newton = with_cg(&contact_case(12, 4, None), 1e-10);
    newton["solver"]["scheme"] = json!("newton");
    refused(newton, "Newton scheme");
    let mut coulomb = with_cg(&contact_case(12, 4, None), 1e-10);
    coulomb["contact"][0]["interaction"] = json!({"coulomb": {"mu": 0.3}});
    coulomb["solver"]["scheme"] = json!("newton");
    refused(coulomb, "Coulomb friction");
    let mut finite = with_cg(&elastic_case("Q4", 4, 2), 1e-10);
    finite["physics"] = json!({"kinematics": "finite"});
    finite["materials"]["m"]["model"] = json!("neo_hookean");
    refused(finite, "finite kinematics");
    // a tolerance outside (0, 1) is bad input
    let text = with_cg(&elastic_case("Q4", 4, 2), 2.0).to_string();
    let e = Model::build(&parse(&text, "test").unwrap(), "test")
        .unwrap_err()
        .to_string();
    assert!(e.contains("solver.linear_tolerance"), "{e}");
}

/// The near-null space the hierarchy starts from: the rigid-body modes of the nodes'
/// coordinates (3 in 2D, 6 in 3D) are in the null space of a free body's stiffness.
#[test]
fn rigid_body_modes_are_the_null_space_of_a_free_body() {
    use contact_patch::solver::amg::{rigid_body_modes, CsrMatrix};
    fn check<const D: usize, K: contact_patch::model::space::SolidCell<D>>(
        name: &str,
        model: &contact_patch::model::Model<D, K>,
    ) {
        let sys = assemble(model, &[]);
        assert_eq!(sys.n, model.dof_count, "{name}: no supports");
        let (mut points, mut components) = (Vec::new(), Vec::new());
        for d in 0..model.dof_count {
            let owner = model.dof_owner(d).unwrap();
            let mut p = [0.0; 3];
            p[..D].copy_from_slice(&model.bodies[owner.body].mesh.nodes[owner.node]);
            points.push(p);
            components.push(owner.component);
        }
        let null = rigid_body_modes(&points, &components, D);
        assert_eq!(null.modes, if D == 2 { 3 } else { 6 });
        let k = CsrMatrix::from_symmetric_upper(&sys.pattern, &sys.k);
        let k_norm = k.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for mode in 0..null.modes {
            let b: Vec<f64> = (0..sys.n)
                .map(|e| null.values[e * null.modes + mode])
                .collect();
            let mut kb = vec![0.0; sys.n];
            k.mul(&b, &mut kb);
            let b_norm = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let worst = kb.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(
                worst <= 1e-12 * k_norm * b_norm * 30.0,
                "{name}: mode {mode}: |K b| = {worst:.3e}"
            );
        }
    }
    let mut free = elastic_case("Q9", 6, 3);
    free["supports"] = json!([]);
    check("Q9", &model_of(&free));
    let mut free3 = elastic_case3("Hex8", 3);
    free3["supports"] = json!([]);
    check("Hex8", &model3_of(&free3));
}

/// The coarsest level is factored within the case's `limits.factor_*`: above them the run
/// stops with the levels' sizes and what to change, instead of factoring at any cost.
#[test]
fn a_coarsest_level_above_the_case_limits_is_refused() {
    let mut case = with_cg(&elastic_case("Q4", 40, 20), 1e-10);
    // a limit on the factor's operations only: the case's gigabytes also bound the stored
    // matrix of a cg_amg solve (`check_work`), which 1e-7 GB would refuse before any level
    case["limits"] = json!({"factor_operations": 1.0});
    let e = solve_static(&model_of(&case), &mut |_| {})
        .unwrap_err()
        .to_string();
    for part in [
        "coarsest level of the multigrid hierarchy",
        "too large to factor",
        "limits.factor_gigabytes",
        "\"linear_solver\": \"direct\"",
    ] {
        assert!(e.contains(part), "{e}");
    }
    // the default limits let it through
    case.as_object_mut().unwrap().remove("limits");
    assert!(solve_static(&model_of(&case), &mut |_| {}).is_ok());
}
