//! Coulomb friction in 3D (issue 13, build item 4): the 2D Newton scheme and return map,
//! generic over the dimension, with the radial return on the disc `|lambda_t| <= mu lambda_n`
//! and two tangential rows per node-based row (`contact::discretization::pair3`).
//!
//! * The frictional tangent of 3D rows against central differences of the residual, in stick
//!   and in slip along several directions, for every node-based discretization.
//! * A block pressed on a rigid plane, then dragged by its top in an arbitrary direction of the
//!   plane (a load path: press, then push with the slip committed): below the Coulomb limit
//!   every point sticks; above it every point slips and the tangential force is `mu N` against
//!   the push; the dissipation is never negative.
//! * Invariance: the mesh and the push rotated together about the normal give the rotated
//!   nodal forces, in stick, partial slip and full slip (the frame of the tangent plane is a
//!   function of the normal alone, not of the mesh).
//! * Plane strain: a 3D block one element thick with `u_y = 0` reproduces the forces of the
//!   2D case (the disc with zero slip along y is the scalar map).
//! * Lagrange multipliers (two tangential multipliers per row, the semi-smooth sets on the
//!   disc) and mortar rows (standard and dual, the weighted tangential slip): the tangent
//!   against central differences in stick and slip (the turn of the slip direction included);
//!   the dragged slab sticks below and slips at `mu N` above the limit; the penalty's forces
//!   approach the Lagrange ones as `1/kappa` (kappa 1e3 to 1e8); the penalty's Newton
//!   iteration, which diverged into a cycle on the partial-slip cube at kappa 1e5 and 1e8,
//!   converges there in at most 5 iterations a step with every step under the line search on
//!   the residual norm; a punch dragged over its foundation by mortar
//!   rows slips at `mu N` with the forces on the two bodies in balance; rotation invariance
//!   of mortar friction; a two-body slab one element thick reproduces 2D plane-strain mortar
//!   and Lagrange friction.
//! * Mortar friction on triangular facets: the dragged punch with Tet4 (Tri3) and Tet10 (Tri6,
//!   the modified multiplier basis) bodies sticks below and slips at `mu N` above the limit,
//!   with the dissipation never negative and the forces on the two bodies in balance.

use contact_patch::contact::friction::Status;
use contact_patch::contact::state::{ContactState, Termination};
use contact_patch::run::run_case3;
use contact_patch::run3d::{build3, Outcome3};
use contact_patch::solver::contact_newton::Probe;
use serde_json::{json, Value};

const MU: f64 = 0.3;
const P: f64 = 10.0;

fn run(case: &Value) -> Outcome3 {
    let parsed = contact_patch::model::parse(&case.to_string(), "friction3d").unwrap();
    run_case3(&parsed, "friction3d").unwrap_or_else(|e| panic!("{e}"))
}

fn termination(o: &Outcome3) -> Termination {
    o.solution.contact.as_ref().unwrap().termination.clone()
}

/// A block `[0, 1]^2 x [0, h]` of `material` `(E, nu)` (Hex8, 2 x 2 x 2 elements), its
/// vertices rotated by `rotation` about the vertical axis through `(0.5, 0.5)`, pressed by `P`
/// onto the rigid plane `z = 0` in step 1 and dragged in step 2 by a prescribed displacement
/// `drag` (x, y) of its top: the pressure on the path `[1, 1]`, the drag on `[0, 1]`.
fn dragged_block(
    (e_modulus, nu, h): (f64, f64, f64),
    rotation: f64,
    drag: [f64; 2],
    enforcement: Value,
) -> Value {
    let breaks = [0.0, 0.5, 1.0];
    let heights = [0.0, 0.5 * h, h];
    let (c, s) = (rotation.cos(), rotation.sin());
    let mut moves = Vec::new();
    for &x in &breaks {
        for &y in &breaks {
            for &z in &heights {
                let (dx, dy) = (x - 0.5, y - 0.5);
                moves.push(json!({"from": [x, y, z],
                    "to": [0.5 + c * dx - s * dy, 0.5 + s * dx + c * dy, z]}));
            }
        }
    }
    json!({
        "name": "dragged-3d",
        "materials": {"m": {"E": e_modulus, "nu": nu}},
        "bodies": [{"name": "block", "material": "m", "mesh": {"block3d": {"element": "Hex8",
            "x": breaks, "y": breaks, "z": heights, "moves": moves}}}],
        "supports": [{"body": "block", "set": "top", "x": drag[0], "y": drag[1], "path": [0.0, 1.0]}],
        "loads": [{"body": "block", "set": "top", "pressure": P, "path": [1.0, 1.0]}],
        "contact": [{
            "name": "base",
            "slave": {"body": "block", "set": "bottom"},
            "master": {"rigid": {"kind": "plane", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]}},
            "discretization": {"kind": "node_to_surface", "passes": 1},
            "enforcement": enforcement,
            "interaction": {"coulomb": {"mu": MU}},
        }],
        "solver": {"scheme": "newton", "load_steps": 2},
    })
}

/// The unit cube of E = 1000: soft against the contact's kappa, tall enough to tip.
const CUBE: (f64, f64, f64) = (1000.0, 0.0, 1.0);

/// A stiff, flat block (E = 1e6, height 0.2): it slides nearly as a rigid body and keeps every
/// bottom point closed (the drag's moment `mu N h = 0.6` is below `N a / 6 = 1.67`, where the
/// trailing edge of a rigid block would lift).
const STIFF_SLAB: (f64, f64, f64) = (1e6, 0.0, 0.2);

fn penalty() -> Value {
    json!({"kind": "penalty", "kappa": 1e4})
}

/// The tangential force on the slave nodes summed (x, y, z), the normal force, and the closed
/// points' statuses.
fn totals(state: &ContactState<3>) -> ([f64; 3], f64, Vec<Status>) {
    let mut tangential = [0.0; 3];
    let mut normal = 0.0;
    let mut statuses = Vec::new();
    for ((r, f), &lambda_n) in state.rows.iter().zip(&state.friction).zip(&state.forces) {
        let f = f.expect("every row of a Coulomb pair is frictional");
        let v = f.force_vector(&r.tangents);
        for k in 0..3 {
            tangential[k] += v[k];
        }
        normal += lambda_n;
        if f.status != Status::Open {
            statuses.push(f.status);
        }
    }
    (tangential, normal, statuses)
}

