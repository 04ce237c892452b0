//! The consistent linearization of the mortar gap between two deformable bodies in the current
//! configuration (finite kinematics): the exact gradient `b_j` and second derivative `H_j` of
//! each mortar row's weighted gap, which the Newton residual (`-lambda_j b_j`) and tangent
//! (`w b_j b_j^T - force H_j`) need.
//!
//! **The gap** (the `mortar` module; Puso & Laursen 2004, Popp, Gee & Wall 2009 for the 2D
//! linearization). With the multiplier functions `Phi_j` of slave node `j`, every quantity in
//! the current positions `x`:
//!
//! ```text
//! g_j(x) = nu_j . S_j / A_j,
//! S_j    = sum_f sum_pieces int_a^b Phi_j(s) (x_s(s) - x_m(xi(s))) |x_s'(s)| t ds,
//! A_j    = sum_f sum_pieces int_a^b Phi_j(s) |x_s'(s)| t ds,
//! nu_j   = -n_j / |n_j|,  n_j = sum_f int_{-1}^{1} N_j(s) [x_s'_y, -x_s'_x] ds,
//! ```
//!
//! over the slave facets `f` that hold node `j` (`S_j = sum_k D_jk x_k - sum_l M_jl x_l`,
//! `A_j = sum_k D_jk`, `nu_j` the reversed nodal normal). It depends on the positions through
//!
//! * the slave facet's curve and length element `|x_s'|` at every Gauss point,
//! * the **segment ends** `a`, `b`: a facet end (fixed) or the projection of a master node
//!   `x_p` onto the slave facet, the root of `(x_s(s) - x_p) . x_s'(s) = 0`,
//! * the Gauss points `s = a + (b - a)(eta + 1)/2`, which move with the ends,
//! * the **projection** `xi(s)` of each Gauss point onto its master facet, the root of
//!   `(x_m(xi) - x_s(s)) . x_m'(xi) = 0`,
//! * the **nodal normal** `nu_j` (the same quadrature as `geometry::Surface`).
//!
//! Which master facet covers which piece and which master nodes make break points are
//! discrete choices of the search (the `mortar` module's `mortar_integrals`), held fixed; the
//! gap is smooth in `x` for fixed choices.
//!
//! **Derivatives by hyper-dual numbers.** Every step above is evaluated in second-order
//! vector dual numbers (`num_dual::Dual2DVec64`, one seed per coordinate of every node the row
//! touches), which carry the exact gradient and Hessian through the arithmetic. The implicit
//! roots (projections) are first found in `f64` and then refined by Newton steps taken in dual
//! numbers: from a converged root one step makes the first derivatives exact, a second one the
//! second derivatives (implicit function theorem), and a third is taken for safety. Line2
//! projections are in closed form.
//!
//! **Against a rigid surface** (`linearize_rigid_row`): `g_j = int Phi_j g(x_s) dGamma /
//! int Phi_j dGamma` with `g` the rigid surface's signed distance, every Gauss point's position
//! and length element in the current positions of the slave facets that hold node `j`; the same
//! hyper-dual evaluation gives its gradient and second derivative (on a straight facet against
//! a line the length element cancels and the second derivative vanishes).
//!
//! The unit tests check `b_j` against central differences of the gap computed afresh by the
//! `f64` segmentation and integration of the `mortar` module (another code path), and `H_j`
//! against central differences of `b_j`, on straight (Line2) and curved (Line3) facets at a
//! deformed, slid, non-matching configuration, including one where a slave facet's end has
//! just crossed a master node.

use super::geometry::{closest_point, Surface};
use super::mortar_segments::{gauss_rule, SubSegment};
use crate::fe::EdgeKind;
use crate::io::scene::MultiplierSpace;
use num_dual::{Dual2DVec64, DualNum};

/// A second-order dual number over the row's coordinates.
type Ad = Dual2DVec64;
type Point = [Ad; 2];

