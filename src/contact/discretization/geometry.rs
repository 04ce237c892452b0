//! Surface geometry in the reference configuration, in 2D and 3D from one code path: facets,
//! closest-point projection (2D here, 3D in [`super::facet_projection`]), normals and nodal
//! weights.
//!
//! A facet is a reference element of dimension `D - 1` mapped into `D` dimensions,
//! `x(s) = sum_a N_a(s) x_a` ([`FacetShape`]): a Line2 or Line3 edge in 2D (`s in [-1, 1]`,
//! ordered counter-clockwise around its cell), a Quad4, Quad9, Tri3 or Tri6 face in 3D (the
//! 2D elements Q4, Q9, T3, T6 of [`crate::fe`], corners counter-clockwise seen from outside).
//! With the tangents `t_k = dx/ds_k`, the outward normal scaled by the area element is
//! `n dA/ds = [t_y, -t_x]` (an edge, `dA = |x'| ds`) or `t_1 x t_2` (a face).
//!
//! * Closest point of `p` on a 2D edge: the root of `(x(s) - p) . x'(s) = 0` (closed form on
//!   Line2, Newton on Line3); the gap along the outward normal is `g = n(s) . (p - x(s))`.
//! * Ray projection (slave normals, 2D): the root of `(x(s) - p) x nu = 0` for a direction `nu`.
//! * Nodal weight of node `a`: `A_a = t int M_a dA` summed over the facets of the surface
//!   (`t` the thickness in 2D, 1 in 3D), and nodal normal: the normalized sum over facets of
//!   `int M_a n dA`, both by the rule of [`FacetShape::surface_rule`]. `M_a` is the facet's
//!   own shape function `N_a` (for Line3: 1/6, 2/3, 1/6 of the length at vertex, mid, vertex;
//!   for a flat Quad9: `h^2 (1/36, 1/9, 4/9)` at corner, mid-side, centre), except on Tri6,
//!   where `int N_a dA = 0` at the corners, so a corner node would get no weight and no normal
//!   from a flat face. There `M_a` is the **modified basis** of Popp, Gee and Wall (Int. J.
//!   Numer. Meth. Engng 79 (2009) 1354-1391, eq. 43; Wohlmuth, Acta Numerica 2011):
//!   `M_corner = N_corner + alpha (N_edge + N_edge')` over its two edges,
//!   `M_edge = (1 - 2 alpha) N_edge`, `alpha = 1/5`; it is still a partition of unity and
//!   gives a flat triangle of area `A` the weights `2 A / 15` (corner) and `A / 5` (mid-edge).
//!   The facet's geometry (the gap, the projection, the row's `-N_a n`) keeps the standard
//!   `N_a`.
//!
//! 2D results are bit-identical to the former 2D-only code: the same shape values, rules and
//! operations in the same order.

use crate::fe::{gauss_square, triangle_rule, EdgeKind, ElementKind};
use crate::fe3d::SolidKind;
use crate::mesh::{Facet, Mesh3};
use crate::model::Body;
use std::collections::BTreeMap;

/// Largest number of nodes of a facet (Quad9).
pub const MAX_FACET_NODES: usize = 9;

/// The modified-basis coefficient `alpha` of Tri6 nodal weights and normals (module notes).
pub const TRI6_MODIFIED_ALPHA: f64 = 0.2;

/// A facet's reference element seen as a surface in `D` dimensions: its shape functions on
/// natural coordinates `s` (one used for edges, `s[1] = 0`; two for faces), the basis of its
/// nodal weights, a quadrature rule over it and its scaled outward normal.
pub trait FacetShape<const D: usize>: Copy + std::fmt::Debug + PartialEq {
    /// Number of natural coordinates: 1 for edges, 2 for faces.
    const PARAMETERS: usize;
    fn node_count(self) -> usize;
    /// Number of corner nodes (they come first).
    fn corner_count(self) -> usize;
    /// Shape functions `n[a]` and natural derivatives `dn[a][k] = dN_a/ds_k` (`k <
    /// PARAMETERS`; the others are 0).
    fn shape(self, s: [f64; 2], n: &mut [f64], dn: &mut [[f64; 2]]);
    /// The basis `M_a` whose integrals are the nodal weights and normals (module notes).
    fn weight_basis(self, s: [f64; 2], m: &mut [f64]) {
        let mut dn = [[0.0; 2]; MAX_FACET_NODES];
        self.shape(s, m, &mut dn[..m.len()]);
    }
    /// Quadrature points and weights on the reference facet for nodal weights and normals.
    fn surface_rule(self) -> Vec<([f64; 2], f64)>;
    /// The outward normal times the area element, `n dA/ds`, from the tangents `t_k = dx/ds_k`.
    fn scaled_normal(tangents: [[f64; D]; 2]) -> [f64; D];
}

