//! `physics.kinematics: "finite"`: total-Lagrangian hyperelastic bodies solved by Newton in
//! load steps (cut in half when Newton fails), alone and in frictionless contact with rigid
//! masters in the current configuration.
//!
//! Every reference here is a closed form written out in this file: the homogeneous
//! deformation `x = F X` and the Cauchy stress of the material at `F`
//! (neo-Hookean `sigma = (mu (b - I) + lambda ln J I) / J`, `b = F F^T`; St. Venant-Kirchhoff
//! `sigma = F (lambda tr E I + 2 mu E) F^T / J`), the stretch of a block compressed between a
//! rigid plane and a prescribed top with free sides (`sigma_xx = 0` solved for the lateral
//! stretch by bisection), and the small-strain solution of the same scene at a small load.

mod finite_common;
use contact_patch::post::{cell_displacements, for_each_quadrature_stress};
use contact_patch::run::{run_case, Outcome};
use contact_patch::solid_finite::deformation_gradient_at;
use serde_json::{json, Value};

const E: f64 = 1000.0;
const NU: f64 = 0.3;

fn lame() -> (f64, f64) {
    (
        E * NU / ((1.0 + NU) * (1.0 - 2.0 * NU)),
        E / (2.0 * (1.0 + NU)),
    )
}

/// The Cauchy stress `[xx, yy, xy]` of `material` at the plane-strain deformation gradient `f`
/// (row-major), written out independently of the library.
fn cauchy(material: &str, f: [[f64; 2]; 2]) -> [f64; 3] {
    let (lambda, mu) = lame();
    let j = f[0][0] * f[1][1] - f[0][1] * f[1][0];
    let mut sigma = [[0.0; 2]; 2];
    match material {
        "neo_hookean" => {
            for i in 0..2 {
                for k in 0..2 {
                    let b = f[i][0] * f[k][0] + f[i][1] * f[k][1];
                    let delta = if i == k { 1.0 } else { 0.0 };
                    sigma[i][k] = (mu * (b - delta) + lambda * j.ln() * delta) / j;
                }
            }
        }
        _ => {
            let mut e = [[0.0; 2]; 2];
            for i in 0..2 {
                for k in 0..2 {
                    let c = f[0][i] * f[0][k] + f[1][i] * f[1][k];
                    e[i][k] = 0.5 * (c - if i == k { 1.0 } else { 0.0 });
                }
            }
            let tr = e[0][0] + e[1][1];
            let s = |i: usize, k: usize| {
                lambda * tr * if i == k { 1.0 } else { 0.0 } + 2.0 * mu * e[i][k]
            };
            for i in 0..2 {
                for k in 0..2 {
                    let mut v = 0.0;
                    for a in 0..2 {
                        for b in 0..2 {
                            v += f[i][a] * s(a, b) * f[k][b];
                        }
                    }
                    sigma[i][k] = v / j;
                }
            }
        }
    }
    [sigma[0][0], sigma[1][1], sigma[0][1]]
}

/// A distorted 3 x 3 block `[0, 2]^2` of `element` (the single-body patch test's mesh).
fn distorted_block(element: &str) -> Value {
    json!({"block": {
        "element": element,
        "x": [0, 0.5, 1.2, 2], "y": [0, 0.7, 1.3, 2],
        "moves": [
            {"from": [0.5, 0.7], "to": [0.62, 0.55]},
            {"from": [1.2, 1.3], "to": [1.05, 1.45]},
            {"from": [1.2, 0.7], "to": [1.32, 0.82]},
            {"from": [0.5, 1.3], "to": [0.38, 1.18]}
        ]
    }})
}

fn scene(material: &str, mesh: Value, steps: usize) -> Value {
    json!({
        "name": "finite",
        "description": "finite kinematics test",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": E, "nu": NU, "model": material}},
        "bodies": [{"name": "block", "material": "m", "mesh": mesh}],
        "physics": {"kinematics": "finite"},
        "solver": {"load_steps": steps},
        "supports": [],
        "loads": [],
        "checks": []
    })
}

fn run(case: &Value) -> contact_patch::Result<Outcome> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("case.json");
    std::fs::write(&path, serde_json::to_string_pretty(case).unwrap()).unwrap();
    run_case(&path, &mut |_| {})
}

