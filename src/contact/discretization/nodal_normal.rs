//! The consistent linearization, in the current configuration (finite kinematics), of the
//! contact rows whose gap is measured along a **nodal normal**: node-to-surface with slave
//! normals, in two forms, and node-to-node. The row's force direction `f` (its `coeffs`), the
//! gap's gradient and the derivative `df/dx` the Newton tangent needs.
//!
//! **The nodal normal** (the same one the `geometry` module's surfaces give): the normalized sum
//! over the surface facets at node `a` of `m_a = int N_a n |x'| ds = int N_a [x'_y, -x'_x] ds`
//! (the facet's Gauss rule), so `n_a = m_a / |m_a|` depends on the node and its neighbours along
//! the surface (a Line2 surface: the two adjacent facets' nodes).
//!
//! **Slave normals** (Taylor 2004, "Normals from FE mesh": the slave form involves 5 nodes on a
//! Line2 surface; Wriggers, *Computational Contact Mechanics*, 2nd ed. 2006, section 4.1). The
//! ray from the slave node `x_s` along `nu = -n_s` meets the master facet
//! `x(xi) = sum_b N_b(xi) x_b` where `c(xi) = (x(xi) - x_s) x nu = 0` (2D cross product), and the
//! gap is `g = nu . (x_s - x(xi))`, so `x_s - x(xi) = g nu`. Its first variation is
//!
//! `delta g = nu . (delta x_s - sum_b N_b delta x_b) - (nu . x_xi) delta xi`
//!
//! (`delta nu` is normal to `nu`, hence to `x_s - x`), where `delta xi` follows from
//! `delta c = 0` and carries `delta nu`, i.e. the slave node's neighbours. Two forms:
//!
//! * **consistent**: the row's force direction is the gradient `b = grad g` over the slave
//!   node, its neighbours and the master facet's nodes, and the tangent adds `-lambda H`,
//!   `H = grad^2 g` (symmetric);
//! * **smooth sliding** (Taylor 2004, "Difficulty: slave normal not perpendicular to master
//!   facet": ignore the `delta xi` term): the force direction is
//!   `f = (nu, -N_b(xi) nu)` on the slave node and the facet's nodes only (3 nodes on Line2),
//!   `delta Pi_c = lambda A (delta x_s - N_b delta x_b) . nu`, while the force
//!   `lambda = -w g` still varies with the whole gap: the tangent is
//!   `w f (grad g)^T - lambda df/dx`, **unsymmetric** (`f != grad g` wherever `nu` is not
//!   perpendicular to the facet). It is the exact derivative of that residual.
//!
//! **Node-to-node** at finite strain: `g = n_m . (x_s - x_m)` with the master node's nodal
//! normal `n_m`, consistently linearized (`b = grad g` over the slave node, the master node and
//! its neighbours, `H = grad^2 g`).
//!
//! The derivatives are exact: forward-mode automatic differentiation (`num-dual`: dual numbers
//! for `df/dx`, second-order dual numbers for `grad g` and `H`) of the gap written out here. The
//! facet parameter `xi` is the root found by the search; two Newton steps on `c(xi) = 0` in
//! dual arithmetic from it carry its first and second derivatives (implicit function theorem:
//! from an exact root, each step doubles the order of the derivatives that are exact). The unit
//! tests check `grad g`, `H` and `df/dx` against central differences of the gap and of `f`
//! computed afresh by the `geometry` module's projection, on straight and curved facets.

use super::geometry::edge_shape;
use crate::fe::EdgeKind;
use crate::io::scene::SlaveNormalVariation;
use nalgebra::DVector;
use num_dual::{gradient, hessian, Dual2DVec64, DualDVec64, DualNum};

