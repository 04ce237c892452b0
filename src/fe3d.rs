//! Reference finite elements and quadrature in 3D: Hex8, Hex27, Tet4, Tet10.
//!
//! Isoparametric Lagrange elements (as in [`crate::fe`] for 2D): `x(xi) = sum_a N_a(xi) x_a`,
//! `u(xi) = sum_a N_a(xi) u_a`, so every linear field is reproduced exactly on any non-inverted
//! mesh (the single-body patch test).
//!
//! * **Hex8**, **Hex27** on `[-1, 1]^3`: tensor products of the 1D linear and quadratic
//!   Lagrange polynomials (nodes at -1, 0, 1).
//! * **Tet4**, **Tet10** on `{xi, eta, zeta >= 0, xi + eta + zeta <= 1}` with barycentric
//!   coordinates `L0 = 1 - xi - eta - zeta, L1 = xi, L2 = eta, L3 = zeta`: `N_a = L_a` (Tet4);
//!   corners `L_a (2 L_a - 1)`, mid-edge nodes `4 L_a L_b` (Tet10).
//!
//! Node ordering is VTK's (`VTK_HEXAHEDRON` 12, `VTK_TRIQUADRATIC_HEXAHEDRON` 29, `VTK_TETRA`
//! 10, `VTK_QUADRATIC_TETRA` 24; VTK file formats, "Cell types"): hex corners 0-3 on
//! `zeta = -1` counter-clockwise, 4-7 above them; Hex27 mid-edge nodes 8-11 on the bottom
//! edges (0-1, 1-2, 2-3, 3-0), 12-15 on the top edges (4-5, 5-6, 6-7, 7-4), 16-19 on the
//! vertical edges (0-4, 1-5, 2-6, 3-7), face centres 20-25 on `xi = -1, +1`, `eta = -1, +1`,
//! `zeta = -1, +1`, the body centre 26; Tet10 mid-edge nodes 4-9 on edges 0-1, 1-2, 2-0, 0-3,
//! 1-3, 2-3.
//!
//! **Facets.** A facet is a 2D reference element of [`crate::fe`]: Quad4 = `Q4` (Hex8),
//! Quad9 = `Q9` (Hex27), Tri3 = `T3` (Tet4), Tri6 = `T6` (Tet10), its nodes listed in that
//! element's order (corners, mid-sides, centre) and its corners counter-clockwise seen from
//! outside, so `dx/ds x dx/dt` is the outward normal times the area scale.
//!
//! **Quadrature** (stiffness, [`SolidKind::stiffness_rule`]): Gauss 2x2x2 (Hex8) and 3x3x3
//! (Hex27), which integrate the divergence identity behind the patch test exactly on
//! distorted hexahedra, as in 2D; for tetrahedra the symmetric rules of degree 1 (the
//! centroid, weight 1/6) for Tet4 and of degree 2 (four points at barycentric `(a, b, b, b)`
//! and permutations, `a = (5 + 3 sqrt 5) / 20`, `b = (5 - sqrt 5) / 20`, weights 1/24; Keast,
//! Comput. Methods Appl. Mech. Engrg. 55 (1986) 339-348, rule 2) for Tet10, which integrate
//! `B^T D B det J` exactly on straight-edged (affine) tetrahedra. Error norms and loads use
//! richer rules: Gauss 5x5x5 on hexahedra and the conical product (collapsed Gauss) rule on
//! tetrahedra, `x = u, y = v (1 - u), z = w (1 - u)(1 - v)` with the Jacobian
//! `(1 - u)^2 (1 - v)` (Stroud, Approximate Calculation of Multiple Integrals, 1971), `n`
//! Gauss-Legendre points per direction being exact for total degree `2 n - 3`.

use crate::fe::{
    gauss_legendre, lagrange_1d_quadratic, point_values, ElementKind, PointValues, QuadPoint,
    ReferenceCell,
};
use serde::{Deserialize, Serialize};