#[test]
fn a_block_dragged_on_a_rigid_plane_sticks_below_and_slips_at_mu_n_above_the_limit() {
    // the stiff slab: a drag of 1e-4 loads the tangential springs (kappa A) to about mu N / 3;
    // a drag of 1 slips every point. A deformable block's points slip along their own
    // directions, turned from the drag by its elastic shear (about mu p h / (G d) = 1.2e-6
    // here): the total force along the drag is mu N to second order in that angle, across it
    // to first order
    for angle in [0.0f64, 0.7, 2.2, -1.9] {
        let e = [angle.cos(), angle.sin()];
        for (d, expect) in [(1e-4, Status::Stick), (1.0, Status::Slip)] {
            let o = run(&dragged_block(
                STIFF_SLAB,
                0.0,
                [d * e[0], d * e[1]],
                penalty(),
            ));
            assert_eq!(termination(&o), Termination::Converged, "{angle} {d}");
            let state = o.solution.contact.as_ref().unwrap();
            assert_eq!(state.steps.len(), 2);
            let (t, n, statuses) = totals(state);
            assert!(
                (n - P).abs() <= 1e-9 * P,
                "the normal force {n} carries the pressure"
            );
            assert_eq!(statuses.len(), 9, "every bottom node is closed");
            assert!(
                statuses.iter().all(|&s| s == expect),
                "{angle} {d}: {statuses:?}"
            );
            let magnitude = (t[0] * t[0] + t[1] * t[1]).sqrt();
            // the force on the block opposes the drag, in the plane
            let along = -(t[0] * e[0] + t[1] * e[1]);
            let across = t[0] * e[1] - t[1] * e[0];
            println!(
                "drag {d} along {angle}: {expect:?}, |F_t| = {magnitude:.12}, mu N = {:.12}",
                MU * n
            );
            let across_bound = if expect == Status::Stick { 1e-12 } else { 1e-5 };
            assert!(
                t[2].abs() <= 1e-12 * P && across.abs() <= across_bound * MU * n,
                "{t:?}: across {across:e}"
            );
            for step in &state.steps {
                let f = step.friction.as_ref().unwrap();
                assert!(f.dissipation >= 0.0, "{f:?}");
                assert!(f.max_cone_ratio <= 1.0 + 1e-12, "{f:?}");
            }
            let last = state.steps.last().unwrap().friction.as_ref().unwrap();
            match expect {
                Status::Stick => {
                    // no slip: the plastic slip stays at zero, nothing is dissipated
                    assert!(magnitude < MU * n && along > 0.0, "{magnitude}");
                    assert_eq!(last.dissipation, 0.0);
                    for f in state.friction.iter().flatten() {
                        assert_eq!(f.plastic_slip, [0.0; 2]);
                    }
                }
                _ => {
                    assert!(
                        (along - MU * n).abs() <= 1e-10 * MU * n,
                        "{along} vs {}",
                        MU * n
                    );
                    assert!(last.dissipation > 0.0);
                    for f in state.friction.iter().flatten() {
                        assert!((f.force_length() - MU * f.normal_force).abs() <= 1e-12 * P);
                    }
                }
            }
        }
    }
}

#[test]
fn rotating_the_mesh_and_the_drag_about_the_normal_rotates_the_answer() {
    // nu = 0.3: the Poisson expansion under the pressure meets friction, so a moderate drag
    // leaves the points partly stuck and partly slipping (a non-linear answer)
    for d in [2e-4, 4e-3, 0.05] {
        let base = run(&dragged_block((1000.0, 0.3, 1.0), 0.0, [d, 0.0], penalty()));
        assert_eq!(termination(&base), Termination::Converged);
        let b = base.solution.contact.as_ref().unwrap();
        let mut count = [0usize; 2];
        for f in b.friction.iter().flatten() {
            count[usize::from(f.status == Status::Slip)] += 1;
        }
        println!("drag {d}: {} stick, {} slip", count[0], count[1]);
        for angle in [0.4f64, 1.3, 3.0] {
            let (c, s) = (angle.cos(), angle.sin());
            let o = run(&dragged_block(
                (1000.0, 0.3, 1.0),
                angle,
                [c * d, s * d],
                penalty(),
            ));
            assert_eq!(termination(&o), Termination::Converged);
            let r = o.solution.contact.as_ref().unwrap();
            assert_eq!(r.rows.len(), b.rows.len());
            for i in 0..b.rows.len() {
                // the same slave node (moves keep the numbering)
                assert_eq!(r.rows[i].slave_node, b.rows[i].slave_node);
                let (fb, fr) = (b.friction[i].unwrap(), r.friction[i].unwrap());
                assert_eq!(fb.status, fr.status, "drag {d}, angle {angle}, row {i}");
                let vb = fb.force_vector(&b.rows[i].tangents);
                let vr = fr.force_vector(&r.rows[i].tangents);
                let expected = [c * vb[0] - s * vb[1], s * vb[0] + c * vb[1], vb[2]];
                for k in 0..3 {
                    assert!(
                        (vr[k] - expected[k]).abs() <= 1e-9 * P,
                        "drag {d}, angle {angle}, row {i}: {vr:?} vs {expected:?}"
                    );
                }
                assert!((r.forces[i] - b.forces[i]).abs() <= 1e-9 * P);
            }
        }
    }
}

/// Largest difference between the tangent's columns and central differences of the residual,
/// relative to the largest tangent entry, at the converged state of `o` (one load step: the
/// committed slip is zero), with every closed point in status `expect`.
fn fd_error(case: &Value, o: &Outcome3, expect: Status) -> f64 {
    let parsed = contact_patch::model::parse(&case.to_string(), "friction3d").unwrap();
    let model = build3(&parsed, "friction3d").unwrap();
    let mut probe = Probe::new(&model, 0.0).unwrap();
    let x = probe.unknowns_at(&o.solution.u, o.solution.contact.as_ref().unwrap());
    let at = probe.evaluate(&x).unwrap();
    assert!(
        at.statuses
            .iter()
            .all(|&s| s == expect || s == Status::Open),
        "{:?}",
        at.statuses
    );
    assert!(at.statuses.contains(&expect));
    assert_eq!(at.symmetric, expect != Status::Slip);
    let scale = at
        .tangent
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
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

/// A punch `[0, 1]^2 x [1, 1.5]` (Hex8, `n` elements a side) pressed onto a foundation `[0,
/// 1]^2 x [0, 1]` (2 a side) and dragged by its top along `angle` by `d`, in one step, with the
/// pair's discretization `disc`.
fn dragged_punch(disc: Value, n: usize, angle: f64, d: f64) -> Value {
    let punch: Vec<f64> = (0..=n).map(|i| i as f64 / n as f64).collect();
    json!({
        "name": "punch-3d",
        "materials": {"m": {"E": 1000.0, "nu": 0.0}},
        "bodies": [
            {"name": "foundation", "material": "m", "mesh": {"block3d": {"element": "Hex8",
                "x": [0, 0.5, 1], "y": [0, 0.5, 1], "z": [0, 1]}}},
            {"name": "punch", "material": "m", "mesh": {"block3d": {"element": "Hex8",
                "x": punch, "y": punch, "z": [1, 1.5]}}}
        ],
        "supports": [
            {"body": "foundation", "set": "bottom", "x": 0.0, "y": 0.0, "z": 0.0},
            {"body": "punch", "set": "top", "x": d * angle.cos(), "y": d * angle.sin()}
        ],
        "loads": [{"body": "punch", "set": "top", "pressure": P}],
        "contact": [{
            "name": "interface",
            "slave": {"body": "punch", "set": "bottom"},
            "master": {"body": "foundation", "set": "top"},
            "discretization": disc,
            "enforcement": {"kind": "penalty", "kappa": 1e4},
            "interaction": {"coulomb": {"mu": MU}},
        }],
        "solver": {"scheme": "newton"},
    })
}

fn one_step_block(master: Value, angle: f64, d: f64) -> Value {
    let mut v = dragged_block(CUBE, 0.0, [d * angle.cos(), d * angle.sin()], penalty());
    v["contact"][0]["master"] = json!({"rigid": master});
    v["solver"]["load_steps"] = json!(1);
    v["supports"][0].as_object_mut().unwrap().remove("path");
    v["loads"][0].as_object_mut().unwrap().remove("path");
    v
}

#[test]
fn the_3d_frictional_tangent_is_the_derivative_of_the_residual_in_stick_and_slip() {
    let plane = json!({"kind": "plane", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]});
    // a sphere of radius 1000 under the block's centre: every bottom node touches it, with
    // normals tilted by up to 7e-4
    let sphere = json!({"kind": "sphere", "centre": [0.5, 0.5, -1000.0], "radius": 1000.0});
    for angle in [0.3f64, 1.9, 4.0] {
        let cases = [
            (
                "rigid plane",
                one_step_block(plane.clone(), angle, 0.05),
                one_step_block(plane.clone(), angle, 1e-6),
            ),
            (
                "rigid sphere",
                one_step_block(sphere.clone(), angle, 0.05),
                one_step_block(sphere.clone(), angle, 1e-6),
            ),
            (
                "node-to-surface",
                dragged_punch(
                    json!({"kind": "node_to_surface", "passes": 1}),
                    3,
                    angle,
                    0.05,
                ),
                dragged_punch(
                    json!({"kind": "node_to_surface", "passes": 1}),
                    3,
                    angle,
                    1e-6,
                ),
            ),
            (
                "node-to-node",
                dragged_punch(json!({"kind": "node_to_node"}), 2, angle, 0.05),
                dragged_punch(json!({"kind": "node_to_node"}), 2, angle, 1e-6),
            ),
        ];
        for (name, slip, stick) in cases {
            for (v, status) in [(stick, Status::Stick), (slip, Status::Slip)] {
                let o = run(&v);
                assert_eq!(
                    termination(&o),
                    Termination::Converged,
                    "{name} {angle} {status:?}"
                );
                let e = fd_error(&v, &o, status);
                println!("{name}, drag along {angle}, {status:?}: tangent vs central differences {e:.1e}");
                assert!(e < 1e-6, "{name} {angle} {status:?}: {e:e}");
            }
        }
    }
}

