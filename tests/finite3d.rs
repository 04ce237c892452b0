//! Finite deformation in 3D (total Lagrangian, neo-Hookean and St. Venant-Kirchhoff on Hex8,
//! Hex27, Tet4 and Tet10): the 2D driver (`solver::finite`, load steps of Newton's method) on
//! the 3D model, through the dimension-generic Newton contact system, against rigid planes and
//! spheres and between 3D bodies in the current geometry.
//!
//! * the homogeneous patch test: every boundary node of a distorted mesh prescribed by
//!   `x = F X`, so `F` and the Cauchy stress are exact at every quadrature point (1e-10), and
//!   the same with `R F` (objectivity: the stress rotates, `sigma(R F) = R sigma(F) R^T`) and
//!   with a pure rotation `R` (zero stress);
//! * the uniaxial neo-Hookean stretch with free lateral faces against its closed form;
//! * a block compressed onto a rigid plane (the homogeneous uniaxial state is exact) and a
//!   block pressed against a rigid sphere, penalty and Lagrange multipliers;
//! * the Newton tangent with a rigid sphere against a central difference of the residual, and
//!   quadratic convergence in the residual history;
//! * between two deformable bodies (node-to-surface, master normals, the facet gap's second
//!   derivative in the tangent): the Newton tangent against central differences with interior,
//!   edge and corner rows; the two-block contact patch test (matching and non-matching); a
//!   60-degree rigid turn of a clamped, bulging pair (objectivity); the penalty approaching
//!   Lagrange multipliers as `O(1/kappa)`; one element thick against the 2D plane-strain case;
//! * what is not built refused with the reason.

use contact_patch::fe::displacement_gradient_at;
use contact_patch::model::Model3;
use contact_patch::run::run_case3;
use contact_patch::run3d::{build3, Outcome3};
use contact_patch::solid::{lame, Voigt};
use contact_patch::solid_finite::Hyperelastic;
use contact_patch::solver::linear::Solution;
use nalgebra::{Matrix3, Vector3};
use serde_json::{json, Value};

mod finite_common;
use finite_common::{lateral_stretch, rotation, to_matrix, E, NU};

const ELEMENTS: [&str; 4] = ["Hex8", "Hex27", "Tet4", "Tet10"];
const MATERIALS: [&str; 2] = ["neo_hookean", "saint_venant_kirchhoff"];

fn law(material: &str) -> Hyperelastic {
    match material {
        "neo_hookean" => Hyperelastic::neo_hookean(E, NU),
        _ => Hyperelastic::saint_venant_kirchhoff(E, NU),
    }
}

/// A unit cube block on breaks `[0, 0.4, 1]` with interior nodes (and, with `faces`, nodes
/// inside the faces) moved: a distorted mesh.
fn block(element: &str, faces: bool) -> Value {
    let mut moves = vec![json!({"from": [0.4, 0.4, 0.4], "to": [0.47, 0.36, 0.43]})];
    if faces {
        moves.push(json!({"from": [0.4, 0.4, 1.0], "to": [0.35, 0.46, 1.0]}));
        moves.push(json!({"from": [0.0, 0.4, 0.4], "to": [0.0, 0.45, 0.33]}));
    }
    json!({"block3d": {"element": element, "x": [0, 0.4, 1], "y": [0, 0.4, 1],
        "z": [0, 0.4, 1], "moves": moves}})
}

fn scene(element: &str, material: &str, steps: usize, faces: bool) -> Value {
    json!({
        "name": "finite-3d",
        "materials": {"rubber": {"E": E, "nu": NU, "model": material}},
        "bodies": [{"name": "block", "material": "rubber", "mesh": block(element, faces)}],
        "physics": {"kinematics": "finite"},
        "solver": {"load_steps": steps},
        "supports": [{"body": "block", "set": "bottom", "z": 0.0}]
    })
}

fn parse(case: &Value) -> contact_patch::io::scene::Case {
    contact_patch::model::parse(&case.to_string(), "finite3d").unwrap()
}

fn run(case: &Value) -> Outcome3 {
    run_case3(&parse(case), "finite3d").unwrap_or_else(|e| panic!("{e}"))
}

/// `F` and the Cauchy stress (Voigt) at every stiffness quadrature point of every cell.
fn point_states(model: &Model3, u: &[f64]) -> Vec<(Matrix3<f64>, [f64; 6])> {
    let body = &model.bodies[0];
    let law = body.hyperelastic.expect("a hyperelastic body");
    let kind = body.mesh.kind;
    let mut dofs = Vec::new();
    let mut out = Vec::new();
    for c in 0..body.mesh.cell_count() {
        body.cell_dofs(c, &mut dofs);
        let ue: Vec<f64> = dofs.iter().map(|&d| u[d]).collect();
        let coords = body.mesh.cell_coords(c);
        for q in kind.stiffness_rule() {
            let (h, _) = displacement_gradient_at(kind, &coords, &ue, q.xi);
            out.push((
                Matrix3::identity() + h,
                Voigt::<3>::symmetric_components(&law.cauchy(&h)),
            ));
        }
    }
    out
}

/// The solve's residual tolerance under finite kinematics: a residual below it ends the
/// iteration, so the contraction into it is not measured.
const TOLERANCE: f64 = contact_patch::solver::contact_newton::FINITE_RESIDUAL_TOLERANCE;

/// The decade above the tolerance is the round-off floor of the stiffest rows (a penalty
/// `kappa A` ten times the element stiffness stalls near 1e-12): iterations into it are not
/// judged.
const FLOOR: f64 = 10.0 * TOLERANCE;

/// Newton's convergence order in the history: once the relative residual `r_k` is below 1e-3
/// (the asymptotic range), the next one in the same attempt is at most `r_k^1.5` (order 1.5
/// at least: a quadratic `r_k+1 = C r_k^2` meets it for `C <= r_k^-0.5`, 30 at 1e-3; a linear
/// rate fails it from `r_k = rate^2` down) unless it is at the floor ([`FLOOR`]). Returns how many
/// iterations were judged; prints the smallest order `ln r_k+1 / ln r_k` and the largest
/// `r_k+1 / r_k^2`.
fn assert_quadratic(solution: &Solution<3>) -> usize {
    let history = &solution.finite.as_ref().expect("a finite solve").history;
    let mut seen = 0;
    let (mut order, mut constant) = (f64::INFINITY, 0.0f64);
    for w in history.windows(2) {
        let (r0, r1) = (w[0].residual, w[1].residual);
        if w[0].step == w[1].step && r0 < 1e-3 {
            seen += 1;
            if r1 > FLOOR {
                order = order.min(r1.ln() / r0.ln());
                constant = constant.max(r1 / (r0 * r0));
            }
            assert!(
                r1 <= r0.powf(1.5).max(FLOOR),
                "step {}: residual {r1:e} after {r0:e} is not of order 1.5: {:?}",
                w[0].step,
                residuals(solution)
            );
        }
    }
    println!("  Newton: {seen} iterations judged, smallest order {order:.2}, largest r_k+1 / r_k^2 {constant:.2e}");
    seen
}

/// The residual history `attempt:residual`, and the reason of every cut attempt.
fn residuals(solution: &Solution<3>) -> Vec<String> {
    let finite = solution.finite.as_ref().unwrap();
    let mut out: Vec<String> = finite
        .history
        .iter()
        .map(|h| format!("{}:{:.1e}", h.step, h.residual))
        .collect();
    for s in finite.steps.iter().filter(|s| !s.accepted) {
        out.push(format!(
            "cut {} ({} to {}): {}",
            s.attempt,
            s.from,
            s.to,
            s.cut_because.as_deref().unwrap_or("")
        ));
    }
    out
}

/// The model of `element`/`material` with every boundary node prescribed by `x = F X`.
fn prescribed_everywhere(element: &str, material: &str, f: &Matrix3<f64>) -> Model3 {
    let mut model = build3(&parse(&scene(element, material, 8, true)), "finite3d").unwrap();
    let body = &model.bodies[0];
    let mut boundary: Vec<usize> = Vec::new();
    for set in ["left", "right", "front", "back", "bottom", "top"] {
        boundary.extend(&body.mesh.node_sets[set]);
    }
    let mut prescribed = vec![None; model.dof_count];
    for &n in &boundary {
        let x = Vector3::from(body.mesh.nodes[n]);
        let u = f * x - x;
        for i in 0..3 {
            prescribed[body.dof(n, i)] = Some(u[i]);
        }
    }
    model.prescribed = prescribed;
    model
}

