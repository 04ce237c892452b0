//! Segment-based mortar integration in 3D (Quad4, Tri3, Quad9 and Tri6 facets), standard and
//! dual multipliers: the mortar matrices `D`, `M` and the weighted-gap rows
//! [`crate::contact::Constraint<3>`].
//!
//! References: M. A. Puso and T. A. Laursen, "A mortar segment-to-segment contact method for
//! large deformation solid mechanics", CMAME 193 (2004) (the auxiliary plane, projection and
//! clipping); A. Popp, M. W. Gee and W. A. Wall, "A finite deformation mortar contact
//! formulation using a primal-dual active set strategy" (2009) and A. Popp et al., "Finite
//! deformation frictional mortar contact using a semi-smooth Newton method with consistent
//! linearization" (2010) (the element-wise dual basis in 3D); Taylor 2004, "2002-2004: Mortar
//! Methods for Contact & Ties" (the interface term `int lambda . (x_m - x_s) dGamma`).
//!
//! With multiplier functions `Phi_j` on the slave surface,
//!
//! ```text
//! D_jk = int Phi_j N_k dA          (slave node j, slave node k)
//! M_jl = int Phi_j N^m_l dA        (slave node j, master node l)
//! g~_j = nu_j . (sum_k D_jk x_k - sum_l M_jl x_l),   A_j = sum_k D_jk
//! ```
//!
//! The integrals are taken segment by segment:
//!
//! 1. **Auxiliary plane.** For each slave facet: the plane through the facet's centre
//!    `x_0 = x(xi_c)` with normal `n_0 = x_xi x x_eta / |x_xi x x_eta|` there (outward); an
//!    orthonormal frame `t_1, t_2, n_0`; points are projected onto it along `n_0`.
//! 2. **Candidates.** Master facets whose bounding boxes, grown by the search distance, meet
//!    the slave facet's box (the bucket grid of the contact search, [`BucketGrid`]). A master facet takes
//!    part only if it faces the slave facet: its projection has the opposite orientation
//!    (negative signed area in the slave's counter-clockwise frame, beyond `1e-9` of its own
//!    area); a facet seen edge-on or from its back does not.
//! 3. **Clipping.** The projected slave polygon (convex, counter-clockwise; each of its pieces
//!    for Quad9 and Tri6, see below) clips the projected master polygon (reversed to counter-clockwise)
//!    by Sutherland-Hodgman
//!    ([`clip_convex_polygons`]): a point is inside an edge when its signed distance is at least
//!    `-tol` (`tol = 1e-8` of the slave facet's diameter, [`CLIP_TOLERANCE`]), an intersection parameter is clamped
//!    to `[0, 1]` (nearly parallel edges), consecutive vertices closer than `tol` merge, and a
//!    polygon with fewer than 3 vertices or an area below `1e-12` of the slave facet's is no
//!    overlap (disjoint facets and facets touching along an edge or a corner).
//! 4. **Cells.** The clip polygon is split into triangles about its vertex average (inside a
//!    convex polygon). On each triangle a symmetric rule on the reference triangle: degree 2
//!    (3 points) between Tri3 facets (the integrands `Phi_j N_k` are products of two linear
//!    functions), degree 5 (Radon's 7 points) where a Quad4 takes part (products of two
//!    bilinear functions, total degree 4 when the facet map is affine) or a Tri6 does and no
//!    Quad9 (a quadratic multiplier times a quadratic, bilinear or linear shape function:
//!    degree at most 4), degree 8 (the collapsed 5 x 5 Gauss product,
//!    [`collapsed_triangle_rule`]) where a Quad9 takes part (two biquadratic functions, total
//!    degree 8). A Quad4 facet that is not a parallelogram (its projection onto the
//!    auxiliary plane) has a bilinear map that is not affine, and a Tri6 whose projected
//!    mid-edge nodes are not the midpoints of its corners (curved) a quadratic one; the
//!    natural coordinates of a plane point are then not polynomials in it, no triangle rule is
//!    exact, and the pair is integrated with the collapsed 8 x 8 product (degree 14,
//!    [`NON_AFFINE_POINTS`]): its integrals agree with a 20 x 20 product to round-off on
//!    distorted facets (`tests/mortar3.rs`), and the skewed Hex8 punch of the 3D patch table
//!    passes (Radon's degree-5 rule left a stress error of 3.7e-8 there). The weight is the rule's weight times twice
//!    the triangle's area: the integrals are taken over the auxiliary plane (exact for flat
//!    slave facets, Puso and Laursen's approximation otherwise).
//! 5. **Back to the facets.** Each Gauss point `p` of the plane maps to the slave and master
//!    natural coordinates by inverting the projected facet map `xi -> P(x(xi))`: in closed form
//!    for Tri3 (affine), by Newton for Quad4, Quad9 and Tri6 from the centre of the piece the
//!    point lies in (converged to `1e-13` in `xi`, at most 50 steps, a failure is an error naming
//!    the facets).
//!
//! **Quad9 facets** (Hex27) are segmented by their four sub-quadrilaterals through the mid-edge
//! and centre nodes (Puso, Laursen and Solberg, "A segment-to-segment mortar contact method
//! for quadratic elements and large deformations", CMAME 197 (2008)): each slave piece clips
//! each master piece, and the cells are integrated with the full biquadratic shape functions.
//! Exact for straight-edged facets (every facet of `mesh::block3`); on curved facets the
//! pieces' chords stand for the curved edges. **Tri6 facets** (Tet10) are segmented the same
//! way, by their four sub-triangles through the mid-edge nodes (`0 3 5`, `3 1 4`, `5 4 2`,
//! `3 4 5`), integrated with the full quadratic shape functions.
//!
//! **Multipliers.** Each slave facet has a multiplier basis `B_k`: its shape functions `N_k`
//! on Quad4, Tri3 and Quad9; on Tri6 the modified basis `N~_k` (below). Standard: `Phi_j =
//! B_j`. Dual: `Phi_j = Psi_j = sum_k a_jk B_k` per slave facet, `A_e = D_e M_e^-1` with `D_e
//! = diag(int_e B_k dA)` and `M_e = [int_e B_j B_k dA]` over the whole facet in the same
//! (auxiliary-plane) measure (Gauss 3x3 for Quad4, 4x4 for Quad9, degree 2 for Tri3, the
//! collapsed 4 x 4 product (degree 6) for Tri6), so `int_e Psi_j B_k dA = delta_jk int_e B_k
//! dA`; where the basis is the shape basis `D` is then diagonal where the slave facet is
//! covered. On affine facets this is
//! `Psi_j = 4 N_j - 1` (Tri3) and `a = [[4, -2, 1, -2], ...]` (Quad4, the nodal pattern of
//! `4 N_j - 2 N_{j+1} + N_{j+2} - 2 N_{j+3}`). On facets whose map is not affine the cell
//! quadrature of `D` is not exact, so biorthogonality then holds to the quadrature error only.
//!
//! **Tri6: the modified basis.** A Tri6 corner function integrates to zero over a flat
//! triangle (`int N_v dA = 0`, `int N_e dA = A/3`), so with `B = N` a corner's row would have
//! `A_j = sum_k D_jk = int N_j dA = 0` (no weight, no normalization) and the dual basis
//! `D_e M_e^-1` would have a zero corner function. Both spaces are therefore built on the
//! modified basis of Puso, Laursen and Solberg (CMAME 197 (2008)) and Popp, Wohlmuth,
//! Gee and Wall ("Dual quadratic mortar finite element methods for 3D finite deformation
//! contact", SIAM J. Sci. Comput. 34 (2012); the same `alpha = 1/5` in the 4C mortar
//! library's `quad2D_modified`): `N~_v = N_v + (1/5) (N_e + N_e')` over the corner's two
//! edges, `N~_e = (3/5) N_e`, [`super::geometry::TRI6_MODIFIED_ALPHA`], the basis of the
//! node-based Tri6 nodal weights too. It is a partition of unity with `int N~_v dA = 2A/15`
//! and `int N~_e dA = A/5` (positive). The displacement keeps the standard `N_k` on both
//! sides, so `D_jk = int Phi_j N_k dA`, `M_jl = int Phi_j N^m_l dA`. Standard rows carry the
//! multiplier mass `int N~_j N~_k dA` (not `D`). The dual basis is biorthogonal to `N~`, not
//! to `N`: with `N = T^-1 N~` (`N_v = N~_v - (1/3) (N~_e + N~_e')`, `N_e = (5/3) N~_e`), a
//! corner row of `D` is diagonal, `D_vv = int N~_v dA`, and a mid-edge row has `D_ee = (5/3)
//! int N~_e dA` and `-(1/3) int N~_e dA` at the edge's two corners (Popp et al.'s `D` in the
//! transformed displacement basis, here in the nodal one). `A_j = int Phi_j dA = int B_j dA`
//! stays positive; the dual basis reproduces constants (`sum_j Psi_j = 1`), so a uniform
//! pressure is a multiplier of the space and the contact patch test is passed.
//!
//! **Rows.** For slave node `j` with the slave surface's outward unit nodal normal `n_j` (an
//! input: the caller owns nodal normals), the gap direction is `nu_j = -n_j` (from master to
//! slave, as the 2D mortar's); the row, normalized by `A_j` as in 2D so that penalty forces
//! `kappa A g` keep their meaning, is
//!
//! ```text
//! g_j(u) = g~_j / A_j + sum_k (D_jk / A_j) nu_j . u_k - sum_l (M_jl / A_j) nu_j . u_l
//! ```
//!
//! with `area = A_j` and, for standard multipliers, the multiplier mass line
//! `mass = [(k, int Phi_j Phi_k dA)]` (the row's own node first; `D_jk` except on Tri6); dual
//! rows carry none (lumped). The
//! coefficients are the small-strain linearization: `D`, `M` and `nu` frozen at the reference
//! configuration. Linear momentum: `sum_k D_jk = sum_l M_jl` at every slave node (both sides'
//! shape functions sum to one at every Gauss point of every cell); angular momentum:
//! `sum_k D_jk x_k = sum_l M_jl x_l` on flat coplanar interfaces (both facets reproduce the
//! plane point at every Gauss point).
//!
//! Quad9 needs no modified basis (its corner integrals `int N_k dA` are positive).