#[test]
fn a_block_one_element_thick_reproduces_the_plane_strain_forces() {
    // 2D: block [0, 2] x [0, 1] (Q4 4 x 2) on the rigid line y = 0, pressed by P and dragged by
    // its top along x, in two steps (press, then drag); 3D: the same block in x and z, one
    // element through y (thickness 1) with u_y = 0 everywhere, on the plane z = 0
    for (d, nu) in [(2e-4, 0.0), (0.05, 0.0), (4e-3, 0.3)] {
        let two = json!({
            "name": "plane-strain-2d",
            "analysis": {"plane": "strain", "thickness": 1.0},
            "materials": {"m": {"E": 1000.0, "nu": nu}},
            "bodies": [{"name": "block", "material": "m",
                "mesh": {"block": {"element": "Q4", "x": [0, 0.5, 1, 1.5, 2], "y": [0, 0.5, 1]}}}],
            "supports": [{"body": "block", "set": "top", "x": d, "path": [0.0, 1.0]}],
            "loads": [{"body": "block", "set": "top", "pressure": P, "path": [1.0, 1.0]}],
            "contact": [{
                "name": "base",
                "slave": {"body": "block", "set": "bottom"},
                "master": {"rigid": {"kind": "line", "point": [0.0, 0.0], "normal": [0.0, 1.0]}},
                "discretization": {"kind": "node_to_surface", "passes": 1},
                "enforcement": {"kind": "penalty", "kappa": 1e4},
                "interaction": {"coulomb": {"mu": MU}},
            }],
            "solver": {"scheme": "newton", "load_steps": 2},
        });
        let parsed = contact_patch::model::parse(&two.to_string(), "plane-strain-2d").unwrap();
        let model = contact_patch::model::Model::build(&parsed, "plane-strain-2d").unwrap();
        let o2 = contact_patch::run::run_model(model, 0.0, std::time::Instant::now(), &mut |_| {})
            .unwrap();
        let s2 = o2.solution.contact.as_ref().unwrap();
        assert_eq!(s2.termination, Termination::Converged);
        let three = json!({
            "name": "plane-strain-3d",
            "materials": {"m": {"E": 1000.0, "nu": nu}},
            "bodies": [{"name": "block", "material": "m", "mesh": {"block3d": {"element": "Hex8",
                "x": [0, 0.5, 1, 1.5, 2], "y": [0, 1], "z": [0, 0.5, 1]}}}],
            "supports": [
                {"body": "block", "set": "all", "y": 0.0},
                {"body": "block", "set": "top", "x": d, "path": [0.0, 1.0]}
            ],
            "loads": [{"body": "block", "set": "top", "pressure": P, "path": [1.0, 1.0]}],
            "contact": [{
                "name": "base",
                "slave": {"body": "block", "set": "bottom"},
                "master": {"rigid": {"kind": "plane", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]}},
                "discretization": {"kind": "node_to_surface", "passes": 1},
                "enforcement": {"kind": "penalty", "kappa": 1e4},
                "interaction": {"coulomb": {"mu": MU}},
            }],
            "solver": {"scheme": "newton", "load_steps": 2},
        });
        let o3 = run(&three);
        let s3 = o3.solution.contact.as_ref().unwrap();
        assert_eq!(s3.termination, Termination::Converged);
        // each 2D slave node at x has two 3D slave nodes (y = 0 and 1), each with half its
        // area: their forces sum to the 2D node's
        let mut worst = 0.0f64;
        let mut statuses = Vec::new();
        for (i, r2) in s2.rows.iter().enumerate() {
            let x = r2.point[0];
            let f2 = s2.friction[i].unwrap();
            let t2 = f2.force_vector(&r2.tangents);
            let (mut normal, mut tangential) = (0.0, 0.0);
            for (j, r3) in s3.rows.iter().enumerate() {
                if (r3.point[0] - x).abs() < 1e-12 {
                    let f3 = s3.friction[j].unwrap();
                    assert_eq!(f3.status, f2.status, "x = {x}");
                    normal += s3.forces[j];
                    tangential += f3.force_vector(&s3.rows[j].tangents)[0];
                }
            }
            statuses.push(f2.status);
            worst = worst
                .max((normal - s2.forces[i]).abs())
                .max((tangential - t2[0]).abs());
        }
        println!("drag {d}, nu {nu}: {statuses:?}, largest force difference {worst:.1e}");
        assert!(worst <= 1e-10 * P, "{worst:e}");
    }
}

#[test]
fn what_3d_friction_does_not_solve_is_refused_with_the_reason() {
    let refused = |v: &Value, needle: &str| {
        let parsed = contact_patch::model::parse(&v.to_string(), "refused").unwrap();
        let e = build3(&parsed, "refused")
            .and_then(|m| {
                // what the model admits, the solve may still refuse (the rows are built there)
                contact_patch::solver::active_set::solve(&m, &mut |_| {}).map(|_| ())
            })
            .expect_err("refused");
        assert!(e.to_string().contains(needle), "{e}");
    };
    let mut active_set = dragged_block(CUBE, 0.0, [0.01, 0.0], penalty());
    active_set["solver"]["scheme"] = json!("active_set");
    refused(
        &active_set,
        "Coulomb friction is solved by the Newton scheme only",
    );
    // the 2D model's rule, in 3D too: a slip point constrains no tangential motion to eliminate
    let mut eliminated = dragged_block(CUBE, 0.0, [0.01, 0.0], json!({"kind": "elimination"}));
    eliminated["name"] = json!("eliminated");
    refused(
        &eliminated,
        "Coulomb friction with constraint elimination is not solved",
    );
}

#[test]
fn the_augmented_lagrangian_and_the_perturbed_tangent_drag_the_block_on_the_disc() {
    // the Uzawa methods: a slip point carries mu lambda_n exactly, a stick point does not move
    // from its stick point (the Lagrange answer, for any kappa)
    let angle = 2.2f64;
    let e = [angle.cos(), angle.sin()];
    for enforcement in [
        // kappa above the slab's stiffness: Uzawa's iteration contracts by about
        // K / (K + kappa A) per update (with kappa = 1e4 it ran into the iteration limit)
        json!({"kind": "augmented_lagrange", "kappa": 1e7, "update": "per_iteration"}),
        json!({"kind": "augmented_lagrange", "kappa": 1e7, "update": "outer_loop"}),
        json!({"kind": "perturbed_tangent", "kappa": 1e7}),
    ] {
        // without a tangential spring a stick point does not move: the slab's shear alone
        // carries the drag, so the drag that sticks is much smaller
        for (d, expect) in [(1e-7, Status::Stick), (1.0, Status::Slip)] {
            let o = run(&dragged_block(
                STIFF_SLAB,
                0.0,
                [d * e[0], d * e[1]],
                enforcement.clone(),
            ));
            assert_eq!(termination(&o), Termination::Converged, "{enforcement} {d}");
            let state = o.solution.contact.as_ref().unwrap();
            let (t, n, statuses) = totals(state);
            assert!((n - P).abs() <= 1e-9 * P);
            assert!(
                statuses.iter().all(|&s| s == expect),
                "{enforcement} {d}: {statuses:?}"
            );
            let along = -(t[0] * e[0] + t[1] * e[1]);
            println!("{enforcement}, drag {d}: {expect:?}, |F_t| along the drag {along:.12}");
            for f in state.friction.iter().flatten() {
                match expect {
                    Status::Stick => {
                        let moved = (0..2)
                            .map(|a| (f.slip[a] - f.committed[a]).abs())
                            .fold(0.0, f64::max);
                        assert!(
                            moved <= 1e-12,
                            "{enforcement}: a stick point moved {moved:e}"
                        );
                    }
                    _ => assert!((f.force_length() - MU * f.normal_force).abs() <= 1e-10 * P),
                }
            }
            if expect == Status::Slip {
                assert!((along - MU * n).abs() <= 1e-10 * MU * n, "{along}");
            }
        }
    }
}

