//! Node-to-node contact between 3D bodies in the current configuration (finite kinematics),
//! consistently linearized with the variation of the master's nodal normal; and the 3D
//! hyper-dual kernels it shares with the finite-strain 3D mortar
//! ([`super::mortar3_linearization`]).
//!
//! **The nodal normal** (the one [`super::geometry::Surface3`] gives): at master node `m`,
//! `n_m = v_m / |v_m|`, `v_m = sum_f int M_m (x_xi x x_eta) dxi` over the master facets `f` that
//! hold `m`, by the facets' surface rule ([`FacetShape::surface_rule`], `M_m` the nodal-weight
//! basis, [`FacetShape::weight_basis`]). It depends on `m` and on every other node of those
//! facets (a Quad4 surface: the 9 nodes of the 2 x 2 patch around an interior node).
//!
//! **The gap** of slave node `s` against the master node `m` it faces (Taylor 2004, "FEM
//! Node-to-Node Contact"; Wriggers, *Computational Contact Mechanics*, 2nd ed. 2006, section
//! 4.1), in the current positions `x`:
//!
//! ```text
//! g = n_m(x) . (x_s - x_m)
//! ```
//!
//! Its gradient `b = grad g` (the row's coefficients) is `n_m` on the slave node, `-n_m` plus
//! `(dn_m/dx_m)^T (x_s - x_m)` on the master node and `(dn_m/dx_b)^T (x_s - x_m)` on the
//! master neighbours `b`; the Newton tangent takes its Hessian `H = grad^2 g`
//! ([`crate::contact::GapHessian`]), which carries the normal's first and second variations.
//! Both are exact: the gap is evaluated in second-order vector dual numbers
//! (`num_dual::Dual2DVec64`, one seed per coordinate of every node of the row), which carry the
//! gradient and the Hessian through the arithmetic.
//!
//! **Pairing.** Finite kinematics pairs the nodes by proximity in the current configuration:
//! each slave node against the nearest master node. The nodes must stay matched: a slave node
//! that has slid along the master surface by more than half the distance from its master node
//! to the nearest other node of the master facets there faces another master node, and the
//! pair is refused with that reason (so is a master node left without a slave node, or claimed
//! twice). The reference configuration must match node for node (`run3d` checks it before
//! the solve, with the small-strain pairing [`super::node_based_rows::node_to_node_rows`]).
//!
//! Expected behaviour: the two-block contact patch test on matching meshes transmits a uniform
//! pressure exactly (each row's gap is the distance of coincident nodes, zero in the
//! homogeneous state), and a rigid rotation of the whole problem rotates the answer
//! (`tests/finite3d_mortar.rs`). The unit tests check `b` and `H` against central differences
//! of the gap computed afresh by [`super::geometry::Surface3`]'s nodal normal (another code
//! path) on a curved, distorted Quad4 and a Tri3 surface.

use super::geometry::{FacetShape, Surface3, MAX_FACET_NODES};
use super::node_based_rows::{dominant_component, node_row, RowSettings};
use super::search::BucketGrid;
use crate::contact::{Constraint, GapHessian};
use crate::fe::ElementKind;
use num_dual::{Derivative, Dual2DVec64, DualNum};

/// A second-order dual number over a row's coordinates.
pub(crate) type Ad = Dual2DVec64;

/// A point in 3D with coordinates of any dual type.
pub(crate) type Point3<T> = [T; 3];

/// A row's gap with its exact gradient and second derivative over `dofs`.
#[derive(Clone, Debug)]
pub(crate) struct LinearizedGap3 {
    pub gap: f64,
    pub dofs: Vec<usize>,
    pub gradient: Vec<f64>,
    /// Row-major, `dofs.len()` squared, symmetric.
    pub hessian: Vec<f64>,
}

/// The positions `points` as second-order dual numbers, one seed per coordinate (`3 k + i` for
/// coordinate `i` of point `k`).
pub(crate) fn seeded3(points: &[[f64; 3]]) -> Vec<Point3<Ad>> {
    let variables = 3 * points.len();
    points
        .iter()
        .enumerate()
        .map(|(k, p)| std::array::from_fn(|i| Ad::from_re(p[i]).derivative(variables, 3 * k + i)))
        .collect()
}

