//! The second derivative of the 3D node-to-surface gap with respect to the nodal positions, for
//! finite kinematics: the 3D counterpart of [`super::node_to_segment`], attached to every
//! node-to-surface row between deformable bodies built in the current configuration
//! ([`super::node_based_rows`], `Constraint::hessian`) and consumed by the Newton tangent
//! ([`crate::solver::contact_newton`]); checked here against finite differences of the gap's
//! gradient.
//!
//! The gap of slave node `x_s` against the closest point `x(xi)` inside a master facet
//! `x(xi) = sum_a N_a(xi) x_a` is `g = n . (x_s - x(xi))`, `n` the facet's unit normal at `xi`,
//! and its gradient is `dg = n . dr~`, `dr~ = dx_s - sum_a N_a dx_a` (see
//! [`super::node_based_rows`]). With the tangents `t_a = dx/dxi_a`, the metric
//! `m_ab = t_a . t_b` (inverse `m^ab`), the curvature `h_ab = n . x_,ab` and
//! `T_a dq = sum_b N_b,a dx_b` (Wriggers, Computational Contact Mechanics, 2nd ed. 2006,
//! section 4.3; Laursen 2002, section 5.3):
//!
//! * the closest point moves by `(m_ab - g h_ab) Dxi_b = t_a . Dr~ + g n . T_a Dq` (the variation
//!   of `(x_s - x(xi)) . t_a = 0`),
//! * the normal turns by `Dn = -m^ab (n . Dt_a) t_b`, `Dt_a = T_a Dq + x_,ab Dxi_b`,
//! * so `D(dg) = Dn . dr~ - (n . T_a dq) Dxi_a`
//!   `= -m^ab (n . T_a Dq + h_ac Dxi_c)(t_b . dr~) - (n . T_a dq) Dxi_a`.
//!
//! **Edges** (the closest point strictly inside edge `k` of the facet, the node outside a convex
//! edge): the gap is the distance to the edge curve `c(tau) = x(A + tau (B - A))` between the
//! natural corners `A`, `B`, `g = |r|`, `r = x_s - c(tau)`, `nu = r / g`, with `r . c' = 0`
//! (`c' = t_a d_a`, `c'' = x_,ab d_a d_b`, `d = B - A`, `T dq = sum_b N_b,a d_a dx_b`). Its
//! gradient is `nu . dr~`; the closest point moves by `m Dtau = c' . Dr~ + g nu . T Dq`,
//! `m = c' . c' - g nu . c''`, and `Dnu = (I - nu nu^T)(Dr~ - c' Dtau) / g`, so
//!
//! `D(dg) = dr~ . (I - nu nu^T) Dr~ / g - (c' . dr~ + g nu . T dq)(c' . Dr~ + g nu . T Dq) / (g m)`
//!
//! (symmetric; `(I - nu nu^T) c' = c'`). The edge's shape functions are those of the facet at
//! the edge point (zero on the facet's other nodes). **Corners**: `g = |x_s - x_v|` and the
//! second derivative is `(I - nu nu^T) / g` on `x_s` and `-` that between `x_s` and `x_v`.
//!
//! A node behind the facet's plane whose closest point is on an edge or a corner (inside the
//! master body under a concave edge, where neither facet's normal through the node meets it)
//! has the gap `-|r|`, so `-1` times the above (the caller's `side`; [`side_of_facet`] for a
//! facet alone): a penetration, not a separation.
//!
//! Edge and corner points are points outside the facet's natural domain (a point on its
//! boundary is interior, to [`super::facet_projection::INSIDE`]), so their distance is positive
//! unless the node sits on the edge or the vertex itself, where the direction `nu` and so the
//! second derivative are undefined: `None` there, and the row keeps its first-order part only
//! (the tangent then lacks the turn of `nu`, the gap itself is exact).

