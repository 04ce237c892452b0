//! Post-processing: stresses and error norms from a displacement solution.
//!
//! * Stress at a point of a cell: `sigma = D B(xi) u_e` (constant per T3 cell, varying otherwise).
//! * Cell stress: at the cell centre. Nodal stress: the average over the cells sharing a node of
//!   each cell's stress evaluated at that node (no smoothing beyond averaging).
//! * Relative L2 displacement error: `sqrt(int |u_h - u|^2 dA / int |u|^2 dA)`, with a Gauss rule
//!   richer than the stiffness rule (see `fe::ElementKind::error_rule`).

use crate::exact::ExactField;
use crate::fe::point_values;
use crate::model::{Body, Model};
use crate::solid::{strain_at, MAX_DOFS};

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
    let mesh = &body.mesh;
    let mut sum = vec![[0.0; 3]; mesh.nodes.len()];
    let mut count = vec![0u32; mesh.nodes.len()];
    let natural = mesh.kind.node_coordinates();
    for c in 0..mesh.cell_count() {
        for (a, &n) in mesh.cell(c).iter().enumerate() {
            let (s, _) = stress_at(body, u, c, natural[a]);
            for i in 0..3 {
                sum[n][i] += s[i];
            }
            count[n] += 1;
        }
    }
    sum.iter()
        .zip(&count)
        .map(|(s, &k)| {
            if k == 0 {
                [0.0; 3]
            } else {
                s.map(|v| v / k as f64)
            }
        })
        .collect()
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
                let pv = point_values(kind, &coords, q.xi);
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
