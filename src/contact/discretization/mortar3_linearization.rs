//! The consistent linearization of the 3D mortar gap between two deformable bodies in the
//! current configuration (finite kinematics): the exact gradient `b_j` and second derivative
//! `H_j` of each mortar row's weighted gap, which the Newton residual (`-lambda_j b_j`) and
//! tangent (`w b_j b_j^T - force H_j`) need.
//!
//! **The gap** (the [`super::mortar3`] module; Puso & Laursen 2004, *CMAME* 193, 601-629, the
//! auxiliary plane, projection and clipping; Popp, Gitterle, Gee & Wall 2010, *IJNME* 83,
//! 1428-1465, its consistent linearization in 3D). With the multiplier functions `Phi_j` of
//! slave node `j`, every quantity in the current positions `x`:
//!
//! ```text
//! g_j(x) = nu_j . S_j / A_j,      nu_j = -n_j / |n_j|,
//! S_j    = sum_(f, c) int_(cell f c) Phi_j(xi_s) (x_s(xi_s) - x_m(xi_m)) dA,
//! A_j    = sum_(f, c) int_(cell f c) Phi_j(xi_s) dA,
//! ```
//!
//! over the overlaps ("cells") of the slave facets `f` that hold `j` with the master facets `c`
//! (`S_j = sum_k D_jk x_k - sum_l M_jl x_l`, `A_j = sum_k D_jk`), `n_j` the slave surface's
//! nodal normal (`sum_f int M_j (x_xi x x_eta) dxi`, [`super::nodal_normal3`]). It depends on
//! the positions through
//!
//! * the **auxiliary plane** of each slave facet: its centre `x_0 = x(xi_c)` and unit normal
//!   `n_0 = x_xi x x_eta / |.|` there, with in-plane axes `t_1 = unit(e - (e . n_0) n_0)`,
//!   `t_2 = n_0 x t_1` (`e` the coordinate axis least aligned with `n_0`, held fixed);
//! * the **projection** of both facets' nodes onto it, `q = ((x - x_0) . t_1, (x - x_0) . t_2)`;
//! * the **clip polygon** (Sutherland-Hodgman): its vertices are projected nodes or
//!   intersections `p + t (q - p)`, `t = d_p / (d_p - d_q)` with the signed distances `d` of
//!   the current polygon's edge ends from a window edge, so every vertex is a function of the
//!   positions (an intersection of intersections too);
//! * the **cells**: triangles about the polygon's vertex average, whose points and weights
//!   (twice the triangle's area times the rule's weight) move with the vertices;
//! * the **natural coordinates** `xi_s`, `xi_m` of each cell point on the projected facets
//!   (closed form on Tri3; Quad4, Quad9 and Tri6: the root of `sum_a N_a(xi) q_a = p`);
//! * the **dual coefficients** `A_e = D_e M_e^-1` of each slave facet (dual multipliers), from
//!   its projected nodes; on Tri6 over the modified basis `N~` the multipliers are built on
//!   (standard and dual, [`super::mortar3`]'s notes, **Multipliers**);
//! * the nodal normal `n_j`.
//!
//! Which master facets overlap which slave facets, which window edges cut, which vertices
//! merge, which triangles of the fan are kept and which cell rule applies (affine or not) are
//! discrete choices of the segmentation, held fixed: every decision is taken on the real parts,
//! which are the `f64` segmentation's. The gap is smooth in `x` for fixed choices.
//!
//! **Derivatives by hyper-dual numbers.** Every step above is evaluated in second-order vector
//! dual numbers (`num_dual`), which carry the exact gradient and Hessian through the
//! arithmetic; the `f64` and the dual evaluation are one generic code path. The implicit roots
//! (the natural coordinates of Quad4, Quad9 and Tri6 points) are first found in `f64`
//! ([`super::mortar3`]'s inverse map) and then carried to second order by the implicit
//! function theorem in dual numbers ([`natural_point`]).
//!
//! **Two stages, joined by the chain rule.** Only the projection onto the auxiliary plane sees
//! the 3D positions: the clip polygon, the cells, their points and weights, the natural
//! coordinates and the dual coefficients are functions of the projected nodes `q` alone, and
//! the gap enters linearly, `S_j = sum_a D_ja x_a - sum_l M_jl x_l` with the planar integrals
//! `D_ja = int Phi_j N_a`, `M_jl = int Phi_j N_l` over the cell. So each cell is evaluated
//! (1) projected nodes in dual numbers over the cell's coordinates (24 for two Quad4 facets),
//! (2) `D` and `M` in dual numbers over the projected nodes (16 for two Quad4 facets: the
//! quadrature points' work, about 2.3 times cheaper per operation than over 24), (3) the
//! second-order chain rule `H = J^T H_q J + sum_k (df/dq_k) H q_k` back to the coordinates
//! ([`composed`]) and the products with `x`. Fixed-size dual numbers on the stack for Quad4 and
//! Tri3 facets, dynamic ones where a Quad9 or a Tri6 takes part. A row sums its cells' contributions
//! embedded into its own coordinates (the slave facets at `j` and the master facets they
//! overlap) and divides in the row's coordinates.
//!
//! Expected behaviour: at the configuration where they are built the rows' gaps are the
//! `f64` mortar rows' ([`super::mortar3::mortar_rows3`]) to round-off, and in the small-load
//! limit their gradients are the small-strain rows' coefficients; the gap is invariant under
//! rigid translations and rotations of both bodies, so the gradient's translations sum to zero
//! and its moment about any point is zero (linear and angular momentum of the contact
//! forces); the two-block patch test passes to round-off. The unit tests check `b_j` against
//! central differences of the gap of [`super::mortar3::mortar_rows3`] (another code path) and
//! `H_j` against central differences of `b_j`, on distorted, curved, non-matching Quad4, Tri3,
//! Quad9 and Tri6 interfaces; `tests/finite3d_mortar.rs` the Newton tangent and the patch test.

use super::geometry::TRI6_MODIFIED_ALPHA;
use super::mortar3::{
    affine_in_plane, cell_rule, collapsed_triangle_rule, inverse_map, is_convex, pieces,
    twice_signed_area, FacetSet3, MortarIntegrals3, CLIP_TOLERANCE, NON_AFFINE_POINTS,
};
use super::nodal_normal3::{
    cross3, dot3, embedded, linearized3, parts, real3, scaled3, seeded3, sub3, unit_nodal_normal,
    Ad, LinearizedGap3, Point3,
};
use crate::fe::{ElementKind, QuadPoint};
use crate::io::scene::MultiplierSpace;
use num_dual::{Dual2SVec64, DualNum};
use std::collections::{BTreeMap, BTreeSet};

/// A point of the auxiliary plane.
type Planar<T> = [T; 2];

fn zero<T: DualNum<Primitive = f64>>() -> T {
    T::from(0.0)
}

/// Shape functions of a facet at (dual) natural coordinates `xi`: the same functions as
/// [`ElementKind::shape`] (Tri3; Quad4 and Quad9 as products of 1D Lagrange polynomials on the
/// nodes of [`ElementKind::node_coordinates`]; Tri6 in the area coordinates `l = (1 - s - t, s,
/// t)`: corners `l_v (2 l_v - 1)`, mid-edge nodes `4 l_a l_b`).
fn shape_values<T: DualNum<Primitive = f64>>(kind: ElementKind, xi: &Planar<T>) -> Vec<T> {
    let [s, t] = xi;
    match kind {
        ElementKind::T3 => vec![-s.clone() - t + 1.0, s.clone(), t.clone()],
        ElementKind::Q4 => kind
            .node_coordinates()
            .iter()
            .map(|c| (s.clone() * c[0] + 1.0) * (t.clone() * c[1] + 1.0) * 0.25)
            .collect(),
        ElementKind::Q9 => {
            let quadratic = |node: f64, s: &T| -> T {
                if node < -0.5 {
                    s.clone() * (s.clone() - 1.0) * 0.5
                } else if node > 0.5 {
                    s.clone() * (s.clone() + 1.0) * 0.5
                } else {
                    -(s.clone() * s) + 1.0
                }
            };
            kind.node_coordinates()
                .iter()
                .map(|c| quadratic(c[0], s) * quadratic(c[1], t))
                .collect()
        }
        ElementKind::T6 => {
            let l = -s.clone() - t + 1.0;
            vec![
                l.clone() * (l.clone() * 2.0 - 1.0),
                s.clone() * (s.clone() * 2.0 - 1.0),
                t.clone() * (t.clone() * 2.0 - 1.0),
                l.clone() * s * 4.0,
                s.clone() * t * 4.0,
                t.clone() * l * 4.0,
            ]
        }
    }
}

