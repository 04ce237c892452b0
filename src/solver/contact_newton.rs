//! Contact as a [`System`] for the Newton core ([`super::newton`]): `solver.scheme:
//! "newton"`, for penalty-type rows (penalty, perturbed Lagrangian with its diagonal
//! perturbation, augmented Lagrangian, perturbed tangent) and Lagrange-multiplier rows, mixed
//! freely pair by pair, frictionless or with Coulomb friction; and constraint-elimination rows
//! on their own (frictionless): the Lagrange rows' residual and sets, with every Newton step
//! solved by eliminating each active row's owned dof instead of factoring the saddle point
//! ([`super::newton::Tangent::elimination`]).
//!
//! The system is generic over the dimension (`ContactSystem<D, K>`, the cells `K` supplying
//! their rows through [`Discretize`]): in 3D it serves finite kinematics against rigid planes
//! and spheres (the sphere's `(I - n n^T) / |x - c|` through [`Discretize::slave_curvature`])
//! and node-to-surface between bodies (each row's facet gap second derivative, carried as its
//! `Constraint::hessian`, [`crate::contact::discretization::facet_gap_hessian`]).
//!
//! Unknowns: the free displacements `x` (prescribed values folded in, [`LinearSystem`]). Each
//! contact row `i` (a [`Constraint`]: gap `g_i(u)`, gradient `b_i`, tributary area `A_i`) with
//! penalty weight `w_i = kappa A_i` and augmentation `lambda_bar_i` (zero for penalty and the
//! perturbed Lagrangian, the Uzawa multiplier for the augmented Lagrangian) carries the force
//! `lambda_i = max(0, lambda_bar_i - w_i g_i)` (ties: no max). The residual and tangent are
//!
//! `R(x) = K x - f - sum_i lambda_i b_i`,
//! `K_T(x) = K + sum_{i active} (w_i b_i b_i^T - lambda_i H_i)`,
//!
//! with `H_i` the second derivative of the gap where the row provides it (rigid circles in the
//! current geometry, [`gap_second_derivative`]). In the current geometry the rows are searched
//! again at every iterate (`x = X + u`), so the geometry updates and the active-set iterations of
//! the active-set scheme are one Newton loop here. Under finite kinematics node-to-surface rows
//! between deformable bodies (master normals) carry the second derivative of their gap over
//! the slave node and the master facet's nodes
//! ([`crate::contact::discretization::node_to_segment`]: the `delta xi` and normal-rotation
//! terms), and the tangent gains `-force H` (`force = lambda - rho g` for a multiplier row, the
//! derivative of its force term). Mortar rows between deformable bodies carry theirs computed
//! with the row ([`crate::contact::GapHessian`], consumed as a `RowCurvature`: the segments, projections
//! and nodal normal varied). Small-strain rows whose gradient lacks its own variation
//! (node-to-surface and mortar against deformable masters in the current geometry) give a
//! tangent that is not exact, and Newton converges linearly on them; the history shows it.
//!
//! The augmented Lagrangian updates `lambda_bar_i <- max(0, lambda_bar_i - w_i g_i)` after every
//! iteration or, in an outer loop, after Newton has converged ([`MultiplierUpdate`]), until
//! every update is negligible (`|w_i g_i| <= 1e-12` of the largest force, or the gap is at the
//! round-off floor `1e-15` of the model size), the stopping rule of the active-set scheme.
//! An open point's multiplier thereby returns to zero; a point that closed in the iteration
//! is updated only after a Newton step that held it (its gap is where the unconstrained step
//! left it, and `w g` there overshoots when `w` exceeds the stiffness the point sees: a block
//! dropped on a rigid line cycled open/closed at its released edge).
//!
//! **The perturbed tangent** (Lim & Taylor 2001; Taylor 2004, "1985: Solution Methods") keeps
//! the Lagrange residual (`R_u = K x - f - lambda b`, `g = 0`) and linearizes it with the
//! perturbed Lagrangian's tangent, the diagonal `-1/w` in the multiplier's equation:
//! `b . dx + d lambda / w = -g_k`. Eliminating `d lambda = -w (g_k + b . dx)` leaves
//! `(K + w b b^T) dx = -(K x_k - f - (lambda_k - w g_k) b)`, the Newton step of the law
//! `lambda = lambda_k - w g(x)` from `x_k`, followed by `lambda_{k+1} = lambda_k - w (g_k + b .
//! dx)`, which is `lambda_k - w g(x_{k+1})` for our rows (their gap is linear in `u` about the
//! point they were built at). That is the augmented Lagrangian with its Uzawa update after
//! every iteration, so the perturbed tangent's rows are run as such rows, with the same
//! stopping rule (the update `w g` negligible: `g = 0`, the Lagrange answer, for any `w`). In
//! the current geometry the rows are searched again at `x_{k+1}` before the update, which then
//! takes the gap there rather than its linearization from `x_k` (a difference of second order
//! in the step, zero at convergence). With Coulomb friction the tangential multiplier follows
//! the same pattern: stick linearizes `g_t - g_t^n = 0` with `-1/w_t`, slip keeps `lambda_t = s
//! mu lambda_n` exactly, which is the augmented return map with its Uzawa update (including its
//! rule of updating a frictional point only once the sets have settled).
//!
//! **Lagrange multipliers** are unknowns of their own, scaled to the stiffness scale `rho`
//! (the largest diagonal entry of `K`): `lambda_j = rho mu_j`, one per row with free
//! equations, numbered after the displacements. The semi-smooth Newton method (primal-dual
//! active set, Hintermüller, Ito & Kunisch 2003; Hüeber & Wohlmuth 2005) decides the status
//! of each point from its last one, as the active-set scheme does: an active point stays
//! active while its force is compressive (above `-1e-10` of the largest force), an inactive
//! one becomes active when it penetrates (ties always active). (The complementarity function
//! `lambda_j - c g_j > 0` with one constant `c` would let the gap a step leaves in the current
//! geometry, of the order of the geometry's change, release every point at once.) It solves
//!
//! `R_u = K x - f - sum_pen lambda_i b_i - rho sum_j mu_j b_j + rho sum_{j active} g_j b_j`,
//! `R_mu_j = -rho g_j(x)` (active), `R_mu_j = -rho mu_j` (inactive),
//!
//! whose tangent is the symmetric saddle-point matrix
//! `[[K_pen + rho B_A^T B_A, -rho B^T], [-rho B_A, -rho I_I]]`, factored by `L D L^T` with
//! negative pivots on the multipliers. The term `rho g_j b_j` vanishes at the solution; it makes
//! the displacement block definite for bodies held only by contact (the augmentation of the
//! active-set scheme). Dependent active rows (a two-pass discretization) make the matrix
//! singular: the step ends `Singular` with the reason, where the active-set scheme picks the
//! minimum-norm multipliers. Under finite kinematics the displacement block also carries
//! `-force H` of the rows' gaps, which makes it indefinite where the forces are large of either
//! sign (a slave node leaving the master's free end, issue 12): pivots of the wrong sign are
//! then not a dependence of rows, and such a tangent is factored by LU
//! ([`Tangent::indefinite_block`]).
//!
//! **Coulomb friction** (pairs with `interaction: {"coulomb": ..}`) with the penalty or the
//! perturbed Lagrangian as normal law:
//! every row carries its tangential slip `g_t` with gradient `b_t`, and the return map of
//! [`crate::contact::friction`] gives the tangential force `lambda_t` from the plastic slip
//! committed at the end of the last load step (`committed`, carried from step to step by
//! [`crate::solver::active_set::solve`]). The residual gains `- lambda_t b_t`, the tangent
//! `w_t b_t b_t^T` in stick and `s mu w b_t b_n^T` in slip (unsymmetric: solved by LU); with
//! `solver.friction_tangent: "symmetrized"` the slip coupling is dropped (a symmetric tangent
//! that is not the derivative: Newton converges linearly in slip; the coupling's symmetric part
//! instead makes the matrix indefinite, and the iteration diverged on the patch test). A change of a point's
//! frictional status (open, stick, slip) counts as a status change of the iteration.
//!
//! **In 3D** (the system is generic over the dimension `D`, [`NewtonDimension`]; small strain,
//! the reference geometry) a point has two tangents `t_1, t_2` and the return map works on the
//! disc: `lambda_t = sum_a lambda_t,a b_t,a` on the residual, and the tangential block
//! `-sum_ab (d lambda_t,a / d g_t,b) b_t,a b_t,b^T` is `w_t` times the frame's identity in stick
//! and, in slip, `w_t mu lambda_n (I - s s^T) / |trial|` (the turn of the slip direction,
//! symmetric), besides the coupling `mu s_a w b_t,a b_n^T`. A slip counts as a change of
//! status when its direction turns by more than a right angle. The secant remedy of a cycle
//! applies to one tangent only (on a disc the slip tangent keeps the stiffness of the
//! direction's turn).
//!
//! **Coulomb friction with Lagrange multipliers** (Lagrange rows of a Coulomb pair): each row
//! with a normal multiplier gains a tangential one per tangent (one in 2D, two in 3D: see "On
//! the disc" below), `lambda_t = rho mu_t`, numbered after the normal ones, and the
//! semi-smooth Newton method of Alart & Curnier (1991) in the active-set form of Hüeber,
//! Stadler & Wohlmuth (2008) takes each point's set from the last iterate
//! ([`crate::contact::friction::multiplier_status`], `c = rho`, the slip increment `dg_t = g_t -
//! g_t^n` from the tangential position committed at the end of the last load step):
//!
//! `R_u -= rho mu_t b_t` (closed points), and
//! `R_t = -rho mu_t` (open), `R_t = -rho dg_t` with `R_u += rho dg_t b_t` (stick, the
//! augmentation that vanishes at the solution and holds a body only friction holds),
//! `R_t = -rho (mu_t - s mu mu_n)` (slip).
//!
//! **On the disc** (3D) a row has two tangential multipliers `mu_t,1, mu_t,2` (unknowns `j, j +
//! 1`), one per tangent `t_a` of its frame, and the sets of
//! [`crate::contact::friction::multiplier_status`] on the vectors: stick `R_t,a = -rho dg_t,a`
//! with `R_u += rho sum_a dg_t,a b_t,a`; slip `R_t = -rho (mu_t - mu mu_n s)` with `s = tau /
//! |tau|`, `tau = rho mu_t - c dg_t`, whose tangent carries the turn of the direction, `T = mu
//! lambda_n (I - s s^T) / |tau|`: `dR_t / d mu_t = -rho (I - T)`, `dR_t / du = -c T B_t` (`B_t`
//! the rows `b_t,a`), `dR_t / d mu_n = rho mu s`. With one tangent `T = 0` and these are the
//! rows above to the last bit. A tangent whose slip the supports prescribe (no free equation in
//! its gradient, e.g. `u_y = 0` everywhere in a plane-strain slab) has nothing to hold in stick:
//! its multiplier is driven to zero there as an open one's (`R_t,a = -rho mu_t,a`), and the
//! supports carry its force.
//!
//! The stick rows keep the saddle-point matrix symmetric; a slip row's equation couples `mu_t`
//! to `mu_n` alone, not to the displacements its column acts on: the tangent is unsymmetric and
//! factored by LU, also with `friction_tangent: "symmetrized"` (this row is the set's equation,
//! not a linearization to drop). The multipliers of a point closed at the end of the last load
//! step start the next one from its forces, and its stick position `g_t^n` is where it ended
//! that step: its first trial force is the committed force (on the cone to round-off if it
//! slipped, where it sticks). A point new to the step starts from zero multipliers and sticks in
//! its first iteration.
//!
//! A body held by nothing but contact rows that are open at the start has a singular tangent:
//! in the first evaluation the rows that would hold it are closed, nearest first
//! (`RigidModes::close_free_bodies`), as in the active-set scheme; their forces may then be
//! tensile, which pulls the body onto the surface, and the next evaluation decides their status
//! from the gaps.

