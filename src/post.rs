//! Post-processing: stresses and error norms from a displacement solution.
//!
//! * Stress at a point of a cell: `sigma = D B(xi) u_e` (constant per T3 cell, varying otherwise);
//!   under finite kinematics the Cauchy stress `sigma = F S F^T / J`
//!   ([`crate::solid_finite`]) at the point, a stress of the deformed configuration reported
//!   at the point's reference position (the `.vtu` holds the reference mesh and the
//!   displacement: warped by the displacement it is the deformed mesh the stress lives on).
//!   Every check that compares stresses (`uniform_stress`, `contact_pressure`, the exact
//!   fields) then compares the Cauchy stress. The out-of-plane `sigma_zz` is the law's too:
//!   `S_33 / J` under finite kinematics, `nu (sigma_xx + sigma_yy)` in small-strain plane
//!   strain, zero in plane stress ([`out_of_plane_stress_at`]).
//! * Cell stress: at the cell centre. Nodal stress: the average over the cells sharing a node of
//!   each cell's stress evaluated at that node (no smoothing beyond averaging).
//! * Relative L2 displacement error: `sqrt(int |u_h - u|^2 dA / int |u|^2 dA)`, with a Gauss rule
//!   richer than the stiffness rule (see `fe::ElementKind::error_rule`).

use crate::contact::forces::PairForces;
use crate::contact::results::PairResults;
use crate::contact::state::ContactState;
use crate::fe::displacement_gradient_at;
use crate::fe::ReferenceCell;
use crate::harness::exact::ExactField;
use crate::io::contact_output::pair_file_names;
use crate::model::space::SolidCell;
use crate::model::{Body, Model};
use crate::solid::{strain_at, MAX_DOFS};
use crate::solid_finite::jacobian;
use serde::Serialize;

/// Element displacements of cell `c` of `body`.
pub fn cell_displacements(body: &Body, u: &[f64], c: usize, out: &mut Vec<f64>) {
    out.clear();
    for &n in body.mesh.cell(c) {
        out.push(u[body.dof(n, 0)]);
        out.push(u[body.dof(n, 1)]);
    }
}

/// Stress `[xx, yy, xy]` and position at natural point `xi` of cell `c`.
pub fn stress_at(body: &Body, u: &[f64], c: usize, xi: [f64; 2]) -> ([f64; 3], [f64; 2]) {
    let mut ue = Vec::with_capacity(MAX_DOFS);
    cell_displacements(body, u, c, &mut ue);
    let coords = body.mesh.cell_coords(c);
    if let Some(law) = &body.hyperelastic {
        // finite kinematics: the Cauchy stress sigma = F S F^T / J of the deformed body
        let (h, x) = displacement_gradient_at(body.mesh.kind, &coords, &ue, xi);
        if jacobian(&h) <= 0.0 {
            return ([f64::NAN; 3], x);
        }
        let sigma = law.cauchy(&h);
        return ([sigma[(0, 0)], sigma[(1, 1)], sigma[(0, 1)]], x);
    }
    let (eps, x) = strain_at(body.mesh.kind, &coords, &ue, xi);
    (body.material.stress(eps), x)
}

/// Calls `visit(cell, x, sigma)` at every stiffness quadrature point of `body`.
pub fn for_each_quadrature_stress(
    body: &Body,
    u: &[f64],
    mut visit: impl FnMut(usize, [f64; 2], [f64; 3]),
) {
    let rule = body.mesh.kind.stiffness_rule();
    for c in 0..body.mesh.cell_count() {
        for q in &rule {
            let (s, x) = stress_at(body, u, c, q.xi);
            visit(c, x, s);
        }
    }
}

/// Stress at the centre of every cell.
pub fn cell_stresses(body: &Body, u: &[f64]) -> Vec<[f64; 3]> {
    let centre = body.mesh.kind.centre();
    (0..body.mesh.cell_count())
        .map(|c| stress_at(body, u, c, centre).0)
        .collect()
}