/// The multiplier basis of a facet from its shape functions' values `n` (dual numbers): `n`
/// itself, but on Tri6 the modified basis of
/// [`super::geometry::FacetShape::weight_basis`] (corners
/// `N_v + alpha (N_e + N_e')`, mid-edge nodes `(1 - 2 alpha) N_e`,
/// [`super::geometry::TRI6_MODIFIED_ALPHA`]), as [`super::mortar3`] builds its multipliers.
fn multiplier_values<T: DualNum<Primitive = f64>>(kind: ElementKind, mut n: Vec<T>) -> Vec<T> {
    if kind == ElementKind::T6 {
        let a = TRI6_MODIFIED_ALPHA;
        let (m3, m4, m5) = (n[3].clone(), n[4].clone(), n[5].clone());
        n[0] += (m3.clone() + &m5) * a;
        n[1] += (m3 + &m4) * a;
        n[2] += (m4 + m5) * a;
        for v in &mut n[3..6] {
            *v = v.clone() * (1.0 - 2.0 * a);
        }
    }
    n
}

/// The projected facet map `xi -> sum_a N_a(xi) q_a` at (dual) `xi` and its Jacobian
/// `[[dp0/dxi, dp0/deta], [dp1/dxi, dp1/deta]]`, by the derivative of the dual shape
/// functions (first-order duals over the two natural coordinates would do; the derivatives
/// come from the `f64` shape derivatives' formulas instead, written out here).
fn planar_map<T: DualNum<Primitive = f64>>(
    kind: ElementKind,
    q: &[Planar<T>],
    xi: &Planar<T>,
) -> (Planar<T>, [[T; 2]; 2]) {
    let n = shape_values(kind, xi);
    let dn = shape_derivatives(kind, xi);
    let mut p = [zero::<T>(), zero::<T>()];
    let mut j = [[zero::<T>(), zero::<T>()], [zero::<T>(), zero::<T>()]];
    for (a, qa) in q.iter().enumerate() {
        for r in 0..2 {
            p[r] += n[a].clone() * &qa[r];
            for c in 0..2 {
                j[r][c] += dn[a][c].clone() * &qa[r];
            }
        }
    }
    (p, j)
}

/// The natural derivatives `[dN_a/dxi, dN_a/deta]` of [`shape_values`].
fn shape_derivatives<T: DualNum<Primitive = f64>>(
    kind: ElementKind,
    xi: &Planar<T>,
) -> Vec<[T; 2]> {
    let [s, t] = xi;
    match kind {
        ElementKind::T3 => vec![
            [T::from(-1.0), T::from(-1.0)],
            [T::from(1.0), zero()],
            [zero(), T::from(1.0)],
        ],
        ElementKind::Q4 => kind
            .node_coordinates()
            .iter()
            .map(|c| {
                [
                    (t.clone() * c[1] + 1.0) * (0.25 * c[0]),
                    (s.clone() * c[0] + 1.0) * (0.25 * c[1]),
                ]
            })
            .collect(),
        ElementKind::Q9 => {
            let quadratic = |node: f64, s: &T| -> (T, T) {
                if node < -0.5 {
                    (s.clone() * (s.clone() - 1.0) * 0.5, s.clone() - 0.5)
                } else if node > 0.5 {
                    (s.clone() * (s.clone() + 1.0) * 0.5, s.clone() + 0.5)
                } else {
                    (-(s.clone() * s) + 1.0, s.clone() * -2.0)
                }
            };
            kind.node_coordinates()
                .iter()
                .map(|c| {
                    let (ls, dls) = quadratic(c[0], s);
                    let (lt, dlt) = quadratic(c[1], t);
                    [dls * &lt, ls * dlt]
                })
                .collect()
        }
        ElementKind::T6 => {
            let l = -s.clone() - t + 1.0;
            let corner = |v: &T| v.clone() * 4.0 - 1.0;
            [
                [-corner(&l), -corner(&l)],
                [corner(s), zero()],
                [zero(), corner(t)],
                [(l.clone() - s) * 4.0, s.clone() * -4.0],
                [t.clone() * 4.0, s.clone() * 4.0],
                [t.clone() * -4.0, (l - t) * 4.0],
            ]
            .into_iter()
            .collect()
        }
    }
}

/// `J^-1 r` for a 2 x 2 matrix.
fn solve2<T: DualNum<Primitive = f64>>(j: &[[T; 2]; 2], r: &Planar<T>) -> Planar<T> {
    let det = j[0][0].clone() * &j[1][1] - j[0][1].clone() * &j[1][0];
    [
        (j[1][1].clone() * &r[0] - j[0][1].clone() * &r[1]) / &det,
        (-(j[1][0].clone() * &r[0]) + j[0][0].clone() * &r[1]) / &det,
    ]
}

/// The natural second derivatives `[d2N_a/dxi2, d2N_a/dxi deta, d2N_a/deta2]` of
/// [`shape_values`] at the real point `xi` (zero on Tri3).
fn shape_second_derivatives(kind: ElementKind, xi: [f64; 2]) -> Vec<[f64; 3]> {
    match kind {
        ElementKind::T3 => vec![[0.0; 3]; 3],
        ElementKind::Q4 => kind
            .node_coordinates()
            .iter()
            .map(|c| [0.0, 0.25 * c[0] * c[1], 0.0])
            .collect(),
        ElementKind::Q9 => {
            // the 1D Lagrange polynomial on nodes -1, 0, 1 with its two derivatives
            let quadratic = |node: f64, s: f64| -> [f64; 3] {
                if node < -0.5 {
                    [0.5 * s * (s - 1.0), s - 0.5, 1.0]
                } else if node > 0.5 {
                    [0.5 * s * (s + 1.0), s + 0.5, 1.0]
                } else {
                    [1.0 - s * s, -2.0 * s, -2.0]
                }
            };
            kind.node_coordinates()
                .iter()
                .map(|c| {
                    let (ls, lt) = (quadratic(c[0], xi[0]), quadratic(c[1], xi[1]));
                    [ls[2] * lt[0], ls[1] * lt[1], ls[0] * lt[2]]
                })
                .collect()
        }
        // corners l (2 l - 1), mid-edge nodes 4 l_a l_b, in l = (1 - s - t, s, t)
        ElementKind::T6 => vec![
            [4.0, 4.0, 4.0],
            [4.0, 0.0, 0.0],
            [0.0, 0.0, 4.0],
            [-8.0, -4.0, 0.0],
            [0.0, 4.0, 0.0],
            [0.0, -4.0, -8.0],
        ],
    }
}