use super::finite_assembly::tangent_and_residual;
use super::linear::{assemble, finish, max_abs, LinearSystem, Solution, Timings, NO_EQUATION};
use super::newton::{self, Evaluation, System, Tangent};
use super::sparse::{GeneralPattern, PatternBuilder, SymmetricPattern};
use crate::contact::discretization::nodal_normal::RowCurvature;
use crate::contact::discretization::OUT_OF_REACH;
use crate::contact::discretization::{row_curvature, Discretize};
use crate::contact::enforcement::{method, Method};
use crate::contact::friction::{
    augmented_return_map, length, multiplier_status, return_map, Committed, FrictionPoint,
    MultiplierSet, ReturnMap, Status, Tangential, MAX_TANGENTS,
};
use crate::contact::rows::{reference_areas, rows_at, ReferenceAreas};
use crate::contact::state::{ContactState, Departure, Termination};
use crate::contact::Constraint;
use crate::contact::{row_key, RowKey};
use crate::error::Result;
use crate::io::scene::{
    ContactGeometry, FrictionTangent, Interaction, Kinematics, MultiplierUpdate,
};
use crate::model::rigid::RigidModes;
use crate::model::Model;
use crate::solver::constraints::AffineConstraints;
use std::collections::{HashMap, HashSet};
use std::time::Instant;

/// Residual tolerance of the Newton solve, relative to the largest applied or contact force.
pub const RESIDUAL_TOLERANCE: f64 = 1e-10;

/// The same under finite kinematics: the consistent tangent converges quadratically, so the
/// last step from `1e-10` costs one solve and brings the answer to round-off (the finite-strain
/// patch test asks for 1e-10 in the stress, which a residual of `1e-10` does not give).
pub const FINITE_RESIDUAL_TOLERANCE: f64 = 1e-12;

/// How a row is enforced in the Newton scheme.
#[derive(Copy, Clone, Debug)]
enum RowLaw {
    /// `lambda = max(0, lambda_bar - w g)`, with Uzawa updates of `lambda_bar` if any.
    Penalty {
        w: f64,
        update: Option<MultiplierUpdate>,
    },
    /// A Lagrange multiplier unknown.
    Multiplier,
}

/// What the Newton contact scheme asks of the model's dimension beyond its discretization
/// ([`Discretize`]): the solids' tangent and residual under finite kinematics.
pub trait NewtonDimension<const D: usize>: Discretize<D> {
    /// The tangent `K_T(u)` on `pattern` and the residual `f_int(u) - f_ext` at the free
    /// equations of `constraints` (finite kinematics), or why not (an inverted element, or
    /// finite strain not built in this dimension).
    fn finite_tangent_and_residual(
        model: &Model<D, Self>,
        constraints: &AffineConstraints,
        pattern: &SymmetricPattern,
        u: &[f64],
    ) -> std::result::Result<(Vec<f64>, Vec<f64>), String>;
}

impl NewtonDimension<2> for crate::fe::ElementKind {
    fn finite_tangent_and_residual(
        model: &Model,
        constraints: &AffineConstraints,
        pattern: &SymmetricPattern,
        u: &[f64],
    ) -> std::result::Result<(Vec<f64>, Vec<f64>), String> {
        tangent_and_residual(model, constraints, pattern, u).map_err(|e| e.to_string())
    }
}

impl NewtonDimension<3> for crate::fe3d::SolidKind {
    /// The hyperelastic kernels of [`crate::solid_finite`] through the dimension-generic
    /// finite assembly.
    fn finite_tangent_and_residual(
        model: &crate::model::Model3,
        constraints: &AffineConstraints,
        pattern: &SymmetricPattern,
        u: &[f64],
    ) -> std::result::Result<(Vec<f64>, Vec<f64>), String> {
        tangent_and_residual(model, constraints, pattern, u).map_err(|e| e.to_string())
    }
}

/// The contact problem of one load step, in `D` dimensions.
pub(crate) struct ContactSystem<
    'a,
    const D: usize = 2,
    K: NewtonDimension<D> = crate::fe::ElementKind,
> {
    model: &'a Model<D, K>,
    sys: LinearSystem,
    /// The pattern of the unknowns: `K`'s, the rows' blocks, and the multipliers' couplings.
    pattern: SymmetricPattern,
    /// Position in `pattern` of each entry of `sys.pattern`.
    k_positions: Vec<usize>,
    version: usize,
    /// Rows of the last evaluation (current geometry) or of the reference configuration.
    rows: Vec<Constraint<D>>,
    /// The multiplier unknown of each row (Lagrange rows with free equations).
    multiplier: Vec<Option<usize>>,
    /// The tangential multiplier unknown of each frictional Lagrange row with a normal one.
    tangential: Vec<Option<usize>>,
    /// The multiplier unknowns of the last pattern, by point (to carry them to a new one).
    carried: HashMap<RowKey, usize>,
    /// Stiffness scale `rho`.
    rho: f64,
    /// The complementarity constant of the Lagrange friction rows, `c = friction_c rho`: 1 until
    /// the iteration cycles, then lowered ([`System::remedy_cycle`]).
    friction_c: f64,
    /// A cycle remedy of penalty-type friction rows: a point that has slipped both ways takes
    /// the secant stiffness between its last iterates on the two sides of the cone instead of
    /// the slip tangent (see [`System::remedy_cycle`]).
    secant_on_reversal: bool,
    /// Under that remedy, the last iterate `(slip, force)` of each slipping point in each
    /// direction (`[positive, negative]`).
    slip_sides: HashMap<RowKey, [Option<(f64, f64)>; 2]>,
    /// Per point: the Uzawa multiplier, the status and the force of the last evaluation.
    augmentation: HashMap<RowKey, f64>,
    active: HashMap<RowKey, bool>,
    /// The statuses of the evaluation before the last one: the set the last Newton step solved
    /// with (an augmentation follows an evaluation after a step).
    stepped_active: HashMap<RowKey, bool>,
    forces: HashMap<RowKey, f64>,
    /// Rows closed in the first evaluation to hold bodies that would otherwise float.
    closed_at_start: HashSet<RowKey>,
    evaluations: usize,
    /// A multiplier row stays active while its force is above `-force_tolerance` (`1e-10` of
    /// the largest force of the last evaluation).
    force_tolerance: f64,
    /// Active points whose slave node left the master surface (no row any more), first time
    /// each node left.
    departures: Vec<Departure>,
    pub(crate) search_seconds: f64,
    /// The rows' reference areas (current geometry), searched once per step.
    reference_areas: ReferenceAreas,
    /// Coulomb pairs: the plastic slip committed at the end of the last load step, by point,
    /// and the frictional status of the last evaluation (with the direction of a slip).
    committed: HashMap<RowKey, Committed>,
    status: HashMap<RowKey, (Status, Tangential)>,
    /// Finite kinematics: the element found inverted at the last evaluation, or the pair found
    /// without rows there (its residual is then NaN, which ends the Newton solve; the load step
    /// is cut).
    inverted: Option<String>,
    /// The displacement of the first evaluation (the step's start): how far a diverging
    /// iterate has moved is measured from it.
    step_start: Vec<f64>,
    /// Augmented-Lagrangian Coulomb pairs: the tangential Uzawa multiplier `lambda_bar_t` by
    /// point (carried from the last load step, updated with the normal one).
    tangential_augmentation: HashMap<RowKey, Tangential>,
    /// Whether the last evaluation changed no point's status (open, stick, slip).
    sets_settled: bool,
    /// A Uzawa update moved a frictional multiplier: the next evaluation keeps the frictional
    /// branches of the last one (`holding` while it runs).
    hold_next: bool,
    holding: bool,
    /// Whether the Uzawa multipliers of the frictional points have been updated in this load
    /// step (Laursen & Simo's bound is held only from then on).
    multipliers_current: bool,
}

impl<'a, const D: usize, K: NewtonDimension<D>> ContactSystem<'a, D, K> {
    /// The problem at the start of a load step: `previous` are the active points of the last
    /// step, `u` its displacement.
    pub(crate) fn new(
        model: &'a Model<D, K>,
        u: Option<&[f64]>,
        previous: Option<&HashSet<RowKey>>,
        committed: HashMap<RowKey, Committed>,
    ) -> Result<Self> {
        let current = model.physics.contact_geometry == ContactGeometry::Current;
        let t = Instant::now();
        let areas = if current {
            reference_areas(model)?
        } else {
            ReferenceAreas::new()
        };
        let start = vec![0.0; model.dof_count];
        let rows = rows_at(model, current.then(|| (u.unwrap_or(&start), &areas)))?;
        crate::solver::refuse_obstacles(model, &rows)?;
        let search_seconds = t.elapsed().as_secs_f64();
        let blocks: Vec<Vec<usize>> = rows.iter().map(|r| r.all_dofs()).collect();
        let sys = assemble(model, &blocks);
        sys.check_assembled(model)?;
        let rho = (0..sys.n)
            .filter_map(|e| sys.pattern.position(e, e).map(|k| sys.k[k].abs()))
            .fold(0.0f64, f64::max)
            .max(f64::MIN_POSITIVE);
        let zero = vec![0.0; model.dof_count];
        let u = u.unwrap_or(&zero);
        let size = model.size();
        let gaps: Vec<f64> = rows.iter().map(|r| r.gap(u)).collect();
        let mut closed: Vec<bool> = rows
            .iter()
            .zip(&gaps)
            .map(|(r, &g)| {
                r.bilateral
                    || g <= 1e-14 * size
                    || previous.is_some_and(|p| p.contains(&row_key(r)))
            })
            .collect();
        RigidModes::new(model).close_free_bodies(&rows, &gaps, size, &mut closed);
        let closed_at_start = rows
            .iter()
            .zip(&closed)
            .filter(|(_, &c)| c)
            .map(|(r, _)| row_key(r))
            .collect();
        let mut system = ContactSystem {
            model,
            pattern: sys.pattern.clone(),
            k_positions: Vec::new(),
            sys,
            version: 0,
            rows,
            multiplier: Vec::new(),
            tangential: Vec::new(),
            carried: HashMap::new(),
            rho,
            friction_c: 1.0,
            secant_on_reversal: false,
            slip_sides: HashMap::new(),
            augmentation: HashMap::new(),
            active: HashMap::new(),
            stepped_active: HashMap::new(),
            forces: HashMap::new(),
            closed_at_start,
            evaluations: 0,
            force_tolerance: 0.0,
            departures: Vec::new(),
            search_seconds,
            reference_areas: areas,
            committed,
            status: HashMap::new(),
            inverted: None,
            step_start: Vec::new(),
            tangential_augmentation: HashMap::new(),
            sets_settled: false,
            hold_next: false,
            holding: false,
            multipliers_current: false,
        };
        system.number_unknowns();
        system.carry_uzawa_multipliers();
        Ok(system)
    }

    /// Augmented-Lagrangian Coulomb rows start a load step from the forces of the last one as
    /// their Uzawa multipliers (see [`crate::contact::friction`]; frictionless rows restart
    /// from zero, as before), and from the stick point where the point ended it, the slip
    /// `g_t^n`: the trial force `lambda_bar_t - w_t (g_t - g_t^n)` at the start of the step is
    /// then the committed force to the last bit, as the penalty map's. (The last step's stick
    /// point differs from `g_t^n` by what its Uzawa iteration left: `w_t` times that residual
    /// was the difference between the committed force and the next step's first trial.)
    fn carry_uzawa_multipliers(&mut self) {
        for r in &self.rows {
            let key = row_key(r);
            let (
                RowLaw::Penalty {
                    update: Some(_), ..
                },
                Some(c),
            ) = (self.law(r), self.committed.get_mut(&key))
            else {
                continue;
            };
            if c.normal_force > 0.0 {
                c.slip = c.start_slip;
                self.augmentation.insert(key, c.normal_force);
                self.tangential_augmentation.insert(key, c.tangential_force);
            }
        }
    }