#[test]
fn the_newton_scheme_in_3d_gives_the_active_set_answer_without_friction() {
    // the Newton scheme, now generic over the dimension, solves frictionless 3D pairs too:
    // the punch pressed on its foundation (no drag) by both schemes, penalty and Lagrange rows
    for enforcement in [
        json!({"kind": "penalty", "kappa": 1e4}),
        json!({"kind": "lagrange"}),
    ] {
        let mut newton =
            dragged_punch(json!({"kind": "node_to_surface", "passes": 1}), 3, 0.0, 0.0);
        newton["contact"][0]["enforcement"] = enforcement.clone();
        newton["contact"][0]
            .as_object_mut()
            .unwrap()
            .remove("interaction");
        let mut active_set = newton.clone();
        active_set["solver"] = json!({"scheme": "active_set"});
        let (a, b) = (run(&newton), run(&active_set));
        assert_eq!(termination(&a), Termination::Converged, "{enforcement}");
        assert_eq!(termination(&b), Termination::Converged, "{enforcement}");
        let (sa, sb) = (
            a.solution.contact.as_ref().unwrap(),
            b.solution.contact.as_ref().unwrap(),
        );
        assert_eq!(sa.rows.len(), sb.rows.len());
        let worst = sa
            .forces
            .iter()
            .zip(&sb.forces)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        println!("{enforcement}: Newton vs active set, largest force difference {worst:.1e}");
        assert!(worst <= 1e-10 * P, "{enforcement}: {worst:e}");
        assert!(sa.friction.iter().all(Option::is_none));
    }
}

fn lagrange() -> Value {
    json!({"kind": "lagrange"})
}

/// `dragged_punch` with the pair's enforcement `enforcement` and both bodies' vertices rotated
/// by `rotation` about the vertical axis through `(0.5, 0.5)` (the drag along `angle` as
/// given), the punch's Poisson ratio `nu`, in two load steps (press, then drag).
fn rotated_punch(
    disc: Value,
    enforcement: Value,
    (n, nu): (usize, f64),
    rotation: f64,
    angle: f64,
    d: f64,
) -> Value {
    let mut v = dragged_punch(disc, n, angle, d);
    let (c, s) = (rotation.cos(), rotation.sin());
    let rotate = |xs: &[f64], ys: &[f64], zs: &[f64]| {
        let mut moves = Vec::new();
        for &x in xs {
            for &y in ys {
                for &z in zs {
                    let (dx, dy) = (x - 0.5, y - 0.5);
                    moves.push(json!({"from": [x, y, z],
                        "to": [0.5 + c * dx - s * dy, 0.5 + s * dx + c * dy, z]}));
                }
            }
        }
        moves
    };
    let punch: Vec<f64> = (0..=n).map(|i| i as f64 / n as f64).collect();
    v["bodies"][0]["mesh"]["block3d"]["moves"] =
        json!(rotate(&[0.0, 0.5, 1.0], &[0.0, 0.5, 1.0], &[0.0, 1.0]));
    v["bodies"][1]["mesh"]["block3d"]["moves"] = json!(rotate(&punch, &punch, &[1.0, 1.5]));
    v["materials"]["p"] = json!({"E": 1000.0, "nu": nu});
    v["bodies"][1]["material"] = json!("p");
    v["contact"][0]["enforcement"] = enforcement;
    v["supports"][1]["path"] = json!([0.0, 1.0]);
    v["loads"][0]["path"] = json!([1.0, 1.0]);
    v["solver"]["load_steps"] = json!(2);
    v
}

#[test]
fn the_3d_lagrange_friction_tangent_is_the_derivative_of_the_residual_in_stick_and_slip() {
    // the rows of the sets on the disc: stick R_t = -rho dg_t, slip R_t = -rho (x_t - mu x_n
    // s(tau)) with the turn of the direction T = mu lambda_n (I - s s^T) / |tau| in its tangent
    let plane = json!({"kind": "plane", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]});
    let with = |mut v: Value, enforcement: &Value| {
        v["contact"][0]["enforcement"] = enforcement.clone();
        v
    };
    let mut worst = 0.0f64;
    for angle in [0.3f64, 1.9, 4.0] {
        let cases = [
            (
                "rigid plane",
                one_step_block(plane.clone(), angle, 0.05),
                one_step_block(plane.clone(), angle, 1e-6),
            ),
            (
                "node-to-surface",
                dragged_punch(
                    json!({"kind": "node_to_surface", "passes": 1}),
                    3,
                    angle,
                    0.05,
                ),
                dragged_punch(
                    json!({"kind": "node_to_surface", "passes": 1}),
                    3,
                    angle,
                    1e-6,
                ),
            ),
            (
                "standard mortar",
                dragged_punch(
                    json!({"kind": "mortar", "multiplier": "standard"}),
                    3,
                    angle,
                    0.05,
                ),
                dragged_punch(
                    json!({"kind": "mortar", "multiplier": "standard"}),
                    3,
                    angle,
                    1e-6,
                ),
            ),
            (
                "dual mortar",
                dragged_punch(
                    json!({"kind": "mortar", "multiplier": "dual"}),
                    3,
                    angle,
                    0.05,
                ),
                dragged_punch(
                    json!({"kind": "mortar", "multiplier": "dual"}),
                    3,
                    angle,
                    1e-6,
                ),
            ),
        ];
        for (name, slip, stick) in cases {
            for enforcement in [lagrange(), penalty()] {
                if (name == "rigid plane" || name == "node-to-surface") && enforcement == penalty()
                {
                    continue; // the penalty's node-based rows: the test above
                }
                for (v, status) in [(stick.clone(), Status::Stick), (slip.clone(), Status::Slip)] {
                    let v = with(v, &enforcement);
                    let o = run(&v);
                    assert_eq!(
                        termination(&o),
                        Termination::Converged,
                        "{name} {enforcement} {angle} {status:?}"
                    );
                    let e = fd_error(&v, &o, status);
                    println!(
                        "{name}, {enforcement}, drag along {angle}, {status:?}: tangent vs central differences {e:.1e}"
                    );
                    assert!(e < 1e-6, "{name} {enforcement} {angle} {status:?}: {e:e}");
                    worst = worst.max(e);
                }
            }
        }
    }
    println!("largest difference {worst:.1e}");
}