/// What the gap of a nodal-normal row is measured against.
#[derive(Clone, Debug, PartialEq)]
pub enum NormalTarget {
    /// Node-to-surface with slave normals: `nu = -n_s` (the row's own node, index 0), the ray's
    /// point `xi` on the master facet whose nodes are `positions[start..]` in edge order.
    SlaveRay {
        master_kind: EdgeKind,
        start: usize,
        xi: f64,
        variation: SlaveNormalVariation,
    },
    /// Node-to-node: `nu = n_m`, the nodal normal of the master node `positions[master]`.
    MasterNode { master: usize },
}

/// A nodal-normal row's nodes: their global dofs (`x`, `y` per node) and positions in the
/// configuration the row was built in, the slave node first; the facets whose nodal normal
/// the gap takes (indices into `positions`, edge order) and whose node carries it.
#[derive(Clone, Debug, PartialEq)]
pub struct NodalNormalLinearization {
    pub dofs: Vec<usize>,
    pub positions: Vec<[f64; 2]>,
    /// The kind of the facets of the surface that owns the normal.
    pub normal_kind: EdgeKind,
    /// The node (index into `positions`) whose nodal normal the gap takes.
    pub normal_node: usize,
    /// The facets of that surface at that node.
    pub normal_facets: Vec<Vec<usize>>,
    pub target: NormalTarget,
}

/// The second-order part of a row's linearization over the row's nodes, in the form the Newton
/// tangent consumes for every row type: with the row's force `lambda` (penalty `lambda = -w g`)
/// acting along its force direction `f` (the row's `coeffs`), the tangent of `-lambda f` is
/// `w f (grad g)^T - lambda df/dx`. `gap_gradient` is `None` where `f = grad g` (then
/// `df/dx` is the gap's symmetric Hessian).
#[derive(Clone, Debug, PartialEq)]
pub struct RowCurvature {
    pub dofs: Vec<usize>,
    /// `df_a / dx_c`, row-major over `dofs`.
    pub direction_derivative: Vec<f64>,
    /// `grad g` over `dofs` where it is not the force direction.
    pub gap_gradient: Option<Vec<f64>>,
}

fn cross<D: DualNum<Primitive = f64>>(a: &[D; 2], b: &[D; 2]) -> D {
    a[0].clone() * b[1].clone() - a[1].clone() * b[0].clone()
}

fn dot<D: DualNum<Primitive = f64>>(a: &[D; 2], b: &[D; 2]) -> D {
    a[0].clone() * b[0].clone() + a[1].clone() * b[1].clone()
}

/// Edge shape functions and their derivatives at a (dual) parameter `s`.
fn shape_at<D: DualNum<Primitive = f64>>(kind: EdgeKind, s: &D) -> (Vec<D>, Vec<D>) {
    let one = D::from(1.0);
    match kind {
        EdgeKind::Line2 => (
            vec![(one.clone() - s.clone()) * 0.5, (one + s.clone()) * 0.5],
            vec![D::from(-0.5), D::from(0.5)],
        ),
        EdgeKind::Line3 => (
            vec![
                s.clone() * (s.clone() - 1.0) * 0.5,
                s.clone() * (s.clone() + 1.0) * 0.5,
                one - s.clone() * s.clone(),
            ],
            vec![s.clone() - 0.5, s.clone() + 0.5, s.clone() * -2.0],
        ),
    }
}

impl NodalNormalLinearization {
    fn node<D: DualNum<Primitive = f64>>(x: &[D], k: usize) -> [D; 2] {
        [x[2 * k].clone(), x[2 * k + 1].clone()]
    }

