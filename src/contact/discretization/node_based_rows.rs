//! Node-based contact rows in 3D: node-to-surface one- and two-pass with master normals,
//! node-to-node, rigid plane and sphere masters, as [`Constraint`] rows with 3 components
//! (`Constraint<3>`; small strain: geometry taken once in the reference configuration, like the
//! 2D rows of [`super::constraints`]). Node-to-node and the rigid masters are written once for any
//! dimension `D` (the same formulas as in 2D, where a rigid plane is a line and a sphere a
//! circle).
//!
//! Every row is the linearization of a gap `g(x)` at the reference positions,
//! `g = g0 + sum_k c_k u_{d_k}` (Taylor 2004, "FEM Node-to-Surface Contact Analysis"; Wriggers,
//! Computational Contact Mechanics, 2nd ed. 2006, sections 4.1-4.3):
//!
//! * **Node-to-surface** (master normals): slave node `x_s` against the closest point `x(xi)`
//!   of the master surface, found among the facets the bucket grid ([`BucketGrid`]) gives
//!   within the search distance (default: the largest master facet) by
//!   [`project_onto_facet`]. Inside a facet, `g = n . (x_s - x(xi))` with the facet's outward
//!   unit normal `n` at `xi`; as `x_s - x(xi)` is along `n` and `n` is a unit vector, the
//!   variations of `xi` and of `n` drop out, so the row is `n` on the slave node's dofs and
//!   `-N_a(xi) n` on facet node `a`'s. **Edges and corners**: a slave node whose closest point
//!   is on an edge shared by two master facets or at a vertex inside the master surface (outside
//!   a convex edge or corner) is held at the distance `g = |x_s - x_c|` along
//!   `nu = (x_s - x_c) / |x_s - x_c|` (or the facet normal when the node sits on it), the row
//!   `nu` on the slave and `-N_a(xi) nu` on the edge's nodes (`-nu` on the vertex): the 3D
//!   corner condition. Behind the facet's plane (a node inside the master body under a concave
//!   edge, which neither facet's normal through the node meets) the gap is `-|x_s - x_c|` and
//!   `nu` turns round (the side of the surface's averaged normal there: the nodal normals
//!   interpolated on the edge, the vertex's at a corner): a penetration, not a separation.
//!   **Kinks under finite kinematics**: within [`SHARED_EDGE_HOLD`] of an edge two facets
//!   share in a concave kink, the facet of lower index holds the node, extended past the edge
//!   ([`held_across_shared_edge`]): there neither facet's row has an equilibrium near the edge
//!   and Newton alternated between them. A slave node whose closest point is on the free
//!   boundary of the master surface (an edge of one facet only, or a vertex on such an edge)
//!   lies beyond it and gets no row under small strain; under finite kinematics (rows built
//!   in the current configuration) a node within a quarter facet ([`FREE_BOUNDARY_EXTENSION`])
//!   beyond it is held against the facet's interpolation extrapolated, as an interior point
//!   (the 2D rows' free-end extension, [`super::END_EXTENSION`]): a slave node of a patch test
//!   whose surface ends where the master's does leaves it by round-off of the iterates
//!   otherwise.
//!   **Finite kinematics**: every node-to-surface row also carries the second derivative of its
//!   gap over the slave node and the facet's nodes ([`super::facet_gap_hessian`], interior,
//!   edge and corner points; `Constraint::hessian`), which the Newton tangent consumes.
//!   **Two-pass** appends the rows with the roles swapped (`pass` 2).
//! * **Node-to-node**: slave node `s` against the master node `m` at the same place (to
//!   `1e-9` of the master surface's size), `g = n_m . (x_s - x_m)` with the master's nodal
//!   normal `n_m` ([`super::geometry`]); `n_m` on the slave, `-n_m` on the master. The nodes
//!   must match one to one (a clear error names the first that does not).
//! * **Rigid masters**: a plane through `point` with outward `normal` (normalized),
//!   `g = n . (x - p)`; a sphere (a circle in 2D) of centre `c` and radius `R`,
//!   `g = |x - c| - R` with gradient `(x - c) / |x - c|`. Only slave dofs appear.
//!
//! Each row's `area` is the slave node's weight (`int M_a dA`), `normal` the gap's gradient with
//! respect to the slave node's displacement, `slave_normal` the slave surface's nodal normal,
//! `point` the slave node's reference position and `owner` the slave dof with the largest
//! `|coefficient|` (the later component on a tie, as in 2D). Coefficients below `1e-12` of the
//! row's largest are round-off of exact zeros (the shape functions of a facet's other nodes at a
//! corner) and are dropped. The global dof of `(body, node, component)` comes from a
//! [`DofNumbering`] (any closure `Fn(usize, usize, usize) -> usize`).

use super::facet_gap_hessian::node_to_facet_gap_hessian_at;
use super::facet_projection::{
    edge_violations, project_onto_extended_facet, project_onto_facet, violated_edges, FacetFeature,
    FacetProjection,
};
use super::geometry::{dot, FacetShape, Surface, Surface3, MAX_FACET_NODES};
use super::search::BucketGrid;
use crate::contact::{Constraint, GapHessian};
use std::collections::{BTreeSet, HashMap};

/// The global dof of component `component` of node `node` of body `body`.
pub trait DofNumbering {
    fn dof(&self, body: usize, node: usize, component: usize) -> usize;
}

impl<F: Fn(usize, usize, usize) -> usize> DofNumbering for F {
    fn dof(&self, body: usize, node: usize, component: usize) -> usize {
        self(body, node, component)
    }
}

/// What every row of a pair needs besides the surfaces.
pub struct RowSettings<'a> {
    pub dofs: &'a dyn DofNumbering,
    /// Index of the contact pair (the rows' `pair`).
    pub pair: usize,
    /// How far from the master surface a slave node is still a candidate (default: the
    /// largest master facet).
    pub search_distance: Option<f64>,
    /// Finite kinematics, the rows built in the current configuration: every node-to-surface
    /// row carries the second derivative of its gap
    /// ([`super::facet_gap_hessian::node_to_facet_gap_hessian`], `Constraint::hessian`) for
    /// the Newton tangent, and a slave node just past the free boundary of the master surface
    /// is held against the facet extended by [`FREE_BOUNDARY_EXTENSION`] (module notes).
    pub current_finite: bool,
}

/// A rigid analytic master surface in `D` dimensions.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum RigidMaster<const D: usize> {
    /// The plane (a line in 2D) through `point`; `normal` points to the side where the slave
    /// body lives (any length but zero).
    Plane { point: [f64; D], normal: [f64; D] },
    /// A sphere (a circle in 2D); the slave body lives outside it.
    Sphere { centre: [f64; D], radius: f64 },
}

/// The gap of position `x` against a rigid master and its gradient (module notes), or why
/// there is none.
pub fn rigid_gap<const D: usize>(
    rigid: &RigidMaster<D>,
    x: [f64; D],
) -> Result<(f64, [f64; D]), String> {
    match *rigid {
        RigidMaster::Plane { point, normal } => {
            let l = dot(normal, normal).sqrt();
            if !(l > 0.0 && l.is_finite()) {
                return Err(format!(
                    "the rigid plane's normal {normal:?} has no direction; give a finite, non-zero outward normal"
                ));
            }
            let n = normal.map(|c| c / l);
            Ok((dot(n, std::array::from_fn(|i| x[i] - point[i])), n))
        }
        RigidMaster::Sphere { centre, radius } => {
            if !(radius > 0.0 && radius.is_finite()) {
                return Err(format!(
                    "the rigid sphere's radius {radius} is not a positive length; give a radius > 0"
                ));
            }
            let d: [f64; D] = std::array::from_fn(|i| x[i] - centre[i]);
            let l = dot(d, d).sqrt();
            if l <= 1e-12 * radius {
                return Err(format!(
                    "the slave surface at {x:?} sits at the centre of the rigid sphere, where the normal is undefined; move the sphere or the slave surface"
                ));
            }
            Ok((l - radius, d.map(|c| c / l)))
        }
    }
}