/// A row's gap with its exact gradient and second derivative over `dofs`.
#[derive(Clone, Debug)]
pub(crate) struct LinearizedGap {
    pub gap: f64,
    pub dofs: Vec<usize>,
    pub gradient: Vec<f64>,
    /// Row-major, `dofs.len()` squared, symmetric.
    pub hessian: Vec<f64>,
}

/// The positions `points` as second-order dual numbers, one seed per coordinate (`2 k`, `2 k + 1`
/// for point `k`).
fn seeded(points: &[[f64; 2]]) -> Vec<Point> {
    let variables = 2 * points.len();
    points
        .iter()
        .enumerate()
        .map(|(k, p)| {
            [
                Ad::from_re(p[0]).derivative(variables, 2 * k),
                Ad::from_re(p[1]).derivative(variables, 2 * k + 1),
            ]
        })
        .collect()
}

/// The gap `g` evaluated in dual numbers over `dofs` (two per seeded point): its value, gradient
/// and second derivative, made exactly symmetric (it is to round-off; its mean is exactly).
fn linearized(g: Ad, dofs: Vec<usize>) -> LinearizedGap {
    let variables = dofs.len();
    let gradient = g.v1.unwrap_generic(nalgebra::U1, nalgebra::Dyn(variables));
    let hessian =
        g.v2.unwrap_generic(nalgebra::Dyn(variables), nalgebra::Dyn(variables));
    let mut values = vec![0.0; variables * variables];
    for a in 0..variables {
        for c in 0..variables {
            values[a * variables + c] = 0.5 * (hessian[(a, c)] + hessian[(c, a)]);
        }
    }
    LinearizedGap {
        gap: g.re,
        dofs,
        gradient: gradient.iter().copied().collect(),
        hessian: values,
    }
}

fn constant(v: f64) -> Ad {
    Ad::from_re(v)
}

fn sub(a: &Point, b: &Point) -> Point {
    [a[0].clone() - &b[0], a[1].clone() - &b[1]]
}

/// Edge shape functions and their derivatives at `s` (node order `[start, end(, mid)]`, as
/// `fe::EdgeKind::shape`).
fn shape(kind: EdgeKind, s: &Ad) -> (Vec<Ad>, Vec<Ad>) {
    match kind {
        EdgeKind::Line2 => (
            vec![(-s.clone() + 1.0) * 0.5, (s.clone() + 1.0) * 0.5],
            vec![constant(-0.5), constant(0.5)],
        ),
        EdgeKind::Line3 => (
            vec![
                s.clone() * (s.clone() - 1.0) * 0.5,
                s.clone() * (s.clone() + 1.0) * 0.5,
                -(s.clone() * s) + 1.0,
            ],
            vec![s.clone() - 0.5, s.clone() + 0.5, s.clone() * -2.0],
        ),
    }
}

/// The multiplier functions at `s` (as `mortar::multiplier`).
fn multiplier(kind: EdgeKind, space: MultiplierSpace, s: &Ad) -> Vec<Ad> {
    match (space, kind) {
        (MultiplierSpace::Standard, _) => shape(kind, s).0,
        (MultiplierSpace::Dual, EdgeKind::Line2) => vec![
            (-(s.clone() * 3.0) + 1.0) * 0.5,
            (s.clone() * 3.0 + 1.0) * 0.5,
        ],
        (MultiplierSpace::Dual, EdgeKind::Line3) => {
            let s2 = s.clone() * s;
            vec![
                (s2.clone() * 5.0 - s.clone() * 2.0 - 1.0) * 0.25,
                (s2.clone() * 5.0 + s.clone() * 2.0 - 1.0) * 0.25,
                (-(s2 * 5.0) + 3.0) * 0.5,
            ]
        }
    }
}

/// Position and tangent of a facet at `s`.
fn facet_point(kind: EdgeKind, coords: &[Point], s: &Ad) -> (Point, Point) {
    let (n, dn) = shape(kind, s);
    let mut x = [constant(0.0), constant(0.0)];
    let mut t = [constant(0.0), constant(0.0)];
    for (a, p) in coords.iter().enumerate() {
        for i in 0..2 {
            x[i] += n[a].clone() * &p[i];
            t[i] += dn[a].clone() * &p[i];
        }
    }
    (x, t)
}