use super::facet_projection::{
    natural_corners, project_onto_facet, shape_second_derivatives, FacetFeature, FacetProjection,
};
use super::geometry::{dot, facet_frame, FacetShape, MAX_FACET_NODES};
use crate::fe::ElementKind;

/// The second derivative of the gap of slave position `x_s` against the facet `coords` of kind
/// `kind`, over the positions `q = [x_s, x_1, .., x_n]` (3 components each): `values[i * len +
/// j] = d2 g / dq_i dq_j`, `len = 3 (n + 1)`, symmetric; `None` where the closest point is on an
/// edge, or the slave node sits on a corner.
pub fn node_to_facet_gap_hessian(
    kind: ElementKind,
    coords: &[[f64; 3]],
    x_s: [f64; 3],
) -> Option<Vec<f64>> {
    let q = project_onto_facet(kind, coords, x_s);
    node_to_facet_gap_hessian_at(kind, coords, x_s, &q, side_of_facet(&q, x_s))
}

/// [`node_to_facet_gap_hessian`] at the closest point `q` of `x_s` on the facet, found by the
/// caller (an interior point may lie on the facet's extension beyond a free boundary,
/// [`super::facet_projection::project_onto_extended_facet`]: the same formulas hold there);
/// on an edge or a corner the gap is `side |x_s - x(q)|` (`side` `1` outside the master body,
/// `-1` inside it, as the caller decides: [`side_of_facet`] for a facet alone).
pub fn node_to_facet_gap_hessian_at(
    kind: ElementKind,
    coords: &[[f64; 3]],
    x_s: [f64; 3],
    q: &FacetProjection,
    side: f64,
) -> Option<Vec<f64>> {
    let n_nodes = coords.len();
    let len = 3 * (n_nodes + 1);
    let q = *q;
    let mut h = vec![0.0; len * len];
    match q.feature {
        FacetFeature::Interior => {}
        FacetFeature::Edge(k) => {
            if q.distance == 0.0 {
                return None;
            }
            let mut h = edge_gap_hessian(kind, coords, x_s, &q, k);
            h.iter_mut().for_each(|v| *v *= side);
            return Some(h);
        }
        FacetFeature::Corner(k) => {
            if q.distance == 0.0 {
                return None;
            }
            let nu = std::array::from_fn::<f64, 3, _>(|i| (x_s[i] - q.point[i]) / q.distance);
            for i in 0..3 {
                for j in 0..3 {
                    let v = side * (f64::from(u8::from(i == j)) - nu[i] * nu[j]) / q.distance;
                    for (a, b, sign) in [(0, 0, 1.0), (0, k + 1, -1.0), (k + 1, 0, -1.0)] {
                        h[(3 * a + i) * len + 3 * b + j] += sign * v;
                    }
                    h[(3 * (k + 1) + i) * len + 3 * (k + 1) + j] += v;
                }
            }
            return Some(h);
        }
    }
    let xi = q.natural;
    let n = q.normal;
    let g = dot(n, std::array::from_fn(|i| x_s[i] - q.point[i]));
    let mut shape = [0.0; MAX_FACET_NODES];
    let mut dshape = [[0.0; 2]; MAX_FACET_NODES];
    FacetShape::<3>::shape(kind, xi, &mut shape[..n_nodes], &mut dshape[..n_nodes]);
    let mut ddshape = [[[0.0; 2]; 2]; MAX_FACET_NODES];
    shape_second_derivatives(kind, xi, &mut ddshape);
    let (_, t) = facet_frame(kind, coords, xi);
    let mut xab = [[[0.0; 3]; 2]; 2];
    for (a, p) in coords.iter().enumerate() {
        for (al, row) in xab.iter_mut().enumerate() {
            for (be, v) in row.iter_mut().enumerate() {
                for i in 0..3 {
                    v[i] += ddshape[a][al][be] * p[i];
                }
            }
        }
    }
    let m = [
        [dot(t[0], t[0]), dot(t[0], t[1])],
        [dot(t[1], t[0]), dot(t[1], t[1])],
    ];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let m_inv = [
        [m[1][1] / det, -m[0][1] / det],
        [-m[1][0] / det, m[0][0] / det],
    ];
    let curvature = [
        [dot(n, xab[0][0]), dot(n, xab[0][1])],
        [dot(n, xab[1][0]), dot(n, xab[1][1])],
    ];
    // rows over q: R^T t_b (t_b . dr~), T_a^T n (n . T_a dq)
    let r_t = |b: usize| -> Vec<f64> {
        let mut v = vec![0.0; len];
        for i in 0..3 {
            v[i] = t[b][i];
            for a in 0..n_nodes {
                v[3 * (a + 1) + i] = -shape[a] * t[b][i];
            }
        }
        v
    };
    let t_n = |al: usize| -> Vec<f64> {
        let mut v = vec![0.0; len];
        for a in 0..n_nodes {
            for i in 0..3 {
                v[3 * (a + 1) + i] = dshape[a][al] * n[i];
            }
        }
        v
    };
    let rt = [r_t(0), r_t(1)];
    let tn = [t_n(0), t_n(1)];
    // Dxi = A^-1 (t_a . Dr~ + g n . T_a Dq), A = m - g h
    let a = [
        [m[0][0] - g * curvature[0][0], m[0][1] - g * curvature[0][1]],
        [m[1][0] - g * curvature[1][0], m[1][1] - g * curvature[1][1]],
    ];
    let det_a = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    let a_inv = [
        [a[1][1] / det_a, -a[0][1] / det_a],
        [-a[1][0] / det_a, a[0][0] / det_a],
    ];
    let rhs: [Vec<f64>; 2] =
        std::array::from_fn(|al| (0..len).map(|j| rt[al][j] + g * tn[al][j]).collect());
    let dxi: [Vec<f64>; 2] = std::array::from_fn(|al| {
        (0..len)
            .map(|j| a_inv[al][0] * rhs[0][j] + a_inv[al][1] * rhs[1][j])
            .collect()
    });
    // n . Dt_a = n . T_a Dq + h_ac Dxi_c
    let n_dt: [Vec<f64>; 2] = std::array::from_fn(|al| {
        (0..len)
            .map(|j| tn[al][j] + curvature[al][0] * dxi[0][j] + curvature[al][1] * dxi[1][j])
            .collect()
    });
    for i in 0..len {
        for j in 0..len {
            let mut v = 0.0;
            for al in 0..2 {
                for be in 0..2 {
                    v -= m_inv[al][be] * rt[be][i] * n_dt[al][j];
                }
                v -= tn[al][i] * dxi[al][j];
            }
            h[i * len + j] = v;
        }
    }
    // the exact form is symmetric; average away the round-off
    for i in 0..len {
        for j in 0..i {
            let s = 0.5 * (h[i * len + j] + h[j * len + i]);
            h[i * len + j] = s;
            h[j * len + i] = s;
        }
    }
    Some(h)
}

