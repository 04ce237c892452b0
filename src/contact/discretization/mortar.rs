//! Mortar discretization (Taylor 2004, "2002-2004: Mortar Methods for Contact & Ties"), 2D,
//! Line2 and Line3 facets, segment-based integration.
//!
//! With multiplier functions `Phi_j` on the slave surface, the interface term
//! `int lambda . (x_s - x_m) dGamma` becomes, per slave node `j`,
//!
//! ```text
//! D_jk = int_slave Phi_j N_k dGamma,   M_jl = int_slave Phi_j N_l(xi_m) dGamma,
//! g_j  = nu_j . (sum_k D_jk x_k - sum_l M_jl x_l) / A_j,   A_j = sum_k D_jk
//! ```
//!
//! (`nu_j` the reversed nodal normal of the slave surface), so a mortar row is a
//! [`crate::contact::Constraint`] with weights `D_jk / A_j` on slave nodes and `M_jl / A_j` on master
//! nodes, and every enforcement method applies unchanged; its force `lambda_j` is the
//! multiplier times `A_j`, a nodal force like the node-to-surface ones.
//!
//! * **Standard** multipliers: `Phi_j = N_j`.
//! * **Dual** multipliers: `Phi_j = sum_k a_jk N_k` biorthogonal to `N`:
//!   `int Phi_j N_k = delta_jk int N_k`, so `D` is diagonal. Line2: `(1 -+ 3 xi)/2`; Line3
//!   (nodes -1, +1, 0): `(5 xi^2 -+ 2 xi - 1)/4` and `(3 - 5 xi^2)/2` (Wohlmuth; the seed's
//!   `alpha = 2, -1`). Each row then touches only its own slave node, so constraint
//!   elimination applies.
//! * **Segments**: each slave facet is split at the projections of the master facets' end
//!   nodes; on each sub-segment the master facet is found at the midpoint and `n_gauss` Gauss
//!   points (3 for Line2, 4 for Line3) integrate `Phi N` exactly on straight facets
//!   (polynomials of degree 2 and 4). Element-based integration without segmentation does
//!   not pass the patch test (benchmarks.md s. 2 reports errors of 1e-3 to 1e-5).
//! * Because `sum_k D_jk = sum_l M_jl` when the slave facet is covered, the forces `D^T lambda`
//!   and `-M^T lambda` balance (linear momentum); the check `force_balance` measures it.
//! * **Multiplier mass** (for the perturbed Lagrangian, `int mu_h lambda_h / kappa`): the L2
//!   pairing of the multiplier field with the slave trace, `int Phi_j N_k dGamma`, is `D_jk`
//!   itself. With standard multipliers `Phi = N`, so it is the consistent (non-diagonal) mass
//!   `int Phi_j Phi_k dGamma`, and each row carries its line `[(k, D_jk)]`
//!   ([`crate::contact::Constraint::mass`], summing to `A_j`). With dual multipliers it is
//!   `delta_jk A_j` by biorthogonality, the lumped mass every row already has in its area, so
//!   dual rows carry none. (The Galerkin pairing `int psi_j psi_k` of two dual functions is not
//!   diagonal, e.g. `h [[1, -1/2], [-1/2, 1]]` on one Line2 facet; we pair the dual multiplier
//!   with the trace space, the choice that keeps dual mortar local.)
//! * **Finite kinematics** (between deformable bodies, frictionless): the same integrals in the
//!   current configuration, and each row's gradient replaced by the exact one of its weighted
//!   gap, with the gap's second derivative attached ([`crate::contact::GapHessian`]): the
//!   segment ends, the projections of the Gauss points and the nodal normal all move with the
//!   nodes (`mortar_linearization`). The pieces found by [`mortar_integrals`] fix which master
//!   facet covers which piece.
//! * The segment-based integrals (multiplier functions, segmentation, `D`, `M`, covers) are in
//!   [`super::mortar_segments`], which both this module and the linearization use.

