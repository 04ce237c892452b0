//! Coulomb friction in the Newton scheme: penalty regularization (penalty and perturbed
//! Lagrangian normal laws) and Lagrange multipliers (tangential multipliers, semi-smooth Newton
//! over open/stick/slip sets)
//! (`src/contact/friction.rs`, `src/solver/contact_newton.rs`), every check against a closed
//! form:
//!
//! * the tangent of the contact system against central differences of its residual, at a stick
//!   and at a slip state (node-to-node, node-to-surface one- and two-pass, master and slave
//!   normals, rigid line and circle, standard and dual mortar);
//! * the frictional patch test (meshes A, D node-to-node; C, E node-to-surface one-pass): a
//!   uniform stress field `[0, -p, q]` loaded by its own tractions on every free boundary;
//!   `q < mu p` sticks (uniform stress exactly where the frictionless penalty passes the patch
//!   test), a prescribed tangential displacement of the punch top slips with `|lambda_t| = mu
//!   lambda_n` at every slave node (`mu p` per unit area where the frictionless test passes);
//! * the sliding limit of a block on an incline, `F/G = (tan a + mu) / (1 - mu tan a)`, with
//!   Coulomb's inequality and non-negative dissipation in every converged step;
//! * Newton's residual history with the consistent (unsymmetric) and the symmetrized tangent;
//! * with Lagrange multipliers: the tangent against central differences in stick and slip, the
//!   patch test (exact stress and no slip in stick, `|lambda_t| = mu lambda_n` to round-off in
//!   slip) with its Newton iteration counts, and the incline limit `F/G = 0.412371`.

use contact_patch::contact::friction::Status;
use contact_patch::io::scene::FrictionTangent;
use contact_patch::model::{parse, Model};
use contact_patch::run::{run_model, Outcome};
use contact_patch::solver::active_set::Termination;
use contact_patch::solver::contact_newton::Probe;
use serde_json::{json, Value};
use std::path::Path;

const P: f64 = 10.0;
const MU: f64 = 0.3;
const KAPPA: f64 = 1e4;

fn read(case: &str) -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(case);
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn build(v: &Value) -> contact_patch::Result<Model> {
    let case = parse(&v.to_string(), "friction")?;
    Model::build(&case, "friction")
}

fn run(v: &Value) -> Outcome {
    run_model(
        build(v).unwrap(),
        0.0,
        std::time::Instant::now(),
        &mut |_| {},
    )
    .unwrap()
}

fn termination(o: &Outcome) -> Termination {
    o.solution.contact.as_ref().unwrap().termination.clone()
}

/// How the punch top is loaded along x.
#[derive(Clone, Copy)]
enum Top {
    /// The traction of the uniform field (`q = sigma_xy`).
    Traction,
    /// Pressure `p` with the tangential displacement `d` prescribed.
    Displacement(f64),
}

/// A patch case with the uniform field `[0, -p, sxy]`, loaded along a path: in the first
/// step (of `steps >= 2`) the pressure `p` alone (on the punch top and the foundation's exposed
/// top), then the shear part of the field's traction `(sxy n_y, sxy n_x)` on every free
/// boundary of both bodies (the foundation's bottom along x too) in the later steps. The field
/// is then the exact solution of the bonded (stick) problem, and of the slip problem with
/// `sxy = mu p`. With one step, both at once.
fn patch(mesh: &str, nu: &str, discretization: Value, sxy: f64, top: Top, steps: usize) -> Value {
    let mut v = read(&format!("cases/patch/patch-{mesh}-nu{nu}.json"));
    let o = v.as_object_mut().unwrap();
    o.remove("sweep");
    o.remove("checks");
    // the patch case's expected failures name the checks removed here
    o.remove("expected_failures");
    v["exact"] = json!({"kind": "uniform_stress", "stress": [0.0, -P, sxy]});
    // normal first, then tangential
    let normal: Vec<f64> = vec![1.0; steps];
    let tangential: Vec<f64> = (1..=steps)
        .map(|k| {
            if steps == 1 {
                1.0
            } else {
                (k - 1) as f64 / (steps - 1) as f64
            }
        })
        .collect();
    let pressure =
        |body: &str, set: &str| json!({"body": body, "set": set, "pressure": P, "path": normal});
    let shear = |body: &str, set: &str, t: [f64; 2]| json!({"body": body, "set": set, "traction": [t[0] * sxy, t[1] * sxy], "path": tangential});
    let mut supports = vec![
        json!({"body": "foundation", "set": "bottom", "y": 0.0}),
        json!({"body": "foundation", "set": "bottom_left", "x": 0.0}),
    ];
    let mut loads = vec![
        pressure("punch", "top"),
        pressure("foundation", "exposed_left"),
        pressure("foundation", "exposed_right"),
        shear("punch", "left", [0.0, -1.0]),
        shear("punch", "right", [0.0, 1.0]),
        shear("foundation", "exposed_left", [1.0, 0.0]),
        shear("foundation", "exposed_right", [1.0, 0.0]),
        shear("foundation", "left", [0.0, -1.0]),
        shear("foundation", "right", [0.0, 1.0]),
        shear("foundation", "bottom", [-1.0, 0.0]),
    ];
    match top {
        Top::Traction => loads.push(shear("punch", "top", [1.0, 0.0])),
        Top::Displacement(d) => {
            supports.push(json!({"body": "punch", "set": "top", "x": d, "path": tangential}))
        }
    }
    v["supports"] = json!(supports);
    v["loads"] = json!(loads);
    v["contact"] = json!([{
        "name": "interface",
        "slave": {"body": "punch", "set": "bottom"},
        "master": {"body": "foundation", "set": "contact"},
        "discretization": discretization,
        "enforcement": {"kind": "penalty", "kappa": KAPPA},
        "interaction": {"coulomb": {"mu": MU}},
    }]);
    v["solver"] = json!({"scheme": "newton", "load_steps": steps});
    v
}

fn node_to_node() -> Value {
    json!({"kind": "node_to_node"})
}
fn node_to_surface() -> Value {
    json!({"kind": "node_to_surface", "passes": 1})
}
fn two_pass() -> Value {
    json!({"kind": "node_to_surface", "passes": 2})
}
fn slave_normals() -> Value {
    json!({"kind": "node_to_surface", "passes": 1, "normal": "slave"})
}
fn mortar(multiplier: &str) -> Value {
    json!({"kind": "mortar", "multiplier": multiplier})
}

/// Largest `|sigma - sigma_exact|` over the quadrature points of every body.
fn stress_error(o: &Outcome, exact: [f64; 3]) -> f64 {
    let mut e = 0.0f64;
    for b in &o.model.bodies {
        contact_patch::post::for_each_quadrature_stress(b, &o.solution.u, |_, _, s| {
            for k in 0..3 {
                e = e.max((s[k] - exact[k]).abs());
            }
        });
    }
    e
}

/// The frictional points of the last step: (status, lambda_t, lambda_n, area, direction).
fn points(o: &Outcome) -> Vec<(Status, f64, f64, f64, [f64; 2])> {
    let c = o.solution.contact.as_ref().unwrap();
    c.rows
        .iter()
        .zip(&c.friction)
        .map(|(r, f)| {
            let f = f.expect("a frictional row");
            (
                f.status,
                f.force[0],
                f.normal_force,
                r.area,
                r.tangents[0].direction,
            )
        })
        .collect()
}

/// The total tangential force on the slave body, x component.
fn tangential_x(o: &Outcome) -> f64 {
    points(o).iter().map(|p| p.1 * p.4[0]).sum()
}

#[test]
fn frictional_patch_test_sticks_below_the_cone_with_the_uniform_stress() {
    let q = 0.5 * MU * P;
    for (mesh, disc, exact_patch) in [
        ("A", node_to_node(), true),
        ("D", node_to_node(), true),
        ("A", node_to_surface(), true),
        ("C", node_to_surface(), false),
        ("E", node_to_surface(), false),
    ] {
        let o = run(&patch(mesh, "0.3", disc.clone(), q, Top::Traction, 2));
        assert_eq!(termination(&o), Termination::Converged, "{mesh} {disc}");
        let pts = points(&o);
        assert!(pts.iter().all(|p| p.0 == Status::Stick), "{mesh} {disc}");
        // the tangential forces carry the applied tangential load 2 q (equilibrium of the punch)
        let t = tangential_x(&o);
        assert!((t + 2.0 * q).abs() <= 1e-10 * 2.0 * q, "{mesh} {disc}: {t}");
        for p in &pts {
            assert!(p.1.abs() <= MU * p.2 * (1.0 + 1e-12));
        }
        // the first step pressed the punch without tangential force: every point stuck
        let steps = &o.solution.contact.as_ref().unwrap().steps;
        let first = steps[0].friction.as_ref().unwrap();
        assert_eq!(first.stick, pts.len());
        assert!(first.tangential_force[0].abs() <= 1e-10 * P, "{first:?}");
        let e = stress_error(&o, [0.0, -P, q]) / P;
        println!("stick, mesh {mesh}, {disc}: stress error {e:.1e} p");
        if exact_patch {
            assert!(e < 1e-8, "{mesh} {disc}: stress error {e:e}");
        } else {
            // one-pass node-to-surface on non-matching meshes fails the frictionless patch test
            // (reports/patch-table.md: 4e-2 on C, 6e-2 on E with the penalty); friction keeps
            // that error, it does not add one of its own order
            assert!(e < 0.15, "{mesh} {disc}: stress error {e:e}");
        }
    }
}