/// The sign of the gap of `x_s` whose closest point `q` on a facet alone is on an edge or a
/// corner: `+1` on the side the facet's normal points to at `q`, `-1` behind it: the gap is
/// `side |x_s - x(q)|`. On a surface of several facets the side is that of the surface's
/// normal there, averaged over the facets at the edge or corner
/// ([`super::node_based_rows`]): outside a convex edge whose facets turn by more than a right
/// angle a node can lie behind one facet's plane.
pub fn side_of_facet(q: &FacetProjection, x_s: [f64; 3]) -> f64 {
    let d: [f64; 3] = std::array::from_fn(|i| x_s[i] - q.point[i]);
    if dot(d, q.normal) < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// The second derivative of the gap of `x_s` against the edge `k` of the facet that holds its
/// closest point `q` at a positive distance (module notes, **Edges**).
fn edge_gap_hessian(
    kind: ElementKind,
    coords: &[[f64; 3]],
    x_s: [f64; 3],
    q: &FacetProjection,
    k: usize,
) -> Vec<f64> {
    let n_nodes = coords.len();
    let len = 3 * (n_nodes + 1);
    let corners = natural_corners(kind);
    let (from, to) = (corners[k], corners[(k + 1) % corners.len()]);
    let d = [to[0] - from[0], to[1] - from[1]];
    let g = q.distance;
    let nu: [f64; 3] = std::array::from_fn(|i| (x_s[i] - q.point[i]) / g);
    let mut shape = [0.0; MAX_FACET_NODES];
    let mut dshape = [[0.0; 2]; MAX_FACET_NODES];
    FacetShape::<3>::shape(
        kind,
        q.natural,
        &mut shape[..n_nodes],
        &mut dshape[..n_nodes],
    );
    let mut ddshape = [[[0.0; 2]; 2]; MAX_FACET_NODES];
    shape_second_derivatives(kind, q.natural, &mut ddshape);
    // c' and c'' along the edge, and the edge derivative of each shape function
    let along: Vec<f64> = (0..n_nodes)
        .map(|a| dshape[a][0] * d[0] + dshape[a][1] * d[1])
        .collect();
    let mut c1 = [0.0; 3];
    let mut c2 = [0.0; 3];
    for (a, p) in coords.iter().enumerate() {
        let second: f64 = (0..2)
            .flat_map(|al| (0..2).map(move |be| (al, be)))
            .map(|(al, be)| ddshape[a][al][be] * d[al] * d[be])
            .sum();
        for i in 0..3 {
            c1[i] += along[a] * p[i];
            c2[i] += second * p[i];
        }
    }
    let m = dot(c1, c1) - g * dot(nu, c2);
    // R~ (3 x len): e_i on the slave, -N_a e_i on node a
    let r_tilde = |i: usize, j: usize| -> f64 {
        let (node, comp) = (j / 3, j % 3);
        if comp != i {
            0.0
        } else if node == 0 {
            1.0
        } else {
            -shape[node - 1]
        }
    };
    // c' . R~ + g nu . T, over q
    let w: Vec<f64> = (0..len)
        .map(|j| {
            let (node, comp) = (j / 3, j % 3);
            let turn = if node == 0 {
                0.0
            } else {
                along[node - 1] * nu[comp]
            };
            c1[comp] * r_tilde(comp, j) + g * turn
        })
        .collect();
    let mut h = vec![0.0; len * len];
    for i in 0..len {
        for j in 0..len {
            // R~^T (I - nu nu^T) R~: both columns act on one component each
            let (ci, cj) = (i % 3, j % 3);
            let projector = f64::from(u8::from(ci == cj)) - nu[ci] * nu[cj];
            let sides = r_tilde(ci, i) * r_tilde(cj, j);
            h[i * len + j] = projector * sides / g - w[i] * w[j] / (g * m);
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The gap's gradient over `q = [x_s, x_1, .., x_n]` at these positions (re-projected):
    /// `n` on the slave, `-N_a n` on node `a` inside; `nu`, `-N_a nu` on an edge, `nu`, `-nu`
    /// at a corner (`nu` the unit direction from the closest point to the slave, turned round
    /// behind the facet, where the gap is `-|x_s - x|`).
    fn gradient(kind: ElementKind, coords: &[[f64; 3]], x_s: [f64; 3]) -> Vec<f64> {
        let q = project_onto_facet(kind, coords, x_s);
        let mut out = vec![0.0; 3 * (coords.len() + 1)];
        let (nu, weights): ([f64; 3], Vec<f64>) = match q.feature {
            FacetFeature::Interior => {
                let mut shape = [0.0; MAX_FACET_NODES];
                let mut dshape = [[0.0; 2]; MAX_FACET_NODES];
                let k = coords.len();
                FacetShape::<3>::shape(kind, q.natural, &mut shape[..k], &mut dshape[..k]);
                (q.normal, shape[..k].to_vec())
            }
            FacetFeature::Corner(c) => (
                std::array::from_fn(|i| {
                    side_of_facet(&q, x_s) * (x_s[i] - q.point[i]) / q.distance
                }),
                (0..coords.len())
                    .map(|a| f64::from(u8::from(a == c)))
                    .collect(),
            ),
            FacetFeature::Edge(_) => {
                let mut shape = [0.0; MAX_FACET_NODES];
                let mut dshape = [[0.0; 2]; MAX_FACET_NODES];
                let k = coords.len();
                FacetShape::<3>::shape(kind, q.natural, &mut shape[..k], &mut dshape[..k]);
                (
                    std::array::from_fn(|i| {
                        side_of_facet(&q, x_s) * (x_s[i] - q.point[i]) / q.distance
                    }),
                    shape[..k].to_vec(),
                )
            }
        };
        for i in 0..3 {
            out[i] = nu[i];
            for (a, w) in weights.iter().enumerate() {
                out[3 * (a + 1) + i] = -w * nu[i];
            }
        }
        out
    }

    /// A Quad4 facet with two opposite corners raised by 0.2 (warped).
    fn warped_quad4() -> Vec<[f64; 3]> {
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.2],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.2],
        ]
    }

    /// A node behind a facet whose closest point is on an edge or a corner has a negative gap,
    /// minus its distance, and a row and second derivative of that sign: the unit direction
    /// from the closest point to the node points into the facet's back side.
    #[test]
    fn behind_the_facet_an_edge_or_corner_gap_is_minus_the_distance() {
        for (x_s, corner) in [([1.4, 0.4, -0.3], false), ([1.3, 1.2, -0.3], true)] {
            let coords = warped_quad4();
            let q = project_onto_facet(ElementKind::Q4, &coords, x_s);
            assert_eq!(matches!(q.feature, FacetFeature::Corner(_)), corner);
            assert!(matches!(
                q.feature,
                FacetFeature::Edge(_) | FacetFeature::Corner(_)
            ));
            assert_eq!(side_of_facet(&q, x_s), -1.0);
            // in front of the facet, mirrored through its edge's plane: +1
            let front = [x_s[0], x_s[1], 0.5];
            let p = project_onto_facet(ElementKind::Q4, &coords, front);
            assert_eq!(side_of_facet(&p, front), 1.0);
        }
    }

    #[test]
    fn the_hessian_is_the_difference_of_the_gradient_on_curved_facets() {
        let mut quad9: Vec<[f64; 3]> = ElementKind::Q9
            .node_coordinates()
            .iter()
            .map(|c| [c[0] + 0.05 * c[1], 0.8 * c[1], 0.0])
            .collect();
        for (k, z) in [(4, 0.15), (5, -0.1), (6, 0.2), (7, 0.05), (8, 0.25)] {
            quad9[k][2] = z;
        }
        let tri6 = super::super::facet_projection::tests::curved_tri6();
        let cases = [
            (ElementKind::Q9, quad9, [0.2, 0.1, 0.4]),
            (ElementKind::Q9, quad9_below(), [-0.3, 0.2, -0.2]),
            (ElementKind::T6, tri6.clone(), [0.5, 0.4, 0.35]),
            (ElementKind::T6, tri6, [0.4, 0.3, -0.1]),
            (ElementKind::Q4, warped_quad4(), [0.6, 0.3, 0.5]),
            (ElementKind::Q4, warped_quad4(), [1.3, 1.2, 0.3]),
            // edges: beyond a straight edge of a warped Quad4, a curved edge of a Quad9 and of
            // a Tri6 (the hypotenuse)
            (ElementKind::Q4, warped_quad4(), [1.4, 0.4, 0.3]),
            (ElementKind::Q9, quad9_below(), [0.3, 1.35, 0.25]),
            (
                ElementKind::T6,
                super::super::facet_projection::tests::curved_tri6(),
                [1.0, 1.0, 0.2],
            ),
            // behind the facet (inside the master body under a concave edge or corner): the
            // gap -|x_s - x| and its second derivative turned round
            (ElementKind::Q4, warped_quad4(), [1.4, 0.4, -0.3]),
            (ElementKind::Q4, warped_quad4(), [1.3, 1.2, -0.3]),
            (
                ElementKind::T6,
                super::super::facet_projection::tests::curved_tri6(),
                [1.3, 1.2, -0.3],
            ),
        ];
        let h = 1e-6;
        let (mut corners, mut edges) = (0, 0);
        for (kind, coords, x_s) in cases {
            let hessian =
                node_to_facet_gap_hessian(kind, &coords, x_s).expect("off the facet's boundary");
            match project_onto_facet(kind, &coords, x_s).feature {
                FacetFeature::Corner(_) => corners += 1,
                FacetFeature::Edge(_) => edges += 1,
                FacetFeature::Interior => {}
            }
            let len = 3 * (coords.len() + 1);
            let largest = hessian.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            assert!(
                largest > 0.1,
                "{kind:?} at {x_s:?}: a Hessian of size {largest}"
            );
            for j in 0..len {
                let moved = |d: f64| {
                    let (mut c, mut s) = (coords.clone(), x_s);
                    if j < 3 {
                        s[j] += d;
                    } else {
                        c[j / 3 - 1][j % 3] += d;
                    }
                    gradient(kind, &c, s)
                };
                let (plus, minus) = (moved(h), moved(-h));
                for i in 0..len {
                    let fd = (plus[i] - minus[i]) / (2.0 * h);
                    assert!(
                        (fd - hessian[i * len + j]).abs() < 1e-6,
                        "{kind:?} at {x_s:?}: d2g/dq{i}dq{j} = {} vs finite difference {fd}",
                        hessian[i * len + j]
                    );
                }
            }
        }
        assert_eq!((corners, edges), (2, 5), "two corner and five edge cases");
    }

    /// A slave node on a facet's edge or corner itself (distance zero, where an edge or corner
    /// gap has no direction) projects as an interior point (the boundary is inside to
    /// `INSIDE`): its Hessian is the interior one, finite; just off the facet beyond the edge
    /// the edge's is finite too.
    #[test]
    fn a_node_on_an_edge_or_a_corner_gets_the_interior_hessian() {
        let quad4 = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.2],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.2],
        ];
        let on_edge = [1.0, 0.5, 0.1];
        let on_corner = quad4[2];
        for x_s in [on_edge, on_corner] {
            let q = project_onto_facet(ElementKind::Q4, &quad4, x_s);
            assert_eq!(q.feature, FacetFeature::Interior, "{x_s:?}");
            assert!(q.distance < 1e-12);
            let h = node_to_facet_gap_hessian(ElementKind::Q4, &quad4, x_s).expect("interior");
            assert!(h.iter().all(|v| v.is_finite()));
        }
        let beyond = [1.0 + 1e-6, 0.5, 0.1];
        let q = project_onto_facet(ElementKind::Q4, &quad4, beyond);
        assert!(
            matches!(q.feature, FacetFeature::Edge(_)),
            "{:?}",
            q.feature
        );
        let h = node_to_facet_gap_hessian(ElementKind::Q4, &quad4, beyond).expect("edge");
        assert!(h.iter().all(|v| v.is_finite()));
    }

    /// A curved Quad9 below its slave point (the gap is negative: penetration).
    fn quad9_below() -> Vec<[f64; 3]> {
        let mut c: Vec<[f64; 3]> = ElementKind::Q9
            .node_coordinates()
            .iter()
            .map(|c| [c[0], c[1], 0.1 * c[0] * c[1]])
            .collect();
        c[8][2] = 0.2;
        c
    }
}