/// The largest deviation of `F` from `target` over every stiffness quadrature point.
fn worst_gradient(o: &Outcome, target: [[f64; 2]; 2]) -> f64 {
    let body = &o.model.bodies[0];
    let mut ue = Vec::new();
    let mut worst = 0.0f64;
    for c in 0..body.mesh.cell_count() {
        cell_displacements(body, &o.solution.u, c, &mut ue);
        let coords = body.mesh.cell_coords(c);
        for q in body.mesh.kind.stiffness_rule() {
            let (f, _) = deformation_gradient_at(body.mesh.kind, &coords, &ue, q.xi);
            for i in 0..2 {
                for k in 0..2 {
                    worst = worst.max((f[(i, k)] - target[i][k]).abs());
                }
            }
        }
    }
    worst
}

/// The largest deviation of the reported (Cauchy) stress from `sigma` over every quadrature
/// point, relative to `max |sigma|`.
fn worst_stress(o: &Outcome, sigma: [f64; 3]) -> f64 {
    let scale = sigma.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0f64;
    for_each_quadrature_stress(&o.model.bodies[0], &o.solution.u, |_, _, s| {
        for i in 0..3 {
            worst = worst.max((s[i] - sigma[i]).abs() / scale);
        }
    });
    worst
}

/// Once the relative residual is below 1e-2, each is below `10 r^2` of the last one in the same
/// load step (or at round-off, 1e-13): the consistent tangent converges quadratically.
fn assert_quadratic(o: &Outcome) -> usize {
    let history = &o.solution.finite.as_ref().unwrap().history;
    let mut seen = 0;
    for w in history.windows(2) {
        if w[0].step == w[1].step && w[0].residual < 1e-2 && w[0].residual > 1e-13 {
            seen += 1;
            assert!(
                w[1].residual <= 10.0 * w[0].residual * w[0].residual + 1e-13,
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
    seen
}

/// The finite-strain patch test: every boundary node of a distorted mesh prescribed by the
/// homogeneous deformation `x = F X` (a stretch of 20 %, a compression of 10 % and a shear of
/// 0.1, through the case's `exact` field, whose displacement is `u = A X` with `A = F - I`
/// symmetric), in four load steps: the interior nodes follow, so `F` is exact at every
/// quadrature point (1e-10) and the reported stress is the material's Cauchy stress at `F`
/// (1e-10 relative), for Q4, Q9, T3, T6 and both materials; Newton converges quadratically.
#[test]
fn a_homogeneous_deformation_is_reproduced_on_a_distorted_mesh() {
    let a = [[0.2, 0.05], [0.05, -0.1]];
    let target = [[1.0 + a[0][0], a[0][1]], [a[1][0], 1.0 + a[1][1]]];
    // the small-strain stress whose exact displacement is u = A X (only the boundary values
    // are taken from it)
    let (lambda, mu) = lame();
    let stress = [
        (lambda + 2.0 * mu) * a[0][0] + lambda * a[1][1],
        lambda * a[0][0] + (lambda + 2.0 * mu) * a[1][1],
        mu * 2.0 * a[0][1],
    ];
    for material in ["neo_hookean", "saint_venant_kirchhoff"] {
        for element in ["Q4", "Q9", "T3", "T6"] {
            let mut case = scene(material, distorted_block(element), 4);
            case["exact"] = json!({"kind": "uniform_stress", "stress": stress});
            case["supports"] = json!(["left", "right", "top", "bottom"]
                .iter()
                .map(|s| json!({"body": "block", "set": s, "x": "exact", "y": "exact"}))
                .collect::<Vec<_>>());
            case["checks"] = json!([{"check": "exact_displacement", "tol": 1e-10}]);
            let o = run(&case).unwrap();
            assert!(o.passed(), "{element} {material}: {:?}", o.checks);
            let history = o.solution.finite.as_ref().unwrap();
            assert_eq!(history.steps.len(), 4, "{element}: {:?}", history.steps);
            assert!(history.steps.iter().all(|s| s.accepted));
            let f_error = worst_gradient(&o, target);
            let s_error = worst_stress(&o, cauchy(material, target));
            println!("{element} {material}: |F - F_exact| {f_error:.1e}, |sigma - sigma_exact| / |sigma| {s_error:.1e}, residuals {:?}",
                history.history.iter().map(|h| format!("{}:{:.1e}", h.step, h.residual)).collect::<Vec<_>>());
            assert!(
                f_error < 1e-10,
                "{element} {material}: F off by {f_error:e}"
            );
            assert!(
                s_error < 1e-10,
                "{element} {material}: sigma off by {s_error:e}"
            );
            assert!(
                assert_quadratic(&o) >= 4,
                "{element} {material}: too few steps to judge"
            );
        }
    }
}

/// A compression of 60 % of the height in one load step inverts the top row of elements at
/// the first iterate (the top moves below the next row of nodes): the step is cut, with the
/// inverted cell named, until the increments converge; the result is the homogeneous uniaxial
/// state (rollers on the left and bottom, free right side), the stretch `F_yy = 0.4` exact.
/// Asking for a compression beyond 100 % runs out of cuts and stops with an error that names
/// the inverted cell and the load step.
#[test]
fn failed_steps_are_cut_in_half_and_inversion_is_refused_by_name() {
    let mut case = scene("neo_hookean", distorted_block("Q4"), 1);
    case["supports"] = json!([
        {"body": "block", "set": "left", "x": 0.0},
        {"body": "block", "set": "bottom", "y": 0.0},
        {"body": "block", "set": "top", "y": -1.2}
    ]);
    case["checks"] = json!([{"check": "equilibrium", "tol": 1e-10}]);
    let o = run(&case).unwrap();
    let history = o.solution.finite.as_ref().unwrap();
    assert!(history.cuts >= 1, "{:?}", history.steps);
    let first = &history.steps[0];
    assert!(!first.accepted);
    let why = first.cut_because.as_deref().unwrap();
    assert!(
        why.contains("inverted") && why.contains("body 'block'") && why.contains("cell"),
        "{why}"
    );
    assert_eq!(history.steps.last().unwrap().to, 1.0);
    assert!(history.steps.last().unwrap().accepted);
    // free right side: sigma_xx = 0 fixes the lateral stretch a with mu (a^2 - 1) +
    // lambda ln(0.4 a) = 0
    let (lambda, mu) = lame();
    let (mut lo, mut hi) = (1.0, 3.0);
    for _ in 0..200 {
        let m = 0.5 * (lo + hi);
        if mu * (m * m - 1.0) + lambda * (0.4 * m).ln() > 0.0 {
            hi = m;
        } else {
            lo = m;
        }
    }
    let a = 0.5 * (lo + hi);
    let f_error = worst_gradient(&o, [[a, 0.0], [0.0, 0.4]]);
    println!(
        "cuts {}, lateral stretch {a}, |F - F_exact| {f_error:.1e}",
        history.cuts
    );
    assert!(f_error < 1e-10, "{f_error:e}");

    case["supports"][2]["y"] = json!(-2.1);
    let err = run(&case).unwrap_err().to_string();
    assert!(
        err.contains("inverted") && err.contains("load step") && err.contains("cell"),
        "{err}"
    );
}

/// The small-strain limit: a block clamped on the left and sheared by a traction on the right
/// gives, at load `p`, a finite-strain displacement that differs from the small-strain one by
/// `O(p^2)`: the difference quarters when the load halves (ratio 4 to 5 %), while it is a small
/// share of the displacement (below 1e-3 at the smaller load).
#[test]
fn at_small_load_finite_and_small_strain_agree_to_second_order() {
    let solve = |material: &str, p: f64| {
        let mut case = scene(material, distorted_block("Q9"), 1);
        if material == "linear_elastic" {
            case["physics"] = json!({});
        }
        case["supports"] = json!([{"body": "block", "set": "left", "x": 0.0, "y": 0.0}]);
        case["loads"] = json!([{"body": "block", "set": "right", "traction": [0.2 * p, p]}]);
        case["checks"] = json!([{"check": "equilibrium", "tol": 1e-10}]);
        run(&case).unwrap().solution.u
    };
    for material in ["neo_hookean", "saint_venant_kirchhoff"] {
        let difference = |p: f64| {
            let (f, s) = (solve(material, p), solve("linear_elastic", p));
            let d = f
                .iter()
                .zip(&s)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            let size = s.iter().fold(0.0f64, |m, a| m.max(a.abs()));
            (d, d / size)
        };
        let ((d1, _), (d2, share)) = (difference(0.1), difference(0.05));
        println!(
            "{material}: difference {d1:.3e} at p = 0.1, {d2:.3e} at p = 0.05, ratio {:.4}",
            d1 / d2
        );
        assert!((d1 / d2 - 4.0).abs() < 0.2, "{material}: ratio {}", d1 / d2);
        assert!(share < 1e-3, "{material}: share {share}");
    }
}

/// The refusals: finite kinematics with friction, with dynamics, with contact between
/// deformable bodies, in plane stress, with a linear-elastic material; a hyperelastic material
/// under small strain. Each names the field and says how to fix it.
#[test]
fn combinations_not_built_are_refused_with_the_reason() {
    let base = scene("neo_hookean", distorted_block("Q4"), 1);
    let expect = |case: &Value, field: &str, words: &str| {
        let err = run(case).unwrap_err().to_string();
        assert!(err.contains(field) && err.contains(words), "{err}");
    };
    let mut c = base.clone();
    c["analysis"]["plane"] = json!("stress");
    expect(&c, "analysis.plane", "plane strain only");
    let mut c = base.clone();
    c["materials"]["m"]["model"] = json!("linear_elastic");
    expect(&c, "material", "needs a hyperelastic material");
    let mut c = base.clone();
    c["physics"] = json!({});
    expect(&c, "materials.m.model", "needs finite kinematics");
    let mut c = base.clone();
    c["materials"]["m"]["density"] = json!(1.0);
    c["physics"]["dynamics"] = json!({"dt": 0.1, "end_time": 1.0});
    c["supports"] = json!([{"body": "block", "set": "left", "x": 0.0, "y": 0.0}]);
    expect(&c, "physics.dynamics", "not built yet");
    let rigid = json!({"rigid": {"kind": "line", "point": [0, 0], "normal": [0, 1]}});
    let mut c = base.clone();
    c["supports"] = json!([{"body": "block", "set": "left", "x": 0.0}]);
    c["physics"]["contact_geometry"] = json!("reference");
    c["solver"]["scheme"] = json!("newton");
    c["contact"] = json!([{
        "name": "ground", "slave": {"body": "block", "set": "bottom"}, "master": rigid,
        "discretization": {"kind": "node_to_surface", "passes": 1},
        "enforcement": {"kind": "penalty", "kappa": 1e5},
        "interaction": {"coulomb": {"mu": 0.3, "kappa_t": 1e5}}
    }]);
    // against a curved master friction under finite kinematics is refused (against a rigid
    // line or plane it is solved: tests/friction.rs)
    let mut curved = c.clone();
    curved["contact"][0]["master"] =
        json!({"rigid": {"kind": "circle", "centre": [1.0, -10.0], "radius": 10.0}});
    expect(&curved, "interaction", "rigid line or plane only");
    let mut d = c.clone();
    d["contact"][0]
        .as_object_mut()
        .unwrap()
        .remove("interaction");
    d["physics"]["contact_geometry"] = json!("current");
    d["solver"]["scheme"] = json!("active_set");
    expect(&d, "solver.scheme", "Newton scheme only");
    let mut d = c.clone();
    d["contact"][0]
        .as_object_mut()
        .unwrap()
        .remove("interaction");
    d["physics"]["contact_geometry"] = json!("current");
    d["physics"]["contact_geometry"] = json!("reference");
    expect(&d, "physics.contact_geometry", "current configuration");
    let mut d = c.clone();
    d["contact"][0]
        .as_object_mut()
        .unwrap()
        .remove("interaction");
    d["physics"]["contact_geometry"] = json!("current");
    d["bodies"] = json!([
        {"name": "block", "material": "m", "mesh": distorted_block("Q4")},
        {"name": "base", "material": "m", "mesh": {"block": {"element": "Q4", "x": [-1, 3], "y": [-1, 0]}}}
    ]);
    d["contact"][0]["master"] = json!({"body": "base", "set": "top"});
    d["supports"] = json!([
        {"body": "base", "set": "bottom", "x": 0.0, "y": 0.0},
        {"body": "block", "set": "left", "x": 0.0}
    ]);
    // between deformable bodies: node-to-surface with master normals (tests/finite_contact.rs)
    // and with slave normals, node-to-node where the nodes match
    // (tests/finite_slave_normals.rs), and standard and dual mortar (tests/finite_mortar.rs)
    // are built; ties are refused
    let mut e = d.clone();
    for multiplier in ["standard", "dual"] {
        e["contact"][0]["discretization"] = json!({"kind": "mortar", "multiplier": multiplier});
        let case = contact_patch::model::parse(&e.to_string(), "mortar").unwrap();
        contact_patch::model::Model::build(&case, "mortar")
            .unwrap_or_else(|err| panic!("{multiplier} mortar is admitted: {err}"));
    }
    // node-to-node on this non-matching interface: refused with the reason before any solve
    e["contact"][0]["discretization"] = json!({"kind": "node_to_node"});
    expect(&e, "contact 'ground'", "the interface nodes do not match");
    // the slave normals' linearization is chosen where it means something only
    e["contact"][0]["discretization"] = json!({"kind": "node_to_surface", "normal": "master", "slave_normal_variation": "smooth_sliding"});
    expect(
        &e,
        "discretization.slave_normal_variation",
        "this pair takes master normals",
    );
    let mut small = e.clone();
    small["contact"][0]["discretization"] = json!({"kind": "node_to_surface", "normal": "slave", "slave_normal_variation": "consistent"});
    small["physics"] = json!({"contact_geometry": "current"});
    small["materials"]["m"]["model"] = json!("linear_elastic");
    expect(
        &small,
        "discretization.slave_normal_variation",
        "this case is small strain",
    );
    let mut against_rigid = c.clone();
    against_rigid["contact"][0]
        .as_object_mut()
        .unwrap()
        .remove("interaction");
    against_rigid["physics"]["contact_geometry"] = json!("current");
    against_rigid["contact"][0]["discretization"] = json!({"kind": "node_to_surface", "normal": "slave", "slave_normal_variation": "consistent"});
    expect(
        &against_rigid,
        "discretization.slave_normal_variation",
        "this pair's master is rigid",
    );
    e["contact"][0]["discretization"] = json!({"kind": "node_to_surface"});
    e["contact"][0]["interaction"] = json!("tied");
    expect(
        &e,
        "interaction",
        "tied pair between deformable bodies is not built yet",
    );
}

/// A block between a rigid plane `y = 0` (frictionless contact of its bottom, node-to-surface
/// against the rigid master, in the current configuration) and a top pushed down by 20 % of
/// its height, pinned in x at one corner: the homogeneous uniaxial state is exact. With
/// Lagrange multipliers `F = diag(a, 0.8)` (`a` from `sigma_xx = 0`, neo-Hookean) at every
/// quadrature point to 1e-10; with the penalty the bottom penetrates uniformly, so `F` is
/// still uniform and diagonal (to 1e-10) and `sigma_xx = 0` (1e-10 of `sigma_yy`). Q4, Q9, T3,
/// T6 on the distorted mesh; the contact force balances the top's reaction.
#[test]
fn a_block_compressed_by_twenty_percent_on_a_rigid_plane_deforms_homogeneously() {
    let (lambda, mu) = lame();
    let (mut lo, mut hi) = (1.0, 3.0);
    for _ in 0..200 {
        let m = 0.5 * (lo + hi);
        if mu * (m * m - 1.0) + lambda * (0.8 * m).ln() > 0.0 {
            hi = m;
        } else {
            lo = m;
        }
    }
    let a = 0.5 * (lo + hi);
    for enforcement in [
        json!({"kind": "lagrange"}),
        json!({"kind": "penalty", "kappa": 1e6}),
    ] {
        for element in ["Q4", "Q9", "T3", "T6"] {
            let mut case = scene("neo_hookean", distorted_block(element), 2);
            case["physics"]["contact_geometry"] = json!("current");
            case["solver"]["scheme"] = json!("newton");
            case["supports"] = json!([
                {"body": "block", "set": "bottom_left", "x": 0.0},
                {"body": "block", "set": "top", "y": -0.4}
            ]);
            case["contact"] = json!([{
                "name": "ground", "slave": {"body": "block", "set": "bottom"},
                "master": {"rigid": {"kind": "line", "point": [0, 0], "normal": [0, 1]}},
                "discretization": {"kind": "node_to_surface", "passes": 1},
                "enforcement": enforcement
            }]);
            case["checks"] = json!([{"check": "force_balance", "tol": 1e-10}]);
            let o = run(&case).unwrap();
            assert!(o.passed(), "{element}: {:?}", o.checks);
            let mut points = Vec::new();
            let body = &o.model.bodies[0];
            let mut ue = Vec::new();
            for c in 0..body.mesh.cell_count() {
                cell_displacements(body, &o.solution.u, c, &mut ue);
                for q in body.mesh.kind.stiffness_rule() {
                    let (f, _) = deformation_gradient_at(
                        body.mesh.kind,
                        &body.mesh.cell_coords(c),
                        &ue,
                        q.xi,
                    );
                    points.push([f[(0, 0)], f[(0, 1)], f[(1, 0)], f[(1, 1)]]);
                }
            }
            let first = points[0];
            let spread = points.iter().fold(0.0f64, |m, p| {
                (0..4).fold(m, |m, i| m.max((p[i] - first[i]).abs()))
            });
            let off_diagonal = first[1].abs().max(first[2].abs());
            let mut worst_xx = 0.0f64;
            let mut largest_yy = 0.0f64;
            for_each_quadrature_stress(body, &o.solution.u, |_, _, s| {
                worst_xx = worst_xx.max(s[0].abs());
                largest_yy = largest_yy.max(s[1].abs());
            });
            let exact = if enforcement["kind"] == "lagrange" {
                worst_gradient(&o, [[a, 0.0], [0.0, 0.8]])
            } else {
                0.0
            };
            let history = o.solution.finite.as_ref().unwrap();
            println!(
                "{element} {}: F spread {spread:.1e}, |F - F_exact| {exact:.1e}, F = {first:?}, sigma_xx / sigma_yy {:.1e}, residuals {:?}",
                enforcement["kind"],
                worst_xx / largest_yy,
                history.history.iter().map(|h| format!("{}:{:.1e}", h.step, h.residual)).collect::<Vec<_>>()
            );
            assert!(
                spread < 1e-10 && off_diagonal < 1e-10,
                "{element}: {spread:e}"
            );
            assert!(exact < 1e-10, "{element}: {exact:e}");
            assert!(worst_xx < 1e-10 * largest_yy, "{element}: {worst_xx:e}");
            assert!(largest_yy > 10.0, "{element}: the block is compressed");
        }
    }
}

/// The tangent of the whole Newton system (hyperelastic solid plus penalty rows against a
/// rigid circle, with the second derivative of the circle's gap) is the central difference of
/// its residual at a deformed, penetrating state off equilibrium, to 1e-6 of its largest
/// entry: node-to-surface rows, and standard and dual mortar rows (the weighted gap's second
/// derivative, `mortar_linearization::linearize_rigid_row`: the length element and the
/// distance at every Gauss point vary with the positions).
#[test]
fn the_newton_tangent_with_a_rigid_circle_is_the_difference_of_the_residual() {
    use contact_patch::solver::contact_newton::Probe;
    for discretization in [
        json!({"kind": "node_to_surface", "passes": 1}),
        json!({"kind": "mortar", "multiplier": "standard"}),
        json!({"kind": "mortar", "multiplier": "dual"}),
    ] {
        let mut case = scene("neo_hookean", distorted_block("Q4"), 1);
        case["physics"]["contact_geometry"] = json!("current");
        case["solver"]["scheme"] = json!("newton");
        case["supports"] = json!([{"body": "block", "set": "top", "x": 0.1, "y": -0.3}]);
        case["contact"] = json!([{
            "name": "roller", "slave": {"body": "block", "set": "bottom"},
            "master": {"rigid": {"kind": "circle", "centre": [1.0, -3.0], "radius": 3.0}},
            "discretization": discretization,
            "enforcement": {"kind": "penalty", "kappa": 1e4}
        }]);
        case["checks"] = json!([{"check": "force_balance", "tol": 1e-8}]);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("case.json");
        std::fs::write(&path, serde_json::to_string_pretty(&case).unwrap()).unwrap();
        let o = run_case(&path, &mut |_| {}).unwrap();
        assert!(o.passed(), "{:?}", o.checks);
        let model = contact_patch::model::admit::load(&path).unwrap();
        let mut probe = Probe::new(&model, 0.0).unwrap();
        // off equilibrium: the solution pushed further down by a nonuniform amount
        let mut x = probe.unknowns(&o.solution.u);
        for (i, v) in x.iter_mut().enumerate() {
            *v += 1e-3 * (0.7 * i as f64).sin() - 5e-3 * (i % 2) as f64;
        }
        let at = probe.evaluate(&x).unwrap();
        let (worst, scale) = finite_common::tangent_difference(&mut probe, &x, &at);
        println!(
            "{discretization}: Newton tangent vs central difference: {worst:.1e} of {scale:.3e}"
        );
        assert!(worst < 1e-6, "{discretization}: {worst:e}");
    }
}