/// The finite-strain patch test: every boundary node of a distorted mesh (interior and face
/// nodes moved) prescribed by the homogeneous deformation `x = F X` (stretches of 20 % and
/// -15 %, shears of 0.1), in eight load steps: the interior nodes follow, so `F` is exact at
/// every quadrature point (1e-10) and the stress is the material's Cauchy stress at `F`
/// (1e-10 relative), every element and both materials; Newton converges quadratically.
/// Objectivity on the same meshes: `x = R F X` (a rotation of 30 degrees about a skew axis)
/// gives `R sigma(F) R^T` (1e-10), and a pure rotation of 60 degrees no stress (1e-10 of `E`).
/// (The cells themselves are checked up to 90 degrees in `solid_finite`; here the first
/// iterate of a step leaves the interior behind the rotated boundary, and larger steps invert
/// cells there and are cut.)
#[test]
fn a_homogeneous_deformation_is_exact_and_objective_on_distorted_meshes() {
    let f = Matrix3::new(1.2, 0.1, 0.0, 0.05, 0.85, 0.1, 0.0, -0.1, 1.1);
    let r = rotation([0.3, -0.4, 1.0], 30f64.to_radians());
    let turn = rotation([1.0, 1.0, 1.0], 60f64.to_radians());
    for material in MATERIALS {
        let sigma = to_matrix(Voigt::<3>::symmetric_components(
            &law(material).cauchy(&(f - Matrix3::identity())),
        ));
        let scale = sigma.abs().max();
        for element in ELEMENTS {
            for (name, target, expected) in [
                ("F", f, sigma),
                ("R F", r * f, r * sigma * r.transpose()),
                ("R", turn, Matrix3::zeros()),
            ] {
                let model = prescribed_everywhere(element, material, &target);
                let solution = contact_patch::solver::finite::solve(&model, &mut |_| {}).unwrap();
                let (mut f_error, mut s_error) = (0.0f64, 0.0f64);
                for (fq, s) in point_states(&model, &solution.u) {
                    f_error = f_error.max((fq - target).abs().max());
                    s_error = s_error.max((to_matrix(s) - expected).abs().max());
                }
                let s_error = s_error / if name == "R" { E } else { scale };
                println!(
                    "{element} {material} x = {name} X: |F - F_exact| {f_error:.1e}, |sigma - sigma_exact| {s_error:.1e}, residuals {:?}",
                    residuals(&solution)
                );
                assert!(
                    f_error < 1e-10,
                    "{element} {material} {name}: F off by {f_error:e}"
                );
                assert!(
                    s_error < 1e-10,
                    "{element} {material} {name}: sigma off by {s_error:e}"
                );
                assert!(
                    assert_quadratic(&solution) >= 8,
                    "{element} {material} {name}: too few iterations to judge: {:?}",
                    residuals(&solution)
                );
            }
        }
    }
}

/// A neo-Hookean unit cube stretched by 50 % in z (top prescribed, rollers on the bottom,
/// left and front faces, the other faces free), in three load steps, against the closed form:
/// `F = diag(b, b, a)` with `b` from `sigma_xx = 0`, `sigma_zz = mu (a^2 - b^2) / (a b^2)`,
/// judged by the case's `uniform_stress_3d` check (1e-10) on the Cauchy stress of every
/// quadrature point, and `F` to 1e-10; the same compressed by 30 %.
#[test]
fn a_uniaxial_neo_hookean_stretch_has_its_closed_form() {
    let (_, mu) = lame(E, NU);
    for a in [1.5, 0.7] {
        let b = lateral_stretch(a);
        let sigma_zz = mu * (a * a - b * b) / (a * b * b);
        for element in ELEMENTS {
            let mut case = scene(element, "neo_hookean", 3, false);
            case["supports"] = json!([
                {"body": "block", "set": "bottom", "z": 0.0},
                {"body": "block", "set": "left", "x": 0.0},
                {"body": "block", "set": "front", "y": 0.0},
                {"body": "block", "set": "top", "z": a - 1.0}
            ]);
            case["checks"] = json!([{"check": "uniform_stress_3d",
                "stress": [0, 0, sigma_zz, 0, 0, 0], "tol": 1e-10}]);
            let o = run(&case);
            let target = Matrix3::from_diagonal(&Vector3::new(b, b, a));
            let f_error = point_states(&o.model, &o.solution.u)
                .iter()
                .fold(0.0f64, |m, (f, _)| m.max((f - target).abs().max()));
            println!(
                "{element} stretch {a}: b = {b:.12}, sigma_zz = {sigma_zz:.6}, stress error {:.1e}, |F - F_exact| {f_error:.1e}, residuals {:?}",
                o.checks[0].error,
                residuals(&o.solution)
            );
            assert!(o.passed(), "{element} {a}: {:?}", o.checks);
            assert!(f_error < 1e-10, "{element} {a}: {f_error:e}");
            assert_quadratic(&o.solution);
        }
    }
}

fn contact_case(element: &str, master: Value, enforcement: Value, top_z: f64) -> Value {
    let mut case = scene(element, "neo_hookean", 2, false);
    case["physics"]["contact_geometry"] = json!("current");
    case["solver"]["scheme"] = json!("newton");
    case["supports"] = json!([
        {"body": "block", "set": "bottom_front_left", "x": 0.0, "y": 0.0},
        {"body": "block", "set": "bottom_front_right", "y": 0.0},
        {"body": "block", "set": "top", "z": top_z}
    ]);
    case["contact"] = json!([{
        "name": "ground", "slave": {"body": "block", "set": "bottom"},
        "master": {"rigid": master},
        "discretization": {"kind": "node_to_surface", "passes": 1},
        "enforcement": enforcement
    }]);
    case
}

/// The resultant of the contact forces on the slave nodes.
fn contact_resultant(o: &Outcome3) -> [f64; 3] {
    let state = o.solution.contact.as_ref().expect("a contact solve");
    let mut total = [0.0; 3];
    for (r, f) in state.rows.iter().zip(&state.forces) {
        for i in 0..3 {
            total[i] += f * r.normal[i];
        }
    }
    total
}

/// A neo-Hookean unit cube between a rigid plane `z = 0` (frictionless node-to-surface
/// contact of its bottom, current geometry) and a top pushed down by 20 %, held in x and y at
/// two bottom corners: the homogeneous uniaxial state is exact. With Lagrange multipliers
/// `F = diag(b, b, 0.8)` (`b` from `sigma_xx = 0`) at every quadrature point to 1e-10; with
/// the penalty the bottom penetrates uniformly, so `F` is still uniform and diagonal (1e-10)
/// and `sigma_xx = sigma_yy = 0` (1e-10 of `sigma_zz`). Every element, except Tet10 with the
/// penalty: the node-based rows' tributary areas on its Tri6 facets are not the consistent
/// `int N_a dA` (zero at the corners), so a uniform penetration does not give the uniform
/// pressure and the state is not homogeneous (its spread is printed, 3.7e-3 measured). The
/// contact force balances the top's reaction (1e-10), and Newton converges quadratically.
#[test]
fn a_block_compressed_onto_a_rigid_plane_deforms_homogeneously() {
    let b = lateral_stretch(0.8);
    let plane = json!({"kind": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]});
    for enforcement in [
        json!({"kind": "lagrange"}),
        json!({"kind": "penalty", "kappa": 1e6}),
    ] {
        for element in ELEMENTS {
            let o = run(&contact_case(
                element,
                plane.clone(),
                enforcement.clone(),
                -0.2,
            ));
            assert!(o.converged(), "{element}");
            let states = point_states(&o.model, &o.solution.u);
            let first = states[0].0;
            let spread = states
                .iter()
                .fold(0.0f64, |m, (f, _)| m.max((f - first).abs().max()));
            let off_diagonal = (first - Matrix3::from_diagonal(&first.diagonal()))
                .abs()
                .max();
            let lateral = states
                .iter()
                .fold(0.0f64, |m, (_, s)| m.max(s[0].abs()).max(s[1].abs()));
            let axial = states.iter().fold(0.0f64, |m, (_, s)| m.max(s[2].abs()));
            let exact = if enforcement["kind"] == "lagrange" {
                (first - Matrix3::from_diagonal(&Vector3::new(b, b, 0.8)))
                    .abs()
                    .max()
            } else {
                0.0
            };
            // the top's reaction balances the contact force
            let body = &o.model.bodies[0];
            let reaction: f64 = body.mesh.node_sets["top"]
                .iter()
                .map(|&n| o.solution.reactions[body.dof(n, 2)])
                .sum();
            let contact = contact_resultant(&o);
            let balance = (reaction + contact[2]).abs() / contact[2].abs();
            println!(
                "{element} {}: F spread {spread:.1e}, |F - F_exact| {exact:.1e}, F_zz {:.12}, sigma_lateral / sigma_zz {:.1e}, balance {balance:.1e}, residuals {:?}",
                enforcement["kind"],
                first[(2, 2)],
                lateral / axial,
                residuals(&o.solution)
            );
            if !(element == "Tet10" && enforcement["kind"] == "penalty") {
                assert!(
                    spread < 1e-10 && off_diagonal < 1e-10,
                    "{element}: {spread:e}"
                );
                assert!(exact < 1e-10, "{element}: {exact:e}");
                assert!(lateral < 1e-10 * axial, "{element}: {lateral:e}");
            }
            assert!(axial > 10.0, "{element}: the block is compressed");
            assert!(balance < 1e-10, "{element}: {balance:e}");
            assert!(contact[0].abs() < 1e-10 * contact[2] && contact[1].abs() < 1e-10 * contact[2]);
            assert_quadratic(&o.solution);
        }
    }
}