/// Nodal stresses averaged over the cells that share each node.
pub fn nodal_stresses(body: &Body, u: &[f64]) -> Vec<[f64; 3]> {
    nodal_average(body, |c, xi| stress_at(body, u, c, xi).0)
}

/// The out-of-plane stress `sigma_zz` at natural point `xi` of cell `c`, by the law the body
/// is solved with: zero in plane stress; in plane strain `nu (sigma_xx + sigma_yy)` under
/// small strain, and under finite kinematics the Cauchy stress `S_33 / J` of the hyperelastic
/// law (`lambda ln J / J` for the neo-Hookean solid), which is not the small-strain relation.
pub fn out_of_plane_stress_at(body: &Body, u: &[f64], c: usize, xi: [f64; 2]) -> f64 {
    if let Some(law) = &body.hyperelastic {
        let mut ue = Vec::with_capacity(MAX_DOFS);
        cell_displacements(body, u, c, &mut ue);
        let coords = body.mesh.cell_coords(c);
        let (h, _) = displacement_gradient_at(body.mesh.kind, &coords, &ue, xi);
        if jacobian(&h) <= 0.0 {
            return f64::NAN;
        }
        return law.cauchy(&h)[(2, 2)];
    }
    body.material.sigma_zz(stress_at(body, u, c, xi).0)
}

/// Nodal out-of-plane stresses ([`out_of_plane_stress_at`]) averaged as [`nodal_stresses`].
pub fn nodal_out_of_plane_stresses(body: &Body, u: &[f64]) -> Vec<f64> {
    nodal_average(body, |c, xi| [out_of_plane_stress_at(body, u, c, xi)])
        .into_iter()
        .map(|[v]| v)
        .collect()
}

/// The average at each node of `value(cell, xi)` evaluated at the node's natural coordinates
/// in every cell that shares it (zero at a node of no cell).
fn nodal_average<const N: usize>(
    body: &Body,
    value: impl Fn(usize, [f64; 2]) -> [f64; N] + Sync,
) -> Vec<[f64; N]> {
    let mesh = &body.mesh;
    let mut sum = vec![[0.0; N]; mesh.nodes.len()];
    let mut count = vec![0u32; mesh.nodes.len()];
    let natural = mesh.kind.node_coordinates();
    // the corner values cell by cell on every core, summed in cell order (the same sums,
    // to the bit, as one loop)
    use rayon::prelude::*;
    let corners: Vec<Vec<[f64; N]>> = (0..mesh.cell_count())
        .into_par_iter()
        .with_min_len(4096)
        .map(|c| {
            (0..mesh.cell(c).len())
                .map(|a| value(c, natural[a]))
                .collect()
        })
        .collect();
    for (c, values) in corners.iter().enumerate() {
        for (&n, s) in mesh.cell(c).iter().zip(values) {
            for i in 0..N {
                sum[n][i] += s[i];
            }
            count[n] += 1;
        }
    }
    sum.iter()
        .zip(&count)
        .map(|(s, &k)| {
            if k == 0 {
                [0.0; N]
            } else {
                s.map(|v| v / k as f64)
            }
        })
        .collect()
}

/// `Ok` when every nodal stress of every body (what the output writes) is finite, else the
/// error naming the first node where one is not.
pub fn check_finite_stresses(model: &Model, u: &[f64]) -> crate::Result<()> {
    check_finite_nodal_stresses(model, u, nodal_stresses)
}