#[test]
fn a_slab_dragged_with_lagrange_multipliers_sticks_below_and_slips_at_mu_n_above() {
    // no tangential spring: a stick point does not move from where the press left it, a slip
    // point carries mu lambda_n exactly; the drag that sticks is carried by the slab's shear
    for angle in [0.0f64, 0.7, 2.2, -1.9] {
        let e = [angle.cos(), angle.sin()];
        for (d, expect) in [(1e-7, Status::Stick), (1.0, Status::Slip)] {
            let o = run(&dragged_block(
                STIFF_SLAB,
                0.0,
                [d * e[0], d * e[1]],
                lagrange(),
            ));
            assert_eq!(termination(&o), Termination::Converged, "{angle} {d}");
            let state = o.solution.contact.as_ref().unwrap();
            assert_eq!(state.steps.len(), 2);
            let (t, n, statuses) = totals(state);
            assert!((n - P).abs() <= 1e-9 * P, "{n}");
            assert_eq!(statuses.len(), 9, "every bottom node is closed");
            assert!(
                statuses.iter().all(|&s| s == expect),
                "{angle} {d}: {statuses:?}"
            );
            let along = -(t[0] * e[0] + t[1] * e[1]);
            let across = t[0] * e[1] - t[1] * e[0];
            let magnitude = (t[0] * t[0] + t[1] * t[1]).sqrt();
            println!(
                "Lagrange, drag {d} along {angle}: {expect:?}, |F_t| = {magnitude:.12}, along {along:.12}, across {across:.1e}, mu N = {:.12}",
                MU * n
            );
            assert!(t[2].abs() <= 1e-12 * P, "{t:?}");
            for step in &state.steps {
                // a slip multiplier lies on the cone to the Newton solve's residual tolerance
                // (1e-10 of the force scale: its equation is R_t = -rho (x_t - mu x_n s))
                let f = step.friction.as_ref().unwrap();
                assert!(f.dissipation >= 0.0, "{f:?}");
                assert!(f.max_cone_ratio <= 1.0 + 1e-10, "{f:?}");
            }
            for f in state.friction.iter().flatten() {
                match expect {
                    Status::Stick => {
                        let moved = (0..2)
                            .map(|a| (f.slip[a] - f.committed[a]).abs())
                            .fold(0.0, f64::max);
                        assert!(moved <= 1e-12, "a stick point moved {moved:e}");
                    }
                    _ => assert!((f.force_length() - MU * f.normal_force).abs() <= 1e-10 * P),
                }
            }
            match expect {
                Status::Stick => assert!(magnitude < MU * n && along > 0.0),
                _ => {
                    assert!((along - MU * n).abs() <= 1e-10 * MU * n, "{along}");
                    assert!(across.abs() <= 1e-5 * MU * n, "{across:e}");
                }
            }
        }
    }
}

/// The largest difference between the nodal contact forces (normal and tangential vectors) of
/// two solves of the same mesh, and the largest force.
fn force_difference(a: &ContactState<3>, b: &ContactState<3>) -> (f64, f64) {
    assert_eq!(a.rows.len(), b.rows.len());
    let mut worst = 0.0f64;
    let mut largest = 0.0f64;
    for i in 0..a.rows.len() {
        assert_eq!(a.rows[i].slave_node, b.rows[i].slave_node);
        let (fa, fb) = (a.friction[i].unwrap(), b.friction[i].unwrap());
        let (va, vb) = (
            fa.force_vector(&a.rows[i].tangents),
            fb.force_vector(&b.rows[i].tangents),
        );
        for k in 0..3 {
            worst = worst.max((va[k] - vb[k]).abs());
        }
        worst = worst.max((a.forces[i] - b.forces[i]).abs());
        largest = largest.max(a.forces[i].abs());
    }
    (worst, largest)
}

#[test]
fn the_penalty_approaches_the_lagrange_answer_as_kappa_grows() {
    // the cube with nu = 0.3 dragged into partial slip: the penalty's nodal forces (normal and
    // tangential, kappa_t = kappa) approach the Lagrange multipliers' as O(1/kappa)
    let angle = 0.7f64;
    let d = 4e-3;
    let drag = [d * angle.cos(), d * angle.sin()];
    let exact = run(&dragged_block((1000.0, 0.3, 1.0), 0.0, drag, lagrange()));
    assert_eq!(termination(&exact), Termination::Converged);
    let e = exact.solution.contact.as_ref().unwrap();
    let statuses: Vec<Status> = e.friction.iter().flatten().map(|f| f.status).collect();
    println!("Lagrange: {statuses:?}");
    assert!(statuses.contains(&Status::Stick) && statuses.contains(&Status::Slip));
    // (kappa = 1e5 and 1e8 diverged into a cycle before the line search on the disc, see
    // `the_penalty_newton_iteration_converges_in_partial_slip_at_every_kappa`)
    let mut last: Option<(f64, f64)> = None;
    for kappa in [1e3, 1e4, 1e5, 1e6, 1e7, 1e8] {
        let o = run(&dragged_block(
            (1000.0, 0.3, 1.0),
            0.0,
            drag,
            json!({"kind": "penalty", "kappa": kappa}),
        ));
        assert_eq!(termination(&o), Termination::Converged, "{kappa}");
        let (worst, largest) = force_difference(o.solution.contact.as_ref().unwrap(), e);
        println!(
            "kappa {kappa:e}: largest nodal force difference to Lagrange {:.3e} of the largest force",
            worst / largest
        );
        if let Some((k0, w0)) = last {
            // at least 5 times smaller per decade of kappa (1/kappa: 10)
            let decades = (kappa / k0).log10();
            assert!(
                w0 / worst >= 5f64.powf(decades),
                "{kappa}: {w0} then {worst}"
            );
        }
        last = Some((kappa, worst));
    }
    let last = last.unwrap().1;
    assert!(last <= 1e-4 * P, "{last:e}");
}

#[test]
fn the_penalty_newton_iteration_converges_in_partial_slip_at_every_kappa() {
    // the cube with nu = 0.3 dragged into partial slip, the drag in one or two steps after the
    // press: the full semi-smooth Newton step diverged at kappa = 1e5 and 1e8 (residual from
    // 0.25 to 1 of the force scale, contact forces up to 7e4 times the load) and ended in a
    // cycle (`active_set_cycling`); with every step under the line search on the residual norm
    // (issue 39; until then it restarted from the first iterate after the cycle), every solve
    // converges to an answer (the normal forces carry the load, no point outside the cone,
    // stick and slip both present). (kappa = 1e3 sticks everywhere: left out.)
    let angle = 0.7f64;
    let d = 4e-3;
    for steps in [2usize, 3] {
        for kappa in [1e4, 1e5, 1e6, 1e7, 1e8] {
            let mut case = dragged_block(
                (1000.0, 0.3, 1.0),
                0.0,
                [d * angle.cos(), d * angle.sin()],
                json!({"kind": "penalty", "kappa": kappa}),
            );
            if steps == 3 {
                case["solver"]["load_steps"] = json!(3);
                case["supports"][0]["path"] = json!([0.0, 0.5, 1.0]);
                case["loads"][0]["path"] = json!([1.0, 1.0, 1.0]);
            }
            let o = run(&case);
            assert_eq!(termination(&o), Termination::Converged, "{kappa} {steps}");
            let state = o.solution.contact.as_ref().unwrap();
            let iterations: Vec<usize> = state.steps.iter().map(|s| s.iterations).collect();
            println!("kappa {kappa:e}, {steps} steps: iterations per step {iterations:?}");
            // (measured: at most 5; with the restart after a cycle, up to 60 at kappa = 1e8 in
            // two steps, the iterations up to the cycle included)
            assert!(
                iterations.iter().all(|&i| i <= 5),
                "{kappa} {steps}: {iterations:?}"
            );
            let (_, n, statuses) = totals(state);
            assert!((n - P).abs() <= 1e-9 * P, "{kappa} {steps}: {n}");
            assert!(
                statuses.contains(&Status::Stick) && statuses.contains(&Status::Slip),
                "{kappa} {steps}: {statuses:?}"
            );
            for f in state.friction.iter().flatten() {
                assert!(f.force_length() <= MU * f.normal_force * (1.0 + 1e-12) + 1e-14);
            }
        }
    }
}

