//! Contact results per point and per surface: what a user compares with another code.
//!
//! For every node of a pair's contact surfaces (the slave surface, and the master surface when
//! the master is a body) this gives, from the nodal forces of [`super::forces`]
//! (`f^k = B_k^T lambda_k`, unique even where the multipliers of dependent rows are not):
//!
//! ```text
//! nodal contact force   f_a = (B_n^T lambda_n + B_t^T lambda_t)_a   (on the node, [x, y])
//! normal pressure       p_a   = -f_a . n_a / A_a (compression positive)
//! shear traction        tau_a =  f_a . t_a / A_a,  t_a = (-n_y, n_x)
//! ```
//!
//! (`B_t^T lambda_t`: the tangential rows of Coulomb pairs, [`super::friction`]; zero elsewhere)
//! with `n_a` the outward unit normal of the surface at the node and `A_a = t int N_a ds` its
//! tributary area (thickness `t`), wherever the node's tributary is wholly covered by the
//! master (or not at all). For a Lagrange multiplier row `lambda_i / A_i` is the multiplier, for
//! a penalty row `kappa (-g_i)`: `p_a` is that same force per tributary area, summed over every
//! row that acts on the node (a master node of a one-pass pair gets the share the projection
//! weights give it).
//!
//! At a node of a slave facet that the master covers only in part (the master ends over it)
//! `p_a` and `tau_a` are the recovered values of [`super::forces`] (**Recovery**): the
//! covered-length-weighted mean over the node's covered facets of each facet's mean traction
//! (the force it transmits over its covered length), skipping slivers (facets covered on less
//! than a tenth). Why not `f_a / A_a`: the node transmits force over its covered part `C_a`
//! only, so a uniform pressure of 100 read 92.0 and 18.0 there (W07). Why not `f_a / C_a`: on a
//! sliver of cover (`C_a -> 0`) that ratio is not bounded (173.9 where the traction is 1,
//! defect D13). The recovery is exact for a uniform traction (except at a node whose only
//! covered facets are slivers: `f_a / A_a` there), bounded on slivers, and `f_a / A_a` to the
//! bit at interior nodes and at every node of node-based rows. `area` is `A_a`; `force` is
//! `f_a`, so `p_a A_a` differs from `-f_a . n_a` at such nodes by the traction of the
//! uncovered part.
//!
//! At a node that is the slave node of a row of the pair (first-pass slave nodes, and the
//! master body's nodes in the second pass of a two-pass pair) the rows also give:
//!
//! * **gap**: the row's gap `g(u)` at the solution (`g < 0`: penetration); the smallest one
//!   if several frictionless rows share the node; for a tie, the normal opening
//!   `-(u_s - u_m) . n_s` of the jump along the slave normal.
//! * **status**: `open` (no row of the node carries force), `closed` (frictionless or tied),
//!   `stick` or `slip` (Coulomb pairs, from the return map of [`super::friction`]).
//! * **slip**: Coulomb pairs only, the tangential slip measure `g_t = t . (u_s - sum N_m u_m)`
//!   at the end of the solve and its plastic part `g_t^p`, at closed points (stick or slip);
//!   an open point is not in contact and has no slip (none reported, as for a frictionless
//!   pair).
//!
//! A node without a row of its own (the master surface of a one-pass pair, or a slave node
//! past the master's free end, whose finite-kinematics row to a master vertex carries no force:
//! `Constraint::past_free_end`) is `unmeasured`: it has a force and a pressure but no gap,
//! status or slip.
//!
//! Per pair the totals: the forces on both sides (from [`super::forces`]), the normal force
//! the pair transmits, `sum_a -f_a . n_a` over the first-pass slave side, the closed area (the
//! sum of the covered tributaries `C_a` over its closed nodes: `A_a` where wholly covered, so
//! a uniform pressure `p` gives normal force = `p` x closed area), the largest pressure and the
//! counts of each status.
//!
//! Under finite kinematics (or contact geometry in the current configuration) the surfaces,
//! their normals and tributary areas are those of the rows' configuration `X + u`
//! ([`super::forces`]): the pressure and shear are true (Cauchy) tractions, force per current
//! area (`tests/output.rs` checks them against a neo-Hookean block's closed form).
//!
//! Positions are reference coordinates (the rows' configuration may be `X + u`: see
//! [`super::forces`]); the displacement at each node is given beside them.