    /// The forces point `r` ended the last load step with, when it was closed then (normal
    /// force positive): the multipliers a Lagrange row starts the step from.
    fn carried_force(&self, r: &Constraint<D>) -> Option<&Committed> {
        self.committed
            .get(&row_key(r))
            .filter(|c| c.normal_force > 0.0)
    }

    /// Start the multipliers of the Lagrange frictional rows in `x` from the forces their
    /// points ended the last load step with, `x_j = lambda / rho` (the rest stay zero). With the
    /// stick point `g_t^n` where the point ended that step, the first iterate of a step is the
    /// committed state to the last bit: a point that slipped sits on the cone and sticks there
    /// ([`multiplier_status`] within [`crate::contact::friction::CONE_ROUND_OFF`]), and a step
    /// that changes nothing is solved at its first iterate. (From zero multipliers every point
    /// stuck in the first iteration and Newton iterated back to the cone.)
    fn start_multipliers(&self, x: &mut [f64]) {
        for (i, r) in self.rows.iter().enumerate() {
            let (Some(j), Some(c)) = (self.multiplier[i], self.carried_force(r)) else {
                continue;
            };
            x[j] = c.normal_force / self.rho;
            if let Some(jt) = self.tangential[i] {
                for a in 0..r.tangents.len() {
                    x[jt + a] = c.tangential_force[a] / self.rho;
                }
            }
        }
    }

    /// The committed slip of point `key` (zero for a point the last step did not have).
    fn committed_slip(&self, key: &RowKey) -> Tangential {
        self.committed
            .get(key)
            .map_or([0.0; MAX_TANGENTS], |c| c.slip)
    }

    /// How row `r` is enforced.
    fn law(&self, r: &Constraint<D>) -> RowLaw {
        let pair = &self.model.contact[r.pair];
        let share = pair.penalty_share();
        match method(&pair.enforcement).kernel() {
            // the model refuses the perturbed Lagrangian's consistent mortar coupling here,
            // so its rows carry the lumped mass: the penalty's law
            Method::Regularized { kappa } | Method::PerturbedLagrange { kappa } => {
                RowLaw::Penalty {
                    w: kappa * share * r.area,
                    update: None,
                }
            }
            Method::AugmentedLagrange { kappa, update } => RowLaw::Penalty {
                w: kappa * share * r.area,
                update: Some(update),
            },
            // the perturbed tangent's iteration written in the displacements is the augmented
            // Lagrangian's with its update after every iteration (see the module notes)
            Method::PerturbedTangent { kappa } => RowLaw::Penalty {
                w: kappa * share * r.area,
                update: Some(MultiplierUpdate::PerIteration),
            },
            // constraint elimination: the Lagrange rows' residual and sets, with the Newton
            // step solved by eliminating each active row's owned dof (`Tangent::elimination`)
            Method::Lagrange | Method::Elimination => RowLaw::Multiplier,
        }
    }

    /// Whether row `r` is enforced by constraint elimination.
    fn eliminated(&self, r: &Constraint<D>) -> bool {
        method(&self.model.contact[r.pair].enforcement).kernel() == Method::Elimination
    }

    /// The friction coefficient and tangential weight `w_t = kappa_t A` of a frictional row.
    fn coulomb(&self, r: &Constraint<D>) -> Option<(f64, f64)> {
        if r.tangents.is_empty() {
            return None;
        }
        let pair = &self.model.contact[r.pair];
        let Interaction::Coulomb { mu, kappa_t } = pair.interaction else {
            return None;
        };
        // Lagrange rows have no tangential penalty (the model refuses kappa_t there): w_t = 0
        let kappa_t = kappa_t
            .or_else(|| method(&pair.enforcement).kappa())
            .unwrap_or(0.0);
        Some((mu, kappa_t * r.area))
    }

    /// The return map of frictional row `i` at `u`, with its normal force and status.
    /// Lagrange rows: the status from [`multiplier_status`] at the unknowns `x`, the force
    /// `lambda_t = rho x_t` (zero open), the plastic slip `g_t` (the committed one in stick) and,
    /// in `d_normal`, the sign `s` of a slip.
    fn friction_at(
        &self,
        i: usize,
        u: &[f64],
        x: &[f64],
        lambda_n: f64,
        on: bool,
    ) -> Option<ReturnMap> {
        let r = &self.rows[i];
        let (mu, w_t) = self.coulomb(r)?;
        let k = r.tangents.len();
        let key = row_key(r);
        let committed = self.committed_slip(&key);
        let g_t = slip_of(r, u);
        match self.law(r) {
            RowLaw::Penalty {
                update: Some(_), ..
            } => {
                // the augmented Lagrangian: the trial force from the Uzawa multiplier and the
                // stick point; Laursen & Simo bound it by the normal multiplier held fixed
                let lambda_bar_n = self.augmentation.get(&key).copied().unwrap_or(0.0);
                // Laursen & Simo hold the bound at mu lambda_bar_n once the step has updated
                // the multipliers; before (the step's first Newton pass) the bound is the
                // current normal force, the consistent form: the multiplier of the last step
                // (or none, zero) bounds the friction of the last load, and a body held by
                // friction alone may have no equilibrium under the new load with it (it slid
                // away on the incline). A point without a normal multiplier takes the
                // consistent form too (at a converged Uzawa iteration every compressed point
                // has one).
                let fixed = self.model.solver.friction_tangent == FrictionTangent::LaursenSimo
                    && self.multipliers_current
                    && lambda_bar_n > 0.0;
                let held = self
                    .holding
                    .then(|| self.status.get(&key))
                    .flatten()
                    .and_then(|&(status, force)| held_branch(k, status, &force));
                return Some(augmented_return_map(
                    mu,
                    w_t,
                    if fixed { lambda_bar_n } else { lambda_n },
                    !fixed,
                    on,
                    &g_t[..k],
                    &committed[..k],
                    &self
                        .tangential_augmentation
                        .get(&key)
                        .copied()
                        .unwrap_or([0.0; MAX_TANGENTS])[..k],
                    held,
                ));
            }
            RowLaw::Penalty { .. } => {
                // from the committed force and slip: the trial force at the start of a step is
                // the committed force to the last bit (see [`return_map`])
                let start = self.committed.get(&key).copied().unwrap_or_default();
                return Some(return_map(mu, w_t, lambda_n, on, &g_t[..k], &start));
            }
            RowLaw::Multiplier => {}
        }
        let set = self.lagrange_set(i, u, x, lambda_n, on)?;
        let j = self.tangential[i]?;
        let mut force = [0.0; MAX_TANGENTS];
        if set.status != Status::Open {
            for (a, f) in force.iter_mut().enumerate().take(k) {
                *f = self.rho * x[j + a];
            }
        }
        Some(ReturnMap {
            status: set.status,
            force,
            plastic_slip: if set.status == Status::Stick {
                committed
            } else {
                g_t
            },
            d_slip: [[0.0; MAX_TANGENTS]; MAX_TANGENTS],
            d_normal: set.direction,
        })
    }

    /// The open/stick/slip set of Lagrange friction row `i` at `(u, x)` with normal force
    /// `lambda_n` (`on`: active): [`multiplier_status`] on the row's `k` tangential multipliers
    /// `lambda_t = rho x_t` and its slip increment `g_t - g_t^n`, `c = friction_c rho`. `None`
    /// for a row without tangential multipliers.
    fn lagrange_set(
        &self,
        i: usize,
        u: &[f64],
        x: &[f64],
        lambda_n: f64,
        on: bool,
    ) -> Option<MultiplierSet> {
        let r = &self.rows[i];
        let (mu, _) = self.coulomb(r)?;
        let j = self.tangential[i]?;
        let k = r.tangents.len();
        if on && self.evaluations == 0 && self.carried_force(r).is_none() {
            // a point new to the step starts with zero multipliers: it sticks in its first
            // iteration (a bound mu lambda_n = 0 would make any round-off slip a slip)
            return Some(MultiplierSet {
                status: Status::Stick,
                direction: [0.0; MAX_TANGENTS],
                turn: [[0.0; MAX_TANGENTS]; MAX_TANGENTS],
            });
        }
        let committed = self.committed_slip(&row_key(r));
        let g_t = slip_of(r, u);
        let lambda_t: Vec<f64> = (0..k).map(|a| self.rho * x[j + a]).collect();
        let increment: Vec<f64> = (0..k).map(|a| g_t[a] - committed[a]).collect();
        Some(multiplier_status(
            mu,
            lambda_n,
            on,
            &lambda_t,
            &increment,
            self.rho * self.friction_c,
        ))
    }

    /// The free equations of a gradient with their coefficients.
    fn free_of(&self, dofs: &[usize], coeffs: &[f64]) -> Vec<(usize, f64)> {
        dofs.iter()
            .zip(coeffs)
            .filter_map(|(&d, &c)| {
                let e = self.sys.eq(d);
                (e != NO_EQUATION).then_some((e, c))
            })
            .collect()
    }

    /// The free equations of row `r` with their coefficients.
    fn free_terms(&self, r: &Constraint<D>) -> Vec<(usize, f64)> {
        r.dofs
            .iter()
            .zip(&r.coeffs)
            .filter_map(|(&d, &c)| {
                let e = self.sys.eq(d);
                (e != NO_EQUATION).then_some((e, c))
            })
            .collect()
    }

    /// Number the multiplier unknowns of the rows and build the pattern of all unknowns.
    fn number_unknowns(&mut self) {
        let n = self.sys.n;
        let mut m = 0;
        self.multiplier = self
            .rows
            .iter()
            .map(|r| {
                let has_free = !self.free_terms(r).is_empty();
                (matches!(self.law(r), RowLaw::Multiplier) && has_free).then(|| {
                    m += 1;
                    n + m - 1
                })
            })
            .collect();
        let normal_count = m;
        self.tangential = self
            .rows
            .iter()
            .zip(&self.multiplier)
            .map(|(r, mult)| {
                // one unknown per tangent, numbered together: `j, j + 1` in 3D
                (mult.is_some() && self.coulomb(r).is_some()).then(|| {
                    m += r.tangents.len();
                    n + m - r.tangents.len()
                })
            })
            .collect();
        debug_assert!(self
            .tangential
            .iter()
            .flatten()
            .all(|&j| j >= n + normal_count));
        if m == 0 {
            self.pattern = self.sys.pattern.clone();
            self.k_positions = (0..self.sys.pattern.nnz()).collect();
            return;
        }
        let p = &self.sys.pattern;
        let mut builder = PatternBuilder::new(n + m);
        for j in 0..n {
            for k in p.col_ptr[j]..p.col_ptr[j + 1] {
                builder.add_block(&[p.row_idx[k], j]);
            }
        }
        for ((r, mult), tangential) in self.rows.iter().zip(&self.multiplier).zip(&self.tangential)
        {
            if let Some(j) = mult {
                let mut block: Vec<usize> = self.free_terms(r).iter().map(|&(e, _)| e).collect();
                // a nodal-normal row's multiplier equation reaches every node of its
                // linearization (smooth sliding: beyond the force direction's nodes)
                if let Some(lin) = &r.nodal_normal {
                    for e in lin.dofs.iter().map(|&d| self.sys.eq(d)) {
                        if e != NO_EQUATION && !block.contains(&e) {
                            block.push(e);
                        }
                    }
                }
                block.push(*j);
                if let Some(jt) = tangential {
                    for t in &r.tangents {
                        for (e, _) in self.free_of(&t.dofs, &t.coeffs) {
                            if !block.contains(&e) {
                                block.push(e);
                            }
                        }
                    }
                    block.extend(*jt..*jt + r.tangents.len());
                }
                builder.add_block(&block);
            }
        }
        self.pattern = builder.build();
        let mut positions = Vec::with_capacity(p.nnz());
        for j in 0..n {
            for k in p.col_ptr[j]..p.col_ptr[j + 1] {
                positions.push(self.pattern.position(p.row_idx[k], j).expect("copied"));
            }
        }
        self.k_positions = positions;
    }