    /// The unit nodal normal of `normal_node` at the coordinates `x` (flattened positions).
    fn nodal_normal<D: DualNum<Primitive = f64>>(&self, x: &[D]) -> [D; 2] {
        let kind = self.normal_kind;
        let mut m = [D::from(0.0), D::from(0.0)];
        for facet in &self.normal_facets {
            let Some(a) = facet.iter().position(|&i| i == self.normal_node) else {
                continue;
            };
            for (s, w) in kind.load_rule() {
                let (n, dn) = edge_shape(kind, s);
                let mut t = [D::from(0.0), D::from(0.0)];
                for (b, &k) in facet.iter().enumerate() {
                    let p = Self::node(x, k);
                    t[0] += p[0].clone() * dn[b];
                    t[1] += p[1].clone() * dn[b];
                }
                m[0] += t[1].clone() * (w * n[a]);
                m[1] -= t[0].clone() * (w * n[a]);
            }
        }
        let l = dot(&m, &m).sqrt();
        [m[0].clone() / l.clone(), m[1].clone() / l]
    }

    /// The ray direction `nu`, the master point's shape values and its parameter (slave rays),
    /// or `nu` and the master node (node-to-node), at `x`.
    #[allow(clippy::type_complexity)]
    fn geometry<D: DualNum<Primitive = f64>>(&self, x: &[D]) -> ([D; 2], [D; 2], Vec<D>) {
        let x_s = Self::node(x, 0);
        match &self.target {
            NormalTarget::MasterNode { master } => {
                let nu = self.nodal_normal(x);
                (nu, Self::node(x, *master), Vec::new())
            }
            NormalTarget::SlaveRay {
                master_kind,
                start,
                xi,
                ..
            } => {
                let n_s = self.nodal_normal(x);
                let nu = [-n_s[0].clone(), -n_s[1].clone()];
                let facet: Vec<[D; 2]> = (*start..self.positions.len())
                    .map(|k| Self::node(x, k))
                    .collect();
                let point = |s: &D| {
                    let (n, dn) = shape_at(*master_kind, s);
                    let mut p = [D::from(0.0), D::from(0.0)];
                    let mut t = [D::from(0.0), D::from(0.0)];
                    for (b, q) in facet.iter().enumerate() {
                        for i in 0..2 {
                            p[i] += q[i].clone() * n[b].clone();
                            t[i] += q[i].clone() * dn[b].clone();
                        }
                    }
                    (p, t, n)
                };
                // two Newton steps on c(s) = (x(s) - x_s) x nu = 0 from the search's root
                let mut s = D::from(*xi);
                for _ in 0..2 {
                    let (p, t, _) = point(&s);
                    let r = [p[0].clone() - x_s[0].clone(), p[1].clone() - x_s[1].clone()];
                    s -= cross(&r, &nu) / cross(&t, &nu);
                }
                let (p, _, n) = point(&s);
                (nu, p, n)
            }
        }
    }

    /// The gap at the flattened coordinates `x`.
    fn gap_at<D: DualNum<Primitive = f64>>(&self, x: &[D]) -> D {
        let x_s = Self::node(x, 0);
        let (nu, p, _) = self.geometry(x);
        let r = [x_s[0].clone() - p[0].clone(), x_s[1].clone() - p[1].clone()];
        dot(&nu, &r)
    }

    /// The smooth-sliding force direction `f = (nu, -N_b nu)` (zero on the neighbours) at `x`.
    fn smooth_direction_at<D: DualNum<Primitive = f64>>(&self, x: &[D]) -> Vec<D> {
        let (nu, _, n) = self.geometry(x);
        let mut f = vec![D::from(0.0); x.len()];
        f[0] = nu[0].clone();
        f[1] = nu[1].clone();
        if let NormalTarget::SlaveRay { start, .. } = self.target {
            for (b, nb) in n.iter().enumerate() {
                for i in 0..2 {
                    f[2 * (start + b) + i] = -(nu[i].clone() * nb.clone());
                }
            }
        }
        f
    }

    fn flat(&self) -> DVector<f64> {
        DVector::from_iterator(
            2 * self.positions.len(),
            self.positions.iter().flat_map(|p| [p[0], p[1]]),
        )
    }

    fn smooth_sliding(&self) -> bool {
        matches!(
            self.target,
            NormalTarget::SlaveRay {
                variation: SlaveNormalVariation::SmoothSliding,
                ..
            }
        )
    }

