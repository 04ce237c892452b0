//! Finite-difference checks of every discretization's constraint rows: the coefficients of a
//! row are the derivatives of the geometric gap with respect to the nodal positions,
//! `c_k = dg/dx_k`, measured by re-running the discretization on meshes whose nodes moved by
//! `+-h` (central differences). Geometry is curved or tilted and the gaps are non-zero, so the
//! closest-point terms are exercised. With master normals (and rigid surfaces) the identity is
//! exact at any gap, because the closest point makes `x_s - x_m` normal to the facet. With
//! slave normals the row freezes the normal: it is exact for the slave node's own dofs and the
//! master's at any gap (`x_s - x_m` is parallel to the unit normal), while the nodes that tilt
//! the slave normal add `-g (n_m . dnu) / (n_m . nu)`, which vanishes where the gap is closed.

use contact_patch::contact::discretization::constraints;
use contact_patch::contact::Constraint;
use contact_patch::io::scene::{DiscretizationSpec, NormalChoice};
use contact_patch::mesh::Facet;
use contact_patch::model::{parse, MasterSide, Model};

fn two_blocks(element: &str, gap: f64, tilt: f64) -> Model {
    let lift = |x: f64| 5.0 + gap + tilt * (x - 4.0);
    let text = format!(
        r#"{{"name": "fd", "materials": {{"m": {{"E": 100.0, "nu": 0.3}}}},
        "bodies": [
          {{"name": "lower", "material": "m", "mesh": {{"block": {{"element": "{element}", "x": [2, 3.1, 4.4, 6, 7], "y": [3, 5],
             "moves": [{{"from": [3.1, 5], "to": [3.1, 5.06]}}, {{"from": [4.4, 5], "to": [4.4, 4.93]}}, {{"from": [6, 5], "to": [6, 5.05]}}]}}}},
           "facet_sets": {{"surface": {{"facets": [[0, 2], [1, 2], [2, 2], [3, 2]]}}}}}},
          {{"name": "upper", "material": "m", "mesh": {{"block": {{"element": "{element}", "x": [3.5, 4.3, 5.2, 6.5], "y": [5.2, 7],
             "moves": [{{"from": [3.5, 5.2], "to": [3.5, {a}]}}, {{"from": [4.3, 5.2], "to": [4.3, {b}]}}, {{"from": [5.2, 5.2], "to": [5.2, {c}]}}, {{"from": [6.5, 5.2], "to": [6.5, {d}]}}]}}}},
           "facet_sets": {{"surface": {{"facets": [[0, 0], [1, 0], [2, 0]]}}}}}}
        ],
        "supports": [{{"body": "lower", "set": "bottom", "x": 0.0, "y": 0.0}}, {{"body": "upper", "set": "top", "x": 0.0, "y": 0.0}}],
        "contact": [{{"name": "c", "slave": {{"body": "upper", "set": "surface"}}, "master": {{"body": "lower", "set": "surface"}},
          "discretization": {{"kind": "node_to_surface"}}, "enforcement": {{"kind": "lagrange"}}}}]}}"#,
        a = lift(3.5),
        b = lift(4.3),
        c = lift(5.2),
        d = lift(6.5),
    );
    Model::build(&parse(&text, "fd").unwrap(), "fd").unwrap()
}

fn find(rows: &[Constraint], r: &Constraint) -> Constraint {
    rows.iter()
        .find(|q| q.slave_body == r.slave_body && q.slave_node == r.slave_node && q.pass == r.pass)
        .cloned()
        .expect("the same slave node")
}

/// Central differences of every row's gap against every dof of the model. Rows of slave nodes
/// at the ends of their pass's slave surface (its lowest and highest x) are skipped: there the
/// gap has a kink where the projection leaves the master surface.
fn check(model: &Model, disc: DiscretizationSpec, h: f64, tol: f64, only_closed: bool) -> usize {
    check_dofs(model, disc, h, tol, only_closed, false)
}

