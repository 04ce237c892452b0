//! Reference finite elements and quadrature.
//!
//! Isoparametric Lagrange elements on the reference square `[-1,1]^2` (Q4, Q9) and the reference
//! triangle `{xi, eta >= 0, xi + eta <= 1}` (T3, T6): the geometry and the displacement share the
//! shape functions `N_a`, so `x(xi) = sum_a N_a(xi) x_a` and `u(xi) = sum_a N_a(xi) u_a`.
//! Isoparametric elements reproduce every linear field exactly on any non-inverted mesh, which is
//! what makes the (single-body) patch test pass on distorted meshes.
//!
//! Node ordering (the same as VTK's `QUAD`, `BIQUADRATIC_QUAD`, `TRIANGLE`, `QUADRATIC_TRIANGLE`):
//! corners counter-clockwise, then mid-side nodes (side `i` joins corner `i` and corner `i+1`),
//! then the Q9 centre node.
//!
//! Quadrature for the stiffness: Gauss 2x2 (Q4), 3x3 (Q9), 1 point (T3), 3 points of degree 2 (T6).
//! These integrate `B^T D B det J` exactly on straight-sided (affine) triangles and integrate the
//! divergence identity behind the patch test exactly on distorted quadrilaterals (`dN/dx det J` is a
//! polynomial of degree (1,1) for Q4 and (3,3) for Q9). Error norms use richer rules.
//!
//! Edges (facets) are `Line2` (nodes at s = -1, +1) or `Line3` (nodes at s = -1, +1, 0), ordered
//! counter-clockwise around their element, so the outward normal is the tangent turned clockwise.
//!
//! **Dimension seam.** [`ReferenceCell<D>`] is what meshes, named sets and output need of a
//! reference cell in `D` dimensions (node count, corners, facets as local node lists, natural
//! node coordinates, shape functions, VTK type); [`QuadPoint<D>`] is a quadrature point in `D`
//! natural coordinates (`D = 2` by default, so the 2D code reads as before). The 2D kinds here
//! implement it for `D = 2` and the solid kinds of [`crate::fe3d`] for `D = 3`; the 2D facets
//! of a solid (Quad4, Quad9, Tri3, Tri6) are the 2D reference elements Q4, Q9, T3, T6 of this
//! module. Code written against the trait (e.g. [`crate::mesh::Mesh`]) serves both dimensions.

use nalgebra::SMatrix;
use serde::{Deserialize, Serialize};

/// A reference element type.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, schemars::JsonSchema)]
pub enum ElementKind {
    Q4,
    Q9,
    T3,
    T6,
}

/// A reference edge type.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, schemars::JsonSchema)]
pub enum EdgeKind {
    Line2,
    Line3,
}

/// A quadrature point on a reference cell: natural coordinates and weight.
#[derive(Copy, Clone, Debug)]
pub struct QuadPoint<const D: usize = 2> {
    pub xi: [f64; D],
    pub weight: f64,
}

/// The dimension seam (see the module docs): a reference cell in `D` natural coordinates.
pub trait ReferenceCell<const D: usize>: Copy + std::fmt::Debug + PartialEq {
    /// Number of nodes.
    fn node_count(self) -> usize;
    /// Number of corner (vertex) nodes; they come first in the node list.
    fn corner_count(self) -> usize;
    /// Whether the cell's shape functions are quadratic.
    fn is_quadratic(self) -> bool;
    /// Local nodes of each facet, corners first, ordered so that the facet's own
    /// parametrisation gives the outward normal (counter-clockwise seen from outside).
    fn facets(self) -> &'static [&'static [usize]];
    /// Number of corners of facet `k`; its first nodes, which identify it.
    fn facet_corner_count(self, k: usize) -> usize;
    /// Natural coordinates of the nodes, in node order.
    fn node_coordinates(self) -> &'static [[f64; D]];
    /// Shape functions `n[a]` and their natural derivatives `dn[a][k] = dN_a/dxi_k` at `xi`.
    fn shape(self, xi: [f64; D], n: &mut [f64], dn: &mut [[f64; D]]);
    /// VTK cell type id.
    fn vtk_cell_type(self) -> u8;
    /// The geometry at a natural point, [`PointValues`] with the node capacity of the cell
    /// family (the most nodes one of its cells has).
    type PointValues: PointGeometry<D>;
    /// Shape values, Cartesian gradients and `det J` at `xi` of the cell with nodes `coords`
    /// (element order): [`point_values`] with the family's capacity.
    fn point_values(self, coords: &[[f64; D]], xi: [f64; D]) -> Self::PointValues;
}