/// The gradient of `g = nu . (sum_k a_k u_k - sum_l b_l u_l)` over slave terms `(node, a_k)`
/// (global dof `slave_dof(node, component)`) and master terms `(node, b_l)` of body `master.0`
/// (`master_dof(body, node, component)`): the dofs in that order, each once, with their
/// coefficients. Coefficients below `1e-12` of the row's largest weight times its largest
/// `|nu_i|` are round-off of exact zeros (mortar integrals of disjoint supports, shape functions
/// at a node) and are dropped; kept, they could pin a dof on their own. Shared by the 2D rows
/// ([`super::weighted_row`]) and these.
pub(crate) fn gradient_coefficients<const D: usize>(
    nu: [f64; D],
    slave_terms: &[(usize, f64)],
    slave_dof: impl Fn(usize, usize) -> usize,
    master: (usize, &[(usize, f64)]),
    master_dof: impl Fn(usize, usize, usize) -> usize,
) -> (Vec<usize>, Vec<f64>) {
    let largest = slave_terms
        .iter()
        .chain(master.1)
        .fold(0.0f64, |a, t| a.max(t.1.abs()))
        * nu.iter().fold(0.0f64, |a, c| a.max(c.abs()));
    let mut dofs = Vec::new();
    let mut coeffs = Vec::new();
    let mut push = |dof: usize, c: f64| {
        if c.abs() > 1e-12 * largest {
            match dofs.iter().position(|&d| d == dof) {
                Some(k) => coeffs[k] += c,
                None => {
                    dofs.push(dof);
                    coeffs.push(c);
                }
            }
        }
    };
    for &(n, a) in slave_terms {
        for (i, &c) in nu.iter().enumerate() {
            push(slave_dof(n, i), a * c);
        }
    }
    for &(n, b) in master.1 {
        for (i, &c) in nu.iter().enumerate() {
            push(master_dof(master.0, n, i), -b * c);
        }
    }
    (dofs, coeffs)
}

/// The component of `nu` with the largest magnitude (the later one on a tie): the slave dof a
/// row owns.
pub(crate) fn dominant_component<const D: usize>(nu: [f64; D]) -> usize {
    let mut component = 0;
    for i in 1..D {
        if nu[i].abs() >= nu[component].abs() {
            component = i;
        }
    }
    component
}

/// The row `g = g0 + nu . (u_s - sum_b w_b u_b)` of slave node `node` of `slave` against master
/// terms `(node, w_b)` of body `master.0` (`None`: a rigid master), pass `pass` (module notes).
#[allow(clippy::too_many_arguments)]
pub fn node_row<const D: usize, K>(
    settings: &RowSettings,
    slave: &Surface<D, K>,
    node: usize,
    nu: [f64; D],
    g0: f64,
    master: Option<(usize, &[(usize, f64)])>,
    pass: u8,
) -> Constraint<D> {
    let dofs_of = settings.dofs;
    let (dofs, coeffs) = gradient_coefficients(
        nu,
        &[(node, 1.0)],
        |n, i| dofs_of.dof(slave.body, n, i),
        master.map_or((0, &[][..]), |m| m),
        |b, n, i| dofs_of.dof(b, n, i),
    );
    let component = dominant_component(nu);
    let data = slave.nodes[&node];
    Constraint {
        dofs,
        coeffs,
        g0,
        area: data.area,
        normal: nu,
        slave_normal: data.normal,
        slave_body: slave.body,
        slave_node: node,
        point: data.position,
        pass,
        owner: dofs_of.dof(slave.body, node, component),
        pair: settings.pair,
        bilateral: false,
        mass: Vec::new(),
        cover: slave.tributaries(node),
        tangents: Vec::new(),
        segment: None,
        nodal_normal: None,
        hessian: None,
        past_free_end: false,
    }
}

/// The rows are usable: finite, each owning one of its dofs; and there is at least one.
fn checked<const D: usize>(
    rows: Vec<Constraint<D>>,
    search_distance: Option<f64>,
) -> Result<Vec<Constraint<D>>, String> {
    if rows.is_empty() {
        return Err(format!(
            "{} ({}) of the master surface, so the pair could never act; check that the surfaces face each other or give a larger search_distance",
            super::OUT_OF_REACH,
            search_distance
                .map(|d| d.to_string())
                .unwrap_or_else(|| "the largest master facet".into())
        ));
    }
    if let Some(bad) = rows.iter().find(|r| {
        !(r.g0.is_finite() && r.coeffs.iter().all(|c| c.is_finite()) && r.dofs.contains(&r.owner))
    }) {
        return Err(format!(
            "the constraint of the slave node at {:?} is degenerate (no finite normal: a master facet of zero area?); check the mesh of the master surface",
            bad.point
        ));
    }
    Ok(rows)
}

/// The diagonal of the bounding box of a surface's nodes.
fn surface_extent<const D: usize, K>(surface: &Surface<D, K>) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; D], [f64::NEG_INFINITY; D]);
    for data in surface.nodes.values() {
        for i in 0..D {
            lo[i] = lo[i].min(data.position[i]);
            hi[i] = hi[i].max(data.position[i]);
        }
    }
    (0..D).map(|i| (hi[i] - lo[i]).powi(2)).sum::<f64>().sqrt()
}

/// Node-to-surface rows (master normals, 3D) of `slave` against `master`, and with
/// `passes == 2` those of `master` against `slave` (module notes).
pub fn node_to_surface_rows(
    slave: &Surface3,
    master: &Surface3,
    passes: u8,
    settings: &RowSettings,
) -> Result<Vec<Constraint<3>>, String> {
    if !(passes == 1 || passes == 2) {
        return Err(format!(
            "node-to-surface takes 1 or 2 passes, not {passes}; use 1 (slave against master) or 2 (both ways)"
        ));
    }
    let mut rows = node_to_surface_pass(slave, master, 1, settings);
    if passes == 2 {
        rows.extend(node_to_surface_pass(master, slave, 2, settings));
    }
    checked(rows, settings.search_distance)
}

/// How far outside its facet (natural units) an interior closest point may have been clamped
/// and still count as inside in a tie ([`closest_facet`]): a hundred times the round-off of
/// the projection, and below the solve's relative tolerance (the row weights, and so the
/// residual, are off by about this much relative to the row's force).
pub const TIE_EXCESS: f64 = 1e-13;

/// Which facet of `master` a slave node at `p` is held against, and where: the closest point
/// among the candidates; in a tie (distances within `tol`) an interior point wins against an
/// edge or a corner, and of two interior points the one the node is inside (the smaller
/// [`FacetProjection::excess`], all below [`TIE_EXCESS`] counting as inside; then the first
/// candidate). A node on or next to an edge shared by two facets (a slave node on a master
/// node or edge of a matching mesh) is so held by a facet whose closest-point gap is the one
/// at its position: the other facet's point, clamped onto its boundary from up to
/// [`super::facet_projection::INSIDE`] outside, gives row weights off by that much (Newton's
/// residual stalled at 1e-10 on the Tet4 stacked blocks, taking the first candidate); and a
/// node within round-off of the edge keeps one facet from one iterate to the next instead of
/// swapping facets with the round-off of its natural coordinates (which stalled the penalty
/// at 1e-11 on the Hex8 stacked blocks, taking the smallest excess).
fn closest_facet(
    master: &Surface3,
    candidates: &[usize],
    p: [f64; 3],
    tol: f64,
) -> Option<(usize, FacetProjection)> {
    let rank = |q: &FacetProjection| {
        (
            q.feature != FacetFeature::Interior,
            if q.excess <= TIE_EXCESS {
                0.0
            } else {
                q.excess
            },
        )
    };
    let mut best: Option<(usize, FacetProjection)> = None;
    for &f in candidates {
        let q = project_onto_facet(master.kind, &master.coords[f], p);
        let better = match &best {
            None => true,
            Some((_, b)) => {
                q.distance < b.distance - tol
                    || (q.distance <= b.distance + tol && rank(&q) < rank(b))
            }
        };
        if better {
            best = Some((f, q));
        }
    }
    best
}

