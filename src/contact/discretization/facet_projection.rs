//! Closest point of a point onto a 3D facet (Quad4, Quad9, Tri3, Tri6), edges and corners
//! included.
//!
//! The facet is `x(s) = sum_a N_a(s) x_a` over its natural domain `S` (`[-1, 1]^2` for the
//! quadrilaterals, `{s, t >= 0, s + t <= 1}` for the triangles; [`crate::fe`]). The closest
//! point of `p` minimizes `f(s) = |x(s) - p|^2 / 2` over `S`:
//!
//! * **Interior**: Newton on the stationarity condition `grad f = 0`,
//!   `f_k = (x - p) . t_k`, `f_kl = t_k . t_l + (x - p) . x_kl` (`t_k = dx/ds_k`,
//!   `x_kl = d2x/ds_k ds_l`), from the facet's centre; where `f_kl` is not positive definite
//!   (far from a strongly curved facet) the Gauss-Newton matrix `t_k . t_l` replaces it, and
//!   each step is at most one natural unit. A root inside `S` (to [`INSIDE`]) is the closest
//!   point, `(x - p) . t_k = 0`: `p - x` is along the facet normal.
//! * **Edges and corners**: otherwise the minimum lies on the boundary of `S`. Each edge
//!   `s(tau) = A + tau (B - A)`, `tau in [0, 1]` between natural corners `A`, `B` is searched
//!   by projected Newton on `phi(tau) = f(s(tau))` (`phi' = (x - p) . T`,
//!   `phi'' = T . T + (x - p) . x_kl d_k d_l`, `T = t_k d_k`, `d = B - A`) from `tau = 1/4,
//!   1/2, 3/4` beside both corners (a quadratic edge may hold two local minima); the closest
//!   of all candidates wins. A minimum at `tau` strictly inside `(0, 1)` is an **edge** point
//!   (`p - x` orthogonal to the edge tangent), at an end a **corner**.
//!
//! The result carries the natural point, the feature, the point, the distance `|p - x|` and
//! the unit outward normal `t_1 x t_2 / |t_1 x t_2|` of the facet at the natural point (on an
//! edge or a corner, the normal of this facet there; the direction from the facet to `p` is
//! `(p - x) / distance`). This is the 3D counterpart of [`super::geometry::closest_point`]
//! (Wriggers, Computational Contact Mechanics, 2nd ed. 2006, section 4.1.2; Laursen,
//! Computational Contact and Impact Mechanics, 2002, section 5.3).

use super::geometry::{cross, dot, facet_frame, MAX_FACET_NODES};
use crate::fe::{lagrange_1d_quadratic, ElementKind};

/// Tolerance on the natural coordinates for "inside the facet".
pub const INSIDE: f64 = 1e-9;

/// Where on the facet the closest point lies.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum FacetFeature {
    /// Inside the facet (its boundary included, to [`INSIDE`]).
    Interior,
    /// On edge `k` (from corner `k` to corner `k + 1`, cyclically), strictly between its ends.
    Edge(usize),
    /// At corner `k` (the facet's local node `k`).
    Corner(usize),
}

/// The closest point of a point on a facet.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct FacetProjection {
    /// Natural coordinates of the closest point (inside the facet's domain).
    pub natural: [f64; 2],
    pub feature: FacetFeature,
    /// The closest point.
    pub point: [f64; 3],
    /// `|p - point|`.
    pub distance: f64,
    /// Unit outward normal of the facet at `natural`.
    pub normal: [f64; 3],
    /// For an interior point: how far (in natural units, [`natural_excess`]) the stationary
    /// point lay outside the natural domain before it was clamped onto it (zero when inside;
    /// at most [`INSIDE`] past each bound for [`project_onto_facet`], up to the margin for
    /// [`project_onto_extended_facet`]); zero on edges and corners. Of two facets that hold a
    /// node at the same distance, the one it is truly inside has the smaller excess.
    pub excess: f64,
}

/// The bounds of the natural domain, one per edge (edge `k` from corner `k` to corner
/// `k + 1` of [`natural_corners`]): how far `s` lies past edge `k`'s line (negative inside).
/// Quadrilaterals: `-1 - t`, `s - 1`, `t - 1`, `-1 - s`; triangles: `-t`, `s + t - 1`, `-s`.
pub fn edge_violations(kind: ElementKind, s: [f64; 2]) -> [f64; 4] {
    if is_quadrilateral(kind) {
        [-1.0 - s[1], s[0] - 1.0, s[1] - 1.0, -1.0 - s[0]]
    } else {
        [-s[1], s[0] + s[1] - 1.0, -s[0], f64::NEG_INFINITY]
    }
}