/// The sphere case: the unit cube pushed up by `lift` (bottom held, prescribed in z) against
/// a rigid sphere of radius 1 that touches its top face at `(0.5, 0.5, 1)`; the top is the
/// slave.
fn sphere_case(element: &str, enforcement: Value, lift: f64, breaks: &[f64]) -> Value {
    json!({
        "name": "sphere-on-block",
        "materials": {"rubber": {"E": E, "nu": NU, "model": "neo_hookean"}},
        "bodies": [{"name": "block", "material": "rubber", "mesh": {"block3d": {
            "element": element, "x": breaks, "y": breaks, "z": [0, 0.5, 1]}}}],
        "physics": {"kinematics": "finite", "contact_geometry": "current"},
        "solver": {"load_steps": 3, "scheme": "newton"},
        "supports": [
            {"body": "block", "set": "bottom", "x": 0.0, "y": 0.0, "z": lift}
        ],
        "contact": [{
            "name": "indenter", "slave": {"body": "block", "set": "top"},
            "master": {"rigid": {"kind": "sphere", "centre": [0.5, 0.5, 2.0], "radius": 1.0}},
            "discretization": {"kind": "node_to_surface", "passes": 1},
            "enforcement": enforcement
        }]
    })
}

/// A rigid sphere pressed 0.1 (10 % of the height) into a neo-Hookean block (current
/// geometry, the sphere's gap second derivative in the tangent), Hex8 and Tet4: Newton
/// converges quadratically; the contact force balances the bottom's reaction (1e-10); with
/// Lagrange multipliers no active node penetrates (1e-10 of the indentation); on the
/// symmetric Hex8 mesh the x and y resultants vanish (1e-10); the penalty's force approaches
/// the Lagrange one as `O(1/kappa)`: its difference falls 5 to 20-fold from kappa 1e5 to 1e6.
#[test]
fn a_rigid_sphere_pressed_into_a_block_converges_quadratically_and_balances() {
    let breaks = [0.0, 0.2, 0.35, 0.45, 0.55, 0.65, 0.8, 1.0];
    let lift = 0.1;
    for element in ["Hex8", "Tet4"] {
        let mut forces = Vec::new();
        for enforcement in [
            json!({"kind": "lagrange"}),
            json!({"kind": "penalty", "kappa": 1e5}),
            json!({"kind": "penalty", "kappa": 1e6}),
        ] {
            let o = run(&sphere_case(element, enforcement.clone(), lift, &breaks));
            assert!(o.converged(), "{element}");
            let state = o.solution.contact.as_ref().unwrap();
            let active = state.active.iter().filter(|&&a| a).count();
            let body = &o.model.bodies[0];
            let reaction: [f64; 3] = std::array::from_fn(|i| {
                body.mesh.node_sets["bottom"]
                    .iter()
                    .map(|&n| o.solution.reactions[body.dof(n, i)])
                    .sum()
            });
            let contact = contact_resultant(&o);
            let balance = (0..3)
                .map(|i| (reaction[i] + contact[i]).abs())
                .fold(0.0, f64::max)
                / contact[2].abs();
            // the gaps of the active rows at the solution (current geometry)
            let worst_gap = state
                .gaps
                .iter()
                .zip(&state.active)
                .filter(|(_, &a)| a)
                .fold(0.0f64, |m, (g, _)| m.max(g.abs()));
            println!(
                "{element} {}: active {active} of {}, contact force {contact:?}, balance {balance:.1e}, largest active |gap| {worst_gap:.1e}, residuals {:?}",
                enforcement,
                state.rows.len(),
                residuals(&o.solution)
            );
            assert!(active >= 4, "{element}: {active}");
            assert!(
                contact[2] < 0.0,
                "{element}: the sphere pushes the top down"
            );
            assert!(balance < 1e-10, "{element}: {balance:e}");
            if element == "Hex8" {
                assert!(
                    contact[0].abs() < 1e-10 * contact[2].abs()
                        && contact[1].abs() < 1e-10 * contact[2].abs(),
                    "{element}: {contact:?}"
                );
            }
            if enforcement["kind"] == "lagrange" {
                assert!(worst_gap < 1e-10 * lift, "{element}: {worst_gap:e}");
            }
            assert!(
                assert_quadratic(&o.solution) >= 3,
                "{element}: too few iterations to judge"
            );
            forces.push(contact[2]);
        }
        let difference = |k: usize| (forces[k] - forces[0]).abs() / forces[0].abs();
        let ratio = difference(1) / difference(2);
        println!(
            "{element}: penalty vs Lagrange force {:.2e} (kappa 1e5), {:.2e} (1e6), ratio {ratio:.2}",
            difference(1),
            difference(2)
        );
        assert!((5.0..20.0).contains(&ratio), "{element}: {ratio}");
    }
}

/// The rigid sphere at kappa 1e7 (Tet4, the scene of the test above). Until issue 39's round-off
/// floor under finite kinematics, Newton stalled at a relative residual near 1e-11 with a fixed
/// active set (3.6e-11 to 6.6e-11, above the tolerance 1e-12) until the load-step cuts were
/// spent, and the run failed. The penalty forces `kappa A g` of gaps computed from positions
/// `X + u` are known only to `kappa A eps |X + u|`: that is the residual's floor, and the solve
/// now ends there, converged, with the force of the Lagrange solution to `O(1/kappa)` (the
/// difference falls about tenfold from kappa 1e6 to 1e7, as from 1e5 to 1e6 above).
#[test]
fn a_penalty_far_stiffer_than_the_block_converges_at_its_round_off_floor() {
    let breaks = [0.0, 0.2, 0.35, 0.45, 0.55, 0.65, 0.8, 1.0];
    let force = |enforcement: Value| {
        let o = run(&sphere_case("Tet4", enforcement.clone(), 0.1, &breaks));
        assert!(o.converged(), "{enforcement}");
        assert_eq!(
            o.solution.finite.as_ref().unwrap().cuts,
            0,
            "{enforcement}: no load step cut"
        );
        contact_resultant(&o)[2]
    };
    let lagrange = force(json!({"kind": "lagrange"}));
    let e6 = (force(json!({"kind": "penalty", "kappa": 1e6})) - lagrange).abs() / lagrange.abs();
    let e7 = (force(json!({"kind": "penalty", "kappa": 1e7})) - lagrange).abs() / lagrange.abs();
    println!("penalty vs Lagrange force: {e6:.2e} (kappa 1e6), {e7:.2e} (1e7)");
    assert!((5.0..20.0).contains(&(e6 / e7)), "{e6:e} / {e7:e}");
}

/// The tangent of the whole 3D Newton system (neo-Hookean solid plus penalty rows against a
/// rigid sphere, with the sphere's gap second derivative) is the central difference of its
/// residual at a deformed, penetrating state off equilibrium, to 1e-6 of its largest entry;
/// against a plane too.
#[test]
fn the_newton_tangent_with_a_rigid_sphere_is_the_difference_of_the_residual() {
    use contact_patch::solver::contact_newton::Probe;
    let breaks = [0.0, 0.3, 0.6, 1.0];
    for (element, enforcement) in [
        ("Hex8", json!({"kind": "penalty", "kappa": 1e4})),
        ("Tet10", json!({"kind": "penalty", "kappa": 1e4})),
        ("Hex8", json!({"kind": "lagrange"})),
    ] {
        let case = sphere_case(element, enforcement.clone(), 0.08, &breaks);
        let o = run(&case);
        assert!(o.converged());
        let model = build3(&parse(&case), "finite3d").unwrap();
        let mut probe = Probe::new(&model, 0.0).unwrap();
        // off equilibrium: the solution with a nonuniform disturbance
        let mut x = probe.unknowns_at(&o.solution.u, o.solution.contact.as_ref().unwrap());
        let n_u = probe.unknowns(&o.solution.u).len();
        for (i, v) in x.iter_mut().enumerate().take(n_u) {
            *v += 1e-3 * (0.7 * i as f64).sin() + 2e-3 * ((i % 3) as f64 - 1.0);
        }
        let at = probe.evaluate(&x).unwrap();
        let n = probe.unknown_count();
        let (worst, scale) = finite_common::tangent_difference(&mut probe, &x, &at);
        println!(
            "{element} {}: Newton tangent vs central difference {worst:.1e} of {scale:.3e} ({n} unknowns)",
            enforcement["kind"]
        );
        assert!(worst < 1e-6, "{element}: {worst:e}");
    }
}

