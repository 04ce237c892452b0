//! Contact forces, pressures and penetrations per pair and per body: the one place that turns
//! row forces into what reports and checks call force, pressure and penetration.
//!
//! **Nodal forces.** The rows of pair `k` act on the bodies with the nodal force vector
//!
//! ```text
//! f^k = B_k^T lambda_k,     f^k_d = sum_{rows i of k} c_id lambda_i
//! ```
//!
//! plus, for Coulomb pairs, the tangential forces `B_t^T lambda_t` of the slip rows
//! ([`crate::contact::TangentRow`]), so the force of a frictional pair is the whole traction it
//! transmits. The nodal force is unique even when `lambda` is not (the dependent rows of a two-pass pair, whose
//! minimum-norm multipliers split the load between the passes: `B^T lambda = K u - f` on the
//! contact dofs whatever the split). The force the pair puts on a body is the sum of `f^k` over
//! that body's dofs; a rigid master takes minus the force on the slave.
//!
//! **Pressures.** At a node `a` of a contact surface with outward unit normal `n_a` and
//! tributary area `A_a = t int N_a ds` (thickness `t`) wholly covered by the master, the
//! traction is `f_a / A_a`: the contact pressure is `p_a = -f_a . n_a / A_a` and the shear
//! traction `tau_a = f_a . t_a / A_a`, `t_a = (-n_y, n_x)`. It does not depend on which body is
//! the slave, nor on how a mortar row is normalized (a row's own `lambda / A` is a multiplier
//! coefficient, not a traction: at a slave node whose support barely overlaps the master it
//! reached 19,976 where the traction is 1, defect D13).
//!
//! **Recovery where a facet is partly covered.** Where the master ends over a slave facet, only
//! part of the node's tributary transmits force: a mortar row at node `a` integrates `N_a` over
//! the covered pieces alone, so a uniform pressure `p` gives `f_a . n_a = -p C_a` with the
//! covered tributary `C_a = sum_e c_a^e`, `c_a^e = t int_{covered part of e} N_a ds` (the rows'
//! [`crate::contact::Constraint::cover`]; node-based rows and rigid masters cover the whole
//! tributary of a node that has a row). `f_a / A_a` then reads `p C_a / A_a` (98.48 and 95.24
//! where the pressure is 100); `f_a / C_a` is exact for a uniform pressure but not bounded: a
//! node whose covered share is a sliver (`C_a -> 0`) carries a force that its tiny share does
//! not scale (173.9 where the traction is 1 after a slide, defect D13). So each component `F_a`
//! of the nodal force (normal, tangential) is recovered facet by facet:
//!
//! ```text
//! L_e = sum_{a in e} c_a^e                                 the facet's covered area
//! v_e = sum_{a in e, C_a > 0} F_a (c_a^e / C_a) / L_e        its mean (the force it transmits / L_e)
//! ```
//!
//! and at node `a`: without cover (`C_a = 0`, no row) `F_a / A_a`; where each facet at `a`
//! covers `a`'s share wholly or not at all, `F_a / C_a` (the force over the covered tributary;
//! `F_a / A_a` to the bit at every node of node-based rows and at every interior node); where a
//! facet covers it in part, the covered-area-weighted mean `sum_e L_e v_e / sum_e L_e` of the
//! means of its covered facets that are not slivers (a sliver: covered on less than
//! [`SLIVER_SHARE`], a tenth, of its area); if all are slivers, `F_a / A_a`. Every value is
//! exact for a uniform traction (`F_a = v C_a` gives `v_e = v`) except at a node whose only
//! covered facets are slivers. On a sliver the value stays bounded: a sliver's mean, whose
//! covered area may be any small number, is never used; the means used are convex
//! combinations of `F_b / C_b` over facets covered on at least a tenth. (D13: the node whose
//! support a sliver of 0.0033 covers reads 0.0148, its neighbour, whose force carries the
//! concentration at the master's corner, the mean 2.57 of its covered facet, where `F / C`
//! reads 173.9 and 3.8.) The pair's transmitted normal force is `sum_a -f_a . n_a` (not `sum_a
//! p_a A_a`), its closed area the sum of the covered `C_a`.
//!
//! **Penetration.** A frictionless row penetrates by `max(0, -g)`. A tie's rows measure the jump
//! `d = u_s - u_m` one component at a time; the normal overlap at the slave node is
//! `max(0, d . n_s)` with `n_s` the slave surface's outward normal (pointing into the other
//! body), the same whichever body is the slave. Penetration is also given relative to the
//! contact element size `h`: the longest slave facet at the node (its chord in 2D, the largest
//! distance between two of its nodes in 3D; [`pair_penetration`] in either dimension).
//!
//! **Configuration.** Normals, areas and the positions of moments are taken where the rows were
//! linearized: the reference configuration, or `X + u_k` with contact geometry in the current
//! configuration.