    /// The force of row `r` at the unknowns `(u, mu)`, and whether it is active.
    fn force(&self, i: usize, u: &[f64], x: &[f64]) -> (f64, bool) {
        let r = &self.rows[i];
        let key = row_key(r);
        let closed = self.evaluations == 0 && self.closed_at_start.contains(&key);
        let g = r.gap(u);
        match self.law(r) {
            RowLaw::Penalty { w, .. } => {
                let trial = self.augmentation.get(&key).copied().unwrap_or(0.0) - w * g;
                if r.bilateral || closed || trial > 0.0 {
                    (trial, true)
                } else {
                    (0.0, false)
                }
            }
            RowLaw::Multiplier => {
                let Some(j) = self.multiplier[i] else {
                    return (0.0, false);
                };
                let lambda = self.rho * x[j];
                let on = r.bilateral
                    || closed
                    || if self.active.get(&key).copied().unwrap_or(false) {
                        lambda >= -self.force_tolerance
                    } else {
                        g < -1e-14 * self.model.size()
                    };
                (lambda, on)
            }
        }
    }

    /// Grow the pattern when a row couples equations it does not hold (a slave node that slid
    /// onto new master nodes) or the rows changed under multipliers: assemble again.
    fn cover(&mut self) {
        let sys = &self.sys;
        let covered = self.rows.iter().all(|r| {
            let eqs: Vec<usize> = r
                .all_dofs()
                .iter()
                .map(|&d| sys.eq(d))
                .filter(|&e| e != NO_EQUATION)
                .collect();
            eqs.iter().all(|&a| {
                eqs.iter()
                    .all(|&b| self.sys.pattern.position(a.min(b), a.max(b)).is_some())
            })
        });
        let multipliers: Vec<RowKey> = self
            .rows
            .iter()
            .filter(|r| matches!(self.law(r), RowLaw::Multiplier) && !self.free_terms(r).is_empty())
            .map(row_key)
            .collect();
        let same_multipliers = multipliers.len() == self.carried.len()
            && multipliers.iter().all(|k| self.carried.contains_key(k));
        // a multiplier couples the equations its row acts on now: a row whose gradient gained
        // a component (a normal on a rigid circle that turned away from an axis) needs new
        // entries in the multiplier's column
        let coupled = same_multipliers
            && self.rows.iter().all(|r| {
                let Some(&j) = self.carried.get(&row_key(r)) else {
                    return true;
                };
                self.free_terms(r)
                    .iter()
                    .all(|&(e, _)| self.pattern.position(e.min(j), e.max(j)).is_some())
            });
        if !covered {
            let blocks: Vec<Vec<usize>> = self.rows.iter().map(|r| r.all_dofs()).collect();
            self.sys = assemble(self.model, &blocks);
        }
        if !covered || !coupled {
            self.number_unknowns();
            self.version += 1;
        } else {
            // the same points, perhaps in another order: their unknowns stay
            self.multiplier = self
                .rows
                .iter()
                .map(|r| self.carried.get(&row_key(r)).copied())
                .collect();
        }
    }

    /// The contact state at the unknowns `x` (after the solve).
    #[allow(clippy::type_complexity)]
    fn state(&self, x: &[f64]) -> (Vec<bool>, Vec<f64>, Vec<f64>, Vec<Option<FrictionPoint>>) {
        let u = self.sys.expand(&x[..self.sys.n]);
        let mut active = Vec::with_capacity(self.rows.len());
        let mut forces = Vec::with_capacity(self.rows.len());
        let mut friction = Vec::with_capacity(self.rows.len());
        for i in 0..self.rows.len() {
            let (f, a) = self.force(i, &u, x);
            active.push(a);
            forces.push(if a { f } else { 0.0 });
            let r = &self.rows[i];
            friction.push(self.friction_at(i, &u, x, f, a).map(|m| {
                let committed = self.committed_slip(&row_key(r));
                let k = r.tangents.len();
                FrictionPoint {
                    status: m.status,
                    force: m.force,
                    tangents: k,
                    mu: self.coulomb(r).expect("frictional").0,
                    normal_force: if a { f } else { 0.0 },
                    slip: slip_of(r, &u),
                    plastic_slip: m.plastic_slip,
                    committed,
                    dissipation: if m.status == Status::Open {
                        0.0
                    } else {
                        -(0..k)
                            .map(|c| m.force[c] * (m.plastic_slip[c] - committed[c]))
                            .sum::<f64>()
                    },
                }
            }));
        }
        let gaps = self.rows.iter().map(|r| r.gap(&u)).collect();
        (active, forces, gaps, friction)
    }

    /// The active points of the last evaluation that have no row at `u`: their slave nodes
    /// slid off the master surface (a warning in the summary).
    fn record_departures(&mut self, u: &[f64]) {
        let now: HashSet<RowKey> = self.rows.iter().map(row_key).collect();
        let mut lost: Vec<RowKey> = self
            .active
            .iter()
            .filter(|(k, &on)| on && !now.contains(k))
            .map(|(k, _)| *k)
            .collect();
        lost.sort();
        for (pair, _, body, node, _) in lost {
            if self
                .departures
                .iter()
                .any(|d| d.body == body && d.node == node)
            {
                continue;
            }
            let b = &self.model.bodies[body];
            let x = b.mesh.nodes[node];
            self.departures.push(Departure {
                pair,
                body,
                node,
                point: (0..D).map(|c| x[c] + u[b.dof(node, c)]).collect(),
                update: self.evaluations,
            });
        }
    }

    /// Remember which point each multiplier unknown belongs to.
    fn remember_multipliers(&mut self) {
        self.carried = self
            .rows
            .iter()
            .zip(&self.multiplier)
            .filter_map(|(r, m)| m.map(|j| (row_key(r), j)))
            .collect();
    }
}

/// The hook of time integration ([`super::dynamics`]): the inertia `c0 M` joins the
/// stiffness and `c0 M d_pred` the right-hand side (`R = (K + c0 M) x - f - c0 M d_pred - ...`),
/// and the rows and their state are read after each step.
impl<const D: usize, K: NewtonDimension<D>> ContactSystem<'_, D, K> {
    /// Add `values` (on the pattern of [`LinearSystem::pattern`]) to the stiffness. The mass
    /// holds every body, so no row is closed at the start to hold a free one.
    pub(crate) fn add_to_stiffness(&mut self, values: &[f64]) {
        self.sys.k.iter_mut().zip(values).for_each(|(k, m)| *k += m);
        self.closed_at_start.clear();
    }

    /// Replace the stiffness by `values` (on the pattern of [`LinearSystem::pattern`]): a
    /// mass-norm projection onto the admissible set has the mass as its only stiffness.
    pub(crate) fn replace_stiffness(&mut self, values: Vec<f64>) {
        self.sys.k = values;
        self.closed_at_start.clear();
    }

    /// The stiffness system over the free equations (numbering, pattern, `K`, `f`).
    pub(crate) fn linear_system(&self) -> &LinearSystem {
        &self.sys
    }

    /// Replace the right-hand side of the displacement equations.
    pub(crate) fn set_right_hand_side(&mut self, rhs: Vec<f64>) {
        self.sys.rhs = rhs;
    }

    pub(crate) fn rows(&self) -> &[Constraint<D>] {
        &self.rows
    }

    /// The penalty weight `w = kappa A` of row `r` (`None` for a multiplier row).
    pub(crate) fn penalty_weight(&self, r: &Constraint<D>) -> Option<f64> {
        match self.law(r) {
            RowLaw::Penalty { w, .. } => Some(w),
            RowLaw::Multiplier => None,
        }
    }

    /// Active flags, forces (compression positive) and gaps of the rows at the unknowns `x`.
    pub(crate) fn row_state(&self, x: &[f64]) -> (Vec<bool>, Vec<f64>, Vec<f64>) {
        let (active, forces, gaps, _) = self.state(x);
        (active, forces, gaps)
    }

    /// The frictional points at the unknowns `x` (`None` for a frictionless row).
    pub(crate) fn friction_state(&self, x: &[f64]) -> Vec<Option<FrictionPoint>> {
        self.state(x).3
    }

    /// Commit the frictional history of `friction` (the points at the end of a converged time
    /// step): each point's plastic slip or stick position and its forces become what the next
    /// step starts from, as between load steps ([`ContactState::friction_history`]).
    /// Augmented-Lagrangian and perturbed-tangent points start the next step from the forces
    /// committed here as their Uzawa multipliers, as a load step does, and Laursen & Simo's
    /// bound waits for the step's first update again.
    pub(crate) fn commit_friction(&mut self, friction: &[Option<FrictionPoint>]) {
        self.committed = crate::contact::state::committed_history(&self.rows, friction);
        self.multipliers_current = false;
        self.hold_next = false;
        // a remedy found needed stays on for the steps that follow (a body coming to rest
        // swings through the cone again in the next step); the iterates are of the last step
        self.slip_sides.clear();
        self.carry_uzawa_multipliers();
    }
}

