//! The rows of a contact pair between 3D bodies: the discretization axis in 3D, meeting the
//! dimension-free enforcement through [`Constraint<3>`] rows (see [`super::Discretize`]).
//!
//! * Node-to-surface, one and two passes, master normals
//!   ([`super::node_based_rows::node_to_surface_rows`]: closest point on Quad4, Quad9, Tri3 and
//!   Tri6 facets with edges and corners);
//! * node-to-node on matching interfaces ([`super::node_based_rows::node_to_node_rows`]);
//! * rigid plane and sphere masters ([`super::node_based_rows::rigid_rows`]), one pass;
//! * segment-based mortar, standard and dual multipliers
//!   ([`super::mortar3::mortar_rows3`]: auxiliary plane, polygon clipping), with the slave
//!   surface's nodal normals (normalized `int N_a n dA`, [`super::geometry::Surface`]).
//!
//! **Tied pairs** keep the interface's initial geometry: every node-based row
//! `g = nu . (u_s - sum_b w_b u_b)` gives three bilateral rows `e_i . (u_s - sum_b w_b u_b)`
//! with zero gap, one per axis (Taylor 2004, "Tied Interfaces"); mortar builds its tied rows
//! with the same `D` and `M` weights. The weights `w_b` of a node-based row are recovered
//! from its coefficients on the component where `|nu_i|` is largest (at least `1/sqrt 3`), so
//! they are exact.
//!
//! **Coulomb pairs** give every node-based row two tangential slip measures (Wriggers 2006,
//! s. 4.3; Laursen 2002, ch. 5), `g_t,a = t_a . (u_s - sum_b w_b u_b)` along an orthonormal
//! frame `t_1, t_2` of the plane normal to the row's normal ([`crate::contact::tangent_frame`]),
//! with the row's own weights `w_b` (recovered as for ties): the relative tangential motion of
//! the slave node against its master point. The return map on the disc turns them into the
//! tangential force ([`crate::contact::friction`]).
//!
//! **Mortar rows of Coulomb pairs** get the weighted tangential slip the same way (Puso &
//! Laursen 2004, *Comput. Methods Appl. Mech. Engrg.* 193, 4891-4913; Gitterle, Popp, Gee &
//! Wall 2010, *Int. J. Numer. Meth. Engng.* 84, 543-571; small strain: the tangential slip of
//! slave node `j` is `t_j,a . (sum_k D_jk u_k - sum_l M_jl u_l) / A_j`, along the tangents
//! of the frame of its nodal normal): a mortar row `g_j = nu_j . (sum_k D_jk u_k - sum_l M_jl
//! u_l) / A_j` is a row with several slave terms, and its weights `D_jk / A_j`, `M_jl / A_j` are
//! recovered from its coefficients on its dominant component as for a node-based row (the
//! standard multipliers' `D_jk` couple several slave nodes; the dual ones' are diagonal, but
//! for the mid-edge rows of Tri6 facets, see [`super::mortar3`]). Its
//! tributary area is `A_j = sum_k D_jk`, the tangential penalty's `w_t = kappa_t A_j` as in 2D.
//!
//! Small strain: the geometry is taken once in the reference configuration. Finite kinematics
//! builds the rows in the current configuration (the model's nodes moved), and the rows
//! between bodies then carry their gap's exact gradient and second derivative:
//! node-to-surface ([`super::facet_gap_hessian`]), node-to-node (nodes paired by proximity,
//! the master's nodal normal varied, [`super::nodal_normal3`]) and mortar (the weighted gap
//! through the auxiliary plane, the clipping and the projections,
//! `super::mortar3_linearization`). Slave normals and mortar against rigid surfaces are not
//! built in 3D and are refused with the reason.

use super::geometry::Surface3;
use super::mortar3::{mortar_rows3, FacetSet3, RowNumbering};
use super::mortar3_linearization::linearize_rows3;
use super::nodal_normal3::node_to_node_current_rows;
use super::node_based_rows::{
    dominant_component, gradient_coefficients, node_to_node_rows, node_to_surface_rows, rigid_rows,
    RigidMaster, RowSettings,
};
use crate::contact::{Constraint, GapHessian, TangentRow};
use crate::io::scene::{
    ContactGeometry, DiscretizationSpec, Interaction, Kinematics, NormalChoice, RigidSurface,
};
use crate::model::{ContactPair, MasterSide, Model3};
use std::collections::BTreeMap;