use super::discretization::geometry::{NodeData, Surface};
use super::discretization::Discretize;
use super::state::ContactState;
use crate::model::{MasterSide, Model};
use std::collections::BTreeMap;

/// The contact traction at one node of a contact surface (`D` components).
#[derive(Clone, Debug)]
pub struct NodalTraction<const D: usize = 2> {
    pub body: usize,
    pub node: usize,
    /// Position (in the configuration of the rows).
    pub point: [f64; D],
    /// Tributary area `t int N_a ds` (`int N_a dA` in 3D).
    pub area: f64,
    /// The part of it that the pair's rows at the node cover, `C_a` (module notes; 0 at a node
    /// without rows).
    pub covered_area: f64,
    /// Outward unit normal of the surface at the node.
    pub normal: [f64; D],
    /// Nodal contact force `f_a`.
    pub force: [f64; D],
    /// The recovered traction `-p_a n_a + tau_a` (module notes).
    pub traction: [f64; D],
    /// The recovered pressure `p_a` (compression positive; `-f_a . n_a / A_a` where the node's
    /// tributary is wholly covered).
    pub pressure: f64,
    /// The recovered shear traction: in 2D `tau_a` along `t_a = (-n_y, n_x)` (signed;
    /// `f_a . t_a / A_a` where the node's tributary is wholly covered), in 3D the magnitude of
    /// the tangential traction vector `tau_a` (module notes).
    pub shear: f64,
    /// Whether a row of the pair has this node as its slave node.
    pub carries_rows: bool,
}

/// The largest penetration of a pair and where it is (`D`: the dimension of the position).
#[derive(Clone, Debug, Default)]
pub struct Penetration<const D: usize = 2> {
    /// Largest overlap (0 when nothing penetrates).
    pub depth: f64,
    /// The same relative to the contact element size at the node (the longest slave facet).
    pub share_of_element: f64,
    /// Body, node and position of the slave node with the largest share.
    pub at: Option<(usize, usize, [f64; D])>,
}

/// What one pair transmits.
#[derive(Clone, Debug)]
pub struct PairForces<const D: usize = 2> {
    pub pair: usize,
    /// Net force on the pair's (first-pass) slave body, and on its master (body or rigid).
    pub on_slave: [f64; D],
    pub on_master: [f64; D],
    /// Net moment (about the origin, in the configuration of the rows) of the forces on both
    /// sides, `[M_x, M_y, M_z]` (in 2D only `M_z`), and the sum of `|f_a|` over all nodes (its
    /// scale).
    pub net_moment: [f64; 3],
    pub force_scale: f64,
    /// Tractions at the nodes of both surfaces (the master's only for a body master).
    pub nodes: Vec<NodalTraction<D>>,
    pub penetration: Penetration<D>,
}

impl<const D: usize> PairForces<D> {
    /// Largest contact pressure over the nodes that carry rows (both sides for two passes).
    pub fn max_pressure(&self) -> f64 {
        self.nodes
            .iter()
            .filter(|n| n.carries_rows)
            .fold(0.0, |m: f64, n| m.max(n.pressure))
    }
}

/// The length of `a` (`hypot` component by component: in 2D `|f|` as `f_x.hypot(f_y)`, and
/// `|M_z|` exactly for a 2D moment).
pub fn length(a: &[f64]) -> f64 {
    a.iter().fold(0.0, |l: f64, &c| l.hypot(c))
}

/// `a` in three components (`[a_x, a_y, 0]` in 2D).
fn in_3d<const D: usize>(a: [f64; D]) -> [f64; 3] {
    std::array::from_fn(|i| if i < D { a[i] } else { 0.0 })
}

/// The directions `d_k` whose nodal force components `f_a . d_k` are recovered as the shear
/// (module notes): in 2D the tangent `t = (-n_y, n_x)` (a signed shear); in 3D the axes
/// projected onto the tangent plane, `e_k - n_k n`, whose components make the tangential
/// traction vector.
fn shear_directions<const D: usize>(n: [f64; D]) -> Vec<[f64; D]> {
    if D == 2 {
        vec![std::array::from_fn(|i| if i == 0 { -n[1] } else { n[0] })]
    } else {
        (0..D)
            .map(|k| std::array::from_fn(|i| f64::from(u8::from(i == k)) - n[k] * n[i]))
            .collect()
    }
}