impl<const D: usize, K: NewtonDimension<D>> System for ContactSystem<'_, D, K> {
    fn pattern(&self) -> &SymmetricPattern {
        &self.pattern
    }

    /// A cycle of Lagrange-multiplier friction: lower the complementarity constant `c` of the
    /// stick/slip test by 100 (down to `1e-12 rho`). The solution does not depend on `c` (at
    /// a converged iterate a stick point has zero slip and a slip point slips against its
    /// force, whatever `c > 0`), the path does: with `c |dg| > 2 mu lambda_n` a slip that runs
    /// with its force is read as a slip the other way, which near the edge of the contact zone
    /// (small `lambda_n`) makes points flip between the two directions or between stick and
    /// slip. A smaller `c` reads such a slip as stick. Measured on the Cattaneo-Mindlin
    /// cylinder with Lagrange friction: `c = rho` cycles at every level, `c = 1e-3 rho`
    /// converges at h = 0.08 and 0.04, `1e-5 rho` at 0.02.
    ///
    /// A cycle of penalty-type friction (penalty, perturbed Lagrangian, augmented Lagrangian,
    /// perturbed tangent): a point whose slip swings from one side of the cone to the other,
    /// `lambda_t = +mu lambda_n` at one iterate and `-mu lambda_n` at the next. The slip tangent
    /// has no tangential stiffness, so each Newton step carries the slip across the stick
    /// range (width `2 mu lambda_n / w_t`) and back. From then on (for the rest of the solve
    /// and the steps after it), a point that has slipped both ways takes the secant stiffness
    /// `(lambda_t - lambda_t^o) / (g_t - g_t^o)` to its last iterate on the other side (regula
    /// falsi on the point's force-slip curve), which brings the iterates into the stick range
    /// when the answer sticks there. The residual, and with it the answer, is unchanged.
    /// Measured on the sliding block of `cases/dynamics` with mu = 3 (it comes to rest): with
    /// kappa = 1e5 and 1e6 every step converges, where all stopped cycling at step 10; at
    /// kappa = 1e7 the secant iterations still run into the iteration limit at step 27.
    fn remedy_cycle(&mut self) -> Option<String> {
        let lagrange_friction = self
            .rows
            .iter()
            .any(|r| !r.tangents.is_empty() && matches!(self.law(r), RowLaw::Multiplier));
        if !lagrange_friction {
            // (one tangent: the remedy does nothing on a disc, see `evaluate`)
            let penalty_friction = self.rows.iter().any(|r| {
                r.tangents.len() == 1
                    && self.coulomb(r).is_some()
                    && matches!(self.law(r), RowLaw::Penalty { .. })
            });
            if !penalty_friction || self.secant_on_reversal {
                return None;
            }
            self.secant_on_reversal = true;
            return Some(
                "giving points whose slip reverses its direction the secant stiffness between their two sides".into(),
            );
        }
        if self.friction_c <= 1e-12 {
            return None;
        }
        self.friction_c *= 1e-2;
        Some(format!(
            "lowering the stick/slip constant c of the Lagrange friction rows to {:.0e} of the stiffness scale",
            self.friction_c
        ))
    }

    /// Penalty-type friction without Uzawa updates (penalty, perturbed Lagrangian) in
    /// small-strain kinematics: every Newton step under the non-monotone line search on the
    /// residual norm ([`crate::solver::newton::ARMIJO`]), whose residual is a function of the
    /// displacements alone. A full step that sends the iterate
    /// farther off than any of the last few is shortened: the semi-smooth step of a friction
    /// point near the cone's edge overshoots its stick range when the tangential stiffness
    /// `w_t` is far above the body's (the slip tangent has no stiffness along the slip), and
    /// the iterates run off (measured on the cube `E = 1000` dragged into partial slip,
    /// `tests/friction3d.rs`: at kappa = 1e5 and 1e8 the residual grew from 0.25 to 1 of the
    /// force scale, with contact forces 150 and 7e4 times the load, and the iteration settled
    /// into a cycle; the drag reversed in `cases/hard/friction-stick-slip-reversal`). The full
    /// step is taken wherever it does not raise the residual above the reference (always near
    /// the solution), so the answer and the quadratic convergence are Newton's.
    /// Left out: finite kinematics (an inverted trial iterate cuts the load step), Lagrange
    /// multipliers and Uzawa updates (the statuses and multipliers they remember between
    /// evaluations would be moved by trial iterates the line search rejects).
    ///
    /// On a disc (3D: two tangents) the search is monotone: the radial return's iterates,
    /// allowed to rise to the largest of the last few residuals, wander (the 3D
    /// Cattaneo-Mindlin level h = 0.025 of `tests/cattaneo3d.rs` ran into the iteration limit
    /// with a window of 5 and converges with 1, as it did with the line search restarted after
    /// a cycle). With one tangent (2D) the non-monotone window keeps the semi-smooth steps that
    /// change a point's status (the friction block of `tests/friction.rs`: 5 iterations a
    /// slip step with the window, 9 to 12 monotone; the sliding block of `cases/dynamics` with
    /// mu = 3 and kappa 1e6 converges with the window and not monotone).
    fn line_search(&self) -> Option<usize> {
        let searched = self.model.physics.kinematics != Kinematics::Finite
            && self.rows.iter().any(|r| self.coulomb(r).is_some())
            && self
                .rows
                .iter()
                .all(|r| matches!(self.law(r), RowLaw::Penalty { update: None, .. }));
        let disc = self
            .rows
            .iter()
            .any(|r| r.tangents.len() == 2 && self.coulomb(r).is_some());
        searched.then_some(if disc {
            1
        } else {
            crate::solver::newton::NONMONOTONE_WINDOW
        })
    }

    /// Lagrange-multiplier friction: a tangential penalty's return map is continuous in the
    /// slip, where the multipliers' stick/slip sets jump.
    fn cycle_advice(&self) -> Option<String> {
        self.rows
            .iter()
            .any(|r| !r.tangents.is_empty() && matches!(self.law(r), RowLaw::Multiplier))
            .then(|| {
                "for Lagrange-multiplier friction consider a tangential penalty (penalty or augmented Lagrangian enforcement with kappa_t), whose return map is continuous in the slip".to_string()
            })
    }

    fn smaller_increment(&self) -> &'static str {
        if self.model.dynamics.is_some() {
            "take a smaller time step (physics.dynamics.dt)"
        } else {
            "apply the load in more load steps (solver.load_steps)"
        }
    }

    fn pattern_version(&self) -> usize {
        self.version
    }

    fn describe_unknown(&self, k: usize) -> String {
        if k < self.sys.n {
            return match self.sys.dof_of(k) {
                Some(d) => super::linear::describe_dof(self.model, d),
                None => format!("equation {k}"),
            };
        }
        match self.multiplier.iter().position(|&m| m == Some(k)) {
            Some(i) => {
                let r = &self.rows[i];
                format!(
                    "the multiplier of the slave node at {} of contact '{}' (pass {})",
                    r.site().at(),
                    self.model.contact[r.pair].name,
                    r.pass
                )
            }
            None => match self.tangential.iter().enumerate().find_map(|(i, m)| {
                m.filter(|&j| (j..j + self.rows[i].tangents.len()).contains(&k))
                    .map(|j| (i, k - j))
            }) {
                Some((i, a)) => {
                    let r = &self.rows[i];
                    let which = if r.tangents.len() > 1 {
                        format!(" along tangent {} {:?}", a + 1, r.tangents[a].direction)
                    } else {
                        String::new()
                    };
                    format!(
                        "the tangential multiplier{which} of the slave node at {} of contact '{}' (pass {})",
                        r.site().at(),
                        self.model.contact[r.pair].name,
                        r.pass
                    )
                }
                None => format!("multiplier {k}"),
            },
        }
    }

    fn carry(&mut self, x: &[f64]) -> Vec<f64> {
        let n = self.sys.n;
        let mut out = x[..n].to_vec();
        out.resize(self.pattern.n, 0.0);
        for (r, m) in self.rows.iter().zip(&self.multiplier) {
            if let (Some(j), Some(&old)) = (m, self.carried.get(&row_key(r))) {
                out[*j] = x[old];
            }
        }
        self.remember_multipliers();
        out
    }

    fn evaluate(
        &mut self,
        x: &[f64],
        general: &GeneralPattern,
        residual: &mut [f64],
        tangent: &mut Tangent,
    ) -> Result<Evaluation> {
        let n = self.sys.n;
        if self.evaluations == 0 {
            self.remember_multipliers();
            self.step_start = self.sys.expand(&x[..n]);
        }
        self.holding = std::mem::take(&mut self.hold_next);
        let u = self.sys.expand(&x[..n]);
        let current = self.model.physics.contact_geometry == ContactGeometry::Current;
        if current && self.evaluations > 0 {
            let t = Instant::now();
            self.rows = match rows_at(self.model, Some((&u, &self.reference_areas))) {
                Ok(rows) => rows,
                // finite kinematics: an iterate that carried a pair off its master (a Newton
                // step far from the solution) fails the step, which is then cut. The pair had
                // rows at the step's start, so the reason is the diverging iterate, not
                // surfaces that never meet: say so, with how far the iterate moved
                Err(e) if self.model.physics.kinematics == Kinematics::Finite => {
                    self.inverted = Some(match &e {
                        crate::error::Error::Invalid { problem, .. }
                            if problem.starts_with(OUT_OF_REACH) =>
                        {
                            diverged_off_master(
                                &e,
                                self.evaluations,
                                &self.step_start,
                                &u,
                                self.model.size(),
                            )
                        }
                        // another reason the rows cannot be built there (e.g. node-to-node
                        // nodes that no longer match): that reason
                        _ => format!("at a Newton iterate, {e}"),
                    });
                    residual.iter_mut().for_each(|v| *v = f64::NAN);
                    return Ok(Evaluation {
                        force_scale: 1.0,
                        ..Evaluation::default()
                    });
                }
                Err(e) => return Err(e),
            };
            self.search_seconds += t.elapsed().as_secs_f64();
            self.record_departures(&u);
            let version = self.version;
            self.cover();
            if self.version != version {
                return Ok(Evaluation::default());
            }
        }
        // finite kinematics: the solids' tangent K_T(u) and residual f_int(u) - f_ext
        let mut solid_residual = None;
        if self.model.physics.kinematics == Kinematics::Finite {
            match K::finite_tangent_and_residual(
                self.model,
                &self.sys.constraints,
                &self.sys.pattern,
                &u,
            ) {
                Ok((k, r)) => {
                    self.sys.k = k;
                    solid_residual = Some(r);
                }
                Err(inverted) => {
                    self.inverted = Some(inverted);
                    residual.iter_mut().for_each(|v| *v = f64::NAN);
                    return Ok(Evaluation {
                        force_scale: 1.0,
                        ..Evaluation::default()
                    });
                }
            }
        }
        let rho = self.rho;
        let mut upper = vec![0.0; self.pattern.nnz()];
        for (k, &p) in self.k_positions.iter().enumerate() {
            upper[p] = self.sys.k[k];
        }
        residual.iter_mut().for_each(|v| *v = 0.0);
        // the magnitude of the terms summed into each row of the residual, whose round-off is
        // the floor of the residual: the stiffness terms |K| |x| (under finite kinematics the
        // tangent's, the size of the terms of f_int) and the loads, then each contact row's
        if let Some(r) = solid_residual {
            residual[..n].copy_from_slice(&r);
        } else {
            self.sys
                .pattern
                .mul(&self.sys.k, &x[..n], &mut residual[..n]);
            residual[..n]
                .iter_mut()
                .zip(&self.sys.rhs)
                .for_each(|(r, f)| *r -= f);
        }
        let mut magnitude = vec![0.0; residual.len()];
        {
            let abs_k: Vec<f64> = self.sys.k.iter().map(|v| v.abs()).collect();
            let abs_x: Vec<f64> = x[..n].iter().map(|v| v.abs()).collect();
            self.sys.pattern.mul(&abs_k, &abs_x, &mut magnitude[..n]);
            magnitude[..n]
                .iter_mut()
                .zip(&self.sys.rhs)
                .for_each(|(m, f)| *m += f.abs());
        }
        // the magnitude of the terms of a row's gap: g = g0 + sum_d c_d u_d in the reference
        // geometry; in the current one the gap is a difference of positions X + u, whose
        // round-off grows with the coordinates (a problem moved away from the origin)
        let gap_magnitude = |r: &Constraint<D>| -> f64 {
            r.g0.abs()
                + r.dofs
                    .iter()
                    .zip(&r.coeffs)
                    .map(|(&d, c)| {
                        let position = if current {
                            let at = self.model.dof_owner(d).map_or(0.0, |o| {
                                self.model.bodies[o.body].mesh.nodes[o.node][o.component]
                            });
                            at + u[d]
                        } else {
                            u[d]
                        };
                        (c * position).abs()
                    })
                    .sum::<f64>()
        };
        let mut eval = Evaluation {
            force_scale: max_abs(&self.sys.rhs),
            ..Evaluation::default()
        };
        // A scene driven by its gaps alone (no load, no prescribed motion: a body placed into
        // an obstacle) has no force scale before its multipliers move; the force that closes
        // the largest active gap, rho |g|, is then the scale (used only when nothing else is).
        let mut closing_force = 0.0_f64;
        let geometric = current && self.model.solver.geometric_stiffness;
        let symmetrized = self.model.solver.friction_tangent == FrictionTangent::Symmetrized;
        // unsymmetric entries (row equation, column equation, value) of slipping points
        let mut coupling: Vec<(usize, usize, f64)> = Vec::new();
        // the unsymmetric entries of slipping Lagrange rows (the set's equation itself: kept
        // with the symmetrized tangent too)
        let mut slip_rows: Vec<(usize, usize, f64)> = Vec::new();
        let mut status = HashMap::new();
        let mut active = HashMap::with_capacity(self.rows.len());
        let mut forces = HashMap::with_capacity(self.rows.len());
        let mut terms: Vec<(usize, f64)> = Vec::new();
        // an active row added the second derivative of its gap to the displacement block
        let mut second_derivatives = false;
        // the unsymmetric entries of rows whose force direction is not their gap's gradient
        // (smooth-sliding slave normals)
        let mut curvature_entries: Vec<(usize, usize, f64)> = Vec::new();
        for i in 0..self.rows.len() {
            let r = &self.rows[i];
            let key = row_key(r);
            let (lambda, on) = self.force(i, &u, x);
            let g = r.gap(&u);
            // a row that opens or closes with its force zero to the force tolerance (a gap
            // zero to round-off) changes nothing: it does not block convergence (it flipped
            // every iteration on a converged penalty solve, N03 of the second defect report)
            let at_zero = match self.law(r) {
                RowLaw::Penalty { w, .. } => {
                    (self.augmentation.get(&key).copied().unwrap_or(0.0) - w * g).abs()
                        <= self.force_tolerance
                }
                RowLaw::Multiplier => {
                    lambda.abs() <= self.force_tolerance && g.abs() <= 1e-12 * self.model.size()
                }
            };
            if self.active.get(&key).copied().unwrap_or(false) != on
                && self.evaluations > 0
                && !at_zero
            {
                eval.status_changes += 1;
            }
            let shown = if on { lambda } else { 0.0 };
            eval.multiplier_change = eval
                .multiplier_change
                .max((shown - self.forces.get(&key).copied().unwrap_or(0.0)).abs());
            if !r.bilateral {
                eval.max_gap_violation = eval.max_gap_violation.max(-g);
            }
            active.insert(key, on);
            forces.insert(key, shown);
            if let Some(mut map) = self.friction_at(i, &u, x, lambda, on) {
                let k = r.tangents.len();
                // the branch of the return map: a slip that reverses is a change too, unless
                // its force is negligible (mu lambda_n at the force tolerance: with mu -> 0 the
                // direction of a slip that is zero to round-off flips at random and changes
                // nothing)
                let previous = self.status.get(&key);
                let negligible_reversal = map.status == Status::Slip
                    && previous.is_some_and(|p| p.0 == Status::Slip)
                    && length(k, &map.force) <= self.force_tolerance;
                let changed = previous.is_none_or(|&(status, force)| {
                    status != map.status
                        || (status == Status::Slip && slip_reversed(k, &force, &map.force))
                });
                if self.evaluations > 0 && changed && !negligible_reversal {
                    eval.status_changes += 1;
                }
                if self.secant_on_reversal
                    && map.status == Status::Slip
                    && self.tangential[i].is_none()
                    && k == 1
                {
                    // the cycle remedy of a slip that swings from one side of the cone to the
                    // other: the slip tangent has no tangential stiffness, so each step swings
                    // it back. Once a point has slipped both ways, its stiffness becomes the
                    // secant to its last iterate on the other side (regula falsi), which
                    // brings the iterates into the stick range if the answer sticks there.
                    // Only the tangent changes: the residual, and so the answer, do not. (One
                    // tangent only: on a disc the slip tangent keeps the stiffness of the
                    // direction's turn, `(I - s s^T)`, and a reversal is not a swing between
                    // two sides.)
                    let w_t = self.coulomb(r).expect("frictional").1;
                    let slip = slip_of(r, &u)[0];
                    let last = self.slip_sides.entry(key).or_default();
                    let side = usize::from(map.force[0] <= 0.0);
                    last[side] = Some((slip, map.force[0]));
                    if let Some((s_o, f_o)) = last[1 - side] {
                        if slip != s_o {
                            map.d_normal = [0.0; MAX_TANGENTS];
                            map.d_slip[0][0] =
                                ((map.force[0] - f_o) / (slip - s_o)).clamp(-w_t, 0.0);
                        }
                    }
                }
                status.insert(key, (map.status, map.force));
                // the tangential gradients over their free equations: one list of equations
                // (the tangents of a point share their nodes) with a coefficient per tangent
                let tangential = tangential_terms(r, |d| self.sys.eq(d));
                for (e, c) in &tangential {
                    for a in 0..k {
                        residual[*e] -= map.force[a] * c[a];
                        eval.force_scale = eval.force_scale.max((map.force[a] * c[a]).abs());
                        if let Some(m) = magnitude.get_mut(*e) {
                            *m += (map.force[a] * c[a]).abs();
                        }
                    }
                }
                if let Some(jt) = self.tangential[i] {
                    // Lagrange rows: the force -rho sum_a x_t,a b_t,a, and the rows of the set,
                    // one per tangent (unknowns jt + a)
                    let jn = self.multiplier[i].expect("a tangential multiplier has a normal one");
                    match map.status {
                        Status::Open => {
                            // R_t = -rho x_t drives the multipliers to zero
                            for a in 0..k {
                                residual[jt + a] = -rho * x[jt + a];
                                upper[self.pattern.position(jt + a, jt + a).expect("diagonal")] =
                                    -rho;
                            }
                        }
                        Status::Stick => {
                            // R_t,a = -rho dg_t,a, and the augmentation rho dg_t,a b_t,a (zero at
                            // the solution) holds a body that only friction holds
                            let committed = self.committed_slip(&key);
                            let slip = slip_of(r, &u);
                            for a in 0..k {
                                let jta = jt + a;
                                if tangential.iter().all(|(_, c)| c[a] == 0.0) {
                                    // a tangent whose slip the supports prescribe (no free
                                    // equation): its stick constrains nothing the solve moves
                                    // (the row would be zero), the supports carry its force,
                                    // and its multiplier is driven to zero as an open one's
                                    residual[jta] = -rho * x[jta];
                                    upper[self.pattern.position(jta, jta).expect("diagonal")] =
                                        -rho;
                                    continue;
                                }
                                let dg = slip[a] - committed[a];
                                residual[jta] = -rho * dg;
                                for (p, (ep, cp)) in tangential.iter().enumerate() {
                                    let ca = cp[a];
                                    residual[*ep] += rho * dg * ca;
                                    upper[self.pattern.position(*ep, jta).expect("coupling")] -=
                                        rho * ca;
                                    for (eq, cq) in &tangential[p..] {
                                        upper[self
                                            .pattern
                                            .position((*ep).min(*eq), (*ep).max(*eq))
                                            .expect("covered")] += rho * ca * cq[a];
                                    }
                                }
                            }
                        }
                        Status::Slip => {
                            // R_t = -rho (x_t - mu x_n s(tau)): the column -rho b_t of the
                            // force only, not its transpose; on the disc the turn of the
                            // direction T = mu lambda_n (I - s s^T) / |tau| with tau = rho x_t -
                            // c dg_t adds rho T in the multipliers' block and -c T b_t in the
                            // displacements' (zero with one tangent)
                            let (mu, _) = self.coulomb(r).expect("frictional");
                            let turn = self
                                .lagrange_set(i, &u, x, lambda, on)
                                .expect("a Lagrange friction row")
                                .turn;
                            let c = rho * self.friction_c;
                            for a in 0..k {
                                let jta = jt + a;
                                let s_a = map.d_normal[a];
                                residual[jta] = -rho * (x[jta] - s_a * mu * x[jn]);
                                upper[self.pattern.position(jta, jta).expect("diagonal")] =
                                    -rho + rho * turn[a][a];
                                for b in a + 1..k {
                                    upper[self.pattern.position(jta, jt + b).expect("block")] =
                                        rho * turn[a][b];
                                }
                                slip_rows.push((jta, jn, rho * s_a * mu));
                                for (e, cs) in &tangential {
                                    upper[self.pattern.position(*e, jta).expect("coupling")] -=
                                        rho * cs[a];
                                    slip_rows.push((jta, *e, rho * cs[a]));
                                    let along: f64 = (0..k).map(|b| turn[a][b] * cs[b]).sum();
                                    if along != 0.0 {
                                        slip_rows.push((jta, *e, -c * along));
                                    }
                                }
                            }
                        }
                    }
                } else if map.d_slip.iter().flatten().any(|&d| d != 0.0) {
                    // -sum_ab (d lambda_t,a / d g_t,b) b_a b_b^T: w_t b_t b_t^T in stick, and in
                    // slip on a disc the turn of the direction, w_t mu lambda_n (I - s s^T) /
                    // |trial| in the frame (symmetric: the upper triangle holds it)
                    for (p, (ep, cp)) in tangential.iter().enumerate() {
                        for (eq, cq) in &tangential[p..] {
                            let mut v = 0.0;
                            for a in 0..k {
                                for b in 0..k {
                                    v += map.d_slip[a][b] * cp[a] * cq[b];
                                }
                            }
                            upper[self
                                .pattern
                                .position((*ep).min(*eq), (*ep).max(*eq))
                                .expect("covered")] -= v;
                        }
                    }
                }
                if map.d_normal.iter().any(|&d| d != 0.0) && self.tangential[i].is_none() {
                    // slip: -b_t (d lambda_t/d lambda_n) (d lambda_n/du)^T, with
                    // d lambda_n/du = -w b_n for the penalty-type normal law
                    let RowLaw::Penalty { w, .. } = self.law(r) else {
                        unreachable!("the model admits friction with penalty-type methods only")
                    };
                    let normal = self.free_terms(r);
                    for (ea, ca) in &tangential {
                        for &(eb, cb) in &normal {
                            for a in 0..k {
                                coupling.push((*ea, eb, map.d_normal[a] * w * ca[a] * cb));
                            }
                        }
                    }
                }
            }
            terms.clear();
            terms.extend(self.free_terms(r));
            // the weight of b b^T in the displacement block, and the force on the equations
            let (w, force) = match (self.law(r), self.multiplier[i]) {
                (RowLaw::Penalty { w, .. }, _) => {
                    if !on {
                        continue;
                    }
                    (w, lambda)
                }
                (RowLaw::Multiplier, None) => continue,
                (RowLaw::Multiplier, Some(j)) => {
                    if !on {
                        // R_mu = -rho mu drives the multiplier to zero; it exerts no force
                        residual[j] = -rho * x[j];
                        upper[self.pattern.position(j, j).expect("diagonal")] = -rho;
                        if let Some(m) = magnitude.get_mut(j) {
                            *m += (rho * x[j]).abs();
                        }
                        continue;
                    }
                    residual[j] = -rho * g;
                    closing_force = closing_force.max((rho * g).abs());
                    if let Some(m) = magnitude.get_mut(j) {
                        *m += rho * gap_magnitude(r);
                    }
                    for &(e, c) in &terms {
                        upper[self.pattern.position(e, j).expect("coupling")] = -rho * c;
                    }
                    // lambda b - rho g b: the augmented force of an active multiplier row
                    (rho, lambda - rho * g)
                }
            };
            if on {
                eval.active += 1;
            }
            // a penalty force w g errs by w times the round-off of its gap's terms
            let penalty_terms = match self.law(r) {
                RowLaw::Penalty { .. } if on => w * gap_magnitude(r),
                _ => 0.0,
            };
            for &(e, c) in &terms {
                residual[e] -= force * c;
                eval.force_scale = eval.force_scale.max((shown * c).abs());
                if let Some(m) = magnitude.get_mut(e) {
                    *m += (force * c).abs() + penalty_terms * c.abs();
                }
            }
            for (a, &(ea, ca)) in terms.iter().enumerate() {
                for &(eb, cb) in &terms[a..] {
                    upper[self
                        .pattern
                        .position(ea.min(eb), ea.max(eb))
                        .expect("covered")] += w * ca * cb;
                }
            }
            // the derivative of the force term `-force b`: `-force H` (`force = lambda - rho g`
            // for a multiplier row, whose `rho g` vanishes only at the solution)
            if geometric && force != 0.0 {
                let b = &self.model.bodies[r.slave_body];
                let dofs: [usize; D] = std::array::from_fn(|c| b.dof(r.slave_node, c));
                let x_s: [f64; D] =
                    std::array::from_fn(|c| b.mesh.nodes[r.slave_node][c] + u[dofs[c]]);
                if let Some(h) = K::slave_curvature(self.model, r, x_s) {
                    for a in 0..D {
                        for c in a..D {
                            let (ea, ec) = (self.sys.eq(dofs[a]), self.sys.eq(dofs[c]));
                            if ea != NO_EQUATION && ec != NO_EQUATION {
                                upper[self
                                    .pattern
                                    .position(ea.min(ec), ea.max(ec))
                                    .expect("node block")] -= force * h[D * a + c];
                            }
                        }
                    }
                }
            }
            if let (true, Some(curvature)) = (geometric, row_curvature(r)) {
                // finite kinematics between deformable bodies: the second-order part of the
                // row's linearization over its nodes (force = lambda_bar - w g for penalty
                // rows, lambda - rho g for multiplier rows: the derivative of -force f)
                second_derivatives = true;
                add_row_curvature(
                    &curvature,
                    r,
                    |d| self.sys.eq(d),
                    (w, force, self.multiplier[i]),
                    &self.pattern,
                    &mut upper,
                    &mut curvature_entries,
                );
            }
        }
        tangent.values = general.symmetric_values(&upper);
        // the symmetrized tangent drops the slip coupling (its symmetric part would make the
        // matrix indefinite and Newton diverge)
        tangent.symmetric = (coupling.is_empty() || symmetrized)
            && slip_rows.is_empty()
            && curvature_entries.is_empty();
        if !symmetrized {
            for (a, b, v) in coupling {
                tangent.values[general.position(a, b).expect("covered")] += v;
            }
        }
        for (a, b, v) in slip_rows.into_iter().chain(curvature_entries) {
            tangent.values[general.position(a, b).expect("covered")] += v;
        }
        tangent.multipliers = self.pattern.n - n;
        tangent.scale = rho;
        // finite kinematics: -force H makes the displacement block indefinite where the force
        // is large against the stiffness (a slave node leaving the master's free end puts the
        // remaining rows under a large force of either sign): the saddle-point matrix has
        // pivots of the wrong sign that are not a dependence of rows
        //
        // In 3D under finite kinematics a pivot of the wrong sign may also be the solid's own
        // geometric stiffness (compressive stress) at an iterate far from equilibrium (the first
        // iterate of a load step, whose prescribed values jumped ahead of the interior), with
        // rows against rigid masters too: factored by LU as well.
        tangent.indefinite_block =
            second_derivatives || (D == 3 && self.model.physics.kinematics == Kinematics::Finite);
        // constraint elimination (the model admits it only on its own): each active row is
        // solved for its owned dof
        if self.rows.iter().any(|r| self.eliminated(r)) {
            let mut owned = Vec::new();
            for (i, r) in self.rows.iter().enumerate() {
                let (Some(j), true) = (self.multiplier[i], active[&row_key(r)]) else {
                    continue;
                };
                // the obstacle check gave every row a free owned dof; one without would reach
                // the solve as an unowned active row, which it refuses with the reason
                if let Some(&(o, _)) = self.free_of(&[r.owner], &[1.0]).first() {
                    owned.push((j, o));
                }
            }
            tangent.elimination = Some(owned);
        }
        self.force_tolerance = 1e-10 * forces.values().fold(0.0f64, |m, f| m.max(f.abs()));
        self.stepped_active = std::mem::replace(&mut self.active, active);
        self.forces = forces;
        self.status = status;
        if eval.force_scale == 0.0 {
            eval.force_scale = closing_force;
        }
        eval.residual_floor =
            newton::ROUNDOFF_TERMS * f64::EPSILON * magnitude.iter().fold(0.0f64, |a, &m| a.max(m));
        self.evaluations += 1;
        self.sets_settled = eval.status_changes == 0;
        self.holding = false;
        Ok(eval)
    }

    fn augment(&mut self, x: &[f64], converged: bool) -> bool {
        let u = self.sys.expand(&x[..self.sys.n]);
        let size = self.model.size();
        let fmax = self.forces.values().fold(0.0f64, |m, f| m.max(f.abs()));
        let mut updates = Vec::new();
        let mut tangential_updates = Vec::new();
        let mut frictional_update = false;
        for (i, r) in self.rows.iter().enumerate() {
            let RowLaw::Penalty {
                w,
                update: Some(rule),
            } = self.law(r)
            else {
                continue;
            };
            if rule == MultiplierUpdate::OuterLoop && !converged {
                continue;
            }
            if self.coulomb(r).is_some() && !self.sets_settled {
                // per iteration, a frictional point's multipliers move once the iteration has
                // settled the open/stick/slip sets: a Uzawa step from an iterate whose branches
                // still change mixes trial states of different sets (it diverged on the slip
                // patch test)
                continue;
            }
            if self.coulomb(r).is_some() {
                frictional_update = true;
            }
            let key = row_key(r);
            let on = self.active.get(&key).copied().unwrap_or(false);
            if self.coulomb(r).is_some() {
                // lambda_bar_t <- proj(lambda_bar_t - w_t (g_t - g_t^n)): the map's force, from
                // the multipliers before this update (zero at an open point)
                let (lambda_n, active) = self.force(i, &u, x);
                let map = self
                    .friction_at(i, &u, x, lambda_n, active)
                    .expect("a frictional row");
                let old = self
                    .tangential_augmentation
                    .get(&key)
                    .copied()
                    .unwrap_or([0.0; MAX_TANGENTS]);
                let k = r.tangents.len();
                let fscale = fmax.max(length(k, &map.force));
                let (slip, committed) = (slip_of(r, &u), self.committed_slip(&key));
                let increment: Tangential = std::array::from_fn(|a| slip[a] - committed[a]);
                let at_floor = map.status == Status::Stick && length(k, &increment) <= 1e-15 * size;
                // the round-off floor of the force itself: a slip or gap at the round-off of
                // the model size times the weights that turn them into forces (the slip force
                // mu lambda_n moves with the normal one). Without it a point whose forces are
                // tiny against that floor (a block resting lightly, mu = 3) kept moving its
                // multiplier by 1e-17 at every update and never converged
                let (mu, w_t) = self.coulomb(r).expect("frictional");
                let force_floor = 1e-15 * size * w_t.max(mu * w);
                let change = length(k, &std::array::from_fn(|a| map.force[a] - old[a]));
                if change > 1e-12 * fscale && change > force_floor && !at_floor {
                    tangential_updates.push((key, map.force));
                }
            }
            if !on {
                // Uzawa's update of an open point: max(0, lambda_bar - w g) = 0 (its trial
                // force is not compressive). Keeping the stale multiplier instead would close
                // the point again wherever g < lambda_bar / w and push it off with a force it
                // no longer carries: a point released at the edge of a contact zone then
                // cycled between open and closed (a block dropped on a rigid line, 2 points)
                if self.augmentation.get(&key).is_some_and(|&l| l != 0.0) {
                    updates.push((key, 0.0));
                }
                continue;
            }
            if !r.bilateral && !self.stepped_active.get(&key).copied().unwrap_or(false) {
                // a point that closed in this iteration: the step that brought it here did not
                // hold it, so its gap is where the unconstrained motion left it, and `w g` the
                // force of the penalty at that point, not the multiplier's correction (with `w`
                // above the stiffness the point sees, an overshoot that pushes it off again:
                // the released edge of a dropped block cycled). The next step holds it with
                // the penalty law; its multiplier moves after that step
                continue;
            }
            let g = r.gap(&u);
            if (w * g).abs() <= 1e-12 * fmax || g.abs() <= 1e-15 * size {
                continue;
            }
            let next = self.augmentation.get(&key).copied().unwrap_or(0.0) - w * g;
            updates.push((key, if r.bilateral { next } else { next.max(0.0) }));
        }
        let moved = !updates.is_empty() || !tangential_updates.is_empty();
        // the Newton step right after the update keeps the frictional branches: at the
        // unchanged displacement the new multiplier adds to the spring's force (a stick point
        // at half the cone bound would be pushed onto it), and the step is the predictor of
        // the updated problem from the converged branches
        self.hold_next = !tangential_updates.is_empty();
        self.multipliers_current |= frictional_update;
        self.augmentation.extend(updates);
        self.tangential_augmentation.extend(tangential_updates);
        moved
    }
}