use super::discretization::Discretize;
use super::forces::{length, pair_forces, PairForces};
use super::friction::Status as FrictionStatus;
use super::state::ContactState;
use crate::model::{MasterSide, Model};
use serde::{Serialize, Serializer};
use std::collections::BTreeMap;

/// A point or vector of `D` components, serialized as a list (the contact results and
/// [`crate::post::PairSummary`]).
pub(crate) fn components<S: Serializer, const D: usize>(
    v: &[f64; D],
    s: S,
) -> Result<S::Ok, S::Error> {
    v.as_slice().serialize(s)
}

/// What the rows say about a contact point.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PointStatus {
    /// No row has this node as its slave node (a one-pass master surface).
    Unmeasured,
    Open,
    Closed,
    Stick,
    Slip,
}

impl PointStatus {
    /// The integer written to `.vtu` files (`contact_status`): 0 unmeasured, 1 open, 2 closed,
    /// 3 stick, 4 slip.
    pub fn code(self) -> i32 {
        match self {
            PointStatus::Unmeasured => 0,
            PointStatus::Open => 1,
            PointStatus::Closed => 2,
            PointStatus::Stick => 3,
            PointStatus::Slip => 4,
        }
    }

    /// The word written to CSV files.
    pub fn word(self) -> &'static str {
        match self {
            PointStatus::Unmeasured => "unmeasured",
            PointStatus::Open => "open",
            PointStatus::Closed => "closed",
            PointStatus::Stick => "stick",
            PointStatus::Slip => "slip",
        }
    }
}

/// Which surface of a pair a point lies on.
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// The pair's (first-pass) slave surface.
    Slave,
    /// The master body's surface.
    Master,
}

/// The results at one node of a contact surface (`D` components).
#[derive(Clone, Debug, Serialize)]
pub struct ContactPoint<const D: usize = 2> {
    pub side: Side,
    /// Body name and local node number.
    pub body: String,
    pub node: usize,
    /// Reference position and displacement.
    #[serde(serialize_with = "components")]
    pub x: [f64; D],
    #[serde(serialize_with = "components")]
    pub u: [f64; D],
    /// Outward unit normal of the surface and tributary area `A_a`.
    #[serde(serialize_with = "components")]
    pub normal: [f64; D],
    pub area: f64,
    /// Nodal contact force `f_a`.
    #[serde(serialize_with = "components")]
    pub force: [f64; D],
    /// The covered part `C_a` of the tributary area (module notes).
    pub covered_area: f64,
    /// The recovered pressure `p_a` (`-f_a . n_a / A_a` where the tributary is wholly covered).
    pub pressure: f64,
    /// The recovered shear traction: in 2D `tau_a` along `t_a = (-n_y, n_x)` (`f_a . t_a / A_a`
    /// where the tributary is wholly covered), in 3D the magnitude of the tangential traction
    /// ([`super::forces`]).
    pub shear: f64,
    /// The gap of the node's rows (`None`: unmeasured).
    pub gap: Option<f64>,
    pub status: PointStatus,
    /// Coulomb pairs, at points in contact (stick or slip): slip measure `g_t` and plastic
    /// slip `g_t^p` (`None` elsewhere: frictionless pairs, open and unmeasured points); in 2D
    /// signed along `t_a`, in 3D their lengths in the tangent plane.
    pub slip: Option<f64>,
    pub plastic_slip: Option<f64>,
}