impl FacetShape<2> for EdgeKind {
    const PARAMETERS: usize = 1;
    fn node_count(self) -> usize {
        EdgeKind::node_count(self)
    }
    fn corner_count(self) -> usize {
        2
    }
    fn shape(self, s: [f64; 2], n: &mut [f64], dn: &mut [[f64; 2]]) {
        let mut d = [0.0; 3];
        let k = EdgeKind::node_count(self);
        EdgeKind::shape(self, s[0], n, &mut d[..k]);
        for a in 0..k {
            dn[a] = [d[a], 0.0];
        }
    }
    fn weight_basis(self, s: [f64; 2], m: &mut [f64]) {
        let mut d = [0.0; 3];
        let k = EdgeKind::node_count(self);
        EdgeKind::shape(self, s[0], m, &mut d[..k]);
    }
    fn surface_rule(self) -> Vec<([f64; 2], f64)> {
        self.load_rule()
            .into_iter()
            .map(|(s, w)| ([s, 0.0], w))
            .collect()
    }
    fn scaled_normal(t: [[f64; 2]; 2]) -> [f64; 2] {
        [t[0][1], -t[0][0]]
    }
}

impl FacetShape<3> for ElementKind {
    const PARAMETERS: usize = 2;
    fn node_count(self) -> usize {
        ElementKind::node_count(self)
    }
    fn corner_count(self) -> usize {
        ElementKind::corner_count(self)
    }
    fn shape(self, s: [f64; 2], n: &mut [f64], dn: &mut [[f64; 2]]) {
        ElementKind::shape(self, s, n, dn)
    }
    fn weight_basis(self, s: [f64; 2], m: &mut [f64]) {
        let mut dn = [[0.0; 2]; MAX_FACET_NODES];
        ElementKind::shape(self, s, m, &mut dn[..m.len()]);
        if self == ElementKind::T6 {
            // corners 0, 1, 2; mid-edge 3 (0-1), 4 (1-2), 5 (2-0)
            let a = TRI6_MODIFIED_ALPHA;
            let (m3, m4, m5) = (m[3], m[4], m[5]);
            m[0] += a * (m3 + m5);
            m[1] += a * (m3 + m4);
            m[2] += a * (m4 + m5);
            for v in &mut m[3..6] {
                *v *= 1.0 - 2.0 * a;
            }
        }
    }
    fn surface_rule(self) -> Vec<([f64; 2], f64)> {
        // exact for M_a dA on flat facets (dA of degree (1,1), (2,2), 0, 2)
        let rule = match self {
            ElementKind::Q4 => gauss_square(3),
            ElementKind::Q9 => gauss_square(4),
            ElementKind::T3 => triangle_rule(2),
            ElementKind::T6 => triangle_rule(5),
        };
        rule.into_iter().map(|q| (q.xi, q.weight)).collect()
    }
    fn scaled_normal(t: [[f64; 3]; 2]) -> [f64; 3] {
        cross(t[0], t[1])
    }
}

/// `a x b`.
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `a . b`.
pub fn dot<const D: usize>(a: [f64; D], b: [f64; D]) -> f64 {
    (0..D).map(|i| a[i] * b[i]).sum()
}

/// Position and tangents `[dx/ds_1, dx/ds_2]` of a facet at natural point `s` (the second
/// tangent is zero on an edge).
pub fn facet_frame<const D: usize, K: FacetShape<D>>(
    kind: K,
    coords: &[[f64; D]],
    s: [f64; 2],
) -> ([f64; D], [[f64; D]; 2]) {
    let mut n = [0.0; MAX_FACET_NODES];
    let mut dn = [[0.0; 2]; MAX_FACET_NODES];
    let k = kind.node_count();
    kind.shape(s, &mut n[..k], &mut dn[..k]);
    let mut x = [0.0; D];
    let mut t = [[0.0; D]; 2];
    for (a, p) in coords.iter().enumerate() {
        for i in 0..D {
            x[i] += n[a] * p[i];
            for (j, tj) in t.iter_mut().enumerate() {
                tj[i] += dn[a][j] * p[i];
            }
        }
    }
    (x, t)
}