use super::geometry::FacetShape;
use super::node_based_rows::{dominant_component, gradient_coefficients};
use super::search::BucketGrid;
use crate::contact::Constraint;
use crate::fe::{gauss_legendre, gauss_square, triangle_rule, ElementKind, QuadPoint, MAX_NODES};
use crate::io::scene::MultiplierSpace;
use crate::mesh::{Facet, Mesh3};
use nalgebra::DMatrix;
use std::collections::{BTreeMap, HashMap};

/// `D_jk` or `M_jl` by slave node `j` (over slave nodes `k` or master nodes `l`).
pub type MortarMatrix3 = BTreeMap<usize, BTreeMap<usize, f64>>;

/// Tolerance on the natural-coordinate step of the inverse Quad4 and Quad9 maps.
const NEWTON_TOLERANCE: f64 = 1e-13;
/// Largest number of Newton steps of the inverse Quad4 and Quad9 maps.
const NEWTON_STEPS: usize = 50;
/// Relative size (of the slave facet's diameter) below which a polygon vertex lies on a window
/// edge and two vertices coincide: about the square root of the machine epsilon.
///
/// Why not round-off size: where a slave edge and a master edge lie on one line (blocks whose
/// outer faces are flush, the two-block patch test), an edge `epsilon h` off the other's line
/// is cut at `t = d_p / (d_p - d_q)` with signed distances `d ~ epsilon h` computed to `1e-16
/// h`, so `t`'s second derivative (about `1 / epsilon^2`) carries an absolute error of about
/// `1e-16 / epsilon^2`: at `epsilon = 1e-8` the Newton tangent of the finite-strain rows
/// (`mortar3_linearization`) is wrong by O(1) there. With a round-off tolerance (`1e-12`) the
/// Newton iterates of the finite-strain patch test wandered at relative residuals `1e-9` to
/// `1e-7` for 20 to 40 iterations a load step until one landed within it; with this one a
/// vertex within `1e-8 h` of a window edge is on it, so the thin cuts whose derivatives
/// round-off spoils are not made, and every step converges in 5 or 6 iterations
/// (`tests/finite3d_mortar.rs`). The price: an overlap up to
/// `1e-8 h` wider or narrower than the exact one, a relative change of the rows below `1e-8`
/// (none where edges are flush or farther apart than that).
pub(crate) const CLIP_TOLERANCE: f64 = 1e-8;

/// One side of a 3D interface: facets of one kind, their node ids and coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct FacetSet3 {
    /// The facets' 2D reference element (`Q4` = Quad4, `T3` = Tri3, `Q9` = Quad9, `T6` =
    /// Tri6).
    pub kind: ElementKind,
    /// Node ids of each facet, in the reference element's order (counter-clockwise seen from
    /// outside the body, so `x_xi x x_eta` is the outward normal).
    pub facets: Vec<Vec<usize>>,
    /// Reference coordinates of each facet's nodes (the same order).
    pub coords: Vec<Vec<[f64; 3]>>,
}