/// One surface of a pair: its body and facets, as indices into the pair's points.
#[derive(Clone, Debug)]
pub struct SurfaceCells {
    pub side: Side,
    /// The VTK cell type of its facets (edges in 2D, faces in 3D).
    pub vtk_type: u8,
    /// Each facet's points (indices into [`PairResults::points`]), in edge order
    /// `[start, end(, mid)]`.
    pub facets: Vec<Vec<usize>>,
}

/// The totals of one pair.
#[derive(Clone, Debug, Serialize)]
pub struct PairTotals<const D: usize = 2> {
    /// Net force on the slave body and on the master (body or rigid surface).
    #[serde(serialize_with = "components")]
    pub force_on_slave: [f64; D],
    #[serde(serialize_with = "components")]
    pub force_on_master: [f64; D],
    /// `sum_a -f_a . n_a` over the slave side: the normal force the pair transmits.
    pub normal_force: f64,
    /// Sum of the covered tributary areas `C_a` of the slave side's closed (closed, stick,
    /// slip) points.
    pub closed_area: f64,
    /// Largest pressure over the points that carry rows (for frictionless pairs the
    /// `max_pressure` of [`super::forces::PairForces`]).
    pub max_pressure: f64,
    /// Points of each status, both sides.
    pub unmeasured: usize,
    pub open: usize,
    pub closed: usize,
    pub stick: usize,
    pub slip: usize,
}

/// Everything a pair's result files hold.
#[derive(Clone, Debug)]
pub struct PairResults<const D: usize = 2> {
    pub pair: usize,
    pub name: String,
    pub points: Vec<ContactPoint<D>>,
    pub surfaces: Vec<SurfaceCells>,
    pub totals: PairTotals<D>,
}

/// The per-point results of every pair of `model` in the contact solution `state` at `u`, in
/// either dimension.
pub fn pair_results<const D: usize, K: Discretize<D>>(
    model: &Model<D, K>,
    state: &ContactState<D>,
    u: &[f64],
) -> Vec<PairResults<D>> {
    pair_forces(model, state)
        .iter()
        .map(|f| one_pair(model, state, u, f))
        .collect()
}

/// What the rows of one slave node found.
#[derive(Default)]
struct RowFindings<const D: usize> {
    frictionless_gap: Option<f64>,
    jump: Option<([f64; D], [f64; D])>,
    carries_force: bool,
    friction: Option<(FrictionStatus, f64, f64)>,
}