/// What finite kinematics does not solve in 3D is refused with the reason.
#[test]
fn combinations_not_built_are_refused_with_the_reason() {
    let refused = |case: &Value, location: &str, words: &str| {
        let err = build3(&parse(case), "finite3d").unwrap_err().to_string();
        assert!(err.contains(location) && err.contains(words), "{err}");
    };
    // a linear elastic body under finite kinematics
    let mut case = scene("Hex8", "neo_hookean", 1, false);
    case["materials"]["rubber"]["model"] = json!("linear_elastic");
    refused(&case, "material", "needs a hyperelastic material");
    // a hyperelastic body under small strain
    let mut case = scene("Hex8", "neo_hookean", 1, false);
    case["physics"] = json!({});
    refused(&case, "materials.rubber.model", "needs finite kinematics");
    let plane = json!({"kind": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]});
    let lagrange = json!({"kind": "lagrange"});
    // contact without the Newton scheme or the current geometry
    let mut case = contact_case("Hex8", plane.clone(), lagrange.clone(), -0.1);
    case["solver"]["scheme"] = json!("active_set");
    refused(&case, "solver.scheme", "Newton scheme only");
    let mut case = contact_case("Hex8", plane.clone(), lagrange.clone(), -0.1);
    case["physics"]["contact_geometry"] = json!("reference");
    refused(&case, "physics.contact_geometry", "current configuration");
    // a tied pair
    let mut case = contact_case("Hex8", plane, lagrange, -0.1);
    case["contact"][0]["interaction"] = json!("tied");
    refused(
        &case,
        "interaction",
        "a tied pair under finite kinematics in 3D is not built",
    );
    // two deformable bodies
    let mut case = scene("Hex8", "neo_hookean", 1, false);
    case["bodies"] = json!([
        {"name": "base", "material": "rubber", "mesh": block("Hex8", false)},
        {"name": "punch", "material": "rubber", "mesh": {"block3d": {"element": "Hex8",
            "x": [0, 1], "y": [0, 1], "z": [1, 2]}}}
    ]);
    case["physics"]["contact_geometry"] = json!("current");
    case["solver"]["scheme"] = json!("newton");
    case["supports"] = json!([{"body": "base", "set": "bottom", "x": 0, "y": 0, "z": 0},
        {"body": "punch", "set": "top", "x": 0, "y": 0, "z": -0.1}]);
    case["contact"] = json!([{"name": "interface", "slave": {"body": "punch", "set": "bottom"},
        "master": {"body": "base", "set": "top"},
        "discretization": {"kind": "node_to_surface", "passes": 1},
        "enforcement": {"kind": "lagrange"}}]);
    assert!(build3(&parse(&case), "finite3d").is_ok());
    // mortar between the bodies is built (tests/finite3d_mortar.rs)
    case["contact"][0]["discretization"] = json!({"kind": "mortar"});
    assert!(build3(&parse(&case), "finite3d").is_ok());
    // node-to-node on these non-matching interfaces (tests/finite3d_mortar.rs runs matching ones)
    case["contact"][0]["discretization"] = json!({"kind": "node_to_node"});
    refused(
        &case,
        "contact[0] 'interface'.discretization",
        "do not match",
    );
    // small strain keeps refusing the Newton scheme and the current geometry
    let mut case = contact_case(
        "Hex8",
        json!({"kind": "plane", "point": [0, 0, 0],
        "normal": [0, 0, 1]}),
        json!({"kind": "lagrange"}),
        -0.1,
    );
    case["physics"] = json!({"contact_geometry": "current"});
    case["materials"]["rubber"]["model"] = json!("linear_elastic");
    refused(&case, "physics.contact_geometry", "under small strain");
}

/// A compression of 110 % cannot be reached: the load steps are cut until the cuts are spent,
/// and the error names the load step and the inverted cell (never a NaN answer).
#[test]
fn inverting_the_block_is_refused_by_name() {
    let mut case = scene("Hex8", "neo_hookean", 1, false);
    case["supports"] = json!([
        {"body": "block", "set": "bottom", "x": 0.0, "y": 0.0, "z": 0.0},
        {"body": "block", "set": "top", "z": -1.1}
    ]);
    let err = run_case3(&parse(&case), "finite3d")
        .unwrap_err()
        .to_string();
    println!("{err}");
    assert!(err.contains("load step") && err.contains("cuts"), "{err}");
    assert!(
        err.contains("det F") && err.contains("of body 'block' is inverted"),
        "{err}"
    );
}

/// `contact-patch run` on the block compressed onto a rigid plane (Hex8, Lagrange): the
/// `.vtu` holds the Cauchy stress `[xx, yy, zz, yz, xz, xy]` at every node, the uniaxial
/// closed form to 1e-12 relative, and `summary.json` the load steps and Newton history
/// (`finite`).
#[test]
fn the_run_command_writes_the_cauchy_stress_and_the_newton_history() {
    let (_, mu) = lame(E, NU);
    let b = lateral_stretch(0.8);
    let sigma_zz = mu * (0.64 - b * b) / (0.8 * b * b);
    let plane = json!({"kind": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]});
    let case = contact_case("Hex8", plane, json!({"kind": "lagrange"}), -0.2);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("case.json");
    std::fs::write(&path, case.to_string()).unwrap();
    let out = dir.path().join("out");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .arg("run")
        .arg(&path)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let vtu = std::fs::read_to_string(out.join("block.vtu")).unwrap();
    let start = vtu.find("Name=\"stress\"").expect("a stress array");
    let body = &vtu[start..];
    let values: Vec<f64> = body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()]
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(values.len(), 6 * 27);
    let expected = [0.0, 0.0, sigma_zz, 0.0, 0.0, 0.0];
    let worst = values
        .chunks(6)
        .flat_map(|s| (0..6).map(move |i| (s[i] - expected[i]).abs()))
        .fold(0.0, f64::max)
        / sigma_zz.abs();
    println!("vtu Cauchy stress against the closed form: {worst:.1e}");
    assert!(worst < 1e-12, "{worst:e}");
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["passed"], true);
    assert_eq!(summary["finite"]["steps"].as_array().unwrap().len(), 2);
    assert!(summary["finite"]["history"].as_array().unwrap().len() >= 4);
}

// ---------------------------------------------------------------------------------------------
// Contact between two deformable 3D bodies (node-to-surface, master normals, current geometry)

/// A base block `[0, 1]^2 x [0, 1]` of `element` on breaks `base` in x and y and a punch
/// `[0, 1]^2 x [1, 2]` on breaks `punch`, neo-Hookean (the same material): the base's bottom
/// held in z (x and y at two corners), the punch's top moved down by `press` (held in x and y
/// at two corners, where the homogeneous state does not move them); the punch's bottom (slave)
/// against the base's top (master), node-to-surface with `passes`, `enforcement`.
fn stacked(
    element: &str,
    base: &[f64],
    punch: &[f64],
    enforcement: Value,
    press: f64,
    passes: u8,
) -> Value {
    json!({
        "name": "stacked-3d",
        "materials": {"rubber": {"E": E, "nu": NU, "model": "neo_hookean"}},
        "bodies": [
            {"name": "base", "material": "rubber", "mesh": {"block3d": {
                "element": element, "x": base, "y": base, "z": [0, 0.5, 1]}}},
            {"name": "punch", "material": "rubber", "mesh": {"block3d": {
                "element": element, "x": punch, "y": punch, "z": [1, 1.5, 2]}}}
        ],
        "physics": {"kinematics": "finite", "contact_geometry": "current"},
        "solver": {"scheme": "newton", "load_steps": 4},
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
            "discretization": {"kind": "node_to_surface", "passes": passes},
            "enforcement": enforcement
        }]
    })
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

const MATCHING3: [f64; 3] = [0.0, 0.5, 1.0];
/// The punch's nodes on a finer grid than the base's (0.25, 0.8 inside the base's facets) that
/// holds the base's nodes: the one-pass node-to-surface rows then pass the contact patch test
/// (the slave nodes' tributary weights integrate the master's shape functions exactly).
const NESTED3: [f64; 5] = [0.0, 0.25, 0.5, 0.8, 1.0];
/// The base's grid bisected: nested for the tetrahedra too. The block mesher cuts every cell's
/// top face along its `+x +y` diagonal, so the base's Tet4 top triangles have edges along
/// `y = x` and `y = x - 0.5`, `y = x + 0.5`; on [`NESTED3`] the line `y = x - 0.5` crosses the
/// punch's cell `[0.5, 0.8] x [0.25, 0.5]` (through `(0.75, 0.25)`), so a master shape function
/// has a kink inside a slave triangle and the slave nodes' weights do not integrate it
/// exactly; on the bisected grid every master edge is a slave edge.
const BISECTED3: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];