/// [`check_finite_stresses`] in any dimension: `nodal(body, u)` gives the nodal stresses the
/// output writes for `body` (any number of components); the error names the body, the node,
/// its position and the stage.
pub fn check_finite_nodal_stresses<const D: usize, K: SolidCell<D>, const S: usize>(
    model: &Model<D, K>,
    u: &[f64],
    nodal: impl Fn(&Body<D, K>, &[f64]) -> Vec<[f64; S]>,
) -> crate::Result<()> {
    for body in &model.bodies {
        let stresses = nodal(body, u);
        if let Some((n, s)) = stresses
            .iter()
            .enumerate()
            .find(|(_, s)| s.iter().any(|v| !v.is_finite()))
        {
            let value = s
                .iter()
                .copied()
                .find(|v| !v.is_finite())
                .unwrap_or(f64::NAN);
            let p = body.mesh.nodes[n];
            let point: Vec<String> = p.iter().map(|x| x.to_string()).collect();
            return Err(crate::solver::linear::non_finite_at(
                model,
                "the nodal stress",
                value,
                &format!("body '{}', node {n} at ({})", body.name, point.join(", ")),
                "when the stresses were computed from the displacement",
            ));
        }
    }
    Ok(())
}

/// Relative L2 error of the displacement of all bodies against `exact`.
pub fn relative_l2_displacement_error(model: &Model, u: &[f64], exact: &ExactField) -> f64 {
    let (mut err, mut norm) = (0.0, 0.0);
    for body in &model.bodies {
        let kind = body.mesh.kind;
        let rule = kind.error_rule();
        let mut ue = Vec::with_capacity(MAX_DOFS);
        for c in 0..body.mesh.cell_count() {
            let coords = body.mesh.cell_coords(c);
            cell_displacements(body, u, c, &mut ue);
            for q in &rule {
                let pv = kind.point_values(&coords, q.xi);
                let mut uh = [0.0; 2];
                for a in 0..kind.node_count() {
                    uh[0] += pv.n[a] * ue[2 * a];
                    uh[1] += pv.n[a] * ue[2 * a + 1];
                }
                let ux = exact.displacement(pv.x, &body.material);
                let w = q.weight * pv.det_j;
                err += w * ((uh[0] - ux[0]).powi(2) + (uh[1] - ux[1]).powi(2));
                norm += w * (ux[0].powi(2) + ux[1].powi(2));
            }
        }
    }
    if norm > 0.0 {
        (err / norm).sqrt()
    } else {
        err.sqrt()
    }
}

/// Finds the cell of a body that contains a point: a bucket grid over the cells' bounding
/// boxes gives the candidates, the isoparametric map is inverted by Newton's method in each,
/// and the first cell whose reference domain contains the result (within `1e-9`) is taken.
pub struct CellLocator<'a> {
    body: &'a Body,
    grid: crate::contact::discretization::search::BucketGrid,
}

impl<'a> CellLocator<'a> {
    pub fn new(body: &'a Body) -> Self {
        let mesh = &body.mesh;
        let boxes = (0..mesh.cell_count())
            .map(|c| {
                let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
                for &n in mesh.cell(c) {
                    for i in 0..2 {
                        lo[i] = lo[i].min(mesh.nodes[n][i]);
                        hi[i] = hi[i].max(mesh.nodes[n][i]);
                    }
                }
                [lo, hi]
            })
            .collect();
        CellLocator {
            body,
            grid: crate::contact::discretization::search::BucketGrid::new(boxes),
        }
    }

    /// The cell containing `p` and the natural coordinates of `p` in it.
    pub fn locate(&self, p: [f64; 2]) -> Option<(usize, [f64; 2])> {
        let mesh = &self.body.mesh;
        let kind = mesh.kind;
        let tol = 1e-9;
        let triangle = matches!(
            kind,
            crate::fe::ElementKind::T3 | crate::fe::ElementKind::T6
        );
        let nn = kind.node_count();
        for c in self.grid.query(p, 1e-9 * mesh.size()) {
            let coords = mesh.cell_coords(c);
            let mut xi = kind.centre();
            for _ in 0..30 {
                let (mut n, mut dn) = (
                    [0.0; crate::fe::MAX_NODES],
                    [[0.0; 2]; crate::fe::MAX_NODES],
                );
                kind.shape(xi, &mut n[..nn], &mut dn[..nn]);
                let mut x = [0.0; 2];
                let mut j = [[0.0; 2]; 2];
                for a in 0..nn {
                    for i in 0..2 {
                        x[i] += n[a] * coords[a][i];
                        for k in 0..2 {
                            j[i][k] += coords[a][i] * dn[a][k];
                        }
                    }
                }
                let r = [p[0] - x[0], p[1] - x[1]];
                let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
                let d = [
                    (j[1][1] * r[0] - j[0][1] * r[1]) / det,
                    (-j[1][0] * r[0] + j[0][0] * r[1]) / det,
                ];
                xi = [xi[0] + d[0], xi[1] + d[1]];
                if d[0].is_nan() || d[0].abs() + d[1].abs() <= 1e-13 {
                    break;
                }
            }
            let inside = if triangle {
                xi[0] >= -tol && xi[1] >= -tol && xi[0] + xi[1] <= 1.0 + tol
            } else {
                xi[0].abs() <= 1.0 + tol && xi[1].abs() <= 1.0 + tol
            };
            if inside {
                return Some((c, xi));
            }
        }
        None
    }

