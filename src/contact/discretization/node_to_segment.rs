//! The consistent linearization of the node-to-segment gap between two deformable bodies in
//! the current configuration (finite kinematics, master normals): the second derivative of
//! the gap with respect to every dof of the row, which the Newton tangent needs besides the
//! gradient `b` the row already carries.
//!
//! **The gap** (Wriggers, *Computational Contact Mechanics*, 2nd ed. 2006, sections 4.1 and
//! 9.1; Simo, Wriggers & Taylor 1985). A master facet `x(xi) = sum_b N_b(xi) x_b` (Line2 or
//! Line3, `xi in [-1, 1]`, tangent `tau = x_xi = sum_b N_b' x_b`, outward unit normal
//! `n = [tau_y, -tau_x] / |tau|`) and a slave node `x_s`. The closest point `xi` solves
//! `f(xi) = (x_s - x(xi)) . tau(xi) = 0`, and the gap is `g = n . (x_s - x(xi))`, so
//! `x_s - x(xi) = g n`.
//!
//! **First variation.** `delta g = n . (delta x_s - sum_b N_b delta x_b)`: the terms of
//! `delta xi` and `delta n` drop out (`n . tau = 0`, and `delta n` is normal to `n` while
//! `x_s - x = g n`). This is the row's gradient `b` (`weighted_row` in the discretization module).
//!
//! **The variation of the closest point.** Differentiating `f = 0`, with the curvature term
//! `kappa = n . x_xixi` (`x_xixi = sum_b N_b'' x_b`, zero on Line2):
//!
//! `delta xi = (T . delta + g N1 . delta) / m`, `m = tau . tau - g kappa`,
//!
//! where, over the row's dofs `delta = (delta x_s, delta x_1, .., delta x_k)`,
//! `T . delta = tau . (delta x_s - sum_b N_b delta x_b)` (the tangential relative motion) and
//! `N1 . delta = n . sum_b N_b' delta x_b` (the rotation of the facet).
//!
//! **Second variation.** With `Delta n = -(n . Delta tau) tau / |tau|^2` (a unit normal turns
//! with the tangent) and `n . Delta tau = N1 . Delta + kappa Delta xi`,
//!
//! `Delta delta g = Delta n . (delta x_s - sum N_b delta x_b) - (N1 . delta) Delta xi`
//! `             = -(1/m) [T N1^T + N1 T^T + g N1 N1^T + (kappa / |tau|^2) T T^T]`
//!
//! (the `T N1^T` coefficient `-(1 + kappa g / m) / |tau|^2` is `-1/m`, so the block is
//! symmetric). On a straight facet (`kappa = 0`, `m = |tau|^2 = (l/2)^2`) this is Wriggers'
//! node-to-segment matrix, `-(1/|tau|^2) (T N1^T + N1 T^T + g N1 N1^T)`, whose `g N1 N1^T` part
//! vanishes with the gap. The contact force `lambda n` on the slave node (and `-N_b lambda n` on
//! the facet) then has the tangent `w b b^T - lambda H` (penalty `lambda = -w g`), the terms
//! of `delta xi` (`T`) and of the normal's rotation (`N1`) included.
//!
//! **The corner condition** (a slave node in the wedge outside a convex master vertex `x_v`):
//! `g = |x_s - x_v|`, `b = (nu, -nu)`, `nu = (x_s - x_v) / g`, and
//! `H = [[P, -P], [-P, P]] / g` with `P = I - nu nu^T`. A node inside the master body under a
//! concave vertex (behind the vertex's normal, past both facets' ends) is a penetration:
//! `g = -|x_s - x_v|`, and `b`, `H` change sign (`side = -1`).
//!
//! The unit tests check `b` and `H` against central differences of the gap computed afresh
//! by the closest-point projection of the `geometry` module, on a straight and a curved facet.

use super::geometry::{edge_shape, facet_point, unit_normal};
use crate::fe::EdgeKind;

/// Where a node-to-segment row meets its master.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum MasterPoint {
    /// The closest point `xi` of a facet of `kind`.
    Facet { kind: EdgeKind, xi: f64 },
    /// A master vertex (the corner condition): `side` is `1` for a node outside a convex
    /// corner, `-1` for a node behind a concave one (its gap `side |x_s - x_v|`).
    Vertex { side: f64 },
}