#[test]
fn mortar_friction_drags_a_punch_over_its_foundation_at_mu_n() {
    // a punch (3 x 3) on a foundation (2 x 2): non-matching Quad4 interface, standard and dual
    // mortar, penalty and Lagrange; pressed, then dragged along three directions
    for multiplier in ["standard", "dual"] {
        for enforcement in [penalty(), lagrange()] {
            for angle in [0.0f64, 0.9, -2.4] {
                let e = [angle.cos(), angle.sin()];
                for (d, expect) in [(1e-7, Status::Stick), (1.0, Status::Slip)] {
                    let v = rotated_punch(
                        json!({"kind": "mortar", "multiplier": multiplier}),
                        enforcement.clone(),
                        (3, 0.0),
                        0.0,
                        angle,
                        d,
                    );
                    let o = run(&v);
                    let what = format!("{multiplier} {enforcement} {angle} {d}");
                    assert_eq!(termination(&o), Termination::Converged, "{what}");
                    let state = o.solution.contact.as_ref().unwrap();
                    let (t, n, statuses) = totals(state);
                    assert!((n - P).abs() <= 1e-9 * P, "{what}: {n}");
                    assert!(
                        statuses.iter().all(|&s| s == expect),
                        "{what}: {statuses:?}"
                    );
                    let along = -(t[0] * e[0] + t[1] * e[1]);
                    let across = t[0] * e[1] - t[1] * e[0];
                    println!(
                        "{what}: {expect:?} at {} points, along {along:.12}, across {across:.1e}, mu N = {:.12}, along / (mu N) - 1 = {:.1e}",
                        statuses.len(),
                        MU * n,
                        along / (MU * n) - 1.0
                    );
                    assert!(t[2].abs() <= 1e-12 * P, "{what}: {t:?}");
                    if expect == Status::Slip {
                        // each point slips along its own direction, turned from the drag by the
                        // foundation's deformation under the tangential traction (the meshes
                        // are not symmetric about a drag at 0.9 or -2.4): the force along the
                        // drag is mu N to second order in the turn, across it to first order
                        let magnitude = (t[0] * t[0] + t[1] * t[1]).sqrt();
                        assert!(magnitude <= MU * n * (1.0 + 1e-10), "{what}: {magnitude}");
                        assert!(along >= MU * n * (1.0 - 1e-8), "{what}: {along}");
                        assert!(across.abs() <= 1e-4 * MU * n, "{what}: {across:e}");
                        for f in state.friction.iter().flatten() {
                            assert!(
                                (f.force_length() - MU * f.normal_force).abs() <= 1e-10 * P,
                                "{what}"
                            );
                        }
                    } else {
                        assert!(along > 0.0 && along < MU * n, "{what}: {along}");
                    }
                    // the forces on the two bodies balance (the rows' D and M weights sum
                    // alike: the punch lies within the foundation)
                    let mut on_body = [[0.0f64; 3]; 2];
                    for (r, (f, &lambda_n)) in state
                        .rows
                        .iter()
                        .zip(state.friction.iter().zip(&state.forces))
                    {
                        let f = f.unwrap();
                        let gradients = std::iter::once((&r.dofs, &r.coeffs, lambda_n)).chain(
                            r.tangents
                                .iter()
                                .zip(&f.force)
                                .map(|(t, &l)| (&t.dofs, &t.coeffs, l)),
                        );
                        for (dofs, coeffs, l) in gradients {
                            for (&dof, &c) in dofs.iter().zip(coeffs) {
                                let owner = o.model.dof_owner(dof).unwrap();
                                on_body[owner.body][owner.component] += l * c;
                            }
                        }
                    }
                    let net = (0..3)
                        .map(|k| (on_body[0][k] + on_body[1][k]).abs())
                        .fold(0.0, f64::max);
                    println!("  net contact force on the two bodies {net:.1e}");
                    assert!(net <= 1e-12 * P, "{what}: {on_body:?}");
                }
            }
        }
    }
}

#[test]
fn mortar_friction_is_invariant_under_rotation_about_the_normal() {
    // both meshes and the drag rotated together: every nodal force rotates, in stick, partial
    // slip (nu = 0.3 in the punch) and full slip
    for multiplier in ["standard", "dual"] {
        for enforcement in [penalty(), lagrange()] {
            for d in [2e-4, 4e-3, 0.05] {
                let disc = json!({"kind": "mortar", "multiplier": multiplier});
                let base = run(&rotated_punch(
                    disc.clone(),
                    enforcement.clone(),
                    (3, 0.3),
                    0.0,
                    0.0,
                    d,
                ));
                assert_eq!(termination(&base), Termination::Converged);
                let b = base.solution.contact.as_ref().unwrap();
                let mut count = [0usize; 3];
                for f in b.friction.iter().flatten() {
                    count[f.status as usize] += 1;
                }
                println!("{multiplier} {enforcement} drag {d}: open, stick, slip {count:?}");
                for angle in [0.4f64, 2.0] {
                    let (c, s) = (angle.cos(), angle.sin());
                    let o = run(&rotated_punch(
                        disc.clone(),
                        enforcement.clone(),
                        (3, 0.3),
                        angle,
                        angle,
                        d,
                    ));
                    assert_eq!(termination(&o), Termination::Converged);
                    let r = o.solution.contact.as_ref().unwrap();
                    assert_eq!(r.rows.len(), b.rows.len());
                    let mut worst = 0.0f64;
                    for i in 0..b.rows.len() {
                        assert_eq!(r.rows[i].slave_node, b.rows[i].slave_node);
                        let (fb, fr) = (b.friction[i].unwrap(), r.friction[i].unwrap());
                        assert_eq!(fb.status, fr.status, "{multiplier} {d} {angle} row {i}");
                        let vb = fb.force_vector(&b.rows[i].tangents);
                        let vr = fr.force_vector(&r.rows[i].tangents);
                        let expected = [c * vb[0] - s * vb[1], s * vb[0] + c * vb[1], vb[2]];
                        for k in 0..3 {
                            worst = worst.max((vr[k] - expected[k]).abs());
                        }
                        worst = worst.max((r.forces[i] - b.forces[i]).abs());
                    }
                    println!("  rotated by {angle}: largest force difference {worst:.1e}");
                    assert!(
                        worst <= 1e-9 * P,
                        "{multiplier} {enforcement} {d} {angle}: {worst:e}"
                    );
                }
            }
        }
    }
}