/// One pass of node-to-surface: the rows of `slave`'s nodes against `master`.
fn node_to_surface_pass(
    slave: &Surface3,
    master: &Surface3,
    pass: u8,
    settings: &RowSettings,
) -> Vec<Constraint<3>> {
    let kind = master.kind;
    let grid = BucketGrid::new(master.boxes());
    let radius = settings
        .search_distance
        .unwrap_or_else(|| master.facet_size());
    let tol = 1e-12 * surface_extent(master);
    let corners = FacetShape::<3>::corner_count(kind);
    // edges of the master surface (corner pairs) with the number of facets on them: an edge of
    // one facet is on the free boundary, and so are its vertices
    let mut edge_facets: HashMap<(usize, usize), usize> = HashMap::new();
    for f in &master.facets {
        for k in 0..corners {
            let (a, b) = (f[k], f[(k + 1) % corners]);
            *edge_facets.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let free_vertices: BTreeSet<usize> = edge_facets
        .iter()
        .filter(|(_, &n)| n == 1)
        .flat_map(|(&(a, b), _)| [a, b])
        .collect();
    let mut rows = Vec::new();
    for (&s, data) in &slave.nodes {
        let p = data.position;
        let candidates = grid.query(p, radius);
        let Some((f, q)) = closest_facet(master, &candidates, p, tol) else {
            continue;
        };
        let facet = &master.facets[f];
        let nodes = facet.len();
        let free_edge = |k: usize| {
            let (a, b) = (facet[k], facet[(k + 1) % corners]);
            edge_facets[&(a.min(b), a.max(b))] == 1
        };
        let beyond_free_boundary = match q.feature {
            FacetFeature::Interior => false,
            FacetFeature::Edge(k) => free_edge(k),
            FacetFeature::Corner(k) => free_vertices.contains(&facet[k]),
        };
        let margin = FREE_BOUNDARY_EXTENSION * natural_span(kind);
        let q = if beyond_free_boundary {
            // finite kinematics: the facet extended (a node that slid just past the end of the
            // master surface); small strain, or farther out: the node has left it
            let extended = settings
                .current_finite
                .then(|| project_onto_extended_facet(kind, &master.coords[f], p, margin));
            match extended.flatten() {
                Some(q) => q,
                None => continue,
            }
        } else if settings.current_finite && q.excess > 0.0 {
            // finite kinematics, an interior point clamped onto the facet from past its free
            // boundary by less than INSIDE: held against the facet extended too, as a node
            // farther past, not at the clamped point (whose row weights stay fixed while the
            // node moves, a residual error of the clamped distance times the row's force: the
            // penalty on the Tet4 stacked blocks stalled at 1.5e-11 with the slave nodes on
            // the free boundary wandering 1e-10 past it); clamped from past an edge shared
            // with another facet (a node on a convex kink), the clamped point stays
            match project_onto_extended_facet(kind, &master.coords[f], p, margin) {
                Some(e) if held_past_free_edges(kind, e.natural, free_edge) => e,
                _ => q,
            }
        } else {
            q
        };
        let (f, q) = if settings.current_finite && q.feature == FacetFeature::Interior {
            held_across_shared_edge(master, &candidates, p, (f, q), &edge_facets, tol)
        } else {
            (f, q)
        };
        let facet = &master.facets[f];
        let mut n = [0.0; MAX_FACET_NODES];
        let mut dn = [[0.0; 2]; MAX_FACET_NODES];
        kind.shape(q.natural, &mut n[..nodes], &mut dn[..nodes]);
        let terms: Vec<(usize, f64)> = facet.iter().copied().zip(n).collect();
        let d: [f64; 3] = std::array::from_fn(|i| p[i] - q.point[i]);
        // on an edge or a corner: outside the master body (`1`) or inside it (`-1`, under a
        // concave edge or corner), by the surface's averaged normal there (the facet's nodal
        // normals interpolated on the edge, the vertex's at a corner)
        let surface_normal: [f64; 3] = match q.feature {
            FacetFeature::Corner(k) => master.nodes[&facet[k]].normal,
            _ => std::array::from_fn(|i| {
                (0..nodes)
                    .map(|a| n[a] * master.nodes[&facet[a]].normal[i])
                    .sum()
            }),
        };
        let side = if dot(d, surface_normal) < 0.0 {
            -1.0
        } else {
            1.0
        };
        let (nu, terms) = match q.feature {
            FacetFeature::Interior => (q.normal, terms),
            FacetFeature::Edge(_) => (away(d, q.distance, q.normal, tol, side), terms),
            FacetFeature::Corner(k) => (
                away(d, q.distance, q.normal, tol, side),
                vec![(facet[k], 1.0)],
            ),
        };
        let g0 = dot(nu, d);
        let mut row = node_row(
            settings,
            slave,
            s,
            nu,
            g0,
            Some((master.body, &terms)),
            pass,
        );
        if settings.current_finite {
            // over the slave node and every node of the facet (zero rows for the nodes off
            // the edge or the corner); none where the node sits on the edge or vertex itself
            row.hessian =
                node_to_facet_gap_hessian_at(kind, &master.coords[f], p, &q, side).map(|values| {
                    let dofs_of = settings.dofs;
                    let mut dofs: Vec<usize> =
                        (0..3).map(|i| dofs_of.dof(slave.body, s, i)).collect();
                    for &m in facet {
                        dofs.extend((0..3).map(|i| dofs_of.dof(master.body, m, i)));
                    }
                    GapHessian { dofs, values }
                });
        }
        rows.push(row);
    }
    rows
}

/// How far past an edge it shares with another facet (natural units, per unit of the facet's
/// natural span) a facet still holds a slave node under finite kinematics
/// ([`held_across_shared_edge`]). The band must hold the node's equilibrium against the
/// extended facet, which lies past the edge by about the row's force times the kink's angle
/// over the slave surface's tangential stiffness: 1e-3 was too narrow for the Tet4 punch on
/// the 0.25/0.8 grid at 20 % compression (Lagrange; its last load step alternated again at a
/// relative residual of 1e-4, `tests/finite3d.rs`,
/// `the_interfaces_that_fail_the_patch_test_converge_to_a_kinked_surface`). On a faceted
/// curved master (kink angle `h / R` between facets of size `h`) the gap error it allows,
/// `1e-2 h^2 / R`, is a twelfth of the facets' own distance from the curve, `h^2 / (8 R)`.
/// The price for a node that slides across a concave edge: where it leaves the band the facet
/// changes and its gap jumps by up to that error (at the edge itself, without the band, the
/// gap is continuous and only its gradient jumps). The same band in 2D (a trial on
/// 2026-11-28, not kept) made the finite contact patch test's foundation-slave Lagrange cell on
/// mesh A pass but took the finite sliding study's master-normal run from one load cut to
/// five, so the 2D rows keep the closest facet.
pub const SHARED_EDGE_HOLD: f64 = 1e-2;

/// Under finite kinematics, the facet that holds a slave node at `p` whose closest point
/// `best` lies inside a facet: of the candidates whose interpolation, extended by at most
/// [`SHARED_EDGE_HOLD`] past edges they share with other facets (never past the free
/// boundary), holds the node at the distance of `best` (to the height the extension can add,
/// twice the distance past the edge, and `tol`) and at a gap no smaller than `best`'s (a
/// concave kink), the one of lowest index, as an interior point of the facet extended.
///
/// Why: a slave node on or next to a kink of the master surface is held by the single facet of
/// its closest point, whose normal changes at the edge. Where the kink is concave (a valley
/// under the node, which the discrete solution of a non-matching or quadratic interface makes
/// even on a flat patch) neither facet's row has an equilibrium near the edge: the force
/// `lambda n_A` pushes the node across the edge onto `B`, and `lambda n_B` pushes it back.
/// Newton then alternates between the two facets forever with a fixed residual (found on the
/// finite two-block patch test: Tet4 with the punch's nodes at 0.25 and 0.8 over the base's
/// 0.5 grid, period-2 cycle at a relative residual of 3e-10 to 2e-7; Tet10 with the penalty,
/// whose vertex and mid-edge nodes penetrate differently). Choosing the facet by index inside
/// a band around the edge makes the choice a function of the position that does not change
/// across the edge, so the rows are smooth there and the node finds its equilibrium against
/// the facet extended a short way past the edge; outside the band the closest facet holds it
/// as before. The price: on a kinked surface the held node's gap is that of the extended
/// facet, off the closest-point gap by at most the distance past the edge times the change of
/// the normal (`SHARED_EDGE_HOLD` facet sizes times the kink's angle), and zero on a flat one.
fn held_across_shared_edge(
    master: &Surface3,
    candidates: &[usize],
    p: [f64; 3],
    best: (usize, FacetProjection),
    edge_facets: &HashMap<(usize, usize), usize>,
    tol: f64,
) -> (usize, FacetProjection) {
    let kind = master.kind;
    let corners = FacetShape::<3>::corner_count(kind);
    let span = natural_span(kind);
    let band = SHARED_EDGE_HOLD * span;
    let size = |f: usize| facet_diameter(&master.coords[f][..corners]);
    // the height an extension past the edges can add to the distance
    let height = |f: usize, q: &FacetProjection| 2.0 * q.excess / span * size(f);
    for &f in candidates {
        if f >= best.0 {
            break;
        }
        let facet = &master.facets[f];
        let shared = |k: usize| {
            let (a, b) = (facet[k], facet[(k + 1) % corners]);
            edge_facets[&(a.min(b), a.max(b))] > 1
        };
        let margin = FREE_BOUNDARY_EXTENSION * span;
        let Some(e) = project_onto_extended_facet(kind, &master.coords[f], p, margin) else {
            continue;
        };
        // past shared edges by at most the band; past the free boundary as far as its
        // extension reaches
        let violations = edge_violations(kind, e.natural);
        if (0..corners).any(|k| violations[k] > band && shared(k)) {
            continue;
        }
        // a concave kink only (a valley: the facet extended lies below the surface beside
        // it, so the node is no closer to it than to `best`); at a convex one the edge rows
        // are continuous and the extension would hold the node above the surface
        let gap = |q: &FacetProjection| dot(q.normal, std::array::from_fn(|i| p[i] - q.point[i]));
        if gap(&e) >= gap(&best.1) - tol
            && (e.distance - best.1.distance).abs() <= height(f, &e) + height(best.0, &best.1) + tol
        {
            return (f, e);
        }
    }
    best
}

/// The largest distance between two of `corners`.
fn facet_diameter(corners: &[[f64; 3]]) -> f64 {
    let mut d = 0.0f64;
    for (a, x) in corners.iter().enumerate() {
        for y in &corners[a + 1..] {
            let r: [f64; 3] = std::array::from_fn(|i| x[i] - y[i]);
            d = d.max(dot(r, r));
        }
    }
    d.sqrt()
}

/// Whether the natural point `s` of a facet (of kind `kind`, `free_edge(k)` telling which of
/// its edges lie on the free boundary of the master surface) lies past a free edge and past no
/// other edge by more than [`TIE_EXCESS`] (round-off at a vertex the free edge shares with an
/// edge between two facets): the facet extended holds the node.
fn held_past_free_edges(
    kind: crate::fe::ElementKind,
    s: [f64; 2],
    free_edge: impl Fn(usize) -> bool,
) -> bool {
    violated_edges(kind, s, 0.0).into_iter().any(&free_edge)
        && violated_edges(kind, s, TIE_EXCESS)
            .into_iter()
            .all(free_edge)
}

/// How far beyond the free boundary of the master surface a slave node is still held against
/// the boundary facet's extension under finite kinematics, as a fraction of the facet's natural
/// span (a quarter facet, as the 2D rows' [`super::END_EXTENSION`]).
pub const FREE_BOUNDARY_EXTENSION: f64 = 0.25;

/// The natural span of a facet: 2 for the quadrilaterals (`[-1, 1]`), 1 for the triangles.
fn natural_span(kind: crate::fe::ElementKind) -> f64 {
    match kind {
        crate::fe::ElementKind::Q4 | crate::fe::ElementKind::Q9 => 2.0,
        crate::fe::ElementKind::T3 | crate::fe::ElementKind::T6 => 1.0,
    }
}

/// The unit direction of `d` (of length `length`) times `side` (`-1` for a node behind the
/// facet, whose gap `nu . d` is then `-length`), or `fallback` when it is shorter than `tol`.
fn away(d: [f64; 3], length: f64, fallback: [f64; 3], tol: f64, side: f64) -> [f64; 3] {
    if length > tol {
        d.map(|c| side * c / length)
    } else {
        fallback
    }
}

/// Node-to-node rows of `slave` against `master` in `D` dimensions (module notes): every slave
/// node against the master node at the same place, with the master's nodal normal.
pub fn node_to_node_rows<const D: usize, K>(
    slave: &Surface<D, K>,
    master: &Surface<D, K>,
    settings: &RowSettings,
) -> Result<Vec<Constraint<D>>, String> {
    let tol = 1e-9 * surface_extent(master);
    let master_nodes: Vec<usize> = master.nodes.keys().copied().collect();
    let grid = BucketGrid::new(
        master
            .nodes
            .values()
            .map(|data| [data.position, data.position])
            .collect(),
    );
    let mut used = vec![false; master_nodes.len()];
    let mut rows = Vec::new();
    for (&s, data) in &slave.nodes {
        let p = data.position;
        let Some(k) = grid.query(p, tol).into_iter().next() else {
            return Err(format!(
                "the interface nodes do not match: slave node at {p:?} has no master node there; node-to-node needs matching meshes, use node-to-surface otherwise"
            ));
        };
        used[k] = true;
        let m = master.nodes[&master_nodes[k]];
        let g0 = dot(m.normal, std::array::from_fn(|i| p[i] - m.position[i]));
        rows.push(node_row(
            settings,
            slave,
            s,
            m.normal,
            g0,
            Some((master.body, &[(master_nodes[k], 1.0)])),
            1,
        ));
    }
    if let Some(k) = used.iter().position(|u| !u) {
        return Err(format!(
            "the interface nodes do not match: master node at {:?} has no slave node there; node-to-node needs matching meshes, use node-to-surface otherwise",
            master.nodes[&master_nodes[k]].position
        ));
    }
    checked(rows, settings.search_distance)
}

/// Rows of every node of `slave` against a rigid master in `D` dimensions (module notes).
pub fn rigid_rows<const D: usize, K>(
    slave: &Surface<D, K>,
    rigid: &RigidMaster<D>,
    settings: &RowSettings,
) -> Result<Vec<Constraint<D>>, String> {
    let mut rows = Vec::new();
    for (&s, data) in &slave.nodes {
        let (g0, nu) = rigid_gap(rigid, data.position)?;
        rows.push(node_row(settings, slave, s, nu, g0, None, 1));
    }
    checked(rows, settings.search_distance)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::discretization::facet_projection::project_onto_facet;
    use crate::fe::ElementKind;
    use crate::fe3d::SolidKind;
    use crate::mesh::{block3, Mesh3};

    const NODES_PER_BODY: usize = 1_000_000;

    /// Node positions of body 0 (slave) and body 1 (master).
    type Positions = [Vec<[f64; 3]>; 2];

    fn dof(body: usize, node: usize, component: usize) -> usize {
        (body * NODES_PER_BODY + node) * 3 + component
    }

    /// `(body, node, component)` of a dof of [`dof`].
    fn owner_of(d: usize) -> (usize, usize, usize) {
        let q = d / 3;
        (q / NODES_PER_BODY, q % NODES_PER_BODY, d % 3)
    }

    fn settings(dofs: &dyn DofNumbering) -> RowSettings<'_> {
        RowSettings {
            dofs,
            pair: 0,
            search_distance: None,
            current_finite: false,
        }
    }

    /// A surface of the given facets over a table of node positions.
    fn surface(
        body: usize,
        kind: ElementKind,
        positions: &[[f64; 3]],
        facets: &[Vec<usize>],
    ) -> Surface3 {
        Surface::from_facets(
            body,
            kind,
            facets.to_vec(),
            facets
                .iter()
                .map(|f| f.iter().map(|&n| positions[n]).collect())
                .collect(),
            1.0,
        )
    }

    /// The exact node-to-surface gap of a point `p` against a master surface: the closest
    /// point over all facets; inside a facet the gap along its normal, at an edge or corner the
    /// distance.
    fn exact_surface_gap(
        kind: ElementKind,
        positions: &[[f64; 3]],
        facets: &[Vec<usize>],
        p: [f64; 3],
    ) -> f64 {
        let mut best: Option<FacetProjection> = None;
        for f in facets {
            let coords: Vec<[f64; 3]> = f.iter().map(|&n| positions[n]).collect();
            let q = project_onto_facet(kind, &coords, p);
            if best.is_none_or(|b| {
                q.distance < b.distance - 1e-13
                    || (q.distance <= b.distance + 1e-13
                        && q.feature == FacetFeature::Interior
                        && b.feature != FacetFeature::Interior)
            }) {
                best = Some(q);
            }
        }
        let q = best.unwrap();
        match q.feature {
            FacetFeature::Interior => dot(q.normal, std::array::from_fn(|i| p[i] - q.point[i])),
            _ => q.distance,
        }
    }

    /// Central differences of `gap(positions of body 0, positions of body 1)` in every
    /// coordinate of `nodes` (body, node) against the row's coefficient there (zero where the
    /// row has none); the largest mismatch.
    fn finite_difference_mismatch(
        row: &Constraint<3>,
        positions: [&[[f64; 3]]; 2],
        nodes: &[(usize, usize)],
        gap: &dyn Fn(&Positions) -> f64,
    ) -> f64 {
        let h = 1e-6;
        let mut worst = 0.0f64;
        let base = [positions[0].to_vec(), positions[1].to_vec()];
        assert!(
            (gap(&base) - row.g0).abs() < 1e-12,
            "g0 {} vs gap {}",
            row.g0,
            gap(&base)
        );
        for &(b, n) in nodes {
            for i in 0..3 {
                let (mut plus, mut minus) = (base.clone(), base.clone());
                plus[b][n][i] += h;
                minus[b][n][i] -= h;
                let fd = (gap(&plus) - gap(&minus)) / (2.0 * h);
                let d = dof(b, n, i);
                let c = row
                    .dofs
                    .iter()
                    .position(|&x| x == d)
                    .map_or(0.0, |k| row.coeffs[k]);
                worst = worst.max((fd - c).abs());
            }
        }
        worst
    }

    /// Node-to-surface rows of slave facets over curved (Quad9 dome), ridged (two Quad4) and
    /// peaked (four Tri3 around an apex) masters, in both passes: every row is the
    /// linearization of the exact gap; interior, edge and corner rows all occur.
    #[test]
    fn node_to_surface_rows_are_the_linearization_of_the_exact_gap() {
        // masters: (kind, positions, facets), body 1
        let mut dome = Vec::new();
        for j in 0..5 {
            for i in 0..5 {
                let (x, y) = (i as f64 * 0.5, j as f64 * 0.5);
                dome.push([x, y, 0.3 - 0.1 * ((x - 1.0).powi(2) + (y - 1.0).powi(2))]);
            }
        }
        let at = |i: usize, j: usize| j * 5 + i;
        let mut dome_facets = Vec::new();
        for (i, j) in [(0, 0), (2, 0), (0, 2), (2, 2)] {
            dome_facets.push(vec![
                at(i, j),
                at(i + 2, j),
                at(i + 2, j + 2),
                at(i, j + 2),
                at(i + 1, j),
                at(i + 2, j + 1),
                at(i + 1, j + 2),
                at(i, j + 1),
                at(i + 1, j + 1),
            ]);
        }
        let ridge = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.4],
            [2.0, 0.0, 0.0],
            [0.0, 1.5, 0.0],
            [1.0, 1.5, 0.4],
            [2.0, 1.5, 0.0],
        ];
        let ridge_facets = vec![vec![0, 1, 4, 3], vec![1, 2, 5, 4]];
        let pyramid = vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 2.0, 0.0],
            [0.0, 2.0, 0.0],
            [1.0, 1.0, 0.5],
        ];
        let pyramid_facets = vec![vec![0, 1, 4], vec![1, 2, 4], vec![2, 3, 4], vec![3, 0, 4]];
        // two curved Tri6 facets on a square, their mid-edge nodes lifted
        let curved_tri6 = vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.0, 2.0, 0.0],
            [2.0, 2.0, 0.0],
            [1.0, 0.0, 0.1],
            [1.0, 1.0, 0.2],
            [0.0, 1.0, 0.05],
            [2.0, 1.0, 0.1],
            [1.0, 2.0, 0.05],
        ];
        let curved_tri6_facets = vec![vec![0, 1, 2, 4, 5, 6], vec![1, 3, 2, 7, 8, 5]];
        // slaves (body 0): a Tri3 patch facing down over each master
        let slave_over = |points: [[f64; 3]; 4]| -> (Vec<[f64; 3]>, Vec<Vec<usize>>) {
            (points.to_vec(), vec![vec![0, 2, 1], vec![0, 3, 2]])
        };
        let cases = [
            (
                ElementKind::Q9,
                dome,
                dome_facets,
                slave_over([
                    [0.3, 0.4, 0.35],
                    [1.6, 0.2, 0.1],
                    [1.7, 1.8, 0.2],
                    [0.5, 1.2, 0.25],
                ]),
            ),
            (
                ElementKind::Q4,
                ridge,
                ridge_facets,
                slave_over([
                    [0.4, 0.3, 0.3],
                    [1.0, 0.5, 0.6],
                    [1.6, 1.1, 0.1],
                    [1.0, 1.0, 0.45],
                ]),
            ),
            (
                ElementKind::T3,
                pyramid,
                pyramid_facets,
                slave_over([
                    [1.0, 1.0, 0.8],
                    [1.5, 0.4, 0.3],
                    [1.05, 1.6, 0.42],
                    [0.3, 0.7, 0.15],
                ]),
            ),
            (
                ElementKind::T6,
                curved_tri6,
                curved_tri6_facets,
                slave_over([
                    [0.5, 0.6, 0.4],
                    [1.4, 0.9, 0.5],
                    [1.5, 1.6, 0.3],
                    [0.7, 1.5, 0.25],
                ]),
            ),
        ];
        let mut features = BTreeSet::new();
        let mut checked_rows = 0;
        let mut worst = 0.0f64;
        for (kind, master_positions, master_facets, (slave_positions, slave_facets)) in cases {
            let master = surface(1, kind, &master_positions, &master_facets);
            let slave = surface(0, ElementKind::T3, &slave_positions, &slave_facets);
            let settings = RowSettings {
                search_distance: Some(2.0),
                ..settings(&dof)
            };
            let rows = node_to_surface_rows(&slave, &master, 2, &settings).unwrap();
            for row in &rows {
                let (own, other) = if row.pass == 1 { (0, 1) } else { (1, 0) };
                let (kind_other, facets_other) = if row.pass == 1 {
                    (kind, master_facets.clone())
                } else {
                    (ElementKind::T3, slave_facets.clone())
                };
                let positions = [&slave_positions[..], &master_positions[..]];
                let gap = |x: &Positions| {
                    exact_surface_gap(kind_other, &x[other], &facets_other, x[own][row.slave_node])
                };
                let mut nodes = vec![(own, row.slave_node)];
                nodes.extend((0..positions[other].len()).map(|n| (other, n)));
                let mismatch = finite_difference_mismatch(row, positions, &nodes, &gap);
                worst = worst.max(mismatch);
                assert!(
                    mismatch < 1e-7,
                    "{kind:?} pass {} node {}: gradient off by {mismatch}",
                    row.pass,
                    row.slave_node
                );
                // the row's normal is its gradient at the slave node, of unit length
                assert!((dot(row.normal, row.normal) - 1.0).abs() < 1e-14);
                assert_eq!(owner_of(row.owner).1, row.slave_node);
                let master_nodes: BTreeSet<usize> = row
                    .dofs
                    .iter()
                    .map(|&d| owner_of(d))
                    .filter(|o| o.0 == other)
                    .map(|o| o.1)
                    .collect();
                features.insert(match master_nodes.len() {
                    1 => "corner",
                    2 => "edge",
                    _ => "interior",
                });
                checked_rows += 1;
            }
        }
        println!(
            "{checked_rows} node-to-surface rows ({features:?}): worst gradient error {worst:.2e}"
        );
        assert_eq!(
            features.len(),
            3,
            "interior, edge and corner rows were all checked"
        );
        assert!(checked_rows >= 16, "{checked_rows} rows checked");
    }

    #[test]
    fn node_to_node_and_rigid_rows_are_the_linearization_of_the_exact_gap() {
        // a curved Quad4 master (nodes on a cylinder of radius 2 about the y axis) and slave
        // nodes on the master nodes' normals at distances 0 and 0.1
        let mut master_positions = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                let a = (i as f64 - 1.0) * 0.3;
                master_positions.push([2.0 * a.sin(), j as f64 * 0.5, 2.0 * a.cos() - 2.0]);
            }
        }
        let facets: Vec<Vec<usize>> = [(0, 0), (1, 0), (0, 1), (1, 1)]
            .iter()
            .map(|&(i, j)| {
                let at = |i: usize, j: usize| j * 3 + i;
                vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]
            })
            .collect();
        let master = surface(1, ElementKind::Q4, &master_positions, &facets);
        for lift in [0.0, 0.1] {
            let slave_positions: Vec<[f64; 3]> = master_positions
                .iter()
                .enumerate()
                .map(|(k, p)| {
                    let n = master.nodes[&k].normal;
                    std::array::from_fn(|i| p[i] + lift * n[i])
                })
                .collect();
            // the slave surface faces the other way: its facets reversed
            let slave_facets: Vec<Vec<usize>> = facets
                .iter()
                .map(|f| vec![f[0], f[3], f[2], f[1]])
                .collect();
            let slave = surface(0, ElementKind::Q4, &slave_positions, &slave_facets);
            // node-to-node needs matched nodes (lift 0); the rigid rows take both
            let matched = if lift == 0.0 {
                node_to_node_rows(&slave, &master, &settings(&dof)).unwrap()
            } else {
                Vec::new()
            };
            assert_eq!(matched.len(), if lift == 0.0 { 9 } else { 0 });
            for row in &matched {
                assert!((row.g0 - lift).abs() < 1e-14);
                let gap = |x: &Positions| {
                    let moved = surface(1, ElementKind::Q4, &x[1], &facets);
                    let n = moved.nodes[&row.slave_node].normal;
                    dot(
                        n,
                        std::array::from_fn(|i| x[0][row.slave_node][i] - x[1][row.slave_node][i]),
                    )
                };
                let mut nodes = vec![(0, row.slave_node)];
                nodes.extend((0..9).map(|n| (1, n)));
                let mismatch = finite_difference_mismatch(
                    row,
                    [&slave_positions[..], &master_positions[..]],
                    &nodes,
                    &gap,
                );
                assert!(mismatch < 1e-8, "node-to-node gradient off by {mismatch}");
            }
            for rigid in [
                RigidMaster::Plane {
                    point: [0.1, 0.2, -1.0],
                    normal: [0.3, -0.2, 2.0],
                },
                RigidMaster::Sphere {
                    centre: [0.2, 0.4, -3.0],
                    radius: 1.5,
                },
            ] {
                let rows = rigid_rows(&slave, &rigid, &settings(&dof)).unwrap();
                assert_eq!(rows.len(), 9);
                for row in &rows {
                    let gap = |x: &Positions| {
                        let p = x[0][row.slave_node];
                        match rigid {
                            RigidMaster::Plane { point, normal } => {
                                let l = dot(normal, normal).sqrt();
                                (0..3).map(|i| normal[i] / l * (p[i] - point[i])).sum()
                            }
                            RigidMaster::Sphere { centre, radius } => {
                                (0..3)
                                    .map(|i| (p[i] - centre[i]).powi(2))
                                    .sum::<f64>()
                                    .sqrt()
                                    - radius
                            }
                        }
                    };
                    let mismatch = finite_difference_mismatch(
                        row,
                        [&slave_positions[..], &master_positions[..]],
                        &[(0, row.slave_node)],
                        &gap,
                    );
                    assert!(mismatch < 1e-8, "{rigid:?}: gradient off by {mismatch}");
                    assert_eq!(row.dofs.len(), 3, "a rigid row has the slave dofs only");
                }
            }
        }
    }

    /// A slave node next to the edge shared by two flat Tri3 master facets (the unit square
    /// cut along its diagonal, the upper facet first among the candidates), pressed in by
    /// 1e-3: a node inside the lower facet by 1e-11 (natural) is held by the lower facet,
    /// whose gap is the one at its position, not by the upper one it lies 1e-11 outside of
    /// (clamped onto its edge); a node inside the lower facet by 1e-15 (round-off of its
    /// natural coordinates, below [`TIE_EXCESS`]) keeps the first candidate either way.
    #[test]
    fn a_node_beside_a_shared_edge_is_held_by_the_facet_it_is_inside() {
        let positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        // upper facet (0, 2, 3) first, lower facet (0, 1, 2) second
        let facets = vec![vec![0, 2, 3], vec![0, 1, 2]];
        let master = surface(1, ElementKind::T3, &positions, &facets);
        let held = |offset: f64| {
            // below the diagonal x = y by `offset` (the lower facet's side)
            let p = [0.4 + offset, 0.4, -1e-3];
            let tol = 1e-12 * surface_extent(&master);
            let (f, q) = closest_facet(&master, &[0, 1], p, tol).unwrap();
            (f, q.feature, q.excess)
        };
        let (f, feature, excess) = held(1e-11);
        assert_eq!((f, feature), (1, FacetFeature::Interior), "{excess:e}");
        assert_eq!(excess, 0.0);
        // and the other way round: above the diagonal, the upper facet
        let (f, _, excess) = held(-1e-11);
        assert_eq!(f, 0, "{excess:e}");
        // within round-off of the edge: the first candidate, clamped by less than TIE_EXCESS
        let (f, feature, excess) = held(1e-15);
        assert_eq!((f, feature), (0, FacetFeature::Interior));
        assert!(excess <= TIE_EXCESS, "{excess:e}");
    }

    /// Two Tri3 master facets meeting at the diagonal `x = y` of the unit square in a shallow
    /// valley (the far corners raised by 1e-3), a slave node on the surface beside the
    /// diagonal at `offset` (natural units of the facets) on either side. Under finite
    /// kinematics a node within [`SHARED_EDGE_HOLD`] of the edge is held by the facet of lower
    /// index on both sides (its row weight on that facet's far corner, `N = -offset` past the
    /// edge, goes through zero continuously) and its gap is continuous; farther out, and under
    /// small strain at any offset, the facet it is over holds it.
    #[test]
    fn a_node_beside_a_valley_keeps_one_facet_across_the_shared_edge() {
        let positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 1e-3],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 1e-3],
        ];
        // facet 0 over x > y, facet 1 over x < y
        let master = surface(
            1,
            ElementKind::T3,
            &positions,
            &[vec![0, 1, 2], vec![0, 2, 3]],
        );
        // the row of a slave node at (0.4 + offset, 0.4 - offset), on the surface: its gap and
        // its coefficients on u_z of master nodes 1 and 3 (the far corners)
        let row_at = |offset: f64, current_finite: bool| {
            let height = 2e-3 * offset.abs();
            let slave_positions = [
                [0.4 + offset, 0.4 - offset, height],
                [0.9, 0.1, 0.5],
                [0.1, 0.9, 0.5],
            ];
            let slave = surface(0, ElementKind::T3, &slave_positions, &[vec![0, 1, 2]]);
            let settings = RowSettings {
                current_finite,
                ..settings(&dof)
            };
            let rows = node_to_surface_rows(&slave, &master, 1, &settings).unwrap();
            let row = rows.iter().find(|r| r.slave_node == 0).unwrap();
            let on = |node: usize| {
                let d = dof(1, node, 2);
                row.dofs.iter().position(|&x| x == d).map(|k| row.coeffs[k])
            };
            (row.g0, on(1), on(3))
        };
        for offset in [1e-6, -1e-6, 1e-4, -1e-4] {
            let (g, w1, w3) = row_at(offset, true);
            // facet 0 holds it on both sides: weight on node 1, none on node 3
            assert!(w1.is_some() && w3.is_none(), "{offset}: {w1:?} {w3:?}");
            // zero over facet 0; over facet 1 the height of the surface above facet 0's
            // extension, the distance past the edge times the change of slope (4e-3 |offset|)
            let expected = if offset > 0.0 {
                0.0
            } else {
                4e-3 * offset.abs()
            };
            assert!(
                (g - expected).abs() < 1e-5 * offset.abs(),
                "{offset}: gap {g:e}, not {expected:e}"
            );
        }
        // facet 0 extended past the edge: the far corner's weight -N_1 nu_z follows the node
        // through zero (N_1 = x - y = 2 offset on facet 0's plane)
        let (_, w_plus, _) = row_at(1e-4, true);
        let (_, w_minus, _) = row_at(-1e-4, true);
        let (w_plus, w_minus) = (w_plus.unwrap(), w_minus.unwrap());
        assert!(
            (w_plus + w_minus).abs() < 1e-9 && w_plus < 0.0,
            "{w_plus} {w_minus}"
        );
        // beyond the band: the facet the node is over
        let (_, w1, w3) = row_at(-0.05, true);
        assert!(w1.is_none() && w3.is_some(), "{w1:?} {w3:?}");
        // small strain: the facet the node is over, however close to the edge
        let (_, w1, w3) = row_at(-1e-6, false);
        assert!(w1.is_none() && w3.is_some(), "{w1:?} {w3:?}");
    }

    /// The row of slave node 0 of the Tri3 triangle `slave_positions` against the Tri3 master
    /// `facets` on `positions` (search distance 2), under small strain and under finite
    /// kinematics.
    fn first_slave_rows(
        positions: &[[f64; 3]],
        facets: &[Vec<usize>],
        slave_positions: [[f64; 3]; 3],
    ) -> Vec<(bool, Constraint<3>)> {
        let master = surface(1, ElementKind::T3, positions, facets);
        let slave = surface(0, ElementKind::T3, &slave_positions, &[vec![0, 1, 2]]);
        [false, true]
            .into_iter()
            .map(|current_finite| {
                let settings = RowSettings {
                    current_finite,
                    search_distance: Some(2.0),
                    ..settings(&dof)
                };
                let rows = node_to_surface_rows(&slave, &master, 1, &settings).unwrap();
                let row = rows.into_iter().find(|r| r.slave_node == 0).unwrap();
                (current_finite, row)
            })
            .collect()
    }

    /// A slave node inside the master body under a steep valley (two Tri3 facets meeting at
    /// the diagonal `x = y` with their far corners raised by 0.5), 0.2 below the edge: the
    /// normals of both facets through it miss their facets, its closest point is on the
    /// shared edge, and its row is a penetration: `g0` is minus its distance to the edge and
    /// the row's slave direction points from the node up to the edge (a positive gap, before,
    /// opened the row of a node pressed in by a penalty and sent Newton off).
    #[test]
    fn a_node_under_a_concave_edge_is_a_penetration() {
        let positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.5],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.5],
        ];
        for (current_finite, row) in first_slave_rows(
            &positions,
            &[vec![0, 1, 2], vec![0, 2, 3]],
            [[0.5, 0.5, -0.2], [0.9, 0.1, 0.8], [0.1, 0.9, 0.8]],
        ) {
            assert!(
                (row.g0 + 0.2).abs() < 1e-12,
                "{current_finite}: g0 {}",
                row.g0
            );
            assert!(
                (row.normal[2] - 1.0).abs() < 1e-12,
                "{current_finite}: {:?}",
                row.normal
            );
        }
    }

    /// A slave node outside a sharp convex edge: two Tri3 master facets meeting along the y
    /// axis, one in the plane `z = 0` (normal `+z`), the other turned down by 135 degrees
    /// (normal `(1, 0, -1) / sqrt 2`, a knife edge pointing along `+x`); a node at
    /// `(0.6, 0.5, -0.2)` in the wedge outside the edge, whose closest point is the edge point
    /// `(0, 0.5, 0)`, lies behind the first facet's plane but outside the body: its gap is plus
    /// its distance (the side is the surface's averaged normal's, not one facet's).
    #[test]
    fn a_node_outside_a_sharp_convex_edge_is_a_separation() {
        let positions = vec![
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 0.5, 0.0],
            [-0.7, 0.5, -0.7],
        ];
        let distance = (0.6f64 * 0.6 + 0.2 * 0.2).sqrt();
        for (current_finite, row) in first_slave_rows(
            &positions,
            &[vec![0, 1, 2], vec![1, 0, 3]],
            [[0.6, 0.5, -0.2], [1.5, 0.1, 0.8], [1.5, 0.9, 0.8]],
        ) {
            assert!(
                (row.g0 - distance).abs() < 1e-12,
                "{current_finite}: g0 {}, not {distance}",
                row.g0
            );
        }
    }

    /// A slave node just past the free edge `y = 0` of two flat Quad4 master facets (by
    /// `offset`, natural `2 offset`), pressed in by 1e-3, under finite kinematics: held by the
    /// facet extended at its natural point `t = -1 - 2 offset`, whatever the offset, so the
    /// far nodes' weights `(1 - s)(1 + t) / 4 = -offset / 2` follow the node (below
    /// [`super::super::facet_projection::INSIDE`], before, the point was clamped onto the
    /// edge and they were zero); under small strain a node within INSIDE stays clamped.
    #[test]
    fn a_node_just_past_the_free_boundary_is_held_by_the_facet_extended() {
        let positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
        ];
        let master = surface(
            1,
            ElementKind::Q4,
            &positions,
            &[vec![0, 1, 2, 3], vec![1, 4, 5, 2]],
        );
        // the weight of master node 3 (across the facet from the free edge) in the row of
        // slave node 0 at (0.5, -offset, -1e-3)
        let far_weight = |offset: f64, current_finite: bool| {
            let slave_positions = [[0.5, -offset, -1e-3], [0.9, 0.6, -1e-3], [0.2, 0.7, -1e-3]];
            let slave = surface(0, ElementKind::T3, &slave_positions, &[vec![0, 1, 2]]);
            let settings = RowSettings {
                current_finite,
                ..settings(&dof)
            };
            let rows = node_to_surface_rows(&slave, &master, 1, &settings).unwrap();
            let row = rows.iter().find(|r| r.slave_node == 0).unwrap();
            let z3 = dof(1, 3, 2);
            // the row's coefficient on u_z of node 3 is -N_3 nu_z
            row.dofs
                .iter()
                .position(|&d| d == z3)
                .map_or(0.0, |k| -row.coeffs[k] / row.normal[2])
        };
        for offset in [1e-10, 1e-8, 1e-3] {
            let weight = far_weight(offset, true);
            assert!(
                (weight + 0.5 * offset).abs() < 1e-6 * offset,
                "{offset:e}: {weight:e}"
            );
        }
        // small strain: clamped onto the edge within INSIDE
        assert_eq!(far_weight(1e-10, false), 0.0);
    }

    #[test]
    fn bad_input_gets_a_reason() {
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let slave = surface(0, ElementKind::T3, &positions, &[vec![0, 1, 2]]);
        let err = rigid_rows(
            &slave,
            &RigidMaster::Plane {
                point: [0.0; 3],
                normal: [0.0; 3],
            },
            &settings(&dof),
        )
        .unwrap_err();
        assert!(err.contains("normal") && err.contains("non-zero"), "{err}");
        let err = rigid_rows(
            &slave,
            &RigidMaster::Sphere {
                centre: [0.0; 3],
                radius: 1.0,
            },
            &settings(&dof),
        )
        .unwrap_err();
        assert!(err.contains("centre of the rigid sphere"), "{err}");
        let far = surface(
            1,
            ElementKind::T3,
            &positions.map(|p| [p[0] + 10.0, p[1], p[2]]),
            &[vec![0, 1, 2]],
        );
        let err = node_to_surface_rows(&slave, &far, 1, &settings(&dof)).unwrap_err();
        assert!(err.contains("search distance"), "{err}");
        let err = node_to_surface_rows(&slave, &far, 3, &settings(&dof)).unwrap_err();
        assert!(err.contains("1 or 2 passes"), "{err}");
        let err = node_to_node_rows(&slave, &far, &settings(&dof)).unwrap_err();
        assert!(err.contains("do not match"), "{err}");
    }

    /// The foundation `[-0.5, 2.5]^2 x [-1, 0]` (6 x 6 cells of 0.5, a top vertex outside the
    /// punch moved within the plane) and the punch `[0.5, 1.5]^2 x [0, 0.5]` with `cells`
    /// cells a side, turned by `angle` about the vertical through (1, 1).
    fn punch_on_foundation(kind: SolidKind, cells: usize, angle: f64) -> (Mesh3, Mesh3) {
        let breaks = |a: f64, b: f64, n: usize| -> Vec<f64> {
            (0..=n).map(|i| a + (b - a) * i as f64 / n as f64).collect()
        };
        let foundation = block3(
            kind,
            &breaks(-0.5, 2.5, 6),
            &breaks(-0.5, 2.5, 6),
            &breaks(-1.0, 0.0, 1),
            &[([0.0, 0.0, 0.0], [0.1, -0.05, 0.0])],
        )
        .unwrap();
        let mut punch = block3(
            kind,
            &breaks(0.5, 1.5, cells),
            &breaks(0.5, 1.5, cells),
            &breaks(0.0, 0.5, 1),
            &[],
        )
        .unwrap();
        let (c, s) = (angle.cos(), angle.sin());
        for p in &mut punch.nodes {
            let (x, y) = (p[0] - 1.0, p[1] - 1.0);
            *p = [1.0 + c * x - s * y, 1.0 + s * x + c * y, p[2]];
        }
        (foundation, punch)
    }

    /// Every row of a flat punch on a flat foundation: no initial gap, the slave coefficients
    /// the master normal `n`, the master coefficients a partition of unity (`sum = -n`).
    fn assert_flat_rows(rows: &[Constraint<3>], label: &str) {
        for row in rows {
            let n = if row.pass == 1 {
                [0.0, 0.0, 1.0]
            } else {
                [0.0, 0.0, -1.0]
            };
            let slave_body = row.slave_body;
            let mut master_sum = [0.0; 3];
            let mut slave_sum = [0.0; 3];
            for (&d, &c) in row.dofs.iter().zip(&row.coeffs) {
                let (b, _, i) = owner_of(d);
                if b == slave_body {
                    slave_sum[i] += c;
                } else {
                    master_sum[i] += c;
                }
            }
            for i in 0..3 {
                assert!(row.g0.abs() < 1e-14, "{label}: g0 = {}", row.g0);
                assert!(
                    (row.normal[i] - n[i]).abs() < 1e-14,
                    "{label}: normal {:?}",
                    row.normal
                );
                assert!(
                    (slave_sum[i] - n[i]).abs() < 1e-14,
                    "{label}: slave {slave_sum:?}"
                );
                assert!(
                    (master_sum[i] + n[i]).abs() < 1e-13,
                    "{label}: master coefficients sum to {master_sum:?}"
                );
            }
        }
    }

    #[test]
    fn a_flat_punch_on_a_flat_foundation_has_no_gap_and_a_partition_of_unity() {
        for kind in SolidKind::ALL {
            for (cells, angle, layout) in [
                (2, 0.0, "matching"),
                (4, 0.0, "nested"),
                (3, 0.5, "rotated"),
            ] {
                let (foundation, punch) = punch_on_foundation(kind, cells, angle);
                let master =
                    Surface3::from_solid_mesh(1, &foundation, &foundation.facet_sets["top"]);
                let slave = Surface3::from_solid_mesh(0, &punch, &punch.facet_sets["bottom"]);
                let label = format!("{kind:?} {layout}");
                for passes in [1, 2] {
                    let rows = node_to_surface_rows(&slave, &master, passes, &settings(&dof))
                        .unwrap_or_else(|e| panic!("{label}: {e}"));
                    assert_flat_rows(&rows, &label);
                    // every punch node has a first-pass row; the punch's area is carried
                    let first: Vec<_> = rows.iter().filter(|r| r.pass == 1).collect();
                    assert_eq!(first.len(), slave.nodes.len(), "{label}");
                    let area: f64 = first.iter().map(|r| r.area).sum();
                    assert!((area - 1.0).abs() < 1e-13, "{label}: area {area}");
                    if passes == 2 {
                        // foundation nodes under the punch (its boundary included) only
                        let under = rows.iter().filter(|r| r.pass == 2).count();
                        assert!(under > 0, "{label}: no second-pass row");
                        for r in rows.iter().filter(|r| r.pass == 2) {
                            let (x, y) = (r.point[0] - 1.0, r.point[1] - 1.0);
                            let (u, v) = (
                                angle.cos() * x + angle.sin() * y,
                                -angle.sin() * x + angle.cos() * y,
                            );
                            assert!(u.abs() <= 0.5 + 1e-12 && v.abs() <= 0.5 + 1e-12, "{label}");
                        }
                    }
                }
                if layout == "matching" {
                    // node-to-node: a punch as wide as the foundation, on the same grid
                    let b = [0.0, 2.0 / 3.0, 4.0 / 3.0, 2.0];
                    let wide = block3(kind, &b, &b, &[0.0, 0.5], &[]).unwrap();
                    let base = block3(kind, &b, &b, &[-1.0, -0.5, 0.0], &[]).unwrap();
                    let slave = Surface3::from_solid_mesh(0, &wide, &wide.facet_sets["bottom"]);
                    let master = Surface3::from_solid_mesh(1, &base, &base.facet_sets["top"]);
                    let rows = node_to_node_rows(&slave, &master, &settings(&dof))
                        .unwrap_or_else(|e| panic!("{label} node-to-node: {e}"));
                    assert_eq!(rows.len(), master.nodes.len());
                    assert_flat_rows(&rows, &format!("{label} node-to-node"));
                }
            }
        }
    }
}