/// The value, gradient and Hessian (made exactly symmetric) of `g` over `variables` seeds.
pub(crate) fn parts(g: &Ad, variables: usize) -> (f64, Vec<f64>, Vec<f64>) {
    let gradient: Vec<f64> = match &g.v1.0 {
        Some(v) => v.iter().copied().collect(),
        None => vec![0.0; variables],
    };
    let mut hessian = vec![0.0; variables * variables];
    if let Some(h) = &g.v2.0 {
        for a in 0..variables {
            for c in 0..variables {
                hessian[a * variables + c] = 0.5 * (h[(a, c)] + h[(c, a)]);
            }
        }
    }
    (g.re, gradient, hessian)
}

/// The gap `g` evaluated in dual numbers over `dofs` (one per seed): its value, gradient and
/// symmetric second derivative.
pub(crate) fn linearized3(g: &Ad, dofs: Vec<usize>) -> LinearizedGap3 {
    let (gap, gradient, hessian) = parts(g, dofs.len());
    LinearizedGap3 {
        gap,
        dofs,
        gradient,
        hessian,
    }
}

/// A dual number over `variables` seeds from its value, gradient and Hessian given over the
/// seeds `map` (local seed `a` is global seed `map[a]`): the embedding of a quantity computed
/// over a subset of a row's coordinates into the row's.
pub(crate) fn embedded(
    value: f64,
    gradient: &[f64],
    hessian: &[f64],
    map: &[usize],
    variables: usize,
) -> Ad {
    let local = map.len();
    let mut v1 = nalgebra::RowDVector::<f64>::zeros(variables);
    let mut v2 = nalgebra::DMatrix::<f64>::zeros(variables, variables);
    for a in 0..local {
        v1[(0, map[a])] += gradient[a];
        for c in 0..local {
            v2[(map[a], map[c])] += hessian[a * local + c];
        }
    }
    Ad::new(value, Derivative::some(v1), Derivative::some(v2))
}

pub(crate) fn sub3<T: DualNum<Primitive = f64>>(a: &Point3<T>, b: &Point3<T>) -> Point3<T> {
    std::array::from_fn(|i| a[i].clone() - &b[i])
}

pub(crate) fn scaled3<T: DualNum<Primitive = f64>>(a: &Point3<T>, s: &T) -> Point3<T> {
    std::array::from_fn(|i| a[i].clone() * s)
}

pub(crate) fn dot3<T: DualNum<Primitive = f64>>(a: &Point3<T>, b: &Point3<T>) -> T {
    a[0].clone() * &b[0] + a[1].clone() * &b[1] + a[2].clone() * &b[2]
}

pub(crate) fn cross3<T: DualNum<Primitive = f64>>(a: &Point3<T>, b: &Point3<T>) -> Point3<T> {
    [
        a[1].clone() * &b[2] - a[2].clone() * &b[1],
        a[2].clone() * &b[0] - a[0].clone() * &b[2],
        a[0].clone() * &b[1] - a[1].clone() * &b[0],
    ]
}

/// The real parts of a point.
pub(crate) fn real3<T: DualNum<Primitive = f64>>(a: &Point3<T>) -> [f64; 3] {
    std::array::from_fn(|i| a[i].re())
}

/// The tangents `[x_xi, x_eta]` of a facet with nodes `coords` at the (fixed) natural point
/// `s`.
pub(crate) fn facet_tangents<T: DualNum<Primitive = f64>>(
    kind: ElementKind,
    coords: &[Point3<T>],
    s: [f64; 2],
) -> [Point3<T>; 2] {
    let mut n = [0.0; MAX_FACET_NODES];
    let mut dn = [[0.0; 2]; MAX_FACET_NODES];
    let k = kind.node_count();
    ElementKind::shape(kind, s, &mut n[..k], &mut dn[..k]);
    let zero = || T::from(0.0);
    let mut t: [Point3<T>; 2] = [[zero(), zero(), zero()], [zero(), zero(), zero()]];
    for (a, p) in coords.iter().enumerate() {
        for (j, tj) in t.iter_mut().enumerate() {
            for i in 0..3 {
                tj[i] += p[i].clone() * dn[a][j];
            }
        }
    }
    t
}