/// The closest point of `p` on a facet, from the `f64` root `start`: closed form on Line2,
/// Newton steps in dual numbers on Line3 (see the module notes).
fn project(kind: EdgeKind, coords: &[Point], p: &Point, start: f64) -> Ad {
    match kind {
        EdgeKind::Line2 => {
            let d = sub(&coords[1], &coords[0]);
            let r = sub(p, &coords[0]);
            (dot2(&r, &d) / dot2(&d, &d)) * 2.0 - 1.0
        }
        EdgeKind::Line3 => {
            // x'' is constant on Line3: sum_a N_a'' x_a with N'' = [1, 1, -2]
            let ddx = [
                coords[0][0].clone() + &coords[1][0] - coords[2][0].clone() * 2.0,
                coords[0][1].clone() + &coords[1][1] - coords[2][1].clone() * 2.0,
            ];
            let mut s = constant(start);
            for _ in 0..3 {
                let (x, t) = facet_point(kind, coords, &s);
                let r = sub(&x, p);
                let f = dot2(&r, &t);
                let df = dot2(&t, &t) + dot2(&r, &ddx);
                s -= f / df;
            }
            s
        }
    }
}

fn dot2(a: &Point, b: &Point) -> Ad {
    a[0].clone() * &b[0] + a[1].clone() * &b[1]
}

/// The gap of slave node `node`'s mortar row with its exact gradient and second derivative
/// (see the module notes), from the pieces the `f64` segmentation found (`pieces[f]` for slave
/// facet `f`, from `mortar::mortar_integrals` at the same positions). `dof(master, node, i)`
/// numbers component `i` of a slave (`master == false`) or master node.
pub(crate) fn linearize_row(
    slave: &Surface,
    master: &Surface,
    pieces: &[Vec<SubSegment>],
    space: MultiplierSpace,
    thickness: f64,
    node: usize,
    dof: impl Fn(bool, usize, usize) -> usize,
) -> LinearizedGap {
    let (ks, km) = (slave.kind, master.kind);
    let facets: Vec<usize> = (0..slave.facets.len())
        .filter(|&f| slave.facets[f].contains(&node))
        .collect();
    // the row's nodes: (on the master side, id, position)
    let mut nodes: Vec<(bool, usize, [f64; 2])> = Vec::new();
    let mut local = |on_master: bool, id: usize, p: [f64; 2]| -> usize {
        match nodes.iter().position(|n| n.0 == on_master && n.1 == id) {
            Some(k) => k,
            None => {
                nodes.push((on_master, id, p));
                nodes.len() - 1
            }
        }
    };
    let mut slave_local = Vec::new();
    let mut master_local: Vec<Vec<usize>> = Vec::new();
    let mut break_local: Vec<Vec<[Option<usize>; 2]>> = Vec::new();
    for &f in &facets {
        slave_local.push(
            (0..ks.node_count())
                .map(|a| local(false, slave.facets[f][a], slave.coords[f][a]))
                .collect::<Vec<_>>(),
        );
    }
    for &f in &facets {
        let mut on_master = Vec::new();
        let mut ends = Vec::new();
        for piece in &pieces[f] {
            let c = piece.master_facet;
            for a in 0..km.node_count() {
                on_master.push(local(true, master.facets[c][a], master.coords[c][a]));
            }
            ends.push(
                piece
                    .ends
                    .map(|(_, source)| source.map(|(id, p)| local(true, id, p))),
            );
        }
        master_local.push(on_master);
        break_local.push(ends);
    }
    let x = seeded(&nodes.iter().map(|n| n.2).collect::<Vec<_>>());
    let gauss = gauss_rule(ks, km);
    let mut area = constant(0.0);
    let mut weighted = [constant(0.0), constant(0.0)];
    let mut normal = [constant(0.0), constant(0.0)];
    for (e, &f) in facets.iter().enumerate() {
        let j = slave.facets[f]
            .iter()
            .position(|&n| n == node)
            .expect("the facet holds the node");
        let xs: Vec<Point> = slave_local[e].iter().map(|&k| x[k].clone()).collect();
        // the nodal normal's share of this facet: int N_j [x'_y, -x'_x] ds
        for (s, w) in ks.load_rule() {
            let s = constant(s);
            let (n, _) = shape(ks, &s);
            let (_, t) = facet_point(ks, &xs, &s);
            normal[0] += n[j].clone() * &t[1] * w;
            normal[1] -= n[j].clone() * &t[0] * w;
        }
        let nm = km.node_count();
        for (p, piece) in pieces[f].iter().enumerate() {
            let xm: Vec<Point> = master_local[e][p * nm..(p + 1) * nm]
                .iter()
                .map(|&k| x[k].clone())
                .collect();
            let [a, b] = [0, 1].map(|side| {
                let (s, _) = piece.ends[side];
                match break_local[e][p][side] {
                    None => constant(s),
                    Some(k) => project(ks, &xs, &x[k], s),
                }
            });
            let half = (b.clone() - &a) * 0.5;
            let master_coords = &master.coords[piece.master_facet];
            for &(eta, wq) in &gauss {
                let s = a.clone() + half.clone() * (eta + 1.0);
                let (xg, t) = facet_point(ks, &xs, &s);
                let jac = dot2(&t, &t).sqrt() * &half * thickness;
                let start = closest_point(km, master_coords, [xg[0].re, xg[1].re]);
                let xi = project(km, &xm, &xg, start);
                let (xmg, _) = facet_point(km, &xm, &xi);
                let phi = multiplier(ks, space, &s);
                let w = jac * &phi[j] * wq;
                area += w.clone();
                let gap = sub(&xg, &xmg);
                for i in 0..2 {
                    weighted[i] += w.clone() * &gap[i];
                }
            }
        }
    }
    let length = dot2(&normal, &normal).sqrt();
    // nu_j = -n_j / |n_j|: g_j = -(n_j . S_j) / (|n_j| A_j)
    let g = -dot2(&normal, &weighted) / (length * area);
    let dofs = nodes
        .iter()
        .flat_map(|n| [dof(n.0, n.1, 0), dof(n.0, n.1, 1)])
        .collect();
    linearized(g, dofs)
}

