//! Segment-based mortar integrals in 2D (Taylor 2004, "2002-2004: Mortar Methods for Contact &
//! Ties"; Puso & Laursen 2004): the multiplier functions, the segmentation of each slave facet
//! at the projections of the master facets' end nodes, and the matrices
//!
//! ```text
//! D_jk = int_slave Phi_j N_k dGamma,   M_jl = int_slave Phi_j N_l(xi_m) dGamma
//! ```
//!
//! by Gauss points on each sub-segment (3 between Line2 facets, 4 where either is Line3: exact
//! for `Phi N` on straight facets). Standard multipliers `Phi_j = N_j`; dual ones biorthogonal
//! to `N` (`int Phi_j N_k = delta_jk int N_k`; Line2 `(1 -+ 3 xi)/2`, Line3 (nodes -1, +1, 0)
//! `(5 xi^2 -+ 2 xi - 1)/4` and `(3 - 5 xi^2)/2`, Wohlmuth). The covered tributary of a slave
//! node (`t int N_a ds` over the overlapped pieces) is integrated on the same pieces.
//!
//! The rows built from these integrals are in [`super::mortar`]; their exact linearization under
//! finite kinematics, which re-integrates on the same pieces, in [`super::mortar_linearization`].
//! Both depend on this module and it on neither.

use super::geometry::{closest_point, edge_shape, facet_point, Surface};
use super::search::BucketGrid;
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

/// A break point on a slave facet: its parameter `s`, and the master node (id, position) whose
/// projection it is (`None` at a facet end).
pub(crate) type BreakPoint = (f64, Option<(usize, [f64; 2])>);

/// A piece of a slave facet between two break points, integrated against one master facet.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SubSegment {
    /// The ends in the slave facet's parameter `s`: a facet end (`None`) or the projection of
    /// a master node (its id and position).
    pub ends: [BreakPoint; 2],
    /// The master facet over the piece (an index into the master surface's facets).
    pub master_facet: usize,
}

/// `D_jk` and `M_jl` by slave node `j` (over slave nodes `k`, master nodes `l`).
pub(crate) type MortarMatrix = BTreeMap<usize, BTreeMap<usize, f64>>;

/// The segment-based mortar integrals of `slave` against `master` (see the module notes):
/// `D`, `M`, and each slave facet's pieces.
pub(crate) fn mortar_integrals(
    slave: &Surface,
    master: &Surface,
    space: MultiplierSpace,
    radius: f64,
    thickness: f64,
) -> (MortarMatrix, MortarMatrix, Vec<Vec<SubSegment>>) {
    let (ks, km) = (slave.kind, master.kind);
    let (ns, nm) = (ks.node_count(), km.node_count());
    let grid = BucketGrid::new(master.boxes());
    let gauss = gauss_rule(ks, km);
    let tol = 1e-12;
    // D[j][k] over slave nodes, M[j][l] over master nodes
    let mut d: MortarMatrix = BTreeMap::new();
    let mut m: MortarMatrix = BTreeMap::new();
    let mut pieces = Vec::with_capacity(slave.coords.len());
    let slave_boxes = slave.boxes();
    for (f, coords) in slave.coords.iter().enumerate() {
        let mut facet_pieces = Vec::new();
        let [lo, hi] = slave_boxes[f];
        let centre = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
        let reach = 0.5 * ((hi[0] - lo[0]).hypot(hi[1] - lo[1])) + radius;
        let candidates = grid.query(centre, reach);
        // break points: facet ends and the projections of master facet end nodes
        let mut breaks: Vec<BreakPoint> = vec![(-1.0, None), (1.0, None)];
        for &c in &candidates {
            for (&p, &node) in master.coords[c][..2].iter().zip(&master.facets[c][..2]) {
                let s = closest_point(ks, coords, p);
                if s.abs() < 1.0 - tol {
                    breaks.push((s, Some((node, p))));
                }
            }
        }
        breaks.sort_by(|a, b| a.0.total_cmp(&b.0));
        breaks.dedup_by(|a, b| (a.0 - b.0).abs() < tol);
        for w in breaks.windows(2) {
            let (a, b) = (w[0].0, w[1].0);
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
            facet_pieces.push(SubSegment {
                ends: [w[0], w[1]],
                master_facet: c,
            });
            for &(eta, wq) in &gauss {
                let s = a + 0.5 * (b - a) * (eta + 1.0);
                let (x, t) = facet_point(ks, coords, s);
                let jac = t[0].hypot(t[1]) * 0.5 * (b - a) * thickness;
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
        pieces.push(facet_pieces);
    }
    (d, m, pieces)
}

/// The covered tributary of each slave node facet by facet, `(facet, t int N_a ds)` over the
/// `pieces` of each slave facet (the parts a master facet overlaps; [`mortar_integrals`]), by
/// `gauss` on each piece: what [`crate::contact::Constraint::cover`] holds for a mortar row.
pub(crate) fn covered_tributaries(
    slave: &Surface,
    pieces: &[Vec<SubSegment>],
    gauss: &[(f64, f64)],
    thickness: f64,
) -> BTreeMap<usize, Vec<(usize, f64)>> {
    let mut cover: BTreeMap<usize, Vec<(usize, f64)>> = BTreeMap::new();
    for (f, facet_pieces) in pieces.iter().enumerate() {
        let coords = &slave.coords[f];
        let mut shares = [0.0; 3];
        for piece in facet_pieces {
            let (a, b) = (piece.ends[0].0, piece.ends[1].0);
            for &(eta, wq) in gauss {
                let s = a + 0.5 * (b - a) * (eta + 1.0);
                let (_, t) = facet_point(slave.kind, coords, s);
                let jac = t[0].hypot(t[1]) * 0.5 * (b - a) * thickness;
                let (n_s, _) = edge_shape(slave.kind, s);
                for (share, n) in shares.iter_mut().zip(n_s) {
                    *share += wq * jac * n;
                }
            }
        }
        for (&node, &share) in slave.facets[f].iter().zip(&shares) {
            cover.entry(node).or_default().push((f, share));
        }
    }
    cover
}

/// Gauss points per sub-segment: 3 between Line2 facets, 4 where either is Line3.
pub(crate) fn gauss_rule(slave: EdgeKind, master: EdgeKind) -> Vec<(f64, f64)> {
    gauss_legendre(if slave == EdgeKind::Line3 || master == EdgeKind::Line3 {
        4
    } else {
        3
    })
}