impl FacetSet3 {
    /// The facet set, or the reason it cannot take part in the 3D mortar: an unsupported
    /// facet kind, facets and coordinates of different lengths, non-finite coordinates, a
    /// node given two positions, or a degenerate facet.
    pub fn new(
        kind: ElementKind,
        facets: Vec<Vec<usize>>,
        coords: Vec<Vec<[f64; 3]>>,
    ) -> Result<Self, String> {
        supported(kind)?;
        if facets.len() != coords.len() {
            return Err(format!(
                "{} facets but {} coordinate lists: give one list of node coordinates per facet",
                facets.len(),
                coords.len()
            ));
        }
        if facets.is_empty() {
            return Err("the facet set is empty: name a surface with at least one facet".into());
        }
        let n = kind.node_count();
        let mut seen: HashMap<usize, [f64; 3]> = HashMap::new();
        let size = coords
            .iter()
            .flatten()
            .flat_map(|p| p.iter())
            .fold(0.0f64, |a, v| a.max(v.abs()));
        for (f, (ids, xs)) in facets.iter().zip(&coords).enumerate() {
            if ids.len() != n || xs.len() != n {
                return Err(format!(
                    "facet {f} has {} node ids and {} coordinates; a {kind:?} facet has {n}",
                    ids.len(),
                    xs.len()
                ));
            }
            for (&id, x) in ids.iter().zip(xs) {
                if x.iter().any(|v| !v.is_finite()) {
                    return Err(format!(
                        "facet {f}: node {id} has a non-finite coordinate {x:?}"
                    ));
                }
                if let Some(y) = seen.insert(id, *x) {
                    if distance(*x, y) > 1e-12 * size.max(1e-300) {
                        return Err(format!(
                            "node {id} has two positions, {y:?} and {x:?} (facet {f}): one node id, one position"
                        ));
                    }
                }
            }
            let (_, normal) = centre_and_normal(kind, xs)
                .map_err(|why| format!("facet {f} (nodes {ids:?}): {why}"))?;
            debug_assert!(normal.iter().all(|v| v.is_finite()));
        }
        Ok(FacetSet3 {
            kind,
            facets,
            coords,
        })
    }

    /// The facet set of `facets` of a 3D mesh (node ids are the mesh's), or why not (see
    /// [`FacetSet3::new`]).
    pub fn from_mesh(mesh: &Mesh3, facets: &[Facet]) -> Result<Self, String> {
        let ids: Vec<Vec<usize>> = facets.iter().map(|&f| mesh.facet_nodes(f)).collect();
        let coords = ids
            .iter()
            .map(|f| f.iter().map(|&n| mesh.nodes[n]).collect())
            .collect();
        FacetSet3::new(mesh.kind.facet_kind(), ids, coords)
    }

    /// Axis-aligned bounding boxes of the facets, `[lo, hi]`.
    pub fn boxes(&self) -> Vec<[[f64; 3]; 2]> {
        self.coords.iter().map(|c| bounding_box(c)).collect()
    }

    /// The largest facet diameter (the largest distance between two of a facet's nodes).
    pub fn facet_size(&self) -> f64 {
        self.coords.iter().map(|c| diameter(c)).fold(0.0, f64::max)
    }

    /// Each node's position (from the first facet that names it).
    pub fn positions(&self) -> BTreeMap<usize, [f64; 3]> {
        let mut out = BTreeMap::new();
        for (ids, xs) in self.facets.iter().zip(&self.coords) {
            for (&id, &x) in ids.iter().zip(xs) {
                out.entry(id).or_insert(x);
            }
        }
        out
    }
}

/// Whether the 3D mortar is built for facets of `kind`, the reason where not: it is built for
/// every facet of the 3D elements (Quad4, Tri3, Quad9 and Tri6).
pub fn supported(kind: ElementKind) -> Result<(), String> {
    match kind {
        ElementKind::Q4 | ElementKind::T3 | ElementKind::Q9 | ElementKind::T6 => Ok(()),
    }
}

/// One integration cell: a clip polygon of a slave facet against one master facet, in 3D on
/// the slave facet's auxiliary plane.
#[derive(Clone, Debug, PartialEq)]
pub struct IntegrationCell {
    pub slave_facet: usize,
    pub master_facet: usize,
    /// The clip polygon's vertices (counter-clockwise seen along the slave's outward normal).
    pub polygon: Vec<[f64; 3]>,
    /// Its area.
    pub area: f64,
}

/// The mortar matrices of an interface and the cells they were integrated on.
#[derive(Clone, Debug, PartialEq)]
pub struct MortarIntegrals3 {
    /// `D_jk` (slave-slave), by slave node `j`.
    pub d: MortarMatrix3,
    /// `M_jl` (slave-master), by slave node `j`.
    pub m: MortarMatrix3,
    /// The multiplier mass `int Phi_j Phi_k dA` (slave-slave) over the same cells, by slave
    /// node `j`: `D` itself where the multiplier basis is the shape basis (standard
    /// multipliers on Quad4, Tri3, Quad9), `int N~_j N~_k` for standard multipliers on Tri6.
    pub multiplier_mass: MortarMatrix3,
    /// Every non-empty clip polygon.
    pub cells: Vec<IntegrationCell>,
    /// The covered tributary of each slave node facet by facet, `(facet, int N_a dA)` over the
    /// clip polygons of each slave facet (what [`crate::contact::Constraint::cover`] holds for
    /// a mortar row: the whole tributary where a facet is wholly covered).
    pub cover: BTreeMap<usize, Vec<(usize, f64)>>,
}

/// The auxiliary plane of a slave facet: origin and orthonormal in-plane axes (`t_1 x t_2`
/// is the facet's unit normal at its centre).
#[derive(Copy, Clone, Debug)]
struct AuxiliaryPlane {
    origin: [f64; 3],
    axes: [[f64; 3]; 2],
}

impl AuxiliaryPlane {
    fn new(origin: [f64; 3], normal: [f64; 3]) -> Self {
        // the in-plane axis: the coordinate axis least aligned with the normal, made orthogonal
        let k = (0..3)
            .min_by(|&a, &b| normal[a].abs().total_cmp(&normal[b].abs()))
            .unwrap_or(0);
        let mut e = [0.0; 3];
        e[k] = 1.0;
        let t1 = unit(sub(e, scale(normal, dot(e, normal))));
        let t2 = cross(normal, t1);
        AuxiliaryPlane {
            origin,
            axes: [t1, t2],
        }
    }

    /// In-plane coordinates of `x` projected along the normal.
    fn project(&self, x: [f64; 3]) -> [f64; 2] {
        let d = sub(x, self.origin);
        [dot(d, self.axes[0]), dot(d, self.axes[1])]
    }

    /// The 3D point of in-plane coordinates `p`.
    fn lift(&self, p: [f64; 2]) -> [f64; 3] {
        add(
            self.origin,
            add(scale(self.axes[0], p[0]), scale(self.axes[1], p[1])),
        )
    }
}

