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
//! tributary area `A_a = t int N_a ds` (thickness `t`), the traction is `f_a / A_a`; the contact
//! pressure is `p_a = -f_a . n_a / A_a`. It does not depend on which body is the slave, nor on
//! how a mortar row is normalized (a row's own `lambda / A` is a multiplier coefficient, not a
//! traction: at a slave node whose support barely overlaps the master it reached 19,976 where
//! the traction is 1, defect D13).
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

use super::discretization::geometry::Surface;
use super::state::ContactState;
use crate::model::{Body, MasterSide, Model};
use std::collections::BTreeMap;

/// The contact traction at one node of a contact surface.
#[derive(Clone, Debug)]
pub struct NodalTraction {
    pub body: usize,
    pub node: usize,
    /// Position (in the configuration of the rows).
    pub point: [f64; 2],
    /// Tributary area `t int N_a ds`.
    pub area: f64,
    /// Outward unit normal of the surface at the node.
    pub normal: [f64; 2],
    /// Nodal contact force `f_a`.
    pub force: [f64; 2],
    /// `-f_a . n_a / A_a` (compression positive).
    pub pressure: f64,
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
pub struct PairForces {
    pub pair: usize,
    /// Net force on the pair's (first-pass) slave body, and on its master (body or rigid).
    pub on_slave: [f64; 2],
    pub on_master: [f64; 2],
    /// Net moment (about the origin, in the configuration of the rows) of the forces on both
    /// sides, and the sum of `|f_a|` over all nodes (its scale).
    pub net_moment: f64,
    pub force_scale: f64,
    /// Tractions at the nodes of both surfaces (the master's only for a body master).
    pub nodes: Vec<NodalTraction>,
    pub penetration: Penetration,
}

impl PairForces {
    /// Largest contact pressure over the nodes that carry rows (both sides for two passes).
    pub fn max_pressure(&self) -> f64 {
        self.nodes
            .iter()
            .filter(|n| n.carries_rows)
            .fold(0.0, |m: f64, n| m.max(n.pressure))
    }
}

/// The body owning global dof `d`, and the local node and component.
fn owner(model: &Model, d: usize) -> (usize, usize, usize) {
    let r = model.dof_owner(d).expect("a body owns every dof");
    (r.body, r.node, r.component)
}

/// `body` moved to `X + u` (or as it is, borrowed, without `u`).
fn placed<'a>(body: &'a Body, u: Option<&[f64]>) -> std::borrow::Cow<'a, Body> {
    let Some(u) = u else {
        return std::borrow::Cow::Borrowed(body);
    };
    let mut b = body.clone();
    for (n, p) in b.mesh.nodes.iter_mut().enumerate() {
        p[0] += u[body.dof(n, 0)];
        p[1] += u[body.dof(n, 1)];
    }
    std::borrow::Cow::Owned(b)
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

/// Forces, pressures and penetrations of every pair of `model` in the contact solution `state`.
pub fn pair_forces(model: &Model, state: &ContactState) -> Vec<PairForces> {
    let config = state.configuration.as_deref();
    (0..model.contact.len())
        .map(|k| one_pair(model, state, k, config))
        .collect()
}

fn one_pair(model: &Model, state: &ContactState, k: usize, config: Option<&[f64]>) -> PairForces {
    let pair = &model.contact[k];
    // The surfaces of both sides, in the configuration of the rows.
    let mut sides = vec![(pair.slave.0, &pair.slave.1)];
    if let MasterSide::Body { body, facets } = &pair.master {
        sides.push((*body, facets));
    }
    let surfaces: Vec<Surface> = sides
        .iter()
        .map(|&(b, facets)| {
            let body = placed(&model.bodies[b], config);
            Surface::new(b, &body, facets, model.thickness)
        })
        .collect();

    // f^k, per (body, node).
    let mut nodal: BTreeMap<(usize, usize), [f64; 2]> = BTreeMap::new();
    let mut slave_nodes = std::collections::BTreeSet::new();
    for (i, (r, &lambda)) in state.rows.iter().zip(&state.forces).enumerate() {
        if r.pair != k {
            continue;
        }
        slave_nodes.insert((r.slave_body, r.slave_node));
        for (&d, &c) in r.dofs.iter().zip(&r.coeffs) {
            let (b, n, comp) = owner(model, d);
            nodal.entry((b, n)).or_insert([0.0; 2])[comp] += c * lambda;
        }
        // a frictional row's tangential force acts along its slip gradient
        if let Some(Some(f)) = state.friction.get(i) {
            for (t, &lambda_t) in r.tangents.iter().zip(&f.force) {
                for (&d, &c) in t.dofs.iter().zip(&t.coeffs) {
                    let (b, n, comp) = owner(model, d);
                    nodal.entry((b, n)).or_insert([0.0; 2])[comp] += c * lambda_t;
                }
            }
        }
    }
    let position = |b: usize, n: usize| {
        let body = &model.bodies[b];
        let p = body.mesh.nodes[n];
        match config {
            Some(u) => [p[0] + u[body.dof(n, 0)], p[1] + u[body.dof(n, 1)]],
            None => p,
        }
    };
    let (mut on_slave, mut on_master) = ([0.0; 2], [0.0; 2]);
    let (mut net_moment, mut force_scale) = (0.0, 0.0);
    for (&(b, n), f) in &nodal {
        let target = if b == pair.slave.0 {
            &mut on_slave
        } else {
            &mut on_master
        };
        target[0] += f[0];
        target[1] += f[1];
        let p = position(b, n);
        net_moment += p[0] * f[1] - p[1] * f[0];
        force_scale += f[0].hypot(f[1]);
    }
    if let MasterSide::Rigid(_) = pair.master {
        on_master = [-on_slave[0], -on_slave[1]];
    }

    let mut nodes = Vec::new();
    for s in &surfaces {
        for (&n, data) in &s.nodes {
            let f = nodal.get(&(s.body, n)).copied().unwrap_or([0.0; 2]);
            let pressure = -(f[0] * data.normal[0] + f[1] * data.normal[1]) / data.area;
            nodes.push(NodalTraction {
                body: s.body,
                node: n,
                point: position(s.body, n),
                area: data.area,
                normal: data.normal,
                force: f,
                pressure,
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