/// The exact gradient and second derivative of the mortar row of slave node `node` against a
/// rigid surface (`mortar::rigid_mortar_rows`): `g_j = int Phi_j g(x) dGamma / int Phi_j dGamma`
/// over the slave facets that hold `node`, with `g` the rigid surface's signed distance
/// (`mortar::rigid_gap`: `n . (x - p)` for a line, `|x - c| - R` for a circle) at the Gauss
/// points `gauss` of each facet, every quantity in the current positions (the length element
/// `|x'|` varies with them). `dof(node, i)` numbers component `i` of a slave node.
pub(crate) fn linearize_rigid_row(
    slave: &Surface,
    rigid: &crate::io::scene::RigidSurface,
    space: MultiplierSpace,
    thickness: f64,
    node: usize,
    gauss: &[(f64, f64)],
    dof: impl Fn(usize, usize) -> usize,
) -> LinearizedGap {
    use crate::io::scene::RigidSurface;
    let ks = slave.kind;
    let facets: Vec<usize> = (0..slave.facets.len())
        .filter(|&f| slave.facets[f].contains(&node))
        .collect();
    let mut nodes: Vec<(usize, [f64; 2])> = Vec::new();
    let mut local: Vec<Vec<usize>> = Vec::new();
    for &f in &facets {
        local.push(
            (0..ks.node_count())
                .map(|a| {
                    let id = slave.facets[f][a];
                    match nodes.iter().position(|n| n.0 == id) {
                        Some(k) => k,
                        None => {
                            nodes.push((id, slave.coords[f][a]));
                            nodes.len() - 1
                        }
                    }
                })
                .collect(),
        );
    }
    let x = seeded(&nodes.iter().map(|n| n.1).collect::<Vec<_>>());
    let distance = |p: &Point| -> Ad {
        match *rigid {
            RigidSurface::Line { point, normal } => {
                let l = normal[0].hypot(normal[1]);
                (p[0].clone() - point[0]) * (normal[0] / l)
                    + (p[1].clone() - point[1]) * (normal[1] / l)
            }
            RigidSurface::Circle { centre, radius } => {
                let d = [p[0].clone() - centre[0], p[1].clone() - centre[1]];
                dot2(&d, &d).sqrt() - radius
            }
            // the model refuses a 3D surface against 2D bodies; no distance is defined
            RigidSurface::Plane { .. } | RigidSurface::Sphere { .. } => constant(f64::NAN),
        }
    };
    let (mut area, mut weighted) = (constant(0.0), constant(0.0));
    for (e, &f) in facets.iter().enumerate() {
        let j = slave.facets[f]
            .iter()
            .position(|&n| n == node)
            .expect("the facet holds the node");
        let xs: Vec<Point> = local[e].iter().map(|&k| x[k].clone()).collect();
        for &(s, wq) in gauss {
            let s = constant(s);
            let (xg, t) = facet_point(ks, &xs, &s);
            let w = dot2(&t, &t).sqrt() * thickness * &multiplier(ks, space, &s)[j] * wq;
            area += w.clone();
            weighted += w * &distance(&xg);
        }
    }
    let g = weighted / area;
    let dofs = nodes
        .iter()
        .flat_map(|n| [dof(n.0, 0), dof(n.0, 1)])
        .collect();
    linearized(g, dofs)
}