impl ReferenceCell<2> for ElementKind {
    fn node_count(self) -> usize {
        ElementKind::node_count(self)
    }
    fn corner_count(self) -> usize {
        ElementKind::corner_count(self)
    }
    fn is_quadratic(self) -> bool {
        ElementKind::is_quadratic(self)
    }
    fn facets(self) -> &'static [&'static [usize]] {
        self.edges()
    }
    fn facet_corner_count(self, _k: usize) -> usize {
        2
    }
    fn node_coordinates(self) -> &'static [[f64; 2]] {
        ElementKind::node_coordinates(self)
    }
    fn shape(self, xi: [f64; 2], n: &mut [f64], dn: &mut [[f64; 2]]) {
        ElementKind::shape(self, xi, n, dn)
    }
    fn vtk_cell_type(self) -> u8 {
        ElementKind::vtk_cell_type(self)
    }
    type PointValues = PointValues<2, MAX_NODES>;
    fn point_values(self, coords: &[[f64; 2]], xi: [f64; 2]) -> PointValues {
        point_values(self, coords, xi)
    }
}

const Q4_EDGES: [&[usize]; 4] = [&[0, 1], &[1, 2], &[2, 3], &[3, 0]];
const Q9_EDGES: [&[usize]; 4] = [&[0, 1, 4], &[1, 2, 5], &[2, 3, 6], &[3, 0, 7]];
const T3_EDGES: [&[usize]; 3] = [&[0, 1], &[1, 2], &[2, 0]];
const T6_EDGES: [&[usize]; 3] = [&[0, 1, 3], &[1, 2, 4], &[2, 0, 5]];

/// Natural coordinates of the nodes of each element (same order as the shape functions).
const Q4_NODES: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
const Q9_NODES: [[f64; 2]; 9] = [
    [-1.0, -1.0],
    [1.0, -1.0],
    [1.0, 1.0],
    [-1.0, 1.0],
    [0.0, -1.0],
    [1.0, 0.0],
    [0.0, 1.0],
    [-1.0, 0.0],
    [0.0, 0.0],
];
const T3_NODES: [[f64; 2]; 3] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
const T6_NODES: [[f64; 2]; 6] = [
    [0.0, 0.0],
    [1.0, 0.0],
    [0.0, 1.0],
    [0.5, 0.0],
    [0.5, 0.5],
    [0.0, 0.5],
];

/// Largest number of nodes of any element; sizes stack buffers.
pub const MAX_NODES: usize = 9;

impl ElementKind {
    pub fn node_count(self) -> usize {
        match self {
            ElementKind::Q4 => 4,
            ElementKind::Q9 => 9,
            ElementKind::T3 => 3,
            ElementKind::T6 => 6,
        }
    }

    /// Number of corner (vertex) nodes; they come first in the node list.
    pub fn corner_count(self) -> usize {
        match self {
            ElementKind::Q4 | ElementKind::Q9 => 4,
            ElementKind::T3 | ElementKind::T6 => 3,
        }
    }

    pub fn is_quadratic(self) -> bool {
        matches!(self, ElementKind::Q9 | ElementKind::T6)
    }

    pub fn edge_kind(self) -> EdgeKind {
        if self.is_quadratic() {
            EdgeKind::Line3
        } else {
            EdgeKind::Line2
        }
    }