/// The facets of one body's facet set, with per-node weights and normals, in `D` dimensions
/// (`Surface` alone is the 2D surface of edges; [`Surface3`] the 3D one of faces).
#[derive(Clone, Debug)]
pub struct Surface<const D: usize = 2, K = EdgeKind> {
    pub body: usize,
    pub kind: K,
    /// Local node ids of each facet, in the facet element's node order (2D edges:
    /// `[start, end(, mid)]`).
    pub facets: Vec<Vec<usize>>,
    /// Reference coordinates of each facet's nodes.
    pub coords: Vec<Vec<[f64; D]>>,
    /// Unique nodes of the surface with their weight (area) and unit normal.
    pub nodes: BTreeMap<usize, NodeData<D>>,
    /// Each facet's share of its nodes' weights, `t int M_a dA` over that facet alone (facet
    /// node order); a node's `area` is the sum of its shares over the facets that hold it.
    pub facet_weights: Vec<Vec<f64>>,
    /// The same by node: `(facet, share)` over the facets that hold it ([`Surface::tributaries`]).
    node_tributaries: BTreeMap<usize, Vec<(usize, f64)>>,
}

/// A 3D surface of Quad4, Quad9, Tri3 or Tri6 faces.
pub type Surface3 = Surface<3, ElementKind>;

#[derive(Copy, Clone, Debug, PartialEq)]
pub struct NodeData<const D: usize = 2> {
    pub area: f64,
    pub normal: [f64; D],
    /// Reference position of the node.
    pub position: [f64; D],
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
        Surface::of_body(body_index, body, facets, thickness, None)
    }
}

impl Surface3 {
    /// The surface of facet set `facets` of the 3D mesh `mesh` of body `body_index` (e.g. a
    /// named set of [`crate::mesh::block3`], `mesh.facet_sets["top"]`).
    pub fn from_solid_mesh(body_index: usize, mesh: &Mesh3, facets: &[Facet]) -> Surface3 {
        let kind = SolidKind::facet_kind(mesh.kind);
        let (nodes, coords) = facets
            .iter()
            .map(|&f| {
                let nodes = mesh.facet_nodes(f);
                let coords: Vec<[f64; 3]> = nodes.iter().map(|&n| mesh.nodes[n]).collect();
                (nodes, coords)
            })
            .unzip();
        Surface::from_facets(body_index, kind, nodes, coords, 1.0)
    }
}

impl<const D: usize, F: FacetShape<D>> Surface<D, F> {
    /// The surface of facet set `facets` of `body` (index `body_index`) in any dimension, its
    /// nodes at `X + u` when the displacement `u` is given (the configuration of contact rows
    /// in the current geometry), its weights times `thickness` (1 in 3D).
    pub fn of_body<K: super::Discretize<D, Facet = F>>(
        body_index: usize,
        body: &Body<D, K>,
        facets: &[Facet],
        thickness: f64,
        u: Option<&[f64]>,
    ) -> Self {
        let mesh = &body.mesh;
        let (nodes, coords) = facets
            .iter()
            .map(|&f| {
                let nodes = mesh.facet_nodes(f);
                let coords: Vec<[f64; D]> = nodes
                    .iter()
                    .map(|&n| {
                        let x = mesh.nodes[n];
                        match u {
                            Some(u) => std::array::from_fn(|i| x[i] + u[body.dof(n, i)]),
                            None => x,
                        }
                    })
                    .collect();
                (nodes, coords)
            })
            .unzip();
        Surface::from_facets(
            body_index,
            mesh.kind.facet_shape(),
            nodes,
            coords,
            thickness,
        )
    }
}

impl<const D: usize, K> Surface<D, K> {
    /// The whole tributary of `node` facet by facet: `(facet, t int M_a dA)` over each facet of
    /// the surface that holds it (`facet` an index into [`Surface::facets`]).
    pub fn tributaries(&self, node: usize) -> Vec<(usize, f64)> {
        self.node_tributaries
            .get(&node)
            .cloned()
            .unwrap_or_default()
    }
}