    /// The gap `g`, its gradient and its Hessian (row-major) over the row's dofs at the stored
    /// positions.
    pub fn gap_gradient_hessian(&self) -> (f64, Vec<f64>, Vec<f64>) {
        let (g, grad, hess) = hessian(
            |x: DVector<Dual2DVec64>| self.gap_at(x.as_slice()),
            &self.flat(),
        );
        let n = grad.len();
        let mut h = vec![0.0; n * n];
        for a in 0..n {
            for c in 0..n {
                // symmetric to round-off; averaged so the tangent's symmetry is exact
                h[a * n + c] = 0.5 * (hess[(a, c)] + hess[(c, a)]);
            }
        }
        (g, grad.iter().copied().collect(), h)
    }

    /// The gap and the row's force direction over the row's dofs (`grad g`, or the
    /// smooth-sliding `f`).
    pub fn gap_and_direction(&self) -> (f64, Vec<f64>) {
        if self.smooth_sliding() {
            let x: Vec<f64> = self.flat().iter().copied().collect();
            (self.gap_at(&x), self.smooth_direction_at(&x))
        } else {
            let (g, grad) = gradient(
                |x: DVector<DualDVec64>| self.gap_at(x.as_slice()),
                &self.flat(),
            );
            (g, grad.iter().copied().collect())
        }
    }