#[cfg(test)]
mod tests {
    use super::super::mortar_segments::mortar_integrals;
    use super::*;

    /// A slave surface (the bottom of an upper body: facets left to right, outward normal
    /// down) and a master surface (the top of a lower body: facets right to left, normal up).
    struct Pair {
        kind: EdgeKind,
        slave: Vec<[f64; 2]>,
        master: Vec<[f64; 2]>,
    }

    impl Pair {
        /// Facet node lists: vertices `0..n` then, for Line3, one mid node per facet.
        fn facets(&self, points: usize, reverse: bool) -> Vec<Vec<usize>> {
            let vertices = match self.kind {
                EdgeKind::Line2 => points,
                EdgeKind::Line3 => points.div_ceil(2),
            };
            (0..vertices - 1)
                .map(|f| {
                    let mut nodes = if reverse {
                        vec![f + 1, f]
                    } else {
                        vec![f, f + 1]
                    };
                    if self.kind == EdgeKind::Line3 {
                        nodes.push(vertices + f);
                    }
                    nodes
                })
                .collect()
        }

        fn surfaces(&self) -> (Surface, Surface) {
            let make = |body: usize, points: &[[f64; 2]], reverse: bool| {
                let facets = self.facets(points.len(), reverse);
                let coords = facets
                    .iter()
                    .map(|f| f.iter().map(|&n| points[n]).collect())
                    .collect();
                Surface::from_facets(body, self.kind, facets, coords, 1.0)
            };
            (make(0, &self.slave, false), make(1, &self.master, true))
        }

        /// Global dof of a slave or master node: the slave's first.
        fn dof(&self, master: bool, node: usize, i: usize) -> usize {
            2 * (node + if master { self.slave.len() } else { 0 }) + i
        }

        fn dofs(&self) -> usize {
            2 * (self.slave.len() + self.master.len())
        }

        fn perturbed(&self, k: usize, h: f64) -> Pair {
            let (mut slave, mut master) = (self.slave.clone(), self.master.clone());
            let n = k / 2;
            if n < slave.len() {
                slave[n][k % 2] += h;
            } else {
                master[n - slave.len()][k % 2] += h;
            }
            Pair {
                kind: self.kind,
                slave,
                master,
            }
        }