    /// Local node indices of each edge, counter-clockwise: `[start, end]` or `[start, end, mid]`.
    pub fn edges(self) -> &'static [&'static [usize]] {
        match self {
            ElementKind::Q4 => &Q4_EDGES,
            ElementKind::Q9 => &Q9_EDGES,
            ElementKind::T3 => &T3_EDGES,
            ElementKind::T6 => &T6_EDGES,
        }
    }

    /// Natural coordinates of the element's nodes.
    pub fn node_coordinates(self) -> &'static [[f64; 2]] {
        match self {
            ElementKind::Q4 => &Q4_NODES,
            ElementKind::Q9 => &Q9_NODES,
            ElementKind::T3 => &T3_NODES,
            ElementKind::T6 => &T6_NODES,
        }
    }

    /// Natural coordinates of the element centre.
    pub fn centre(self) -> [f64; 2] {
        match self {
            ElementKind::Q4 | ElementKind::Q9 => [0.0, 0.0],
            ElementKind::T3 | ElementKind::T6 => [1.0 / 3.0, 1.0 / 3.0],
        }
    }

    /// VTK cell type id.
    pub fn vtk_cell_type(self) -> u8 {
        match self {
            ElementKind::Q4 => 9,
            ElementKind::Q9 => 28,
            ElementKind::T3 => 5,
            ElementKind::T6 => 22,
        }
    }

    /// Shape functions `n[a]` and their natural derivatives `dn[a] = [dN_a/dxi, dN_a/deta]`.
    pub fn shape(self, xi: [f64; 2], n: &mut [f64], dn: &mut [[f64; 2]]) {
        let [s, t] = xi;
        match self {
            ElementKind::Q4 => {
                for (a, c) in Q4_NODES.iter().enumerate() {
                    n[a] = 0.25 * (1.0 + c[0] * s) * (1.0 + c[1] * t);
                    dn[a] = [
                        0.25 * c[0] * (1.0 + c[1] * t),
                        0.25 * c[1] * (1.0 + c[0] * s),
                    ];
                }
            }
            ElementKind::Q9 => {
                for (a, c) in Q9_NODES.iter().enumerate() {
                    let (ls, dls) = lagrange_1d_quadratic(c[0], s);
                    let (lt, dlt) = lagrange_1d_quadratic(c[1], t);
                    n[a] = ls * lt;
                    dn[a] = [dls * lt, ls * dlt];
                }
            }
            ElementKind::T3 => {
                n[0] = 1.0 - s - t;
                n[1] = s;
                n[2] = t;
                dn[0] = [-1.0, -1.0];
                dn[1] = [1.0, 0.0];
                dn[2] = [0.0, 1.0];
            }
            ElementKind::T6 => {
                let l1 = 1.0 - s - t;
                let (l2, l3) = (s, t);
                // d(l1, l2, l3)/d(s, t)
                let d1 = [-1.0, -1.0];
                let d2 = [1.0, 0.0];
                let d3 = [0.0, 1.0];
                let corner = |l: f64, d: [f64; 2]| {
                    (
                        l * (2.0 * l - 1.0),
                        [(4.0 * l - 1.0) * d[0], (4.0 * l - 1.0) * d[1]],
                    )
                };
                let mid = |la: f64, da: [f64; 2], lb: f64, db: [f64; 2]| {
                    (
                        4.0 * la * lb,
                        [
                            4.0 * (da[0] * lb + la * db[0]),
                            4.0 * (da[1] * lb + la * db[1]),
                        ],
                    )
                };
                let vals = [
                    corner(l1, d1),
                    corner(l2, d2),
                    corner(l3, d3),
                    mid(l1, d1, l2, d2),
                    mid(l2, d2, l3, d3),
                    mid(l3, d3, l1, d1),
                ];
                for (a, (v, d)) in vals.into_iter().enumerate() {
                    n[a] = v;
                    dn[a] = d;
                }
            }
        }
    }

    /// Quadrature rule that integrates the stiffness of this element (see module docs).
    pub fn stiffness_rule(self) -> Vec<QuadPoint> {
        match self {
            ElementKind::Q4 => gauss_square(2),
            ElementKind::Q9 => gauss_square(3),
            ElementKind::T3 => triangle_rule(1),
            ElementKind::T6 => triangle_rule(2),
        }
    }

    /// A richer rule for error norms of smooth reference fields.
    pub fn error_rule(self) -> Vec<QuadPoint> {
        match self {
            ElementKind::Q4 | ElementKind::Q9 => gauss_square(5),
            ElementKind::T3 | ElementKind::T6 => triangle_rule(5),
        }
    }
}