    /// The second-order part of the row's linearization (see [`RowCurvature`]).
    pub fn curvature(&self) -> RowCurvature {
        let (_, grad, hess) = self.gap_gradient_hessian();
        if !self.smooth_sliding() {
            return RowCurvature {
                dofs: self.dofs.clone(),
                direction_derivative: hess,
                gap_gradient: None,
            };
        }
        let n = grad.len();
        let mut jac = vec![0.0; n * n];
        let x = self.flat();
        for a in 0..n {
            let (_, row) = gradient(
                |x: DVector<DualDVec64>| self.smooth_direction_at(x.as_slice())[a].clone(),
                &x,
            );
            for c in 0..n {
                jac[a * n + c] = row[c];
            }
        }
        RowCurvature {
            dofs: self.dofs.clone(),
            direction_derivative: jac,
            gap_gradient: Some(grad),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::geometry::{facet_point, ray_point};
    use super::*;

    /// A slave surface `slave` (three nodes, two facets of `slave_kind`, or five nodes on Line3)
    /// against the master facet `master`: the row of the slave surface's middle vertex.
    fn slave_row(
        slave_kind: EdgeKind,
        slave: &[[f64; 2]],
        master_kind: EdgeKind,
        master: &[[f64; 2]],
        variation: SlaveNormalVariation,
    ) -> NodalNormalLinearization {
        // positions: the slave node, its neighbours, then the master facet
        let (positions, facets) = match slave_kind {
            // slave = [left, middle, right]; facets middle->left? edge order along the
            // surface: [left, middle], [middle, right]
            EdgeKind::Line2 => (
                vec![slave[1], slave[0], slave[2]],
                vec![vec![1, 0], vec![0, 2]],
            ),
            // slave = [left, middle, right, mid of left facet, mid of right facet]
            EdgeKind::Line3 => (
                vec![slave[1], slave[0], slave[2], slave[3], slave[4]],
                vec![vec![1, 0, 3], vec![0, 2, 4]],
            ),
        };
        let start = positions.len();
        let mut positions = positions;
        positions.extend_from_slice(master);
        let mut lin = NodalNormalLinearization {
            dofs: (0..2 * positions.len()).collect(),
            positions,
            normal_kind: slave_kind,
            normal_node: 0,
            normal_facets: facets,
            target: NormalTarget::SlaveRay {
                master_kind,
                start,
                xi: 0.0,
                variation,
            },
        };
        lin.target = NormalTarget::SlaveRay {
            master_kind,
            start,
            xi: fresh_xi(&lin),
            variation,
        };
        lin
    }

    /// The nodal normal by the geometry module's surface weights (independent of this module):
    /// the normalized sum of `int N_a n |x'|` over the facets at the node.
    fn reference_normal(lin: &NodalNormalLinearization) -> [f64; 2] {
        let kind = lin.normal_kind;
        let mut m = [0.0; 2];
        for facet in &lin.normal_facets {
            let a = facet.iter().position(|&i| i == lin.normal_node).unwrap();
            let coords: Vec<[f64; 2]> = facet.iter().map(|&k| lin.positions[k]).collect();
            for (s, w) in kind.load_rule() {
                let (n, _) = edge_shape(kind, s);
                let (_, t) = facet_point(kind, &coords, s);
                let len = (t[0] * t[0] + t[1] * t[1]).sqrt();
                let normal = super::super::geometry::unit_normal(t);
                m[0] += w * n[a] * len * normal[0];
                m[1] += w * n[a] * len * normal[1];
            }
        }
        let l = (m[0] * m[0] + m[1] * m[1]).sqrt();
        [m[0] / l, m[1] / l]
    }

    fn fresh_xi(lin: &NodalNormalLinearization) -> f64 {
        let NormalTarget::SlaveRay {
            master_kind, start, ..
        } = lin.target
        else {
            unreachable!()
        };
        let n = reference_normal(lin);
        ray_point(
            master_kind,
            &lin.positions[start..],
            lin.positions[0],
            [-n[0], -n[1]],
        )
    }

    /// The gap computed afresh: the reference normal, the geometry module's ray projection
    /// (slave rays) or the master node.
    fn fresh_gap(lin: &NodalNormalLinearization) -> f64 {
        let x_s = lin.positions[0];
        let n = reference_normal(lin);
        match lin.target {
            NormalTarget::SlaveRay {
                master_kind, start, ..
            } => {
                let xi = fresh_xi(lin);
                let (p, _) = facet_point(master_kind, &lin.positions[start..], xi);
                -n[0] * (x_s[0] - p[0]) - n[1] * (x_s[1] - p[1])
            }
            NormalTarget::MasterNode { master } => {
                let p = lin.positions[master];
                n[0] * (x_s[0] - p[0]) + n[1] * (x_s[1] - p[1])
            }
        }
    }

    /// The smooth-sliding force direction computed afresh.
    fn fresh_direction(lin: &NodalNormalLinearization) -> Vec<f64> {
        let NormalTarget::SlaveRay {
            master_kind, start, ..
        } = lin.target
        else {
            unreachable!()
        };
        let n = reference_normal(lin);
        let nu = [-n[0], -n[1]];
        let (shape, _) = edge_shape(master_kind, fresh_xi(lin));
        let mut f = vec![0.0; 2 * lin.positions.len()];
        f[0] = nu[0];
        f[1] = nu[1];
        for b in 0..master_kind.node_count() {
            for i in 0..2 {
                f[2 * (start + b) + i] = -shape[b] * nu[i];
            }
        }
        f
    }

    fn moved(lin: &NodalNormalLinearization, k: usize, h: f64) -> NodalNormalLinearization {
        let mut m = lin.clone();
        m.positions[k / 2][k % 2] += h;
        if let NormalTarget::SlaveRay {
            master_kind,
            start,
            variation,
            ..
        } = m.target
        {
            m.target = NormalTarget::SlaveRay {
                master_kind,
                start,
                xi: fresh_xi(&m),
                variation,
            };
        }
        m
    }

    fn largest(v: &[f64]) -> f64 {
        v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
    }

    /// `grad g` against central differences of the fresh gap, and `H` against central
    /// differences of `grad g` (relative to their largest entries).
    fn check_gap(lin: &NodalNormalLinearization) -> (f64, f64) {
        let (g, grad, hess) = lin.gap_gradient_hessian();
        assert!((g - fresh_gap(lin)).abs() < 1e-13, "{g} {}", fresh_gap(lin));
        let n = grad.len();
        let h = 1e-6;
        let (mut eg, mut eh) = (0.0f64, 0.0f64);
        for k in 0..n {
            let (p, q) = (moved(lin, k, h), moved(lin, k, -h));
            let fd = (fresh_gap(&p) - fresh_gap(&q)) / (2.0 * h);
            eg = eg.max((fd - grad[k]).abs() / largest(&grad));
            let (gp, gq) = (p.gap_gradient_hessian().1, q.gap_gradient_hessian().1);
            for a in 0..n {
                let fd = (gp[a] - gq[a]) / (2.0 * h);
                eh = eh.max((fd - hess[a * n + k]).abs() / largest(&hess));
            }
        }
        (eg, eh)
    }

    const LINE2_SLAVE: [[f64; 2]; 3] = [[-0.45, 0.62], [0.1, 0.55], [0.6, 0.71]];
    const LINE2_MASTER: [[f64; 2]; 2] = [[-0.4, 0.1], [1.3, 0.45]];
    // a curved slave surface (mid nodes off the chords) over a curved master facet
    const LINE3_SLAVE: [[f64; 2]; 5] = [
        [-0.5, 0.6],
        [0.1, 0.55],
        [0.7, 0.72],
        [-0.2, 0.61],
        [0.42, 0.6],
    ];
    const LINE3_MASTER: [[f64; 2]; 3] = [[-1.0, 0.0], [1.1, 0.1], [0.05, 0.25]];

    #[test]
    fn the_slave_normal_gap_s_gradient_and_second_derivative_are_its_differences() {
        for (kind, slave, master) in [
            (EdgeKind::Line2, &LINE2_SLAVE[..], &LINE2_MASTER[..]),
            (EdgeKind::Line3, &LINE3_SLAVE[..], &LINE3_MASTER[..]),
        ] {
            // the slave node above the facet (g > 0), then pushed below it (g < 0)
            for lift in [0.0, -0.8] {
                let mut slave = slave.to_vec();
                slave.iter_mut().for_each(|p| p[1] += lift);
                let lin = slave_row(kind, &slave, kind, master, SlaveNormalVariation::Consistent);
                let (eg, eh) = check_gap(&lin);
                let (g, grad, _) = lin.gap_gradient_hessian();
                // the neighbours carry part of the gradient (the normal's variation): the
                // "5 nodes" of the slave form
                let on_neighbours =
                    largest(&grad[2..2 * (lin.positions.len() - kind.node_count())]);
                println!(
                    "{kind:?} g {g:.3}: gradient {eg:.1e}, second derivative {eh:.1e}, largest neighbour entry {on_neighbours:.3}"
                );
                assert!(eg < 1e-8 && eh < 1e-7, "{eg:e} {eh:e}");
                assert!(on_neighbours > 1e-3);
                let (g2, b) = lin.gap_and_direction();
                assert!((g2 - g).abs() < 1e-15);
                assert!(b.iter().zip(&grad).all(|(x, y)| (x - y).abs() < 1e-14));
            }
        }
    }

    #[test]
    fn the_smooth_sliding_direction_s_derivative_is_its_difference() {
        for (kind, slave, master) in [
            (EdgeKind::Line2, &LINE2_SLAVE[..], &LINE2_MASTER[..]),
            (EdgeKind::Line3, &LINE3_SLAVE[..], &LINE3_MASTER[..]),
        ] {
            let lin = slave_row(
                kind,
                slave,
                kind,
                master,
                SlaveNormalVariation::SmoothSliding,
            );
            let (g, f) = lin.gap_and_direction();
            assert!((g - fresh_gap(&lin)).abs() < 1e-13);
            let fresh = fresh_direction(&lin);
            assert!(f.iter().zip(&fresh).all(|(a, b)| (a - b).abs() < 1e-13));
            let curvature = lin.curvature();
            let jac = &curvature.direction_derivative;
            let grad = curvature.gap_gradient.as_ref().unwrap();
            let n = f.len();
            let h = 1e-6;
            let mut error = 0.0f64;
            for k in 0..n {
                let (p, q) = (moved(&lin, k, h), moved(&lin, k, -h));
                let (fp, fq) = (fresh_direction(&p), fresh_direction(&q));
                for a in 0..n {
                    let fd = (fp[a] - fq[a]) / (2.0 * h);
                    error = error.max((fd - jac[a * n + k]).abs() / largest(jac));
                }
            }
            // the force direction differs from the gap's gradient (the ignored delta xi term),
            // so the tangent w f grad^T - lambda df/dx is unsymmetric
            let difference = f
                .iter()
                .zip(grad)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            let asymmetry = (0..n)
                .flat_map(|a| (0..n).map(move |c| (a, c)))
                .fold(0.0f64, |m, (a, c)| {
                    m.max((jac[a * n + c] - jac[c * n + a]).abs())
                });
            println!(
                "{kind:?}: df/dx against differences {error:.1e}; |f - grad g| {difference:.3}, asymmetry of df/dx {asymmetry:.3}"
            );
            assert!(error < 1e-7, "{error:e}");
            assert!(difference > 1e-2 && asymmetry > 1e-2);
            // three nodes on Line2: nothing on the neighbours
            let start = lin.positions.len() - kind.node_count();
            assert!(f[2..2 * start].iter().all(|&v| v == 0.0));
        }
    }

    #[test]
    fn the_node_to_node_gap_s_gradient_and_second_derivative_are_its_differences() {
        // the master node (index 1) with its surface neighbours 2 and 3, the slave node off it
        // (tangentially and normally)
        for slave in [[0.13, 0.08], [-0.05, -0.04]] {
            let lin = NodalNormalLinearization {
                dofs: (0..8).collect(),
                positions: vec![slave, [0.0, 0.0], [-0.5, 0.1], [0.55, 0.05]],
                normal_kind: EdgeKind::Line2,
                normal_node: 1,
                // edge order: outward normal up for facets running right to left
                normal_facets: vec![vec![3, 1], vec![1, 2]],
                target: NormalTarget::MasterNode { master: 1 },
            };
            let n = reference_normal(&lin);
            assert!(n[1] > 0.9, "{n:?}");
            let (eg, eh) = check_gap(&lin);
            println!("node-to-node: gradient {eg:.1e}, second derivative {eh:.1e}");
            assert!(eg < 1e-8 && eh < 1e-7, "{eg:e} {eh:e}");
        }
    }

    #[test]
    fn the_nodal_normal_is_the_surface_s() {
        // the nodal normal in dual arithmetic against the geometry module's weights, on Line3
        // facets through nodes on a circle of radius 2 about the origin, placed symmetrically
        // about the middle node: its normal is the radius there
        let at = |a: f64| [2.0 * a.sin(), 2.0 * a.cos()];
        let lin = NodalNormalLinearization {
            dofs: (0..10).collect(),
            positions: vec![at(0.0), at(-0.2), at(0.2), at(-0.1), at(0.1)],
            normal_kind: EdgeKind::Line3,
            normal_node: 0,
            // edge order right to left: the outward normal of the disc, up
            normal_facets: vec![vec![0, 1, 3], vec![2, 0, 4]],
            target: NormalTarget::MasterNode { master: 0 },
        };
        let x: Vec<f64> = lin.positions.iter().flat_map(|p| [p[0], p[1]]).collect();
        let n = lin.nodal_normal(&x);
        let r = reference_normal(&lin);
        assert!((n[0] - r[0]).abs() < 1e-15 && (n[1] - r[1]).abs() < 1e-15);
        assert!(n[0].abs() < 1e-12 && (n[1] - 1.0).abs() < 1e-12, "{n:?}");
    }
}