/// A 3D reference element type.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, schemars::JsonSchema)]
pub enum SolidKind {
    Hex8,
    Hex27,
    Tet4,
    Tet10,
}

/// Largest number of nodes of any 3D element; sizes stack buffers.
pub const MAX_SOLID_NODES: usize = 27;

const HEX8_FACETS: [&[usize]; 6] = [
    &[0, 4, 7, 3],
    &[1, 2, 6, 5],
    &[0, 1, 5, 4],
    &[3, 7, 6, 2],
    &[0, 3, 2, 1],
    &[4, 5, 6, 7],
];
const HEX27_FACETS: [&[usize]; 6] = [
    &[0, 4, 7, 3, 16, 15, 19, 11, 20],
    &[1, 2, 6, 5, 9, 18, 13, 17, 21],
    &[0, 1, 5, 4, 8, 17, 12, 16, 22],
    &[3, 7, 6, 2, 19, 14, 18, 10, 23],
    &[0, 3, 2, 1, 11, 10, 9, 8, 24],
    &[4, 5, 6, 7, 12, 13, 14, 15, 25],
];
const TET4_FACETS: [&[usize]; 4] = [&[0, 2, 1], &[0, 1, 3], &[0, 3, 2], &[1, 2, 3]];
const TET10_FACETS: [&[usize]; 4] = [
    &[0, 2, 1, 6, 5, 4],
    &[0, 1, 3, 4, 8, 7],
    &[0, 3, 2, 7, 9, 6],
    &[1, 2, 3, 5, 9, 8],
];

const HEX_CORNERS: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];
/// Hex27 mid-edge nodes 8-19: the corners each joins.
const HEX27_EDGES: [[usize; 2]; 12] = [
    [0, 1],
    [1, 2],
    [2, 3],
    [3, 0],
    [4, 5],
    [5, 6],
    [6, 7],
    [7, 4],
    [0, 4],
    [1, 5],
    [2, 6],
    [3, 7],
];
const HEX27_FACE_CENTRES: [[f64; 3]; 7] = [
    [-1.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, -1.0],
    [0.0, 0.0, 1.0],
    [0.0, 0.0, 0.0],
];
const TET_CORNERS: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
];
/// Tet10 mid-edge nodes 4-9: the corners each joins.
const TET10_EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]];

fn midpoint(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        0.5 * (a[0] + b[0]),
        0.5 * (a[1] + b[1]),
        0.5 * (a[2] + b[2]),
    ]
}

/// Natural coordinates of the nodes of each kind, built once from the tables above.
fn node_table(kind: SolidKind) -> &'static [[f64; 3]] {
    static TABLES: std::sync::OnceLock<[Vec<[f64; 3]>; 4]> = std::sync::OnceLock::new();
    let tables = TABLES.get_or_init(|| {
        let mut hex27 = HEX_CORNERS.to_vec();
        hex27.extend(
            HEX27_EDGES
                .iter()
                .map(|&[a, b]| midpoint(HEX_CORNERS[a], HEX_CORNERS[b])),
        );
        hex27.extend(HEX27_FACE_CENTRES);
        let mut tet10 = TET_CORNERS.to_vec();
        tet10.extend(
            TET10_EDGES
                .iter()
                .map(|&[a, b]| midpoint(TET_CORNERS[a], TET_CORNERS[b])),
        );
        [HEX_CORNERS.to_vec(), hex27, TET_CORNERS.to_vec(), tet10]
    });
    match kind {
        SolidKind::Hex8 => &tables[0],
        SolidKind::Hex27 => &tables[1],
        SolidKind::Tet4 => &tables[2],
        SolidKind::Tet10 => &tables[3],
    }
}

impl SolidKind {
    pub const ALL: [SolidKind; 4] = [
        SolidKind::Hex8,
        SolidKind::Hex27,
        SolidKind::Tet4,
        SolidKind::Tet10,
    ];