/// How far the natural point `s` lies outside the facet's natural domain: the sum of the
/// violations of its bounds (`|s_k| <= 1` on the quadrilaterals; `s, t >= 0`, `s + t <= 1` on
/// the triangles), zero inside. A sum, not the largest violation: of two facets that a node
/// just past the free boundary of the master surface lies beyond by the same amount, the one
/// it is inside across their shared edge has the smaller excess.
pub fn natural_excess(kind: ElementKind, s: [f64; 2]) -> f64 {
    edge_violations(kind, s)
        .iter()
        .filter(|v| **v > 0.0)
        .fold(0.0, |sum, v| sum + v)
}

/// The edges of the facet (edge `k` from corner `k` to corner `k + 1`) whose bound the natural
/// point `s` violates by more than `tol`.
pub fn violated_edges(kind: ElementKind, s: [f64; 2], tol: f64) -> Vec<usize> {
    edge_violations(kind, s)
        .iter()
        .enumerate()
        .filter(|(_, v)| **v > tol)
        .map(|(k, _)| k)
        .collect()
}

/// Natural coordinates of the facet's corners, counter-clockwise.
pub fn natural_corners(kind: ElementKind) -> &'static [[f64; 2]] {
    const QUAD: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
    const TRI: [[f64; 2]; 3] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
    match kind {
        ElementKind::Q4 | ElementKind::Q9 => &QUAD,
        ElementKind::T3 | ElementKind::T6 => &TRI,
    }
}

fn is_quadrilateral(kind: ElementKind) -> bool {
    matches!(kind, ElementKind::Q4 | ElementKind::Q9)
}

/// Whether `s` lies in the facet's natural domain, to `tol`.
pub fn natural_inside(kind: ElementKind, s: [f64; 2], tol: f64) -> bool {
    if is_quadrilateral(kind) {
        s[0].abs() <= 1.0 + tol && s[1].abs() <= 1.0 + tol
    } else {
        s[0] >= -tol && s[1] >= -tol && s[0] + s[1] <= 1.0 + tol
    }
}

/// The point of the natural domain nearest to `s` (for points within round-off of it).
fn clamp_natural(kind: ElementKind, s: [f64; 2]) -> [f64; 2] {
    if is_quadrilateral(kind) {
        return s.map(|v| v.clamp(-1.0, 1.0));
    }
    let mut s = s.map(|v| v.max(0.0));
    let excess = s[0] + s[1] - 1.0;
    if excess > 0.0 {
        s = s.map(|v| (v - 0.5 * excess).max(0.0));
        let excess = s[0] + s[1] - 1.0;
        if excess > 0.0 {
            // one coordinate was clamped at 0: the other carries the rest
            let k = usize::from(s[1] > s[0]);
            s[k] -= excess;
        }
    }
    s
}

/// Second natural derivatives `ddn[a][k][l] = d2 N_a / ds_k ds_l` of the facet's shape
/// functions at `s`.
pub fn shape_second_derivatives(kind: ElementKind, s: [f64; 2], ddn: &mut [[[f64; 2]; 2]]) {
    match kind {
        ElementKind::Q4 => {
            for (a, c) in natural_corners(kind).iter().enumerate() {
                let st = 0.25 * c[0] * c[1];
                ddn[a] = [[0.0, st], [st, 0.0]];
            }
        }
        ElementKind::Q9 => {
            let second = |node: f64| if node.abs() < 0.5 { -2.0 } else { 1.0 };
            for (a, c) in ElementKind::Q9.node_coordinates().iter().enumerate() {
                let (ls, dls) = lagrange_1d_quadratic(c[0], s[0]);
                let (lt, dlt) = lagrange_1d_quadratic(c[1], s[1]);
                let st = dls * dlt;
                ddn[a] = [[second(c[0]) * lt, st], [st, ls * second(c[1])]];
            }
        }
        ElementKind::T3 => {
            for v in ddn.iter_mut().take(3) {
                *v = [[0.0; 2]; 2];
            }
        }
        ElementKind::T6 => {
            // barycentric gradients: L1 = 1 - s - t, L2 = s, L3 = t
            let d = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];
            let outer = |a: [f64; 2], b: [f64; 2], w: f64| {
                [
                    [w * a[0] * b[0], w * a[0] * b[1]],
                    [w * a[1] * b[0], w * a[1] * b[1]],
                ]
            };
            let sum = |x: [[f64; 2]; 2], y: [[f64; 2]; 2]| {
                [
                    [x[0][0] + y[0][0], x[0][1] + y[0][1]],
                    [x[1][0] + y[1][0], x[1][1] + y[1][1]],
                ]
            };
            for c in 0..3 {
                ddn[c] = outer(d[c], d[c], 4.0);
            }
            for (m, (a, b)) in [(0, 1), (1, 2), (2, 0)].into_iter().enumerate() {
                ddn[3 + m] = sum(outer(d[a], d[b], 4.0), outer(d[b], d[a], 4.0));
            }
        }
    }
}