/// Longest facet at each node of `surface`: the largest distance between two nodes of a
/// facet that holds the node (in 2D the chord of the edge).
pub(crate) fn element_sizes<const D: usize, K>(surface: &Surface<D, K>) -> BTreeMap<usize, f64> {
    let mut h = BTreeMap::new();
    for (nodes, coords) in surface.facets.iter().zip(&surface.coords) {
        let mut len = 0.0f64;
        for (a, p) in coords.iter().enumerate() {
            for q in &coords[a + 1..] {
                let d2: f64 = (0..D).map(|i| (q[i] - p[i]).powi(2)).sum();
                len = len.max(d2.sqrt());
            }
        }
        for &n in nodes {
            let e = h.entry(n).or_insert(0.0f64);
            *e = e.max(len);
        }
    }
    h
}

/// Forces, pressures and penetrations of every pair of `model` in the contact solution `state`,
/// in either dimension.
pub fn pair_forces<const D: usize, K: Discretize<D>>(
    model: &Model<D, K>,
    state: &ContactState<D>,
) -> Vec<PairForces<D>> {
    let config = state.configuration.as_deref();
    (0..model.contact.len())
        .map(|k| one_pair(model, state, k, config))
        .collect()
}

fn one_pair<const D: usize, K: Discretize<D>>(
    model: &Model<D, K>,
    state: &ContactState<D>,
    k: usize,
    config: Option<&[f64]>,
) -> PairForces<D> {
    let pair = &model.contact[k];
    // The surfaces of both sides, in the configuration of the rows (the out-of-plane thickness
    // weighs the 2D tributaries).
    let mut sides = vec![(pair.slave.0, &pair.slave.1)];
    if let MasterSide::Body { body, facets } = &pair.master {
        sides.push((*body, facets));
    }
    let thickness = if D == 2 { model.thickness } else { 1.0 };
    let surfaces: Vec<Surface<D, K::Facet>> = sides
        .iter()
        .map(|&(b, facets)| Surface::of_body(b, &model.bodies[b], facets, thickness, config))
        .collect();
    let owner = |d: usize| {
        let r = model.dof_owner(d).expect("a body owns every dof");
        (r.body, r.node, r.component)
    };

    // f^k, per (body, node).
    let mut nodal: BTreeMap<(usize, usize), [f64; D]> = BTreeMap::new();
    let mut slave_nodes = std::collections::BTreeSet::new();
    for (i, (r, &lambda)) in state.rows.iter().zip(&state.forces).enumerate() {
        if r.pair != k {
            continue;
        }
        slave_nodes.insert((r.slave_body, r.slave_node));
        for (&d, &c) in r.dofs.iter().zip(&r.coeffs) {
            let (b, n, comp) = owner(d);
            nodal.entry((b, n)).or_insert([0.0; D])[comp] += c * lambda;
        }
        // a frictional row's tangential force acts along its slip gradient
        if let Some(Some(f)) = state.friction.get(i) {
            for (t, &lambda_t) in r.tangents.iter().zip(&f.force) {
                for (&d, &c) in t.dofs.iter().zip(&t.coeffs) {
                    let (b, n, comp) = owner(d);
                    nodal.entry((b, n)).or_insert([0.0; D])[comp] += c * lambda_t;
                }
            }
        }
    }
    let position = |b: usize, n: usize| -> [f64; D] {
        let body = &model.bodies[b];
        let p = body.mesh.nodes[n];
        match config {
            Some(u) => std::array::from_fn(|i| p[i] + u[body.dof(n, i)]),
            None => p,
        }
    };
    let (mut on_slave, mut on_master) = ([0.0; D], [0.0; D]);
    let (mut net_moment, mut force_scale) = ([0.0; 3], 0.0);
    for (&(b, n), f) in &nodal {
        let target = if b == pair.slave.0 {
            &mut on_slave
        } else {
            &mut on_master
        };
        for i in 0..D {
            target[i] += f[i];
        }
        let (p, f3) = (in_3d(position(b, n)), in_3d(*f));
        for i in 0..3 {
            let (j, l) = ((i + 1) % 3, (i + 2) % 3);
            net_moment[i] += p[j] * f3[l] - p[l] * f3[j];
        }
        force_scale += length(f);
    }
    if let MasterSide::Rigid(_) = pair.master {
        on_master = on_slave.map(|f| -f);
    }

    // the covered tributaries of the rows, per surface (pass 1: the slave surface, pass 2: the
    // master body's), node and facet
    let mut cover: Vec<Cover> = vec![BTreeMap::new(); surfaces.len()];
    for r in state.rows.iter().filter(|r| r.pair == k) {
        let Some(c) = usize::from(r.pass)
            .checked_sub(1)
            .and_then(|side| cover.get_mut(side))
        else {
            continue;
        };
        let facets = c.entry(r.slave_node).or_default();
        for &(f, w) in &r.cover {
            let e = facets.entry(f).or_insert(0.0f64);
            *e = e.max(w);
        }
    }
    let dot = |a: [f64; D], b: [f64; D]| (0..D).map(|i| a[i] * b[i]).sum::<f64>();
    let mut nodes = Vec::new();
    for (s, cover) in surfaces.iter().zip(&cover) {
        let force = |n: usize| nodal.get(&(s.body, n)).copied().unwrap_or([0.0; D]);
        let component = |along: &dyn Fn(&NodeData<D>) -> [f64; D]| -> BTreeMap<usize, f64> {
            s.nodes
                .iter()
                .map(|(&n, data)| (n, dot(force(n), along(data))))
                .collect()
        };
        let pressure = recovered(s, cover, &component(&|d| d.normal.map(|c| -c)));
        let shear: Vec<BTreeMap<usize, f64>> = (0..if D == 2 { 1 } else { D })
            .map(|k| recovered(s, cover, &component(&|d| shear_directions(d.normal)[k])))
            .collect();
        for (&n, data) in &s.nodes {
            let (nn, p) = (data.normal, pressure[&n]);
            // the tangential traction `sum_k v_k d_k`: `tau t` in 2D, the recovered vector
            // projected onto the node's tangent plane in 3D
            let mut tangential = [0.0; D];
            for (v, d) in shear.iter().zip(shear_directions(nn)) {
                for i in 0..D {
                    tangential[i] += v[&n] * d[i];
                }
            }
            let tau = if D == 2 {
                shear[0][&n]
            } else {
                dot(tangential, tangential).sqrt()
            };
            // the whole tributary where it is covered to round-off
            let covered_area = cover.get(&n).map_or(0.0, |c| c.values().sum());
            let covered_area = if (covered_area - data.area).abs() <= 1e-14 * data.area {
                data.area
            } else {
                covered_area
            };
            nodes.push(NodalTraction {
                body: s.body,
                node: n,
                point: position(s.body, n),
                area: data.area,
                covered_area,
                normal: nn,
                force: force(n),
                traction: std::array::from_fn(|i| -p * nn[i] + tangential[i]),
                pressure: p,
                shear: tau,
                carries_rows: slave_nodes.contains(&(s.body, n)),
            });
        }
    }

    let sizes: Vec<BTreeMap<usize, f64>> = surfaces.iter().map(element_sizes).collect();
    let penetration = pair_penetration(state, k, &surfaces, &sizes, position);

    PairForces {
        pair: k,
        on_slave,
        on_master,
        net_moment,
        force_scale,
        nodes,
        penetration,
    }
}