    /// The facet's 2D reference element (Quad4 = Q4, Quad9 = Q9, Tri3 = T3, Tri6 = T6).
    pub fn facet_kind(self) -> ElementKind {
        match self {
            SolidKind::Hex8 => ElementKind::Q4,
            SolidKind::Hex27 => ElementKind::Q9,
            SolidKind::Tet4 => ElementKind::T3,
            SolidKind::Tet10 => ElementKind::T6,
        }
    }

    pub fn is_hexahedron(self) -> bool {
        matches!(self, SolidKind::Hex8 | SolidKind::Hex27)
    }

    /// Natural coordinates of the element centre.
    pub fn centre(self) -> [f64; 3] {
        if self.is_hexahedron() {
            [0.0; 3]
        } else {
            [0.25; 3]
        }
    }

    /// Quadrature rule that integrates the stiffness of this element (see module docs).
    pub fn stiffness_rule(self) -> Vec<QuadPoint<3>> {
        match self {
            SolidKind::Hex8 => gauss_cube(2),
            SolidKind::Hex27 => gauss_cube(3),
            SolidKind::Tet4 => tetrahedron_rule(1),
            SolidKind::Tet10 => tetrahedron_rule(2),
        }
    }

    /// A richer rule for loads and error norms of smooth fields.
    pub fn error_rule(self) -> Vec<QuadPoint<3>> {
        if self.is_hexahedron() {
            gauss_cube(5)
        } else {
            tetrahedron_conical(5)
        }
    }
}

impl ReferenceCell<3> for SolidKind {
    fn node_count(self) -> usize {
        match self {
            SolidKind::Hex8 => 8,
            SolidKind::Hex27 => 27,
            SolidKind::Tet4 => 4,
            SolidKind::Tet10 => 10,
        }
    }
    fn corner_count(self) -> usize {
        if self.is_hexahedron() {
            8
        } else {
            4
        }
    }
    fn is_quadratic(self) -> bool {
        matches!(self, SolidKind::Hex27 | SolidKind::Tet10)
    }
    fn facets(self) -> &'static [&'static [usize]] {
        match self {
            SolidKind::Hex8 => &HEX8_FACETS,
            SolidKind::Hex27 => &HEX27_FACETS,
            SolidKind::Tet4 => &TET4_FACETS,
            SolidKind::Tet10 => &TET10_FACETS,
        }
    }
    fn facet_corner_count(self, _k: usize) -> usize {
        self.facet_kind().corner_count()
    }
    fn node_coordinates(self) -> &'static [[f64; 3]] {
        node_table(self)
    }
    fn shape(self, xi: [f64; 3], n: &mut [f64], dn: &mut [[f64; 3]]) {
        match self {
            SolidKind::Hex8 => {
                for (a, c) in HEX_CORNERS.iter().enumerate() {
                    let l = [
                        0.5 * (1.0 + c[0] * xi[0]),
                        0.5 * (1.0 + c[1] * xi[1]),
                        0.5 * (1.0 + c[2] * xi[2]),
                    ];
                    let d = [0.5 * c[0], 0.5 * c[1], 0.5 * c[2]];
                    n[a] = l[0] * l[1] * l[2];
                    dn[a] = [d[0] * l[1] * l[2], l[0] * d[1] * l[2], l[0] * l[1] * d[2]];
                }
            }
            SolidKind::Hex27 => {
                for (a, c) in node_table(self).iter().enumerate() {
                    let (l0, d0) = lagrange_1d_quadratic(c[0], xi[0]);
                    let (l1, d1) = lagrange_1d_quadratic(c[1], xi[1]);
                    let (l2, d2) = lagrange_1d_quadratic(c[2], xi[2]);
                    n[a] = l0 * l1 * l2;
                    dn[a] = [d0 * l1 * l2, l0 * d1 * l2, l0 * l1 * d2];
                }
            }
            SolidKind::Tet4 | SolidKind::Tet10 => {
                let l = [1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]];
                let dl = [
                    [-1.0, -1.0, -1.0],
                    [1.0, 0.0, 0.0],
                    [0.0, 1.0, 0.0],
                    [0.0, 0.0, 1.0],
                ];
                if self == SolidKind::Tet4 {
                    n[..4].copy_from_slice(&l);
                    dn[..4].copy_from_slice(&dl);
                    return;
                }
                for a in 0..4 {
                    n[a] = l[a] * (2.0 * l[a] - 1.0);
                    dn[a] = dl[a].map(|d| (4.0 * l[a] - 1.0) * d);
                }
                for (k, &[a, b]) in TET10_EDGES.iter().enumerate() {
                    n[4 + k] = 4.0 * l[a] * l[b];
                    dn[4 + k] = [0, 1, 2].map(|i| 4.0 * (dl[a][i] * l[b] + l[a] * dl[b][i]));
                }
            }
        }
    }
    fn vtk_cell_type(self) -> u8 {
        match self {
            SolidKind::Hex8 => 12,
            SolidKind::Hex27 => 29,
            SolidKind::Tet4 => 10,
            SolidKind::Tet10 => 24,
        }
    }
    type PointValues = PointValues<3, MAX_SOLID_NODES>;
    fn point_values(self, coords: &[[f64; 3]], xi: [f64; 3]) -> Self::PointValues {
        point_values(self, coords, xi)
    }
}