/// The rows of `pair` of the 3D model `model`, or why its discretization does not apply.
pub fn pair_rows(model: &Model3, pair: &ContactPair) -> Result<Vec<Constraint<3>>, String> {
    let frictional = pair.interaction.friction().is_some();
    let tied = pair.interaction == Interaction::Tied;
    let (slave_body, slave_facets) = &pair.slave;
    let slave =
        Surface3::from_solid_mesh(*slave_body, &model.bodies[*slave_body].mesh, slave_facets);
    let numbering = |b: usize, n: usize, c: usize| model.bodies[b].dof(n, c);
    let settings = RowSettings {
        dofs: &numbering,
        pair: 0,
        search_distance: pair.search_distance,
        // finite kinematics builds the rows in the current configuration (the model's nodes
        // moved, `contact::rows::rows_at`): their gaps' second derivatives for Newton
        current_finite: model.physics.kinematics == Kinematics::Finite
            && model.physics.contact_geometry == ContactGeometry::Current
            && !tied,
    };
    let rows = match (&pair.master, &pair.discretization) {
        (MasterSide::Rigid(rigid), DiscretizationSpec::NodeToSurface { passes, .. }) => {
            if *passes != 1 {
                return Err("a rigid master has no nodes to be slaves of a second pass: use \"passes\": 1".into());
            }
            rigid_rows(&slave, &rigid_master(rigid)?, &settings)?
        }
        (MasterSide::Rigid(_), _) => {
            return Err(
                "against a rigid surface in 3D only node-to-surface is built: use {\"kind\": \"node_to_surface\", \"passes\": 1}".into(),
            )
        }
        (MasterSide::Body { body, facets }, discretization) => {
            let master = Surface3::from_solid_mesh(*body, &model.bodies[*body].mesh, facets);
            match discretization {
                DiscretizationSpec::NodeToSurface { normal, passes, .. } => {
                    if *normal != NormalChoice::Master {
                        return Err("slave normals in 3D are not built yet: use \"normal\": \"master\"".into());
                    }
                    node_to_surface_rows(&slave, &master, *passes, &settings)?
                }
                DiscretizationSpec::NodeToNode if settings.current_finite => {
                    node_to_node_current_rows(&slave, &master, &settings)?
                }
                DiscretizationSpec::NodeToNode => node_to_node_rows(&slave, &master, &settings)?,
                DiscretizationSpec::Mortar { multiplier } => {
                    // mortar builds its tied rows itself (the same D and M weights)
                    let rows = mortar(model, pair, &slave, *body, facets, *multiplier, tied)?;
                    return Ok(if frictional {
                        with_tangents(model, rows)
                    } else {
                        rows
                    });
                }
            }
        }
    };
    Ok(if tied {
        tie(model, rows)
    } else if frictional {
        with_tangents(model, rows)
    } else {
        rows
    })
}

/// The weights of a node-based row `g = nu . (u_s - sum_b w_b u_b)`.
struct RowWeights {
    /// The slave terms `(node, w)`.
    slave: Vec<(usize, f64)>,
    /// The master body (rigid masters: the slave body) and its terms `(node, w_b)` (rigid
    /// masters: none).
    master_body: usize,
    master: Vec<(usize, f64)>,
}

/// The weights of row `r`, recovered from its coefficients on the component where `|nu_i|` is
/// largest.
fn row_weights(model: &Model3, r: &Constraint<3>) -> RowWeights {
    let i = dominant_component(r.normal);
    let mut slave_terms: Vec<(usize, f64)> = Vec::new();
    let mut master_terms: Vec<(usize, usize, f64)> = Vec::new();
    for (&d, &c) in r.dofs.iter().zip(&r.coeffs) {
        let Some(owner) = model.dof_owner(d) else {
            continue;
        };
        if owner.component != i {
            continue;
        }
        let w = c / r.normal[i];
        if owner.body == r.slave_body {
            slave_terms.push((owner.node, w));
        } else {
            master_terms.push((owner.body, owner.node, -w));
        }
    }
    RowWeights {
        slave: slave_terms,
        master_body: master_terms.first().map_or(r.slave_body, |t| t.0),
        master: master_terms.iter().map(|t| (t.1, t.2)).collect(),
    }
}

/// The gradient of `e . (u_s - sum_b w_b u_b)` with the weights of [`row_weights`].
fn gradient_along(
    model: &Model3,
    r: &Constraint<3>,
    weights: &RowWeights,
    e: [f64; 3],
) -> (Vec<usize>, Vec<f64>) {
    gradient_coefficients(
        e,
        &weights.slave,
        |n, c| model.bodies[r.slave_body].dof(n, c),
        (weights.master_body, &weights.master),
        |b, n, c| model.bodies[b].dof(n, c),
    )
}