/// The covered tributary `c_a^e` of each node `a` of a surface on each facet `e` that holds it
/// ([`crate::contact::Constraint::cover`]).
pub type Cover = BTreeMap<usize, BTreeMap<usize, f64>>;

/// A facet covered on less than this share of its area is a sliver: its mean traction is not
/// used (module notes, **Recovery**).
pub const SLIVER_SHARE: f64 = 0.1;

/// The nodal values `v_a` of a traction component recovered from the nodal forces' component
/// `F_a` (`values`) on `surface`, in any dimension (module notes, **Recovery**): with the
/// covered tributary `C_a = sum_e c_a^e`, each facet's covered area `L_e = sum_a c_a^e` and,
/// unless it is a sliver (`L_e < SLIVER_SHARE` of its area), its mean `v_e = sum_{a, C_a > 0}
/// F_a (c_a^e / C_a) / L_e`,
///
/// ```text
/// v_a = F_a / A_a                                   no cover (C_a = 0)
/// v_a = F_a / sum_{e at a, c_a^e > 0} A_a^e         each facet at a covers a's share wholly or not at all
/// v_a = sum_e L_e v_e / sum_e L_e                   over the facets at a with c_a^e > 0 that are
///                                                   not slivers, where one covers a's share in part
/// v_a = F_a / A_a                                   if all those are slivers
/// ```
pub fn recovered<const D: usize, K>(
    surface: &Surface<D, K>,
    cover: &Cover,
    values: &BTreeMap<usize, f64>,
) -> BTreeMap<usize, f64> {
    let covered = |n: usize| cover.get(&n).map_or(0.0, |c| c.values().sum::<f64>());
    let share = |n: usize, f: usize| {
        cover
            .get(&n)
            .and_then(|c| c.get(&f))
            .copied()
            .unwrap_or(0.0)
    };
    // each facet's covered area and, unless it is a sliver, its mean value
    let means: Vec<Option<(f64, f64)>> = surface
        .facets
        .iter()
        .zip(&surface.facet_weights)
        .enumerate()
        .map(|(f, (nodes, whole))| {
            let (mut force, mut length) = (0.0, 0.0);
            for &n in nodes {
                let c = share(n, f);
                if c > 0.0 {
                    force += values[&n] * c / covered(n);
                    length += c;
                }
            }
            let area: f64 = whole.iter().sum();
            (length > 0.0 && length >= SLIVER_SHARE * area).then(|| (length, force / length))
        })
        .collect();
    // per node: whether a facet covers its share in part, the tributary on uncovered facets,
    // and the covered-area-weighted sum of its facets' means
    #[derive(Default)]
    struct AtNode {
        partly: bool,
        uncovered: f64,
        weighted: f64,
        length: f64,
    }
    let mut at: BTreeMap<usize, AtNode> = BTreeMap::new();
    for (f, (nodes, whole)) in surface
        .facets
        .iter()
        .zip(&surface.facet_weights)
        .enumerate()
    {
        for (&n, &a) in nodes.iter().zip(whole) {
            let e = at.entry(n).or_default();
            let c = share(n, f);
            if c <= 0.0 {
                e.uncovered += a;
                continue;
            }
            e.partly |= a - c > 1e-14 * a;
            if let Some((length, mean)) = means[f] {
                e.weighted += length * mean;
                e.length += length;
            }
        }
    }
    surface
        .nodes
        .iter()
        .map(|(&n, data)| {
            let v = values[&n];
            let value = match at.get(&n) {
                Some(e) if covered(n) > 0.0 && !e.partly => v / (data.area - e.uncovered),
                Some(e) if covered(n) > 0.0 && e.length > 0.0 => e.weighted / e.length,
                _ => v / data.area,
            };
            // + 0.0: a node without force has value 0, not -0
            (n, value + 0.0)
        })
        .collect()
}