/// Shape functions (at most 9) of a facet at `xi`, and their natural derivatives.
fn shape(kind: ElementKind, xi: [f64; 2]) -> ([f64; MAX_NODES], [[f64; 2]; MAX_NODES]) {
    let mut n = [0.0; MAX_NODES];
    let mut dn = [[0.0; 2]; MAX_NODES];
    kind.shape(xi, &mut n, &mut dn);
    (n, dn)
}

/// The basis the multipliers of a slave facet are built on, at `xi` (module notes,
/// **Multipliers**): the facet's shape functions `N_k`, except on Tri6, where it is the
/// modified basis `N~` of [`FacetShape::weight_basis`] (corners `N_v + (N_e + N_e') / 5`,
/// mid-edge nodes `3/5 N_e`).
fn multiplier_basis(kind: ElementKind, xi: [f64; 2]) -> [f64; MAX_NODES] {
    let mut m = [0.0; MAX_NODES];
    <ElementKind as FacetShape<3>>::weight_basis(kind, xi, &mut m[..kind.node_count()]);
    m
}

/// The centre `x(xi_c)` of a facet and its outward unit normal there, or why it has none.
fn centre_and_normal(kind: ElementKind, xs: &[[f64; 3]]) -> Result<([f64; 3], [f64; 3]), String> {
    let (n, dn) = shape(kind, kind.centre());
    let mut x = [0.0; 3];
    let mut tangents = [[0.0; 3]; 2];
    for (a, p) in xs.iter().enumerate() {
        x = add(x, scale(*p, n[a]));
        for (t, d) in tangents.iter_mut().zip(dn[a]) {
            *t = add(*t, scale(*p, d));
        }
    }
    let normal = cross(tangents[0], tangents[1]);
    let length = norm(normal);
    let size = diameter(xs);
    if length.is_nan() || length <= 1e-12 * size * size {
        return Err(format!(
            "the facet is degenerate (its tangents at the centre are parallel, |x_xi x x_eta| = {length:e}); fix the mesh"
        ));
    }
    Ok((x, scale(normal, 1.0 / length)))
}

/// The projected facet map `xi -> sum_a N_a(xi) q_a` on in-plane corners `q`: its value and
/// Jacobian `[[dp0/dxi, dp0/deta], [dp1/dxi, dp1/deta]]`.
fn planar_map(kind: ElementKind, q: &[[f64; 2]], xi: [f64; 2]) -> ([f64; 2], [[f64; 2]; 2]) {
    let (n, dn) = shape(kind, xi);
    let mut p = [0.0; 2];
    let mut j = [[0.0; 2]; 2];
    for (a, qa) in q.iter().enumerate() {
        for r in 0..2 {
            p[r] += n[a] * qa[r];
            for c in 0..2 {
                j[r][c] += dn[a][c] * qa[r];
            }
        }
    }
    (p, j)
}

/// The natural coordinates of in-plane point `p` on the projected facet with nodes `q`:
/// closed form for Tri3, Newton from `start` for Quad4, Quad9 and Tri6. `None` if the map is
/// singular or Newton does not converge.
pub(crate) fn inverse_map(
    kind: ElementKind,
    q: &[[f64; 2]],
    p: [f64; 2],
    start: [f64; 2],
) -> Option<[f64; 2]> {
    let solve = |j: [[f64; 2]; 2], r: [f64; 2]| {
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let scale = (j[0][0].abs() + j[0][1].abs()) * (j[1][0].abs() + j[1][1].abs());
        (det.abs() > 1e-14 * scale).then(|| {
            [
                (j[1][1] * r[0] - j[0][1] * r[1]) / det,
                (-j[1][0] * r[0] + j[0][0] * r[1]) / det,
            ]
        })
    };
    match kind {
        ElementKind::T3 => {
            let j = [
                [q[1][0] - q[0][0], q[2][0] - q[0][0]],
                [q[1][1] - q[0][1], q[2][1] - q[0][1]],
            ];
            solve(j, [p[0] - q[0][0], p[1] - q[0][1]])
        }
        _ => {
            let mut xi = start;
            for _ in 0..NEWTON_STEPS {
                let (x, j) = planar_map(kind, q, xi);
                let step = solve(j, [p[0] - x[0], p[1] - x[1]])?;
                xi = [xi[0] + step[0], xi[1] + step[1]];
                if !(xi[0].is_finite() && xi[1].is_finite()) {
                    return None;
                }
                if step[0].abs().max(step[1].abs()) < NEWTON_TOLERANCE {
                    return Some(xi);
                }
            }
            None
        }
    }
}

/// Twice the signed area of a planar polygon (positive counter-clockwise).
pub(crate) fn twice_signed_area(polygon: &[[f64; 2]]) -> f64 {
    let k = polygon.len();
    (0..k)
        .map(|i| {
            let (a, b) = (polygon[i], polygon[(i + 1) % k]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum()
}

/// Whether a counter-clockwise polygon is strictly convex (every turn to the left, beyond
/// `tol` times the edge lengths' product).
pub(crate) fn is_convex(polygon: &[[f64; 2]], tol: f64) -> bool {
    let k = polygon.len();
    (0..k).all(|i| {
        let (a, b, c) = (polygon[i], polygon[(i + 1) % k], polygon[(i + 2) % k]);
        let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - b[0], c[1] - b[1]]);
        u[0] * v[1] - u[1] * v[0] > tol * u[0].hypot(u[1]) * v[0].hypot(v[1])
    })
}

/// The intersection of the polygon `subject` with the convex counter-clockwise polygon
/// `window` (Sutherland-Hodgman), both in the plane: counter-clockwise if `subject` is, with
/// vertices closer than `tol` merged; empty when the overlap has fewer than 3 vertices or no
/// area above `tol` squared (disjoint polygons, or touching along an edge or at a corner). A
/// point is inside a window edge when its signed distance from it is at least `-tol`;
/// intersection parameters are clamped to `[0, 1]`, so nearly parallel edges give no point
/// outside the segment.
pub fn clip_convex_polygons(subject: &[[f64; 2]], window: &[[f64; 2]], tol: f64) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = subject.to_vec();
    let k = window.len();
    for i in 0..k {
        if out.is_empty() {
            break;
        }
        let (a, b) = (window[i], window[(i + 1) % k]);
        let e = [b[0] - a[0], b[1] - a[1]];
        let length = e[0].hypot(e[1]);
        if length <= tol {
            continue;
        }
        let distance = |p: [f64; 2]| (e[0] * (p[1] - a[1]) - e[1] * (p[0] - a[0])) / length;
        let input = std::mem::take(&mut out);
        let m = input.len();
        for s in 0..m {
            let (p, q) = (input[s], input[(s + 1) % m]);
            let (dp, dq) = (distance(p), distance(q));
            let (p_in, q_in) = (dp >= -tol, dq >= -tol);
            if p_in {
                out.push(p);
            }
            if p_in != q_in {
                let t = (dp / (dp - dq)).clamp(0.0, 1.0);
                out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
            }
        }
    }
    // merge coincident neighbours (also the last with the first)
    let mut merged: Vec<[f64; 2]> = Vec::with_capacity(out.len());
    for p in out {
        if merged
            .last()
            .is_none_or(|l| (l[0] - p[0]).hypot(l[1] - p[1]) > tol)
        {
            merged.push(p);
        }
    }
    while merged.len() > 1 {
        let (f, l) = (merged[0], merged[merged.len() - 1]);
        if (f[0] - l[0]).hypot(f[1] - l[1]) > tol {
            break;
        }
        merged.pop();
    }
    if merged.len() < 3 || twice_signed_area(&merged).abs() <= 2.0 * tol * tol {
        return Vec::new();
    }
    merged
}