/// The unnormalized nodal normal `v = sum_f int M_a (x_xi x x_eta) dxi` of the node that is
/// local node `a_f` of each facet `facets[f]` (its nodes' positions), by the surface rule of
/// `kind` (module notes).
pub(crate) fn nodal_normal_sum<T: DualNum<Primitive = f64>>(
    kind: ElementKind,
    facets: &[(Vec<Point3<T>>, usize)],
) -> Point3<T> {
    let k = kind.node_count();
    let rule = FacetShape::<3>::surface_rule(kind);
    let mut v = [T::from(0.0), T::from(0.0), T::from(0.0)];
    for (coords, a) in facets {
        for &(s, w) in &rule {
            let mut m = [0.0; MAX_FACET_NODES];
            FacetShape::<3>::weight_basis(kind, s, &mut m[..k]);
            if m[*a] == 0.0 {
                continue;
            }
            let [t1, t2] = facet_tangents(kind, coords, s);
            let scaled = cross3(&t1, &t2);
            for i in 0..3 {
                v[i] += scaled[i].clone() * (w * m[*a]);
            }
        }
    }
    v
}

/// The unit nodal normal (module notes) of the node that is local node `a_f` of each facet.
pub(crate) fn unit_nodal_normal<T: DualNum<Primitive = f64>>(
    kind: ElementKind,
    facets: &[(Vec<Point3<T>>, usize)],
) -> Point3<T> {
    let v = nodal_normal_sum(kind, facets);
    let length = dot3(&v, &v).sqrt();
    std::array::from_fn(|i| v[i].clone() / &length)
}

/// The nodes of a row whose gap takes the nodal normal of node `node` of `surface`: that node,
/// then the other nodes of its facets (each once); and those facets as (indices into the list,
/// the node's place in the facet).
pub(crate) fn normal_patch(
    surface: &Surface3,
    node: usize,
) -> (Vec<usize>, Vec<(Vec<usize>, usize)>) {
    let mut nodes = vec![node];
    let mut facets = Vec::new();
    for facet in surface.facets.iter().filter(|f| f.contains(&node)) {
        let mut local = Vec::with_capacity(facet.len());
        for &n in facet {
            let k = match nodes.iter().position(|&m| m == n) {
                Some(k) => k,
                None => {
                    nodes.push(n);
                    nodes.len() - 1
                }
            };
            local.push(k);
        }
        let a = facet
            .iter()
            .position(|&n| n == node)
            .expect("the facet holds the node");
        facets.push((local, a));
    }
    (nodes, facets)
}

/// The position of node `node` of `surface` (from the first facet that names it).
fn position_of(surface: &Surface3, node: usize) -> [f64; 3] {
    surface.nodes[&node].position
}

/// The linearized node-to-node gap (module notes) of the slave node at `x_s` (global dofs
/// `slave_dofs`) against master node `m` of `master`, whose nodes' global dofs are
/// `master_dof(node, i)`.
pub(crate) fn node_to_node_gap(
    x_s: [f64; 3],
    slave_dofs: [usize; 3],
    master: &Surface3,
    m: usize,
    master_dof: impl Fn(usize, usize) -> usize,
) -> LinearizedGap3 {
    let (nodes, facets) = normal_patch(master, m);
    let mut positions = vec![x_s];
    positions.extend(nodes.iter().map(|&n| position_of(master, n)));
    let x = seeded3(&positions);
    // the master patch's points are x[1..]
    let facet_points: Vec<(Vec<Point3<Ad>>, usize)> = facets
        .iter()
        .map(|(local, a)| (local.iter().map(|&k| x[k + 1].clone()).collect(), *a))
        .collect();
    let n = unit_nodal_normal(master.kind, &facet_points);
    let g = dot3(&n, &sub3(&x[0], &x[1]));
    let mut dofs: Vec<usize> = slave_dofs.to_vec();
    for &node in &nodes {
        dofs.extend((0..3).map(|i| master_dof(node, i)));
    }
    linearized3(&g, dofs)
}