/// Tensor-product Gauss rule with `n^3` points on `[-1, 1]^3`.
pub fn gauss_cube(n: usize) -> Vec<QuadPoint<3>> {
    let g = gauss_legendre(n);
    let mut out = Vec::with_capacity(n * n * n);
    for &(z, wz) in &g {
        for &(y, wy) in &g {
            for &(x, wx) in &g {
                out.push(QuadPoint {
                    xi: [x, y, z],
                    weight: wx * wy * wz,
                });
            }
        }
    }
    out
}

/// Symmetric rules on the reference tetrahedron (volume 1/6) exact for polynomials of
/// `degree` 1 (the centroid) or 2 (Keast's four points); a higher degree gets the conical
/// product rule exact for it.
pub fn tetrahedron_rule(degree: usize) -> Vec<QuadPoint<3>> {
    match degree {
        0 | 1 => vec![QuadPoint {
            xi: [0.25; 3],
            weight: 1.0 / 6.0,
        }],
        2 => {
            let a = (5.0 + 3.0 * 5f64.sqrt()) / 20.0;
            let b = (5.0 - 5f64.sqrt()) / 20.0;
            [[b, b, b], [a, b, b], [b, a, b], [b, b, a]]
                .into_iter()
                .map(|xi| QuadPoint {
                    xi,
                    weight: 1.0 / 24.0,
                })
                .collect()
        }
        d => tetrahedron_conical((d + 3).div_ceil(2)),
    }
}