impl EdgeKind {
    pub fn node_count(self) -> usize {
        match self {
            EdgeKind::Line2 => 2,
            EdgeKind::Line3 => 3,
        }
    }

    /// Shape functions on `s in [-1, 1]` and their derivatives; node order `[start, end(, mid)]`.
    pub fn shape(self, s: f64, n: &mut [f64], dn: &mut [f64]) {
        match self {
            EdgeKind::Line2 => {
                n[0] = 0.5 * (1.0 - s);
                n[1] = 0.5 * (1.0 + s);
                dn[0] = -0.5;
                dn[1] = 0.5;
            }
            EdgeKind::Line3 => {
                n[0] = 0.5 * s * (s - 1.0);
                n[1] = 0.5 * s * (s + 1.0);
                n[2] = 1.0 - s * s;
                dn[0] = s - 0.5;
                dn[1] = s + 0.5;
                dn[2] = -2.0 * s;
            }
        }
    }

    /// Gauss points that integrate the consistent load of a polynomial traction of degree `p`
    /// times the edge shape functions exactly on a straight edge.
    pub fn load_rule(self) -> Vec<(f64, f64)> {
        match self {
            EdgeKind::Line2 => gauss_legendre(3),
            EdgeKind::Line3 => gauss_legendre(4),
        }
    }
}

/// Value and derivative of the 1D quadratic Lagrange polynomial that is 1 at `node` (-1, 0 or 1).
pub(crate) fn lagrange_1d_quadratic(node: f64, s: f64) -> (f64, f64) {
    if node < -0.5 {
        (0.5 * s * (s - 1.0), s - 0.5)
    } else if node > 0.5 {
        (0.5 * s * (s + 1.0), s + 0.5)
    } else {
        (1.0 - s * s, -2.0 * s)
    }
}

/// Gauss-Legendre points and weights on `[-1, 1]`, by Newton iteration on `P_n`.
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    // the rules up to 16 points are computed once (the mortar segments and element loops ask
    // for them thousands of times)
    static RULES: std::sync::OnceLock<Vec<Vec<(f64, f64)>>> = std::sync::OnceLock::new();
    const CACHED: usize = 16;
    if (1..=CACHED).contains(&n) {
        let rules = RULES.get_or_init(|| {
            (0..=CACHED)
                .map(|k| compute_gauss_legendre(k.max(1)))
                .collect()
        });
        return rules[n].clone();
    }
    compute_gauss_legendre(n)
}

/// The `n`-point Gauss-Legendre rule by Newton iteration on the Legendre polynomial.
fn compute_gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    assert!(n >= 1, "a Gauss rule needs at least one point");
    let mut rule = Vec::with_capacity(n);
    for i in 0..n {
        // Chebyshev-like initial guess, then Newton on the Legendre polynomial.
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (p, d) = legendre_with_derivative(n, x);
            dp = d;
            let dx = p / d;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let (_, d) = legendre_with_derivative(n, x);
        dp = if d != 0.0 { d } else { dp };
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        rule.push((x, w));
    }
    rule.sort_by(|a, b| a.0.total_cmp(&b.0));
    rule
}

fn legendre_with_derivative(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    for k in 2..=n {
        let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
        p0 = p1;
        p1 = p2;
    }
    let p = if n == 0 { 1.0 } else { p1 };
    let d = n as f64 * (x * p - p0) / (x * x - 1.0);
    (p, d)
}