#[test]
fn a_slab_interface_one_element_thick_reproduces_plane_strain_mortar_and_lagrange_friction() {
    // 2D: a punch [0, 2] x [1, 1.5] (Q4, 3 x 1) pressed by P onto a foundation [0, 2] x [0, 1]
    // (Q4, 4 x 2) and dragged by its top along x (press, then drag); 3D: the same in x and z,
    // one element through y (thickness 1), u_y = 0 everywhere; mortar (standard, dual) and
    // node-to-surface, Lagrange multipliers and the penalty; in stick, full slip and partial
    // slip (the drag 0.02 with nu = 0.3 leaves the trailing points stuck)
    let punch_x = [0.0, 2.0 / 3.0, 4.0 / 3.0, 2.0];
    let base_x = [0.0, 0.5, 1.0, 1.5, 2.0];
    let mut worst_all = 0.0f64;
    for disc in [
        json!({"kind": "mortar", "multiplier": "standard"}),
        json!({"kind": "mortar", "multiplier": "dual"}),
        json!({"kind": "node_to_surface", "passes": 1}),
    ] {
        for enforcement in [lagrange(), penalty()] {
            for (d, nu) in [(2e-4, 0.0), (0.05, 0.0), (4e-3, 0.3), (0.02, 0.3)] {
                let contact = json!([{
                    "name": "interface",
                    "slave": {"body": "punch", "set": "bottom"},
                    "master": {"body": "base", "set": "top"},
                    "discretization": disc,
                    "enforcement": enforcement,
                    "interaction": {"coulomb": {"mu": MU}},
                }]);
                let two = json!({
                    "name": "slab-2d",
                    "analysis": {"plane": "strain", "thickness": 1.0},
                    "materials": {"m": {"E": 1000.0, "nu": nu}},
                    "bodies": [
                        {"name": "base", "material": "m",
                            "mesh": {"block": {"element": "Q4", "x": base_x, "y": [0, 0.5, 1]}}},
                        {"name": "punch", "material": "m",
                            "mesh": {"block": {"element": "Q4", "x": punch_x, "y": [1, 1.5]}}}
                    ],
                    "supports": [
                        {"body": "base", "set": "bottom", "x": 0.0, "y": 0.0},
                        {"body": "punch", "set": "top", "x": d, "path": [0.0, 1.0]}
                    ],
                    "loads": [{"body": "punch", "set": "top", "pressure": P, "path": [1.0, 1.0]}],
                    "contact": contact,
                    "solver": {"scheme": "newton", "load_steps": 2},
                });
                let parsed = contact_patch::model::parse(&two.to_string(), "slab-2d").unwrap();
                let model = contact_patch::model::Model::build(&parsed, "slab-2d").unwrap();
                let o2 = contact_patch::run::run_model(
                    model,
                    0.0,
                    std::time::Instant::now(),
                    &mut |_| {},
                )
                .unwrap();
                let s2 = o2.solution.contact.as_ref().unwrap();
                assert_eq!(s2.termination, Termination::Converged);
                let three = json!({
                    "name": "slab-3d",
                    "materials": {"m": {"E": 1000.0, "nu": nu}},
                    "bodies": [
                        {"name": "base", "material": "m", "mesh": {"block3d": {"element": "Hex8",
                            "x": base_x, "y": [0, 1], "z": [0, 0.5, 1]}}},
                        {"name": "punch", "material": "m", "mesh": {"block3d": {"element": "Hex8",
                            "x": punch_x, "y": [0, 1], "z": [1, 1.5]}}}
                    ],
                    "supports": [
                        {"body": "base", "set": "all", "y": 0.0},
                        {"body": "punch", "set": "all", "y": 0.0},
                        {"body": "base", "set": "bottom", "x": 0.0, "z": 0.0},
                        {"body": "punch", "set": "top", "x": d, "path": [0.0, 1.0]}
                    ],
                    "loads": [{"body": "punch", "set": "top", "pressure": P, "path": [1.0, 1.0]}],
                    "contact": contact,
                    "solver": {"scheme": "newton", "load_steps": 2},
                });
                let o3 = run(&three);
                let s3 = o3.solution.contact.as_ref().unwrap();
                assert_eq!(s3.termination, Termination::Converged);
                // each 2D slave node at x has two 3D slave nodes (y = 0 and 1): their forces
                // sum to the 2D node's
                let mut worst = 0.0f64;
                let mut statuses = Vec::new();
                for (i, r2) in s2.rows.iter().enumerate() {
                    let x = r2.point[0];
                    let f2 = s2.friction[i].unwrap();
                    let t2 = f2.force_vector(&r2.tangents);
                    let (mut normal, mut tangential, mut count) = (0.0, [0.0; 3], 0);
                    for (j, r3) in s3.rows.iter().enumerate() {
                        if (r3.point[0] - x).abs() < 1e-12 {
                            let f3 = s3.friction[j].unwrap();
                            assert_eq!(f3.status, f2.status, "x = {x}");
                            normal += s3.forces[j];
                            let v = f3.force_vector(&s3.rows[j].tangents);
                            for k in 0..3 {
                                tangential[k] += v[k];
                            }
                            count += 1;
                        }
                    }
                    assert_eq!(count, 2);
                    statuses.push(f2.status);
                    worst = worst
                        .max((normal - s2.forces[i]).abs())
                        .max((tangential[0] - t2[0]).abs())
                        .max((tangential[2] - t2[1]).abs())
                        .max(tangential[1].abs());
                }
                println!(
                    "{disc} {enforcement}, drag {d}, nu {nu}: {statuses:?}, largest force difference {worst:.1e}"
                );
                assert!(
                    worst <= 1e-10 * P,
                    "{disc} {enforcement} {d} {nu}: {worst:e}"
                );
                worst_all = worst_all.max(worst);
            }
        }
    }
    println!("largest difference {worst_all:.1e}");
}

#[test]
fn mortar_friction_on_triangular_facets_sticks_below_and_slips_at_mu_n_above() {
    // `rotated_punch` with Tet4 (Tri3 facets) and Tet10 (Tri6 facets, the modified multiplier
    // basis of mortar3) bodies: a punch (3 x 3 blocks) on a foundation (2 x 2), non-matching,
    // standard and dual multipliers, penalty and Lagrange; pressed, then dragged along three
    // directions: below the limit every closed point sticks and the tangential force is below
    // mu N; above it every point slips and the force along the drag is mu N; the dissipation
    // of every step is never negative and no point leaves the cone; the contact forces on the
    // two bodies balance
    for element in ["Tet4", "Tet10"] {
        for multiplier in ["standard", "dual"] {
            for enforcement in [penalty(), lagrange()] {
                for angle in [0.0f64, 0.9, -2.4] {
                    let e = [angle.cos(), angle.sin()];
                    for (d, expect) in [(1e-7, Status::Stick), (1.0, Status::Slip)] {
                        let mut v = rotated_punch(
                            json!({"kind": "mortar", "multiplier": multiplier}),
                            enforcement.clone(),
                            (3, 0.0),
                            0.0,
                            angle,
                            d,
                        );
                        for body in 0..2 {
                            let mesh = &mut v["bodies"][body]["mesh"]["block3d"];
                            mesh["element"] = json!(element);
                            mesh.as_object_mut().unwrap().remove("moves");
                        }
                        let o = run(&v);
                        let what = format!("{element} {multiplier} {enforcement} {angle} {d}");
                        assert_eq!(termination(&o), Termination::Converged, "{what}");
                        let state = o.solution.contact.as_ref().unwrap();
                        let (t, n, statuses) = totals(state);
                        assert!((n - P).abs() <= 1e-9 * P, "{what}: {n}");
                        assert!(!statuses.is_empty(), "{what}: no closed point");
                        assert!(
                            statuses.iter().all(|&s| s == expect),
                            "{what}: {statuses:?}"
                        );
                        let along = -(t[0] * e[0] + t[1] * e[1]);
                        let across = t[0] * e[1] - t[1] * e[0];
                        println!(
                            "{what}: {expect:?} at {} points, along {along:.12}, across {across:.1e}, mu N = {:.12}, along / (mu N) - 1 = {:.1e}",
                            statuses.len(),
                            MU * n,
                            along / (MU * n) - 1.0
                        );
                        assert!(t[2].abs() <= 1e-12 * P, "{what}: {t:?}");
                        for step in &state.steps {
                            let f = step.friction.as_ref().unwrap();
                            assert!(f.dissipation >= 0.0, "{what}: {f:?}");
                        }
                        // inside the cone to the Newton tolerance (an absolute one: a ratio
                        // |lambda_t| / (mu lambda_n) at a point of small lambda_n magnifies it)
                        for f in state.friction.iter().flatten() {
                            assert!(
                                f.force_length() <= MU * f.normal_force + 1e-10 * P,
                                "{what}: {f:?}"
                            );
                        }
                        let last = state.steps.last().unwrap().friction.as_ref().unwrap();
                        if expect == Status::Slip {
                            // as on Quad4 facets: each point slips along its own direction,
                            // turned from the drag by the foundation's deformation; the Kuhn
                            // split is symmetric about no vertical plane, so the turn is not
                            // zero even along x. Its bound: the foundation's top moves by at
                            // most what the traction mu P / A shears its depth H to,
                            // mu P H / (G A) = 0.3 * 10 * 1 / 500 = 6e-3 (nu = 0, G = E / 2),
                            // against the drag d = 1: the turn theta <= 6e-3, the force across
                            // the drag <= mu N sin(theta), along it >= mu N cos(theta)
                            let theta = MU * P * 1.0 / 500.0 / d;
                            let magnitude = (t[0] * t[0] + t[1] * t[1]).sqrt();
                            assert!(magnitude <= MU * n * (1.0 + 1e-10), "{what}: {magnitude}");
                            assert!(along >= MU * n * theta.cos(), "{what}: {along}");
                            assert!(across.abs() <= MU * n * theta.sin(), "{what}: {across:e}");
                            assert!(last.dissipation > 0.0, "{what}: {last:?}");
                            for f in state.friction.iter().flatten() {
                                assert!(
                                    (f.force_length() - MU * f.normal_force).abs() <= 1e-10 * P,
                                    "{what}"
                                );
                            }
                        } else {
                            assert!(along > 0.0 && along < MU * n, "{what}: {along}");
                            assert_eq!(last.dissipation, 0.0, "{what}");
                        }
                        let mut on_body = [[0.0f64; 3]; 2];
                        for (r, (f, &lambda_n)) in state
                            .rows
                            .iter()
                            .zip(state.friction.iter().zip(&state.forces))
                        {
                            let f = f.unwrap();
                            let gradients = std::iter::once((&r.dofs, &r.coeffs, lambda_n)).chain(
                                r.tangents
                                    .iter()
                                    .zip(&f.force)
                                    .map(|(t, &l)| (&t.dofs, &t.coeffs, l)),
                            );
                            for (dofs, coeffs, l) in gradients {
                                for (&dof, &c) in dofs.iter().zip(coeffs) {
                                    let owner = o.model.dof_owner(dof).unwrap();
                                    on_body[owner.body][owner.component] += l * c;
                                }
                            }
                        }
                        let net = (0..3)
                            .map(|k| (on_body[0][k] + on_body[1][k]).abs())
                            .fold(0.0, f64::max);
                        assert!(net <= 1e-12 * P, "{what}: {on_body:?}");
                    }
                }
            }
        }
    }
}