#[test]
fn frictional_patch_test_slips_with_traction_mu_p_under_a_prescribed_tangential_displacement() {
    let sxy = MU * P;
    for (mesh, disc, exact_patch) in [
        ("A", node_to_node(), true),
        ("D", node_to_node(), true),
        ("A", node_to_surface(), true),
        ("C", node_to_surface(), false),
        ("E", node_to_surface(), false),
    ] {
        let o = run(&patch(
            mesh,
            "0.0",
            disc.clone(),
            sxy,
            Top::Displacement(0.05),
            2,
        ));
        assert_eq!(termination(&o), Termination::Converged, "{mesh} {disc}");
        let pts = points(&o);
        let normal: f64 = pts.iter().map(|p| p.2).sum();
        for p in &pts {
            assert_eq!(p.0, Status::Slip, "{mesh} {disc}");
            // Coulomb's law holds to round-off at every slave node, against the motion (+x)
            assert!(
                (p.1.abs() - MU * p.2).abs() <= 1e-12 * MU * P,
                "{mesh} {disc}"
            );
            assert!(p.1 * p.4[0] < 0.0);
            if exact_patch {
                // and the traction is mu p at every node where the patch test passes
                assert!(
                    (p.1.abs() / p.3 - MU * P).abs() <= 1e-9 * MU * P,
                    "{mesh} {disc}: {}",
                    p.1 / p.3
                );
            }
        }
        // the pressures sum to the load 2 p; the tangential forces to mu times that
        assert!((normal - 2.0 * P).abs() <= 1e-10 * P, "{mesh} {disc}");
        let t = tangential_x(&o);
        assert!((t + 2.0 * MU * P).abs() <= 1e-10 * P, "{mesh} {disc}: {t}");
        let e = stress_error(&o, [0.0, -P, sxy]) / P;
        println!("slip, mesh {mesh}, {disc}: stress error {e:.1e} p");
        if exact_patch {
            assert!(e < 1e-8, "{mesh} {disc}: stress error {e:e}");
        } else {
            assert!(e < 0.15, "{mesh} {disc}: stress error {e:e}");
        }
        let s = o.solution.contact.as_ref().unwrap().steps.clone();
        for step in &s {
            let f = step.friction.as_ref().unwrap();
            assert!(f.dissipation >= 0.0 && f.max_cone_ratio <= 1.0 + 1e-12);
        }
        // pressed without sliding in the first step, sliding with dissipation in the last
        assert_eq!(s[0].friction.as_ref().unwrap().slip, 0);
        let last = s.last().unwrap().friction.as_ref().unwrap();
        assert!(last.dissipation > 0.0);
    }
}

/// A block `[0, 2] x [0, 1]` on a rigid master, loaded by a uniform body force: the weight `G`
/// and a horizontal push `F` of an incline at angle `a`, written in the incline's frame (the
/// rigid line is `y = 0`).
fn incline(f_over_g: f64, tan_a: f64, steps: usize) -> Value {
    let g = 10.0;
    let (s, c) = (
        tan_a / (1.0 + tan_a * tan_a).sqrt(),
        1.0 / (1.0 + tan_a * tan_a).sqrt(),
    );
    let f = f_over_g * g;
    let area = 2.0;
    json!({
        "name": "incline",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": 1000.0, "nu": 0.3}},
        "bodies": [{"name": "block", "material": "m",
            "mesh": {"block": {"element": "Q4", "x": [0, 0.5, 1, 1.5, 2], "y": [0, 0.5, 1]}}}],
        "supports": [],
        "loads": [{"body": "block", "body_force": [(f * c - g * s) / area, -(g * c + f * s) / area]}],
        "contact": [{
            "name": "base",
            "slave": {"body": "block", "set": "bottom"},
            "master": {"rigid": {"kind": "line", "point": [0.0, 0.0], "normal": [0.0, 1.0]}},
            "discretization": {"kind": "node_to_surface", "passes": 1},
            "enforcement": {"kind": "penalty", "kappa": 1e5},
            "interaction": {"coulomb": {"mu": MU}},
        }],
        "solver": {"scheme": "newton", "load_steps": steps},
    })
}

#[test]
fn a_block_on_an_incline_slides_at_the_coulomb_limit() {
    let tan_a: f64 = 0.1;
    let limit = (tan_a + MU) / (1.0 - MU * tan_a);
    assert!((limit - 0.412371).abs() < 1e-6);
    let (s, c) = (
        tan_a / (1.0 + tan_a * tan_a).sqrt(),
        1.0 / (1.0 + tan_a * tan_a).sqrt(),
    );
    for ratio in [0.5, 0.98, 0.995] {
        let o = run(&incline(ratio * limit, tan_a, 4));
        assert_eq!(
            termination(&o),
            Termination::Converged,
            "F/G = {ratio} limit"
        );
        let state = o.solution.contact.as_ref().unwrap();
        // Coulomb's inequality and non-negative dissipation in every converged step
        assert_eq!(state.steps.len(), 4);
        for step in &state.steps {
            let f = step.friction.as_ref().unwrap();
            assert!(f.max_cone_ratio <= 1.0 + 1e-12, "{f:?}");
            assert!(f.dissipation >= 0.0, "{f:?}");
        }
        // the contact forces carry the load along and across the incline
        let (g, f) = (10.0, ratio * limit * 10.0);
        let tangential = tangential_x(&o);
        let normal: f64 = points(&o).iter().map(|p| p.2).sum();
        assert!(
            (tangential + (f * c - g * s)).abs() <= 1e-9 * g,
            "{tangential}"
        );
        assert!((normal - (g * c + f * s)).abs() <= 1e-9 * g, "{normal}");
        assert!(tangential.abs() <= MU * normal * (1.0 + 1e-12));
        let last = state.steps.last().unwrap().friction.clone().unwrap();
        println!(
            "F/G = {ratio} x limit: stick {}, slip {}, |T|/(mu N) = {:.6}",
            last.stick,
            last.slip,
            tangential.abs() / (MU * normal)
        );
    }
    // just past the limit no equilibrium exists: the block slides away
    let o = run(&incline(1.01 * limit, tan_a, 4));
    assert_ne!(termination(&o), Termination::Converged);
}

#[test]
fn on_a_load_path_the_block_starts_to_slide_at_the_coulomb_limit() {
    // the weight first, then the push ramped across the limit: the solve converges in every
    // step below it, up to 0.999 of it, and stops at the first step past it, saying that the
    // friction cannot hold the load (issue 39)
    let tan_a: f64 = 0.1;
    let limit = (tan_a + MU) / (1.0 - MU * tan_a);
    let ramp = [
        0.0, 0.25, 0.5, 0.75, 0.9, 0.97, 0.99, 0.998, 0.999, 1.005, 1.02,
    ];
    let (g, area) = (10.0, 2.0);
    let (s, c) = (
        tan_a / (1.0 + tan_a * tan_a).sqrt(),
        1.0 / (1.0 + tan_a * tan_a).sqrt(),
    );
    let f = limit * g;
    let mut v = incline(0.0, tan_a, ramp.len());
    v["loads"] = json!([
        {"body": "block", "body_force": [-g * s / area, -g * c / area], "path": vec![1.0; ramp.len()]},
        {"body": "block", "body_force": [f * c / area, -f * s / area], "path": ramp},
    ]);
    let o = run(&v);
    let steps = &o.solution.contact.as_ref().unwrap().steps;
    let past = ramp.iter().position(|&r| r > 1.0).unwrap();
    assert_eq!(steps.len(), past + 1, "{steps:?}");
    for (k, step) in steps.iter().enumerate() {
        if k < past {
            assert_eq!(step.termination, Termination::Converged, "step {}", k + 1);
            let fr = step.friction.as_ref().unwrap();
            assert!(fr.max_cone_ratio <= 1.0 + 1e-12, "{fr:?}");
            assert!(fr.dissipation >= 0.0, "{fr:?}");
            // the tangential forces carry the tangential load of the step
            let load = ramp[k] * f * c - g * s;
            assert!((fr.tangential_force[0] + load).abs() <= 1e-9 * g, "{fr:?}");
        } else {
            assert_ne!(step.termination, Termination::Converged);
        }
    }
    let said: Vec<&String> = o
        .warnings
        .iter()
        .filter(|w| w.contains("the frictional forces cannot hold the load"))
        .collect();
    assert_eq!(said.len(), 1, "{:?}", o.warnings);
    assert!(
        said[0].contains(&format!("load step {}", past + 1)),
        "{}",
        said[0]
    );
    // the ratio of the tangential load to mu times the normal load, in the incline's frame
    let at = ramp[past];
    let ratio = (at * f * c - g * s) / (MU * (g * c + at * f * s));
    assert!(
        said[0].contains(&format!("ratio {ratio:.6}")),
        "{ratio}: {}",
        said[0]
    );
    // no remedy that cannot help (a softer penalty, more iterations)
    assert!(
        o.warnings.iter().all(|w| !w.contains("lower kappa")),
        "{:?}",
        o.warnings
    );
    // under its weight alone (tan a < mu) the block holds; an edge node may slip locally
    // (Poisson's expansion against friction), as the counts show
    let first = steps[0].friction.as_ref().unwrap();
    assert!(first.stick > first.slip, "{first:?}");
}