/// The conical product rule with `n^3` points (see module docs), exact for total degree
/// `2 n - 3`.
pub fn tetrahedron_conical(n: usize) -> Vec<QuadPoint<3>> {
    let g: Vec<(f64, f64)> = gauss_legendre(n)
        .into_iter()
        .map(|(s, w)| (0.5 * (1.0 + s), 0.5 * w))
        .collect();
    let mut out = Vec::with_capacity(n * n * n);
    for &(u, wu) in &g {
        for &(v, wv) in &g {
            for &(w, ww) in &g {
                out.push(QuadPoint {
                    xi: [u, v * (1.0 - u), w * (1.0 - u) * (1.0 - v)],
                    weight: wu * wv * ww * (1.0 - u) * (1.0 - u) * (1.0 - v),
                });
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Vector3};

    fn fact(k: u32) -> f64 {
        (1..=k).map(f64::from).product()
    }

    #[test]
    fn cube_rules_integrate_their_degree() {
        // n points per direction: exact for degree 2n - 1 in each variable
        for n in [2, 3, 5] {
            let rule = gauss_cube(n);
            let top = 2 * n as i32 - 1;
            for (a, b, c) in [
                (0, 0, 0),
                (2, 0, 0),
                (top - 1, 2, 0),
                (top - 1, top - 1, top - 1),
            ] {
                let num: f64 = rule
                    .iter()
                    .map(|q| q.weight * q.xi[0].powi(a) * q.xi[1].powi(b) * q.xi[2].powi(c))
                    .sum();
                let one = |p: i32| {
                    if p % 2 == 1 {
                        0.0
                    } else {
                        2.0 / (p as f64 + 1.0)
                    }
                };
                let exact = one(a) * one(b) * one(c);
                // relative to the value (the weights of 125 points sum to 8)
                assert!(
                    (num - exact).abs() < 1e-14 * (1.0 + exact.abs()),
                    "n={n} ({a},{b},{c}): {num} vs {exact}"
                );
            }
        }
    }

    #[test]
    fn tetrahedron_rules_integrate_their_degree() {
        // int over the reference tetrahedron of x^a y^b z^c = a! b! c! / (a+b+c+3)!
        for (degree, rule) in [
            (1u32, tetrahedron_rule(1)),
            (2, tetrahedron_rule(2)),
            (5, tetrahedron_rule(5)),
            (7, tetrahedron_conical(5)),
        ] {
            for a in 0..=degree {
                for b in 0..=(degree - a) {
                    for c in 0..=(degree - a - b) {
                        let num: f64 = rule
                            .iter()
                            .map(|q| {
                                q.weight
                                    * q.xi[0].powi(a as i32)
                                    * q.xi[1].powi(b as i32)
                                    * q.xi[2].powi(c as i32)
                            })
                            .sum();
                        let exact = fact(a) * fact(b) * fact(c) / fact(a + b + c + 3);
                        assert!(
                            (num - exact).abs() < 1e-15,
                            "degree {degree}: x^{a} y^{b} z^{c}: {num} vs {exact}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn shape_functions_are_kronecker_partition_of_unity_and_match_finite_differences() {
        for kind in SolidKind::ALL {
            let nn = kind.node_count();
            assert_eq!(kind.node_coordinates().len(), nn);
            let mut n = [0.0; MAX_SOLID_NODES];
            let mut dn = [[0.0; 3]; MAX_SOLID_NODES];
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
            let xi = [0.21, 0.17, 0.13];
            kind.shape(xi, &mut n[..nn], &mut dn[..nn]);
            let total: f64 = n[..nn].iter().sum();
            assert!((total - 1.0).abs() < 1e-14, "{kind:?}: sum N = {total}");
            let h = 1e-6;
            for k in 0..3 {
                let (mut xp, mut xm) = (xi, xi);
                xp[k] += h;
                xm[k] -= h;
                let (mut np, mut nm) = ([0.0; MAX_SOLID_NODES], [0.0; MAX_SOLID_NODES]);
                let mut scratch = [[0.0; 3]; MAX_SOLID_NODES];
                kind.shape(xp, &mut np[..nn], &mut scratch[..nn]);
                kind.shape(xm, &mut nm[..nn], &mut scratch[..nn]);
                let mut sum = 0.0;
                for a in 0..nn {
                    sum += dn[a][k];
                    let fd = (np[a] - nm[a]) / (2.0 * h);
                    assert!((fd - dn[a][k]).abs() < 1e-8, "{kind:?} dN_{a}/dxi_{k}");
                }
                assert!(sum.abs() < 1e-14, "{kind:?}: sum dN/dxi_{k} = {sum}");
            }
        }
    }

    /// Natural point of the solid on facet `f` at the facet's natural point `s`: the facet's
    /// corners mapped by the facet element's corner shape functions (the facets are flat in
    /// natural coordinates).
    fn on_facet(kind: SolidKind, f: usize, s: [f64; 2]) -> [f64; 3] {
        let fk = kind.facet_kind();
        let corners = fk.corner_count();
        let linear = if corners == 4 {
            ElementKind::Q4
        } else {
            ElementKind::T3
        };
        let mut n = [0.0; 4];
        let mut dn = [[0.0; 2]; 4];
        linear.shape(s, &mut n[..corners], &mut dn[..corners]);
        let local = kind.facets()[f];
        let mut xi = [0.0; 3];
        for c in 0..corners {
            let p = kind.node_coordinates()[local[c]];
            for i in 0..3 {
                xi[i] += n[c] * p[i];
            }
        }
        xi
    }

    #[test]
    fn facet_shapes_match_element_shapes_on_every_facet_and_normals_point_out() {
        for kind in SolidKind::ALL {
            let nn = kind.node_count();
            let fk = kind.facet_kind();
            let fnn = fk.node_count();
            let centre = kind.centre();
            for (f, local) in kind.facets().iter().enumerate() {
                assert_eq!(local.len(), fnn, "{kind:?} facet {f}");
                for s in [[0.1, 0.2], [0.3, 0.05], [0.25, 0.6]] {
                    let xi = on_facet(kind, f, s);
                    let mut n = [0.0; MAX_SOLID_NODES];
                    let mut dn = [[0.0; 3]; MAX_SOLID_NODES];
                    kind.shape(xi, &mut n[..nn], &mut dn[..nn]);
                    let mut nf = [0.0; 9];
                    let mut dnf = [[0.0; 2]; 9];
                    fk.shape(s, &mut nf[..fnn], &mut dnf[..fnn]);
                    for (k, &a) in local.iter().enumerate() {
                        assert!(
                            (n[a] - nf[k]).abs() < 1e-14,
                            "{kind:?} facet {f} node {k}: {} vs {}",
                            n[a],
                            nf[k]
                        );
                    }
                    // nodes off the facet vanish on it
                    for a in (0..nn).filter(|a| !local.contains(a)) {
                        assert!(n[a].abs() < 1e-14, "{kind:?} facet {f}: N_{a} = {}", n[a]);
                    }
                    // the facet's tangents, crossed, point away from the centre
                    let mut t = [[0.0; 3]; 2];
                    for (k, &a) in local.iter().enumerate() {
                        for i in 0..3 {
                            for j in 0..2 {
                                t[j][i] += dnf[k][j] * kind.node_coordinates()[a][i];
                            }
                        }
                    }
                    let normal = Vector3::from(t[0]).cross(&Vector3::from(t[1]));
                    let out = Vector3::from(xi) - Vector3::from(centre);
                    assert!(normal.dot(&out) > 0.0, "{kind:?} facet {f} points inwards");
                }
            }
        }
    }

    #[test]
    fn point_values_reproduce_an_affine_map() {
        // x = A xi + c: dN/dx = A^-T dN/dxi, det J = det A, sum N_a x_a = x
        let a = Matrix3::new(1.2, 0.1, -0.2, 0.05, 0.9, 0.1, 0.0, -0.1, 1.1);
        let c = Vector3::new(0.3, -0.2, 0.5);
        for kind in SolidKind::ALL {
            let coords: Vec<[f64; 3]> = kind
                .node_coordinates()
                .iter()
                .map(|p| (a * Vector3::from(*p) + c).into())
                .collect();
            let xi = [0.2, 0.1, 0.3];
            let pv = kind.point_values(&coords, xi);
            // det A by the rule of Sarrus
            assert!((pv.det_j - 1.1955).abs() < 1e-14, "{}", pv.det_j);
            let x = a * Vector3::from(xi) + c;
            for i in 0..3 {
                assert!((pv.x[i] - x[i]).abs() < 1e-14);
            }
            // the gradient of the field x_i is e_i
            for i in 0..3 {
                for k in 0..3 {
                    let g: f64 = (0..kind.node_count())
                        .map(|b| coords[b][i] * pv.dndx[b][k])
                        .sum();
                    let expect = if i == k { 1.0 } else { 0.0 };
                    assert!((g - expect).abs() < 1e-13, "{kind:?} d x_{i}/d x_{k} = {g}");
                }
            }
        }
    }
}