/// The dragged block under finite kinematics: neo-Hookean, the contact geometry of the current
/// configuration (friction there is solved against a rigid plane or line, whose tangents do
/// not turn).
fn at_finite_strain(mut v: Value) -> Value {
    v["materials"]["m"]["model"] = json!("neo_hookean");
    v["physics"] = json!({"kinematics": "finite", "contact_geometry": "current"});
    v
}

#[test]
fn at_finite_strain_a_block_dragged_obliquely_over_a_rigid_plane_slides_at_mu_n() {
    // a soft flat block (E = 100, height 0.2: the pressure 10 compresses it by a tenth)
    // dragged by 0.5 along two directions: every bottom node slides with the force mu lambda_n,
    // against its own slip; the forces sum to mu N nearly along the drag (the nodes slip along
    // directions turned by the block's shear, so the sum is below mu N by second order)
    for (name, enforcement) in [
        ("penalty", json!({"kind": "penalty", "kappa": 1e3})),
        ("Lagrange", json!({"kind": "lagrange"})),
    ] {
        for angle in [0.0f64, 0.7] {
            let e = [angle.cos(), angle.sin()];
            let d = 0.5;
            let o = run(&at_finite_strain(dragged_block(
                (100.0, 0.3, 0.2),
                0.0,
                [d * e[0], d * e[1]],
                enforcement.clone(),
            )));
            assert_eq!(termination(&o), Termination::Converged, "{name} {angle}");
            let state = o.solution.contact.as_ref().unwrap();
            let (t, n, statuses) = totals(state);
            assert!((n - P).abs() <= 1e-9 * P, "{name} {angle}: normal {n}");
            assert_eq!(
                statuses.len(),
                9,
                "{name} {angle}: every bottom node is closed"
            );
            assert!(
                statuses.iter().all(|&s| s == Status::Slip),
                "{name} {angle}: {statuses:?}"
            );
            for f in state.friction.iter().flatten() {
                assert!(
                    (f.force_length() - MU * f.normal_force).abs() <= 1e-12 * P,
                    "{name} {angle}: {f:?}"
                );
            }
            let along = -(t[0] * e[0] + t[1] * e[1]);
            let across = t[0] * e[1] - t[1] * e[0];
            assert!(t[2].abs() <= 1e-12 * P, "{name} {angle}: {t:?}");
            assert!(
                along <= MU * n * (1.0 + 1e-12) && along >= 0.99 * MU * n,
                "{name} {angle}: along {along}, mu N {}",
                MU * n
            );
            for step in &state.steps {
                let f = step.friction.as_ref().unwrap();
                assert!(f.dissipation >= 0.0, "{f:?}");
                assert!(f.max_cone_ratio <= 1.0 + 1e-12, "{f:?}");
            }
            println!(
                "finite strain, {name}, drag {d} along {angle}: along {along:.10}, across {across:.2e}, mu N {:.10}, iterations {:?}",
                MU * n,
                state.steps.iter().map(|s| s.iterations).collect::<Vec<_>>()
            );
        }
    }
}

#[test]
fn a_half_model_on_its_symmetry_plane_carries_half_the_frictional_force() {
    // the slab dragged along x is symmetric about y = 0.5: its half y >= 0.5 with u_y = 0 on
    // the plane y = 0.5 carries half of every force. The slave nodes on that plane have their
    // tangent along y held (every dof of that row prescribed): with Lagrange multipliers its
    // multiplier had an empty row and the factorization met a zero pivot; the tangent is
    // dropped and the support carries that direction
    // (stick: the penalty's springs take a drag of 1e-4; Lagrange multipliers hold the points,
    // so only the slab's shear takes a drag, 1e-7)
    for (name, enforcement, stick) in [
        ("penalty", penalty(), 1e-4),
        ("Lagrange", json!({"kind": "lagrange"}), 1e-7),
    ] {
        for d in [stick, 1.0] {
            let full = run(&dragged_block(
                STIFF_SLAB,
                0.0,
                [d, 0.0],
                enforcement.clone(),
            ));
            let mut case = dragged_block(STIFF_SLAB, 0.0, [d, 0.0], enforcement.clone());
            case["bodies"][0]["mesh"]["block3d"]["y"] = json!([0.5, 1.0]);
            // (no rotation: the moves are the identity)
            case["bodies"][0]["mesh"]["block3d"]
                .as_object_mut()
                .unwrap()
                .remove("moves");
            case["supports"]
                .as_array_mut()
                .unwrap()
                .push(json!({"body": "block", "set": "front", "y": 0.0}));
            let half = run(&case);
            assert_eq!(termination(&full), Termination::Converged, "{name} {d}");
            assert_eq!(termination(&half), Termination::Converged, "{name} {d}");
            let (t_full, n_full, s_full) = totals(full.solution.contact.as_ref().unwrap());
            let (t_half, n_half, s_half) = totals(half.solution.contact.as_ref().unwrap());
            // (two solves, each to Newton's tolerance: the stiff slab's penalty leaves 7.5e-12 P)
            assert!(
                (2.0 * n_half - n_full).abs() <= 1e-10 * P,
                "{name} {d}: normal {n_half} vs {n_full} / 2; tangential {t_half:?} vs {t_full:?}"
            );
            for k in 0..3 {
                assert!(
                    (2.0 * t_half[k] - t_full[k]).abs() <= 1e-10 * MU * P,
                    "{name} {d}: {t_half:?} vs {t_full:?}"
                );
            }
            let expect = if d == stick {
                Status::Stick
            } else {
                Status::Slip
            };
            assert!(
                s_full.iter().chain(&s_half).all(|&s| s == expect),
                "{name} {d}: {s_full:?} {s_half:?}"
            );
            println!(
                "{name}, drag {d}: half-model force x {:.12} (full / 2 {:.12}), {} closed points of the half",
                t_half[0],
                0.5 * t_full[0],
                s_half.len()
            );
        }
    }
}