/// As `check`; with `frozen_normal`, the other nodes of the slave body are not perturbed.
fn check_dofs(
    model: &Model,
    disc: DiscretizationSpec,
    h: f64,
    tol: f64,
    only_closed: bool,
    frozen_normal: bool,
) -> usize {
    let mut model = model.clone();
    model.contact[0].discretization = disc.clone();
    let rows = constraints(&model, &model.contact[0]).unwrap();
    assert!(!rows.is_empty());
    let mut checked = 0;
    let pair = &model.contact[0];
    let surface_ends = |body: usize, facets: &[Facet]| {
        let mesh = &model.bodies[body].mesh;
        facets
            .iter()
            .flat_map(|&f| mesh.facet_nodes(f))
            .map(|n| mesh.nodes[n][0])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            })
    };
    // a rigid master has no second pass
    let ends = [
        surface_ends(pair.slave.0, &pair.slave.1),
        match &pair.master {
            MasterSide::Body { body, facets } => surface_ends(*body, facets),
            MasterSide::Rigid(_) => (f64::NAN, f64::NAN),
        },
    ];
    let end = |r: &Constraint| {
        let (lo, hi) = ends[usize::from(r.pass == 2)];
        r.point[0] <= lo + 1e-9 || r.point[0] >= hi - 1e-9
    };
    for r in rows
        .iter()
        .filter(|r| (!only_closed || r.g0.abs() < 1e-12) && !end(r))
    {
        for (bi, body) in model.bodies.iter().enumerate() {
            for n in 0..body.mesh.nodes.len() {
                if frozen_normal && bi == r.slave_body && n != r.slave_node {
                    continue;
                }
                for i in 0..2 {
                    let gap_at = |delta: f64| {
                        let mut m = model.clone();
                        m.bodies[bi].mesh.nodes[n][i] += delta;
                        find(&constraints(&m, &m.contact[0]).unwrap(), r).g0
                    };
                    let fd = (gap_at(h) - gap_at(-h)) / (2.0 * h);
                    let dof = body.dof(n, i);
                    let c = r
                        .dofs
                        .iter()
                        .position(|&d| d == dof)
                        .map(|k| r.coeffs[k])
                        .unwrap_or(0.0);
                    assert!(
                        (fd - c).abs() < tol,
                        "{disc:?}: row of slave node {} (pass {}), dof {dof}: fd {fd} vs {c}",
                        r.slave_node,
                        r.pass
                    );
                }
            }
        }
        checked += 1;
    }
    checked
}

#[test]
fn node_to_surface_master_normal_rows_are_gap_gradients() {
    for element in ["Q4", "Q9"] {
        let m = two_blocks(element, 0.03, 0.02);
        let disc = DiscretizationSpec::NodeToSurface {
            passes: 1,
            normal: NormalChoice::Master,
            slave_normal_variation: None,
        };
        assert!(check(&m, disc.clone(), 1e-6, 1e-7, false) >= 2);
        let two = DiscretizationSpec::NodeToSurface {
            passes: 2,
            normal: NormalChoice::Master,
            slave_normal_variation: None,
        };
        assert!(
            check(&m, two, 1e-6, 1e-7, false) >= 4,
            "{element}: two-pass rows"
        );
    }
}

#[test]
fn node_to_surface_slave_normal_rows_are_gap_gradients_on_tilted_faces() {
    for element in ["Q4", "Q9"] {
        let m = two_blocks(element, 0.03, 0.08);
        for passes in [1, 2] {
            let disc = DiscretizationSpec::NodeToSurface {
                passes,
                normal: NormalChoice::Slave,
                slave_normal_variation: None,
            };
            assert!(
                check_dofs(&m, disc, 1e-6, 1e-7, false, true) >= 2 * passes as usize,
                "{element} {passes}"
            );
        }
    }
}