/// The stacked pair of [`stacked`] held on symmetry planes instead of at two corners: `x = 0` on
/// both blocks' `left` faces and `y = 0` on their `front` faces (the homogeneous state
/// `u = ((b - 1) X, (b - 1) Y, ..)` satisfies both), with the base's bottom and the punch's top
/// carried along z as before. This takes away the sway of the blocks that the two corner nodes
/// leave free and under which the uniform state of the corner-held pair buckles
/// ([`the_corner_held_pair_buckles_and_the_pair_on_symmetry_planes_does_not`]).
fn stacked_on_symmetry_planes(
    element: &str,
    base: &[f64],
    punch: &[f64],
    enforcement: Value,
    press: f64,
    passes: u8,
) -> Value {
    let mut case = stacked(element, base, punch, enforcement, press, passes);
    case["supports"] = json!([
        {"body": "base", "set": "bottom", "z": 0.0},
        {"body": "base", "set": "left", "x": 0.0},
        {"body": "base", "set": "front", "y": 0.0},
        {"body": "punch", "set": "top", "z": press},
        {"body": "punch", "set": "left", "x": 0.0},
        {"body": "punch", "set": "front", "y": 0.0}
    ]);
    case
}

/// The finite-strain contact patch test between two deformable blocks: both compressed by
/// 20 % through a frictionless flat interface, where the homogeneous uniaxial state
/// `F = diag(b, b, 0.8)` (`b` from `sigma_xx = 0`) is exact in both; the pair held on symmetry
/// planes ([`stacked_on_symmetry_planes`]), where that state is a stable equilibrium. With
/// Lagrange multipliers the Cauchy stress is `sigma_zz` of the closed form at every quadrature
/// point of both bodies to 1e-10 of it: matching interfaces on Hex8, Tet4, Hex27 and Tet10, and
/// the nested non-matching interface on Hex8 and Hex27 ([`NESTED3`]) and on Tet4 (bisected,
/// [`BISECTED3`]); the penalty (matching on Hex8, Tet4 and Hex27, nested on Hex8, Hex27 and
/// bisected Tet4, and two passes on the matching Hex8 and Tet4 grids) gives the uniform stress
/// of a uniform penetration (spread 1e-10 relative).
///
/// Held at two corner nodes instead (the scene's supports until 2026-11-28) the pair buckles:
/// Hex27 ran out of load-step cuts with its iterates sliding the slave nodes off the master
/// nodes, which was the Newton iteration leaving an unstable equilibrium, not a defect of the
/// rows. The interfaces where the node-to-surface rows cannot pass (Tet4 on [`NESTED3`], the
/// Tet10 penalty) are in
/// [`the_interfaces_that_fail_the_patch_test_converge_to_a_kinked_surface`].
#[test]
fn the_two_block_contact_patch_test_transmits_a_uniform_pressure() {
    let (_, mu) = lame(E, NU);
    let b = lateral_stretch(0.8);
    let sigma_zz = mu * (0.64 - b * b) / (0.8 * b * b);
    let expected = [0.0, 0.0, sigma_zz, 0.0, 0.0, 0.0];
    let lagrange = json!({"kind": "lagrange"});
    let cases: [(&str, &[f64], &str); 7] = [
        ("Hex8", &MATCHING3, "matching"),
        ("Tet4", &MATCHING3, "matching"),
        ("Hex27", &MATCHING3, "matching"),
        ("Tet10", &MATCHING3, "matching"),
        ("Hex8", &NESTED3, "non-matching"),
        ("Hex27", &NESTED3, "non-matching"),
        ("Tet4", &BISECTED3, "non-matching bisected"),
    ];
    for (element, punch, interface) in cases {
        let o = run(&stacked_on_symmetry_planes(
            element,
            &MATCHING3,
            punch,
            lagrange.clone(),
            -0.4,
            1,
        ));
        assert!(o.converged(), "{element} {interface}");
        let error = stress_error(&all_stresses(&o), &expected);
        println!(
            "{element} {interface} lagrange: stress error {error:.1e} of sigma_zz {sigma_zz:.4}, residuals {:?}",
            residuals(&o.solution)
        );
        assert!(error < 1e-10, "{element} {interface}: {error:e}");
    }
    // the penalty: a uniform penetration, a uniform stress
    // (and with two passes on the matching grids: each slave node on a master node, both
    // ways)
    let penalty_cases: [(&str, &[f64], &str, u8); 8] = [
        ("Hex8", &MATCHING3, "matching", 1),
        ("Tet4", &MATCHING3, "matching", 1),
        ("Hex27", &MATCHING3, "matching", 1),
        ("Hex8", &NESTED3, "non-matching", 1),
        ("Hex27", &NESTED3, "non-matching", 1),
        ("Tet4", &BISECTED3, "non-matching bisected", 1),
        ("Hex8", &MATCHING3, "matching two-pass", 2),
        ("Tet4", &MATCHING3, "matching two-pass", 2),
    ];
    for (element, punch, interface, passes) in penalty_cases {
        let o = run(&stacked_on_symmetry_planes(
            element,
            &MATCHING3,
            punch,
            json!({"kind": "penalty", "kappa": 1e5}),
            -0.4,
            passes,
        ));
        assert!(o.converged(), "{element} {interface} penalty");
        let stresses = all_stresses(&o);
        let spread = stress_error(&stresses, &stresses[0]);
        println!(
            "{element} {interface} penalty: stress spread {spread:.1e}, sigma_zz {:.4} (Lagrange {sigma_zz:.4}), residuals {:?}",
            stresses[0][2],
            residuals(&o.solution)
        );
        assert!(spread < 1e-10, "{element} {interface}: {spread:e}");
        assert!(stresses[0][0].abs() < 1e-10 * sigma_zz.abs());
    }
}

/// The two-block scene of the patch test on the interfaces where one-pass node-to-surface
/// cannot transmit a uniform pressure: Tet4 on [`NESTED3`] (a master edge crosses slave
/// triangles, [`BISECTED3`]), Lagrange and penalty, and Tet10 with the penalty (the Tri6
/// slave's vertex and mid-edge weights, `2 A / 15` and `A / 5`, are not its consistent nodal
/// forces `0` and `A / 3` under a uniform pressure, so a uniform penetration is not an
/// equilibrium). Their discrete solution bends the master surface into shallow kinks under the
/// slave nodes on the diagonals, where the node's row on either facet pushes it across the
/// edge onto the other: Newton alternated between the two facets with a fixed residual (a
/// period-2 cycle at a relative 3e-10 to 2e-7, ten load cuts spent). Held by one facet within a
/// band around the edge (`SHARED_EDGE_HOLD`), and with the negative gap of a node behind a
/// concave edge, they converge; the stress is not uniform (the patch test fails, by a few
/// percent of `sigma_zz`), which is the finding the table reports, not a solver failure.
#[test]
fn the_interfaces_that_fail_the_patch_test_converge_to_a_kinked_surface() {
    let cases: [(&str, &[f64], Value); 3] = [
        ("Tet4", &NESTED3, json!({"kind": "lagrange"})),
        ("Tet4", &NESTED3, json!({"kind": "penalty", "kappa": 1e5})),
        (
            "Tet10",
            &MATCHING3,
            json!({"kind": "penalty", "kappa": 1e5}),
        ),
    ];
    for (element, punch, enforcement) in cases {
        let name = format!("{element} {}", enforcement["kind"]);
        let o = run(&stacked_on_symmetry_planes(
            element,
            &MATCHING3,
            punch,
            enforcement,
            -0.4,
            1,
        ));
        assert!(o.converged(), "{name}");
        assert!(o.warnings.is_empty(), "{name}: {:?}", o.warnings);
        let stresses = all_stresses(&o);
        let spread = stress_error(&stresses, &stresses[0]);
        println!(
            "{name}: stress spread {spread:.2e} of sigma_zz {:.4}, residuals {:?}",
            stresses[0][2],
            residuals(&o.solution)
        );
        assert!(spread > 1e-3 && spread < 0.2, "{name}: {spread:e}");
        assert_quadratic(&o.solution);
    }
}

/// The number of negative eigenvalues of the Newton system's tangent of `case` (Lagrange
/// multipliers) at its solution, less the number of multipliers: the saddle-point matrix
/// `[[A, B^T], [B, D]]` has one negative eigenvalue per multiplier plus one per direction of
/// negative stiffness of `A` on the kernel of the active rows `B` (Sylvester's law of inertia
/// on its block elimination), so 0 means a stable equilibrium and more an unstable one. Also
/// the eigenvalue nearest zero of those counted, and the solver's own verdict (the last
/// Newton iteration's `stability`) with its warnings.
fn unstable_directions(
    case: &Value,
) -> (
    usize,
    f64,
    Option<contact_patch::solver::newton::Stability>,
    Vec<String>,
) {
    let o = run(case);
    assert!(o.converged());
    let verdict = o
        .solution
        .finite
        .as_ref()
        .unwrap()
        .history
        .last()
        .unwrap()
        .stability;
    let state = o.solution.contact.as_ref().unwrap();
    // the tangent at the last load step's prescribed values: the model of one step
    let mut one_step = case.clone();
    one_step["solver"]["load_steps"] = json!(1);
    let model = build3(&parse(&one_step), "finite3d").unwrap();
    let mut probe = contact_patch::solver::contact_newton::Probe::new(&model, 0.0).unwrap();
    let x = probe.unknowns_at(&o.solution.u, state);
    let multipliers = x.len() - probe.unknowns(&o.solution.u).len();
    // a first evaluation at x covers the rows found there; the tangent is the second's
    probe.evaluate(&x).unwrap();
    let at = probe.evaluate(&x).unwrap();
    assert!(at.symmetric);
    let n = at.tangent.len();
    let matrix = nalgebra::DMatrix::from_fn(n, n, |i, j| at.tangent[i][j]);
    let mut eigenvalues: Vec<f64> = nalgebra::SymmetricEigen::new(matrix)
        .eigenvalues
        .iter()
        .copied()
        .collect();
    eigenvalues.sort_by(|a, b| a.total_cmp(b));
    let negative = eigenvalues.iter().filter(|v| **v < 0.0).count();
    (
        negative - multipliers,
        eigenvalues[multipliers],
        verdict,
        o.warnings.clone(),
    )
}