/// The natural coordinates of the (dual) in-plane point `p` on the projected facet `q`:
/// closed form on Tri3; on Quad4, Quad9 and Tri6 the `f64` root `xi_0` of [`inverse_map`] from
/// `start`, carried to second order (module notes): with `x_0`, `J_0` the map and its
/// Jacobian at `xi_0` (linear in `q`, the shape functions' values there `f64`) and `B` its
/// second derivative, `xi = xi_0 + d` solves `x_0 + J_0 d + B(d, d) / 2 = p` (exact to second
/// order: the third-order terms of the map vanish in second-order dual numbers), so
/// `d_1 = J_0^-1 (p - x_0)` is `d` to first order and `d = J_0^-1 (p - x_0 - B(d_1, d_1) / 2)`
/// to second. (Two Newton steps in dual numbers from `xi_0` give the same derivatives at about
/// three times the cost.)
fn natural_point<T: DualNum<Primitive = f64>>(
    kind: ElementKind,
    q: &[Planar<T>],
    p: &Planar<T>,
    start: [f64; 2],
) -> Option<Planar<T>> {
    if kind == ElementKind::T3 {
        let j = [
            [q[1][0].clone() - &q[0][0], q[2][0].clone() - &q[0][0]],
            [q[1][1].clone() - &q[0][1], q[2][1].clone() - &q[0][1]],
        ];
        return Some(solve2(
            &j,
            &[p[0].clone() - &q[0][0], p[1].clone() - &q[0][1]],
        ));
    }
    let q_re: Vec<[f64; 2]> = q.iter().map(|v| [v[0].re(), v[1].re()]).collect();
    let root = inverse_map(kind, &q_re, [p[0].re(), p[1].re()], start)?;
    let values = shape_values::<f64>(kind, &root);
    let derivatives = shape_derivatives::<f64>(kind, &root);
    let second = shape_second_derivatives(kind, root);
    let mut x0 = [zero::<T>(), zero::<T>()];
    let mut j0 = [[zero::<T>(), zero::<T>()], [zero::<T>(), zero::<T>()]];
    let mut curvature = [[0.0f64; 3]; 2];
    for (a, qa) in q.iter().enumerate() {
        for r in 0..2 {
            x0[r] += qa[r].clone() * values[a];
            for c in 0..2 {
                j0[r][c] += qa[r].clone() * derivatives[a][c];
            }
            for m in 0..3 {
                curvature[r][m] += second[a][m] * q_re[a][r];
            }
        }
    }
    let inverse_det = (j0[0][0].clone() * &j0[1][1] - j0[0][1].clone() * &j0[1][0]).recip();
    let apply = |r: &Planar<T>| -> Planar<T> {
        [
            (j0[1][1].clone() * &r[0] - j0[0][1].clone() * &r[1]) * &inverse_det,
            (j0[0][0].clone() * &r[1] - j0[1][0].clone() * &r[0]) * &inverse_det,
        ]
    };
    let residual = [p[0].clone() - &x0[0], p[1].clone() - &x0[1]];
    let d1 = apply(&residual);
    let (ss, st, tt) = (
        d1[0].clone() * &d1[0],
        d1[0].clone() * &d1[1],
        d1[1].clone() * &d1[1],
    );
    let bend = |b: &[f64; 3]| -> T {
        (ss.clone() * b[0] + st.clone() * (2.0 * b[1]) + tt.clone() * b[2]) * 0.5
    };
    let d = apply(&[
        residual[0].clone() - bend(&curvature[0]),
        residual[1].clone() - bend(&curvature[1]),
    ]);
    Some([d[0].clone() + root[0], d[1].clone() + root[1]])
}

/// The reals of a planar polygon.
fn real_polygon<T: DualNum<Primitive = f64>>(polygon: &[Planar<T>]) -> Vec<[f64; 2]> {
    polygon.iter().map(|p| [p[0].re(), p[1].re()]).collect()
}

/// [`super::mortar3::clip_convex_polygons`] in dual numbers: the same decisions (on the real
/// parts), every vertex a function of the positions (module notes).
fn clip<T: DualNum<Primitive = f64>>(
    subject: &[Planar<T>],
    window: &[Planar<T>],
    tol: f64,
) -> Vec<Planar<T>> {
    let mut out: Vec<Planar<T>> = subject.to_vec();
    let k = window.len();
    for i in 0..k {
        if out.is_empty() {
            break;
        }
        let (a, b) = (&window[i], &window[(i + 1) % k]);
        let e = [b[0].clone() - &a[0], b[1].clone() - &a[1]];
        let length = (e[0].clone() * &e[0] + e[1].clone() * &e[1]).sqrt();
        if length.re() <= tol {
            continue;
        }
        let distance = |p: &Planar<T>| -> T {
            (e[0].clone() * (p[1].clone() - &a[1]) - e[1].clone() * (p[0].clone() - &a[0]))
                / &length
        };
        let input = std::mem::take(&mut out);
        let m = input.len();
        for s in 0..m {
            let (p, q) = (&input[s], &input[(s + 1) % m]);
            let (dp, dq) = (distance(p), distance(q));
            let (p_in, q_in) = (dp.re() >= -tol, dq.re() >= -tol);
            if p_in {
                out.push(p.clone());
            }
            if p_in != q_in {
                let t = dp.clone() / (dp - dq);
                let t = if t.re() < 0.0 {
                    zero()
                } else if t.re() > 1.0 {
                    T::from(1.0)
                } else {
                    t
                };
                out.push([
                    p[0].clone() + t.clone() * (q[0].clone() - &p[0]),
                    p[1].clone() + t * (q[1].clone() - &p[1]),
                ]);
            }
        }
    }
    let close =
        |a: &Planar<T>, b: &Planar<T>| (a[0].re() - b[0].re()).hypot(a[1].re() - b[1].re()) <= tol;
    let mut merged: Vec<Planar<T>> = Vec::with_capacity(out.len());
    for p in out {
        if merged.last().is_none_or(|l| !close(l, &p)) {
            merged.push(p);
        }
    }
    while merged.len() > 1 && close(&merged[0], &merged[merged.len() - 1]) {
        merged.pop();
    }
    if merged.len() < 3 || twice_signed_area(&real_polygon(&merged)).abs() <= 2.0 * tol * tol {
        return Vec::new();
    }
    merged
}

/// The dual coefficients `a_jk` of a slave facet with projected nodes `q`
/// ([`super::mortar3::dual_coefficients`] in dual numbers): `A_e = D_e M_e^-1`, the inverse by
/// Gauss-Jordan elimination with partial pivoting (pivots chosen on the real parts).
fn dual_coefficients<T: DualNum<Primitive = f64>>(
    kind: ElementKind,
    q: &[Planar<T>],
) -> Option<Vec<Vec<T>>> {
    let n = kind.node_count();
    // the rules of `mortar3::dual_coefficients`
    let rule: Vec<QuadPoint> = match kind {
        ElementKind::T3 => crate::fe::triangle_rule(2),
        ElementKind::T6 => collapsed_triangle_rule(4),
        ElementKind::Q9 => crate::fe::gauss_square(4),
        ElementKind::Q4 => crate::fe::gauss_square(3),
    };
    let mut mass: Vec<Vec<T>> = vec![vec![zero(); n]; n];
    let mut lumped: Vec<T> = vec![zero(); n];
    for qp in &rule {
        let xi = [T::from(qp.xi[0]), T::from(qp.xi[1])];
        let values = multiplier_values(kind, shape_values(kind, &xi));
        let (_, j) = planar_map(kind, q, &xi);
        let det = j[0][0].clone() * &j[1][1] - j[0][1].clone() * &j[1][0];
        let w = det.abs() * qp.weight;
        for a in 0..n {
            lumped[a] += w.clone() * &values[a];
            for b in 0..n {
                mass[a][b] += w.clone() * &values[a] * &values[b];
            }
        }
    }
    // Gauss-Jordan on [mass | I]
    let mut inverse: Vec<Vec<T>> = (0..n)
        .map(|r| {
            (0..n)
                .map(|c| T::from(if r == c { 1.0 } else { 0.0 }))
                .collect()
        })
        .collect();
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&a, &b| mass[a][col].re().abs().total_cmp(&mass[b][col].re().abs()))?;
        if mass[pivot][col].re().abs() <= 1e-300 {
            return None;
        }
        mass.swap(col, pivot);
        inverse.swap(col, pivot);
        let d = mass[col][col].clone();
        for c in 0..n {
            mass[col][c] = mass[col][c].clone() / &d;
            inverse[col][c] = inverse[col][c].clone() / &d;
        }
        for r in 0..n {
            if r == col {
                continue;
            }
            let factor = mass[r][col].clone();
            for c in 0..n {
                let m = mass[col][c].clone() * &factor;
                mass[r][c] -= m;
                let i = inverse[col][c].clone() * &factor;
                inverse[r][c] -= i;
            }
        }
    }
    Some(
        (0..n)
            .map(|j| (0..n).map(|k| lumped[j].clone() * &inverse[j][k]).collect())
            .collect(),
    )
}