        /// The gap of slave node `node` by the `f64` segmentation and integration of the
        /// `mortar` module, found afresh.
        fn gap(&self, space: MultiplierSpace, node: usize) -> f64 {
            let (slave, master) = self.surfaces();
            let (d, m, _) = mortar_integrals(&slave, &master, space, master.facet_size(), 1.0);
            let area: f64 = d[&node].values().sum();
            let n = slave.nodes[&node].normal;
            let mut s = [0.0; 2];
            for (&k, &v) in &d[&node] {
                for i in 0..2 {
                    s[i] += v * self.slave[k][i];
                }
            }
            for (&l, &v) in &m[&node] {
                for i in 0..2 {
                    s[i] -= v * self.master[l][i];
                }
            }
            -(n[0] * s[0] + n[1] * s[1]) / area
        }

        /// The linearized gap of `node`, gradient and Hessian spread over every dof.
        fn linearized(&self, space: MultiplierSpace, node: usize) -> (f64, Vec<f64>, Vec<f64>) {
            let (slave, master) = self.surfaces();
            let (_, _, pieces) = mortar_integrals(&slave, &master, space, master.facet_size(), 1.0);
            let lin = linearize_row(&slave, &master, &pieces, space, 1.0, node, |m, n, i| {
                self.dof(m, n, i)
            });
            let n = self.dofs();
            let (mut b, mut h) = (vec![0.0; n], vec![0.0; n * n]);
            let m = lin.dofs.len();
            for a in 0..m {
                b[lin.dofs[a]] = lin.gradient[a];
                for c in 0..m {
                    h[lin.dofs[a] * n + lin.dofs[c]] = lin.hessian[a * m + c];
                }
            }
            (lin.gap, b, h)
        }
    }

    /// A deformed, slid, non-matching pair: slave vertices `slave_x` at about `y = 0.98`
    /// (penetrating), master vertices at `0, 0.5, .., 2` about `y = 1`, each moved by a wave;
    /// Line3 mid nodes off their chords (curved facets).
    fn pair(kind: EdgeKind, slave_x: &[f64]) -> Pair {
        let wave = |k: usize, x: f64| {
            let k = k as f64;
            [
                0.01 * (1.7 * k).sin(),
                0.015 * (2.3 * k).cos() + 0.02 * x * x,
            ]
        };
        let master_x = [0.0, 0.5, 1.0, 1.5, 2.0];
        let mut master: Vec<[f64; 2]> = master_x
            .iter()
            .enumerate()
            .map(|(k, &x)| {
                let w = wave(k, x);
                [x + w[0], 1.0 + w[1]]
            })
            .collect();
        let mut slave: Vec<[f64; 2]> = slave_x
            .iter()
            .map(|&x| [x, 0.98 + 0.03 * (x - 1.0) * (x - 1.0)])
            .collect();
        if kind == EdgeKind::Line3 {
            let mids = |v: &[[f64; 2]], bulge: f64| -> Vec<[f64; 2]> {
                v.windows(2)
                    .enumerate()
                    .map(|(f, w)| {
                        let s = if f % 2 == 0 { bulge } else { -bulge };
                        [
                            0.5 * (w[0][0] + w[1][0]) + 0.01,
                            0.5 * (w[0][1] + w[1][1]) + s,
                        ]
                    })
                    .collect()
            };
            let (ms, mm) = (mids(&slave, 0.02), mids(&master, 0.03));
            slave.extend(ms);
            master.extend(mm);
        }
        Pair {
            kind,
            slave,
            master,
        }
    }