/// The dual coefficients `a_jk` of a slave facet whose projected nodes are `q` (see the
/// module notes): `A_e = D_e M_e^-1` over the facet in the auxiliary-plane measure, on the
/// multiplier basis (the shape functions `N_k`; the modified basis `N~_k` on Tri6), so
/// `Psi_j = sum_k a_jk N_k` (`sum_k a_jk N~_k` on Tri6).
pub fn dual_coefficients(
    kind: ElementKind,
    q: &[[f64; 2]],
) -> Result<[[f64; MAX_NODES]; MAX_NODES], String> {
    supported(kind)?;
    let n = kind.node_count();
    // exact for N_j N_k |J| on straight-sided facets: degree 2 (Tri3), (3, 3) (Quad4),
    // (7, 7) (Quad9); for Tri6 degree 6, exact also where the facet is curved in its plane
    // (N~_j N~_k of degree 4 times |J| of degree 2)
    let rule: Vec<QuadPoint> = match kind {
        ElementKind::T3 => triangle_rule(2),
        ElementKind::T6 => collapsed_triangle_rule(4),
        ElementKind::Q9 => gauss_square(4),
        ElementKind::Q4 => gauss_square(3),
    };
    let mut mass = DMatrix::<f64>::zeros(n, n);
    let mut lumped = vec![0.0; n];
    for qp in &rule {
        let values = multiplier_basis(kind, qp.xi);
        let (_, j) = planar_map(kind, q, qp.xi);
        let w = qp.weight * (j[0][0] * j[1][1] - j[0][1] * j[1][0]).abs();
        for a in 0..n {
            lumped[a] += w * values[a];
            for b in 0..n {
                mass[(a, b)] += w * values[a] * values[b];
            }
        }
    }
    let inverse = mass
        .try_inverse()
        .ok_or("the slave facet's mass matrix is singular (a degenerate facet); fix the mesh")?;
    let mut a = [[0.0; MAX_NODES]; MAX_NODES];
    for j in 0..n {
        for k in 0..n {
            a[j][k] = lumped[j] * inverse[(j, k)];
        }
    }
    Ok(a)
}

/// The pieces a facet is segmented by, each with its local nodes (counter-clockwise) and the
/// natural point the inverse map starts from (the piece's centre): the facet itself (Quad4,
/// Tri3), the four sub-quadrilaterals of a Quad9 through its mid-edge and centre nodes, or
/// the four sub-triangles of a Tri6 through its mid-edge nodes (Puso, Laursen and Solberg's
/// segmentation of quadratic facets; exact for straight-edged facets, chords of curved ones).
pub(crate) fn pieces(kind: ElementKind) -> &'static [(&'static [usize], [f64; 2])] {
    const QUAD4: [(&[usize], [f64; 2]); 1] = [(&[0, 1, 2, 3], [0.0, 0.0])];
    const TRI3: [(&[usize], [f64; 2]); 1] = [(&[0, 1, 2], [1.0 / 3.0, 1.0 / 3.0])];
    const QUAD9: [(&[usize], [f64; 2]); 4] = [
        (&[0, 4, 8, 7], [-0.5, -0.5]),
        (&[4, 1, 5, 8], [0.5, -0.5]),
        (&[8, 5, 2, 6], [0.5, 0.5]),
        (&[7, 8, 6, 3], [-0.5, 0.5]),
    ];
    // corners 0, 1, 2 at (0, 0), (1, 0), (0, 1); mid-edge nodes 3 (0-1), 4 (1-2), 5 (2-0)
    const TRI6: [(&[usize], [f64; 2]); 4] = [
        (&[0, 3, 5], [1.0 / 6.0, 1.0 / 6.0]),
        (&[3, 1, 4], [2.0 / 3.0, 1.0 / 6.0]),
        (&[5, 4, 2], [1.0 / 6.0, 2.0 / 3.0]),
        (&[3, 4, 5], [1.0 / 3.0, 1.0 / 3.0]),
    ];
    match kind {
        ElementKind::Q9 => &QUAD9,
        ElementKind::T6 => &TRI6,
        ElementKind::T3 => &TRI3,
        ElementKind::Q4 => &QUAD4,
    }
}

/// A triangle of a cell: its first corner, its two edge vectors from there, its area.
struct CellTriangle {
    corner: [f64; 2],
    edges: [[f64; 2]; 2],
    area: f64,
}

impl CellTriangle {
    /// The in-plane point of natural coordinates `[r, t]` on the reference triangle.
    fn point(&self, [r, t]: [f64; 2]) -> [f64; 2] {
        let [e1, e2] = self.edges;
        [
            self.corner[0] + r * e1[0] + t * e2[0],
            self.corner[1] + r * e1[1] + t * e2[1],
        ]
    }
}

/// The triangles of a convex counter-clockwise polygon about its vertex average (degenerate
/// ones left out).
fn fan(polygon: &[[f64; 2]]) -> Vec<CellTriangle> {
    let k = polygon.len();
    let centroid = polygon
        .iter()
        .fold([0.0; 2], |s, p| [s[0] + p[0], s[1] + p[1]])
        .map(|v| v / k as f64);
    (0..k)
        .filter_map(|i| {
            let (a, b) = (polygon[i], polygon[(i + 1) % k]);
            let e1 = [a[0] - centroid[0], a[1] - centroid[1]];
            let e2 = [b[0] - centroid[0], b[1] - centroid[1]];
            let area = 0.5 * (e1[0] * e2[1] - e1[1] * e2[0]);
            (area > 0.0).then_some(CellTriangle {
                corner: centroid,
                edges: [e1, e2],
                area,
            })
        })
        .collect()
}