/// One load step by Newton's method, from the active points `previous` and the displacement
/// `start` of the last step.
pub(crate) fn solve_step<const D: usize, K: NewtonDimension<D>>(
    model: &Model<D, K>,
    previous: Option<HashSet<RowKey>>,
    start: Option<Vec<f64>>,
    committed: HashMap<RowKey, Committed>,
    progress: &mut dyn FnMut(&str),
) -> Result<Solution<D>> {
    let mut timings = Timings::default();
    let t = Instant::now();
    progress("assembling");
    let mut system = ContactSystem::new(model, start.as_deref(), previous.as_ref(), committed)?;
    timings.assembly = (t.elapsed().as_secs_f64() - system.search_seconds).max(0.0);
    let mut x: Vec<f64> = vec![0.0; system.pattern.n];
    if let Some(u) = &start {
        for (e, &d) in system.sys.constraints.free_dofs().iter().enumerate() {
            x[e] = u[d];
        }
    }
    system.start_multipliers(&mut x);
    let first = x.clone();
    let mut inverted = false;
    let mut cut = false;
    let t = Instant::now();
    progress("newton iterations");
    let mut outcome = newton::solve(
        &mut system,
        &mut x,
        newton::Settings {
            max_iterations: model.solver.max_iterations,
            tolerance: if model.physics.kinematics == Kinematics::Finite {
                FINITE_RESIDUAL_TOLERANCE
            } else {
                RESIDUAL_TOLERANCE
            },
            factor_limit: model.factor_limit,
            iteration_dofs: model.iteration_dofs,
        },
    )?;
    if model.physics.kinematics == Kinematics::Finite
        && outcome.termination != Termination::Converged
    {
        // the step is cut (crate::solver::finite): report the reason, and the state it
        // started from (an iterate may be inverted, with no internal force)
        if let Some(why) = system.inverted.take() {
            outcome.termination = Termination::Singular(why);
            inverted = true;
        }
        let n = system.sys.n;
        x.iter_mut().for_each(|v| *v = 0.0);
        x[..n].copy_from_slice(&first[..n]);
        cut = true;
    }
    timings.factorization = outcome.factorization_seconds;
    timings.contact_search = system.search_seconds;
    timings.solve =
        (t.elapsed().as_secs_f64() - outcome.factorization_seconds - timings.contact_search)
            .max(0.0);
    let u = system.sys.expand(&x[..system.sys.n]);
    let (active, forces, gaps, friction) = system.state(&x);
    let mut contact_force = vec![0.0; model.dof_count];
    for ((r, &f), fr) in system.rows.iter().zip(&forces).zip(&friction) {
        for (&d, &c) in r.dofs.iter().zip(&r.coeffs) {
            contact_force[d] += c * f;
        }
        if let Some(fr) = fr {
            for (t, &lambda_t) in r.tangents.iter().zip(&fr.force) {
                for (&d, &c) in t.dofs.iter().zip(&t.coeffs) {
                    contact_force[d] += c * lambda_t;
                }
            }
        }
    }
    let current = model.physics.contact_geometry == ContactGeometry::Current;
    let mut solution = if cut {
        // a failed step under finite kinematics: its prescribed values and the state it
        // started from need not fit together, and the driver keeps only its termination and
        // history
        Solution {
            reactions: vec![0.0; u.len()],
            u: u.clone(),
            equations: system.sys.n,
            matrix_nonzeros: system.sys.pattern.nnz(),
            relative_residual: f64::NAN,
            force_scale: f64::NAN,
            timings,
            contact: None,
            dynamics: None,
            finite: None,
            iterative: None,
        }
    } else {
        finish(model, &system.sys, u.clone(), &contact_force, timings)?
    };
    let iterations = outcome.iterations;
    solution.contact = Some(ContactState {
        rows: std::mem::take(&mut system.rows),
        active,
        forces,
        gaps,
        termination: match outcome.termination {
            Termination::Singular(why) if inverted => Termination::Singular(why),
            Termination::Singular(why) => Termination::Singular(format!(
                "{why}; the active rows may depend on each other (a node constrained twice, as in a two-pass discretization with Lagrange multipliers), or a body may be held only by rows that opened"
            )),
            t => t,
        },
        iterations,
        rank_deficiency: None,
        linear_solver: outcome.linear_solver,
        geometry_updates: if current { iterations } else { 1 },
        configuration: current.then_some(u),
        departures: std::mem::take(&mut system.departures),
        steps: Vec::new(),
        history: outcome.history,
        geometry_changes: Vec::new(),
        friction,
    });
    Ok(solution)
}