/// A block `[0, 2] x [0, 1]` pressed by `p` onto a rigid master and dragged by a prescribed
/// displacement `d` of its top along x (`nu = 0`: no Poisson expansion for friction to resist,
/// so a small `d` sticks at every point).
fn dragged(master: Value, d: f64) -> Value {
    json!({
        "name": "dragged",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": 1000.0, "nu": 0.0}},
        "bodies": [{"name": "block", "material": "m",
            "mesh": {"block": {"element": "Q4", "x": [0, 0.5, 1, 1.5, 2], "y": [0, 0.5, 1]}}}],
        "supports": [{"body": "block", "set": "top", "x": d}],
        "loads": [{"body": "block", "set": "top", "pressure": P}],
        "contact": [{
            "name": "base",
            "slave": {"body": "block", "set": "bottom"},
            "master": {"rigid": master},
            "discretization": {"kind": "node_to_surface", "passes": 1},
            "enforcement": {"kind": "penalty", "kappa": 1e4},
            "interaction": {"coulomb": {"mu": MU}},
        }],
        "solver": {"scheme": "newton"},
    })
}

/// Largest difference between the tangent's columns and central differences of the residual,
/// relative to the largest tangent entry.
fn fd_error(model: &Model, o: &Outcome, expect: Status) -> f64 {
    let mut probe = Probe::new(model, 0.0).unwrap();
    let x = probe.unknowns_at(&o.solution.u, o.solution.contact.as_ref().unwrap());
    let at = probe.evaluate(&x).unwrap();
    // every closed point in the expected status (open points may stay open)
    let same = |st: &[Status]| st.iter().all(|&s| s == expect || s == Status::Open);
    assert!(same(&at.statuses), "{:?}", at.statuses);
    assert!(at.statuses.contains(&expect));
    // Laursen & Simo's form is symmetric in slip too; the others only in stick
    let laursen_simo = model.solver.friction_tangent == FrictionTangent::LaursenSimo;
    assert_eq!(
        at.symmetric,
        laursen_simo || !at.statuses.contains(&Status::Slip)
    );
    let scale = at
        .tangent
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    if at.symmetric {
        let n = at.tangent.len();
        for i in 0..n {
            for j in 0..i {
                assert_eq!(at.tangent[i][j], at.tangent[j][i], "({i}, {j})");
            }
        }
    }
    let h = 1e-7 * x.iter().fold(1e-3f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0f64;
    for j in 0..x.len() {
        let mut xp = x.clone();
        xp[j] += h;
        let rp = probe.evaluate(&xp).unwrap();
        let mut xm = x.clone();
        xm[j] -= h;
        let rm = probe.evaluate(&xm).unwrap();
        assert!(rp.statuses == at.statuses && rm.statuses == at.statuses);
        for i in 0..x.len() {
            let fd = (rp.residual[i] - rm.residual[i]) / (2.0 * h);
            worst = worst.max((fd - at.tangent[i][j]).abs() / scale);
        }
    }
    worst
}

fn line() -> Value {
    json!({"kind": "line", "point": [0.0, 0.0], "normal": [0.0, 1.0]})
}

/// A circle of radius 1000 touching the block's bottom at its middle: under the load every
/// slave node touches it (the gap at the ends, 5e-4, is below the penetration p / kappa), and
/// the tilt of its normal there, 1e-3, stays well inside the friction cone.
fn circle() -> Value {
    json!({"kind": "circle", "centre": [1.0, -1000.0], "radius": 1000.0})
}

/// The one-step slip (top dragged 0.05, nu = 0) and stick (traction mu p / 2, nu = 0.3) patch
/// tests of `mesh` with discretization `disc`, as the finite-difference checks use them.
fn slip_and_stick(mesh: &str, disc: Value) -> (Value, Value) {
    (
        patch(
            mesh,
            "0.0",
            disc.clone(),
            MU * P,
            Top::Displacement(0.05),
            1,
        ),
        patch(mesh, "0.3", disc, 0.5 * MU * P, Top::Traction, 1),
    )
}

/// Solve every case in stick and in slip with its pair's normal law set by `law`, and check the
/// frictional tangent against central differences of the residual at the converged state.
fn assert_tangents_match_differences(
    label: &str,
    cases: Vec<(&str, (Value, Value))>,
    law: fn(Value) -> Value,
) {
    for (name, (slip, stick)) in cases {
        for (v, status) in [(law(stick), Status::Stick), (law(slip), Status::Slip)] {
            let o = run(&v);
            assert_eq!(termination(&o), Termination::Converged, "{name} {status:?}");
            let model = build(&v).unwrap();
            let e = fd_error(&model, &o, status);
            println!("{label}, {name}, {status:?}: tangent vs central differences {e:.1e}");
            assert!(e < 1e-6, "{label} {name} {status:?}: {e:e}");
        }
    }
}

#[test]
fn the_frictional_tangent_is_the_derivative_of_the_residual_in_stick_and_in_slip() {
    assert_tangents_match_differences(
        "penalty",
        vec![
            ("A node-to-node", slip_and_stick("A", node_to_node())),
            ("C node-to-surface", slip_and_stick("C", node_to_surface())),
            ("rigid line", (dragged(line(), 0.05), dragged(line(), 1e-6))),
            (
                "C two-pass node-to-surface",
                slip_and_stick("C", two_pass()),
            ),
            (
                "C node-to-surface, slave normals",
                slip_and_stick("C", slave_normals()),
            ),
            ("C mortar", slip_and_stick("C", mortar("standard"))),
            ("E dual mortar", slip_and_stick("E", mortar("dual"))),
            (
                "rigid circle",
                (dragged(circle(), 0.05), dragged(circle(), 1e-6)),
            ),
        ],
        |v| v,
    );
}

/// Residual history of the first step of `v` with the given friction tangent.
fn history(v: &Value, tangent: &str) -> (Termination, Vec<(f64, usize, &'static str)>) {
    let mut v = v.clone();
    v["solver"]["friction_tangent"] = json!(tangent);
    let o = run(&v);
    let c = o.solution.contact.as_ref().unwrap();
    (
        c.termination.clone(),
        c.history
            .iter()
            .map(|h| (h.residual, h.status_changes, h.linear_solver))
            .collect(),
    )
}

#[test]
fn newton_with_the_consistent_tangent_beats_the_symmetrized_one_in_slip() {
    for (name, v) in [
        (
            "patch A, node-to-node",
            patch(
                "A",
                "0.0",
                node_to_node(),
                MU * P,
                Top::Displacement(0.05),
                1,
            ),
        ),
        (
            "patch C, node-to-surface",
            patch(
                "C",
                "0.0",
                node_to_surface(),
                MU * P,
                Top::Displacement(0.05),
                1,
            ),
        ),
        (
            "patch C, mortar",
            patch(
                "C",
                "0.0",
                mortar("standard"),
                MU * P,
                Top::Displacement(0.05),
                1,
            ),
        ),
        (
            "patch E, dual mortar",
            patch(
                "E",
                "0.0",
                mortar("dual"),
                MU * P,
                Top::Displacement(0.05),
                1,
            ),
        ),
    ] {
        let (t_c, consistent) = history(&v, "consistent");
        let (t_s, symmetrized) = history(&v, "symmetrized");
        println!("{name}\n  consistent  {consistent:?}\n  symmetrized {symmetrized:?}");
        assert_eq!(t_c, Termination::Converged, "{name}");
        assert_eq!(t_s, Termination::Converged, "{name}");
        // the consistent tangent is unsymmetric in slip: LU
        assert_eq!(consistent.last().unwrap().2, "lu");
        // with the branch fixed the residual is affine in u and the consistent tangent exact:
        // the first iteration without a status change lands on the solution
        let settled = consistent.iter().position(|h| h.1 == 0).unwrap();
        assert_eq!(settled, consistent.len() - 1, "{name}");
        assert!(consistent.last().unwrap().0 <= 1e-10);
        // the symmetrized tangent converges linearly: more iterations, the residual falling
        // by a bounded factor per iteration once the branch is fixed
        assert!(symmetrized.len() > consistent.len() + 2, "{name}");
        let tail: Vec<f64> = symmetrized
            .iter()
            .filter(|h| h.1 == 0)
            .map(|h| h.0)
            .collect();
        let rates: Vec<f64> = tail.windows(2).map(|w| w[1] / w[0]).collect();
        assert!(rates.iter().all(|&r| r < 1.0), "{name}: {rates:?}");
    }
    // on the rigid circle (points opening and closing on the way) the consistent tangent
    // settles its branches in four iterations and then lands on the solution; the symmetrized
    // one was seen to cycle between two branch sets there (iteration limit), not asserted
    let (t, consistent) = history(&dragged(circle(), 0.05), "consistent");
    assert_eq!(t, Termination::Converged);
    assert_eq!(
        consistent.iter().position(|h| h.1 == 0),
        Some(consistent.len() - 1)
    );
}

fn refusal(v: &Value) -> String {
    match build(v) {
        Ok(_) => panic!("accepted"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn friction_is_refused_where_this_slice_does_not_solve_it_with_the_fix() {
    let base = patch("A", "0.3", node_to_node(), 0.0, Top::Traction, 1);
    assert!(build(&base).is_ok());
    let with = |f: &dyn Fn(&mut Value)| {
        let mut v = base.clone();
        f(&mut v);
        refusal(&v)
    };
    let m = with(&|v| v["contact"][0]["interaction"]["coulomb"]["mu"] = json!(-0.1));
    assert!(m.contains("mu must be a finite number >= 0"), "{m}");
    let m = with(&|v| v["contact"][0]["interaction"]["coulomb"]["kappa_t"] = json!(0.0));
    assert!(m.contains("kappa_t must be positive"), "{m}");
    let m = with(&|v| v["solver"]["scheme"] = json!("active_set"));
    assert!(
        m.contains("Newton scheme only") && m.contains("\"newton\""),
        "{m}"
    );
    // Lagrange multipliers carry friction without a tangential penalty: kappa_t is refused
    let m = with(&|v| {
        v["contact"][0]["enforcement"] = json!({"kind": "lagrange"});
        v["contact"][0]["interaction"]["coulomb"]["kappa_t"] = json!(1e4);
    });
    assert!(
        m.contains("kappa_t has no role with Lagrange multipliers")
            && m.contains("leave kappa_t out"),
        "{m}"
    );
    let m = with(&|v| v["contact"][0]["enforcement"] = json!({"kind": "elimination"}));
    assert!(
        m.contains("constraint elimination is not solved")
            && m.contains("a slipping point constrains no tangential motion")
            && m.contains("use Lagrange multipliers"),
        "{m}"
    );
    // the perturbed tangent carries friction (the_perturbed_tangent_carries_friction_..)
    let mut v = base.clone();
    v["contact"][0]["enforcement"] = json!({"kind": "perturbed_tangent", "kappa": KAPPA});
    assert!(build(&v).is_ok());
    // every discretization carries friction (tests/friction_table.rs)
    for d in [
        json!({"kind": "mortar", "multiplier": "standard"}),
        json!({"kind": "mortar", "multiplier": "dual"}),
        json!({"kind": "node_to_surface", "passes": 2}),
        json!({"kind": "node_to_surface", "passes": 1, "normal": "slave"}),
    ] {
        let mut v = base.clone();
        v["contact"][0]["discretization"] = d.clone();
        assert!(build(&v).is_ok(), "{d}");
    }
    // in the current geometry, friction is solved against a flat rigid master only (a block
    // dragged over a rigid line: at_finite_strain_a_block_dragged_far_over_a_rigid_line_..)
    let m = with(&|v| v["physics"] = json!({"contact_geometry": "current"}));
    assert!(
        m.contains("against a rigid line or plane only")
            && m.contains("convected coordinates")
            && m.contains("contact_geometry\": \"reference\""),
        "{m}"
    );
    let m = with(&|v| v["loads"][0]["path"] = json!([0.0, 1.0]));
    assert!(
        m.contains("one factor per load step: 2 given, solver.load_steps is 1"),
        "{m}"
    );
    // unknown fields of the interaction are refused by the parser
    let mut v = base.clone();
    v["contact"][0]["interaction"]["coulomb"]["m"] = json!(0.3);
    assert!(parse(&v.to_string(), "friction").is_err());
}

#[test]
fn a_frictionless_scene_builds_no_tangential_row() {
    let mut v = patch("A", "0.3", node_to_node(), 0.0, Top::Traction, 1);
    v["contact"][0]
        .as_object_mut()
        .unwrap()
        .remove("interaction");
    // the punch needs its x support back without friction
    v["supports"]
        .as_array_mut()
        .unwrap()
        .push(json!({"body": "punch", "set": "top_left", "x": 0.0}));
    let o = run(&v);
    let c = o.solution.contact.as_ref().unwrap();
    assert!(c.rows.iter().all(|r| r.tangents.is_empty()));
    assert!(c.friction.iter().all(|f| f.is_none()));
    assert!(c.steps.iter().all(|s| s.friction.is_none()));
}

#[test]
fn the_summary_reports_the_tangential_force_and_the_stick_and_slip_counts() {
    let o = run(&patch(
        "A",
        "0.0",
        node_to_node(),
        MU * P,
        Top::Displacement(0.05),
        2,
    ));
    let nodal: Vec<Vec<[f64; 3]>> = o
        .model
        .bodies
        .iter()
        .map(|b| contact_patch::post::nodal_stresses(b, &o.solution.u))
        .collect();
    let summary = serde_json::to_value(contact_patch::io::output::summary(&o, &nodal)).unwrap();
    let pair = &summary["contact"]["pairs"][0];
    let f = &pair["friction"];
    assert_eq!(f["slip"], json!(3), "{f}");
    assert_eq!(f["stick"], json!(0), "{f}");
    let t = f["tangential_force"][0].as_f64().unwrap();
    assert!((t + 2.0 * MU * P).abs() <= 1e-10 * P, "{f}");
    // the punch top moved d = 0.05; the uniform shear gamma = mu p / G carries it through the
    // punch and the foundation (heights 2 and 5, u_x = gamma y), the penalty spring takes
    // mu p / kappa_t: the rest slid, against the traction mu p over the width 2
    let (d, gamma) = (0.05, MU * P / 500.0);
    let slid = d - gamma * 7.0 - MU * P / KAPPA;
    let dissipation = f["dissipation"].as_f64().unwrap();
    assert!(
        (dissipation - 2.0 * MU * P * slid).abs() <= 1e-10,
        "{dissipation} against {}",
        2.0 * MU * P * slid
    );
    // per step too
    let steps = summary["contact"]["steps"].as_array().unwrap();
    assert_eq!(steps[0]["friction"]["slip"], json!(0));
    assert_eq!(steps[1]["friction"]["slip"], json!(3));
}

#[test]
fn the_perturbed_lagrangian_carries_friction_as_the_penalty_does() {
    let mut v = patch(
        "A",
        "0.0",
        node_to_node(),
        MU * P,
        Top::Displacement(0.05),
        2,
    );
    v["contact"][0]["enforcement"] = json!({"kind": "perturbed_lagrange", "kappa": KAPPA});
    let o = run(&v);
    assert_eq!(termination(&o), Termination::Converged);
    for p in points(&o) {
        assert_eq!(p.0, Status::Slip);
        assert!((p.1.abs() / p.3 - MU * P).abs() <= 1e-9 * MU * P);
    }
    assert!(stress_error(&o, [0.0, -P, MU * P]) < 1e-8 * P);
    // Laursen & Simo's form needs the augmented Lagrangian's normal multiplier
    v["solver"]["friction_tangent"] = json!("laursen_simo");
    let m = refusal(&v);
    assert!(
        m.contains("bounds the slip force by the normal Uzawa multiplier")
            && m.contains("this pair uses perturbed_lagrange")
            && m.contains("augmented_lagrange"),
        "{m}"
    );
}

/// `v` with Lagrange multipliers as the normal law of its pair (and so for friction).
fn lagrange(mut v: Value) -> Value {
    v["contact"][0]["enforcement"] = json!({"kind": "lagrange"});
    v
}

/// Newton iterations of every load step of a solve.
fn iterations_per_step(o: &Outcome) -> Vec<usize> {
    let state = o.solution.contact.as_ref().unwrap();
    state.steps.iter().map(|s| s.iterations).collect()
}

#[test]
fn lagrange_multipliers_tangent_is_the_derivative_of_the_residual_in_stick_and_in_slip() {
    assert_tangents_match_differences(
        "Lagrange",
        vec![
            ("A node-to-node", slip_and_stick("A", node_to_node())),
            ("C node-to-surface", slip_and_stick("C", node_to_surface())),
            ("rigid line", (dragged(line(), 0.05), dragged(line(), 1e-6))),
            ("E dual mortar", slip_and_stick("E", mortar("dual"))),
        ],
        lagrange,
    );
}

#[test]
fn lagrange_multipliers_pass_the_frictional_patch_test_in_stick_and_in_slip() {
    for (mesh, disc) in [
        ("A", node_to_node()),
        ("D", node_to_node()),
        ("A", node_to_surface()),
    ] {
        // stick: the exact uniform stress, no slip, the tangential load carried
        let q = 0.5 * MU * P;
        let o = run(&lagrange(patch(
            mesh,
            "0.3",
            disc.clone(),
            q,
            Top::Traction,
            2,
        )));
        assert_eq!(termination(&o), Termination::Converged, "{mesh} {disc}");
        let pts = points(&o);
        assert!(pts.iter().all(|p| p.0 == Status::Stick), "{mesh} {disc}");
        for p in &pts {
            // no slip in the step (the committed position kept) and inside the cone
            assert!(p.1.abs() <= MU * p.2 * (1.0 + 1e-12));
        }
        let state = o.solution.contact.as_ref().unwrap();
        for (f, r) in state.friction.iter().zip(&state.rows) {
            if let Some(f) = f {
                assert!((f.slip[0] - f.committed[0]).abs() <= 1e-14 * 8.0, "{r:?}");
                assert_eq!(f.dissipation, 0.0);
            }
        }
        let t = tangential_x(&o);
        assert!((t + 2.0 * q).abs() <= 1e-10 * 2.0 * q, "{mesh} {disc}: {t}");
        let e = stress_error(&o, [0.0, -P, q]) / P;
        let its = iterations_per_step(&o);
        println!("Lagrange stick, mesh {mesh}, {disc}: stress error {e:.1e} p, Newton iterations per step {its:?}");
        assert!(e < 1e-8, "{mesh} {disc}: stress error {e:e}");
        assert!(its.iter().all(|&k| k <= 4), "{its:?}");

        // slip: |lambda_t| = mu lambda_n at every node to round-off, traction mu p
        let sxy = MU * P;
        let o = run(&lagrange(patch(
            mesh,
            "0.0",
            disc.clone(),
            sxy,
            Top::Displacement(0.05),
            2,
        )));
        assert_eq!(termination(&o), Termination::Converged, "{mesh} {disc}");
        let pts = points(&o);
        let mut worst = 0.0f64;
        for p in &pts {
            assert_eq!(p.0, Status::Slip, "{mesh} {disc}");
            worst = worst.max((p.1.abs() - MU * p.2).abs() / (MU * P));
            assert!(p.1 * p.4[0] < 0.0);
            assert!(
                (p.1.abs() / p.3 - MU * P).abs() <= 1e-9 * MU * P,
                "{mesh} {disc}"
            );
        }
        assert!(worst <= 1e-13, "{mesh} {disc}: {worst:e}");
        let normal: f64 = pts.iter().map(|p| p.2).sum();
        assert!((normal - 2.0 * P).abs() <= 1e-10 * P, "{mesh} {disc}");
        let t = tangential_x(&o);
        assert!((t + 2.0 * MU * P).abs() <= 1e-10 * P, "{mesh} {disc}: {t}");
        let e = stress_error(&o, [0.0, -P, sxy]) / P;
        let s = o.solution.contact.as_ref().unwrap().steps.clone();
        for step in &s {
            let f = step.friction.as_ref().unwrap();
            assert!(f.dissipation >= 0.0 && f.max_cone_ratio <= 1.0 + 1e-12);
        }
        assert_eq!(s[0].friction.as_ref().unwrap().slip, 0);
        assert!(s.last().unwrap().friction.as_ref().unwrap().dissipation > 0.0);
        let its = iterations_per_step(&o);
        println!("Lagrange slip, mesh {mesh}, {disc}: | |lambda_t| - mu lambda_n | <= {worst:.1e} mu p, stress error {e:.1e} p, Newton iterations per step {its:?}");
        assert!(e < 1e-8, "{mesh} {disc}: stress error {e:e}");
        assert!(its.iter().all(|&k| k <= 5), "{its:?}");
        // the slip rows are the sets' equations, not a linearization: the symmetrized tangent
        // keeps them, and the solve is the same
        let mut v = lagrange(patch(
            mesh,
            "0.0",
            disc.clone(),
            sxy,
            Top::Displacement(0.05),
            2,
        ));
        v["solver"]["friction_tangent"] = json!("symmetrized");
        let s = run(&v);
        assert_eq!(termination(&s), Termination::Converged, "{mesh} {disc}");
        assert_eq!(iterations_per_step(&s), its, "{mesh} {disc}");
        assert!((tangential_x(&s) - t).abs() <= 1e-12 * P, "{mesh} {disc}");
    }
}

/// The checks of a converged incline solve at `F/G = f_over_g` (slope `tan_a`, weight 10): in
/// every step Coulomb's inequality (to `cone`) and non-negative dissipation, and the forces on
/// the block in balance with the load along and across the incline (to 1e-9 of the weight)
/// inside the cone. Returns `|T| / (mu N)`.
fn assert_incline_balance(o: &Outcome, f_over_g: f64, tan_a: f64, cone: f64, label: &str) -> f64 {
    assert_eq!(termination(o), Termination::Converged, "{label}");
    let state = o.solution.contact.as_ref().unwrap();
    for step in &state.steps {
        let f = step.friction.as_ref().unwrap();
        assert!(f.max_cone_ratio <= 1.0 + cone, "{label}: {f:?}");
        assert!(f.dissipation >= 0.0, "{label}: {f:?}");
    }
    let (s, c) = (
        tan_a / (1.0 + tan_a * tan_a).sqrt(),
        1.0 / (1.0 + tan_a * tan_a).sqrt(),
    );
    let (g, f) = (10.0, f_over_g * 10.0);
    let tangential = tangential_x(o);
    let normal: f64 = points(o).iter().map(|p| p.2).sum();
    assert!(
        (tangential + (f * c - g * s)).abs() <= 1e-9 * g,
        "{label}: {tangential}"
    );
    assert!(
        (normal - (g * c + f * s)).abs() <= 1e-9 * g,
        "{label}: {normal}"
    );
    assert!(tangential.abs() <= MU * normal * (1.0 + cone), "{label}");
    tangential.abs() / (MU * normal)
}

#[test]
fn lagrange_multipliers_hold_a_block_on_an_incline_up_to_the_coulomb_limit() {
    let tan_a: f64 = 0.1;
    let limit = (tan_a + MU) / (1.0 - MU * tan_a);
    assert!((limit - 0.412371).abs() < 1e-6);
    for ratio in [0.5, 0.98, 0.995, 0.999] {
        let o = run(&lagrange(incline(ratio * limit, tan_a, 4)));
        let share = assert_incline_balance(
            &o,
            ratio * limit,
            tan_a,
            1e-12,
            &format!("F/G = {ratio} limit"),
        );
        println!(
            "Lagrange, F/G = {ratio} x limit: |T|/(mu N) = {share:.6}, Newton iterations per step {:?}",
            iterations_per_step(&o)
        );
    }
    // just past the limit no equilibrium exists, and the run says why
    let o = run(&lagrange(incline(1.01 * limit, tan_a, 4)));
    assert_ne!(termination(&o), Termination::Converged);
    assert!(
        o.warnings.iter().any(|w| w.contains(
            "load step 1 has no equilibrium: the frictional forces cannot hold the load"
        )),
        "{:?}",
        o.warnings
    );
}

/// `v` with the augmented Lagrangian as the normal law of its pair (and so for friction), the
/// Uzawa update `update` (`per_iteration` or `outer_loop`).
fn augmented(mut v: Value, update: &str) -> Value {
    v["contact"][0]["enforcement"] =
        json!({"kind": "augmented_lagrange", "kappa": KAPPA, "update": update});
    v
}

/// `v` with the augmented Lagrangian in Laursen & Simo's symmetric form.
fn laursen_simo(v: Value) -> Value {
    let mut v = augmented(v, "per_iteration");
    v["solver"]["friction_tangent"] = json!("laursen_simo");
    v
}

/// The discretizations of the finite-difference checks of the augmented forms.
fn augmented_fd_cases() -> Vec<(&'static str, (Value, Value))> {
    vec![
        ("A node-to-node", slip_and_stick("A", node_to_node())),
        ("C node-to-surface", slip_and_stick("C", node_to_surface())),
        ("rigid line", (dragged(line(), 0.05), dragged(line(), 1e-6))),
        (
            "C two-pass node-to-surface",
            slip_and_stick("C", two_pass()),
        ),
        ("C mortar", slip_and_stick("C", mortar("standard"))),
        ("E dual mortar", slip_and_stick("E", mortar("dual"))),
        (
            "rigid circle",
            (dragged(circle(), 0.05), dragged(circle(), 1e-6)),
        ),
    ]
}

#[test]
fn augmented_lagrangian_tangent_is_the_derivative_of_the_residual_in_stick_and_in_slip() {
    // at the converged Uzawa multipliers (held fixed: the Newton problem of one Uzawa pass)
    assert_tangents_match_differences("augmented Lagrangian", augmented_fd_cases(), |v| {
        augmented(v, "per_iteration")
    });
}

#[test]
fn laursen_simo_tangent_is_symmetric_and_the_derivative_of_the_residual() {
    // the slip force mu lambda_bar_n does not move with u: the exact tangent is symmetric
    // (checked entry by entry in fd_error) in slip as in stick
    assert_tangents_match_differences("Laursen-Simo", augmented_fd_cases(), laursen_simo);
}

/// The frictional points' forces of two solves, the largest difference relative to `p`.
fn force_difference(a: &Outcome, b: &Outcome) -> f64 {
    let (pa, pb) = (points(a), points(b));
    assert_eq!(pa.len(), pb.len());
    pa.iter()
        .zip(&pb)
        .map(|(x, y)| {
            assert_eq!(x.0, y.0);
            (x.1 - y.1).abs().max((x.2 - y.2).abs()) / P
        })
        .fold(0.0, f64::max)
}

/// The frictional patch cases the Uzawa methods are held to Lagrange on: meshes A and D
/// node-to-node, A node-to-surface, C mortar and E dual mortar, each in stick (`q = mu p / 2`)
/// and in slip (the top dragged), two load steps: `(mesh, discretization, status, q, case)`.
fn uzawa_patch_cases() -> Vec<(&'static str, Value, Status, f64, Value)> {
    let mut cases = Vec::new();
    for (mesh, disc) in [
        ("A", node_to_node()),
        ("D", node_to_node()),
        ("A", node_to_surface()),
        ("C", mortar("standard")),
        ("E", mortar("dual")),
    ] {
        for (status, nu, sxy, top) in [
            (Status::Stick, "0.3", 0.5 * MU * P, Top::Traction),
            (Status::Slip, "0.0", MU * P, Top::Displacement(0.05)),
        ] {
            let base = patch(mesh, nu, disc.clone(), sxy, top, 2);
            cases.push((mesh, disc.clone(), status, sxy, base));
        }
    }
    cases
}

/// Coulomb's inequality and non-negative dissipation in every load step of `o`.
fn assert_coulomb_in_every_step(o: &Outcome, what: &str) {
    for step in &o.solution.contact.as_ref().unwrap().steps {
        let f = step.friction.as_ref().unwrap();
        assert!(f.max_cone_ratio <= 1.0 + 1e-12, "{what}: {f:?}");
        assert!(f.dissipation >= 0.0, "{what}: {f:?}");
    }
}

#[test]
fn augmented_lagrangian_friction_converges_to_the_lagrange_answer() {
    // every Uzawa variant on the frictional patch test, stick (q = mu p / 2) and slip (the top
    // dragged), two load steps: the same statuses and forces as Lagrange multipliers, exact
    // stress, Coulomb's inequality and non-negative dissipation in every step
    for (mesh, disc, status, sxy, base) in uzawa_patch_cases() {
        let exact = run(&lagrange(base.clone()));
        assert_eq!(termination(&exact), Termination::Converged);
        for (label, v) in [
            ("per iteration", augmented(base.clone(), "per_iteration")),
            ("outer loop", augmented(base.clone(), "outer_loop")),
            ("Laursen-Simo", laursen_simo(base.clone())),
        ] {
            let o = run(&v);
            let what = format!("{mesh} {disc} {status:?} {label}");
            assert_eq!(termination(&o), Termination::Converged, "{what}");
            let pts = points(&o);
            assert!(pts.iter().all(|p| p.0 == status), "{what}");
            let d = force_difference(&o, &exact);
            let e = stress_error(&o, [0.0, -P, sxy]) / P;
            assert_coulomb_in_every_step(&o, &what);
            let state = o.solution.contact.as_ref().unwrap();
            if status == Status::Slip {
                for p in &pts {
                    assert!((p.1.abs() - MU * p.2).abs() <= 1e-12 * MU * P, "{what}");
                }
            } else {
                // stick is exact: the points end where the step started them
                for f in state.friction.iter().flatten() {
                    assert!((f.slip[0] - f.committed[0]).abs() <= 1e-12, "{what}: {f:?}");
                }
            }
            println!(
                    "{what}: forces vs Lagrange {d:.1e} p, stress error {e:.1e} p, Newton iterations per step {:?}",
                    iterations_per_step(&o)
                );
            assert!(d <= 1e-10, "{what}: {d:e}");
            assert!(e <= 1e-8, "{what}: {e:e}");
        }
    }
}

/// The perturbed tangent (Lim & Taylor 2001): Newton on the Lagrange residual with the
/// perturbed Lagrangian's tangent. Its answer is the Lagrange one for `kappa` and `100 kappa`
/// alike (not a penalty answer that moves with it): the gap closes and the forces are
/// Lagrange's. (A small `kappa` costs iterations, not accuracy: at `kappa = 1e2 = E / 10` the
/// slip step of mesh A took 104 iterations, its multiplier change falling by 0.85 per update,
/// the linear rate of an update that is not Newton's.)
#[test]
fn the_perturbed_tangent_carries_friction_to_the_lagrange_answer_independent_of_kappa() {
    for (mesh, disc, status, sxy, base) in uzawa_patch_cases() {
        let exact = run(&lagrange(base.clone()));
        assert_eq!(termination(&exact), Termination::Converged);
        for kappa in [KAPPA, 100.0 * KAPPA] {
            let mut v = base.clone();
            v["contact"][0]["enforcement"] = json!({"kind": "perturbed_tangent", "kappa": kappa});
            let o = run(&v);
            let what = format!("{mesh} {disc} {status:?} kappa {kappa:e}");
            assert_eq!(termination(&o), Termination::Converged, "{what}");
            let pts = points(&o);
            assert!(pts.iter().all(|p| p.0 == status), "{what}");
            assert_coulomb_in_every_step(&o, &what);
            let state = o.solution.contact.as_ref().unwrap();
            let d = force_difference(&o, &exact);
            let e = stress_error(&o, [0.0, -P, sxy]) / P;
            let penetration = state
                .gaps
                .iter()
                .zip(&state.active)
                .filter(|(_, &on)| on)
                .fold(0.0f64, |m, (g, _)| m.max(-g));
            println!(
                    "{what}: forces vs Lagrange {d:.1e} p, stress error {e:.1e} p, penetration {penetration:.1e}, Newton iterations per step {:?}",
                    iterations_per_step(&o)
                );
            assert!(d <= 1e-10, "{what}: {d:e}");
            assert!(e <= 1e-8, "{what}: {e:e}");
            // the gap closes (a penalty of this kappa leaves p / kappa ~ 1e-3 to 1e-1)
            assert!(penetration <= 1e-10, "{what}: {penetration:e}");
        }
    }
}

#[test]
fn augmented_lagrangian_holds_a_block_on_an_incline_up_to_the_coulomb_limit() {
    let tan_a: f64 = 0.1;
    let limit = (tan_a + MU) / (1.0 - MU * tan_a);
    assert!((limit - 0.412371).abs() < 1e-6);
    type Law = fn(Value) -> Value;
    let variants: [(&str, Law); 3] = [
        ("per iteration", |v| augmented(v, "per_iteration")),
        ("outer loop", |v| augmented(v, "outer_loop")),
        ("Laursen-Simo", laursen_simo),
    ];
    for (label, law) in variants {
        for ratio in [0.5, 0.98, 0.995] {
            let o = run(&law(incline(ratio * limit, tan_a, 4)));
            // Laursen & Simo bound the slip force by the normal multiplier, which the Uzawa
            // loop brings to the normal force lambda_n = lambda_bar_n - w g until the gap g is
            // at its round-off floor (1e-15 of the model size): |lambda_t| / (mu lambda_n)
            // exceeds 1 by up to w 1e-15 L / lambda_n (about 1e-11 here), the consistent
            // form's slip force is mu lambda_n itself
            let cone = if label == "Laursen-Simo" {
                1e-10
            } else {
                1e-12
            };
            let share = assert_incline_balance(
                &o,
                ratio * limit,
                tan_a,
                cone,
                &format!("{label}: F/G = {ratio} limit"),
            );
            println!(
                "augmented Lagrangian {label}, F/G = {ratio} x limit: |T|/(mu N) = {share:.6}, Newton iterations per step {:?}",
                iterations_per_step(&o)
            );
        }
        // just past the limit no equilibrium exists: the solve does not converge, or the
        // block slides away without bound and the solve says so
        match run_model(
            build(&law(incline(1.01 * limit, tan_a, 4))).unwrap(),
            0.0,
            std::time::Instant::now(),
            &mut |_| {},
        ) {
            Ok(o) => assert_ne!(termination(&o), Termination::Converged, "{label}"),
            Err(e) => assert!(e.to_string().contains("not finite"), "{label}: {e}"),
        }
    }
}

#[test]
fn the_convergence_study_puts_the_exact_tangents_ahead_of_the_symmetrized_one() {
    // reports/friction-convergence.*: on the slip patch every variant converges; the exact
    // tangents (consistent, and Laursen & Simo's symmetric one of the augmented Lagrangian)
    // need fewer Newton iterations in the slipping step than the symmetrized tangent
    let runs =
        contact_patch::harness::friction_convergence::study(Path::new(env!("CARGO_MANIFEST_DIR")))
            .unwrap();
    let last = |problem: &str, enforcement: &str, tangent: &str| {
        let r = runs
            .iter()
            .find(|r| {
                r.problem.starts_with(problem)
                    && r.enforcement == enforcement
                    && r.tangent == tangent
            })
            .unwrap();
        println!("{problem} {enforcement} {tangent}: {r:?}");
        assert_eq!(r.termination, "converged", "{r:?}");
        assert!(*r.last_step_residuals.last().unwrap() <= 1e-10, "{r:?}");
        *r.iterations.last().unwrap()
    };
    for enforcement in ["penalty", "augmented_lagrange"] {
        assert!(
            last("slip patch", enforcement, "consistent")
                < last("slip patch", enforcement, "symmetrized")
        );
    }
    assert!(
        last("slip patch", "augmented_lagrange", "laursen_simo")
            < last("slip patch", "augmented_lagrange", "symmetrized")
    );
    assert!(last("incline", "penalty", "consistent") < last("incline", "penalty", "symmetrized"));
    last("incline", "augmented_lagrange", "laursen_simo");
}

/// `v` under finite kinematics: its material `m` neo-Hookean of modulus `e`, the contact
/// geometry of the current configuration (friction there is solved against a rigid line or
/// plane: the tangent does not turn, so the slip `t . u_s` is the distance slid over it).
fn at_finite_strain(mut v: Value, e: f64) -> Value {
    v["materials"]["m"]["E"] = json!(e);
    v["materials"]["m"]["model"] = json!("neo_hookean");
    v["physics"] = json!({"kinematics": "finite", "contact_geometry": "current"});
    v
}

/// The largest difference between the displacements of two solves of one model, relative to
/// the largest displacement of the second.
fn largest_difference(a: &Outcome, b: &Outcome) -> f64 {
    let largest = b.solution.u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    a.solution
        .u
        .iter()
        .zip(&b.solution.u)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / largest
}

#[test]
fn at_finite_strain_a_soft_block_holds_on_an_incline_up_to_the_coulomb_limit() {
    // E = 20 under a weight of 10 on a block 2 x 1: strains of about a quarter, where the
    // small-strain answer is off by more than 5 %; the limit F/G is a balance of forces on the
    // block, whatever its deformation
    let tan_a: f64 = 0.1;
    let limit = (tan_a + MU) / (1.0 - MU * tan_a);
    let soft = |ratio: f64, law: fn(Value) -> Value| {
        let mut v = at_finite_strain(incline(ratio * limit, tan_a, 4), 20.0);
        v["contact"][0]["enforcement"] = json!({"kind": "penalty", "kappa": 1e3});
        law(v)
    };
    let penalty: fn(Value) -> Value = |v| v;
    for (name, law) in [("penalty", penalty), ("Lagrange", lagrange)] {
        for ratio in [0.5, 0.98] {
            let o = run(&soft(ratio, law));
            let label = format!("{name} {ratio}");
            let share = assert_incline_balance(&o, ratio * limit, tan_a, 1e-12, &label);
            // the deformation is finite: the small-strain answer differs
            let mut small = soft(ratio, law);
            small["materials"]["m"] = json!({"E": 20.0, "nu": 0.3});
            small["physics"] = json!({});
            let linear = run(&small);
            let difference = largest_difference(&o, &linear);
            println!(
                "finite strain, {name}, F/G = {ratio} x limit: |T|/(mu N) = {share:.6}, iterations {:?}, largest difference from the small-strain displacements {difference:.3} of their largest",
                iterations_per_step(&o)
            );
            assert!(difference > 0.05, "{difference}");
        }
        // just past the limit no equilibrium exists, at any load factor of the proportional
        // load: the finite-strain driver cuts the first step until its cuts are spent, and
        // says so
        let v = soft(1.01, law);
        let failed = run_model(
            build(&v).unwrap(),
            0.0,
            std::time::Instant::now(),
            &mut |_| {},
        );
        let Err(error) = failed else {
            panic!("{name}: converged past the limit, where no equilibrium exists")
        };
        let message = error.to_string();
        assert!(
            message.contains("load step") && message.contains("cuts of the load increment"),
            "{name}: {message}"
        );
    }
}

/// The block of [`dragged`] under finite kinematics (E = 100, Poisson's ratio `nu`, 10 %
/// compression by the pressure), its top pressed in the first of four load steps and dragged
/// by `d` over the other three. (With `nu = 0` the neo-Hookean block compressed along y keeps
/// its width, `sigma_xx = mu (b_xx - 1) / J = 0` at `F_xx = 1`: nothing slides in the press.)
fn dragged_at_finite_strain(d: f64, nu: f64) -> Value {
    let mut v = at_finite_strain(dragged(line(), d), 100.0);
    v["materials"]["m"]["nu"] = json!(nu);
    v["solver"]["load_steps"] = json!(4);
    v["supports"][0]["path"] = json!([0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0]);
    v["loads"][0]["path"] = json!([1.0, 1.0, 1.0, 1.0]);
    v
}

#[test]
fn at_finite_strain_a_block_dragged_far_over_a_rigid_line_slides_at_mu_n() {
    // dragged by 60 % of its height: every bottom node in contact slides, each with the force
    // mu lambda_n against the drag, and the block's whole tangential force is mu N with N the
    // pressure's. The couple of the friction on the bottom and the drag on the top lifts the
    // trailing corner (x = 0) off the line at finite strain (measured: a gap of 0.012 at
    // height 1; the small-strain answer keeps it closed under a small pressure)
    let penalty: fn(Value) -> Value = |v| v;
    for (name, law) in [("penalty", penalty), ("Lagrange", lagrange)] {
        let o = run(&law(dragged_at_finite_strain(0.6, 0.3)));
        assert_eq!(termination(&o), Termination::Converged, "{name}");
        let pts = points(&o);
        assert_eq!(pts.len(), 5);
        let normal: f64 = pts.iter().map(|p| p.2).sum();
        assert!((normal - 2.0 * P).abs() <= 1e-9 * P, "{name}: {normal}");
        assert_eq!(pts[0].0, Status::Open, "{name}: {pts:?}");
        assert_eq!((pts[0].1, pts[0].2), (0.0, 0.0), "{name}: {pts:?}");
        for p in &pts[1..] {
            assert_eq!(p.0, Status::Slip, "{name}: {pts:?}");
            // the force on the block opposes the drag along +x
            assert!(p.1 * p.4[0] < 0.0, "{name}: {p:?}");
            assert!((p.1.abs() - MU * p.2).abs() <= 1e-12 * P, "{name}: {p:?}");
        }
        let t = tangential_x(&o);
        assert!((t + MU * normal).abs() <= 1e-12 * P, "{name}: {t}");
        let state = o.solution.contact.as_ref().unwrap();
        for step in &state.steps {
            let f = step.friction.as_ref().unwrap();
            assert!(f.max_cone_ratio <= 1.0 + 1e-12, "{name} {f:?}");
            assert!(f.dissipation >= 0.0, "{name} {f:?}");
        }
        assert!(
            state
                .steps
                .last()
                .unwrap()
                .friction
                .as_ref()
                .unwrap()
                .dissipation
                > 0.0
        );
        println!(
            "finite strain, dragged 0.6, {name}: T = {t:.12}, mu N = {:.12}, iterations {:?}",
            MU * normal,
            iterations_per_step(&o)
        );
    }
}

#[test]
fn at_finite_strain_the_frictional_tangent_is_the_derivative_of_the_residual() {
    let cases = || {
        vec![(
            "rigid line, finite strain",
            (
                dragged_at_finite_strain(0.6, 0.3),
                dragged_at_finite_strain(1e-6, 0.0),
            ),
        )]
    };
    assert_tangents_match_differences("penalty", cases(), |v| v);
    assert_tangents_match_differences("Lagrange", cases(), lagrange);
}

#[test]
fn at_finite_strain_the_load_steps_carry_the_slip_history() {
    // dragged far into slip over three steps, then a fourth step that changes nothing: each
    // point stays where the last step left it (its committed slip), so the block stays put.
    // (Before the finite-strain driver carried the committed slip from step to step, each step
    // measured slip from the reference position, and the Lagrange multipliers' solve of this
    // drag ended in an inverted cell)
    let penalty: fn(Value) -> Value = |v| v;
    for (name, law) in [("penalty", penalty), ("Lagrange", lagrange)] {
        let mut held = law(dragged_at_finite_strain(0.6, 0.3));
        held["solver"]["load_steps"] = json!(5);
        held["supports"][0]["path"] = json!([0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0, 1.0]);
        held["loads"][0]["path"] = json!([1.0, 1.0, 1.0, 1.0, 1.0]);
        let o = run(&held);
        assert_eq!(termination(&o), Termination::Converged, "{name}");
        let at_four = run(&law(dragged_at_finite_strain(0.6, 0.3)));
        let moved = largest_difference(&o, &at_four);
        assert!(moved <= 1e-10, "{name}: {moved:e}");
        // (each closed point stays on the cone's edge, where stick and slip with no slip
        // increment are the same state: its forces are those of the fourth step)
        let (pts, before) = (points(&o), points(&at_four));
        for (p, q) in pts.iter().zip(&before) {
            assert!((p.1 - q.1).abs() <= 1e-10 * P, "{name}: {p:?} vs {q:?}");
            assert!((p.2 - q.2).abs() <= 1e-10 * P, "{name}: {p:?} vs {q:?}");
        }
        println!("finite strain, {name}: the held step moved the block by {moved:.1e} of its largest displacement");
    }
}

/// The friction block of `contact-patch friction-convergence` (one case, shared) under
/// `enforcement`, loaded along `path`.
fn friction_block(element: &str, enforcement: Value, path: &[(f64, f64)]) -> Value {
    let mut v = contact_patch::harness::friction_convergence::friction_block(element, path);
    v["contact"][0]["enforcement"] = enforcement;
    v
}

/// What the friction block's closed form fixes in each step (`nu = 0`, width `W = 2`): the
/// top moved by `d` while pressed slips at every point where the move outruns the elastic
/// range (`|d - d^n| > 2 mu p (H / G + 1 / kappa_t)`, `H / G = 1 / 500`), the tangential
/// force then `-mu p W sign(d - d^n)` on the block; after a slip step the same direction's
/// traction is already in place, so the next slip step moves the bottom with the top and
/// dissipates `mu p W |d - d^n|`. A step inside the elastic range sticks with `|F_t| < mu p
/// W` (but for the end nodes) and dissipates next to nothing; an unloaded step carries no
/// force. Per step: the status, the
/// tangential force (`None`: only inside the cone), the dissipation (`None`: only `>= 0`; the
/// first slip step after a press or a reversal shears the block as well, which the free
/// sides of the block make a two-dimensional field).
fn friction_block_closed_form(path: &[(f64, f64)]) -> Vec<(Status, Option<f64>, Option<f64>)> {
    let width = 2.0;
    let elastic = 2.0 * MU * P * (1.0 / 500.0 + 1e-4);
    let mut last: Option<f64> = None; // the direction of the last slip step
    let mut previous = 0.0;
    path.iter()
        .map(|&(pressure, d)| {
            let step = d - previous;
            previous = d;
            if pressure == 0.0 {
                return (Status::Open, Some(0.0), None);
            }
            if step.abs() < elastic {
                if step != 0.0 {
                    last = None;
                }
                return (Status::Stick, None, None);
            }
            let direction = step.signum();
            let force = -MU * P * pressure * width * direction;
            let dissipation =
                (last == Some(direction)).then(|| MU * P * pressure * width * step.abs());
            last = Some(direction);
            (Status::Slip, Some(force), dissipation)
        })
        .collect()
}

/// Issue 39: a friction block pressed, slid by ten element lengths, brought back through a
/// step that sticks and slid back past its start, with Q4 and Q9 cells and every
/// enforcement that carries friction: every step converges (Newton after a slip starts on the
/// cone, in stick), in a few iterations, and each step's status, tangential force and
/// dissipation are the closed form's.
#[test]
fn a_friction_block_slid_back_and_forth_converges_in_every_step_to_the_closed_form() {
    let path = contact_patch::harness::friction_convergence::friction_block_path();
    let penalty = 1e4;
    let enforcements = [
        ("penalty", json!({"kind": "penalty", "kappa": penalty})),
        (
            "perturbed Lagrangian",
            json!({"kind": "perturbed_lagrange", "kappa": penalty}),
        ),
        (
            "augmented Lagrangian",
            json!({"kind": "augmented_lagrange", "kappa": penalty}),
        ),
        ("Lagrange", json!({"kind": "lagrange"})),
    ];
    for element in ["Q4", "Q9"] {
        for (name, enforcement) in &enforcements {
            let o = run(&friction_block(element, enforcement.clone(), &path));
            let expected = friction_block_closed_form(&path);
            let state = o.solution.contact.as_ref().unwrap();
            let label = format!("{element}, {name}");
            assert_eq!(
                state.steps.len(),
                path.len(),
                "{label}: {:?}",
                state.termination
            );
            let iterations: Vec<usize> = state.steps.iter().map(|s| s.iterations).collect();
            println!("{label}: iterations per step {iterations:?}");
            for (step, (status, force, dissipation)) in state.steps.iter().zip(&expected) {
                let what = format!("{label}, step {}", step.step);
                assert_eq!(step.termination, Termination::Converged, "{what}");
                let f = step.friction.as_ref().unwrap();
                let points = f.open + f.stick + f.slip;
                let count = match status {
                    // unloaded: open, or closed at a zero gap with a force of round-off
                    Status::Open => f.open + f.stick + f.slip,
                    // the two end nodes, where the free sides concentrate the traction, may
                    // go on slipping through a small reversal
                    Status::Stick => f.stick + f.slip.min(2),
                    // (an end node may lift off: the drag tips the block, whose sides are free)
                    Status::Slip => f.slip + f.open.min(2),
                };
                assert_eq!(count, points, "{what}: {f:?}, expected {status:?}");
                let bound = MU * P * 2.0;
                match force {
                    Some(force) => assert!(
                        (f.tangential_force[0] - force).abs() <= 1e-9 * bound,
                        "{what}: {f:?}, expected {force}"
                    ),
                    None => assert!(f.tangential_force[0].abs() < bound, "{what}: {f:?}"),
                }
                match dissipation {
                    Some(d) => assert!(
                        (f.dissipation - d).abs() <= 1e-9 * (1.0 + d),
                        "{what}: {f:?}, expected {d}"
                    ),
                    None => assert!(f.dissipation >= 0.0, "{what}: {f:?}"),
                }
            }
            // the penalty laws in at most 5 iterations a step (the augmented Lagrangian's
            // count includes its Uzawa passes; Lagrange multipliers have their own sets)
            if name.starts_with("penalty") || name.starts_with("perturbed") {
                let worst = iterations.iter().max().copied().unwrap_or(0);
                assert!(worst <= 5, "{label}: {iterations:?}");
            }
        }
    }
}

/// The iterations-per-step table of `contact-patch friction-convergence` (issue 39): every
/// discretization and enforcement of the slip patch's sweep, the friction blocks and defect
/// N01, with this very build as the baseline: the baseline runner (a case file, `run`, its
/// summary) reads the same iterations and endings the in-process solves give, and every
/// penalty-type cell converges.
#[test]
fn the_iterations_per_step_table_reads_a_baseline_build_as_it_solves_in_process() {
    use contact_patch::harness::friction_convergence::{step_iterations, step_iterations_report};
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let work = tempfile::tempdir().unwrap();
    let binary = Path::new(env!("CARGO_BIN_EXE_contact-patch"));
    let rows = step_iterations(root, Some(binary), work.path()).unwrap();
    assert!(rows.len() >= 50, "{}", rows.len());
    assert!(rows.iter().any(|r| r.problem.starts_with("defect N01")));
    for r in &rows {
        let (iterations, termination) = r.baseline.clone().unwrap();
        let what = format!("{} / {} / {}", r.problem, r.discretization, r.enforcement);
        if r.termination == "converged" {
            assert_eq!(
                (&iterations, termination.as_str()),
                (&r.iterations, "converged"),
                "{what}"
            );
        } else {
            assert!(termination != "converged", "{what}: {termination}");
        }
        if r.enforcement == "penalty" || r.enforcement == "perturbed_lagrange" {
            assert!(
                r.termination == "converged" || r.termination.starts_with("refused: "),
                "{what}: {}",
                r.termination
            );
        }
    }
    let report = step_iterations_report(&rows, Some("this build"));
    assert!(report.contains("| before | after |"), "{report}");
}

/// `friction-convergence --baseline` runs the baseline build in a scratch folder inside the
/// output folder and removes only that folder: the files already in the output folder survive,
/// and nothing of the scratch folder is left.
#[test]
fn the_baseline_scratch_folder_is_removed_and_nothing_else() {
    let out = tempfile::tempdir().unwrap();
    let keep = out.path().join("keep.txt");
    std::fs::write(&keep, "must survive").unwrap();
    std::fs::create_dir(out.path().join("sub")).unwrap();
    std::fs::write(out.path().join("sub/also.txt"), "must survive").unwrap();
    let binary = env!("CARGO_BIN_EXE_contact-patch");
    let o = std::process::Command::new(binary)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["friction-convergence", "--baseline", binary, "--out"])
        .arg(out.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read_to_string(&keep).unwrap(), "must survive");
    assert_eq!(
        std::fs::read_to_string(out.path().join("sub/also.txt")).unwrap(),
        "must survive"
    );
    let mut names: Vec<String> = std::fs::read_dir(out.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "friction-convergence.json",
            "friction-convergence.md",
            "keep.txt",
            "sub"
        ]
    );
}

/// Issue 39, item 1: the state a step starts from is exact. The friction block is pressed and
/// slid by 5 (every point slips), or slid by 5 and moved back by 0.0002 (a reversal inside the
/// elastic range: the points stick, but for the ends), and then the same load is applied again
/// (a step that changes nothing). Starting from the committed forces and slips to the last
/// bit (the penalty map's trial `lambda_t^n - w_t (g_t - g_t^n)`; the augmented Lagrangian's
/// Uzawa multipliers with the stick point where the point ended), the repeated step is solved
/// at its first iterate: every point that slipped sits on the cone and sticks there, the
/// tangential force is the last step's to round-off, and nothing is dissipated. (An augmented
/// Lagrangian start from the last step's stick point missed the committed force of a sticking
/// point by `w_t` times what its Uzawa iteration left of `g_t^n - g_t^p`; Lagrange multipliers
/// that restarted from zero took up to 30 iterations back to the cone.)
#[test]
fn a_repeated_load_step_starts_and_ends_at_the_committed_state() {
    let paths = [
        ("after a slip", vec![(1.0, 0.0), (1.0, 5.0), (1.0, 5.0)]),
        (
            "after a reversal",
            vec![(1.0, 0.0), (1.0, 5.0), (1.0, 4.9998), (1.0, 4.9998)],
        ),
    ];
    let enforcements = [
        ("penalty", json!({"kind": "penalty", "kappa": 1e4})),
        (
            "perturbed Lagrangian",
            json!({"kind": "perturbed_lagrange", "kappa": 1e4}),
        ),
        (
            "augmented Lagrangian",
            json!({"kind": "augmented_lagrange", "kappa": 1e4}),
        ),
        (
            "augmented Lagrangian, outer loop",
            json!({"kind": "augmented_lagrange", "kappa": 1e4, "update": "outer_loop"}),
        ),
        ("Lagrange", json!({"kind": "lagrange"})),
    ];
    for (when, path) in &paths {
        for element in ["Q4", "Q9"] {
            for (name, enforcement) in &enforcements {
                let label = format!("{element}, {name}, {when}");
                let o = run(&friction_block(element, enforcement.clone(), path));
                let state = o.solution.contact.as_ref().unwrap();
                let n = path.len();
                assert_eq!(state.steps.len(), n, "{label}: {:?}", state.termination);
                let (last, repeated) = (&state.steps[n - 2], &state.steps[n - 1]);
                assert_eq!(repeated.termination, Termination::Converged, "{label}");
                let (a, b) = (
                    last.friction.as_ref().unwrap(),
                    repeated.friction.as_ref().unwrap(),
                );
                if *when == "after a slip" {
                    // slid by 5 (ten element lengths): every closed point slips
                    assert_eq!(a.stick, 0, "{label}: {a:?}");
                }
                assert!(a.slip + a.stick > 0, "{label}: {a:?}");
                // the repeated step: the points stick where they were (on the cone if they
                // slipped) with their force: the penalty laws and Lagrange multipliers (a
                // point on the cone within its round-off that does not move sticks). The
                // augmented Lagrangian's status of such a point is a tie: its normal force
                // restarts from its multiplier, the committed force, minus `w_n g_n^n` (the
                // gap its Uzawa iteration left, within its tolerance), so a point on the cone
                // may go on slipping by that much. Its force and dissipation are fixed all the
                // same
                let sticks_in_place = !name.starts_with("augmented");
                let closed = a.slip + a.stick;
                if sticks_in_place {
                    assert_eq!(
                        (b.slip, b.stick, b.open),
                        (0, closed, a.open),
                        "{label}: {b:?}"
                    );
                } else {
                    assert_eq!(
                        (b.slip + b.stick, b.open),
                        (closed, a.open),
                        "{label}: {b:?}"
                    );
                }
                // every method solves the repeated step at its first iterate (Lagrange
                // multipliers start the step from the committed forces; from zero they took 1
                // to 30 iterations back to the cone, within Newton's tolerance)
                let bound = MU * P * 2.0;
                let tol = 1e-12 * bound;
                assert!(
                    (b.tangential_force[0] - a.tangential_force[0]).abs() <= tol,
                    "{label}: {} then {}",
                    a.tangential_force[0],
                    b.tangential_force[0]
                );
                assert!(b.dissipation.abs() <= tol, "{label}: {b:?}");
                assert_eq!(repeated.iterations, 0, "{label}");
                println!(
                    "{label}: the repeated step in {} iterations, {:?}",
                    repeated.iterations, b
                );
            }
        }
    }
}