/// The rule on each cell triangle (weights summing to 1/2): degree 2 between Tri3 facets,
/// degree 5 (Radon's 7 points) where a Quad4 or a Tri6 takes part and no Quad9 (at most
/// quadratic times quadratic, degree 4), degree 8 where a Quad9 does (biquadratic times
/// biquadratic: the collapsed 5 x 5 Gauss product, see [`collapsed_triangle_rule`]).
pub(crate) fn cell_rule(slave: ElementKind, master: ElementKind) -> Vec<QuadPoint> {
    if slave == ElementKind::Q9 || master == ElementKind::Q9 {
        collapsed_triangle_rule(5)
    } else if slave == ElementKind::T3 && master == ElementKind::T3 {
        triangle_rule(2)
    } else {
        triangle_rule(5)
    }
}

/// Points per direction of the collapsed Gauss product for cells where a Quad4 facet that is
/// not a parallelogram or a curved Tri6 takes part (module notes, step 4).
pub const NON_AFFINE_POINTS: usize = 8;

/// Whether a facet's projected map (node positions `q` on the auxiliary plane) is affine: a
/// Tri3 always, a Quad4 when it is a parallelogram (`q0 - q1 + q2 - q3 = 0` to `1e-12` of its
/// diameter), a Tri6 when its mid-edge nodes are the midpoints of its corners (to `1e-12` of
/// its diameter). Quad9 facets keep their degree-8 rule on sub-quadrilaterals either way.
pub(crate) fn affine_in_plane(kind: ElementKind, q: &[[f64; 2]]) -> bool {
    if kind == ElementKind::T6 {
        let size = (0..3)
            .flat_map(|a| (0..3).map(move |b| (a, b)))
            .map(|(a, b)| (q[a][0] - q[b][0]).hypot(q[a][1] - q[b][1]))
            .fold(0.0, f64::max);
        // mid-edge node 3 + e joins corners e and e + 1
        return (0..3).all(|e| {
            let (a, b, m) = (q[e], q[(e + 1) % 3], q[3 + e]);
            (m[0] - 0.5 * (a[0] + b[0])).hypot(m[1] - 0.5 * (a[1] + b[1])) <= 1e-12 * size
        });
    }
    if kind != ElementKind::Q4 {
        return true;
    }
    let size = (0..4)
        .flat_map(|a| (0..4).map(move |b| (a, b)))
        .map(|(a, b)| (q[a][0] - q[b][0]).hypot(q[a][1] - q[b][1]))
        .fold(0.0, f64::max);
    let skew = (0..2)
        .map(|i| (q[0][i] - q[1][i] + q[2][i] - q[3][i]).abs())
        .fold(0.0, f64::max);
    skew <= 1e-12 * size
}

/// The `n x n` Gauss-Legendre product on the square mapped onto the reference triangle by
/// `(a, b) -> (a (1 - b), b)` (Duffy), weights times the map's Jacobian `1 - b`: a monomial of
/// total degree `d` becomes degree `d` in `a` and `d + 1` in `b`, so the rule is exact for
/// total degree `2 n - 2`.
pub fn collapsed_triangle_rule(n: usize) -> Vec<QuadPoint> {
    let g = gauss_legendre(n);
    let mut out = Vec::with_capacity(n * n);
    for &(t, wt) in &g {
        let b = 0.5 * (t + 1.0);
        for &(s, ws) in &g {
            let a = 0.5 * (s + 1.0);
            out.push(QuadPoint {
                xi: [a * (1.0 - b), b],
                weight: 0.25 * ws * wt * (1.0 - b),
            });
        }
    }
    out
}

/// The projected corners of facet `xs` on `plane`.
fn projected(plane: &AuxiliaryPlane, xs: &[[f64; 3]]) -> Vec<[f64; 2]> {
    xs.iter().map(|&x| plane.project(x)).collect()
}

/// The segment-based mortar integrals of `slave` against `master` (see the module notes).
/// `search_distance`: how far apart (in the bounding boxes) a master facet may still be a
/// candidate; `None` for the largest master facet's diameter.
pub fn mortar_integrals3(
    slave: &FacetSet3,
    master: &FacetSet3,
    space: MultiplierSpace,
    search_distance: Option<f64>,
) -> Result<MortarIntegrals3, String> {
    mortar_integrals3_with_points(slave, master, space, search_distance, NON_AFFINE_POINTS)
}