/// Node-to-node rows of `slave` against `master` in the current configuration (finite
/// kinematics, module notes): every slave node against the nearest master node, the gap
/// along the master's nodal normal with its exact gradient (the row's coefficients) and
/// Hessian (`Constraint::hessian`); or why the nodes no longer match.
pub fn node_to_node_current_rows(
    slave: &Surface3,
    master: &Surface3,
    settings: &RowSettings,
) -> Result<Vec<Constraint<3>>, String> {
    let master_nodes: Vec<usize> = master.nodes.keys().copied().collect();
    let grid = BucketGrid::new(
        master
            .nodes
            .values()
            .map(|data| [data.position, data.position])
            .collect(),
    );
    let radius = master.facet_size();
    let mut used: Vec<Option<usize>> = vec![None; master_nodes.len()];
    let mut rows = Vec::new();
    let dofs = settings.dofs;
    for (&s, data) in &slave.nodes {
        let p = data.position;
        let distance2 = |k: usize| {
            let x = master.nodes[&master_nodes[k]].position;
            (0..3).map(|i| (p[i] - x[i]).powi(2)).sum::<f64>()
        };
        let Some(k) = grid
            .query(p, radius)
            .into_iter()
            .min_by(|&a, &b| distance2(a).total_cmp(&distance2(b)))
        else {
            return Err(format!(
                "the interface nodes no longer match: the slave node at {p:?} (current configuration) has no master node within a facet ({radius:e}); node-to-node needs nodes that stay matched, use node_to_surface or mortar where they slide"
            ));
        };
        let m = master_nodes[k];
        let md = master.nodes[&m];
        let d: [f64; 3] = std::array::from_fn(|i| p[i] - md.position[i]);
        let normal_part: f64 = (0..3).map(|i| d[i] * md.normal[i]).sum();
        let along = (0..3)
            .map(|i| (d[i] - normal_part * md.normal[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        // half the distance from m to the nearest other node of its facets
        let half = 0.5
            * master
                .facets
                .iter()
                .zip(&master.coords)
                .filter(|(f, _)| f.contains(&m))
                .flat_map(|(f, c)| {
                    f.iter()
                        .zip(c)
                        .filter(|(&n, _)| n != m)
                        .map(|(_, x)| {
                            (0..3)
                                .map(|i| (x[i] - md.position[i]).powi(2))
                                .sum::<f64>()
                                .sqrt()
                        })
                        .collect::<Vec<_>>()
                })
                .fold(f64::INFINITY, f64::min);
        if along > half {
            return Err(format!(
                "the interface nodes no longer match: the slave node at {p:?} (current configuration) has slid {along:.3e} along the master surface from its master node at {:?}, more than half the way to the next master node ({half:.3e}); node-to-node needs nodes that stay matched, use node_to_surface or mortar where they slide",
                md.position
            ));
        }
        if let Some(other) = used[k].replace(s) {
            return Err(format!(
                "the interface nodes no longer match: the slave nodes at {:?} and {p:?} (current configuration) both face the master node at {:?}; node-to-node needs nodes that stay matched, use node_to_surface or mortar where they slide",
                slave.nodes[&other].position, md.position
            ));
        }
        let slave_dofs: [usize; 3] = std::array::from_fn(|i| dofs.dof(slave.body, s, i));
        let lin = node_to_node_gap(p, slave_dofs, master, m, |n, i| dofs.dof(master.body, n, i));
        // the row's area, slave normal, point and pass as the small-strain row's
        let mut row = node_row(
            settings,
            slave,
            s,
            md.normal,
            lin.gap,
            Some((master.body, &[(m, 1.0)])),
            1,
        );
        let nu: [f64; 3] = std::array::from_fn(|i| lin.gradient[i]);
        row.normal = nu;
        row.owner = slave_dofs[dominant_component(nu)];
        row.g0 = lin.gap;
        row.dofs.clear();
        row.coeffs.clear();
        for (&dof, &c) in lin.dofs.iter().zip(&lin.gradient) {
            if c != 0.0 {
                row.dofs.push(dof);
                row.coeffs.push(c);
            }
        }
        row.hessian = Some(GapHessian {
            dofs: lin.dofs,
            values: lin.hessian,
        });
        rows.push(row);
    }
    if let Some(k) = used.iter().position(|u| u.is_none()) {
        return Err(format!(
            "the interface nodes no longer match: the master node at {:?} (current configuration) has no slave node; node-to-node needs nodes that stay matched",
            master.nodes[&master_nodes[k]].position
        ));
    }
    if rows.is_empty() {
        return Err("the slave surface has no nodes".into());
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A curved, distorted surface of `kind` facets (Quad4: 3 x 3 nodes on a saddle with moved
    /// nodes; Tri3: the same nodes, each quadrilateral split in two), outward normal about +z.
    fn curved_surface(kind: ElementKind, body: usize) -> Surface3 {
        let mut positions = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                let (x, y) = (
                    i as f64 * 0.5 + 0.03 * (j as f64),
                    j as f64 * 0.5 - 0.02 * (i as f64),
                );
                positions.push([x, y, 0.2 * (x - 0.5) * (y - 0.4) + 0.05 * x * x]);
            }
        }
        let at = |i: usize, j: usize| j * 3 + i;
        let mut facets = Vec::new();
        for j in 0..2 {
            for i in 0..2 {
                let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                match kind {
                    ElementKind::T3 => {
                        facets.push(vec![q[0], q[1], q[2]]);
                        facets.push(vec![q[0], q[2], q[3]]);
                    }
                    _ => facets.push(q.to_vec()),
                }
            }
        }
        let coords = facets
            .iter()
            .map(|f| f.iter().map(|&n| positions[n]).collect())
            .collect();
        Surface3::from_facets(body, kind, facets, coords, 1.0)
    }

    /// The surface with node `node`'s coordinate `i` moved by `h`.
    fn moved(s: &Surface3, node: usize, i: usize, h: f64) -> Surface3 {
        let coords = s
            .facets
            .iter()
            .zip(&s.coords)
            .map(|(f, c)| {
                f.iter()
                    .zip(c)
                    .map(|(&n, &x)| {
                        let mut x = x;
                        if n == node {
                            x[i] += h;
                        }
                        x
                    })
                    .collect()
            })
            .collect();
        Surface3::from_facets(s.body, s.kind, s.facets.clone(), coords, 1.0)
    }

    /// `grad g` against central differences of the gap computed afresh with `Surface3`'s
    /// nodal normal, and `H` against central differences of `grad g`, at a slave point off the
    /// master node (so the normal's variation enters), for the interior node of a curved Quad4
    /// and Tri3 surface and a node on its boundary.
    #[test]
    fn the_gap_gradient_and_hessian_are_the_differences_of_the_gap() {
        for kind in [ElementKind::Q4, ElementKind::T3] {
            let master = curved_surface(kind, 1);
            for m in [4, 1] {
                let xm = master.nodes[&m].position;
                let x_s = [xm[0] + 0.03, xm[1] - 0.02, xm[2] + 0.07];
                let dof = |n: usize, i: usize| 3 * n + i + 100;
                let lin = node_to_node_gap(x_s, [0, 1, 2], &master, m, dof);
                let gap = |x_s: [f64; 3], surface: &Surface3| {
                    let d = surface.nodes[&m];
                    (0..3)
                        .map(|i| d.normal[i] * (x_s[i] - d.position[i]))
                        .sum::<f64>()
                };
                assert!((lin.gap - gap(x_s, &master)).abs() < 1e-15);
                let h = 1e-6;
                let (mut worst_b, mut worst_h) = (0.0f64, 0.0f64);
                let v = lin.dofs.len();
                for (a, &d) in lin.dofs.iter().enumerate() {
                    let (plus, minus, grad_plus, grad_minus) = if d < 3 {
                        let (mut p, mut q) = (x_s, x_s);
                        p[d] += h;
                        q[d] -= h;
                        (
                            gap(p, &master),
                            gap(q, &master),
                            node_to_node_gap(p, [0, 1, 2], &master, m, dof),
                            node_to_node_gap(q, [0, 1, 2], &master, m, dof),
                        )
                    } else {
                        let (node, i) = ((d - 100) / 3, (d - 100) % 3);
                        let (sp, sm) = (moved(&master, node, i, h), moved(&master, node, i, -h));
                        (
                            gap(x_s, &sp),
                            gap(x_s, &sm),
                            node_to_node_gap(x_s, [0, 1, 2], &sp, m, dof),
                            node_to_node_gap(x_s, [0, 1, 2], &sm, m, dof),
                        )
                    };
                    worst_b = worst_b.max(((plus - minus) / (2.0 * h) - lin.gradient[a]).abs());
                    for c in 0..v {
                        let fd = (grad_plus.gradient[c] - grad_minus.gradient[c]) / (2.0 * h);
                        worst_h = worst_h.max((fd - lin.hessian[a * v + c]).abs());
                    }
                }
                let scale_h = lin.hessian.iter().fold(0.0f64, |s, v| s.max(v.abs()));
                println!("{kind:?} node {m}: {v} dofs, gradient off by {worst_b:.1e}, Hessian off by {worst_h:.1e} of {scale_h:.2e}");
                assert!(worst_b < 1e-9, "{kind:?} {m}: {worst_b:e}");
                assert!(worst_h < 1e-7 * scale_h, "{kind:?} {m}: {worst_h:e}");
                // the normal's variation enters: the master neighbours carry coefficients
                assert!(lin.gradient[6..].iter().any(|c| c.abs() > 1e-3));
            }
        }
    }
}