/// `x_kl = sum_a N_a,kl x_a`.
fn second_derivative(kind: ElementKind, coords: &[[f64; 3]], s: [f64; 2]) -> [[[f64; 3]; 2]; 2] {
    let mut ddn = [[[0.0; 2]; 2]; MAX_FACET_NODES];
    shape_second_derivatives(kind, s, &mut ddn);
    let mut out = [[[0.0; 3]; 2]; 2];
    for (a, p) in coords.iter().enumerate() {
        for k in 0..2 {
            for l in 0..2 {
                for i in 0..3 {
                    out[k][l][i] += ddn[a][k][l] * p[i];
                }
            }
        }
    }
    out
}

fn difference(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// The stationary point of `|x(s) - p|^2 / 2` Newton reaches from the facet's centre, or
/// `None` when it does not converge or leaves the neighbourhood of the facet.
fn interior_newton(kind: ElementKind, coords: &[[f64; 3]], p: [f64; 3]) -> Option<[f64; 2]> {
    let mut s = if is_quadrilateral(kind) {
        [0.0, 0.0]
    } else {
        [1.0 / 3.0, 1.0 / 3.0]
    };
    for _ in 0..60 {
        let (x, t) = facet_frame(kind, coords, s);
        let r = difference(x, p);
        let g = [dot(r, t[0]), dot(r, t[1])];
        let gauss = [
            [dot(t[0], t[0]), dot(t[0], t[1])],
            [dot(t[1], t[0]), dot(t[1], t[1])],
        ];
        let xkl = second_derivative(kind, coords, s);
        let full = [
            [
                gauss[0][0] + dot(r, xkl[0][0]),
                gauss[0][1] + dot(r, xkl[0][1]),
            ],
            [
                gauss[1][0] + dot(r, xkl[1][0]),
                gauss[1][1] + dot(r, xkl[1][1]),
            ],
        ];
        let det = |h: [[f64; 2]; 2]| h[0][0] * h[1][1] - h[0][1] * h[1][0];
        let h = if full[0][0] > 0.0 && det(full) > 0.0 {
            full
        } else {
            gauss
        };
        let dh = det(h);
        if dh.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let mut step = [
            -(h[1][1] * g[0] - h[0][1] * g[1]) / dh,
            -(-h[1][0] * g[0] + h[0][0] * g[1]) / dh,
        ];
        let length = step[0].hypot(step[1]);
        if length > 1.0 {
            step = step.map(|v| v / length);
        }
        s = [s[0] + step[0], s[1] + step[1]];
        if s[0].abs() > 4.0 || s[1].abs() > 4.0 {
            return None;
        }
        if length < 1e-14 {
            return Some(s);
        }
    }
    None
}

/// The minimum of `|x(s(tau)) - p|^2 / 2` over `tau in [0, 1]` on the edge from natural corner
/// `a` to `b`: `(tau, squared distance)`.
fn edge_minimum(
    kind: ElementKind,
    coords: &[[f64; 3]],
    p: [f64; 3],
    a: [f64; 2],
    b: [f64; 2],
) -> (f64, f64) {
    let d = [b[0] - a[0], b[1] - a[1]];
    let at = |tau: f64| [a[0] + tau * d[0], a[1] + tau * d[1]];
    let squared = |tau: f64| {
        let (x, _) = facet_frame(kind, coords, at(tau));
        let r = difference(x, p);
        dot(r, r)
    };
    let mut best = (0.0, squared(0.0));
    let end = (1.0, squared(1.0));
    if end.1 < best.1 {
        best = end;
    }
    for start in [0.25, 0.5, 0.75] {
        let mut tau: f64 = start;
        for _ in 0..60 {
            let s = at(tau);
            let (x, t) = facet_frame(kind, coords, s);
            let r = difference(x, p);
            let tangent: [f64; 3] = std::array::from_fn(|i| t[0][i] * d[0] + t[1][i] * d[1]);
            let xkl = second_derivative(kind, coords, s);
            let curvature: [f64; 3] = std::array::from_fn(|i| {
                xkl[0][0][i] * d[0] * d[0]
                    + 2.0 * xkl[0][1][i] * d[0] * d[1]
                    + xkl[1][1][i] * d[1] * d[1]
            });
            let slope = dot(r, tangent);
            let second = dot(tangent, tangent) + dot(r, curvature);
            let next = if second > 0.0 {
                (tau - slope / second).clamp(0.0, 1.0)
            } else if slope > 0.0 {
                0.0
            } else {
                1.0
            };
            let moved = (next - tau).abs();
            tau = next;
            if moved < 1e-15 {
                break;
            }
        }
        let value = squared(tau);
        if value < best.1 {
            best = (tau, value);
        }
    }
    best
}

/// The closest point of `p` on the facet of kind `kind` (Q4, Q9, T3 or T6) with node
/// positions `coords` (module notes).
pub fn project_onto_facet(kind: ElementKind, coords: &[[f64; 3]], p: [f64; 3]) -> FacetProjection {
    let finish = |natural: [f64; 2], feature: FacetFeature, excess: f64| {
        let (x, t) = facet_frame(kind, coords, natural);
        let n = cross(t[0], t[1]);
        let l = dot(n, n).sqrt();
        let r = difference(p, x);
        FacetProjection {
            natural,
            feature,
            point: x,
            distance: dot(r, r).sqrt(),
            normal: n.map(|c| c / l),
            excess,
        }
    };
    if let Some(s) = interior_newton(kind, coords, p) {
        if natural_inside(kind, s, INSIDE) {
            return finish(
                clamp_natural(kind, s),
                FacetFeature::Interior,
                natural_excess(kind, s),
            );
        }
    }
    let corners = natural_corners(kind);
    let mut best: Option<(f64, [f64; 2], FacetFeature)> = None;
    for k in 0..corners.len() {
        let (a, b) = (corners[k], corners[(k + 1) % corners.len()]);
        let (tau, squared) = edge_minimum(kind, coords, p, a, b);
        if best.is_some_and(|(d, _, _)| d <= squared) {
            continue;
        }
        let (natural, feature) = if tau <= 0.0 {
            (a, FacetFeature::Corner(k))
        } else if tau >= 1.0 {
            (b, FacetFeature::Corner((k + 1) % corners.len()))
        } else {
            (
                [a[0] + tau * (b[0] - a[0]), a[1] + tau * (b[1] - a[1])],
                FacetFeature::Edge(k),
            )
        };
        best = Some((squared, natural, feature));
    }
    let (_, natural, feature) = best.expect("a facet has edges");
    finish(natural, feature, 0.0)
}

/// The stationary point of `|x(s) - p|^2 / 2` over the facet's interpolation extended beyond
/// its natural domain by `margin` natural units (the domain grown by `margin`, the
/// interpolation extrapolated), as an interior point (the gap along the facet's normal there);
/// `None` when Newton finds none within it. Finite kinematics holds a slave node that has slid
/// just past the free boundary of the master surface against it
/// ([`super::node_based_rows`]).
pub fn project_onto_extended_facet(
    kind: ElementKind,
    coords: &[[f64; 3]],
    p: [f64; 3],
    margin: f64,
) -> Option<FacetProjection> {
    let s = interior_newton(kind, coords, p)?;
    if !natural_inside(kind, s, margin) {
        return None;
    }
    let (x, t) = facet_frame(kind, coords, s);
    let n = cross(t[0], t[1]);
    let l = dot(n, n).sqrt();
    let r = difference(p, x);
    Some(FacetProjection {
        natural: s,
        feature: FacetFeature::Interior,
        point: x,
        distance: dot(r, r).sqrt(),
        normal: n.map(|c| c / l),
        excess: natural_excess(kind, s),
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::contact::discretization::geometry::FacetShape;

    /// A Tri6 facet with straight-line corners and mid-edge nodes moved off them (curved).
    pub(crate) fn curved_tri6() -> Vec<[f64; 3]> {
        vec![
            [0.0, 0.0, 0.0],
            [1.5, 0.1, 0.0],
            [0.2, 1.3, 0.1],
            [0.75, 0.0, -0.15],
            [0.9, 0.7, 0.2],
            [0.1, 0.65, -0.1],
        ]
    }

    /// A flat, a bilinear-warped and two curved facets of every kind.
    fn facets() -> Vec<(ElementKind, Vec<[f64; 3]>, &'static str)> {
        let quad9_flat = vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.5, 0.0],
            [0.0, 1.5, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.75, 0.0],
            [1.0, 1.5, 0.0],
            [0.0, 0.75, 0.0],
            [1.0, 0.75, 0.0],
        ];
        // moved mid-nodes: a dome, bulging up by 0.3 at the centre and 0.2 at the mid-sides
        let mut quad9_curved = quad9_flat.clone();
        for (k, lift) in [(4, 0.2), (5, 0.15), (6, 0.2), (7, 0.25), (8, 0.3)] {
            quad9_curved[k][2] = lift;
        }
        quad9_curved[8][0] += 0.1;
        let tri6_curved = curved_tri6();
        vec![
            (
                ElementKind::Q4,
                vec![
                    [0.0, 0.0, 0.0],
                    [1.0, 0.1, 0.0],
                    [1.2, 1.0, 0.0],
                    [-0.1, 0.9, 0.0],
                ],
                "flat Quad4",
            ),
            (
                ElementKind::Q4,
                vec![
                    [0.0, 0.0, 0.0],
                    [1.0, 0.0, 0.2],
                    [1.0, 1.0, 0.0],
                    [0.0, 1.0, 0.2],
                ],
                "warped Quad4",
            ),
            (ElementKind::Q9, quad9_flat, "flat Quad9"),
            (ElementKind::Q9, quad9_curved, "curved Quad9"),
            (
                ElementKind::T3,
                vec![[0.0, 0.0, 0.0], [1.0, 0.2, 0.1], [0.3, 1.1, -0.1]],
                "Tri3",
            ),
            (ElementKind::T6, tri6_curved, "curved Tri6"),
        ]
    }

    /// The smallest distance from `p` to the facet over a fine sampling of its natural domain,
    /// refined by a local sampling around the best sample.
    fn brute_force(kind: ElementKind, coords: &[[f64; 3]], p: [f64; 3]) -> (f64, [f64; 2]) {
        let n = 400;
        let quad = is_quadrilateral(kind);
        let sample = |i: usize, j: usize| -> Option<[f64; 2]> {
            let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
            if quad {
                Some([2.0 * u - 1.0, 2.0 * v - 1.0])
            } else if u + v <= 1.0 {
                Some([u, v])
            } else {
                None
            }
        };
        let distance = |s: [f64; 2]| {
            let (x, _) = facet_frame(kind, coords, s);
            let r = difference(x, p);
            dot(r, r).sqrt()
        };
        let mut best = (f64::INFINITY, [0.0; 2]);
        for i in 0..=n {
            for j in 0..=n {
                if let Some(s) = sample(i, j) {
                    let d = distance(s);
                    if d < best.0 {
                        best = (d, s);
                    }
                }
            }
        }
        // refine: shrinking local samplings clamped to the domain
        let mut h = 2.0 / n as f64;
        for _ in 0..30 {
            let centre = best.1;
            for i in -4i32..=4 {
                for j in -4i32..=4 {
                    let s = clamp_natural(
                        kind,
                        [
                            centre[0] + h * i as f64 / 4.0,
                            centre[1] + h * j as f64 / 4.0,
                        ],
                    );
                    let d = distance(s);
                    if d < best.0 {
                        best = (d, s);
                    }
                }
            }
            h *= 0.5;
        }
        best
    }

    #[test]
    fn second_derivatives_match_finite_differences_of_the_first() {
        let h = 1e-6;
        for kind in [
            ElementKind::Q4,
            ElementKind::Q9,
            ElementKind::T3,
            ElementKind::T6,
        ] {
            let k = FacetShape::<3>::node_count(kind);
            let s = [0.23, 0.31];
            let mut ddn = [[[0.0; 2]; 2]; MAX_FACET_NODES];
            shape_second_derivatives(kind, s, &mut ddn);
            for l in 0..2 {
                let (mut plus, mut minus) = (s, s);
                plus[l] += h;
                minus[l] -= h;
                let (mut n, mut dp, mut dm) = ([0.0; 9], [[0.0; 2]; 9], [[0.0; 2]; 9]);
                kind.shape(plus, &mut n[..k], &mut dp[..k]);
                kind.shape(minus, &mut n[..k], &mut dm[..k]);
                for a in 0..k {
                    for m in 0..2 {
                        let fd = (dp[a][m] - dm[a][m]) / (2.0 * h);
                        assert!(
                            (fd - ddn[a][m][l]).abs() < 1e-8,
                            "{kind:?} N_{a},{m}{l}: {} vs finite difference {fd}",
                            ddn[a][m][l]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn projections_match_brute_force_minimization_with_orthogonality() {
        let mut features = std::collections::BTreeSet::new();
        for (kind, coords, name) in facets() {
            let corners = natural_corners(kind);
            // points over, beside and beyond the facet: interior, edge and corner cases
            let mut points = Vec::new();
            for (u, v) in [
                (0.3, 0.4),
                (0.5, 0.2),
                (1.4, 0.5),
                (0.5, -0.4),
                (-0.3, -0.3),
                (1.3, 1.2),
                (0.1, 0.1),
                (0.9, 0.05),
            ] {
                for h in [-0.4, 0.05, 0.7] {
                    // natural (u, v) of the unit square mapped onto the facet's domain, then
                    // extrapolated through its corners and lifted
                    let s = if is_quadrilateral(kind) {
                        [2.0 * u - 1.0, 2.0 * v - 1.0]
                    } else {
                        [u * (1.0 - 0.5 * v), v * (1.0 - 0.5 * u)]
                    };
                    let (x, t) = facet_frame(kind, &coords, clamp_natural(kind, s));
                    let n = cross(t[0], t[1]);
                    let l = dot(n, n).sqrt();
                    let over = [
                        s[0] - clamp_natural(kind, s)[0],
                        s[1] - clamp_natural(kind, s)[1],
                    ];
                    points.push(std::array::from_fn(|i| {
                        x[i] + h * n[i] / l + over[0] * t[0][i] + over[1] * t[1][i]
                    }));
                }
            }
            for p in points {
                let q = project_onto_facet(kind, &coords, p);
                let (d, s) = brute_force(kind, &coords, p);
                assert!(
                    q.distance <= d + 1e-12,
                    "{name}: projection of {p:?} at distance {} ({:?} at {:?}), sampling finds {d} at {s:?}",
                    q.distance,
                    q.feature,
                    q.natural
                );
                assert!(
                    q.distance >= d - 1e-9,
                    "{name}: the sampling's minimum {d} is below the projection's {}",
                    q.distance
                );
                let r = difference(p, q.point);
                let (x, t) = facet_frame(kind, &coords, q.natural);
                assert_eq!(
                    x, q.point,
                    "{name}: the point is the facet's at the natural point"
                );
                match q.feature {
                    FacetFeature::Interior => {
                        for (k, tk) in t.iter().enumerate() {
                            let c = dot(r, *tk) / dot(*tk, *tk).sqrt();
                            assert!(c.abs() < 1e-12, "{name}: (x - p).t_{k} = {c}");
                        }
                        // p - x is along the normal
                        let along = dot(r, q.normal);
                        assert!((along.abs() - q.distance).abs() < 1e-12, "{name}");
                    }
                    FacetFeature::Edge(k) => {
                        let (a, b) = (corners[k], corners[(k + 1) % corners.len()]);
                        let d = [b[0] - a[0], b[1] - a[1]];
                        let tangent: [f64; 3] =
                            std::array::from_fn(|i| t[0][i] * d[0] + t[1][i] * d[1]);
                        let c = dot(r, tangent) / dot(tangent, tangent).sqrt();
                        assert!(c.abs() < 1e-12, "{name}: (x - p).T on edge {k} = {c}");
                    }
                    FacetFeature::Corner(k) => {
                        assert_eq!(q.natural, corners[k], "{name}");
                        assert_eq!(q.point, coords[k], "{name}: a corner is its node");
                    }
                }
                features.insert(format!("{:?}", std::mem::discriminant(&q.feature)));
                let n = dot(q.normal, q.normal).sqrt();
                assert!((n - 1.0).abs() < 1e-14);
            }
        }
        assert_eq!(features.len(), 3, "interior, edge and corner cases all met");
    }
}