/// [`mortar_integrals3`] with `non_affine_points` points per direction of the collapsed Gauss
/// product on the cells of non-affine Quad4 and Tri6 pairs (module notes, step 4), to study
/// that rule.
pub fn mortar_integrals3_with_points(
    slave: &FacetSet3,
    master: &FacetSet3,
    space: MultiplierSpace,
    search_distance: Option<f64>,
    non_affine_points: usize,
) -> Result<MortarIntegrals3, String> {
    supported(slave.kind)?;
    supported(master.kind)?;
    let reach = match search_distance {
        Some(r) if r.is_finite() && r >= 0.0 => r,
        Some(r) => {
            return Err(format!(
                "the search distance {r} is not a finite non-negative length"
            ))
        }
        None => master.facet_size(),
    };
    let (ks, km) = (slave.kind, master.kind);
    let (ns, nm) = (ks.node_count(), km.node_count());
    let affine_rule = cell_rule(ks, km);
    let non_affine_rule = collapsed_triangle_rule(non_affine_points.max(1));
    let grid = BucketGrid::new(
        master
            .boxes()
            .into_iter()
            .map(|[lo, hi]| [lo.map(|v| v - reach), hi.map(|v| v + reach)])
            .collect(),
    );
    let mut d: MortarMatrix3 = BTreeMap::new();
    let mut m: MortarMatrix3 = BTreeMap::new();
    let mut multiplier_mass: MortarMatrix3 = BTreeMap::new();
    let mut cells = Vec::new();
    let mut cover: BTreeMap<usize, Vec<(usize, f64)>> = BTreeMap::new();
    for (f, xs) in slave.coords.iter().enumerate() {
        let (origin, normal) = centre_and_normal(ks, xs)
            .map_err(|why| format!("slave facet {f} (nodes {:?}): {why}", slave.facets[f]))?;
        let plane = AuxiliaryPlane::new(origin, normal);
        let q_slave = projected(&plane, xs);
        let size = diameter(xs);
        let tol = CLIP_TOLERANCE * size;
        let windows: Vec<(Vec<[f64; 2]>, [f64; 2])> = pieces(ks)
            .iter()
            .map(|(local, start)| (local.iter().map(|&a| q_slave[a]).collect(), *start))
            .collect();
        if windows.iter().any(|(w, _)| !is_convex(w, 1e-10)) {
            return Err(format!(
                "slave facet {f} (nodes {:?}) is not convex in its own plane (warped or folded); fix the mesh",
                slave.facets[f]
            ));
        }
        let slave_area = 0.5 * twice_signed_area(&q_slave[..ks.corner_count()]);
        let slave_affine = affine_in_plane(ks, &q_slave);
        let phi_of = match space {
            MultiplierSpace::Standard => None,
            MultiplierSpace::Dual => Some(
                dual_coefficients(ks, &q_slave).map_err(|why| format!("slave facet {f}: {why}"))?,
            ),
        };
        let [lo, hi] = bounding_box(xs);
        let mut d_local = [[0.0; MAX_NODES]; MAX_NODES];
        let mut mass_local = [[0.0; MAX_NODES]; MAX_NODES];
        let mut cover_local = [0.0; MAX_NODES];
        let mut m_local: Vec<(usize, [[f64; MAX_NODES]; MAX_NODES])> = Vec::new();
        // the cube about the slave box's centre holds the box; keep the boxes that meet it
        let centre: [f64; 3] = std::array::from_fn(|i| 0.5 * (lo[i] + hi[i]));
        let half = (0..3).map(|i| 0.5 * (hi[i] - lo[i])).fold(0.0, f64::max);
        let candidates = grid.query(centre, half).into_iter().filter(|&c| {
            let [blo, bhi] = grid.item_box(c);
            (0..3).all(|i| blo[i] <= hi[i] && lo[i] <= bhi[i])
        });
        for c in candidates {
            let q_master = projected(&plane, &master.coords[c]);
            // a master facet facing the slave one projects clockwise; edge-on or back: skipped
            let master_area = 0.5 * twice_signed_area(&q_master[..km.corner_count()]);
            if -master_area <= 0.5e-9 * twice_area_3d(km, &master.coords[c]) {
                continue;
            }
            let rule = if slave_affine && affine_in_plane(km, &q_master) {
                &affine_rule
            } else {
                &non_affine_rule
            };
            let mut m_facet = [[0.0; MAX_NODES]; MAX_NODES];
            let mut overlaps = false;
            for (local, start_m) in pieces(km) {
                let subject: Vec<[f64; 2]> = local.iter().rev().map(|&a| q_master[a]).collect();
                for (window, start_s) in &windows {
                    let clipped = clip_convex_polygons(&subject, window, tol);
                    if clipped.len() < 3 || 0.5 * twice_signed_area(&clipped) <= 1e-12 * slave_area
                    {
                        continue;
                    }
                    if subject.len() == 4 && !is_convex(&subject, 1e-10) {
                        return Err(format!(
                            "master facet {c} (nodes {:?}) projects onto the plane of slave facet {f} as a non-convex quadrilateral (warped, or nearly edge-on); refine the mesh",
                            master.facets[c]
                        ));
                    }
                    overlaps = true;
                    let mut area = 0.0;
                    for triangle in fan(&clipped) {
                        area += triangle.area;
                        for qp in rule {
                            let p = triangle.point(qp.xi);
                            let w = qp.weight * 2.0 * triangle.area;
                            let xi_s = inverse_map(ks, &q_slave, p, *start_s).ok_or_else(|| {
                                format!("the point {:?} of slave facet {f} has no natural coordinates on it (the inverse map did not converge); fix the mesh", plane.lift(p))
                            })?;
                            let xi_m = inverse_map(km, &q_master, p, *start_m).ok_or_else(|| {
                                format!("the point {:?} of slave facet {f} has no natural coordinates on master facet {c} (the inverse map did not converge); fix the mesh", plane.lift(p))
                            })?;
                            let (n_s, _) = shape(ks, xi_s);
                            let (n_m, _) = shape(km, xi_m);
                            let basis = multiplier_basis(ks, xi_s);
                            let phi = multiplier_values(ns, &basis, phi_of.as_ref());
                            for j in 0..ns {
                                cover_local[j] += w * n_s[j];
                                for k in 0..ns {
                                    d_local[j][k] += w * phi[j] * n_s[k];
                                    mass_local[j][k] += w * phi[j] * phi[k];
                                }
                                for l in 0..nm {
                                    m_facet[j][l] += w * phi[j] * n_m[l];
                                }
                            }
                        }
                    }
                    cells.push(IntegrationCell {
                        slave_facet: f,
                        master_facet: c,
                        polygon: clipped.iter().map(|&p| plane.lift(p)).collect(),
                        area,
                    });
                }
            }
            if overlaps {
                m_local.push((c, m_facet));
            }
        }
        if m_local.is_empty() {
            continue;
        }
        let ids = &slave.facets[f];
        for j in 0..ns {
            cover.entry(ids[j]).or_default().push((f, cover_local[j]));
            let dj = d.entry(ids[j]).or_default();
            for k in 0..ns {
                *dj.entry(ids[k]).or_default() += d_local[j][k];
            }
            let mass_j = multiplier_mass.entry(ids[j]).or_default();
            for k in 0..ns {
                *mass_j.entry(ids[k]).or_default() += mass_local[j][k];
            }
            let mj = m.entry(ids[j]).or_default();
            for (c, m_facet) in &m_local {
                for l in 0..nm {
                    *mj.entry(master.facets[*c][l]).or_default() += m_facet[j][l];
                }
            }
        }
    }
    Ok(MortarIntegrals3 {
        d,
        m,
        multiplier_mass,
        cells,
        cover,
    })
}

/// The multiplier functions at a point with multiplier-basis values `n` (the shape functions,
/// the modified basis on Tri6): `n` itself (standard) or `sum_k a_jk n_k` (dual).
fn multiplier_values(
    ns: usize,
    n: &[f64; MAX_NODES],
    dual: Option<&[[f64; MAX_NODES]; MAX_NODES]>,
) -> [f64; MAX_NODES] {
    match dual {
        None => *n,
        Some(a) => {
            let mut phi = [0.0; MAX_NODES];
            for j in 0..ns {
                phi[j] = (0..ns).map(|k| a[j][k] * n[k]).sum();
            }
            phi
        }
    }
}

/// The weighted gap of slave node `j`: `g~_j = nu . (sum_k D_jk x_k - sum_l M_jl x_l)` for
/// positions `slave_x`, `master_x` (by node id), or `None` where `j` has no `D` line.
pub fn weighted_gap(
    integrals: &MortarIntegrals3,
    j: usize,
    nu: [f64; 3],
    slave_x: &BTreeMap<usize, [f64; 3]>,
    master_x: &BTreeMap<usize, [f64; 3]>,
) -> Option<f64> {
    let dj = integrals.d.get(&j)?;
    let mut g = 0.0;
    for (k, w) in dj {
        g += w * dot(nu, slave_x[k]);
    }
    for (l, w) in integrals.m.get(&j).into_iter().flatten() {
        g -= w * dot(nu, master_x[l]);
    }
    Some(g)
}