/// Why the stacked pair held at two corner nodes (the base's bottom and the punch's top each
/// held laterally at `bottom_front_left` / `top_front_left` and along y at the next corner)
/// leaves the uniform state: that state is a stable equilibrium at small compression and an
/// unstable one past a critical compression, the sway of two short columns whose ends slide
/// freely (the lowest mode moves every node along x, both blocks alike). Measured on the
/// matching Hex27 pair with Lagrange multipliers (`unstable_directions`): stable at 1 % and
/// 2.5 % (smallest eigenvalue of the stiffness on the active rows' kernel 0.16, then 0.10),
/// unstable at 5 % (-0.080) and 7 % (-0.30); the Hex8 pair, stiffer in bending, at 10 %
/// (-0.67). On symmetry planes ([`stacked_on_symmetry_planes`]) the sway is held and the
/// uniform state of the Hex27 pair at 20 % is stable (smallest eigenvalue 8.6). The solver
/// says the same of each (`stability` on the last Newton iteration, from the inertia of its
/// factorizations and the test of `LinearSolver::stability_at`) and warns of the unstable
/// ones; `contact-patch run` on the corner-held Hex8 pair at 20 % (which converges, its
/// iterates kept on the uniform state by the symmetry of mesh and load) prints the warning
/// and exits 0 (the answer balances the loads), the pair on symmetry planes does not warn.
#[test]
fn the_corner_held_pair_buckles_and_the_pair_on_symmetry_planes_does_not() {
    let lagrange = json!({"kind": "lagrange"});
    let corner_held = |element: &str, press: f64, steps: usize| {
        let mut case = stacked(element, &MATCHING3, &MATCHING3, lagrange.clone(), press, 1);
        case["solver"]["load_steps"] = json!(steps);
        case
    };
    let measured = [
        (
            "Hex27 held at corners, 2.5 %",
            corner_held("Hex27", -0.05, 2),
            0,
        ),
        (
            "Hex27 held at corners, 5 %",
            corner_held("Hex27", -0.1, 4),
            1,
        ),
        (
            "Hex8 held at corners, 10 %",
            corner_held("Hex8", -0.2, 8),
            1,
        ),
        (
            "Hex27 on symmetry planes, 20 %",
            stacked_on_symmetry_planes("Hex27", &MATCHING3, &MATCHING3, lagrange.clone(), -0.4, 1),
            0,
        ),
    ];
    for (what, case, expected) in measured {
        let (unstable, nearest, verdict, warnings) = unstable_directions(&case);
        println!("{what}: {unstable} unstable direction(s), the lowest stiffness {nearest:.3e}; the solver: {verdict:?}");
        assert_eq!(unstable, expected, "{what}: lowest stiffness {nearest:e}");
        let stable = contact_patch::solver::newton::Stability::Stable;
        let said_unstable = verdict != Some(stable);
        assert_eq!(said_unstable, expected > 0, "{what}: {verdict:?}");
        assert_eq!(
            warnings
                .iter()
                .any(|w| w.contains("not a stable equilibrium")),
            expected > 0,
            "{what}: {warnings:?}"
        );
    }
    let (code, stderr) = run_binary(&corner_held("Hex8", -0.4, 4));
    assert_eq!(code, Some(0), "{stderr}");
    assert!(
        stderr.contains("warning: the state the solve converged to is not a stable equilibrium"),
        "{stderr}"
    );
    let (code, stderr) = run_binary(&stacked_on_symmetry_planes(
        "Hex8",
        &MATCHING3,
        &MATCHING3,
        lagrange.clone(),
        -0.4,
        1,
    ));
    assert_eq!(code, Some(0), "{stderr}");
    assert!(!stderr.contains("stable equilibrium"), "{stderr}");
}

/// `contact-patch run` on `case`: the exit code and stderr; a panic fails the test.
fn run_binary(case: &Value) -> (Option<i32>, String) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("case.json");
    std::fs::write(&path, case.to_string()).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .args(["run", path.to_str().unwrap(), "--out"])
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!stderr.contains("panicked"), "a panic:\n{stderr}");
    (out.status.code(), stderr)
}

/// The two-block Hex27 scene on the matching interface held at two corner nodes (finite strain,
/// node-to-surface between the bodies, Lagrange multipliers, 20 % compression): its uniform
/// state is unstable past about 5 %
/// ([`the_corner_held_pair_buckles_and_the_pair_on_symmetry_planes_does_not`]), the Newton
/// iterates leave it, slide the slave nodes off the master nodes and invert a cell, so it runs
/// out of load-step cuts, and the binary says so with exit code 2 and a hint, without a panic;
/// the reason of the last cut is a diverging iterate (an inverted cell, or a pair carried out
/// of reach), never a pair that "could never act".
#[test]
fn the_hex27_two_block_scene_that_runs_out_of_cuts_is_an_error_not_a_panic() {
    let case = stacked(
        "Hex27",
        &MATCHING3,
        &MATCHING3,
        json!({"kind": "lagrange"}),
        -0.4,
        1,
    );
    let (code, stderr) = run_binary(&case);
    assert_eq!(code, Some(2), "{stderr}");
    for needle in ["error:", "load step", "cuts of the load increment", "hint:"] {
        assert!(stderr.contains(needle), "lacks {needle:?}:\n{stderr}");
    }
    assert!(!stderr.contains("could never act"), "{stderr}");
}

/// A block3d move that lifts a top-face node of the master off the face (above the rest of
/// the block) keeps the automatic `top` set: it is the block's top layer, not the top of the
/// bounding box. The pair's master surface has the four facets of the unmoved top and the
/// lifted node is on it, where the move put it.
#[test]
fn a_move_off_the_top_face_keeps_the_automatic_top_set() {
    let mut case = stacked(
        "Hex8",
        &MATCHING3,
        &MATCHING3,
        json!({"kind": "lagrange"}),
        -0.4,
        1,
    );
    case["bodies"][0]["mesh"]["block3d"]["moves"] =
        json!([{"from": [0.5, 0.5, 1.0], "to": [0.5, 0.5, 1.05]}]);
    let model = build3(&parse(&case), "finite3d").unwrap_or_else(|e| panic!("{e}"));
    let contact_patch::model::MasterSide::Body { body, facets } = &model.contact[0].master else {
        panic!("the master is body 'base'");
    };
    assert_eq!(facets.len(), 4);
    let mesh = &model.bodies[*body].mesh;
    let lifted = mesh.nearest_node([0.5, 0.5, 1.05]).unwrap();
    assert!(lifted.1 < 1e-14);
    assert!(facets
        .iter()
        .any(|&f| mesh.facet_nodes(f).contains(&lifted.0)));
}