#[test]
fn node_to_surface_slave_normal_rows_are_gap_gradients_where_closed() {
    // a flat, closed interface: the slave normal rows must match the gap's derivative
    let text = std::fs::read_to_string(format!(
        "{}/cases/patch/patch-C-nu0.3.json",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let m = Model::build(&parse(&text, "C").unwrap(), "C").unwrap();
    let disc = DiscretizationSpec::NodeToSurface {
        passes: 1,
        normal: NormalChoice::Slave,
        slave_normal_variation: None,
    };
    assert_eq!(check(&m, disc, 1e-6, 1e-7, true), 2);
    let text = std::fs::read_to_string(format!(
        "{}/cases/patch/patch-E-nu0.3.json",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let m = Model::build(&parse(&text, "E").unwrap(), "E").unwrap();
    let disc = DiscretizationSpec::NodeToSurface {
        passes: 2,
        normal: NormalChoice::Slave,
        slave_normal_variation: None,
    };
    assert!(check(&m, disc, 1e-6, 1e-7, true) >= 8);
}

#[test]
fn node_to_node_rows_are_gap_gradients() {
    let text = std::fs::read_to_string(format!(
        "{}/cases/patch/patch-D-nu0.3.json",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let m = Model::build(&parse(&text, "D").unwrap(), "D").unwrap();
    // node-to-node pairs nodes within 1e-9 of the model size, so the step stays below that
    assert_eq!(
        check(&m, DiscretizationSpec::NodeToNode, 1e-10, 1e-5, false),
        3
    );
}

#[test]
fn rigid_surface_rows_are_gap_gradients() {
    for rigid in [
        r#"{"kind": "line", "point": [0, 4.9], "normal": [0.1, 1]}"#,
        r#"{"kind": "circle", "centre": [5, 0], "radius": 4.8}"#,
    ] {
        let text = format!(
            r#"{{"name": "rigid", "materials": {{"m": {{"E": 100.0, "nu": 0.3}}}},
            "bodies": [{{"name": "b", "material": "m", "mesh": {{"block": {{"element": "Q9", "x": [4, 5, 6], "y": [5, 6]}}}}}}],
            "supports": [{{"body": "b", "set": "top", "x": 0.0}}],
            "contact": [{{"name": "c", "slave": {{"body": "b", "set": "bottom"}}, "master": {{"rigid": {rigid}}},
              "discretization": {{"kind": "node_to_surface"}}, "enforcement": {{"kind": "lagrange"}}}}]}}"#
        );
        let m = Model::build(&parse(&text, "rigid").unwrap(), "rigid").unwrap();
        let disc = DiscretizationSpec::NodeToSurface {
            passes: 1,
            normal: NormalChoice::Master,
            slave_normal_variation: None,
        };
        assert_eq!(check(&m, disc, 1e-6, 1e-7, false), 3, "{rigid}");
    }
}

/// Mortar rows against a rigid line (tilted, so the gap varies along the slave surface) and a
/// rigid circle are the whole derivatives of the weighted gap `int Phi_j g dGamma / A_j` with
/// respect to the slave positions, at a non-zero gap, on Line2 (Q4) and Line3 (Q9) slaves, both
/// multiplier spaces: central differences (`h = 1e-6`) agree with the row to 1e-7 on every dof.
#[test]
fn rigid_mortar_rows_are_weighted_gap_gradients() {
    use contact_patch::io::scene::MultiplierSpace;
    for element in ["Q4", "Q9"] {
        for rigid in [
            r#"{"kind": "line", "point": [0, 4.9], "normal": [0.1, 1]}"#,
            r#"{"kind": "circle", "centre": [5, 0], "radius": 4.8}"#,
        ] {
            let text = format!(
                r#"{{"name": "rigid", "materials": {{"m": {{"E": 100.0, "nu": 0.3}}}},
                "bodies": [{{"name": "b", "material": "m", "mesh": {{"block": {{"element": "{element}", "x": [4, 4.6, 5.5, 6], "y": [5, 6]}}}}}}],
                "supports": [{{"body": "b", "set": "top", "x": 0.0}}],
                "contact": [{{"name": "c", "slave": {{"body": "b", "set": "bottom"}}, "master": {{"rigid": {rigid}}},
                  "discretization": {{"kind": "mortar"}}, "enforcement": {{"kind": "lagrange"}}}}]}}"#
            );
            let m = Model::build(&parse(&text, "rigid").unwrap(), "rigid").unwrap();
            for multiplier in [MultiplierSpace::Standard, MultiplierSpace::Dual] {
                let disc = DiscretizationSpec::Mortar { multiplier };
                let rows = constraints(&m, &m.contact[0]).unwrap();
                assert!(
                    rows.iter().all(|r| r.g0 > 0.01),
                    "{rigid}: an open interface"
                );
                let interior = if element == "Q9" { 5 } else { 2 };
                assert_eq!(
                    check(&m, disc, 1e-6, 1e-7, false),
                    interior,
                    "{element} {rigid} {multiplier:?}"
                );
            }
        }
    }
}

/// On a flat interface the rigid-line mortar row is the deformable mortar row with the master's
/// displacement dropped: a Q9 slave against a foundation body whose top (non-matching facets,
/// covering the slave) lies on the line gives, node by node, the same gap and the same slave
/// coefficients to 1e-14, both multiplier spaces.
#[test]
fn rigid_line_mortar_rows_are_the_deformable_rows_without_master_dofs() {
    use contact_patch::io::scene::MultiplierSpace;
    let slave = r#"{"name": "punch", "material": "m", "mesh": {"block": {"element": "Q9", "x": [0, 0.7, 1.5, 2.2, 3], "y": [0.1, 0.8, 2]}}}"#;
    let build = |master: &str, extra_body: &str| {
        let text = format!(
            r#"{{"name": "flat", "materials": {{"m": {{"E": 100.0, "nu": 0.3}}}},
            "bodies": [{slave}{extra_body}],
            "supports": [{{"body": "punch", "set": "top", "x": 0.0}}],
            "contact": [{{"name": "c", "slave": {{"body": "punch", "set": "bottom"}}, "master": {master},
              "discretization": {{"kind": "mortar"}}, "enforcement": {{"kind": "lagrange"}}}}]}}"#
        );
        Model::build(&parse(&text, "flat").unwrap(), "flat").unwrap()
    };
    let deformable = build(
        r#"{"body": "base", "set": "top"}"#,
        r#", {"name": "base", "material": "m", "mesh": {"block": {"element": "Q4", "x": [-1, 0.5, 1.9, 4], "y": [-1, 0]}}}"#,
    );
    let rigid = build(
        r#"{"rigid": {"kind": "line", "point": [0, 0], "normal": [0, 1]}}"#,
        "",
    );
    for multiplier in [MultiplierSpace::Standard, MultiplierSpace::Dual] {
        let rows = |m: &Model| {
            let mut m = m.clone();
            m.contact[0].discretization = DiscretizationSpec::Mortar { multiplier };
            constraints(&m, &m.contact[0]).unwrap()
        };
        let (d_rows, r_rows) = (rows(&deformable), rows(&rigid));
        assert_eq!(d_rows.len(), 9, "{multiplier:?}: one row per slave node");
        assert_eq!(r_rows.len(), d_rows.len(), "{multiplier:?}");
        let slave_dofs = 2 * deformable.bodies[0].mesh.nodes.len();
        for d in &d_rows {
            let r = find(&r_rows, d);
            assert!(
                (r.g0 - d.g0).abs() < 1e-14,
                "{multiplier:?}: gap {} vs {}",
                r.g0,
                d.g0
            );
            assert!((r.g0 - 0.1).abs() < 1e-14, "{multiplier:?}: gap {}", r.g0);
            for (&dof, &c) in d
                .dofs
                .iter()
                .zip(&d.coeffs)
                .filter(|(&dof, _)| dof < slave_dofs)
            {
                let k = r.dofs.iter().position(|&x| x == dof);
                let got = k.map(|k| r.coeffs[k]).unwrap_or(0.0);
                assert!(
                    (got - c).abs() < 1e-14,
                    "{multiplier:?}: dof {dof}: {got} vs {c}"
                );
            }
            assert!(r.dofs.iter().all(|&x| x < slave_dofs));
            let on_slave = d.dofs.iter().filter(|&&x| x < slave_dofs).count();
            assert!(r.dofs.len() <= on_slave, "{multiplier:?}: {r:?} vs {d:?}");
        }
    }
}