/// The auxiliary plane of the slave facet with nodes `xs` (current positions) and the
/// projections onto it of the slave facet's nodes and of the master facet's nodes `xm`
/// (module notes): `(q_slave, q_master)`.
fn projected_nodes<T: DualNum<Primitive = f64>>(
    ks: ElementKind,
    xs: &[Point3<T>],
    xm: &[Point3<T>],
) -> (Vec<Planar<T>>, Vec<Planar<T>>) {
    let centre = [T::from(ks.centre()[0]), T::from(ks.centre()[1])];
    let values = shape_values(ks, &centre);
    let derivatives = shape_derivatives(ks, &centre);
    let mut origin = [zero::<T>(), zero::<T>(), zero::<T>()];
    let mut tangents = [
        [zero::<T>(), zero::<T>(), zero::<T>()],
        [zero::<T>(), zero::<T>(), zero::<T>()],
    ];
    for (a, p) in xs.iter().enumerate() {
        for i in 0..3 {
            origin[i] += values[a].clone() * &p[i];
            for (t, d) in tangents.iter_mut().zip(&derivatives[a]) {
                t[i] += d.clone() * &p[i];
            }
        }
    }
    let scaled = cross3(&tangents[0], &tangents[1]);
    let normal = scaled3(&scaled, &dot3(&scaled, &scaled).sqrt().recip());
    let re_normal = real3(&normal);
    let axis = (0..3)
        .min_by(|&a, &b| re_normal[a].abs().total_cmp(&re_normal[b].abs()))
        .unwrap_or(0);
    let mut e: Point3<T> = [zero(), zero(), zero()];
    e[axis] = T::from(1.0);
    let t1 = sub3(&e, &scaled3(&normal, &normal[axis]));
    let t1 = scaled3(&t1, &dot3(&t1, &t1).sqrt().recip());
    let t2 = cross3(&normal, &t1);
    let project = |x: &Point3<T>| -> Planar<T> {
        let d = sub3(x, &origin);
        [dot3(&d, &t1), dot3(&d, &t2)]
    };
    (
        xs.iter().map(project).collect(),
        xm.iter().map(project).collect(),
    )
}

/// One cell's planar integrals for every node `j` of the slave facet: `D_ja = int Phi_j N_a dA`
/// over the slave facet's nodes `a` (`slave[j][a]`) and `M_jl = int Phi_j N_l dA` over the
/// master facet's nodes `l` (`master[j][l]`). Its shares of a row follow as
/// `A_j = sum_a D_ja`, `S_j = sum_a D_ja x_a - sum_l M_jl x_l`.
struct PlanarShare<T> {
    slave: Vec<Vec<T>>,
    master: Vec<Vec<T>>,
}

/// The planar integrals of the overlap of the slave facet and the master facet with projected
/// nodes `q_slave` and `q_master` on the slave facet's auxiliary plane (module notes; the steps
/// of [`super::mortar3::mortar_integrals3`] for one facet pair, the same decisions on the real
/// parts; `tol` the clipping tolerance). The polygon, the cells, their points and weights, the
/// natural coordinates and the dual coefficients are functions of the projected nodes only,
/// so derivatives over them carry through to the positions by the chain rule
/// ([`cell_parts`]).
fn planar_share<T: DualNum<Primitive = f64>>(
    ks: ElementKind,
    km: ElementKind,
    q_slave: &[Planar<T>],
    q_master: &[Planar<T>],
    tol: f64,
    space: MultiplierSpace,
) -> Result<PlanarShare<T>, String> {
    let (ns, nm) = (ks.node_count(), km.node_count());
    let re_slave = real_polygon(q_slave);
    let re_master = real_polygon(q_master);
    let slave_area = 0.5 * twice_signed_area(&re_slave[..ks.corner_count()]);
    let rule: Vec<QuadPoint> = if affine_in_plane(ks, &re_slave) && affine_in_plane(km, &re_master)
    {
        cell_rule(ks, km)
    } else {
        collapsed_triangle_rule(NON_AFFINE_POINTS)
    };
    let dual = match space {
        MultiplierSpace::Standard => None,
        MultiplierSpace::Dual => Some(dual_coefficients(ks, q_slave).ok_or(
            "the slave facet's mass matrix is singular (a degenerate facet); fix the mesh",
        )?),
    };
    let mut share = PlanarShare {
        slave: vec![vec![zero(); ns]; ns],
        master: vec![vec![zero(); nm]; ns],
    };
    for (local_m, start_m) in pieces(km) {
        let subject: Vec<Planar<T>> = local_m.iter().rev().map(|&a| q_master[a].clone()).collect();
        for (local_s, start_s) in pieces(ks) {
            let window: Vec<Planar<T>> = local_s.iter().map(|&a| q_slave[a].clone()).collect();
            let clipped = clip(&subject, &window, tol);
            let re_clipped = real_polygon(&clipped);
            if clipped.len() < 3 || 0.5 * twice_signed_area(&re_clipped) <= 1e-12 * slave_area {
                continue;
            }
            if subject.len() == 4 && !is_convex(&real_polygon(&subject), 1e-10) {
                return Err("a master facet projects onto the plane of a slave facet as a non-convex quadrilateral (warped, or nearly edge-on); refine the mesh".into());
            }
            // the fan about the vertex average
            let k = clipped.len();
            let centroid: Planar<T> = [
                clipped.iter().fold(zero::<T>(), |s, p| s + &p[0]) / k as f64,
                clipped.iter().fold(zero::<T>(), |s, p| s + &p[1]) / k as f64,
            ];
            for i in 0..k {
                let (a, b) = (&clipped[i], &clipped[(i + 1) % k]);
                let e1 = [a[0].clone() - &centroid[0], a[1].clone() - &centroid[1]];
                let e2 = [b[0].clone() - &centroid[0], b[1].clone() - &centroid[1]];
                let area = (e1[0].clone() * &e2[1] - e1[1].clone() * &e2[0]) * 0.5;
                if area.re() <= 0.0 {
                    continue;
                }
                for qp in &rule {
                    let [r, t] = qp.xi;
                    let p = [
                        centroid[0].clone() + e1[0].clone() * r + e2[0].clone() * t,
                        centroid[1].clone() + e1[1].clone() * r + e2[1].clone() * t,
                    ];
                    let w = area.clone() * (2.0 * qp.weight);
                    let xi_s = natural_point(ks, q_slave, &p, *start_s).ok_or(
                        "a point of a slave facet has no natural coordinates on it (the inverse map did not converge); fix the mesh",
                    )?;
                    let xi_m = natural_point(km, q_master, &p, *start_m).ok_or(
                        "a point of a slave facet has no natural coordinates on a master facet (the inverse map did not converge); fix the mesh",
                    )?;
                    let n_s = shape_values(ks, &xi_s);
                    let n_m = shape_values(km, &xi_m);
                    let basis = multiplier_values(ks, n_s.clone());
                    for j in 0..ns {
                        let phi = match &dual {
                            None => basis[j].clone(),
                            Some(a) => {
                                (0..ns).fold(zero::<T>(), |s, k| s + a[j][k].clone() * &basis[k])
                            }
                        };
                        let wj = w.clone() * phi;
                        for (d, n) in share.slave[j].iter_mut().zip(&n_s) {
                            *d += wj.clone() * n;
                        }
                        for (m, n) in share.master[j].iter_mut().zip(&n_m) {
                            *m += wj.clone() * n;
                        }
                    }
                }
            }
        }
    }
    Ok(share)
}