/// What the second derivative of a node-to-segment gap needs: the row's nodes (the slave node
/// first, then the master facet's nodes in edge order, or the corner vertex), their global dofs
/// (`x`, `y` per node) and their positions in the configuration the row was built in.
#[derive(Clone, Debug, PartialEq)]
pub struct SegmentLinearization {
    pub dofs: Vec<usize>,
    pub positions: Vec<[f64; 2]>,
    pub point: MasterPoint,
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

impl SegmentLinearization {
    /// The gap `g` and its second derivative `H` (row-major, `dofs.len()` squared) at the
    /// stored positions.
    pub fn gap_and_hessian(&self) -> (f64, Vec<f64>) {
        let n_dofs = 2 * self.positions.len();
        let mut h = vec![0.0; n_dofs * n_dofs];
        let x_s = self.positions[0];
        match self.point {
            MasterPoint::Vertex { side } => {
                let x_v = self.positions[1];
                let d = [x_s[0] - x_v[0], x_s[1] - x_v[1]];
                let g = dot(d, d).sqrt();
                if g == 0.0 {
                    return (0.0, h);
                }
                let nu = [d[0] / g, d[1] / g];
                for i in 0..2 {
                    for j in 0..2 {
                        let p = side * (if i == j { 1.0 } else { 0.0 } - nu[i] * nu[j]) / g;
                        h[i * n_dofs + j] = p;
                        h[(2 + i) * n_dofs + 2 + j] = p;
                        h[i * n_dofs + 2 + j] = -p;
                        h[(2 + i) * n_dofs + j] = -p;
                    }
                }
                (side * g, h)
            }
            MasterPoint::Facet { kind, xi } => {
                let facet = &self.positions[1..];
                let (shape, dshape) = edge_shape(kind, xi);
                let (x, tau) = facet_point(kind, facet, xi);
                let n = unit_normal(tau);
                let r = [x_s[0] - x[0], x_s[1] - x[1]];
                let g = dot(n, r);
                // x_xixi = sum_b N_b'' x_b: N'' = [1, 1, -2] on Line3, zero on Line2
                let kappa = match kind {
                    EdgeKind::Line2 => 0.0,
                    EdgeKind::Line3 => {
                        let xx = [
                            facet[0][0] + facet[1][0] - 2.0 * facet[2][0],
                            facet[0][1] + facet[1][1] - 2.0 * facet[2][1],
                        ];
                        dot(n, xx)
                    }
                };
                let tau2 = dot(tau, tau);
                let m = tau2 - g * kappa;
                // T and N1 over the dofs (slave node, then the facet's nodes)
                let mut t = vec![0.0; n_dofs];
                let mut n1 = vec![0.0; n_dofs];
                t[0] = tau[0];
                t[1] = tau[1];
                for b in 0..facet.len() {
                    for i in 0..2 {
                        t[2 + 2 * b + i] = -shape[b] * tau[i];
                        n1[2 + 2 * b + i] = dshape[b] * n[i];
                    }
                }
                let c = kappa / tau2;
                for a in 0..n_dofs {
                    for e in a..n_dofs {
                        let v =
                            -(t[a] * n1[e] + n1[a] * t[e] + g * n1[a] * n1[e] + c * t[a] * t[e])
                                / m;
                        h[a * n_dofs + e] = v;
                        h[e * n_dofs + a] = v;
                    }
                }
                (g, h)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::geometry::closest_point;
    use super::*;

    /// The gap of `positions` (slave, then facet nodes) by a fresh closest-point projection.
    fn gap(kind: EdgeKind, positions: &[[f64; 2]]) -> f64 {
        let xi = closest_point(kind, &positions[1..], positions[0]);
        let (x, tau) = facet_point(kind, &positions[1..], xi);
        let n = unit_normal(tau);
        dot(n, [positions[0][0] - x[0], positions[0][1] - x[1]])
    }

    /// The gradient `b = (n, -N_b n)` at `positions`.
    fn gradient(kind: EdgeKind, positions: &[[f64; 2]]) -> Vec<f64> {
        let xi = closest_point(kind, &positions[1..], positions[0]);
        let (shape, _) = edge_shape(kind, xi);
        let (_, tau) = facet_point(kind, &positions[1..], xi);
        let n = unit_normal(tau);
        let mut b = vec![n[0], n[1]];
        for s in shape.iter().take(positions.len() - 1) {
            b.extend([-s * n[0], -s * n[1]]);
        }
        b
    }

    fn perturbed(positions: &[[f64; 2]], k: usize, h: f64) -> Vec<[f64; 2]> {
        let mut p = positions.to_vec();
        p[k / 2][k % 2] += h;
        p
    }

    /// The gradient and the second derivative against central differences of the gap
    /// projected afresh (and of the gradient), relative to their largest entries.
    fn check(kind: EdgeKind, positions: Vec<[f64; 2]>) -> (f64, f64) {
        let xi = closest_point(kind, &positions[1..], positions[0]);
        let lin = SegmentLinearization {
            dofs: (0..2 * positions.len()).collect(),
            positions: positions.clone(),
            point: MasterPoint::Facet { kind, xi },
        };
        let (g, hess) = lin.gap_and_hessian();
        assert!((g - gap(kind, &positions)).abs() < 1e-14);
        let n = 2 * positions.len();
        let b = gradient(kind, &positions);
        let h = 1e-6;
        let (mut gradient_error, mut hessian_error) = (0.0f64, 0.0f64);
        let b_scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let h_scale = hess.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for k in 0..n {
            let (p, q) = (perturbed(&positions, k, h), perturbed(&positions, k, -h));
            let fd = (gap(kind, &p) - gap(kind, &q)) / (2.0 * h);
            gradient_error = gradient_error.max((fd - b[k]).abs() / b_scale);
            let (bp, bq) = (gradient(kind, &p), gradient(kind, &q));
            for a in 0..n {
                let fd = (bp[a] - bq[a]) / (2.0 * h);
                hessian_error = hessian_error.max((fd - hess[a * n + k]).abs() / h_scale);
            }
        }
        for a in 0..n {
            for k in 0..n {
                assert_eq!(hess[a * n + k], hess[k * n + a], "symmetric");
            }
        }
        (gradient_error, hessian_error)
    }

    #[test]
    fn the_second_derivative_is_the_difference_of_the_gradient_on_a_straight_facet() {
        // a tilted facet, the slave node above it (g > 0) and one below it (g < 0)
        for slave in [[0.7, 0.9], [0.2, -0.15]] {
            let (gb, gh) = check(EdgeKind::Line2, vec![slave, [-0.4, 0.1], [1.3, 0.35]]);
            println!("Line2: gradient {gb:.1e}, second derivative {gh:.1e}");
            assert!(gb < 1e-8 && gh < 1e-7, "{gb:e} {gh:e}");
        }
    }

    #[test]
    fn the_second_derivative_is_the_difference_of_the_gradient_on_a_curved_facet() {
        // a parabola arc with its mid node off the chord: the curvature term kappa
        for slave in [[0.3, 0.6], [-0.2, 0.05]] {
            let (gb, gh) = check(
                EdgeKind::Line3,
                vec![slave, [-1.0, 0.0], [1.1, 0.1], [0.05, 0.25]],
            );
            println!("Line3: gradient {gb:.1e}, second derivative {gh:.1e}");
            assert!(gb < 1e-8 && gh < 1e-7, "{gb:e} {gh:e}");
        }
    }

    /// The corner condition's gap and second derivative against the second difference of the
    /// signed distance `side |x_s - x_v|`, outside a convex vertex (`side = 1`) and behind a
    /// concave one (`side = -1`).
    #[test]
    fn the_corner_condition_has_the_distance_s_second_derivative() {
        let positions = vec![[0.4, 0.3], [0.1, -0.2]];
        for side in [1.0, -1.0] {
            let lin = SegmentLinearization {
                dofs: vec![0, 1, 2, 3],
                positions: positions.clone(),
                point: MasterPoint::Vertex { side },
            };
            let (g, hess) = lin.gap_and_hessian();
            let distance = |p: &[[f64; 2]]| {
                side * ((p[0][0] - p[1][0]).powi(2) + (p[0][1] - p[1][1]).powi(2)).sqrt()
            };
            assert!((g - distance(&positions)).abs() < 1e-15);
            let h = 1e-5;
            for a in 0..4 {
                for k in 0..4 {
                    // the second difference of the signed distance
                    let pp = perturbed(&perturbed(&positions, a, h), k, h);
                    let pm = perturbed(&perturbed(&positions, a, h), k, -h);
                    let mp = perturbed(&perturbed(&positions, a, -h), k, h);
                    let mm = perturbed(&perturbed(&positions, a, -h), k, -h);
                    let fd = (distance(&pp) - distance(&pm) - distance(&mp) + distance(&mm))
                        / (4.0 * h * h);
                    assert!(
                        (fd - hess[a * 4 + k]).abs() < 1e-5,
                        "side {side}, {a} {k}: {fd} {}",
                        hess[a * 4 + k]
                    );
                }
            }
        }
    }
}