/// Mortar rows are the derivatives of the weighted gap `nu . (D x_s - M x_m) / A` where the
/// interface is closed (there the derivatives of `D`, `M` and of the segmentation multiply a
/// zero gap), on the non-nested meshes C (Line2) and E (Line3), both multiplier spaces.
#[test]
fn mortar_rows_are_weighted_gap_gradients_where_closed() {
    use contact_patch::io::scene::MultiplierSpace;
    for mesh in ["C", "E"] {
        let text = std::fs::read_to_string(format!(
            "{}/cases/patch/patch-{mesh}-nu0.3.json",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap();
        let m = Model::build(&parse(&text, mesh).unwrap(), mesh).unwrap();
        for multiplier in [MultiplierSpace::Standard, MultiplierSpace::Dual] {
            let n = check(
                &m,
                DiscretizationSpec::Mortar { multiplier },
                1e-6,
                1e-7,
                true,
            );
            assert!(n >= 2, "{mesh} {multiplier:?}: {n} rows checked");
        }
    }
}

/// Linear momentum: every mortar row's weights satisfy `sum_k D_jk = sum_l M_jl`, so its
/// slave and master forces cancel exactly (checked on a curved, open interface where nothing
/// else cancels).
#[test]
fn mortar_rows_conserve_linear_momentum() {
    use contact_patch::io::scene::MultiplierSpace;
    for element in ["Q4", "Q9"] {
        let mut m = two_blocks(element, 0.03, 0.02);
        for multiplier in [MultiplierSpace::Standard, MultiplierSpace::Dual] {
            m.contact[0].discretization = DiscretizationSpec::Mortar { multiplier };
            let rows = constraints(&m, &m.contact[0]).unwrap();
            assert!(rows.len() >= 3);
            for r in &rows {
                let (mut fx, mut fy) = (0.0, 0.0);
                for (&d, &c) in r.dofs.iter().zip(&r.coeffs) {
                    if d % 2 == 0 {
                        fx += c
                    } else {
                        fy += c
                    }
                }
                assert!(
                    fx.abs() < 1e-13 && fy.abs() < 1e-13,
                    "{element} {multiplier:?}: net force ({fx}, {fy}) of row {r:?}"
                );
            }
        }
    }
}

/// The corner condition: a slave node above a convex kink of the master surface projects into
/// neither facet and is held against the shared vertex along the vertex-to-node direction;
/// that row is the gradient of the distance to the vertex.
#[test]
fn corner_rows_are_gap_gradients() {
    // the lower surface peaks at (6, 5.05); the upper block gets a node right above it
    let mut m = two_blocks("Q4", 0.03, 0.0);
    let upper = m.body_index("upper").unwrap();
    let at6 = m.bodies[upper]
        .mesh
        .nodes
        .iter()
        .position(|p| (p[0] - 6.5).abs() < 1e-12 && p[1] < 5.1)
        .unwrap();
    m.bodies[upper].mesh.nodes[at6] = [6.0, 5.12];
    let rows = constraints(&m, &m.contact[0]).unwrap();
    let corner = rows
        .iter()
        .find(|r| r.slave_node == at6)
        .expect("a row for the node above the peak");
    let lower = m.body_index("lower").unwrap();
    let master_nodes: std::collections::BTreeSet<usize> = corner
        .dofs
        .iter()
        .filter(|&&d| {
            d >= m.bodies[lower].dof_offset
                && d < m.bodies[lower].dof_offset + m.bodies[lower].dof_count()
        })
        .map(|d| (d - m.bodies[lower].dof_offset) / 2)
        .collect();
    assert_eq!(
        master_nodes.len(),
        1,
        "a corner row acts on the shared vertex only: {corner:?}"
    );
    let v = *master_nodes.iter().next().unwrap();
    assert!((m.bodies[lower].mesh.nodes[v][0] - 6.0).abs() < 1e-12);
    // central differences of that row's gap against the slave node and the vertex
    assert_corner_row_is_its_gap_gradient(&m, corner, [(upper, at6), (lower, v)]);
}

/// The corner row `corner` of slave node `nodes[0]` against the vertex `nodes[1]` (each
/// `(body, node)`) against central differences of its gap, both nodes moved by `+-1e-6`
/// along x and y.
fn assert_corner_row_is_its_gap_gradient(
    m: &Model,
    corner: &Constraint,
    nodes: [(usize, usize); 2],
) {
    let slave = nodes[0].1;
    let h = 1e-6;
    for (b, n) in nodes {
        for i in 0..2 {
            let gap_at = |delta: f64| {
                let mut mm = m.clone();
                mm.bodies[b].mesh.nodes[n][i] += delta;
                constraints(&mm, &mm.contact[0])
                    .unwrap()
                    .into_iter()
                    .find(|r| r.slave_node == slave)
                    .unwrap()
                    .g0
            };
            let fd = (gap_at(h) - gap_at(-h)) / (2.0 * h);
            let dof = m.bodies[b].dof(n, i);
            let c = corner
                .dofs
                .iter()
                .position(|&d| d == dof)
                .map(|k| corner.coeffs[k])
                .unwrap_or(0.0);
            assert!((fd - c).abs() < 1e-7, "dof {dof}: fd {fd} vs {c}");
        }
    }
}

/// The corner condition behind a concave kink: the lower surface has a valley at (4.4, 4.93)
/// (its neighbours at 5.06 and 5.05); a slave node 0.13 below it, inside the lower block,
/// projects past the ends of both facets and is held against the vertex, as a penetration:
/// its gap is minus its distance to the vertex (it read plus, an open row for a node pressed
/// in), and the row is that signed distance's gradient.
#[test]
fn a_node_under_a_concave_corner_is_a_penetration() {
    let mut m = two_blocks("Q4", 0.03, 0.0);
    let upper = m.body_index("upper").unwrap();
    let lower = m.body_index("lower").unwrap();
    let below = m.bodies[upper]
        .mesh
        .nodes
        .iter()
        .position(|p| (p[0] - 4.3).abs() < 1e-12 && p[1] < 5.3)
        .unwrap();
    m.bodies[upper].mesh.nodes[below] = [4.4, 4.8];
    let corner = constraints(&m, &m.contact[0])
        .unwrap()
        .into_iter()
        .find(|r| r.slave_node == below)
        .expect("a row for the node under the valley");
    let on_lower: Vec<usize> = corner
        .dofs
        .iter()
        .filter(|&&d| {
            d >= m.bodies[lower].dof_offset
                && d < m.bodies[lower].dof_offset + m.bodies[lower].dof_count()
        })
        .map(|d| (d - m.bodies[lower].dof_offset) / 2)
        .collect();
    let v = on_lower[0];
    assert!(on_lower.iter().all(|&n| n == v), "{corner:?}");
    assert_eq!(m.bodies[lower].mesh.nodes[v], [4.4, 4.93]);
    assert!((corner.g0 + 0.13).abs() < 1e-12, "gap {}", corner.g0);
    assert_corner_row_is_its_gap_gradient(&m, &corner, [(upper, below), (lower, v)]);
}