/// Tensor-product Gauss rule with `n x n` points on `[-1, 1]^2`.
pub fn gauss_square(n: usize) -> Vec<QuadPoint> {
    let g = gauss_legendre(n);
    let mut out = Vec::with_capacity(n * n);
    for &(y, wy) in &g {
        for &(x, wx) in &g {
            out.push(QuadPoint {
                xi: [x, y],
                weight: wx * wy,
            });
        }
    }
    out
}

/// Symmetric rules on the reference triangle (area 1/2) exact for polynomials of `degree`:
/// 1 (centroid), 2 (three interior points), 5 (Radon's seven points).
pub fn triangle_rule(degree: usize) -> Vec<QuadPoint> {
    let p = |a: f64, b: f64, w: f64| QuadPoint {
        xi: [a, b],
        weight: w,
    };
    match degree {
        0 | 1 => vec![p(1.0 / 3.0, 1.0 / 3.0, 0.5)],
        2 => {
            let w = 1.0 / 6.0;
            vec![
                p(1.0 / 6.0, 1.0 / 6.0, w),
                p(2.0 / 3.0, 1.0 / 6.0, w),
                p(1.0 / 6.0, 2.0 / 3.0, w),
            ]
        }
        _ => {
            let r15 = 15f64.sqrt();
            let (a1, b1) = ((6.0 - r15) / 21.0, (9.0 + 2.0 * r15) / 21.0);
            let (a2, b2) = ((6.0 + r15) / 21.0, (9.0 - 2.0 * r15) / 21.0);
            let (w1, w2) = ((155.0 - r15) / 2400.0, (155.0 + r15) / 2400.0);
            vec![
                p(1.0 / 3.0, 1.0 / 3.0, 9.0 / 80.0),
                p(a1, a1, w1),
                p(b1, a1, w1),
                p(a1, b1, w1),
                p(a2, a2, w2),
                p(b2, a2, w2),
                p(a2, b2, w2),
            ]
        }
    }
}

/// Geometry of a cell at one natural point: shape values `n`, Cartesian gradients `dndx`,
/// `det J` and the point `x`. `N` is the capacity of the node arrays (the most nodes a cell of
/// the family has: [`MAX_NODES`] in 2D, [`crate::fe3d::MAX_SOLID_NODES`] in 3D); the entries
/// past the cell's node count are zero.
#[derive(Clone, Debug)]
pub struct PointValues<const D: usize = 2, const N: usize = MAX_NODES> {
    pub n: [f64; N],
    pub dndx: [[f64; D]; N],
    pub det_j: f64,
    pub x: [f64; D],
}

/// What code generic over the cell reads of its [`PointValues`], whatever their capacity.
pub trait PointGeometry<const D: usize> {
    /// `det J`.
    fn jacobian_determinant(&self) -> f64;
    /// The point `x(xi)`.
    fn point(&self) -> [f64; D];
    /// The Cartesian gradients `dN_a/dx` (entries past the cell's node count zero).
    fn gradients(&self) -> &[[f64; D]];
    /// The shape values `N_a` (entries past the cell's node count zero).
    fn values(&self) -> &[f64];
}

impl<const D: usize, const N: usize> PointGeometry<D> for PointValues<D, N> {
    fn jacobian_determinant(&self) -> f64 {
        self.det_j
    }
    fn point(&self) -> [f64; D] {
        self.x
    }
    fn gradients(&self) -> &[[f64; D]] {
        &self.dndx
    }
    fn values(&self) -> &[f64] {
        &self.n
    }
}

/// `H_ik = sum_a u_a,i dN_a/dx_k`: the gradient of the field with nodal values `u_e` (`D` per
/// node, `[u_x0, u_y0, ...]`) from the gradients `dndx` of its nodes; with reference gradients
/// the displacement gradient `H = F - I`.
pub fn field_gradient<const D: usize>(dndx: &[[f64; D]], u_e: &[f64]) -> SMatrix<f64, D, D> {
    let mut h = SMatrix::<f64, D, D>::zeros();
    for (a, g) in dndx.iter().enumerate() {
        for i in 0..D {
            for k in 0..D {
                h[(i, k)] += u_e[D * a + i] * g[k];
            }
        }
    }
    h
}