    /// Displacement and stress at the point `p` (if it lies in the body).
    pub fn sample(&self, u: &[f64], p: [f64; 2]) -> Option<([f64; 2], [f64; 3])> {
        let body = self.body;
        let (c, xi) = self.locate(p)?;
        let coords = body.mesh.cell_coords(c);
        let pv = body.mesh.kind.point_values(&coords, xi);
        let mut ue = Vec::with_capacity(MAX_DOFS);
        cell_displacements(body, u, c, &mut ue);
        let mut uh = [0.0; 2];
        for a in 0..body.mesh.kind.node_count() {
            uh[0] += pv.n[a] * ue[2 * a];
            uh[1] += pv.n[a] * ue[2 * a + 1];
        }
        Some((uh, stress_at(body, u, c, xi).0))
    }
}

/// The reaction of one support set: per component, the sum of the reactions `K u - f` at the
/// dofs the set's supports prescribe. A dof that several sets prescribe (the same node held in
/// the same component by two sets) counts once, in the set of the first support of the case
/// that prescribes it; a later set lists it under `shared`. A node held in x by one set and in
/// y by another gives each set its own component. A component the set prescribes nowhere (or
/// only where an earlier set counts it) reads 0; `held` names the components it prescribes.
#[derive(serde::Serialize)]
pub struct ReactionSummary {
    pub body: String,
    pub set: String,
    pub x: f64,
    pub y: f64,
    /// The z component (3D bodies only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z: Option<f64>,
    /// The components the set's supports prescribe (`"x"`, `"y"`, `"z"`).
    pub held: Vec<&'static str>,
    /// Dofs the set prescribes whose reaction counts in an earlier set.
    pub shared: Vec<SharedReaction>,
}

/// Dofs of a support set whose reaction counts in another (earlier) set.
#[derive(serde::Serialize)]
pub struct SharedReaction {
    pub component: &'static str,
    /// The set that counts them.
    pub counted_in: String,
    pub nodes: usize,
}

/// The reaction of every support set of `model` (see [`ReactionSummary`]), 2D and 3D.
pub fn reaction_summaries<const D: usize, K: SolidCell<D>>(
    model: &crate::model::Model<D, K>,
    reactions: &[f64],
) -> Vec<ReactionSummary> {
    const COMPONENTS: [&str; 3] = ["x", "y", "z"];
    // the set that counts each dof: the first support prescribing it
    let mut owner: std::collections::BTreeMap<usize, usize> = std::collections::BTreeMap::new();
    for &(set, _, dof) in &model.support_dofs {
        owner.entry(dof).or_insert(set);
    }
    model
        .support_sets
        .iter()
        .enumerate()
        .map(|(i, (bi, set))| {
            let mut own = [0.0; 3];
            let mut held = [false; 3];
            let mut counted = std::collections::BTreeSet::new();
            let mut shared: std::collections::BTreeMap<(usize, usize), usize> =
                std::collections::BTreeMap::new();
            for &(s, comp, dof) in model.support_dofs.iter().filter(|e| e.0 == i) {
                held[comp] = true;
                let first = owner[&dof];
                if first == s {
                    if counted.insert(dof) {
                        own[comp] += reactions[dof];
                    }
                } else if counted.insert(dof) {
                    *shared.entry((comp, first)).or_insert(0) += 1;
                }
            }
            ReactionSummary {
                body: model.bodies[*bi].name.clone(),
                set: set.clone(),
                x: own[0],
                y: own[1],
                z: (D == 3).then_some(own[2]),
                held: (0..D).filter(|&c| held[c]).map(|c| COMPONENTS[c]).collect(),
                shared: shared
                    .into_iter()
                    .map(|((comp, first), nodes)| {
                        let (fb, fs) = &model.support_sets[first];
                        SharedReaction {
                            component: COMPONENTS[comp],
                            counted_in: format!("{}.{fs}", model.bodies[*fb].name),
                            nodes,
                        }
                    })
                    .collect(),
            }
        })
        .collect()
}

