//! Surface geometry in the reference configuration: facets, closest-point projection,
//! normals and nodal weights.
//!
//! A facet is a Line2 or Line3 edge `x(s) = sum_a N_a(s) x_a`, `s in [-1, 1]`, ordered
//! counter-clockwise around its cell, so its outward normal is `n = [x'_y, -x'_x] / |x'|`.
//!
//! * Closest point of `p`: the root of `(x(s) - p) . x'(s) = 0` (closed form on Line2, Newton on
//!   Line3); the gap along the outward normal is `g = n(s) . (p - x(s))`.
//! * Ray projection (slave normals): the root of `(x(s) - p) x nu = 0` for a direction `nu`.
//! * Nodal weight of node `a`: `A_a = t int N_a |x'| ds` summed over the facets of the surface
//!   (for Line3: 1/6, 2/3, 1/6 of the length at vertex, mid, vertex).
//! * Nodal normal: the normalized sum over facets of `int N_a n |x'| ds`.

use crate::fe::EdgeKind;
use crate::mesh::Facet;
use crate::model::Body;
use std::collections::BTreeMap;

/// The facets of one body's facet set, with per-node weights and normals.
#[derive(Clone, Debug)]
pub struct Surface {
    pub body: usize,
    pub kind: EdgeKind,
    /// Local node ids of each facet, in edge order `[start, end(, mid)]`.
    pub facets: Vec<Vec<usize>>,
    /// Reference coordinates of each facet's nodes.
    pub coords: Vec<Vec<[f64; 2]>>,
    /// Unique nodes of the surface with their weight (area) and unit normal.
    pub nodes: BTreeMap<usize, NodeData>,
}

#[derive(Copy, Clone, Debug, PartialEq)]
pub struct NodeData {
    pub area: f64,
    pub normal: [f64; 2],
}

/// Edge shape values `N`, derivatives `dN` at `s`.
pub fn edge_shape(kind: EdgeKind, s: f64) -> ([f64; 3], [f64; 3]) {
    let (mut n, mut dn) = ([0.0; 3], [0.0; 3]);
    let k = kind.node_count();
    kind.shape(s, &mut n[..k], &mut dn[..k]);
    (n, dn)
}

/// Position and tangent `x'(s)` of a facet.
pub fn facet_point(kind: EdgeKind, coords: &[[f64; 2]], s: f64) -> ([f64; 2], [f64; 2]) {
    let (n, dn) = edge_shape(kind, s);
    let mut x = [0.0; 2];
    let mut t = [0.0; 2];
    for (a, p) in coords.iter().enumerate() {
        for i in 0..2 {
            x[i] += n[a] * p[i];
            t[i] += dn[a] * p[i];
        }
    }
    (x, t)
}

pub fn unit_normal(t: [f64; 2]) -> [f64; 2] {
    let l = (t[0] * t[0] + t[1] * t[1]).sqrt();
    [t[1] / l, -t[0] / l]
}

/// Parameter of the closest point of the facet's curve to `p` (not clamped to [-1, 1]).
pub fn closest_point(kind: EdgeKind, coords: &[[f64; 2]], p: [f64; 2]) -> f64 {
    if kind == EdgeKind::Line2 {
        let (a, b) = (coords[0], coords[1]);
        let d = [b[0] - a[0], b[1] - a[1]];
        let t = ((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1]);
        return 2.0 * t - 1.0;
    }
    let mut s = 0.0;
    for _ in 0..50 {
        let (x, t) = facet_point(kind, coords, s);
        // x'' is constant on Line3: sum_a N_a'' x_a with N'' = [1, 1, -2]
        let ddx = [
            coords[0][0] + coords[1][0] - 2.0 * coords[2][0],
            coords[0][1] + coords[1][1] - 2.0 * coords[2][1],
        ];
        let f = (x[0] - p[0]) * t[0] + (x[1] - p[1]) * t[1];
        let df = t[0] * t[0] + t[1] * t[1] + (x[0] - p[0]) * ddx[0] + (x[1] - p[1]) * ddx[1];
        let ds = f / df;
        s -= ds;
        if ds.abs() < 1e-15 {
            break;
        }
    }
    s
}

/// Parameter where the ray `p + t nu` crosses the facet's curve (not clamped).
pub fn ray_point(kind: EdgeKind, coords: &[[f64; 2]], p: [f64; 2], nu: [f64; 2]) -> f64 {
    let cross = |a: [f64; 2], b: [f64; 2]| a[0] * b[1] - a[1] * b[0];
    let mut s = 0.0;
    for _ in 0..50 {
        let (x, t) = facet_point(kind, coords, s);
        let f = cross([x[0] - p[0], x[1] - p[1]], nu);
        let df = cross(t, nu);
        if df == 0.0 {
            return f64::NAN;
        }
        let ds = f / df;
        s -= ds;
        if ds.abs() < 1e-15 {
            break;
        }
    }
    s
}