/// The displacement gradient `H = F - I` at natural point `xi` of a cell of kind `kind` with
/// reference nodes `coords` and displacements `u_e`, with the reference position of the point.
pub fn displacement_gradient_at<const D: usize, C: ReferenceCell<D>>(
    kind: C,
    coords: &[[f64; D]],
    u_e: &[f64],
    xi: [f64; D],
) -> (SMatrix<f64, D, D>, [f64; D]) {
    let pv = kind.point_values(coords, xi);
    let n = kind.node_count();
    (field_gradient(&pv.gradients()[..n], u_e), pv.point())
}

/// Shape values, Cartesian gradients `dN_a/dx = J^-T dN_a/dxi` and `det J` at `xi` for a cell
/// of kind `kind` with nodes `coords` (element order), `J = dx/dxi`; the gradients are zero
/// where `det J = 0`. One function for every dimension (the cells' own
/// [`ReferenceCell::point_values`] fix the capacity `N`).
pub fn point_values<const D: usize, const N: usize, C: ReferenceCell<D>>(
    kind: C,
    coords: &[[f64; D]],
    xi: [f64; D],
) -> PointValues<D, N> {
    let nn = kind.node_count();
    let mut n = [0.0; N];
    let mut dn = [[0.0; D]; N];
    kind.shape(xi, &mut n[..nn], &mut dn[..nn]);
    // J[i][k] = d x_i / d xi_k
    let mut j = [[0.0; D]; D];
    let mut x = [0.0; D];
    for a in 0..nn {
        for i in 0..D {
            x[i] += n[a] * coords[a][i];
            for k in 0..D {
                j[i][k] += coords[a][i] * dn[a][k];
            }
        }
    }
    let (det_j, cofactor) = determinant_and_cofactor(&j);
    let mut dndx = [[0.0; D]; N];
    if det_j != 0.0 {
        // J^-T = cof J / det J: dN/dx_i = sum_k (cof J)_ik / det J dN/dxi_k
        let mut inverse_t = [[0.0; D]; D];
        for i in 0..D {
            for k in 0..D {
                inverse_t[i][k] = cofactor[i][k] / det_j;
            }
        }
        for a in 0..nn {
            for i in 0..D {
                dndx[a][i] = (0..D).fold(0.0, |s, k| s + inverse_t[i][k] * dn[a][k]);
            }
        }
    }
    PointValues { n, dndx, det_j, x }
}

/// `det J` and the cofactor matrix `cof J = det J J^-T` of a 2x2 or 3x3 matrix (the cofactor
/// expansion along the first row; in 3D each cofactor is the 2x2 minor of the cyclically next
/// rows and columns).
pub fn determinant_and_cofactor<const D: usize>(j: &[[f64; D]; D]) -> (f64, [[f64; D]; D]) {
    let mut cofactor = [[0.0; D]; D];
    match D {
        1 => cofactor[0][0] = 1.0,
        2 => {
            cofactor[0][0] = j[1][1];
            cofactor[0][1] = -j[1][0];
            cofactor[1][0] = -j[0][1];
            cofactor[1][1] = j[0][0];
        }
        3 => {
            for (r, row) in cofactor.iter_mut().enumerate() {
                let (r0, r1) = ((r + 1) % 3, (r + 2) % 3);
                for (c, entry) in row.iter_mut().enumerate() {
                    let (c0, c1) = ((c + 1) % 3, (c + 2) % 3);
                    *entry = j[r0][c0] * j[r1][c1] - j[r0][c1] * j[r1][c0];
                }
            }
        }
        _ => unreachable!("cells have 1, 2 or 3 natural coordinates"),
    }
    let det = (1..D).fold(j[0][0] * cofactor[0][0], |s, k| {
        s + j[0][k] * cofactor[0][k]
    });
    (det, cofactor)
}