use super::geometry::{edge_shape, facet_point, Surface};
use super::mortar_linearization::{linearize_rigid_row, linearize_row};
use super::mortar_segments::{covered_tributaries, gauss_rule, mortar_integrals, multiplier};
use super::Rows;
use crate::contact::GapHessian;
use crate::fe::{gauss_legendre, EdgeKind};
use crate::io::scene::{Kinematics, MultiplierSpace, RigidSurface};
use std::collections::BTreeMap;

/// Mortar rows of `slave` against `master`. Under finite kinematics (frictionless, not tied)
/// each row's gradient is the exact one and the row carries its gap's second derivative
/// ([`super::mortar_linearization`]).
pub(crate) fn mortar_rows(
    rows: &mut Rows,
    slave: &Surface,
    master: &Surface,
    space: MultiplierSpace,
) -> Result<(), String> {
    let model = rows.model;
    let sb = &model.bodies[slave.body];
    let mb = &model.bodies[master.body];
    let radius = rows.search_distance.unwrap_or_else(|| master.facet_size());
    let (d, m, pieces) = mortar_integrals(slave, master, space, radius, model.thickness);
    let cover = covered_tributaries(
        slave,
        &pieces,
        &gauss_rule(slave.kind, master.kind),
        model.thickness,
    );
    let linearize = model.physics.kinematics == Kinematics::Finite && !rows.tied;
    for (&j, dj) in &d {
        let area: f64 = dj.values().sum();
        if area <= 1e-12 * radius * model.thickness {
            continue; // the node's multiplier sees no master surface
        }
        let slave_terms: Vec<(usize, f64)> = std::iter::once(j)
            .chain(dj.keys().copied().filter(|&k| k != j))
            .map(|k| (k, dj.get(&k).copied().unwrap_or(0.0) / area))
            .collect();
        let master_terms: Vec<(usize, f64)> = m
            .get(&j)
            .map(|mj| mj.iter().map(|(&l, &v)| (l, v / area)).collect())
            .unwrap_or_default();
        let n = slave.nodes[&j].normal;
        let nu = [-n[0], -n[1]];
        let mut g0 = 0.0;
        for &(k, w) in &slave_terms {
            let x = sb.mesh.nodes[k];
            g0 += w * (nu[0] * x[0] + nu[1] * x[1]);
        }
        for &(l, w) in &master_terms {
            let x = mb.mesh.nodes[l];
            g0 -= w * (nu[0] * x[0] + nu[1] * x[1]);
        }
        let before = rows.out.len();
        rows.push(
            slave,
            j,
            nu,
            g0,
            &slave_terms,
            Some((master.body, &master_terms)),
            area,
            1,
        );
        for r in &mut rows.out[before..] {
            r.cover = cover.get(&j).cloned().unwrap_or_default();
        }
        if linearize {
            let row = rows.out.last_mut().expect("the row was just pushed");
            let dof = |master: bool, node: usize, i: usize| {
                if master {
                    mb.dof(node, i)
                } else {
                    sb.dof(node, i)
                }
            };
            let lin = linearize_row(slave, master, &pieces, space, model.thickness, j, dof);
            row.g0 = lin.gap;
            row.dofs = lin.dofs.clone();
            row.coeffs = lin.gradient;
            row.hessian = Some(GapHessian {
                dofs: lin.dofs,
                values: lin.hessian,
            });
        }
        if space == MultiplierSpace::Standard {
            // the multiplier mass M_jk = int N_j N_k = D_jk (Phi = N), in area units
            let mass: Vec<(usize, f64)> = std::iter::once(j)
                .chain(dj.keys().copied().filter(|&k| k != j))
                .map(|k| (k, dj.get(&k).copied().unwrap_or(0.0)))
                .collect();
            for r in &mut rows.out[before..] {
                r.mass = mass.clone();
            }
        }
    }
    if rows.out.is_empty() {
        return Err("no slave facet overlaps a master facet".into());
    }
    Ok(())
}

/// Gauss points per slave facet for the mortar integrals against a rigid circle.
pub const RIGID_CIRCLE_GAUSS: usize = 8;