/// Every row with its two tangential slip measures along the frame of its unit normal.
fn with_tangents(model: &Model3, mut rows: Vec<Constraint<3>>) -> Vec<Constraint<3>> {
    for r in &mut rows {
        let l = r.normal.iter().map(|v| v * v).sum::<f64>().sqrt();
        let frame = crate::contact::tangent_frame(r.normal.map(|v| v / l));
        let weights = row_weights(model, r);
        r.tangents = frame
            .iter()
            .map(|&t| {
                let (dofs, coeffs) = gradient_along(model, r, &weights, t);
                TangentRow {
                    dofs,
                    coeffs,
                    direction: t,
                }
            })
            .collect();
    }
    rows
}

/// The rigid master of a 3D pair.
fn rigid_master(rigid: &RigidSurface) -> Result<RigidMaster<3>, String> {
    match *rigid {
        RigidSurface::Plane { point, normal } => Ok(RigidMaster::Plane { point, normal }),
        RigidSurface::Sphere { centre, radius } => Ok(RigidMaster::Sphere { centre, radius }),
        RigidSurface::Line { .. } | RigidSurface::Circle { .. } => {
            Err("a rigid line or circle is 2D: a 3D body meets a \"plane\" or a \"sphere\"".into())
        }
    }
}

/// The mortar rows of the pair (frictionless or tied).
fn mortar(
    model: &Model3,
    pair: &ContactPair,
    slave: &Surface3,
    master_body: usize,
    master_facets: &[crate::mesh::Facet],
    multiplier: crate::io::scene::MultiplierSpace,
    tied: bool,
) -> Result<Vec<Constraint<3>>, String> {
    let (slave_body, slave_facets) = &pair.slave;
    let slave_set = FacetSet3::from_mesh(&model.bodies[*slave_body].mesh, slave_facets)?;
    let master_set = FacetSet3::from_mesh(&model.bodies[master_body].mesh, master_facets)?;
    let normals: BTreeMap<usize, [f64; 3]> =
        slave.nodes.iter().map(|(&n, d)| (n, d.normal)).collect();
    let slave_dof = |n: usize, i: usize| model.bodies[*slave_body].dof(n, i);
    let master_dof = |n: usize, i: usize| model.bodies[master_body].dof(n, i);
    let numbering = RowNumbering {
        slave_body: *slave_body,
        pair: 0,
        pass: 1,
        slave_dof: &slave_dof,
        master_dof: &master_dof,
        tied,
    };
    let (mut rows, integrals) = mortar_rows3(
        &slave_set,
        &master_set,
        multiplier,
        &normals,
        &numbering,
        pair.search_distance,
    )?;
    let finite = model.physics.kinematics == Kinematics::Finite
        && model.physics.contact_geometry == ContactGeometry::Current;
    if finite && !tied {
        // finite kinematics: each row's exact gradient and the second derivative of its gap
        // (segmentation, projections and nodal normal varied)
        let nodes: Vec<usize> = rows.iter().map(|r| r.slave_node).collect();
        let linearized = linearize_rows3(
            &slave_set,
            &master_set,
            multiplier,
            &integrals,
            &nodes,
            &slave_dof,
            &master_dof,
        )?;
        for row in &mut rows {
            let lin = &linearized[&row.slave_node];
            row.g0 = lin.gap;
            row.dofs.clear();
            row.coeffs.clear();
            for (&d, &c) in lin.dofs.iter().zip(&lin.gradient) {
                if c != 0.0 {
                    row.dofs.push(d);
                    row.coeffs.push(c);
                }
            }
            row.hessian = Some(GapHessian {
                dofs: lin.dofs.clone(),
                values: lin.hessian.clone(),
            });
        }
    }
    Ok(rows)
}

/// Three bilateral rows (x, y, z) with zero gap for every node-based row, with its weights.
fn tie(model: &Model3, rows: Vec<Constraint<3>>) -> Vec<Constraint<3>> {
    let mut out = Vec::with_capacity(3 * rows.len());
    for r in rows {
        // the weights of the row's nodes: coefficient on component i over nu_i
        let weights = row_weights(model, &r);
        for axis in 0..3 {
            let mut e = [0.0; 3];
            e[axis] = 1.0;
            let (dofs, coeffs) = gradient_along(model, &r, &weights, e);
            out.push(Constraint {
                dofs,
                coeffs,
                g0: 0.0,
                normal: e,
                owner: model.bodies[r.slave_body].dof(r.slave_node, axis),
                bilateral: true,
                ..r.clone()
            });
        }
    }
    out
}