impl<const D: usize, K: FacetShape<D>> Surface<D, K> {
    /// The surface of facets given by their node ids and positions (facet node order), with
    /// the nodal weights and normals computed from them; `thickness` multiplies the weights
    /// (the out-of-plane thickness in 2D, 1 in 3D).
    pub fn from_facets(
        body_index: usize,
        kind: K,
        facet_nodes: Vec<Vec<usize>>,
        facet_coords: Vec<Vec<[f64; D]>>,
        thickness: f64,
    ) -> Self {
        let mut out = Surface {
            body: body_index,
            kind,
            facets: Vec::new(),
            coords: Vec::new(),
            nodes: BTreeMap::new(),
            facet_weights: Vec::new(),
            node_tributaries: BTreeMap::new(),
        };
        let mut sums: BTreeMap<usize, (f64, [f64; D], [f64; D])> = BTreeMap::new();
        let k = kind.node_count();
        let rule = kind.surface_rule();
        for (nodes, coords) in facet_nodes.into_iter().zip(facet_coords) {
            let mut shares = vec![0.0; k];
            for &(s, w) in &rule {
                let mut m = [0.0; MAX_FACET_NODES];
                kind.weight_basis(s, &mut m[..k]);
                let (_, t) = facet_frame(kind, &coords, s);
                let scaled = K::scaled_normal(t);
                let len = dot(scaled, scaled).sqrt();
                let normal = scaled.map(|c| c / len);
                for a in 0..k {
                    let e = sums.entry(nodes[a]).or_insert((0.0, [0.0; D], coords[a]));
                    e.0 += w * m[a] * len * thickness;
                    shares[a] += w * m[a] * len * thickness;
                    for i in 0..D {
                        e.1[i] += w * m[a] * len * normal[i];
                    }
                }
            }
            for (&node, &share) in nodes.iter().zip(&shares) {
                out.node_tributaries
                    .entry(node)
                    .or_default()
                    .push((out.facets.len(), share));
            }
            out.facets.push(nodes);
            out.coords.push(coords);
            out.facet_weights.push(shares);
        }
        for (node, (area, n, position)) in sums {
            let l = dot(n, n).sqrt();
            let normal = if l > 0.0 { n.map(|c| c / l) } else { [0.0; D] };
            out.nodes.insert(
                node,
                NodeData {
                    area,
                    normal,
                    position,
                },
            );
        }
        out
    }

    /// Bounding boxes of the facets (for the search).
    pub fn boxes(&self) -> Vec<[[f64; D]; 2]> {
        self.coords
            .iter()
            .map(|c| {
                let mut lo = [f64::INFINITY; D];
                let mut hi = [f64::NEG_INFINITY; D];
                for p in c {
                    for i in 0..D {
                        lo[i] = lo[i].min(p[i]);
                        hi[i] = hi[i].max(p[i]);
                    }
                }
                [lo, hi]
            })
            .collect()
    }