/// The largest penetration of pair `k` in `state`, in any dimension: frictionless rows one by
/// one (`max(0, -g)`), the rows of a tie together per slave node (the jump along the slave
/// surface's outward normal); relative to the contact element size at the node, the longest
/// facet there of `surfaces` (`sizes[i]`: [`element_sizes`] of `surfaces[i]`); `position`
/// places a node of a body (in the configuration of the rows).
pub fn pair_penetration<const D: usize, K>(
    state: &ContactState<D>,
    k: usize,
    surfaces: &[Surface<D, K>],
    sizes: &[BTreeMap<usize, f64>],
    position: impl Fn(usize, usize) -> [f64; D],
) -> Penetration<D> {
    let size_at = |b: usize, n: usize| {
        surfaces
            .iter()
            .zip(sizes)
            .find(|(s, _)| s.body == b)
            .and_then(|(_, h)| h.get(&n).copied())
            .unwrap_or(0.0)
    };
    let mut depth_at: BTreeMap<(usize, usize), f64> = BTreeMap::new();
    let mut jumps: BTreeMap<(usize, usize), ([f64; D], [f64; D])> = BTreeMap::new();
    for (r, &g) in state.rows.iter().zip(&state.gaps) {
        if r.pair != k {
            continue;
        }
        let key = (r.slave_body, r.slave_node);
        if r.bilateral {
            // the row's gradient on the slave node is the unit direction of the component it
            // ties; its gap is that component of the jump
            let e = jumps.entry(key).or_insert(([0.0; D], r.slave_normal));
            for i in 0..D {
                e.0[i] += g * r.normal[i];
            }
        } else {
            let d = depth_at.entry(key).or_insert(0.0f64);
            *d = d.max(-g);
        }
    }
    for (key, (d, ns)) in jumps {
        let e = depth_at.entry(key).or_insert(0.0f64);
        *e = e.max((0..D).map(|i| d[i] * ns[i]).sum());
    }
    let mut penetration = Penetration::default();
    for (&(b, n), &depth) in &depth_at {
        let depth = depth.max(0.0);
        let h = size_at(b, n);
        let share = if h > 0.0 { depth / h } else { 0.0 };
        penetration.depth = penetration.depth.max(depth);
        if share > penetration.share_of_element || penetration.at.is_none() && depth > 0.0 {
            penetration.share_of_element = share;
            penetration.at = Some((b, n, position(b, n)));
        }
    }
    penetration
}