/// The largest distance between two of a facet's (real) nodes.
fn diameter<T: DualNum<Primitive = f64>>(xs: &[Point3<T>]) -> f64 {
    let mut d = 0.0f64;
    for (i, a) in xs.iter().enumerate() {
        for b in &xs[i + 1..] {
            let (a, b) = (real3(a), real3(b));
            d = d.max((0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt());
        }
    }
    d
}

/// A quantity as `f64` parts over some variables: (value, gradient, Hessian row-major).
type Parts = (f64, Vec<f64>, Vec<f64>);

/// A cell's share of the rows in `f64` parts over its facets' coordinates (slave facet's
/// nodes first, `3 k + i` for coordinate `i` of node `k`): per slave node, `A_j` and `S_j`.
struct CellParts {
    area: Vec<Parts>,
    weighted: Vec<[Parts; 3]>,
}

/// The parts of a second-order dual number of `N` variables (Hessian made exactly symmetric).
fn sized_parts<const N: usize>(g: &Dual2SVec64<N>) -> Parts {
    let gradient: Vec<f64> = match &g.v1.0 {
        Some(v) => v.iter().copied().collect(),
        None => vec![0.0; N],
    };
    let mut hessian = vec![0.0; N * N];
    if let Some(h) = &g.v2.0 {
        for a in 0..N {
            for c in 0..N {
                hessian[a * N + c] = 0.5 * (h[(a, c)] + h[(c, a)]);
            }
        }
    }
    (g.re, gradient, hessian)
}

/// The projected nodes (slave facet's first; `2 k + i` for coordinate `i` of node `k`) in
/// parts over the cell's coordinates `points`, in dual numbers of `N = 3 points.len()`
/// variables.
fn projected_parts_sized<const N: usize>(ks: ElementKind, points: &[[f64; 3]]) -> Vec<Parts> {
    let x: Vec<Point3<Dual2SVec64<N>>> = points
        .iter()
        .enumerate()
        .map(|(k, p)| {
            std::array::from_fn(|i| Dual2SVec64::<N>::from_re(p[i]).derivative(3 * k + i))
        })
        .collect();
    let ns = ks.node_count();
    let (q_slave, q_master) = projected_nodes(ks, &x[..ns], &x[ns..]);
    q_slave
        .iter()
        .chain(&q_master)
        .flat_map(|q| q.iter().map(sized_parts))
        .collect()
}

/// [`projected_parts_sized`] in dual numbers of a dynamic size.
fn projected_parts_dynamic(ks: ElementKind, points: &[[f64; 3]]) -> Vec<Parts> {
    let x = seeded3(points);
    let ns = ks.node_count();
    let (q_slave, q_master) = projected_nodes(ks, &x[..ns], &x[ns..]);
    q_slave
        .iter()
        .chain(&q_master)
        .flat_map(|q| q.iter().map(|v| parts(v, 3 * points.len())))
        .collect()
}

/// The planar integrals `(D, M)` in parts over the projected nodes `q` (slave facet's first;
/// `2 k + i`), in dual numbers of `P = 2 q.len()` variables.
fn planar_parts_sized<const P: usize>(
    ks: ElementKind,
    km: ElementKind,
    q: &[[f64; 2]],
    tol: f64,
    space: MultiplierSpace,
) -> Result<PlanarShare<Parts>, String> {
    let z: Vec<Planar<Dual2SVec64<P>>> = q
        .iter()
        .enumerate()
        .map(|(k, v)| {
            std::array::from_fn(|i| Dual2SVec64::<P>::from_re(v[i]).derivative(2 * k + i))
        })
        .collect();
    let ns = ks.node_count();
    let share = planar_share(ks, km, &z[..ns], &z[ns..], tol, space)?;
    Ok(PlanarShare {
        slave: share
            .slave
            .iter()
            .map(|r| r.iter().map(sized_parts).collect())
            .collect(),
        master: share
            .master
            .iter()
            .map(|r| r.iter().map(sized_parts).collect())
            .collect(),
    })
}

/// [`planar_parts_sized`] in dual numbers of a dynamic size.
fn planar_parts_dynamic(
    ks: ElementKind,
    km: ElementKind,
    q: &[[f64; 2]],
    tol: f64,
    space: MultiplierSpace,
) -> Result<PlanarShare<Parts>, String> {
    let variables = 2 * q.len();
    let z: Vec<Planar<Ad>> = q
        .iter()
        .enumerate()
        .map(|(k, v)| std::array::from_fn(|i| Ad::from_re(v[i]).derivative(variables, 2 * k + i)))
        .collect();
    let ns = ks.node_count();
    let share = planar_share(ks, km, &z[..ns], &z[ns..], tol, space)?;
    let to_parts = |v: &Ad| parts(v, variables);
    Ok(PlanarShare {
        slave: share
            .slave
            .iter()
            .map(|r| r.iter().map(to_parts).collect())
            .collect(),
        master: share
            .master
            .iter()
            .map(|r| r.iter().map(to_parts).collect())
            .collect(),
    })
}

/// The chain rule to second order: `f(z(x))` in parts over the `n` variables `x`, from `f`'s
/// parts over `z` and each `z_k`'s parts over `x`:
/// `grad = J^T grad_z f`, `H = J^T H_z f J + sum_k (df/dz_k) H z_k` with `J = dz/dx`.
fn composed(f: &Parts, inner: &[Parts], n: usize) -> Parts {
    let p = inner.len();
    let (value, gf, hf) = f;
    let mut gradient = vec![0.0; n];
    let mut hessian = vec![0.0; n * n];
    // H_z f J, p x n
    let mut hj = vec![0.0; p * n];
    for (k, (_, gk, hk)) in inner.iter().enumerate() {
        if gf[k] != 0.0 {
            for (g, d) in gradient.iter_mut().zip(gk) {
                *g += gf[k] * d;
            }
            for (h, d) in hessian.iter_mut().zip(hk) {
                *h += gf[k] * d;
            }
        }
        for l in 0..p {
            let c = hf[l * p + k];
            if c != 0.0 {
                for (t, d) in hj[l * n..(l + 1) * n].iter_mut().zip(gk) {
                    *t += c * d;
                }
            }
        }
    }
    for (l, (_, gl, _)) in inner.iter().enumerate() {
        for (a, &c) in gl.iter().enumerate() {
            if c != 0.0 {
                for (h, t) in hessian[a * n..(a + 1) * n]
                    .iter_mut()
                    .zip(&hj[l * n..(l + 1) * n])
                {
                    *h += c * t;
                }
            }
        }
    }
    (*value, gradient, hessian)
}

/// `total += sign f x_v` in parts over `n` variables, `x_v` the variable `v` (value `x`).
fn add_times_variable(total: &mut Parts, f: &Parts, sign: f64, x: f64, v: usize, n: usize) {
    total.0 += sign * f.0 * x;
    for (t, g) in total.1.iter_mut().zip(&f.1) {
        *t += sign * x * g;
    }
    total.1[v] += sign * f.0;
    for (t, h) in total.2.iter_mut().zip(&f.2) {
        *t += sign * x * h;
    }
    for (b, g) in f.1.iter().enumerate() {
        total.2[v * n + b] += sign * g;
        total.2[b * n + v] += sign * g;
    }
}

/// The share of the cell of a slave facet and a master facet with nodes `points` (the slave
/// facet's first) in `f64` parts over their coordinates (module notes): the projected nodes
/// in dual numbers over the coordinates, the planar integrals `D_ja`, `M_jl` in dual numbers
/// over the projected nodes (fewer variables: 16 instead of 24 for two Quad4 facets, where the
/// quadrature points' work is), joined by the chain rule ([`composed`]), then
/// `A_j = sum_a D_ja`, `S_j = sum_a D_ja x_a - sum_l M_jl x_l`. Dual numbers of a fixed size
/// on the stack where the pair of kinds has one here (Tri3 and Quad4 facets), of a dynamic
/// size otherwise (Quad9, Tri6).
fn cell_parts(
    ks: ElementKind,
    km: ElementKind,
    points: &[[f64; 3]],
    space: MultiplierSpace,
) -> Result<CellParts, String> {
    let ns = ks.node_count();
    let n = 3 * points.len();
    let projected = match n {
        18 => projected_parts_sized::<18>(ks, points),
        21 => projected_parts_sized::<21>(ks, points),
        24 => projected_parts_sized::<24>(ks, points),
        _ => projected_parts_dynamic(ks, points),
    };
    let q: Vec<[f64; 2]> = projected.chunks(2).map(|c| [c[0].0, c[1].0]).collect();
    let tol = CLIP_TOLERANCE * diameter(&points[..ns]);
    let planar = match 2 * points.len() {
        12 => planar_parts_sized::<12>(ks, km, &q, tol, space)?,
        14 => planar_parts_sized::<14>(ks, km, &q, tol, space)?,
        16 => planar_parts_sized::<16>(ks, km, &q, tol, space)?,
        _ => planar_parts_dynamic(ks, km, &q, tol, space)?,
    };
    let nothing = || -> Parts { (0.0, vec![0.0; n], vec![0.0; n * n]) };
    let mut cell = CellParts {
        area: Vec::with_capacity(ns),
        weighted: Vec::with_capacity(ns),
    };
    for j in 0..ns {
        let mut area = nothing();
        let mut weighted: [Parts; 3] = std::array::from_fn(|_| nothing());
        let terms = planar.slave[j]
            .iter()
            .enumerate()
            .map(|(a, d)| (d, 1.0, a))
            .chain(
                planar.master[j]
                    .iter()
                    .enumerate()
                    .map(|(l, m)| (m, -1.0, ns + l)),
            );
        for (coefficient, sign, k) in terms {
            let c = composed(coefficient, &projected, n);
            if sign > 0.0 {
                area.0 += c.0;
                for (t, g) in area.1.iter_mut().zip(&c.1) {
                    *t += g;
                }
                for (t, h) in area.2.iter_mut().zip(&c.2) {
                    *t += h;
                }
            }
            for (i, s) in weighted.iter_mut().enumerate() {
                add_times_variable(s, &c, sign, points[k][i], 3 * k + i, n);
            }
        }
        cell.area.push(area);
        cell.weighted.push(weighted);
    }
    Ok(cell)
}

/// The rows' gaps with their exact gradients and Hessians (module notes) for the slave nodes
/// `nodes`, at the positions of `slave` and `master` (current configuration), from the
/// overlaps the `f64` segmentation found (`integrals.cells`). `slave_dof(node, i)` and
/// `master_dof(node, i)` number the coordinates.
pub(crate) fn linearize_rows3(
    slave: &FacetSet3,
    master: &FacetSet3,
    space: MultiplierSpace,
    integrals: &MortarIntegrals3,
    nodes: &[usize],
    slave_dof: &dyn Fn(usize, usize) -> usize,
    master_dof: &dyn Fn(usize, usize) -> usize,
) -> Result<BTreeMap<usize, LinearizedGap3>, String> {
    let (ks, km) = (slave.kind, master.kind);
    let (ns, nm) = (ks.node_count(), km.node_count());
    let overlaps: BTreeSet<(usize, usize)> = integrals
        .cells
        .iter()
        .map(|c| (c.slave_facet, c.master_facet))
        .collect();
    // every cell of the requested rows once, over its two facets' coordinates
    let wanted: BTreeSet<usize> = nodes.iter().copied().collect();
    let mut cells: BTreeMap<(usize, usize), CellParts> = BTreeMap::new();
    for &(f, c) in &overlaps {
        if !slave.facets[f].iter().any(|n| wanted.contains(n)) {
            continue;
        }
        let mut points = slave.coords[f].clone();
        points.extend(master.coords[c].iter().copied());
        let share = cell_parts(ks, km, &points, space)
            .map_err(|why| format!("slave facet {f}, master facet {c}: {why}"))?;
        cells.insert((f, c), share);
    }
    let mut out = BTreeMap::new();
    for &j in nodes {
        // the row's nodes: (master side, id)
        let mut row_nodes: Vec<(bool, usize, [f64; 3])> = Vec::new();
        let mut local = |on_master: bool, id: usize, x: [f64; 3]| -> usize {
            match row_nodes.iter().position(|n| n.0 == on_master && n.1 == id) {
                Some(k) => k,
                None => {
                    row_nodes.push((on_master, id, x));
                    row_nodes.len() - 1
                }
            }
        };
        let facets: Vec<usize> = (0..slave.facets.len())
            .filter(|&f| slave.facets[f].contains(&j))
            .collect();
        let mut slave_local: Vec<Vec<usize>> = Vec::new();
        for &f in &facets {
            slave_local.push(
                (0..ns)
                    .map(|a| local(false, slave.facets[f][a], slave.coords[f][a]))
                    .collect(),
            );
        }
        let mut row_cells: Vec<((usize, usize), usize, Vec<usize>)> = Vec::new();
        for (e, &f) in facets.iter().enumerate() {
            let a = slave.facets[f]
                .iter()
                .position(|&n| n == j)
                .expect("the facet holds j");
            for &(_, c) in overlaps.range((f, 0)..(f + 1, 0)) {
                let mut map: Vec<usize> = slave_local[e]
                    .iter()
                    .flat_map(|&k| (0..3).map(move |i| 3 * k + i))
                    .collect();
                for l in 0..nm {
                    let k = local(true, master.facets[c][l], master.coords[c][l]);
                    map.extend((0..3).map(|i| 3 * k + i));
                }
                row_cells.push(((f, c), a, map));
            }
        }
        let x = seeded3(&row_nodes.iter().map(|n| n.2).collect::<Vec<_>>());
        let variables = x.len() * 3;
        let normal_facets: Vec<(Vec<Point3<Ad>>, usize)> = facets
            .iter()
            .enumerate()
            .map(|(e, &f)| {
                let a = slave.facets[f]
                    .iter()
                    .position(|&n| n == j)
                    .expect("the facet holds j");
                (slave_local[e].iter().map(|&k| x[k].clone()).collect(), a)
            })
            .collect();
        let n = unit_nodal_normal(ks, &normal_facets);
        let mut area = Ad::from(0.0);
        let mut weighted: Point3<Ad> = [Ad::from(0.0), Ad::from(0.0), Ad::from(0.0)];
        for (key, a, map) in &row_cells {
            let cell = &cells[key];
            let (v, g, h) = &cell.area[*a];
            area += embedded(*v, g, h, map, variables);
            for i in 0..3 {
                let (v, g, h) = &cell.weighted[*a][i];
                weighted[i] += embedded(*v, g, h, map, variables);
            }
        }
        // nu_j = -n_j: g_j = -(n_j . S_j) / A_j
        let g = -dot3(&n, &weighted) / area;
        let dofs = row_nodes
            .iter()
            .flat_map(|&(on_master, id, _)| {
                (0..3).map(move |i| {
                    if on_master {
                        master_dof(id, i)
                    } else {
                        slave_dof(id, i)
                    }
                })
            })
            .collect();
        out.insert(j, linearized3(&g, dofs));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::geometry::{FacetShape, Surface3};
    use super::super::mortar3::{mortar_rows3, RowNumbering};
    use super::*;
    use crate::fe::MAX_NODES;

    /// A grid surface of `kind` facets on `cells x cells` quadrilaterals (Tri3 and Tri6: each
    /// split in two; Quad9 and Tri6: `2 cells + 1` nodes a side) with node positions `at(u, v)` for grid
    /// parameters in `[0, 1]`; outward normal along `+z` (`up`) or `-z`.
    fn grid(
        kind: ElementKind,
        cells: usize,
        up: bool,
        at: &dyn Fn(f64, f64) -> [f64; 3],
    ) -> FacetSet3 {
        let quadratic = matches!(kind, ElementKind::Q9 | ElementKind::T6);
        let per = if quadratic { 2 } else { 1 };
        let n = per * cells + 1;
        let id = |i: usize, j: usize| j * n + i;
        let mut facets = Vec::new();
        for j in 0..cells {
            for i in 0..cells {
                let (i0, j0) = (per * i, per * j);
                let quad = [
                    id(i0, j0),
                    id(i0 + per, j0),
                    id(i0 + per, j0 + per),
                    id(i0, j0 + per),
                ];
                // a Quad9's nodes on the quadratic grids
                let mut f: Vec<usize> = match quadratic {
                    true => vec![
                        quad[0],
                        quad[1],
                        quad[2],
                        quad[3],
                        id(i0 + 1, j0),
                        id(i0 + 2, j0 + 1),
                        id(i0 + 1, j0 + 2),
                        id(i0, j0 + 1),
                        id(i0 + 1, j0 + 1),
                    ],
                    false => quad.to_vec(),
                };
                if !up {
                    // the same facet seen from below: corners reversed, mid-edges with them
                    f = match quadratic {
                        true => vec![f[0], f[3], f[2], f[1], f[7], f[6], f[5], f[4], f[8]],
                        false => vec![f[0], f[3], f[2], f[1]],
                    };
                }
                match kind {
                    ElementKind::T3 => {
                        facets.push(vec![f[0], f[1], f[2]]);
                        facets.push(vec![f[0], f[2], f[3]]);
                    }
                    // corners, then the mid-edge nodes 0-1, 1-2, 2-0 (the Quad9's centre on
                    // the diagonal)
                    ElementKind::T6 => {
                        facets.push(vec![f[0], f[1], f[2], f[4], f[5], f[8]]);
                        facets.push(vec![f[0], f[2], f[3], f[8], f[6], f[7]]);
                    }
                    _ => facets.push(f),
                }
            }
        }
        let step = 1.0 / (n - 1) as f64;
        let coords = facets
            .iter()
            .map(|f| {
                f.iter()
                    .map(|&k| at((k % n) as f64 * step, (k / n) as f64 * step))
                    .collect()
            })
            .collect();
        FacetSet3::new(kind, facets, coords).unwrap()
    }

    /// A curved master (`z` up) and a smaller, turned, curved slave above it (penetrating by
    /// up to about 0.03), neither matching the other, every node moved off the grid.
    fn curved_pair(kind: ElementKind, cells: usize) -> (FacetSet3, FacetSet3) {
        let master = grid(kind, cells, true, &|u, v| {
            let (x, y) = (u + 0.04 * (7.0 * v).sin(), v + 0.03 * (5.0 * u).cos());
            [x, y, 0.08 * (x - 0.5) * (y - 0.3) + 0.03 * x * x]
        });
        let (c, s) = (0.3f64.cos(), 0.3f64.sin());
        let slave = grid(kind, cells, false, &|u, v| {
            let (a, b) = (0.15 + 0.7 * u + 0.02 * (9.0 * v).sin(), 0.2 + 0.6 * v);
            let (x, y) = (
                0.5 + c * (a - 0.5) - s * (b - 0.5),
                0.5 + s * (a - 0.5) + c * (b - 0.5),
            );
            [
                x,
                y,
                0.08 * (x - 0.5) * (y - 0.3) + 0.03 * x * x - 0.03 + 0.04 * x * y,
            ]
        });
        (slave, master)
    }

    fn slave_dof(n: usize, i: usize) -> usize {
        3 * n + i
    }
    fn master_dof(n: usize, i: usize) -> usize {
        30_000 + 3 * n + i
    }

    /// The facet set with the coordinate of `dof` (numbered as above) moved by `h`.
    fn moved(set: &FacetSet3, master: bool, dof: usize, h: f64) -> FacetSet3 {
        let base = if master { 30_000 } else { 0 };
        let mut out = set.clone();
        if dof < base || (!master && dof >= 30_000) {
            return out;
        }
        let (node, i) = ((dof - base) / 3, (dof - base) % 3);
        for (f, ids) in set.facets.iter().enumerate() {
            for (a, &n) in ids.iter().enumerate() {
                if n == node {
                    out.coords[f][a][i] += h;
                }
            }
        }
        out
    }

    /// The `f64` mortar rows' gaps (`mortar3`, another code path) by slave node.
    fn f64_gaps(
        slave: &FacetSet3,
        master: &FacetSet3,
        space: MultiplierSpace,
    ) -> BTreeMap<usize, f64> {
        let surface = Surface3::from_facets(
            0,
            slave.kind,
            slave.facets.clone(),
            slave.coords.clone(),
            1.0,
        );
        let normals: BTreeMap<usize, [f64; 3]> =
            surface.nodes.iter().map(|(&n, d)| (n, d.normal)).collect();
        let numbering = RowNumbering {
            slave_body: 0,
            pair: 0,
            pass: 1,
            slave_dof: &slave_dof,
            master_dof: &master_dof,
            tied: false,
        };
        let (rows, _) =
            mortar_rows3(slave, master, space, &normals, &numbering, Some(0.5)).unwrap();
        rows.iter().map(|r| (r.slave_node, r.g0)).collect()
    }

    fn linearize(
        slave: &FacetSet3,
        master: &FacetSet3,
        space: MultiplierSpace,
        nodes: &[usize],
    ) -> BTreeMap<usize, LinearizedGap3> {
        let integrals =
            super::super::mortar3::mortar_integrals3(slave, master, space, Some(0.5)).unwrap();
        linearize_rows3(
            slave,
            master,
            space,
            &integrals,
            nodes,
            &slave_dof,
            &master_dof,
        )
        .unwrap()
    }

    /// On a curved, distorted, non-matching, penetrating interface (Quad4, Tri3, Quad9, Tri6;
    /// standard and dual multipliers): every row's gap is the `f64` mortar row's (1e-13), its
    /// gradient the central difference of the `f64` rows' gaps (1e-7 of the largest entry),
    /// its Hessian times three directions (Tri6: one) the central difference of the gradient
    /// along them (1e-6 of the largest entry); the gradient's translations sum to zero and its moment
    /// about the origin vanishes (1e-10: linear and angular momentum of the row's forces).
    #[test]
    fn rows_gradients_and_hessians_are_the_differences_of_the_f64_gaps() {
        let cases = [
            (ElementKind::Q4, MultiplierSpace::Standard),
            (ElementKind::Q4, MultiplierSpace::Dual),
            (ElementKind::T3, MultiplierSpace::Standard),
            (ElementKind::T3, MultiplierSpace::Dual),
            (ElementKind::Q9, MultiplierSpace::Standard),
            (ElementKind::T6, MultiplierSpace::Standard),
            (ElementKind::T6, MultiplierSpace::Dual),
        ];
        for (kind, space) in cases {
            // Tri6 on one cell a side (two facets: 16 pieces and 64 points a fan triangle per
            // facet pair make the dynamic dual numbers' cells the slowest), the rest on two
            let cells = if kind == ElementKind::T6 { 1 } else { 2 };
            let (slave, master) = curved_pair(kind, cells);
            let gaps = f64_gaps(&slave, &master, space);
            let nodes: Vec<usize> = gaps.keys().copied().collect();
            let start = std::time::Instant::now();
            let rows = linearize(&slave, &master, space, &nodes);
            let seconds = start.elapsed().as_secs_f64();
            let h = 1e-6;
            let (mut worst_gap, mut worst_b, mut worst_momentum) = (0.0f64, 0.0f64, 0.0f64);
            // the central differences of every f64 gap, one coordinate at a time
            let mut differences: BTreeMap<usize, BTreeMap<usize, f64>> = BTreeMap::new();
            let all_dofs: BTreeSet<usize> =
                rows.values().flat_map(|r| r.dofs.iter().copied()).collect();
            for &d in &all_dofs {
                let plus = f64_gaps(
                    &moved(&slave, false, d, h),
                    &moved(&master, true, d, h),
                    space,
                );
                let minus = f64_gaps(
                    &moved(&slave, false, d, -h),
                    &moved(&master, true, d, -h),
                    space,
                );
                for &j in &nodes {
                    differences
                        .entry(j)
                        .or_default()
                        .insert(d, (plus[&j] - minus[&j]) / (2.0 * h));
                }
            }
            for (&j, row) in &rows {
                worst_gap = worst_gap.max((row.gap - gaps[&j]).abs());
                let scale = row.gradient.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for (a, &d) in row.dofs.iter().enumerate() {
                    worst_b = worst_b.max((differences[&j][&d] - row.gradient[a]).abs() / scale);
                }
                // translations and rotations of both bodies leave the gap unchanged
                let (mut force, mut moment) = ([0.0; 3], [0.0; 3]);
                let positions: BTreeMap<usize, [f64; 3]> = slave
                    .positions()
                    .into_iter()
                    .map(|(n, x)| (3 * n, x))
                    .chain(
                        master
                            .positions()
                            .into_iter()
                            .map(|(n, x)| (30_000 + 3 * n, x)),
                    )
                    .collect();
                for (a, &d) in row.dofs.iter().enumerate() {
                    let i = d % 3;
                    let x = positions[&(d - i)];
                    force[i] += row.gradient[a];
                    let mut b = [0.0; 3];
                    b[i] = row.gradient[a];
                    moment[0] += x[1] * b[2] - x[2] * b[1];
                    moment[1] += x[2] * b[0] - x[0] * b[2];
                    moment[2] += x[0] * b[1] - x[1] * b[0];
                }
                for v in force.iter().chain(&moment) {
                    worst_momentum = worst_momentum.max(v.abs() / scale);
                }
            }
            // the Hessian of the first row along three directions
            let j = nodes[0];
            let row = &rows[&j];
            let v = row.dofs.len();
            let scale_h = row.hessian.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let mut worst_h = 0.0f64;
            // (Tri6: one direction; each is two linearizations of about 2 s)
            let directions = if kind == ElementKind::T6 { 1 } else { 3 };
            for k in 0..directions {
                let direction: Vec<f64> = (0..v).map(|a| ((a * 7 + k * 3) as f64).sin()).collect();
                let shifted = |sign: f64| {
                    let (mut s, mut m) = (slave.clone(), master.clone());
                    for (a, &d) in row.dofs.iter().enumerate() {
                        let step = sign * h * direction[a];
                        if d >= 30_000 {
                            m = moved(&m, true, d, step);
                        } else {
                            s = moved(&s, false, d, step);
                        }
                    }
                    linearize(&s, &m, space, &[j]).remove(&j).unwrap()
                };
                let (plus, minus) = (shifted(1.0), shifted(-1.0));
                assert_eq!(plus.dofs, row.dofs);
                for a in 0..v {
                    let fd = (plus.gradient[a] - minus.gradient[a]) / (2.0 * h);
                    let hv: f64 = (0..v).map(|c| row.hessian[a * v + c] * direction[c]).sum();
                    worst_h = worst_h.max((fd - hv).abs() / scale_h);
                }
            }
            println!(
                "{kind:?} {space:?} ({:.1} s in all): {} rows in {seconds:.2} s; gap vs f64 {worst_gap:.1e}, gradient vs difference {worst_b:.1e}, Hessian vs difference {worst_h:.1e} (of {scale_h:.2e}), momentum {worst_momentum:.1e}",
                start.elapsed().as_secs_f64(),
                rows.len()
            );
            assert!(rows.len() >= 4, "{kind:?}: {} rows", rows.len());
            assert!(worst_gap < 1e-13, "{kind:?} {space:?}: {worst_gap:e}");
            assert!(worst_b < 1e-7, "{kind:?} {space:?}: {worst_b:e}");
            assert!(worst_h < 1e-6, "{kind:?} {space:?}: {worst_h:e}");
            assert!(
                worst_momentum < 1e-10,
                "{kind:?} {space:?}: {worst_momentum:e}"
            );
        }
    }

    /// The dual-number shape functions are [`ElementKind::shape`]'s, values and derivatives; their
    /// second derivatives the differences of the first; the multiplier basis the `f64` rows'.
    #[test]
    fn shape_functions_are_the_elements() {
        for kind in [
            ElementKind::Q4,
            ElementKind::T3,
            ElementKind::Q9,
            ElementKind::T6,
        ] {
            let xi = [0.23, -0.41];
            let k = kind.node_count();
            let (mut n, mut dn) = ([0.0; MAX_NODES], [[0.0; 2]; MAX_NODES]);
            kind.shape(xi, &mut n[..k], &mut dn[..k]);
            let values = shape_values::<f64>(kind, &xi);
            let derivatives = shape_derivatives::<f64>(kind, &xi);
            for a in 0..k {
                assert!((values[a] - n[a]).abs() < 1e-15, "{kind:?} {a}");
                assert!((derivatives[a][0] - dn[a][0]).abs() < 1e-15, "{kind:?} {a}");
                assert!((derivatives[a][1] - dn[a][1]).abs() < 1e-15, "{kind:?} {a}");
            }
            // the second derivatives: central differences of the first (quadratic at most in
            // each coordinate, so only round-off remains)
            let second = shape_second_derivatives(kind, xi);
            let h = 1e-4;
            let along =
                |ds: f64, dt: f64| shape_derivatives::<f64>(kind, &[xi[0] + ds, xi[1] + dt]);
            let (ps, ms, pt, mt) = (along(h, 0.0), along(-h, 0.0), along(0.0, h), along(0.0, -h));
            for a in 0..k {
                let differences = [
                    (ps[a][0] - ms[a][0]) / (2.0 * h),
                    (pt[a][0] - mt[a][0]) / (2.0 * h),
                    (pt[a][1] - mt[a][1]) / (2.0 * h),
                ];
                for (d, s) in differences.iter().zip(&second[a]) {
                    assert!((d - s).abs() < 1e-9, "{kind:?} {a}: {d} vs {s}");
                }
            }
            // the multiplier basis is the one the f64 rows are built on
            let mut basis = [0.0; MAX_NODES];
            FacetShape::<3>::weight_basis(kind, xi, &mut basis[..k]);
            let dual_basis = multiplier_values(kind, values);
            for a in 0..k {
                assert!((dual_basis[a] - basis[a]).abs() < 1e-15, "{kind:?} {a}");
            }
        }
    }
}