/// The whole Newton system's tangent (neo-Hookean solids, node-to-surface rows between the two
/// bodies with the second derivative of their gaps) against central differences of its
/// residual, with closest points inside facets, on edges and at a corner of the master
/// surface: a Hex8 base whose top is deformed into a pyramid (its centre node raised by 0.15:
/// four convex ridges meeting at a convex apex) and a punch whose bottom nodes sit above the apex (held by
/// the corner), above the ridges (held by the edges) and, pressed in by 0.19, in the facets;
/// every node disturbed by a wavy field. Rows active with compressive forces: Lagrange
/// multipliers and the augmented Lagrangian (Uzawa multipliers given, so the edge and corner
/// rows, whose gap is a distance, are active too), and the penalty (the penetrating interior
/// rows). The largest difference relative to the largest tangent entry is below 1e-7.
#[test]
fn the_newton_tangent_between_3d_bodies_is_the_difference_of_the_residual() {
    for enforcement in [
        json!({"kind": "lagrange"}),
        json!({"kind": "augmented_lagrange", "kappa": 1e4}),
        json!({"kind": "penalty", "kappa": 1e4}),
    ] {
        let case = json!({
            "name": "pyramid",
            "materials": {"rubber": {"E": E, "nu": NU, "model": "neo_hookean"}},
            "bodies": [
                {"name": "base", "material": "rubber", "mesh": {"block3d": {"element": "Hex8",
                    "x": [0, 0.5, 1], "y": [0, 0.5, 1], "z": [0, 0.5, 1]}}},
                {"name": "punch", "material": "rubber", "mesh": {"block3d": {"element": "Hex8",
                    "x": [0.2, 0.5, 0.8], "y": [0.2, 0.5, 0.8], "z": [1.2, 1.7]}}}
            ],
            "physics": {"kinematics": "finite", "contact_geometry": "current"},
            "solver": {"scheme": "newton", "load_steps": 1},
            "supports": [
                {"body": "base", "set": "bottom", "x": 0.0, "y": 0.0, "z": 0.0},
                {"body": "punch", "set": "top", "x": 0.0, "y": 0.0, "z": 0.0}
            ],
            "contact": [{
                "name": "pyramid", "slave": {"body": "punch", "set": "bottom"},
                "master": {"body": "base", "set": "top"},
                "discretization": {"kind": "node_to_surface", "passes": 1},
                "enforcement": enforcement,
                "search_distance": 1.0
            }]
        });
        let model = build3(&parse(&case), "finite3d").unwrap();
        let mut u = vec![0.0; model.dof_count];
        for (b, body) in model.bodies.iter().enumerate() {
            for (n, p) in body.mesh.nodes.iter().enumerate() {
                let k = (b * 1000 + n) as f64;
                let wave = [
                    1e-3 * (1.3 * k).sin(),
                    1e-3 * (0.7 * k).cos(),
                    1e-3 * (0.9 * k).sin() + 5e-3 * p[0] * p[1],
                ];
                let mut shift = [0.0; 3];
                if b == 0 && p == &[0.5, 0.5, 1.0] {
                    // the apex of the pyramid
                    shift[2] = 0.15;
                }
                if b == 1 && p[2] < 1.25 && (p[0] - 0.5).abs() > 0.1 && (p[1] - 0.5).abs() > 0.1 {
                    // the punch's bottom nodes over the facets, pressed in
                    shift[2] = -0.19;
                }
                for i in 0..3 {
                    u[body.dof(n, i)] = shift[i] + wave[i];
                }
            }
        }
        // the rows at u, all active with compressive forces
        let rows = finite_common::rows_at3(&model, &u);
        // interior rows act on a facet's four nodes, edge rows on two, corner rows on one
        let master_nodes = |r: &contact_patch::contact::Constraint<3>| r.dofs.len() / 3 - 1;
        let count = |m: usize| rows.iter().filter(|r| master_nodes(r) == m).count();
        let (interior, edge, corner) = (count(4), count(2), count(1));
        assert!(
            interior >= 4 && edge >= 4 && corner >= 1,
            "{interior} {edge} {corner}"
        );
        assert!(rows.iter().all(|r| r.hessian.is_some()));
        let (worst, scale) = finite_common::tangent_difference_with_rows3(&model, &u, rows);
        println!(
            "{}: rows: {interior} interior, {edge} edge, {corner} corner; tangent vs central difference {worst:.1e} of {scale:.3e}",
            enforcement["kind"]
        );
        assert!(worst < 1e-7, "{}: {worst:e}", enforcement["kind"]);
    }
}

/// The Newton tangent against central differences of the residual where slave nodes hang past
/// the master surface's free boundary and are held by its boundary facets extended: the
/// stacked Hex8 and Tet4 pair with the punch shifted by 0.05 along x (its last row of bottom
/// nodes 0.05 past the base's top), pressed in by 0.01 and disturbed by a wavy field; every
/// row active (Lagrange multipliers with given forces; the penalty's rows penetrate). The
/// largest difference relative to the largest tangent entry is below 1e-7.
#[test]
fn the_newton_tangent_past_the_free_boundary_is_the_difference_of_the_residual() {
    let shifted = [0.05, 0.55, 1.05];
    for element in ["Hex8", "Tet4"] {
        for enforcement in [
            json!({"kind": "lagrange"}),
            json!({"kind": "penalty", "kappa": 1e4}),
        ] {
            let mut case = stacked(element, &MATCHING3, &MATCHING3, enforcement.clone(), 0.0, 1);
            case["bodies"][1]["mesh"]["block3d"]["x"] = json!(shifted);
            let model = build3(&parse(&case), "finite3d").unwrap();
            let mut u = vec![0.0; model.dof_count];
            for (b, body) in model.bodies.iter().enumerate() {
                for (n, p) in body.mesh.nodes.iter().enumerate() {
                    let k = (b * 1000 + n) as f64;
                    let press = if b == 1 { -0.01 } else { 0.0 };
                    let wave = [
                        1e-3 * (1.3 * k).sin(),
                        1e-3 * (0.7 * k).cos(),
                        press + 1e-3 * (0.9 * k).sin() * p[2] * (2.0 - p[2]),
                    ];
                    for (i, w) in wave.iter().enumerate() {
                        u[body.dof(n, i)] = *w;
                    }
                }
            }
            let rows = finite_common::rows_at3(&model, &u);
            // the slave nodes past x = 1 have rows (held by the facets extended)
            let past = rows.iter().filter(|r| r.point[0] > 1.02).count();
            assert!(past >= 3, "{element}: {past} rows past the free boundary");
            let n_rows = rows.len();
            let (worst, scale) = finite_common::tangent_difference_with_rows3(&model, &u, rows);
            println!(
                "{element} {}: {n_rows} rows, {past} past the free boundary; tangent vs central difference {worst:.1e} of {scale:.3e}",
                enforcement["kind"]
            );
            assert!(worst < 1e-7, "{element} {}: {worst:e}", enforcement["kind"]);
        }
    }
}

/// The punch's nodes off the base's: none on a master facet's edge (where the node-to-surface
/// gap has a kink across facets, and Newton's iterates swap facets at round-off).
const OFFSET3: [f64; 4] = [0.0, 0.3, 0.7, 1.0];

/// The stacked pair with the non-matching interface [`OFFSET3`] (Hex8, 4 load steps, with
/// `enforcement`) with the base's bottom and the punch's top clamped and carried by the linear
/// map `x = A X`, `A = diag(1, 1, 0.85)`: a 15 % compression between clamped faces, so the blocks
/// bulge and the interface slides (not a homogeneous state); the whole problem turned rigidly
/// by `R` (every reference position `X -> R X`, the faces carried by `R A R^T`, so every load
/// step is the turned one of the plain problem).
fn clamped(enforcement: Value, r: &Matrix3<f64>) -> (Model3, Solution<3>) {
    let mut case = stacked("Hex8", &MATCHING3, &OFFSET3, enforcement, 0.0, 1);
    case["solver"]["load_steps"] = json!(4);
    case["supports"] = json!([
        {"body": "base", "set": "bottom", "x": 0.0, "y": 0.0, "z": 0.0},
        {"body": "punch", "set": "top", "x": 0.0, "y": 0.0, "z": 0.0}
    ]);
    let model = build3(&parse(&case), "finite3d").unwrap();
    finite_common::turned_and_squeezed(model, r)
}

/// The total contact force on the slave nodes of a solution.
fn total_contact_force(solution: &Solution<3>) -> Vector3<f64> {
    let state = solution.contact.as_ref().unwrap();
    state
        .rows
        .iter()
        .zip(&state.forces)
        .map(|(r, f)| Vector3::from(r.normal) * *f)
        .sum()
}

/// Objectivity: the clamped, bulging stacked pair ([`clamped`]) turned rigidly as a whole by 60
/// degrees about `(1, 2, 3)` (facets, normals and sliding in no axis direction) gives the turned
/// answer: the displacements `u_R = R u` (1e-8 of the largest), the Cauchy stress
/// `sigma_R = R sigma R^T` at every quadrature point (1e-8 of the largest component), each slave
/// node's contact force unchanged in magnitude (1e-8 of the largest) and the resultant rotated.
#[test]
fn a_large_rigid_rotation_of_the_stacked_pair_leaves_the_contact_stress_unchanged() {
    let identity = Matrix3::identity();
    let r = rotation([1.0, 2.0, 3.0], std::f64::consts::FRAC_PI_3);
    let (model, plain) = clamped(json!({"kind": "lagrange"}), &identity);
    let (rotated_model, turned) = clamped(json!({"kind": "lagrange"}), &r);
    let scale_u = plain.u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst_x = 0.0f64;
    for body in &model.bodies {
        for n in 0..body.mesh.nodes.len() {
            let u1 = Vector3::from_fn(|i, _| plain.u[body.dof(n, i)]);
            let u2 = Vector3::from_fn(|i, _| turned.u[body.dof(n, i)]);
            worst_x = worst_x.max((r * u1 - u2).abs().max());
        }
    }
    let s1: Vec<[f64; 6]> = model
        .bodies
        .iter()
        .flat_map(|b| contact_patch::run3d::body_stresses(b, &plain.u))
        .map(|(_, s)| s)
        .collect();
    let s2: Vec<[f64; 6]> = rotated_model
        .bodies
        .iter()
        .flat_map(|b| contact_patch::run3d::body_stresses(b, &turned.u))
        .map(|(_, s)| s)
        .collect();
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
    let (c1, c2) = (
        plain.contact.as_ref().unwrap(),
        turned.contact.as_ref().unwrap(),
    );
    let scale_f = c1.forces.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst_f = 0.0f64;
    for (row, f) in c1.rows.iter().zip(&c1.forces) {
        let k = c2
            .rows
            .iter()
            .position(|q| q.slave_node == row.slave_node && q.pass == row.pass)
            .expect("the same slave nodes");
        worst_f = worst_f.max((c2.forces[k] - f).abs());
    }
    let (f1, f2) = (total_contact_force(&plain), total_contact_force(&turned));
    let worst_resultant = (r * f1 - f2).abs().max() / f1.norm();
    println!(
        "rotated 60 deg: |x_R - R x| {:.1e}, |sigma_R - R sigma R^T| {:.1e}, |f_R| - |f| {:.1e}, resultant {:.1e} (largest u {scale_u:.3}, sigma {scale_s:.1}, row force {scale_f:.2}, resultant {f1:?})",
        worst_x / scale_u,
        worst_s / scale_s,
        worst_f / scale_f,
        worst_resultant
    );
    assert!(scale_u > 0.1 && f1.norm() > 10.0, "a real compression");
    assert!(worst_x < 1e-8 * scale_u, "{worst_x:e}");
    assert!(worst_s < 1e-8 * scale_s, "{worst_s:e}");
    assert!(worst_f < 1e-8 * scale_f, "{worst_f:e}");
    assert!(worst_resultant < 1e-8, "{worst_resultant:e}");
}