    /// `b_j` against central differences of the gap found afresh, `H_j` against central
    /// differences of `b_j`, relative to their largest entries; for every slave node whose
    /// facets are fully covered.
    fn check(pair: &Pair, space: MultiplierSpace, node: usize) -> (f64, f64) {
        let (g, b, hess) = pair.linearized(space, node);
        let reference = pair.gap(space, node);
        assert!(
            (g - reference).abs() < 1e-13,
            "{:?} {space:?} node {node}: gap {g} against {reference}",
            pair.kind
        );
        let n = pair.dofs();
        let h = 1e-6;
        let b_scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let h_scale = hess.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let (mut gradient_error, mut hessian_error) = (0.0f64, 0.0f64);
        for k in 0..n {
            let (p, q) = (pair.perturbed(k, h), pair.perturbed(k, -h));
            let fd = (p.gap(space, node) - q.gap(space, node)) / (2.0 * h);
            gradient_error = gradient_error.max((fd - b[k]).abs() / b_scale);
            let (bp, bq) = (p.linearized(space, node).1, q.linearized(space, node).1);
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

    fn check_all(kind: EdgeKind, slave_x: &[f64]) {
        let pair = pair(kind, slave_x);
        for space in [MultiplierSpace::Standard, MultiplierSpace::Dual] {
            // the inner slave vertices (their facets lie over the master), and on Line3 the
            // mid nodes
            let mids = if kind == EdgeKind::Line3 {
                slave_x.len()..2 * slave_x.len() - 1
            } else {
                0..0
            };
            for node in (1..slave_x.len() - 1).chain(mids) {
                let (gb, gh) = check(&pair, space, node);
                println!(
                    "{kind:?} {space:?} node {node}: gradient {gb:.1e}, second derivative {gh:.1e}"
                );
                assert!(
                    gb < 1e-8 && gh < 1e-7,
                    "{kind:?} {space:?} {node}: {gb:e} {gh:e}"
                );
            }
        }
    }

    #[test]
    fn the_mortar_gap_s_derivatives_are_its_differences_on_straight_facets() {
        check_all(EdgeKind::Line2, &[0.27, 0.66, 1.13, 1.52]);
    }

    #[test]
    fn the_mortar_gap_s_derivatives_are_its_differences_on_curved_facets() {
        check_all(EdgeKind::Line3, &[0.27, 0.66, 1.13, 1.52]);
    }

    /// A slave vertex 1e-4 on either side of the master vertex near `x = 1` (a segment end
    /// crossing a master node): the derivatives hold on both sides, and the gap and its gradient
    /// change across the crossing only by the order of the distance moved.
    #[test]
    fn the_derivatives_hold_where_a_segment_end_crosses_a_master_node() {
        for kind in [EdgeKind::Line2, EdgeKind::Line3] {
            // the master vertex 2 sits at x = 1 + 0.01 sin(3.4)
            let crossing = 1.0 + 0.01 * (3.4f64).sin();
            let mut sides = Vec::new();
            for offset in [-1e-4, 1e-4] {
                let slave_x = [0.27, 0.66, crossing + offset, 1.52];
                check_all(kind, &slave_x);
                let pair = pair(kind, &slave_x);
                sides.push(pair.linearized(MultiplierSpace::Standard, 2));
            }
            let jump = (sides[0].0 - sides[1].0).abs();
            let gradient_jump = sides[0]
                .1
                .iter()
                .zip(&sides[1].1)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            println!("{kind:?}: across the crossing the gap moves {jump:.1e}, its gradient {gradient_jump:.1e}");
            assert!(
                jump < 1e-3 && gradient_jump < 1e-2,
                "{jump:e} {gradient_jump:e}"
            );
        }
    }
    /// The rigid-surface mortar gap of `node` in `f64` (`mortar::multiplier`,
    /// `mortar::rigid_gap`, `geometry::facet_point`: another code path).
    fn rigid_reference(
        slave: &Surface,
        rigid: &crate::io::scene::RigidSurface,
        space: MultiplierSpace,
        node: usize,
        gauss: &[(f64, f64)],
    ) -> f64 {
        use super::super::geometry::facet_point as point_f64;
        use super::super::mortar::rigid_gap;
        use super::super::mortar_segments::multiplier as phi_f64;
        let (mut weighted, mut area) = (0.0, 0.0);
        for (f, nodes) in slave.facets.iter().enumerate() {
            let Some(j) = nodes.iter().position(|&n| n == node) else {
                continue;
            };
            for &(s, wq) in gauss {
                let (x, t) = point_f64(slave.kind, &slave.coords[f], s);
                let w = t[0].hypot(t[1]) * phi_f64(slave.kind, space, s)[j] * wq;
                weighted += w * rigid_gap(rigid, x).unwrap().0;
                area += w;
            }
        }
        weighted / area
    }

    /// The mortar gap against a rigid line and a rigid circle (`linearize_rigid_row`): its
    /// value against the `f64` integration, its gradient against central differences of that
    /// gap, its second derivative against central differences of the gradient, on straight and
    /// curved (Line3) slave facets at a deformed state, standard and dual multipliers.
    #[test]
    fn the_rigid_mortar_gap_s_derivatives_are_its_differences() {
        use crate::io::scene::RigidSurface;
        let gauss = crate::fe::gauss_legendre(8);
        for rigid in [
            RigidSurface::Line {
                point: [0.0, 0.9],
                normal: [0.1, 1.0],
            },
            RigidSurface::Circle {
                centre: [1.0, -2.0],
                radius: 2.9,
            },
        ] {
            for kind in [EdgeKind::Line2, EdgeKind::Line3] {
                for space in [MultiplierSpace::Standard, MultiplierSpace::Dual] {
                    let base = pair(kind, &[0.1, 0.6, 1.1, 1.6]);
                    let surface = |p: &Pair| p.surfaces().0;
                    let n = 2 * base.slave.len();
                    for node in 0..base.slave.len() {
                        let lin = linearize_rigid_row(
                            &surface(&base),
                            &rigid,
                            space,
                            1.0,
                            node,
                            &gauss,
                            |k, i| 2 * k + i,
                        );
                        let reference =
                            rigid_reference(&surface(&base), &rigid, space, node, &gauss);
                        assert!(
                            (lin.gap - reference).abs() < 1e-13,
                            "{kind:?} {space:?} {node}"
                        );
                        let m = lin.dofs.len();
                        let (mut b, mut hess) = (vec![0.0; n], vec![0.0; n * n]);
                        for a in 0..m {
                            b[lin.dofs[a]] = lin.gradient[a];
                            for c in 0..m {
                                hess[lin.dofs[a] * n + lin.dofs[c]] = lin.hessian[a * m + c];
                            }
                        }
                        let h = 1e-6;
                        let scale_b = b.iter().fold(0.0f64, |x, v| x.max(v.abs()));
                        // against a line with a single straight facet the length element cancels
                        // and H vanishes: measured against the gradient's scale then (the facets
                        // are about 0.5 long)
                        let scale_h = hess.iter().fold(0.0f64, |x, v| x.max(v.abs())).max(scale_b);
                        let (mut worst_b, mut worst_h) = (0.0f64, 0.0f64);
                        for k in 0..n {
                            let (p, q) = (base.perturbed(k, h), base.perturbed(k, -h));
                            let fd = (rigid_reference(&surface(&p), &rigid, space, node, &gauss)
                                - rigid_reference(&surface(&q), &rigid, space, node, &gauss))
                                / (2.0 * h);
                            worst_b = worst_b.max((fd - b[k]).abs() / scale_b);
                            let gradient = |p: &Pair| {
                                let lin = linearize_rigid_row(
                                    &surface(p),
                                    &rigid,
                                    space,
                                    1.0,
                                    node,
                                    &gauss,
                                    |k, i| 2 * k + i,
                                );
                                let mut b = vec![0.0; n];
                                for (a, &d) in lin.dofs.iter().enumerate() {
                                    b[d] = lin.gradient[a];
                                }
                                b
                            };
                            let (bp, bq) = (gradient(&p), gradient(&q));
                            for a in 0..n {
                                let fd = (bp[a] - bq[a]) / (2.0 * h);
                                worst_h = worst_h.max((fd - hess[a * n + k]).abs() / scale_h);
                            }
                        }
                        assert!(
                            worst_b < 1e-8 && worst_h < 1e-7,
                            "{kind:?} {space:?} node {node}: gradient {worst_b:e}, second derivative {worst_h:e}"
                        );
                    }
                }
            }
        }
    }
}