/// A cell whose Jacobian is not positive at a node or a quadrature point: `det J` there, the
/// point, and whether it is negative (inverted) rather than zero.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct BadGeometry<const D: usize = 2> {
    pub det_j: f64,
    pub at: [f64; D],
    pub inverted: bool,
}

/// Check that `det J` is positive, relative to the cell's size (its bounding-box diagonal to
/// the power `D`), at the nodes and the points of `rule` (the stiffness rule).
pub fn check_geometry<const D: usize, C: ReferenceCell<D>>(
    kind: C,
    coords: &[[f64; D]],
    rule: &[QuadPoint<D>],
) -> Result<(), BadGeometry<D>> {
    let mut lo = [f64::INFINITY; D];
    let mut hi = [f64::NEG_INFINITY; D];
    for p in coords {
        for i in 0..D {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    let diagonal_squared: f64 = (0..D).map(|i| (hi[i] - lo[i]).powi(2)).sum();
    let scale = diagonal_squared
        .sqrt()
        .powi(D as i32)
        .max(f64::MIN_POSITIVE);
    let points = kind
        .node_coordinates()
        .iter()
        .copied()
        .chain(rule.iter().map(|q| q.xi));
    for xi in points {
        let pv = kind.point_values(coords, xi);
        let det_j = pv.jacobian_determinant();
        if det_j.is_nan() || det_j <= 1e-10 * scale {
            return Err(BadGeometry {
                det_j,
                at: pv.point(),
                inverted: det_j < 0.0,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_rules_integrate_their_degree() {
        for n in 1..=6 {
            let g = gauss_legendre(n);
            for deg in 0..(2 * n) {
                let num: f64 = g.iter().map(|(x, w)| w * x.powi(deg as i32)).sum();
                let exact = if deg % 2 == 1 {
                    0.0
                } else {
                    2.0 / (deg as f64 + 1.0)
                };
                assert!(
                    (num - exact).abs() < 1e-14,
                    "n={n} deg={deg}: {num} vs {exact}"
                );
            }
        }
    }

    #[test]
    fn triangle_rules_integrate_their_degree() {
        // int over the reference triangle of xi^a eta^b = a! b! / (a+b+2)!
        let fact = |k: u32| (1..=k).map(f64::from).product::<f64>();
        for (degree, rule) in [
            (1, triangle_rule(1)),
            (2, triangle_rule(2)),
            (5, triangle_rule(5)),
        ] {
            for a in 0..=degree {
                for b in 0..=(degree - a) {
                    let num: f64 = rule
                        .iter()
                        .map(|q| q.weight * q.xi[0].powi(a as i32) * q.xi[1].powi(b as i32))
                        .sum();
                    let exact = fact(a) * fact(b) / fact(a + b + 2);
                    assert!(
                        (num - exact).abs() < 1e-15,
                        "degree {degree}: x^{a} y^{b}: {num} vs {exact}"
                    );
                }
            }
        }
    }

    #[test]
    fn shape_functions_are_kronecker_and_partition_of_unity() {
        for kind in [
            ElementKind::Q4,
            ElementKind::Q9,
            ElementKind::T3,
            ElementKind::T6,
        ] {
            let nn = kind.node_count();
            let mut n = [0.0; MAX_NODES];
            let mut dn = [[0.0; 2]; MAX_NODES];
            for (b, xb) in kind.node_coordinates().iter().enumerate() {
                kind.shape(*xb, &mut n[..nn], &mut dn[..nn]);
                for a in 0..nn {
                    let expect = if a == b { 1.0 } else { 0.0 };
                    assert!(
                        (n[a] - expect).abs() < 1e-15,
                        "{kind:?}: N_{a}(node {b}) = {}",
                        n[a]
                    );
                }
            }
            // derivatives sum to zero and match finite differences at an arbitrary point
            let xi = [0.21, 0.17];
            kind.shape(xi, &mut n[..nn], &mut dn[..nn]);
            let h = 1e-6;
            for k in 0..2 {
                let mut sum = 0.0;
                let mut xp = xi;
                xp[k] += h;
                let mut xm = xi;
                xm[k] -= h;
                let (mut np, mut nm) = ([0.0; MAX_NODES], [0.0; MAX_NODES]);
                let mut scratch = [[0.0; 2]; MAX_NODES];
                kind.shape(xp, &mut np[..nn], &mut scratch[..nn]);
                kind.shape(xm, &mut nm[..nn], &mut scratch[..nn]);
                for a in 0..nn {
                    sum += dn[a][k];
                    let fd = (np[a] - nm[a]) / (2.0 * h);
                    assert!((fd - dn[a][k]).abs() < 1e-8, "{kind:?} dN_{a}/dxi_{k}");
                }
                assert!(sum.abs() < 1e-14);
            }
        }
    }

    #[test]
    fn edge_shapes_match_element_shapes_on_the_boundary() {
        // Along edge 0 of each element (from corner 0 to corner 1), the element shape functions of
        // the edge nodes equal the edge shape functions.
        for kind in [
            ElementKind::Q4,
            ElementKind::Q9,
            ElementKind::T3,
            ElementKind::T6,
        ] {
            let nn = kind.node_count();
            let edge = kind.edges()[0];
            let x0 = kind.node_coordinates()[edge[0]];
            let x1 = kind.node_coordinates()[edge[1]];
            for s in [-0.8, -0.1, 0.4, 1.0] {
                let t = 0.5 * (1.0 + s);
                let xi = [x0[0] + t * (x1[0] - x0[0]), x0[1] + t * (x1[1] - x0[1])];
                let mut n = [0.0; MAX_NODES];
                let mut dn = [[0.0; 2]; MAX_NODES];
                kind.shape(xi, &mut n[..nn], &mut dn[..nn]);
                let mut ne = [0.0; 3];
                let mut dne = [0.0; 3];
                kind.edge_kind().shape(s, &mut ne, &mut dne);
                for (k, &a) in edge.iter().enumerate() {
                    assert!((n[a] - ne[k]).abs() < 1e-14, "{kind:?} edge node {k}");
                }
            }
        }
    }

    #[test]
    fn inverted_and_degenerate_elements_are_detected() {
        let good = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert!(check_geometry(ElementKind::Q4, &good, &ElementKind::Q4.stiffness_rule()).is_ok());
        let clockwise = vec![[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]];
        assert!(
            check_geometry(
                ElementKind::Q4,
                &clockwise,
                &ElementKind::Q4.stiffness_rule()
            )
            .unwrap_err()
            .inverted
        );
        let collapsed = vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]];
        let err = check_geometry(
            ElementKind::T3,
            &collapsed,
            &ElementKind::T3.stiffness_rule(),
        )
        .unwrap_err();
        assert!(!err.inverted && err.det_j.abs() < 1e-12);
        // a bow-tie (non-convex beyond repair) is inverted somewhere inside
        let bowtie = vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]];
        assert!(
            check_geometry(ElementKind::Q4, &bowtie, &ElementKind::Q4.stiffness_rule()).is_err()
        );
    }

    #[test]
    fn an_inverted_or_flat_solid_is_detected_as_a_quadrilateral_is() {
        use crate::fe3d::SolidKind;
        let cube: Vec<[f64; 3]> = SolidKind::Hex8.node_coordinates().to_vec();
        let rule = SolidKind::Hex8.stiffness_rule();
        assert!(check_geometry(SolidKind::Hex8, &cube, &rule).is_ok());
        // the top and bottom faces swapped: det J < 0 everywhere
        let mut mirrored = cube.clone();
        mirrored.rotate_left(4);
        let err = check_geometry(SolidKind::Hex8, &mirrored, &rule).unwrap_err();
        assert!(err.inverted && err.det_j < 0.0, "{err:?}");
        // a flat tetrahedron (its fourth corner on the base plane): det J = 0
        let flat = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ];
        let err =
            check_geometry(SolidKind::Tet4, &flat, &SolidKind::Tet4.stiffness_rule()).unwrap_err();
        assert!(!err.inverted && err.det_j.abs() < 1e-12, "{err:?}");
    }
}