    /// Largest facet size: the longest chord between two corners of a facet.
    pub fn facet_size(&self) -> f64 {
        let corners = self.kind.corner_count();
        self.coords
            .iter()
            .flat_map(|c| {
                (0..corners).flat_map(move |a| {
                    (a + 1..corners).map(move |b| {
                        (0..D)
                            .map(|i| (c[b][i] - c[a][i]).powi(2))
                            .sum::<f64>()
                            .sqrt()
                    })
                })
            })
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

    use crate::fe3d::SolidKind;
    use crate::mesh::block3;

    /// A block's top surface (flat, at z = 0.5) with an interior vertex moved within it.
    fn flat_top(kind: SolidKind) -> Surface3 {
        let b = [0.0, 0.4, 1.1, 2.0];
        let mesh = block3(
            kind,
            &b,
            &[0.0, 0.5, 1.5],
            &[0.0, 0.5],
            &[([0.4, 0.5, 0.5], [0.55, 0.65, 0.5])],
        )
        .unwrap();
        Surface3::from_solid_mesh(0, &mesh, &mesh.facet_sets["top"])
    }

    #[test]
    fn nodal_weights_sum_to_the_area_and_flat_normals_are_the_plane_s() {
        for kind in SolidKind::ALL {
            let top = flat_top(kind);
            let area: f64 = top.nodes.values().map(|d| d.area).sum();
            assert!(
                (area - 3.0).abs() < 1e-13,
                "{kind:?}: weights sum to {area}, not 2 x 1.5"
            );
            for (node, d) in &top.nodes {
                assert!(d.area > 0.0, "{kind:?} node {node}: weight {}", d.area);
                let e = [d.normal[0], d.normal[1], d.normal[2] - 1.0];
                assert!(
                    dot(e, e).sqrt() < 1e-14,
                    "{kind:?} node {node}: {:?}",
                    d.normal
                );
            }
        }
        // 2D: the thickness multiplies the weights; an edge's normal is the turned tangent
        let edge = Surface::from_facets(
            0,
            EdgeKind::Line3,
            vec![vec![0, 1, 2]],
            vec![vec![[0.0, 0.0], [2.0, 0.0], [1.0, 0.0]]],
            0.5,
        );
        assert!((edge.nodes[&2].area - 2.0 * 0.5 * 2.0 / 3.0).abs() < 1e-15);
        assert_eq!(edge.nodes[&0].normal, [0.0, -1.0]);
    }

    #[test]
    fn single_facet_weights_have_their_closed_forms() {
        // Quad9 on a square of side h: h^2 (1/36, 1/9, 4/9) at corners, mid-sides, centre
        let h = 1.5;
        let square: Vec<[f64; 3]> = crate::fe::ElementKind::Q9
            .node_coordinates()
            .iter()
            .map(|c| [0.5 * h * (c[0] + 1.0), 0.5 * h * (c[1] + 1.0), 0.2])
            .collect();
        let s = Surface::from_facets(
            0,
            ElementKind::Q9,
            vec![(0..9).collect()],
            vec![square],
            1.0,
        );
        for (a, expected) in [(0, 1.0 / 36.0), (4, 1.0 / 9.0), (8, 4.0 / 9.0)] {
            assert!(
                (s.nodes[&a].area - expected * h * h).abs() < 1e-15,
                "Quad9 node {a}"
            );
        }
        // Tri6 with the modified basis: 2A/15 at corners, A/5 at mid-edges (A = area)
        let tri: Vec<[f64; 3]> = [
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.5, 1.5, 0.0],
            [1.0, 0.0, 0.0],
            [1.25, 0.75, 0.0],
            [0.25, 0.75, 0.0],
        ]
        .to_vec();
        let a = 0.5 * 2.0 * 1.5;
        let s = Surface::from_facets(0, ElementKind::T6, vec![(0..6).collect()], vec![tri], 1.0);
        for node in 0..3 {
            assert!((s.nodes[&node].area - 2.0 * a / 15.0).abs() < 1e-15);
            assert!((s.nodes[&(node + 3)].area - a / 5.0).abs() < 1e-15);
            assert_eq!(s.nodes[&node].normal, [0.0, 0.0, 1.0]);
        }
    }

    /// The maximum angle between the nodal normal and the radial direction over the interior
    /// nodes of a cube-sphere patch (a block's top face, `n` cells a side, projected onto the
    /// sphere of radius 2 about the origin).
    fn sphere_normal_error(kind: SolidKind, n: usize) -> f64 {
        let b: Vec<f64> = (0..=n).map(|i| -0.6 + 1.2 * i as f64 / n as f64).collect();
        let mesh = block3(kind, &b, &b, &[0.0, 1.0], &[]).unwrap();
        let facets = &mesh.facet_sets["top"];
        let radial = |p: [f64; 3]| p.map(|c| c / dot(p, p).sqrt());
        let (nodes, coords): (Vec<Vec<usize>>, Vec<Vec<[f64; 3]>>) = facets
            .iter()
            .map(|&f| {
                let nodes = mesh.facet_nodes(f);
                let coords = nodes
                    .iter()
                    .map(|&k| radial(mesh.nodes[k]).map(|c| 2.0 * c))
                    .collect();
                (nodes, coords)
            })
            .unzip();
        let surface = Surface::from_facets(0, SolidKind::facet_kind(kind), nodes, coords, 1.0);
        surface
            .nodes
            .values()
            .filter(|d| d.position[0].abs() < 0.5 && d.position[1].abs() < 0.5)
            .map(|d| {
                let r = radial(d.position);
                let c = cross(r, d.normal);
                dot(c, c).sqrt().asin()
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn nodal_normals_of_a_sphere_converge_to_the_radial_direction() {
        for kind in SolidKind::ALL {
            let coarse = sphere_normal_error(kind, 6);
            let fine = sphere_normal_error(kind, 12);
            let order = (coarse / fine).log2();
            println!("{kind:?}: {coarse:.3e} -> {fine:.3e}, order {order:.2}");
            assert!(
                fine < coarse && order > 1.0,
                "{kind:?}: {coarse:.3e} -> {fine:.3e}"
            );
        }
    }
}
