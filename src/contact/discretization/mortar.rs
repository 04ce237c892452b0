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

use super::geometry::{closest_point, edge_shape, facet_point, Surface};
use super::search::BucketGrid;
use super::Rows;
use crate::fe::{gauss_legendre, EdgeKind};
use crate::io::scene::MultiplierSpace;
use std::collections::BTreeMap;

/// Multiplier function values at `s` on a slave facet.
pub fn multiplier(kind: EdgeKind, space: MultiplierSpace, s: f64) -> [f64; 3] {
    match (space, kind) {
        (MultiplierSpace::Standard, _) => edge_shape(kind, s).0,
        (MultiplierSpace::Dual, EdgeKind::Line2) => {
            [0.5 * (1.0 - 3.0 * s), 0.5 * (1.0 + 3.0 * s), 0.0]
        }
        (MultiplierSpace::Dual, EdgeKind::Line3) => {
            let s2 = s * s;
            [
                0.25 * (5.0 * s2 - 2.0 * s - 1.0),
                0.25 * (5.0 * s2 + 2.0 * s - 1.0),
                0.5 * (3.0 - 5.0 * s2),
            ]
        }
    }
}

/// Mortar rows of `slave` against `master`.
pub(crate) fn mortar_rows(
    rows: &mut Rows,
    slave: &Surface,
    master: &Surface,
    space: MultiplierSpace,
) -> Result<(), String> {
    let model = rows.model;
    let sb = &model.bodies[slave.body];
    let mb = &model.bodies[master.body];
    let (ks, km) = (slave.kind, master.kind);
    let (ns, nm) = (ks.node_count(), km.node_count());
    let grid = BucketGrid::new(master.boxes());
    let radius = rows.search_distance.unwrap_or_else(|| master.facet_size());
    let gauss = gauss_legendre(if ks == EdgeKind::Line3 || km == EdgeKind::Line3 {
        4
    } else {
        3
    });
    let tol = 1e-12;
    // D[j][k] over slave nodes, M[j][l] over master nodes
    let mut d: BTreeMap<usize, BTreeMap<usize, f64>> = BTreeMap::new();
    let mut m: BTreeMap<usize, BTreeMap<usize, f64>> = BTreeMap::new();
    let slave_boxes = slave.boxes();
    for (f, coords) in slave.coords.iter().enumerate() {
        let [lo, hi] = slave_boxes[f];
        let centre = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
        let reach = 0.5 * ((hi[0] - lo[0]).hypot(hi[1] - lo[1])) + radius;
        let candidates = grid.query(centre, reach);
        // break points: facet ends and the projections of master facet end nodes
        let mut breaks = vec![-1.0, 1.0];
        for &c in &candidates {
            for &p in &master.coords[c][..2] {
                let s = closest_point(ks, coords, p);
                if s.abs() < 1.0 - tol {
                    breaks.push(s);
                }
            }
        }
        breaks.sort_by(f64::total_cmp);
        breaks.dedup_by(|a, b| (*a - *b).abs() < tol);
        for w in breaks.windows(2) {
            let (a, b) = (w[0], w[1]);
            let (xm, _) = facet_point(ks, coords, 0.5 * (a + b));
            // the master facet over this sub-segment: the nearest one whose projection is inside
            let mut best: Option<(f64, usize)> = None;
            for &c in &candidates {
                let xi = closest_point(km, &master.coords[c], xm);
                if xi.is_nan() || xi.abs() > 1.0 + 1e-9 {
                    continue;
                }
                let (x, _) = facet_point(km, &master.coords[c], xi);
                let dist = (x[0] - xm[0]).hypot(x[1] - xm[1]);
                if best.is_none_or(|bb| dist < bb.0) {
                    best = Some((dist, c));
                }
            }
            let Some((_, c)) = best else { continue };
            for &(eta, wq) in &gauss {
                let s = a + 0.5 * (b - a) * (eta + 1.0);
                let (x, t) = facet_point(ks, coords, s);
                let jac = t[0].hypot(t[1]) * 0.5 * (b - a) * model.thickness;
                let xi = closest_point(km, &master.coords[c], x);
                let (n_s, _) = edge_shape(ks, s);
                let (n_m, _) = edge_shape(km, xi);
                let phi = multiplier(ks, space, s);
                for j in 0..ns {
                    let dj = d.entry(slave.facets[f][j]).or_default();
                    for k in 0..ns {
                        *dj.entry(slave.facets[f][k]).or_default() += wq * jac * phi[j] * n_s[k];
                    }
                    let mj = m.entry(slave.facets[f][j]).or_default();
                    for l in 0..nm {
                        *mj.entry(master.facets[c][l]).or_default() += wq * jac * phi[j] * n_m[l];
                    }
                }
            }
        }
    }
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