/// The penalty's answer approaches the Lagrange one as `O(1/kappa)` on the clamped, bulging
/// pair ([`clamped`], a non-uniform contact pressure): the contact resultant's difference and
/// the largest displacement difference each fall 5- to 20-fold from kappa 1e5 to 1e6.
#[test]
fn the_penalty_approaches_lagrange_multipliers_as_one_over_kappa() {
    let identity = Matrix3::identity();
    let (_, lagrange) = clamped(json!({"kind": "lagrange"}), &identity);
    let reference = total_contact_force(&lagrange);
    let mut differences = Vec::new();
    for kappa in [1e5, 1e6] {
        let (_, penalty) = clamped(json!({"kind": "penalty", "kappa": kappa}), &identity);
        let force = (total_contact_force(&penalty) - reference).norm() / reference.norm();
        let displacement = penalty
            .u
            .iter()
            .zip(&lagrange.u)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        println!("kappa {kappa:e}: resultant {force:.2e}, displacement {displacement:.2e}");
        differences.push((force, displacement));
    }
    let ratios = (
        differences[0].0 / differences[1].0,
        differences[0].1 / differences[1].1,
    );
    println!(
        "ratios from kappa 1e5 to 1e6: resultant {:.2}, displacement {:.2}",
        ratios.0, ratios.1
    );
    assert!((5.0..20.0).contains(&ratios.0), "{ratios:?}");
    assert!((5.0..20.0).contains(&ratios.1), "{ratios:?}");
}

/// One element thick with every `u_y` held, the 3D node-to-surface rows are the 2D plane-strain
/// ones: the 2D two-block case of `tests/finite_contact.rs` (a Q4 base `[0, 3] x [0, 1]`, a
/// narrower top block on non-matching nodes slid by 0.25 and pressed by 0.04 in 3 load steps,
/// neo-Hookean, Lagrange multipliers) extruded into Hex8 over `y in [0, 1]` (the 2D thickness):
/// every node's displacement (x, z) is the 2D node's (x, y) to 1e-9 of the largest, and the
/// contact resultant the 2D one to 1e-9.
#[test]
fn one_element_thick_is_the_2d_plane_strain_finite_contact() {
    let (slide, press, steps) = (0.25, -0.04, 3);
    let case2 = finite_common::two_blocks(
        "Q4",
        &finite_common::NON_MATCHING,
        json!({"kind": "node_to_surface", "passes": 1}),
        json!({"kind": "lagrange"}),
        (slide, press),
        steps,
    );
    let (_dir, path) = finite_common::write(&case2);
    let two = contact_patch::run::run_case(&path, &mut |_| {}).unwrap_or_else(|e| panic!("{e}"));
    let case3 = json!({
        "name": "two-blocks-3d",
        "materials": {"m": {"E": E, "nu": NU, "model": "neo_hookean"}},
        "bodies": [
            {"name": "base", "material": "m", "mesh": {"block3d": {"element": "Hex8",
                "x": [0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0], "y": [0, 1], "z": [0, 0.5, 1]}}},
            {"name": "top", "material": "m", "mesh": {"block3d": {"element": "Hex8",
                "x": finite_common::NON_MATCHING, "y": [0, 1], "z": [1, 1.4, 1.8]}}}
        ],
        "physics": {"kinematics": "finite", "contact_geometry": "current"},
        "solver": {"scheme": "newton", "load_steps": steps},
        "supports": [
            {"body": "base", "set": "bottom", "x": 0.0, "z": 0.0},
            {"body": "top", "set": "top", "x": slide, "z": press},
            {"body": "base", "set": "all", "y": 0.0},
            {"body": "top", "set": "all", "y": 0.0}
        ],
        "contact": [{
            "name": "interface", "slave": {"body": "top", "set": "bottom"},
            "master": {"body": "base", "set": "top"},
            "discretization": {"kind": "node_to_surface", "passes": 1},
            "enforcement": {"kind": "lagrange"}
        }]
    });
    let three = run(&case3);
    assert!(three.converged());
    let scale = two.solution.u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0f64;
    for (b3, b2) in three.model.bodies.iter().zip(&two.model.bodies) {
        for (n, p) in b3.mesh.nodes.iter().enumerate() {
            let m = b2
                .mesh
                .nodes
                .iter()
                .position(|q| (q[0] - p[0]).abs() < 1e-12 && (q[1] - p[2]).abs() < 1e-12)
                .expect("the 2D node under the 3D one");
            for (i3, i2) in [(0, 0), (2, 1)] {
                let d = three.solution.u[b3.dof(n, i3)] - two.solution.u[b2.dof(m, i2)];
                worst = worst.max(d.abs());
            }
            assert_eq!(three.solution.u[b3.dof(n, 1)], 0.0);
        }
    }
    let state2 = two.solution.contact.as_ref().unwrap();
    let resultant2: [f64; 2] = std::array::from_fn(|i| {
        state2
            .rows
            .iter()
            .zip(&state2.forces)
            .map(|(r, f)| f * r.normal[i])
            .sum()
    });
    let resultant3 = contact_resultant(&three);
    let force_error = ((resultant3[0] - resultant2[0]).abs()
        + (resultant3[2] - resultant2[1]).abs())
        / resultant2[1].abs();
    println!(
        "3D one element thick vs 2D plane strain: displacement {:.1e} of {scale:.3}, resultant {force_error:.1e} ({resultant3:?} vs {resultant2:?})",
        worst / scale
    );
    assert!(resultant2[1].abs() > 1.0, "the blocks are pressed together");
    assert!(worst < 1e-9 * scale, "{worst:e}");
    assert!(force_error < 1e-9, "{force_error:e}");
}

/// Two passes (penalty, kappa 1e5) between the blocks compressed by 20 % with the punch's
/// nodes off the base's ([`OFFSET3`]): Newton converges, the contact forces of both passes
/// balance the punch top's reaction (1e-10), and the stress is near the uniform one (printed).
#[test]
fn two_passes_converge_and_balance() {
    let (_, mu) = lame(E, NU);
    let b = lateral_stretch(0.8);
    let sigma_zz = mu * (0.64 - b * b) / (0.8 * b * b);
    let penalty = json!({"kind": "penalty", "kappa": 1e5});
    let o = run(&stacked("Hex8", &MATCHING3, &OFFSET3, penalty, -0.4, 2));
    assert!(o.converged());
    let state = o.solution.contact.as_ref().unwrap();
    let passes: Vec<u8> = state.rows.iter().map(|r| r.pass).collect();
    assert!(passes.contains(&1) && passes.contains(&2));
    // the force on the punch: pass-1 rows push its nodes, pass-2 rows push the base's
    let mut on_punch = 0.0;
    for (r, f) in state.rows.iter().zip(&state.forces) {
        let sign = if r.pass == 1 { 1.0 } else { -1.0 };
        on_punch += sign * f * r.normal[2];
    }
    let punch = &o.model.bodies[1];
    let reaction: f64 = punch.mesh.node_sets["top"]
        .iter()
        .map(|&n| o.solution.reactions[punch.dof(n, 2)])
        .sum();
    let balance = (reaction + on_punch).abs() / reaction.abs();
    let error = stress_error(&all_stresses(&o), &[0.0, 0.0, sigma_zz, 0.0, 0.0, 0.0]);
    println!(
        "Hex8 two passes, penalty 1e5: punch force {on_punch:.6}, top reaction {reaction:.6}, balance {balance:.1e}, stress off the uniform Lagrange state {error:.1e}, residuals {:?}",
        residuals(&o.solution)
    );
    assert!(balance < 1e-10, "{balance:e}");
}