/// What one contact pair transmits (`D` components: the same summary in 2D and 3D).
#[derive(Serialize)]
pub struct PairSummary<const D: usize = 2> {
    pub name: String,
    /// Net force on the slave body and on the master (body or rigid surface), `[x, y(, z)]`.
    #[serde(serialize_with = "crate::contact::results::components")]
    pub force_on_slave: [f64; D],
    #[serde(serialize_with = "crate::contact::results::components")]
    pub force_on_master: [f64; D],
    pub max_pressure: f64,
    pub max_penetration: f64,
    pub max_penetration_share: f64,
    /// Body, node and position of the slave node with the largest share.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_penetration_at: Option<PointRef<D>>,
    /// Coulomb pairs: total tangential force, stick/slip/open counts, dissipation.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction: Option<crate::contact::friction::FrictionSummary>,
    /// The normal force the pair transmits (`sum_a -f_a . n_a` over the slave surface), the
    /// covered tributary area of its closed points, and the points of each status (both
    /// surfaces; see [`crate::contact::results`]).
    pub normal_force: f64,
    pub closed_area: f64,
    pub point_status: PointStatusCounts,
    /// The pair's per-point files in this folder: contact `.vtu`, `.csv`, `.json`.
    pub files: [String; 3],
}

/// How many points of a pair's surfaces have each status.
#[derive(Serialize)]
pub struct PointStatusCounts {
    pub unmeasured: usize,
    pub open: usize,
    pub closed: usize,
    pub stick: usize,
    pub slip: usize,
}

/// A node named for a user: body name, node number, position.
#[derive(Serialize)]
pub struct PointRef<const D: usize = 2> {
    pub body: String,
    pub node: usize,
    #[serde(serialize_with = "crate::contact::results::components")]
    pub point: [f64; D],
}

/// The summary of every pair of `model` (in either dimension) from its forces and per-point
/// results in the contact solution `state`.
pub fn pair_summaries<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    state: &ContactState<D>,
    forces: &[PairForces<D>],
    results: &[PairResults<D>],
) -> Vec<PairSummary<D>> {
    forces
        .iter()
        .zip(results)
        .map(|(f, r)| PairSummary {
            name: model.contact[f.pair].name.clone(),
            force_on_slave: f.on_slave,
            force_on_master: f.on_master,
            max_pressure: f.max_pressure(),
            max_penetration: f.penetration.depth,
            max_penetration_share: f.penetration.share_of_element,
            max_penetration_at: f.penetration.at.map(|(b, node, point)| PointRef {
                body: model.bodies[b].name.clone(),
                node,
                point,
            }),
            friction: state.friction_summary(Some(f.pair)),
            normal_force: r.totals.normal_force,
            closed_area: r.totals.closed_area,
            point_status: PointStatusCounts {
                unmeasured: r.totals.unmeasured,
                open: r.totals.open,
                closed: r.totals.closed,
                stick: r.totals.stick,
                slip: r.totals.slip,
            },
            files: pair_file_names(&r.name).unwrap_or_default(),
        })
        .collect()
}