/// The pointwise gap to a rigid surface at `x` and its gradient (the unit normal there).
pub(crate) fn rigid_gap(rigid: &RigidSurface, x: [f64; 2]) -> Result<(f64, [f64; 2]), String> {
    match *rigid {
        RigidSurface::Line { point, normal } => {
            let l = normal[0].hypot(normal[1]);
            let n = [normal[0] / l, normal[1] / l];
            Ok((n[0] * (x[0] - point[0]) + n[1] * (x[1] - point[1]), n))
        }
        RigidSurface::Circle { centre, radius } => {
            let d = [x[0] - centre[0], x[1] - centre[1]];
            let l = d[0].hypot(d[1]);
            if l <= 1e-12 * radius {
                return Err(format!(
                    "the slave surface at ({}, {}) sits at the centre of the rigid circle, where the normal is undefined",
                    x[0], x[1]
                ));
            }
            Ok((l - radius, [d[0] / l, d[1] / l]))
        }
        RigidSurface::Plane { .. } | RigidSurface::Sphere { .. } => Err(format!(
            "the rigid surface is 3D and the slave surface at ({}, {}) 2D",
            x[0], x[1]
        )),
    }
}

/// Mortar rows of `slave` against a rigid surface (see the module notes).
pub(crate) fn rigid_mortar_rows(
    rows: &mut Rows,
    slave: &Surface,
    rigid: &RigidSurface,
    space: MultiplierSpace,
) -> Result<(), String> {
    let model = rows.model;
    let ks = slave.kind;
    let ns = ks.node_count();
    let gauss = gauss_legendre(match rigid {
        RigidSurface::Circle { .. } => RIGID_CIRCLE_GAUSS,
        RigidSurface::Line { .. } if ks == EdgeKind::Line3 => 4,
        RigidSurface::Line { .. } => 3,
        RigidSurface::Plane { .. } | RigidSurface::Sphere { .. } => {
            return Err("the rigid surface is 3D and the slave surface 2D".into())
        }
    });
    // per slave node j: D_jk, int Phi_j g, and int Phi_j N_k n (per k)
    let mut d: BTreeMap<usize, BTreeMap<usize, f64>> = BTreeMap::new();
    let mut weighted_gap: BTreeMap<usize, f64> = BTreeMap::new();
    let mut gradient: BTreeMap<usize, BTreeMap<usize, [f64; 2]>> = BTreeMap::new();
    for (f, coords) in slave.coords.iter().enumerate() {
        for &(s, wq) in &gauss {
            let (x, t) = facet_point(ks, coords, s);
            let jac = t[0].hypot(t[1]) * model.thickness;
            let (g, n) = rigid_gap(rigid, x)?;
            let (n_s, _) = edge_shape(ks, s);
            let phi = multiplier(ks, space, s);
            for j in 0..ns {
                let w = wq * jac * phi[j];
                let node = slave.facets[f][j];
                *weighted_gap.entry(node).or_default() += w * g;
                let dj = d.entry(node).or_default();
                let cj = gradient.entry(node).or_default();
                for k in 0..ns {
                    let other = slave.facets[f][k];
                    *dj.entry(other).or_default() += w * n_s[k];
                    let c = cj.entry(other).or_default();
                    c[0] += w * n_s[k] * n[0];
                    c[1] += w * n_s[k] * n[1];
                }
            }
        }
    }
    // the weights' own variation: d(int Phi_j g dGamma / A_j) also holds
    // int Phi_j (g - g_j) d(dGamma), with d(dGamma)/dx_k = t N_k' x'/|x'| ds
    let mut weight_term: BTreeMap<usize, BTreeMap<usize, [f64; 2]>> = BTreeMap::new();
    for (f, coords) in slave.coords.iter().enumerate() {
        for &(s, wq) in &gauss {
            let (x, t) = facet_point(ks, coords, s);
            let l = t[0].hypot(t[1]);
            let (g, _) = rigid_gap(rigid, x)?;
            let (_, dn_s) = edge_shape(ks, s);
            let phi = multiplier(ks, space, s);
            for j in 0..ns {
                let node = slave.facets[f][j];
                let area: f64 = d[&node].values().sum();
                let g_j = weighted_gap[&node] / area;
                let w = wq * model.thickness * phi[j] * (g - g_j);
                let cj = weight_term.entry(node).or_default();
                for k in 0..ns {
                    let c = cj.entry(slave.facets[f][k]).or_default();
                    c[0] += w * dn_s[k] * t[0] / l;
                    c[1] += w * dn_s[k] * t[1] / l;
                }
            }
        }
    }
    let sb = &model.bodies[slave.body];
    for (&j, dj) in &d {
        let area: f64 = dj.values().sum();
        if area <= 1e-12 * slave.facet_size() * model.thickness {
            continue;
        }
        let order: Vec<usize> = std::iter::once(j)
            .chain(dj.keys().copied().filter(|&k| k != j))
            .collect();
        let slave_terms: Vec<(usize, f64)> = order.iter().map(|&k| (k, dj[&k] / area)).collect();
        let cj = &gradient[&j];
        let sum = cj
            .values()
            .fold([0.0; 2], |a, c| [a[0] + c[0], a[1] + c[1]]);
        let l = sum[0].hypot(sum[1]);
        let nu = [sum[0] / l, sum[1] / l];
        let g0 = weighted_gap[&j] / area;
        let before = rows.out.len();
        rows.push(slave, j, nu, g0, &slave_terms, None, area, 1);
        if !rows.tied {
            // the exact gradient in place of the weights times one direction (the same on a line)
            let row = &mut rows.out[before];
            let largest = cj
                .values()
                .fold(0.0f64, |a, c| a.max(c[0].abs()).max(c[1].abs()));
            row.dofs.clear();
            row.coeffs.clear();
            let extra = &weight_term[&j];
            for &k in &order {
                for i in 0..2 {
                    let c = (cj[&k][i] + extra[&k][i]) / area;
                    if c.abs() > 1e-12 * largest / area {
                        row.dofs.push(sb.dof(k, i));
                        row.coeffs.push(c);
                    }
                }
            }
        }
        if model.physics.kinematics == Kinematics::Finite && !rows.tied {
            // finite kinematics: the gap's second derivative too (the length element and the
            // distance vary with the positions), by hyper-dual numbers
            let lin = linearize_rigid_row(
                slave,
                rigid,
                space,
                model.thickness,
                j,
                &gauss,
                |node, i| sb.dof(node, i),
            );
            let row = &mut rows.out[before];
            row.g0 = lin.gap;
            row.dofs = lin.dofs.clone();
            row.coeffs = lin.gradient;
            row.hessian = Some(GapHessian {
                dofs: lin.dofs,
                values: lin.hessian,
            });
        }
        if space == MultiplierSpace::Standard {
            let mass: Vec<(usize, f64)> = order.iter().map(|&k| (k, dj[&k])).collect();
            for r in &mut rows.out[before..] {
                r.mass = mass.clone();
            }
        }
    }
    if rows.out.is_empty() {
        return Err("no slave node carries a mortar row against the rigid surface".into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dual_functions_are_biorthogonal() {
        for kind in [EdgeKind::Line2, EdgeKind::Line3] {
            let k = kind.node_count();
            let g = gauss_legendre(5);
            for j in 0..k {
                for l in 0..k {
                    let (mut int_psi_n, mut int_n) = (0.0, 0.0);
                    for &(s, w) in &g {
                        let psi = multiplier(kind, MultiplierSpace::Dual, s);
                        let (n, _) = edge_shape(kind, s);
                        int_psi_n += w * psi[j] * n[l];
                        int_n += w * n[l];
                    }
                    let expect = if j == l { int_n } else { 0.0 };
                    assert!(
                        (int_psi_n - expect).abs() < 1e-14,
                        "{kind:?} {j} {l}: {int_psi_n} vs {expect}"
                    );
                }
            }
        }
    }
}