/// Why a load step failed when a contact pair had no slave node within reach of its master at
/// Newton iterate `evaluation` (`error`, from [`rows_at`], beginning [`OUT_OF_REACH`]): the pair had rows at the step's start
/// (`start`), so the iterate `u` carried its slave nodes out of reach of the master: the
/// iteration diverged. The message says so and how far the iterate moved (largest nodal
/// displacement change, and as a fraction of the model size `size`), rather than the
/// discretization's "could never act", which is about surfaces that never meet.
fn diverged_off_master(
    error: &crate::error::Error,
    evaluation: usize,
    start: &[f64],
    u: &[f64],
    size: f64,
) -> String {
    let moved = u
        .iter()
        .zip(start)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    let pair = match error {
        crate::error::Error::Invalid { location, .. } => location.clone(),
        other => format!("a contact pair ({other})"),
    };
    format!(
        "Newton's iteration diverged: iterate {evaluation} moved nodes by up to {moved:.3e} ({:.2} of the model size) from the load step's start and carried every slave node of {pair} beyond the search distance of its master, so the pair has no rows there (it had at the step's start); a smaller load increment keeps the iterates near the surface",
        moved / size
    )
}

/// The slip of row `r` at `u` along each of its tangents (components past its tangents zero).
fn slip_of<const D: usize>(r: &Constraint<D>, u: &[f64]) -> Tangential {
    let mut out = [0.0; MAX_TANGENTS];
    for (o, t) in out.iter_mut().zip(&r.tangents) {
        *o = t.slip(u);
    }
    out
}