fn one_pair<const D: usize, K: Discretize<D>>(
    model: &Model<D, K>,
    state: &ContactState<D>,
    u: &[f64],
    forces: &PairForces<D>,
) -> PairResults<D> {
    let k = forces.pair;
    let pair = &model.contact[k];
    let mut findings: BTreeMap<(usize, usize), RowFindings<D>> = BTreeMap::new();
    for (i, r) in state.rows.iter().enumerate() {
        // a row past the master's free end that carries no force is no measurement: the node
        // has no master facet under it ([`Constraint::past_free_end`])
        if r.pair != k || (r.past_free_end && !state.active[i]) {
            continue;
        }
        let found = findings.entry((r.slave_body, r.slave_node)).or_default();
        let g = state.gaps[i];
        if r.bilateral {
            let e = found.jump.get_or_insert(([0.0; D], r.slave_normal));
            for c in 0..D {
                e.0[c] += g * r.normal[c];
            }
        } else {
            found.frictionless_gap = Some(found.frictionless_gap.map_or(g, |m: f64| m.min(g)));
        }
        found.carries_force |= state.active[i];
        if let Some(Some(fp)) = state.friction.get(i) {
            // in 2D the one tangent's signed slip, in 3D the slip's length in the plane
            let along = |v: &[f64]| {
                if fp.tangents == 1 {
                    v[0]
                } else {
                    length(&v[..fp.tangents])
                }
            };
            found.friction = Some((fp.status, along(&fp.slip), along(&fp.plastic_slip)));
        }
    }

    let mut sides = vec![(Side::Slave, pair.slave.0, &pair.slave.1)];
    if let MasterSide::Body { body, facets } = &pair.master {
        sides.push((Side::Master, *body, facets));
    }
    let mut points = Vec::new();
    let mut index: BTreeMap<(Side, usize, usize), usize> = BTreeMap::new();
    let mut surfaces = Vec::new();
    for &(side, b, facet_set) in &sides {
        let body = &model.bodies[b];
        let side_nodes: std::collections::BTreeSet<usize> = facet_set
            .iter()
            .flat_map(|&f| body.mesh.facet_nodes(f))
            .collect();
        for &node in &side_nodes {
            let Some(n) = forces.nodes.iter().find(|t| t.body == b && t.node == node) else {
                continue;
            };
            let found = findings.get(&(b, n.node));
            let (gap, status, slip, plastic_slip) = match found {
                None => (None, PointStatus::Unmeasured, None, None),
                Some(f) => {
                    let gap = match (f.frictionless_gap, f.jump) {
                        (Some(g), _) => Some(g),
                        (None, Some((d, ns))) => Some(-(0..D).map(|c| d[c] * ns[c]).sum::<f64>()),
                        (None, None) => None,
                    };
                    let status = match (f.friction, f.carries_force) {
                        (Some((FrictionStatus::Stick, ..)), true) => PointStatus::Stick,
                        (Some((FrictionStatus::Slip, ..)), true) => PointStatus::Slip,
                        (_, true) => PointStatus::Closed,
                        (_, false) => PointStatus::Open,
                    };
                    // an open point transmits nothing and has no slip: its slip measure
                    // (the tangential motion of a point not in contact) is not reported
                    let friction = f.friction.filter(|_| status != PointStatus::Open);
                    (gap, status, friction.map(|x| x.1), friction.map(|x| x.2))
                }
            };
            let nn = n.normal;
            // the nodal force of `forces`: normal rows plus, for Coulomb pairs, the tangential
            // forces `B_t^T lambda_t` (see `contact::forces`)
            let force = n.force;
            index.insert((side, b, n.node), points.len());
            points.push(ContactPoint {
                side,
                body: body.name.clone(),
                node: n.node,
                x: body.mesh.nodes[n.node],
                u: std::array::from_fn(|c| u[body.dof(n.node, c)]),
                normal: nn,
                area: n.area,
                force,
                covered_area: n.covered_area,
                // + 0.0: a node without force has pressure 0, not -0
                pressure: n.pressure + 0.0,
                shear: n.shear + 0.0,
                gap,
                status,
                slip,
                plastic_slip,
            });
        }
        let facets = facet_set
            .iter()
            .map(|&f| {
                body.mesh
                    .facet_nodes(f)
                    .iter()
                    .map(|n| index[&(side, b, *n)])
                    .collect()
            })
            .collect();
        surfaces.push(SurfaceCells {
            side,
            vtk_type: body.mesh.kind.facet_vtk_type(),
            facets,
        });
    }

    let count = |s: PointStatus| points.iter().filter(|p| p.status == s).count();
    let slave_side = points.iter().filter(|p| p.side == Side::Slave);
    let totals = PairTotals {
        force_on_slave: forces.on_slave,
        force_on_master: forces.on_master,
        normal_force: slave_side
            .clone()
            .map(|p| -(0..D).map(|c| p.force[c] * p.normal[c]).sum::<f64>())
            .sum(),
        closed_area: slave_side
            .filter(|p| p.status > PointStatus::Open)
            .map(|p| p.covered_area)
            .sum::<f64>()
            + 0.0,
        max_pressure: points
            .iter()
            .filter(|p| p.status != PointStatus::Unmeasured)
            .fold(0.0, |m: f64, p| m.max(p.pressure)),
        unmeasured: count(PointStatus::Unmeasured),
        open: count(PointStatus::Open),
        closed: count(PointStatus::Closed),
        stick: count(PointStatus::Stick),
        slip: count(PointStatus::Slip),
    };
    PairResults {
        pair: k,
        name: pair.name.clone(),
        points,
        surfaces,
        totals,
    }
}