/// Who the rows belong to and how their dofs are numbered (the caller's numbering).
pub struct RowNumbering<'a> {
    /// The slave body's index (for [`Constraint::slave_body`]).
    pub slave_body: usize,
    /// The contact pair's index (for [`Constraint::pair`]).
    pub pair: usize,
    /// 1 or 2 (two-pass: the roles swapped).
    pub pass: u8,
    /// The global dof of component `i` of slave node `n`: `slave_dof(n, i)`.
    pub slave_dof: &'a dyn Fn(usize, usize) -> usize,
    /// The global dof of component `i` of master node `n`.
    pub master_dof: &'a dyn Fn(usize, usize) -> usize,
    /// Tied rows: three bilateral rows per slave node (along `e_x`, `e_y`, `e_z`, zero initial
    /// gap) with the same weights, in place of the one frictionless row along `nu_j`.
    pub tied: bool,
}

/// The mortar rows of `slave` against `master` (see the module notes): one row per slave node
/// whose multiplier sees the master surface, in increasing node id. `normals` gives each slave
/// node's outward unit normal (the caller's nodal normals; any non-zero length is normalized).
/// Errors: unsupported facets, a missing or degenerate normal, no overlap at all.
pub fn mortar_rows3(
    slave: &FacetSet3,
    master: &FacetSet3,
    space: MultiplierSpace,
    normals: &BTreeMap<usize, [f64; 3]>,
    numbering: &RowNumbering,
    search_distance: Option<f64>,
) -> Result<(Vec<Constraint<3>>, MortarIntegrals3), String> {
    let integrals = mortar_integrals3(slave, master, space, search_distance)?;
    let slave_x = slave.positions();
    let master_x = master.positions();
    let smallest_area = 1e-12 * slave.facet_size().powi(2);
    let mut rows = Vec::new();
    for (&j, dj) in &integrals.d {
        let area: f64 = dj.values().sum();
        if area <= smallest_area {
            continue; // the node's multiplier sees no master surface
        }
        let n = *normals.get(&j).ok_or_else(|| {
            format!(
                "slave node {j} at {:?} has no nodal normal: give one for every node of the slave surface",
                slave_x[&j]
            )
        })?;
        let length = norm(n);
        if !(length.is_finite() && length > 0.0) {
            return Err(format!(
                "the nodal normal {n:?} of slave node {j} at {:?} is zero or not finite",
                slave_x[&j]
            ));
        }
        let n = scale(n, 1.0 / length);
        let nu = scale(n, -1.0);
        let slave_terms: Vec<(usize, f64)> = std::iter::once(j)
            .chain(dj.keys().copied().filter(|&k| k != j))
            .map(|k| (k, dj.get(&k).copied().unwrap_or(0.0) / area))
            .collect();
        let master_terms: Vec<(usize, f64)> = integrals
            .m
            .get(&j)
            .map(|mj| mj.iter().map(|(&l, &v)| (l, v / area)).collect())
            .unwrap_or_default();
        let mass: Vec<(usize, f64)> = match space {
            // Tri6: the modified basis is not the shape basis, the mass is not D
            MultiplierSpace::Standard if slave.kind == ElementKind::T6 => slave_terms
                .iter()
                .map(|&(k, _)| (k, integrals.multiplier_mass[&j][&k]))
                .collect(),
            MultiplierSpace::Standard => slave_terms.iter().map(|&(k, w)| (k, w * area)).collect(),
            MultiplierSpace::Dual => Vec::new(),
        };
        let directions: Vec<([f64; 3], f64)> = if numbering.tied {
            (0..3)
                .map(|i| {
                    let mut e = [0.0; 3];
                    e[i] = 1.0;
                    (e, 0.0)
                })
                .collect()
        } else {
            let g = weighted_gap(&integrals, j, nu, &slave_x, &master_x).unwrap_or(0.0);
            vec![(nu, g / area)]
        };
        for (direction, g0) in directions {
            let mut row = weighted_row(numbering, j, direction, &slave_terms, &master_terms);
            row.g0 = g0;
            row.area = area;
            row.slave_normal = n;
            row.point = slave_x[&j];
            row.bilateral = numbering.tied;
            row.mass = mass.clone();
            row.cover = integrals.cover.get(&j).cloned().unwrap_or_default();
            rows.push(row);
        }
    }
    if rows.is_empty() {
        return Err(
            "no slave facet overlaps a master facet facing it: check that the two surfaces face each other (outward normals opposed) and lie within the search distance".into(),
        );
    }
    Ok((rows, integrals))
}

/// A row `nu . (sum_k a_k u_k - sum_l b_l u_l)` (zero gap, unit area; the caller fills in the
/// rest); coefficients below `1e-12` of the largest are round-off of exact zeros and dropped.
/// The owner is the row's own node's dof with the largest `|nu_i|`.
fn weighted_row(
    numbering: &RowNumbering,
    node: usize,
    nu: [f64; 3],
    slave_terms: &[(usize, f64)],
    master_terms: &[(usize, f64)],
) -> Constraint<3> {
    let (dofs, coeffs) = gradient_coefficients(
        nu,
        slave_terms,
        |k, i| (numbering.slave_dof)(k, i),
        (0, master_terms),
        |_, l, i| (numbering.master_dof)(l, i),
    );
    let component = dominant_component(nu);
    Constraint {
        dofs,
        coeffs,
        g0: 0.0,
        area: 1.0,
        normal: nu,
        slave_normal: [0.0; 3],
        slave_body: numbering.slave_body,
        slave_node: node,
        point: [0.0; 3],
        pass: numbering.pass,
        owner: (numbering.slave_dof)(node, component),
        pair: numbering.pair,
        bilateral: false,
        mass: Vec::new(),
        // set by the caller from the mortar integrals (`MortarIntegrals3::cover`)
        cover: Vec::new(),
        tangents: Vec::new(),
        segment: None,
        nodal_normal: None,
        hessian: None,
        past_free_end: false,
    }
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    scale(a, 1.0 / norm(a))
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm(sub(a, b))
}

/// The largest distance between two of `xs`.
fn diameter(xs: &[[f64; 3]]) -> f64 {
    let mut d = 0.0f64;
    for (i, &a) in xs.iter().enumerate() {
        for &b in &xs[i + 1..] {
            d = d.max(distance(a, b));
        }
    }
    d
}

fn bounding_box(xs: &[[f64; 3]]) -> [[f64; 3]; 2] {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in xs {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    [lo, hi]
}

/// Twice the area of a facet's corner polygon in 3D (the norm of its vector area).
fn twice_area_3d(kind: ElementKind, xs: &[[f64; 3]]) -> f64 {
    let k = kind.corner_count();
    let mut v = [0.0; 3];
    for i in 0..k {
        v = add(v, cross(xs[i], xs[(i + 1) % k]));
    }
    norm(v)
}