impl Surface {
    /// The surface of facet set `facets` of `body` (index `body_index`), thickness `t`.
    pub fn new(body_index: usize, body: &Body, facets: &[Facet], thickness: f64) -> Surface {
        let kind = body.mesh.kind.edge_kind();
        let (nodes, coords) = facets
            .iter()
            .map(|&f| {
                let nodes = body.mesh.facet_nodes(f);
                let coords: Vec<[f64; 2]> = nodes.iter().map(|&n| body.mesh.nodes[n]).collect();
                (nodes, coords)
            })
            .unzip();
        Surface::from_facets(body_index, kind, nodes, coords, thickness)
    }

    /// The surface of facets given by their node ids and positions (edge order), with the
    /// nodal weights and normals computed from them.
    pub fn from_facets(
        body_index: usize,
        kind: EdgeKind,
        facet_nodes: Vec<Vec<usize>>,
        facet_coords: Vec<Vec<[f64; 2]>>,
        thickness: f64,
    ) -> Surface {
        let mut out = Surface {
            body: body_index,
            kind,
            facets: Vec::new(),
            coords: Vec::new(),
            nodes: BTreeMap::new(),
        };
        let mut sums: BTreeMap<usize, (f64, [f64; 2])> = BTreeMap::new();
        let k = kind.node_count();
        for (nodes, coords) in facet_nodes.into_iter().zip(facet_coords) {
            for (s, w) in kind.load_rule() {
                let (n, _) = edge_shape(kind, s);
                let (_, t) = facet_point(kind, &coords, s);
                let len = (t[0] * t[0] + t[1] * t[1]).sqrt();
                let normal = unit_normal(t);
                for a in 0..k {
                    let e = sums.entry(nodes[a]).or_insert((0.0, [0.0; 2]));
                    e.0 += w * n[a] * len * thickness;
                    e.1[0] += w * n[a] * len * normal[0];
                    e.1[1] += w * n[a] * len * normal[1];
                }
            }
            out.facets.push(nodes);
            out.coords.push(coords);
        }
        for (node, (area, n)) in sums {
            let l = (n[0] * n[0] + n[1] * n[1]).sqrt();
            let normal = if l > 0.0 {
                [n[0] / l, n[1] / l]
            } else {
                [0.0, 0.0]
            };
            out.nodes.insert(node, NodeData { area, normal });
        }
        out
    }

    /// Bounding boxes of the facets (for the search).
    pub fn boxes(&self) -> Vec<[[f64; 2]; 2]> {
        self.coords
            .iter()
            .map(|c| {
                let mut lo = [f64::INFINITY; 2];
                let mut hi = [f64::NEG_INFINITY; 2];
                for p in c {
                    for i in 0..2 {
                        lo[i] = lo[i].min(p[i]);
                        hi[i] = hi[i].max(p[i]);
                    }
                }
                [lo, hi]
            })
            .collect()
    }

    /// Largest facet length (chord).
    pub fn facet_size(&self) -> f64 {
        self.coords
            .iter()
            .map(|c| ((c[1][0] - c[0][0]).powi(2) + (c[1][1] - c[0][1]).powi(2)).sqrt())
            .fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projections_on_a_curved_line3() {
        // a parabola arc: x(s) = [s, 0.2 (1 - s^2)], nodes at s = -1, 1, 0
        let coords = [[-1.0, 0.0], [1.0, 0.0], [0.0, 0.2]];
        let p = [0.3, 0.9];
        let s = closest_point(EdgeKind::Line3, &coords, p);
        let (x, t) = facet_point(EdgeKind::Line3, &coords, s);
        assert!(((x[0] - p[0]) * t[0] + (x[1] - p[1]) * t[1]).abs() < 1e-13);
        let nu = [0.1, -1.0];
        let s = ray_point(EdgeKind::Line3, &coords, p, nu);
        let (x, _) = facet_point(EdgeKind::Line3, &coords, s);
        assert!(((x[0] - p[0]) * nu[1] - (x[1] - p[1]) * nu[0]).abs() < 1e-13);
        // Line2 closed form
        let s = closest_point(EdgeKind::Line2, &[[0.0, 0.0], [2.0, 0.0]], [1.5, 3.0]);
        assert!((s - 0.5).abs() < 1e-15);
    }
}