/// Whether a slip with force `now` runs against the slip of the last iterate (force `before`):
/// with one tangent, a change of side (`lambda_t > 0` against not); on a disc, a turn of more
/// than a right angle.
fn slip_reversed(k: usize, before: &Tangential, now: &Tangential) -> bool {
    if k == 1 {
        (before[0] > 0.0) != (now[0] > 0.0)
    } else {
        (0..k).map(|a| before[a] * now[a]).sum::<f64>() < 0.0
    }
}

/// The branch an augmented-Lagrangian point is held in after a Uzawa update, from its status
/// and force at the last evaluation: stick, or slip along the force's direction (one tangent:
/// its sign, `-1` for a zero force). A slip with no force on a disc has no direction to hold:
/// `None` (the trial force decides).
fn held_branch(k: usize, status: Status, force: &Tangential) -> Option<(Status, Tangential)> {
    if status != Status::Slip {
        return Some((status, [0.0; MAX_TANGENTS]));
    }
    if k == 1 {
        return Some((status, [if force[0] > 0.0 { 1.0 } else { -1.0 }, 0.0]));
    }
    let l = length(k, force);
    (l > 0.0).then(|| (status, std::array::from_fn(|a| force[a] / l)))
}

/// The free equations of row `r`'s tangential gradients (`eq` maps a dof to its equation,
/// [`NO_EQUATION`] when prescribed), in the order of the first tangent's dofs, each with its
/// coefficient along every tangent (the tangents of a point act on the same nodes; a dof
/// another tangent has that the first lacks is appended).
fn tangential_terms<const D: usize>(
    r: &Constraint<D>,
    eq: impl Fn(usize) -> usize,
) -> Vec<(usize, Tangential)> {
    let mut out: Vec<(usize, Tangential)> = Vec::new();
    for (a, t) in r.tangents.iter().enumerate() {
        for (&d, &c) in t.dofs.iter().zip(&t.coeffs) {
            let e = eq(d);
            if e == NO_EQUATION {
                continue;
            }
            match out.iter_mut().find(|(x, _)| *x == e).filter(|_| a > 0) {
                Some((_, coeffs)) => coeffs[a] += c,
                None => {
                    let mut coeffs = [0.0; MAX_TANGENTS];
                    coeffs[a] = c;
                    out.push((e, coeffs));
                }
            }
        }
    }
    out
}

/// Add the second-order part of active row `row`'s linearization ([`RowCurvature`]) to the
/// tangent: with the row's force `force` along its force direction `f` (the row's `coeffs`) and
/// the weight `w` of `f f^T` already in the displacement block (`law = (w, force, multiplier)`),
/// `-force df/dx` and, where `f` is not the gap's gradient, `w f (grad g - f)^T` (and in the
/// multiplier's equation `-rho (grad g - f)^T`, `rho = w`), so that the block is
/// `w f (grad g)^T - force df/dx`. Symmetric contributions go into the upper triangle `upper` of
/// `pattern`, the others into `unsymmetric` as (row equation, column equation, value).
fn add_row_curvature<const D: usize>(
    curvature: &RowCurvature,
    row: &Constraint<D>,
    eq: impl Fn(usize) -> usize,
    (w, force, multiplier): (f64, f64, Option<usize>),
    pattern: &SymmetricPattern,
    upper: &mut [f64],
    unsymmetric: &mut Vec<(usize, usize, f64)>,
) {
    let m = curvature.dofs.len();
    let eqs: Vec<usize> = curvature.dofs.iter().map(|&d| eq(d)).collect();
    let d = &curvature.direction_derivative;
    let Some(gradient) = &curvature.gap_gradient else {
        for a in 0..m {
            for c in a..m {
                let (ea, ec) = (eqs[a], eqs[c]);
                if ea != NO_EQUATION && ec != NO_EQUATION {
                    upper[pattern
                        .position(ea.min(ec), ea.max(ec))
                        .expect("the row's nodes are covered")] -= force * d[a * m + c];
                }
            }
        }
        return;
    };
    // the force direction over the curvature's dofs
    let f: Vec<f64> = curvature
        .dofs
        .iter()
        .map(|dof| {
            row.dofs
                .iter()
                .position(|x| x == dof)
                .map_or(0.0, |k| row.coeffs[k])
        })
        .collect();
    for a in 0..m {
        if eqs[a] == NO_EQUATION {
            continue;
        }
        for c in 0..m {
            if eqs[c] == NO_EQUATION {
                continue;
            }
            let v = -force * d[a * m + c] + w * f[a] * (gradient[c] - f[c]);
            if v != 0.0 {
                unsymmetric.push((eqs[a], eqs[c], v));
            }
        }
    }
    if let Some(j) = multiplier {
        for c in 0..m {
            if eqs[c] != NO_EQUATION && gradient[c] != f[c] {
                unsymmetric.push((j, eqs[c], -w * (gradient[c] - f[c])));
            }
        }
    }
}

/// The residual and the tangent of the Newton scheme's contact system, one evaluation at a time,
/// for finite-difference checks of the tangent (`tests/friction.rs`): not part of the solver's
/// interface.
#[doc(hidden)]
pub struct Probe<'a, const D: usize = 2, K: NewtonDimension<D> = crate::fe::ElementKind> {
    system: ContactSystem<'a, D, K>,
    general: GeneralPattern,
}

/// One evaluation of a [`Probe`].
#[doc(hidden)]
pub struct ProbeEvaluation {
    pub residual: Vec<f64>,
    /// Dense, row-major: `tangent[i][j] = dR_i / dx_j`.
    pub tangent: Vec<Vec<f64>>,
    pub symmetric: bool,
    /// The frictional status of every frictional row.
    pub statuses: Vec<Status>,
}

impl<'a, const D: usize, K: NewtonDimension<D>> Probe<'a, D, K> {
    /// The system of `model`'s first load step, every frictional point with the committed
    /// plastic slip `committed` along each of its tangents.
    pub fn new(model: &'a Model<D, K>, committed: f64) -> Result<Self> {
        Self::with_committed(model, |_| [committed; MAX_TANGENTS])
    }

    /// The same with the committed plastic slip of each frictional point given by its row
    /// (components along the row's tangents).
    pub fn with_committed(
        model: &'a Model<D, K>,
        committed: impl Fn(&Constraint<D>) -> Tangential,
    ) -> Result<Self> {
        let mut system = ContactSystem::new(model, None, None, HashMap::new())?;
        system.committed = system
            .rows
            .iter()
            .filter(|r| !r.tangents.is_empty())
            .map(|r| {
                let mut slip = committed(r);
                slip[r.tangents.len()..].iter_mut().for_each(|s| *s = 0.0);
                (row_key(r), Committed::at_plastic_slip(slip))
            })
            .collect();
        // past the first evaluation, which closes rows to hold free bodies (and numbers the
        // multipliers: a search at another state keeps them)
        system.evaluations = 1;
        system.remember_multipliers();
        let general = GeneralPattern::from_symmetric(&system.pattern);
        Ok(Probe { system, general })
    }

    /// How many unknowns the system has: the free displacements, then the multipliers.
    pub fn unknown_count(&self) -> usize {
        self.general.n
    }

    /// The free unknowns of the global displacement `u`.
    pub fn unknowns(&self, u: &[f64]) -> Vec<f64> {
        self.system
            .sys
            .constraints
            .free_dofs()
            .iter()
            .map(|&d| u[d])
            .collect()
    }

    /// The unknowns at a solved state with Lagrange multipliers: the free displacements of `u`,
    /// then the scaled normal and tangential multipliers `lambda / rho` of `state`'s rows; the
    /// rows active in `state` start active. Augmented-Lagrangian rows take the state's forces
    /// as their Uzawa multipliers and its committed stick points.
    pub fn unknowns_at(&mut self, u: &[f64], state: &ContactState<D>) -> Vec<f64> {
        let mut x = self.unknowns(u);
        x.resize(self.general.n, 0.0);
        let system = &mut self.system;
        for (i, r) in state.rows.iter().enumerate() {
            let key = row_key(r);
            let Some(k) = system.rows.iter().position(|s| row_key(s) == key) else {
                continue;
            };
            system.active.insert(key, state.active[i]);
            if let RowLaw::Penalty {
                update: Some(_), ..
            } = system.law(r)
            {
                // the augmented Lagrangian at its converged Uzawa multipliers
                system.augmentation.insert(key, state.forces[i]);
                system.multipliers_current = true;
                if let Some(f) = &state.friction[i] {
                    system.tangential_augmentation.insert(key, f.force);
                    system
                        .committed
                        .insert(key, Committed::at_plastic_slip(f.committed));
                }
            }
            if let Some(j) = system.multiplier[k] {
                x[j] = state.forces[i] / system.rho;
            }
            if let (Some(j), Some(f)) = (system.tangential[k], &state.friction[i]) {
                for a in 0..r.tangents.len() {
                    x[j + a] = f.force[a] / system.rho;
                }
            }
        }
        x
    }

    pub fn evaluate(&mut self, x: &[f64]) -> Result<ProbeEvaluation> {
        let n = self.general.n;
        let mut residual = vec![0.0; n];
        let mut tangent = Tangent {
            values: vec![0.0; self.general.nnz()],
            symmetric: true,
            multipliers: 0,
            scale: 1.0,
            elimination: None,
            indefinite_block: false,
        };
        let version = self.system.version;
        self.system
            .evaluate(x, &self.general, &mut residual, &mut tangent)?;
        if self.system.version != version {
            // the rows at x couple new equations (a slave node slid onto another facet): the
            // evaluation stopped at the new pattern; evaluate again on it
            self.general = GeneralPattern::from_symmetric(&self.system.pattern);
            tangent.values = vec![0.0; self.general.nnz()];
            self.system
                .evaluate(x, &self.general, &mut residual, &mut tangent)?;
        }
        let g = &self.general;
        let mut dense = vec![vec![0.0; n]; n];
        for j in 0..n {
            for k in g.col_ptr[j]..g.col_ptr[j + 1] {
                dense[g.row_idx[k]][j] = tangent.values[k];
            }
        }
        let statuses = self
            .system
            .rows
            .iter()
            .filter_map(|r| self.system.status.get(&row_key(r)).map(|b| b.0))
            .collect();
        Ok(ProbeEvaluation {
            residual,
            tangent: dense,
            symmetric: tangent.symmetric,
            statuses,
        })
    }
}
