//! The active-set Newton loop for frictionless small-strain contact, written once against
//! [`Constraint`] rows for every enforcement method (see [`crate::contact::enforcement`]).
//!
//! Unknowns: free displacements `u` and one contact force `lambda_i >= 0` per row (compression
//! positive). Equilibrium `K u = f + B^T lambda`; complementarity `g >= 0`, `lambda >= 0`,
//! `g lambda = 0`. Each iteration solves the linear problem of the current active set, then
//! updates the set: an active row whose force turns tensile is released, an inactive row that
//! penetrates is activated (for penalty-type methods: a row is active when its trial force
//! `lambda_k - kappa A g` is compressive; for perturbed Lagrangian rows with a consistent
//! multiplier mass, which keep their multipliers, an active row stays while `lambda >= 0` and
//! an inactive one closes when `g + C lambda < 0`). The loop ends with a [`Termination`] reason.
//!
//! The penalty predictor (Lagrange multipliers and elimination): a set that is too small lets
//! the body penetrate far beyond its contact zone, and the next set, every penetrating row, is
//! far too large. The multipliers of a too-large set are tensile only at the edges of the zone
//! (the gap is forced shut there), so the loop would open one row per edge and iteration, a
//! count that grows with the mesh. At the first set that grows, the loop therefore hands the
//! set to a penalty iteration, `(K + sum kappa A_i b_i b_i^T) u = f - sum kappa A_i g0_i b_i`
//! with the rule "active while compressive", whose tension spreads over many rows and sheds
//! them together; it runs at `kappa = E / L` (the largest Young's modulus over the model size)
//! and then at 100 times as much per level up to the stiffness scale, each level from the set of
//! the one before, and the multiplier loop resumes from its set (`Kernel::penalty_predictor`).
//! Its iterations are in the history and count against the iteration limits. A level whose
//! set comes back (the penalty iteration cycles) ends there. A penalty iterate is never the
//! answer: the loop ends only on a multiplier iterate whose set is stable.
//!
//! Work limit: a loop takes at most `limits.iteration_dofs / dofs` iterations (at least one),
//! and an iteration of the minimum-norm Schur path (dependent Lagrange rows), which solves once
//! per active row, counts those solves too; when the limit is below `solver.max_iterations`
//! and reached, the loop ends with [`Termination::WorkLimit`], saying how far the set got and
//! how to raise the limit.
//!
//! Cycling: for the methods without a multiplier iteration of their own (Lagrange,
//! elimination, penalty, perturbed Lagrangian) the set alone determines the iterate, so a set
//! chosen a second time in one loop (the sets are kept in a hash set) repeats its iterate and
//! the loop would cycle (Murty, *Linear Complementarity*, 1988, ch. 4: pivoting schemes cycle
//! on degenerate problems, here a point with zero force at zero gap). The iteration is marked
//! in the history (`repeated_set`). The remedy (`solver.cycling_remedy: "hold"`, the default)
//! holds the rows that changed status at least twice closed while their force (multiplier or
//! a penalty row's trial force) is not tensile beyond the force tolerance: the rule a Lagrange
//! row already follows, a hysteresis band for penalty rows, whose rule opens a row whose trial
//! force is not compressive. A set that repeats under the remedy, or with it `"off"`, ends the
//! loop with [`Termination::ActiveSetCycling`] naming the points and what to change.
//!
//! Linear algebra: `M = K + sum_i w_i b_i b_i^T` over the active rows, factored by sparse
//! Cholesky; the pattern includes every candidate row, so its symbolic analysis is done once.
//! Lagrange multipliers come from the Schur complement `S = B M^-1 B^T` (dense, one column per
//! active row) with `w = rho` (an augmentation that leaves the solution unchanged and makes `M`
//! definite even for bodies held only by contact). `S` is decomposed by Jacobi rotations; its
//! null eigenvalues are the rank deficiency of the multiplier system (duplicated constraints
//! of a two-pass discretization), and the pseudo-inverse picks the minimum-norm multipliers,
//! so the displacement is still returned when it exists. Perturbed Lagrangian rows with a
//! consistent multiplier mass (standard mortar) are solved in the same saddle-point system with
//! their perturbation `C` on its multiplier block, the other rows of the penalty family entering
//! it with their weights (see `Kernel::saddle_ldlt`).
//!
//! Rigid modes: before each solve the rigid modes of every body are tested against the
//! prescribed dofs and the ACTIVE rows (`crate::model::rigid`, three modes per body). The first
//! active set closes, besides the rows with zero gap, the rows at the smallest gap of a body that
//! could otherwise move, until its modes are held (closest points first). A later set that
//! leaves a motion `m` free is solved with springs `S = STABILIZATION K_ee` on the bodies it
//! moves and with the load's component along `m` removed, so that the iterate carries no
//! arbitrary rigid motion and only chooses the next set; if the load pushes along `m`, the body
//! is moved along the push until its first open row closes. A set that leaves a motion free is
//! never `Converged`: the loop ends with `Singular` naming the body, the mode and why. The
//! factorizations report pivots that are zero relative to the matrix or needed regularization
//! ([`crate::solver::sparse`]), and a non-finite iterate is an error naming where it appeared.

use crate::contact::discretization::Discretize;
use crate::contact::enforcement::{method, method as enforcement_method, Method};
use crate::contact::rows::{reference_areas, rows_at, ReferenceAreas};
pub use crate::contact::state::{
    ContactState, Departure, IterationRecord, StepRecord, Termination,
};
use crate::contact::{row_key, Constraint, RowKey};
use crate::error::{Error, Result};
use crate::io::scene::{ContactGeometry, CyclingRemedy, FactorUpdate, MultiplierUpdate};
use crate::model::rigid::{FreeMode, RigidModes};
use crate::model::Model;
use crate::solver::conditioning::{
    condition_estimate_symmetric, condition_estimate_symmetric_columns, EQUILIBRIUM_ROUND_OFF,
};
use crate::solver::constraints::{AffineConstraints, ConstraintBuilder, ConstraintError};
use crate::solver::dense::symmetric_eigen;
use crate::solver::linear::{assemble_with, finish, LinearSystem, Solution, Timings, NO_EQUATION};
use crate::solver::low_rank::{LowRankBase, Operator};
use crate::solver::sparse::{Cholesky, PatternBuilder};
use std::collections::{HashMap, HashSet};
use std::rc::Rc;
use std::time::Instant;

/// Largest active set whose rank deficiency is measured for methods without multipliers.
pub const RANK_CHECK_LIMIT: usize = 500;

/// Largest active set of a multiplier method whose rank deficiency is measured, and whose
/// dependent rows may be solved by the dense pseudo-inverse of the Schur complement: both
/// hold an `m x m` dense matrix and cost `O(m^3)` (2000 rows: 32 MB, a few seconds). Above it
/// the saddle-point LDL^T is tried directly, and dependent rows are reported as a singular
/// system instead of exhausting memory.
pub const DENSE_MULTIPLIER_LIMIT: usize = 2000;

/// Most steps of iterative refinement of one LDL^T solve (it stops earlier once the correction
/// no longer halves or reaches round-off).
pub const MAX_REFINEMENT: usize = 10;

/// A row in equation space: free equations, coefficients, gap with prescribed values folded in.
struct EqRow {
    eqs: Vec<usize>,
    coeffs: Vec<f64>,
    g0: f64,
}

impl EqRow {
    fn dot(&self, x: &[f64]) -> f64 {
        self.eqs
            .iter()
            .zip(&self.coeffs)
            .map(|(&e, c)| c * x[e])
            .sum()
    }
    fn add_to(&self, scale: f64, y: &mut [f64]) {
        for (&e, c) in self.eqs.iter().zip(&self.coeffs) {
            y[e] += scale * c;
        }
    }
}

/// Solve the contact problem of `model` (each pair by its own method, the pairs of one family,
/// see [`crate::contact::enforcement::Family`]) in the load steps of `model.solver`: step `k` of `n`
/// applies the load factor `k / n` and starts from the active set of step `k - 1` (the only
/// state frictionless contact has to carry). The solve stops at the first step that does not
/// converge; its termination is the solve's.
pub fn solve<const D: usize, K: ContactStep<D>>(
    model: &Model<D, K>,
    progress: &mut dyn FnMut(&str),
) -> Result<Solution<D>> {
    crate::solver::iterative::refuse_unless_admitted(model)?;
    let n = model.solver.load_steps;
    let mut iterative: Option<crate::solver::iterative::IterativeRecord> = None;
    let mut previous: Option<HashSet<RowKey>> = None;
    let mut records: Vec<StepRecord> = Vec::new();
    let mut start: Option<Vec<f64>> = None;
    // the committed plastic slip of every frictional point (Coulomb pairs)
    let mut friction: HashMap<RowKey, crate::contact::friction::Committed> = HashMap::new();
    let mut departures: Vec<Departure> = Vec::new();
    let mut history: Vec<IterationRecord> = Vec::new();
    let mut timings = crate::solver::linear::Timings::default();
    let mut step = 1;
    loop {
        let t = step as f64 / n as f64;
        let at = model.at_step(step, n);
        let mut solution = K::solve_step(
            &at,
            previous.take(),
            start.take(),
            std::mem::take(&mut friction),
            progress,
        )?;
        timings.accumulate(&solution.timings);
        solution.timings = timings.clone();
        crate::solver::iterative::IterativeRecord::merge(&mut iterative, &solution.iterative);
        solution.iterative = iterative.clone();
        let state = solution.contact.as_mut().expect("a contact solve");
        records.push(StepRecord {
            step,
            load_factor: t,
            termination: state.termination.clone(),
            iterations: state.iterations,
            geometry_updates: state.geometry_updates,
            geometry_changes: std::mem::take(&mut state.geometry_changes),
            friction: state.friction_summary(None),
        });
        state.steps = records.clone();
        for r in &mut state.history {
            r.step = step;
            r.geometry_update = r.geometry_update.max(1);
        }
        history.append(&mut state.history);
        state.history = history.clone();
        departures.append(&mut state.departures);
        state.departures = departures.clone();
        if step == n || state.termination != Termination::Converged {
            return Ok(solution);
        }
        previous = Some(active_keys(state));
        friction = state.friction_history();
        start = Some(solution.u);
        step += 1;
    }
}

/// The identities of the active rows of `state`.
pub(crate) fn active_keys<const D: usize>(state: &ContactState<D>) -> HashSet<RowKey> {
    state
        .rows
        .iter()
        .zip(&state.active)
        .filter(|(_, &a)| a)
        .map(|(r, _)| row_key(r))
        .collect()
}

/// One load step of a contact solve in the model's dimension (see [`solve`]): in 2D every
/// scheme (active set or Newton, reference or current geometry, friction); in 3D the
/// reference configuration, by the active-set scheme or by the Newton scheme (which solves
/// Coulomb friction).
pub trait ContactStep<const D: usize>: Discretize<D> {
    fn solve_step(
        model: &Model<D, Self>,
        previous: Option<HashSet<RowKey>>,
        start: Option<Vec<f64>>,
        friction: HashMap<RowKey, crate::contact::friction::Committed>,
        progress: &mut dyn FnMut(&str),
    ) -> Result<Solution<D>>;
}

impl ContactStep<2> for crate::fe::ElementKind {
    fn solve_step(
        model: &Model,
        previous: Option<HashSet<RowKey>>,
        start: Option<Vec<f64>>,
        friction: HashMap<RowKey, crate::contact::friction::Committed>,
        progress: &mut dyn FnMut(&str),
    ) -> Result<Solution> {
        solve_step(model, previous, start, friction, progress)
    }
}

impl ContactStep<3> for crate::fe3d::SolidKind {
    fn solve_step(
        model: &crate::model::Model3,
        previous: Option<HashSet<RowKey>>,
        start: Option<Vec<f64>>,
        friction: HashMap<RowKey, crate::contact::friction::Committed>,
        progress: &mut dyn FnMut(&str),
    ) -> Result<Solution<3>> {
        if model.solver.scheme == crate::io::scene::Scheme::Newton {
            // the Newton scheme in the reference geometry (small strain), frictionless or
            // with Coulomb friction: the 2D code path, generic over the dimension
            return crate::solver::contact_newton::solve_step(
                model, previous, start, friction, progress,
            );
        }
        solve_at(model, None, previous.as_ref(), None, progress)
    }
}

/// One load step, starting from the active rows `previous` and (current geometry) the
/// configuration `start` of the last step, if given.
fn solve_step(
    model: &Model,
    mut previous: Option<HashSet<RowKey>>,
    start: Option<Vec<f64>>,
    friction: HashMap<RowKey, crate::contact::friction::Committed>,
    progress: &mut dyn FnMut(&str),
) -> Result<Solution> {
    if model.solver.scheme == crate::io::scene::Scheme::Newton {
        return crate::solver::contact_newton::solve_step(
            model, previous, start, friction, progress,
        );
    }
    match model.physics.contact_geometry {
        ContactGeometry::Reference => solve_at(model, None, previous.as_ref(), None, progress),
        ContactGeometry::Current => {
            // fixed point on the geometry: rows linearized at the last solution u_k,
            // g(u) = g(X + u_k) + c(X + u_k) . (u - u_k); each update starts from the active
            // set of the last one (rows are matched by their identity, `RowKey`)
            let mut u = start.unwrap_or_else(|| vec![0.0; model.dof_count]);
            let mut departures: Vec<Departure> = Vec::new();
            let mut history: Vec<IterationRecord> = Vec::new();
            let mut forces: Option<HashMap<RowKey, f64>> = None;
            let mut timings = crate::solver::linear::Timings::default();
            let mut iterative: Option<crate::solver::iterative::IterativeRecord> = None;
            let mut changes: Vec<f64> = Vec::new();
            let max_updates = model.solver.max_geometry_updates;
            let areas = reference_areas(model)?;
            for update in 1..=max_updates {
                let mut solution = solve_at(
                    model,
                    Some((&u, &areas)),
                    previous.as_ref(),
                    forces.as_ref(),
                    progress,
                )?;
                let state = solution.contact.as_mut().expect("a contact solve");
                if let Some(previous) = &previous {
                    for (pair, _, body, node, _) in slid_off(previous, &state.rows) {
                        let b = &model.bodies[body];
                        let x = b.mesh.nodes[node];
                        let departure = Departure {
                            pair,
                            body,
                            node,
                            point: vec![x[0] + u[b.dof(node, 0)], x[1] + u[b.dof(node, 1)]],
                            update,
                        };
                        if !departures
                            .iter()
                            .any(|d: &Departure| d.body == body && d.node == node)
                        {
                            departures.push(departure);
                        }
                    }
                }
                state.departures = departures.clone();
                timings.accumulate(&solution.timings);
                solution.timings = timings.clone();
                crate::solver::iterative::IterativeRecord::merge(
                    &mut iterative,
                    &solution.iterative,
                );
                solution.iterative = iterative.clone();
                let state = solution.contact.as_mut().expect("a contact solve");
                for r in &mut state.history {
                    r.geometry_update = update;
                }
                history.append(&mut state.history);
                state.history = history.clone();
                previous = Some(active_keys(state));
                forces = Some(
                    state
                        .rows
                        .iter()
                        .zip(&state.forces)
                        .map(|(r, &f)| (row_key(r), f))
                        .collect(),
                );
                let scale = solution
                    .u
                    .iter()
                    .fold(0.0f64, |m, v| m.max(v.abs()))
                    .max(f64::MIN_POSITIVE);
                let change = solution
                    .u
                    .iter()
                    .zip(&u)
                    .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
                    / scale;
                let state = solution.contact.as_mut().expect("a contact solve");
                state.geometry_updates = update;
                changes.push(change);
                state.geometry_changes = changes.clone();
                if change <= model.solver.geometry_tolerance
                    || state.termination != Termination::Converged
                {
                    return Ok(solution);
                }
                if update == max_updates {
                    state.termination = Termination::IterationLimit;
                    return Ok(solution);
                }
                u = solution.u;
            }
            unreachable!("the loop returns")
        }
    }
}

/// The rows active in `previous` that have no row in `rows` (their slave nodes left the master
/// surface), in order.
fn slid_off<const D: usize>(previous: &HashSet<RowKey>, rows: &[Constraint<D>]) -> Vec<RowKey> {
    let now: HashSet<RowKey> = rows.iter().map(row_key).collect();
    let mut lost: Vec<RowKey> = previous
        .iter()
        .filter(|k| !now.contains(k))
        .copied()
        .collect();
    lost.sort();
    lost
}

/// Newton's geometric term of the contact forces, for the rows whose gap has a second
/// derivative `H` (see [`gap_second_derivative`]): with the contact force `lambda n(u)` on the
/// slave node, `n(u) ~ n(u_k) + H (u - u_k)`, so equilibrium linearized at `u_k` with the
/// forces `lambda_k` of the last geometry update reads
/// `(K - lambda_k H) u = f + B_k^T lambda - lambda_k H u_k`. With it the geometry updates are
/// Newton iterations (quadratic convergence) instead of a fixed point.
fn add_geometric_stiffness<const D: usize, K: Discretize<D>>(
    model: &Model<D, K>,
    rows: &[Constraint<D>],
    u: &[f64],
    forces: &HashMap<RowKey, f64>,
    sys: &mut LinearSystem,
) {
    for r in rows {
        let Some(&lambda) = forces.get(&row_key(r)) else {
            continue;
        };
        if lambda == 0.0 {
            continue;
        }
        let b = &model.bodies[r.slave_body];
        let dofs: [usize; D] = std::array::from_fn(|i| b.dof(r.slave_node, i));
        let x = b.mesh.nodes[r.slave_node];
        let x_s: [f64; D] = std::array::from_fn(|i| x[i] + u[dofs[i]]);
        let Some(h) = K::slave_curvature(model, r, x_s) else {
            continue;
        };
        let eqs: [usize; D] = std::array::from_fn(|i| sys.eq(dofs[i]));
        if eqs.contains(&NO_EQUATION) {
            continue;
        }
        let block: Vec<f64> = h.iter().map(|v| -lambda * v).collect();
        sys.pattern.scatter(&eqs, &block, &mut sys.k);
        for a in 0..D {
            sys.rhs[eqs[a]] -= lambda * (0..D).map(|c| h[D * a + c] * u[dofs[c]]).sum::<f64>();
        }
    }
}

/// One contact solve with the rows of `rows_at(model, current)`; `previous` (the active rows of the
/// last geometry update) starts the active set together with the rows closed at `u`;
/// `previous_forces` (of the last geometry update) give Newton's geometric term.
fn solve_at<const D: usize, K: Discretize<D>>(
    model: &Model<D, K>,
    current: Option<(&[f64], &ReferenceAreas)>,
    previous: Option<&HashSet<RowKey>>,
    previous_forces: Option<&HashMap<RowKey, f64>>,
    progress: &mut dyn FnMut(&str),
) -> Result<Solution<D>> {
    let u = current.map(|(u, _)| u);
    let configuration = u.map(|u| u.to_vec());
    let mut timings = Timings::default();
    let t = Instant::now();
    progress("contact search");
    let mut rows = rows_at(model, current)?;
    timings.contact_search = t.elapsed().as_secs_f64();
    let t = Instant::now();
    // each pair is enforced by its own method; the pairs of one solve share a family
    // (validated in the model), whose first member drives the loop
    crate::solver::refuse_obstacles(model, &rows)?;
    let method = method(&model.contact[0].enforcement).kernel();
    progress("assembling");
    let blocks: Vec<Vec<usize>> = rows.iter().map(|r| r.dofs.clone()).collect();
    let constraints = AffineConstraints::dirichlet(&model.prescribed);
    let mut eq_rows: Vec<EqRow> = rows
        .iter()
        .map(|r| {
            let mut out = EqRow {
                eqs: Vec::new(),
                coeffs: Vec::new(),
                g0: r.g0,
            };
            for (&d, &c) in r.dofs.iter().zip(&r.coeffs) {
                match constraints.equations()[d] {
                    NO_EQUATION => out.g0 += c * constraints.constants()[d],
                    e => {
                        out.eqs.push(e);
                        out.coeffs.push(c);
                    }
                }
            }
            // a row whose free part is round-off of its full gradient acts on prescribed dofs only
            let full = r.coeffs.iter().fold(0.0f64, |a, c| a.max(c.abs()));
            let free = out.coeffs.iter().fold(0.0f64, |a, c| a.max(c.abs()));
            if free <= 1e-12 * full {
                out.eqs.clear();
                out.coeffs.clear();
            }
            out
        })
        .collect();
    // the factor's ordering and symbolic analysis run beside the assembly of the values
    // (with CG + AMG nothing is factored: no symbolic analysis, no updates of a factor)
    let use_amg = model.solver.linear_solver == crate::io::scene::LinearSolver::CgAmg;
    let trailing = trailing_equations(
        &eq_rows,
        model.solver.factor_update,
        constraints.free_count(),
    );
    let points = (!use_amg).then(|| model.equation_points(constraints.free_dofs()));
    let (mut sys, analysis) = assemble_with(model, constraints, &blocks, |pattern| {
        points.map(|points| {
            Cholesky::analyse_with_trailing_at(
                pattern,
                &trailing,
                Some(&points),
                &model.factor_limit,
            )
        })
    });
    sys.check_assembled(model)?;
    if let Some(r) = rows
        .iter()
        .find(|r| !r.g0.is_finite() || r.coeffs.iter().any(|c| !c.is_finite()))
    {
        return Err(crate::solver::linear::non_finite_at(
            model,
            "the contact gap or its gradient",
            r.g0,
            &format!(
                "the slave node at ({}, {}) of contact '{}'",
                r.point[0], r.point[1], model.contact[r.pair].name
            ),
            "when the contact rows were evaluated",
        ));
    }
    if let (Some(u), Some(forces), true) = (u, previous_forces, model.solver.geometric_stiffness) {
        add_geometric_stiffness(model, &rows, u, forces, &mut sys);
    }
    // A row on prescribed dofs only holds by itself when its gap is zero (e.g. a tie row along
    // a roller); it is dropped, since as a constraint it would only make the multiplier system
    // singular. If its gap is not zero the data contradict each other.
    let size = model.size();
    if let Some((r, e)) = rows
        .iter()
        .zip(&eq_rows)
        .find(|(_, e)| e.eqs.is_empty() && e.g0.abs() > 1e-12 * size)
    {
        return Err(Error::invalid(
            &model.source,
            format!("contact '{}'", model.contact[r.pair].name),
            format!("the constraint of the slave node at ({}, {}) involves only prescribed dofs and their values violate it (gap {:.3e})", r.point[0], r.point[1], e.g0),
            "make the supports of the two sides agree at this node, or remove one of them",
        ));
    }
    let keep: Vec<bool> = eq_rows.iter().map(|e| !e.eqs.is_empty()).collect();
    let mut k = 0;
    rows.retain(|_| {
        k += 1;
        keep[k - 1]
    });
    eq_rows.retain(|e| !e.eqs.is_empty());
    let perturbation = perturbation(model, &rows);
    let coupled = perturbation.iter().any(|c| !c.is_empty());
    timings.assembly = t.elapsed().as_secs_f64();

    let t = Instant::now();
    progress("contact iterations");
    let amg = use_amg
        .then(|| crate::solver::iterative::AmgSolver::new(model, sys.constraints.free_dofs()));
    if amg.is_some() && coupled {
        return Err(crate::solver::iterative::refuse_saddle_point(model));
    }
    let chol = analysis
        .transpose()
        .map_err(|e| sys.factor_error(model, e))?;
    let update_rank = match amg {
        Some(_) => 0,
        None => update_rank(model.solver.factor_update, sys.n),
    };
    let update_columns = match (model.solver.factor_update, &chol) {
        (FactorUpdate::LowRank, _) => MAX_UPDATE_RANK,
        (_, Some(chol)) => new_columns_bound(&chol.work()),
        (_, None) => 0,
    };
    let initial_active = previous.map(|previous| {
        rows.iter()
            .map(|r| {
                let gap = u.map_or(r.g0, |u| r.gap(u));
                previous.contains(&row_key(r)) || gap <= 1e-14 * size
            })
            .collect()
    });
    let eq_dof = sys.constraints.free_dofs().to_vec();
    let mut kernel = Kernel {
        prepared_for: None,
        initial_active,
        history: Vec::new(),
        condition: None,
        model,
        sys: &sys,
        rows: &eq_rows,
        constraints: &rows,
        modes: RigidModes::new(model),
        eq_dof,
        k: sys.k.clone(),
        rhs: sys.rhs.clone(),
        free: None,
        iteration: 0,
        chol,
        saddle: if method == Method::Lagrange || coupled {
            Saddle::new(&sys, &eq_rows, &perturbation, &model.factor_limit)
                .map_err(|e| sys.factor_error(model, e))?
        } else {
            None
        },
        perturbation,
        linear_solver: "cholesky",
        extra_solves: 0,
        cache: None,
        low_rank: None,
        update_columns,
        update_rank,
        deferred_condition: update_rank > 0,
        amg,
        last_iterate: None,
        unrefined: None,
        factorizations: 0.0,
        estimate_condition: true,
    };
    let state = kernel.active_set_loop(method, &rows)?;
    kernel.estimate_last_condition();
    let (x, forces, active, termination, iterations) = state;
    let linear_solver = kernel.linear_solver;
    let iterative = kernel.amg.take().map(|amg| amg.record);
    let history = std::mem::take(&mut kernel.history);
    let factor_time = kernel.factorizations;
    timings.factorization = factor_time;
    timings.solve = (t.elapsed().as_secs_f64() - factor_time).max(0.0);

    let u = sys.expand(&x);
    let mut contact_force = vec![0.0; model.dof_count];
    for (r, &f) in rows.iter().zip(&forces) {
        for (&d, &c) in r.dofs.iter().zip(&r.coeffs) {
            contact_force[d] += c * f;
        }
    }
    let gaps: Vec<f64> = rows.iter().map(|r| r.gap(&u)).collect();
    let active_rows: Vec<&EqRow> = eq_rows
        .iter()
        .zip(&active)
        .filter(|(_, &a)| a)
        .map(|(r, _)| r)
        .collect();
    let multipliers = matches!(method, Method::Lagrange | Method::Elimination);
    let rank_limit = if multipliers {
        DENSE_MULTIPLIER_LIMIT
    } else {
        RANK_CHECK_LIMIT
    };
    let rank_deficiency =
        (active_rows.len() <= rank_limit).then(|| rank_deficiency(&active_rows, sys.n));
    let mut solution = finish(model, &sys, u, &contact_force, timings)?;
    solution.iterative = iterative;
    let n_rows = rows.len();
    solution.contact = Some(ContactState {
        rows,
        active,
        forces,
        gaps,
        termination,
        iterations,
        rank_deficiency,
        linear_solver,
        geometry_updates: 1,
        configuration,
        departures: Vec::new(),
        steps: Vec::new(),
        history,
        geometry_changes: Vec::new(),
        friction: vec![None; n_rows],
    });
    Ok(solution)
}

/// The perturbation `C = A^-1 M A^-1 / kappa` of the perturbed Lagrangian over the rows that
/// keep their multipliers (see [`crate::contact::enforcement`]): for each row `i`, the entries
/// `(j, C_ij)`, symmetric, the diagonal included; empty for every other row. Rows are coupled
/// when their pair's method uses the multiplier mass and the row carries a consistent one
/// ([`Constraint::mass`], standard mortar); the mass line of row `i` names slave nodes, matched
/// to the rows of the same pair, pass and direction. `M_ij` is in area units and the rows' forces
/// are nodal forces `lambda_i = A_i p_i`, so `int Phi_i (g_h + p_h / kappa) = 0` divided by
/// `A_i` is `g_i + sum_j M_ij lambda_j / (kappa A_i A_j) = 0`.
fn perturbation<const D: usize, K: Discretize<D>>(
    model: &Model<D, K>,
    rows: &[Constraint<D>],
) -> Vec<Vec<(usize, f64)>> {
    let index: HashMap<RowKey, usize> = rows
        .iter()
        .enumerate()
        .map(|(i, r)| (row_key(r), i))
        .collect();
    let mut c: Vec<std::collections::BTreeMap<usize, f64>> = vec![Default::default(); rows.len()];
    for (i, r) in rows.iter().enumerate() {
        let enforcement = enforcement_method(&model.contact[r.pair].enforcement);
        if r.mass.is_empty() || !enforcement.uses_multiplier_mass() {
            continue;
        }
        let kappa = enforcement
            .kappa()
            .expect("a method using the multiplier mass has a kappa");
        let (pair, pass, body, _, direction) = row_key(r);
        for &(node, m) in &r.mass {
            if let Some(&j) = index.get(&(pair, pass, body, node, direction)) {
                // half from each of the two rows' lines: M is symmetric
                let v = 0.5 * m / (kappa * r.area * rows[j].area);
                *c[i].entry(j).or_default() += v;
                *c[j].entry(i).or_default() += v;
            }
        }
    }
    c.into_iter().map(|c| c.into_iter().collect()).collect()
}

/// The saddle-point pattern `[[K, B^T], [B, D]]` over all candidate rows, analysed once; with a
/// perturbation `C`, `D` holds `C` and `C C` and the coupling block `B^T C` as well (see
/// [`Kernel::saddle_ldlt`]).
struct Saddle {
    pattern: crate::solver::sparse::SymmetricPattern,
    /// Position in `pattern` of each stored entry of the stiffness pattern.
    k_positions: Vec<usize>,
    ldlt: crate::solver::sparse::Ldlt,
    /// Both triangles of `pattern` and its LU analysis, made on the first LU fallback and reused
    /// by every later one.
    lu: std::cell::OnceCell<
        Option<(
            crate::solver::sparse::GeneralPattern,
            crate::solver::sparse::Lu,
        )>,
    >,
    /// The case's bound on the work of a factorization (for the LU fallback).
    limit: crate::solver::sparse::WorkLimit,
}

impl Saddle {
    /// Solve with the saddle matrix whose upper triangle is `values` by LU (the fallback when
    /// LDL^T refuses); `None` when LU fails or gives a non-finite result.
    fn lu_solve(&self, values: &[f64], rhs: &[f64]) -> Option<Vec<f64>> {
        let (general, lu) = self
            .lu
            .get_or_init(|| {
                let general = crate::solver::sparse::GeneralPattern::from_symmetric(&self.pattern);
                crate::solver::sparse::Lu::analyse(&general, &self.limit)
                    .ok()
                    .map(|lu| (general, lu))
            })
            .as_ref()?;
        let factor = lu.factor(general, &general.symmetric_values(values)).ok()?;
        let mut x = rhs.to_vec();
        factor.solve_in_place(&mut x);
        x.iter().all(|v| v.is_finite()).then_some(x)
    }
}

impl Saddle {
    fn new(
        sys: &LinearSystem,
        rows: &[EqRow],
        perturbation: &[Vec<(usize, f64)>],
        limit: &crate::solver::sparse::WorkLimit,
    ) -> Result<Option<Saddle>, crate::solver::sparse::FactorError> {
        let (n, m) = (sys.n, rows.len());
        let mut b = PatternBuilder::new(n + m);
        let p = &sys.pattern;
        for j in 0..n {
            for k in p.col_ptr[j]..p.col_ptr[j + 1] {
                b.add_block(&[p.row_idx[k], j]);
            }
        }
        for (i, row) in rows.iter().enumerate() {
            for &e in &row.eqs {
                b.add_block(&[e, n + i]);
            }
            // C, C C and B^T C
            for &(k, _) in &perturbation[i] {
                b.add_block(&[n + i, n + k]);
                for &(j, _) in &perturbation[k] {
                    b.add_block(&[n + i, n + j]);
                }
                for &e in &rows[k].eqs {
                    b.add_block(&[e, n + i]);
                }
            }
        }
        let pattern = b.build();
        let mut k_positions = Vec::with_capacity(p.nnz());
        for j in 0..n {
            for k in p.col_ptr[j]..p.col_ptr[j + 1] {
                let Some(position) = pattern.position(p.row_idx[k], j) else {
                    return Ok(None);
                };
                k_positions.push(position);
            }
        }
        // a factor above the limit is refused with its size; another failure of the analysis
        // leaves the saddle-point path out, as before
        let ldlt = match crate::solver::sparse::Ldlt::analyse(&pattern, n, limit) {
            Ok(ldlt) => ldlt,
            Err(e @ crate::solver::sparse::FactorError::TooLarge { .. }) => return Err(e),
            Err(_) => return Ok(None),
        };
        Ok(Some(Saddle {
            pattern,
            k_positions,
            ldlt,
            lu: std::cell::OnceCell::new(),
            limit: *limit,
        }))
    }
}

/// An iterate of the penalty family solved with `operator` for the Uzawa forces `lambda_k`,
/// neither judged by its accurate equilibrium residual nor refined yet.
struct Unrefined {
    operator: Rc<Operator>,
    lambda_k: Vec<f64>,
    x: Vec<f64>,
}

struct Kernel<'a, const D: usize, K: Discretize<D>> {
    /// Whether [`Kernel::factor`] estimates the condition number of what it factors (not for
    /// the penalty predictor, whose systems are never the answer's).
    estimate_condition: bool,
    /// The active set `prepare` last ran for.
    prepared_for: Option<Vec<bool>>,
    model: &'a Model<D, K>,
    sys: &'a LinearSystem,
    rows: &'a [EqRow],
    /// The same rows in global dofs (rigid-mode test, messages).
    constraints: &'a [Constraint<D>],
    modes: RigidModes<'a, D, K>,
    /// Global dof of each equation.
    eq_dof: Vec<usize>,
    /// The stiffness of the current solve: `K_ff`, plus the stabilizing springs while a rigid
    /// motion is free (see [`Kernel::prepare`]).
    k: Vec<f64>,
    /// The right-hand side of the current solve: `f_f - K_fp u_p`, without its component
    /// along the free rigid motions while they are stabilized.
    rhs: Vec<f64>,
    /// The rigid motions the current active set leaves free, if any.
    free: Option<Free>,
    /// The iteration of the active-set loop (for messages).
    iteration: usize,
    /// The symbolic analysis of `M` (`None` with CG + AMG, which factors nothing).
    chol: Option<Cholesky>,
    /// CG + AMG (`solver.linear_solver: "cg_amg"`), with its hierarchy kept between
    /// iterations ([`crate::solver::iterative`]).
    amg: Option<crate::solver::iterative::AmgSolver>,
    /// The last iterate of the CG path, the start of the next solve.
    last_iterate: Option<Vec<f64>>,
    /// An iterate of the penalty family whose iterative refinement was put off (see
    /// [`Kernel::regularized`]): refined only if its active set turns out stable.
    unrefined: Option<Unrefined>,
    /// Built only for Lagrange multipliers and for perturbed Lagrangian rows with a consistent
    /// multiplier mass.
    saddle: Option<Saddle>,
    /// The perturbed Lagrangian's consistent perturbation `C` (see [`perturbation`]).
    perturbation: Vec<Vec<(usize, f64)>>,
    linear_solver: &'static str,
    /// Solves of the last iteration beyond its one solve (the minimum-norm Schur path solves
    /// once per active row), counted against the work limit.
    extra_solves: usize,
    /// The last operator (a factorization or a low-rank update of one) with its active set
    /// and weights.
    cache: Option<(Vec<bool>, Vec<f64>, Rc<Operator>)>,
    /// The last factorization of the penalty family's matrix, which later iterations update
    /// by low rank ([`crate::solver::low_rank`]) while few rows changed; `None` when updates
    /// are off.
    low_rank: Option<LowRankBase>,
    /// The most rows an update may change (0: every change refactors).
    update_rank: usize,
    /// The most new columns `A^-1 b_i` an update may solve for: about half the rank at which
    /// their solves cost a factorization ([`new_columns_bound`]).
    update_columns: usize,
    /// With updates on, the condition number is estimated for the last iteration's matrix
    /// only ([`Kernel::estimate_last_condition`]), not for every factored matrix.
    deferred_condition: bool,
    factorizations: f64,
    /// The first active set, when a geometry update starts from the last one's.
    initial_active: Option<Vec<bool>>,
    /// One record per iteration.
    history: Vec<IterationRecord>,
    /// The estimated 1-norm condition number of the last factored system
    /// ([`crate::solver::conditioning`]).
    condition: Option<f64>,
}

type LoopResult = (Vec<f64>, Vec<f64>, Vec<bool>, Termination, usize);

/// Springs `STABILIZATION K_ee` hold a free rigid motion while the active set leaves it free:
/// small enough to leave the elastic part of the iterate unchanged to about this relative
/// amount, large enough that the pivots of the motion stay far above round-off
/// ([`crate::solver::sparse::TINY_PIVOT`]).
pub const STABILIZATION: f64 = 1e-8;

/// A load component along a free motion larger than this share of the load pushes the body
/// (below it, it is round-off of a balanced load).
const PUSH: f64 = 1e-8;

/// The rigid motions an active set leaves free, in equation space.
struct Free {
    /// The body that moves most, its mode, and why.
    mode: FreeMode,
    /// The motions `m_k`, orthonormal in the inner product `a^T S b` of the springs `S`.
    motions: Vec<Vec<f64>>,
}

/// Why a linear solve of the active-set loop failed: a singular system ends the loop with
/// [`Termination::Singular`], a fatal error (a non-finite value) ends the run.
enum StepError {
    Singular(String),
    Fatal(Error),
}

impl From<String> for StepError {
    fn from(msg: String) -> Self {
        StepError::Singular(msg)
    }
}

type Step<T> = std::result::Result<T, StepError>;

/// The most stiffness levels of the penalty predictor ([`Kernel::penalty_predictor`]), and the
/// most iterations at one level.
const PREDICTOR_LEVELS: usize = 12;
const PREDICTOR_LEVEL_ITERATIONS: usize = 30;
/// The factor between the penalties of consecutive levels of the predictor, and the share of
/// status changes (one in this many active rows) at which a level that is not the last hands its
/// set on.
const PREDICTOR_STEP: f64 = 100.0;
const PREDICTOR_SETTLED: usize = 100;

impl<const D: usize, K: Discretize<D>> Kernel<'_, D, K> {
    /// Gap below which a row counts as closed when the active set starts and when a row is
    /// activated: `1e-14` times the model size.
    fn gap_tol(&self) -> f64 {
        let size = self.model.size();
        1e-14 * size
    }

    /// `max |K x - f - B^T lambda|` over the free equations relative to the largest of `|f|`
    /// and `|B^T lambda|` (forces of inactive rows are zero). The product `K x` rounded in
    /// working precision carries an error of about `|K| |x| eps`, itself of the order of
    /// [`EQUILIBRIUM_ROUND_OFF`] on ill-conditioned systems; a residual above that bound is
    /// therefore computed again with `K x` accumulated in twice the precision
    /// ([`SymmetricPattern::residual_accurate`](crate::solver::sparse::SymmetricPattern::residual_accurate)),
    /// so that an iterate the refinement brought to round-off is not reported above it by the
    /// rounding of its own check.
    fn equilibrium_residual(&self, x: &[f64], forces: &[f64], active: &[bool]) -> f64 {
        let plain = self.equilibrium_residual_in(x, forces, active, false);
        if plain > EQUILIBRIUM_ROUND_OFF {
            self.equilibrium_residual_in(x, forces, active, true)
        } else {
            plain
        }
    }

    /// [`Kernel::equilibrium_residual`] with `K x` in working precision, or `accurate`ly.
    fn equilibrium_residual_in(
        &self,
        x: &[f64],
        forces: &[f64],
        active: &[bool],
        accurate: bool,
    ) -> f64 {
        let mut r = vec![0.0; self.sys.n];
        if accurate {
            // rest = f - K x accurately, then K x = f - rest rounded once (an error of
            // eps |K x|, far below the bound, where the plain sum's is eps |K| |x|)
            let mut rest = vec![0.0; self.sys.n];
            self.sys
                .pattern
                .residual_accurate(&self.sys.k, x, &self.sys.rhs, &mut rest);
            r.iter_mut()
                .zip(&self.sys.rhs)
                .zip(&rest)
                .for_each(|((v, f), q)| *v = f - q);
        } else {
            self.sys.pattern.mul(&self.sys.k, x, &mut r);
        }
        let mut contact = vec![0.0; self.sys.n];
        for (i, row) in self.rows.iter().enumerate() {
            if active[i] {
                row.add_to(forces[i], &mut contact);
            }
        }
        let scale = self
            .sys
            .rhs
            .iter()
            .chain(&contact)
            .fold(0.0f64, |m, v| m.max(v.abs()))
            .max(f64::MIN_POSITIVE);
        r.iter()
            .zip(&self.sys.rhs)
            .zip(&contact)
            .fold(0.0f64, |m, ((k, f), c)| {
                let e = (k - f - c).abs();
                if e.is_nan() || e > m {
                    e
                } else {
                    m
                }
            })
            / scale
    }

    /// Factor `K + sum_active w_i b_i b_i^T`.
    /// (The last factorization is kept: the iterative methods repeat the same active set and
    /// weights until the set changes.)
    fn factor(&mut self, active: &[bool], w: &[f64]) -> std::result::Result<Rc<Operator>, String> {
        if let Some((a, ww, f)) = &self.cache {
            if a == active && ww == w {
                return Ok(f.clone());
            }
        }
        let t = Instant::now();
        let values = self.augmented(active, w);
        let Some(chol) = self.chol.as_ref() else {
            return Err("no factorization with CG + AMG (solver.linear_solver)".into());
        };
        let f = Rc::new(
            chol.factor(&self.sys.pattern, &values)
                .map_err(|e| self.sys.factor_error(self.model, e).to_string())?,
        );
        if self.update_rank > 0 {
            self.low_rank = Some(LowRankBase::new(f.clone(), effective_weights(active, w)));
        }
        let f = Rc::new(Operator::Factored(f));
        self.finish_operator(active, w, &values, &f, t);
        Ok(f)
    }

    /// The operator of `K + sum_active w_i b_i b_i^T`: the last factorization updated by low
    /// rank when few enough rows changed since it ([`crate::solver::low_rank`]), else a new
    /// factorization ([`Kernel::factor`]).
    fn factor_or_update(
        &mut self,
        active: &[bool],
        w: &[f64],
    ) -> std::result::Result<Rc<Operator>, String> {
        if let Some((a, ww, f)) = &self.cache {
            if a == active && ww == w {
                return Ok(f.clone());
            }
        }
        let t = Instant::now();
        let rows = self.rows;
        let n = self.sys.n;
        let row = |i: usize| (&rows[i].eqs[..], &rows[i].coeffs[..]);
        let update = match self.low_rank.as_mut() {
            Some(base) if self.update_rank > 0 => {
                let weights = effective_weights(active, w);
                match base.trailing_update(&weights, row, n) {
                    Some(update) => Some(Operator::Trailing(update)),
                    None => base
                        .update(&weights, row, n, self.update_rank, self.update_columns)
                        .map(Operator::Updated),
                }
            }
            _ => None,
        };
        let Some(update) = update else {
            return self.factor(active, w);
        };
        // the matrix itself only for an estimate of its condition now (a deferred estimate
        // forms it once, at the end)
        let values = if self.estimate_condition && !self.deferred_condition {
            self.augmented(active, w)
        } else {
            Vec::new()
        };
        let f = Rc::new(update);
        self.finish_operator(active, w, &values, &f, t);
        Ok(f)
    }

    /// With the condition estimate deferred, the estimate of the matrix of the last iteration
    /// (the cached operator's), written into the last history record when that record has
    /// none; its time counts as factorization.
    fn estimate_last_condition(&mut self) {
        if !self.deferred_condition {
            return;
        }
        let Some((active, w, f)) = self.cache.clone() else {
            return;
        };
        let Some(last) = self.history.last_mut() else {
            return;
        };
        if last.condition_estimate.is_some() || last.linear_solver == "penalty-predictor" {
            return;
        }
        let t = Instant::now();
        let values = self.augmented(&active, &w);
        let estimate = condition_estimate_symmetric_columns(&self.sys.pattern, &values, |b| {
            f.solve_columns_in_place(b, b.len() / self.sys.n.max(1))
        });
        if let Some(last) = self.history.last_mut() {
            last.condition_estimate = Some(estimate);
        }
        self.condition = Some(estimate);
        self.factorizations += t.elapsed().as_secs_f64();
    }

    /// The condition estimate of a new operator (when asked for; `values` is its matrix, read
    /// only then), its time, and the cache.
    fn finish_operator(
        &mut self,
        active: &[bool],
        w: &[f64],
        values: &[f64],
        f: &Rc<Operator>,
        start: Instant,
    ) {
        self.condition = if self.estimate_condition && !self.deferred_condition {
            Some(condition_estimate_symmetric(
                &self.sys.pattern,
                values,
                |b| f.solve_in_place(b),
            ))
        } else {
            None
        };
        self.factorizations += start.elapsed().as_secs_f64();
        self.cache = Some((active.to_vec(), w.to_vec(), f.clone()));
    }

    /// Values of `K + sum_active w_i b_i b_i^T` on the stiffness pattern.
    fn augmented(&self, active: &[bool], w: &[f64]) -> Vec<f64> {
        let mut values = self.k.clone();
        for (i, row) in self.rows.iter().enumerate() {
            if !active[i] || w[i] == 0.0 {
                continue;
            }
            let m = row.eqs.len();
            let mut block = vec![0.0; m * m];
            for a in 0..m {
                for b in 0..m {
                    block[a * m + b] = w[i] * row.coeffs[a] * row.coeffs[b];
                }
            }
            self.sys.pattern.scatter(&row.eqs, &block, &mut values);
        }
        values
    }

    /// Multipliers from the saddle-point system of the rows `multiplier`, whose equations are
    /// `K u - B^T lambda = f` and `B u + g0 + C lambda = 0` (`C` the perturbation, zero for
    /// Lagrange multipliers, see [`perturbation`]). It is solved as the stationary point of
    /// `1/2 u K u - f u - lambda (B u + g0) - 1/2 lambda C lambda + alpha/2 |B u + g0 + C lambda|^2`,
    /// whose augmentation vanishes at the solution and makes the displacement block definite
    /// for bodies held only by contact, scaled so that both blocks share the stiffness scale
    /// `rho` (`lambda = rho mu`):
    ///
    /// ```text
    /// [[K + alpha B^T B,          -rho B^T (I - alpha C)],  [u ]   [f - alpha B^T g0      ]
    ///  [-rho (I - alpha C) B,  -rho^2 C (I - alpha C)]]  [mu] = [rho (I - alpha C) g0]
    /// ```
    ///
    /// (its second row is `-rho (I - alpha C)` times the constraint, so with `alpha C < I` the
    /// solution is the unaugmented one; with `alpha C <= I / 2` the multiplier block's Schur
    /// complement is negative definite). Lagrange multipliers: `C = 0`, `alpha = rho`:
    /// `[[K + rho B^T B, -rho B^T], [-rho B, 0]] [u; mu] = [f - rho B^T g0; rho g0]`. The other
    /// rows: `-rho mu_i = 0`; the active ones among them add `w_i b_i b_i^T` to `K` (penalty
    /// rows, whose terms the caller put in `rhs_u`; `w_i = alpha` for the multiplier rows).
    /// Factored by LDL^T with multipliers ordered last, then refined. The residual is judged
    /// block by block: equilibrium against the force scale, gap rows against the model size; a
    /// non-finite iterate or scale never passes. A pivot that needed regularization or is zero
    /// relative to the matrix means the system is singular: that is an error naming the
    /// equation. If LDL^T fails otherwise, sparse LU of the same matrix is tried; `None` when
    /// neither gives a small residual (Lagrange multipliers then fall back to the Schur
    /// complement, which also handles dependent rows).
    #[allow(clippy::too_many_arguments)]
    fn saddle_ldlt(
        &mut self,
        active: &[bool],
        multiplier: &[bool],
        w: &[f64],
        rhs_u: Vec<f64>,
        rho: f64,
        alpha: f64,
    ) -> Step<Option<(Vec<f64>, Vec<f64>)>> {
        let t = Instant::now();
        let n = self.sys.n;
        let m = self.rows.len();
        let size = self.model.size();
        let Some(saddle) = self.saddle.as_ref() else {
            return Ok(None);
        };
        let k = self.augmented(active, w);
        let mut values = vec![0.0; saddle.pattern.nnz()];
        for (p, &v) in saddle.k_positions.iter().zip(&k) {
            values[*p] += v;
        }
        let mut rhs = rhs_u;
        rhs.resize(n + m, 0.0);
        // C restricted to the multiplier rows
        let c: Vec<Vec<(usize, f64)>> = (0..m)
            .map(|i| {
                if multiplier[i] {
                    self.perturbation[i]
                        .iter()
                        .copied()
                        .filter(|&(j, _)| multiplier[j])
                        .collect()
                } else {
                    Vec::new()
                }
            })
            .collect();
        let at = |a: usize, b: usize| saddle.pattern.position(a, b).expect("entry stored");
        for (i, row) in self.rows.iter().enumerate() {
            if !multiplier[i] {
                values[at(n + i, n + i)] = -rho;
                continue;
            }
            // -rho (I - alpha C) B
            for (&e, &co) in row.eqs.iter().zip(&row.coeffs) {
                values[at(e, n + i)] += -rho * co;
            }
            for &(k, c_ik) in &c[i] {
                let rk = &self.rows[k];
                for (&e, &co) in rk.eqs.iter().zip(&rk.coeffs) {
                    values[at(e, n + i)] += rho * alpha * c_ik * co;
                }
            }
            // -rho^2 (C - alpha C C), upper triangle
            for &(j, c_ij) in &c[i] {
                if j >= i {
                    values[at(n + i, n + j)] -= rho * rho * c_ij;
                }
            }
            for &(k, c_ik) in &c[i] {
                for &(j, c_kj) in &c[k] {
                    if j >= i {
                        values[at(n + i, n + j)] += rho * rho * alpha * c_ik * c_kj;
                    }
                }
            }
            row.add_to(-alpha * row.g0, &mut rhs);
            let c_g0: f64 = c[i].iter().map(|&(k, c_ik)| c_ik * self.rows[k].g0).sum();
            rhs[n + i] = rho * (row.g0 - alpha * c_g0);
        }
        let mut signs = vec![1i8; n + m];
        signs[n..].iter_mut().for_each(|s| *s = -1);
        let force_scale = crate::solver::linear::max_abs(&rhs[..n]);
        // residual of x, block by block: (equilibrium / forces, gaps / size); NaN when x or the
        // scale is not finite, so that it never passes
        let residual = |x: &[f64], r: &mut Vec<f64>| -> (f64, f64) {
            if !force_scale.is_finite() || x.iter().any(|v| !v.is_finite()) {
                return (f64::NAN, f64::NAN);
            }
            saddle.pattern.residual_accurate(&values, x, &rhs, r);
            let forces = x[n..]
                .iter()
                .fold(force_scale, |a, v| a.max((rho * v).abs()))
                .max(f64::MIN_POSITIVE);
            let ru = crate::solver::linear::max_abs(&r[..n]) / forces;
            let rg = crate::solver::linear::max_abs(&r[n..]) / rho / size;
            (ru, rg)
        };
        let small = |(ru, rg): (f64, f64)| ru <= 1e-11 && rg <= 1e-13;
        let mut r = vec![0.0; n + m];
        let mut solved = None;
        match saddle
            .ldlt
            .factor(&saddle.pattern, &values, &signs, 1e-13 * rho, rho)
        {
            Ok(factor) => {
                self.condition = Some(condition_estimate_symmetric(
                    &saddle.pattern,
                    &values,
                    |b| factor.solve_in_place(b),
                ));
                let mut x = rhs.clone();
                factor.solve_in_place(&mut x);
                // a finite matrix and right-hand side with a non-finite solution or residual:
                // the numbers overflow, which no other solver can mend
                saddle.pattern.mul(&values, &x, &mut r);
                r.iter_mut().zip(&rhs).for_each(|(a, b)| *a = b - *a);
                let stage = format!("in the LDL^T solve of contact iteration {}", self.iteration);
                for (v, what) in [(&x, "the solution"), (&r, "the residual K u - f")] {
                    if let Some(e) = v.iter().position(|v| !v.is_finite()) {
                        let error = if e < n {
                            crate::solver::linear::non_finite(
                                self.model,
                                what,
                                v[e],
                                self.sys.dof_of(e),
                                &stage,
                            )
                        } else {
                            let c = &self.constraints[e - n];
                            crate::solver::linear::non_finite_at(
                                self.model,
                                &format!("{what} (contact force row)"),
                                v[e],
                                &format!(
                                    "the slave node at ({}, {}) of contact '{}'",
                                    c.point[0], c.point[1], self.model.contact[c.pair].name
                                ),
                                &stage,
                            )
                        };
                        return Err(StepError::Fatal(error));
                    }
                }
                // iterative refinement with an accurate residual, while the correction at
                // least halves and is above round-off of x: the answer converges to the
                // solution of the stored matrix to about working precision, so that it does
                // not depend on the elimination order (the numbering)
                let mut res = residual(&x, &mut r);
                let mut last_step = f64::INFINITY;
                for _ in 0..MAX_REFINEMENT {
                    factor.solve_in_place(&mut r);
                    let step = crate::solver::linear::max_abs(&r);
                    // (a NaN step stops too)
                    if step.is_nan() || step >= 0.5 * last_step {
                        break;
                    }
                    x.iter_mut().zip(&r).for_each(|(a, d)| *a += d);
                    last_step = step;
                    res = residual(&x, &mut r);
                    if step <= f64::EPSILON * crate::solver::linear::max_abs(&x) {
                        break;
                    }
                }
                if small(res) {
                    solved = Some((x, "ldlt"));
                }
            }
            Err(e @ crate::solver::sparse::FactorError::ZeroPivot { .. }) => {
                self.factorizations += t.elapsed().as_secs_f64();
                return Err(StepError::Singular(self.saddle_error(e)));
            }
            Err(_) => {}
        }
        if solved.is_none() {
            if let Some(x) = saddle.lu_solve(&values, &rhs) {
                if small(residual(&x, &mut r)) {
                    solved = Some((x, "lu"));
                }
            }
        }
        self.factorizations += t.elapsed().as_secs_f64();
        let Some((mut x, solver)) = solved else {
            return Ok(None);
        };
        self.linear_solver = solver;
        let forces = (0..m)
            .map(|i| if multiplier[i] { rho * x[n + i] } else { 0.0 })
            .collect();
        x.truncate(n);
        Ok(Some((x, forces)))
    }

    /// The message for a singular saddle-point matrix: an equation below `n` is a
    /// displacement, above it the multiplier of a contact row.
    fn saddle_error(&self, e: crate::solver::sparse::FactorError) -> String {
        let n = self.sys.n;
        match e {
            crate::solver::sparse::FactorError::ZeroPivot { equation, .. } if equation >= n => {
                let r = &self.constraints[equation - n];
                Error::Solver {
                    path: self.model.source.clone(),
                    problem: format!(
                        "the multiplier system is singular at the contact row of the slave node at ({}, {}) of contact '{}'",
                        r.point[0], r.point[1], self.model.contact[r.pair].name
                    ),
                    hint: "the active constraints may depend on each other (a node constrained twice)".into(),
                }
                .to_string()
            }
            e => self.sys.factor_error(self.model, e).to_string(),
        }
    }

    /// Penalty-type solve: `M u = rhs + sum_active b_i (lambda_k,i - w_i g0_i)`, refined
    /// against the unpenalized equilibrium residual when that is not at round-off (see
    /// [`Kernel::penalty_equilibrium`]). Without `refine` the iterate is only solved for and
    /// kept ([`Unrefined`]); a later call with `refine` and the same operator and forces judges
    /// and refines that iterate instead of solving again (the loop refines only the iterate of
    /// a stable set, the one it may return).
    fn regularized(
        &mut self,
        active: &[bool],
        w: &[f64],
        lambda_k: &[f64],
        refine: bool,
    ) -> Step<Vec<f64>> {
        if self.amg.is_some() {
            return self.regularized_iterative(active, w, lambda_k);
        }
        let f = self.factor_or_update(active, w)?;
        let pending = self.unrefined.take();
        let (x, r, best) = match pending {
            // this operator's iterate, left unrefined by the solve before: judge it now
            Some(u) if refine && Rc::ptr_eq(&u.operator, &f) && u.lambda_k == lambda_k => {
                let mut r = vec![0.0; self.sys.n];
                let best = self.penalty_equilibrium(&u.x, active, w, lambda_k, &mut r);
                (u.x, r, best)
            }
            _ if !refine => {
                let x = self.solve_only(&f, active, w, lambda_k);
                self.linear_solver = f.solver_name();
                self.unrefined = Some(Unrefined {
                    operator: f.clone(),
                    lambda_k: lambda_k.to_vec(),
                    x: x.clone(),
                });
                return Ok(x);
            }
            _ => self.solve_once(&f, active, w, lambda_k),
        };
        let (x, best) = self.refine_from(&f, x, r, best, active, w, lambda_k);
        if f.rank() == 0 || best <= EQUILIBRIUM_ROUND_OFF {
            self.linear_solver = f.solver_name();
            return Ok(x);
        }
        // the update's answer did not reach round-off: factor this matrix and solve again
        self.cache = None;
        let f = self.factor(active, w)?;
        self.linear_solver = "cholesky";
        let (x, r, best) = self.solve_once(&f, active, w, lambda_k);
        Ok(self.refine_from(&f, x, r, best, active, w, lambda_k).0)
    }

    /// The solve of [`Kernel::regularized`] by CG + AMG from the last iterate, to the case's
    /// relative residual: `M x = f_f - K_fp u_p + sum_active b_i (lambda_k,i - w_i g0_i)`.
    /// A solve that does not converge ends the run (never a silent answer).
    fn regularized_iterative(
        &mut self,
        active: &[bool],
        w: &[f64],
        lambda_k: &[f64],
    ) -> Step<Vec<f64>> {
        let values = self.augmented(active, w);
        let mut b = self.rhs.clone();
        for (i, row) in self.rows.iter().enumerate() {
            if active[i] {
                row.add_to(lambda_k[i] - w[i] * row.g0, &mut b);
            }
        }
        let mut x = self
            .last_iterate
            .take()
            .unwrap_or_else(|| vec![0.0; self.sys.n]);
        let amg = self.amg.as_mut().expect("the CG path has its solver");
        let setup = amg.record.setup_seconds;
        let outcome = amg.solve(&self.sys.pattern, &values, &b, &mut x);
        self.factorizations += amg.record.setup_seconds - setup;
        if let Err(why) = outcome {
            return Err(StepError::Fatal(Error::Solver {
                path: self.model.source.clone(),
                problem: format!(
                    "the linear solve of active-set iteration {} is {why}",
                    self.iteration
                ),
                hint: "a body held only by contact that lost it is a mechanism, which also stops CG; check the supports".into(),
            }));
        }
        self.linear_solver = "cg-amg";
        self.condition = None;
        self.last_iterate = Some(x.clone());
        Ok(x)
    }

    /// The solve of [`Kernel::regularized`] with the operator `f`; returns the iterate, its
    /// equilibrium residual vector and that residual's relative size
    /// ([`Kernel::penalty_equilibrium`]).
    fn solve_once(
        &self,
        f: &Operator,
        active: &[bool],
        w: &[f64],
        lambda_k: &[f64],
    ) -> (Vec<f64>, Vec<f64>, f64) {
        let x = self.solve_only(f, active, w, lambda_k);
        let mut r = vec![0.0; self.sys.n];
        let best = self.penalty_equilibrium(&x, active, w, lambda_k, &mut r);
        (x, r, best)
    }

    /// `M^-1 (f_f - K_fp u_p + sum_active b_i (lambda_k,i - w_i g0_i))` with the operator `f`.
    fn solve_only(&self, f: &Operator, active: &[bool], w: &[f64], lambda_k: &[f64]) -> Vec<f64> {
        let mut x = self.rhs.clone();
        for (i, row) in self.rows.iter().enumerate() {
            if active[i] {
                row.add_to(lambda_k[i] - w[i] * row.g0, &mut x);
            }
        }
        f.solve_in_place(&mut x);
        x
    }

    /// Iterative refinement of the iterate `x` (residual `r`, relative size `best`) with the
    /// residual of equilibrium `f - K u + B^T lambda(u)`, `lambda_i = lambda_k,i - w_i (g0_i +
    /// b_i u)` (equal to `rhs - M u` in exact arithmetic, but computed from the forces the run
    /// reports, with an accurate `K u`): only when it is above round-off (a stiff penalty), and
    /// only while it at least halves; the best iterate is kept. Returns it and its residual.
    #[allow(clippy::too_many_arguments)]
    fn refine_from(
        &self,
        f: &Operator,
        mut x: Vec<f64>,
        mut r: Vec<f64>,
        mut best: f64,
        active: &[bool],
        w: &[f64],
        lambda_k: &[f64],
    ) -> (Vec<f64>, f64) {
        if best.is_finite() && best > EQUILIBRIUM_ROUND_OFF {
            for _ in 0..MAX_REFINEMENT {
                f.solve_in_place(&mut r);
                let trial: Vec<f64> = x.iter().zip(&r).map(|(a, d)| a + d).collect();
                let mut r_trial = vec![0.0; self.sys.n];
                let e = self.penalty_equilibrium(&trial, active, w, lambda_k, &mut r_trial);
                if e.is_nan() || e > 0.5 * best {
                    break;
                }
                (x, r, best) = (trial, r_trial, e);
                if best <= EQUILIBRIUM_ROUND_OFF {
                    break;
                }
            }
        }
        (x, best)
    }

    /// `r = f - K u + sum_active b_i lambda_i(u)` with `lambda_i = lambda_k,i - w_i (g0_i +
    /// b_i u)` (`K u` accumulated in twice the working precision); returns `max |r|` relative
    /// to the largest of `|f|` and `|b_i lambda_i|` (NaN when not finite).
    fn penalty_equilibrium(
        &self,
        x: &[f64],
        active: &[bool],
        w: &[f64],
        lambda_k: &[f64],
        r: &mut [f64],
    ) -> f64 {
        self.sys.pattern.residual_accurate(&self.k, x, &self.rhs, r);
        let mut contact = vec![0.0; self.sys.n];
        for (i, row) in self.rows.iter().enumerate() {
            if active[i] {
                let lambda = lambda_k[i] - w[i] * (row.g0 + row.dot(x));
                row.add_to(lambda, &mut contact);
            }
        }
        r.iter_mut().zip(&contact).for_each(|(a, c)| *a += c);
        let scale =
            crate::solver::linear::max_abs(self.rhs.iter().chain(&contact)).max(f64::MIN_POSITIVE);
        crate::solver::linear::max_abs(r.iter()) / scale
    }

    /// The stiffness scale `rho` (the largest diagonal entry of `K`, 1 without one), which
    /// keeps the augmented matrices well conditioned.
    fn stiffness_scale(&self) -> f64 {
        let mut rho = 0.0f64;
        for j in 0..self.sys.n {
            if let Some(p) = self.sys.pattern.position(j, j) {
                rho = rho.max(self.sys.k[p]);
            }
        }
        if rho > 0.0 {
            rho
        } else {
            1.0
        }
    }

    /// The perturbed Lagrangian with a consistent multiplier mass, in the loop of the
    /// penalty-regularized family: the active rows with a perturbation (see [`perturbation`])
    /// keep their multipliers in the saddle-point system of [`Kernel::saddle_ldlt`]; every other
    /// active row enters with its penalty weight `w_i` and its Uzawa force `lambda_k,i`, as in
    /// [`Kernel::regularized`]. The augmentation is the stiffness scale, limited to
    /// `alpha ||C||_inf <= 1/2`.
    fn perturbed(
        &mut self,
        active: &[bool],
        w: &[f64],
        lambda_k: &[f64],
    ) -> Step<(Vec<f64>, Vec<f64>)> {
        let m = self.rows.len();
        let rho = self.stiffness_scale();
        let multiplier: Vec<bool> = (0..m)
            .map(|i| active[i] && !self.perturbation[i].is_empty())
            .collect();
        let norm = (0..m)
            .filter(|&i| multiplier[i])
            .map(|i| {
                self.perturbation[i]
                    .iter()
                    .filter(|&&(j, _)| multiplier[j])
                    .map(|(_, v)| v.abs())
                    .sum::<f64>()
            })
            .fold(0.0f64, f64::max);
        let alpha = if norm > 0.0 { rho.min(0.5 / norm) } else { rho };
        let weights: Vec<f64> = (0..m)
            .map(|i| if multiplier[i] { alpha } else { w[i] })
            .collect();
        let mut rhs = self.rhs.clone();
        for (i, row) in self.rows.iter().enumerate() {
            if active[i] && !multiplier[i] {
                row.add_to(lambda_k[i] - w[i] * row.g0, &mut rhs);
            }
        }
        let Some((x, mut forces)) =
            self.saddle_ldlt(active, &multiplier, &weights, rhs, rho, alpha)?
        else {
            return Err(StepError::Singular(format!(
                "the saddle-point system of the perturbed Lagrangian (contact iteration {}) could not be solved to a small residual by LDL^T or LU",
                self.iteration
            )));
        };
        for (i, row) in self.rows.iter().enumerate() {
            if active[i] && !multiplier[i] {
                forces[i] = lambda_k[i] - w[i] * (row.g0 + row.dot(&x));
            }
        }
        Ok((x, forces))
    }

    /// Lagrange multipliers: LDL^T of the saddle-point system when the active rows are
    /// independent, else the Schur complement of the augmented system with a pseudo-inverse.
    fn lagrange(&mut self, active: &[bool]) -> Step<(Vec<f64>, Vec<f64>)> {
        let n = self.sys.n;
        // rho: the stiffness scale, so that M stays well conditioned
        let rho = self.stiffness_scale();
        let active_rows: Vec<&EqRow> = self
            .rows
            .iter()
            .zip(active)
            .filter(|(_, &a)| a)
            .map(|(r, _)| r)
            .collect();
        let dense_allowed = active_rows.len() <= DENSE_MULTIPLIER_LIMIT;
        if !dense_allowed || rank_deficiency(&active_rows, n) == 0 {
            let w = vec![rho; self.rows.len()];
            let rhs = self.rhs.clone();
            if let Some(solution) = self.saddle_ldlt(active, active, &w, rhs, rho, rho)? {
                return Ok(solution);
            }
        }
        if !dense_allowed {
            return Err(StepError::Singular(format!(
                "the saddle-point system of {} active Lagrange-multiplier rows cannot be \
                 factored (dependent rows), and the dense pseudo-inverse that would give \
                 minimum-norm multipliers is limited to {DENSE_MULTIPLIER_LIMIT} rows; use a \
                 penalty-type method or elimination for this interface, or a coarser mesh",
                active_rows.len()
            )));
        }
        self.linear_solver = "schur-pseudo-inverse";
        // rank-deficient (or LDL^T refused): minimum-norm multipliers from the Schur complement
        let w = vec![rho; self.rows.len()];
        let f = self.factor(active, &w)?;
        let idx: Vec<usize> = (0..self.rows.len()).filter(|&i| active[i]).collect();
        let mut z0 = self.rhs.clone();
        for &i in &idx {
            self.rows[i].add_to(-rho * self.rows[i].g0, &mut z0);
        }
        f.solve_in_place(&mut z0);
        self.extra_solves += idx.len();
        let mut zs: Vec<Vec<f64>> = Vec::with_capacity(idx.len());
        for &i in &idx {
            let mut z = vec![0.0; n];
            self.rows[i].add_to(1.0, &mut z);
            f.solve_in_place(&mut z);
            zs.push(z);
        }
        let m = idx.len();
        let mut s = vec![0.0; m * m];
        let mut r = vec![0.0; m];
        for a in 0..m {
            r[a] = -self.rows[idx[a]].g0 - self.rows[idx[a]].dot(&z0);
            for b in 0..m {
                s[a * m + b] = self.rows[idx[a]].dot(&zs[b]);
            }
        }
        // symmetrize round-off
        for a in 0..m {
            for b in 0..a {
                let v = 0.5 * (s[a * m + b] + s[b * m + a]);
                s[a * m + b] = v;
                s[b * m + a] = v;
            }
        }
        let lam = pseudo_solve(&s, &r, m)?;
        let mut x = z0;
        for (k, z) in zs.iter().enumerate() {
            for j in 0..n {
                x[j] += lam[k] * z[j];
            }
        }
        let mut forces = vec![0.0; self.rows.len()];
        for (k, &i) in idx.iter().enumerate() {
            forces[i] = lam[k];
        }
        Ok((x, forces))
    }

    /// Constraint elimination: each active row `g0 + sum_k c_k x_k = 0` solved for its owned
    /// equation `o`, `x_o = sum_{k != o} (-c_k / c_o) x_k - g0 / c_o`. The rows are affine
    /// constraints ([`crate::solver::constraints`]) on the equations of the Dirichlet-reduced
    /// system, layered on it: the prescribed values are already folded into `g0` (the chain
    /// through a prescribed master, resolved once when the rows were built), and the reduced
    /// system `T^T K T y = T^T (f - K t)` is formed from the assembled `K_ff` of this solve
    /// (stabilizing springs included), then `x = T y + t`. The force of a row is the multiplier
    /// of its line, the residual at its owned equation, over `c_o`:
    /// `lambda = (K x - f)_o / c_o`. Rows of different pairs that are solved for the same
    /// equation, or whose lines form a cycle, end the loop as singular; a chain (a row naming
    /// another row's owned equation) is resolved.
    fn eliminate(&mut self, active: &[bool], owners: &[usize]) -> Step<(Vec<f64>, Vec<f64>)> {
        let n = self.sys.n;
        let refuse = |e: ConstraintError| -> StepError {
            let at = |q: usize| crate::solver::linear::describe_dof(self.model, self.eq_dof[q]);
            let what = match e {
                ConstraintError::Repeated { dof } => {
                    format!("two active rows are solved for the same dof ({})", at(dof))
                }
                ConstraintError::Cycle { dofs } => format!(
                    "the active rows solved for {} depend on each other in a cycle",
                    dofs.iter().map(|&q| at(q)).collect::<Vec<_>>().join("; ")
                ),
                ConstraintError::NotFinite { dof } => format!(
                    "the row solved for {} has a coefficient that is not finite relative to the owned one",
                    at(dof)
                ),
                other => other.to_string(),
            };
            StepError::Singular(
                Error::Solver {
                    path: self.model.source.clone(),
                    problem: format!("constraint elimination cannot solve the active contact rows: {what}"),
                    hint: "let each row own a slave dof no other row touches (one elimination pair per slave surface), or use Lagrange multipliers".into(),
                }
                .to_string(),
            )
        };
        // one line per active row: x_o = sum_k (-c_k / c_o) x_k - g0 / c_o
        let mut builder = ConstraintBuilder::new(n);
        let mut lines: Vec<(usize, f64)> = Vec::new(); // (row, c_o)
        let mut masters: Vec<(usize, f64)> = Vec::new();
        for (i, row) in self.rows.iter().enumerate() {
            if !active[i] {
                continue;
            }
            let o = owners[i];
            let k = row
                .eqs
                .iter()
                .position(|&q| q == o)
                .expect("the owner is in its row");
            let co = row.coeffs[k];
            masters.clear();
            masters.extend(
                row.eqs
                    .iter()
                    .zip(&row.coeffs)
                    .filter(|(&q, _)| q != o)
                    .map(|(&q, &c)| (q, -c / co)),
            );
            builder
                .constrain(o, &masters, -row.g0 / co)
                .map_err(&refuse)?;
            lines.push((i, co));
        }
        let constraints = builder.close().map_err(&refuse)?;
        let t = Instant::now();
        let reduction = constraints.reduction(&self.sys.pattern);
        let values = reduction.matrix(&self.k);
        let mut y = reduction.rhs(&self.k, &self.rhs);
        let chol = Cholesky::analyse(&reduction.pattern, &self.model.factor_limit)
            .map_err(|e| self.sys.factor_error(self.model, e).to_string())?;
        // a failing pivot is named by its unknown of the reduced system: map it back
        let free = constraints.free_dofs();
        let f = chol.factor(&reduction.pattern, &values).map_err(|e| {
            self.sys
                .factor_error(self.model, e.map_equation(|q| free[q]))
                .to_string()
        })?;
        self.condition = Some(condition_estimate_symmetric(
            &reduction.pattern,
            &values,
            |b| f.solve_in_place(b),
        ));
        self.factorizations += t.elapsed().as_secs_f64();
        f.solve_in_place(&mut y);
        let x = constraints.expand(&y);
        // forces from the residual at the owned equations: (K x - rhs)_o = c_o lambda
        let mut r = vec![0.0; n];
        self.sys.pattern.mul(&self.k, &x, &mut r);
        r.iter_mut().zip(&self.rhs).for_each(|(a, b)| *a -= b);
        let mut forces = vec![0.0; self.rows.len()];
        for (&(i, co), mu) in lines.iter().zip(constraints.forces(&r)) {
            forces[i] = mu / co;
        }
        Ok((x, forces))
    }

    /// Prepare the solve of the active set `active`: if the prescribed dofs and the active rows
    /// leave a rigid motion free (see `crate::model::rigid`), the matrix would be singular on it. It
    /// is then stabilized: springs `S = STABILIZATION K_ee` on the equations of the bodies it
    /// moves, and the load's component along the free motions removed from the right-hand side,
    /// `f' = f - sum_k S m_k (m_k . f)` with `m_k` orthonormal in `S`, so that the iterate
    /// satisfies `m_k^T S u = 0` (no arbitrary rigid motion) and only serves to choose the next
    /// active set. Otherwise `K` and `f` are restored.
    fn prepare(&mut self, active: &[bool]) {
        // a function of the active set alone: the iterative methods repeat it many times
        if self.prepared_for.as_deref() == Some(active) {
            return;
        }
        self.prepared_for = Some(active.to_vec());
        let basis = self.modes.free_motions(
            self.constraints
                .iter()
                .zip(active)
                .filter(|(_, &a)| a)
                .map(|(r, _)| (&r.dofs[..], &r.coeffs[..])),
        );
        if basis.is_empty() {
            if self.free.take().is_some() {
                self.k = self.sys.k.clone();
                self.rhs = self.sys.rhs.clone();
                self.cache = None;
                self.low_rank = None;
            }
            return;
        }
        let active_rows: Vec<&Constraint<D>> = self
            .constraints
            .iter()
            .zip(active)
            .filter(|(_, &a)| a)
            .map(|(r, _)| r)
            .collect();
        let mode = self.modes.describe(&basis, &active_rows);
        let n = self.sys.n;
        let nb = self.model.bodies.len();
        let moved: Vec<bool> = (0..nb)
            .map(|b| {
                basis
                    .iter()
                    .any(|q| (0..3).any(|k| q[3 * b + k].abs() > 1e-12))
            })
            .collect();
        let mut springs = vec![0.0; n];
        for e in 0..n {
            if let Some((b, _)) = self.modes.at(self.eq_dof[e]) {
                if moved[b] {
                    let p = self.sys.pattern.col_ptr[e + 1] - 1; // the diagonal closes the column
                    springs[e] = STABILIZATION * self.sys.k[p];
                }
            }
        }
        // the motions in equation space, orthonormalized in a^T S b (modified Gram-Schmidt)
        let dot_s = |a: &[f64], b: &[f64]| -> f64 {
            a.iter()
                .zip(b)
                .zip(&springs)
                .map(|((x, y), s)| x * y * s)
                .sum()
        };
        let mut motions: Vec<Vec<f64>> = Vec::new();
        for q in &basis {
            let mut m: Vec<f64> = self
                .eq_dof
                .iter()
                .map(|&d| self.modes.displacement(q, d))
                .collect();
            for prev in &motions {
                let c = dot_s(&m, prev);
                m.iter_mut().zip(prev).for_each(|(a, p)| *a -= c * p);
            }
            let norm = dot_s(&m, &m).sqrt();
            if norm > 0.0 {
                m.iter_mut().for_each(|v| *v /= norm);
                motions.push(m);
            }
        }
        let mut k = self.sys.k.clone();
        for e in 0..n {
            k[self.sys.pattern.col_ptr[e + 1] - 1] += springs[e];
        }
        let mut rhs = self.sys.rhs.clone();
        for m in &motions {
            let c: f64 = m.iter().zip(&self.sys.rhs).map(|(a, b)| a * b).sum();
            for e in 0..n {
                rhs[e] -= c * springs[e] * m[e];
            }
        }
        self.k = k;
        self.rhs = rhs;
        self.cache = None;
        self.low_rank = None;
        self.free = Some(Free { mode, motions });
    }

    /// After a stabilized solve: if the loads push along the free motions (a component above
    /// `PUSH` of the load), the body moves rigidly along the push `d = sum_k m_k (m_k . f)` until
    /// the first open row closes: `x <- x + t d` with `t` the smallest `g_i / (-b_i . d)` over
    /// the rows that `d` closes. Returns the rows that closed (to be activated); an error when
    /// no row stops the motion.
    fn push_to_contact(
        &self,
        x: &mut [f64],
        active: &[bool],
    ) -> std::result::Result<Vec<usize>, String> {
        let Some(free) = &self.free else {
            return Ok(Vec::new());
        };
        let f = &self.sys.rhs;
        let f_norm = f.iter().map(|v| v * v).sum::<f64>().sqrt();
        let mut d = vec![0.0; self.sys.n];
        let mut pushed = false;
        for m in &free.motions {
            let c: f64 = m.iter().zip(f).map(|(a, b)| a * b).sum();
            let m_norm = m.iter().map(|v| v * v).sum::<f64>().sqrt();
            if c.abs() > PUSH * f_norm * m_norm {
                pushed = true;
            }
            d.iter_mut().zip(m).for_each(|(a, v)| *a += c * v);
        }
        if !pushed {
            return Ok(Vec::new());
        }
        let d_norm = d.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let closing: Vec<(usize, f64)> = (0..self.rows.len())
            .filter(|&i| !active[i])
            .filter_map(|i| {
                let rate = self.rows[i].dot(&d);
                (rate < -1e-12 * d_norm).then(|| {
                    let gap = self.rows[i].g0 + self.rows[i].dot(x);
                    (i, (gap / -rate).max(0.0))
                })
            })
            .collect();
        let Some(t) = closing.iter().map(|c| c.1).min_by(f64::total_cmp) else {
            let name = &self.model.bodies[free.mode.body].name;
            return Err(Error::Solver {
                path: self.model.source.clone(),
                problem: format!(
                    "the loads push body '{name}' to {} ({}), and no contact row can stop that motion",
                    free.mode.motion(), free.mode.why
                ),
                hint: "add a support that holds this motion, or check the direction of the loads and of the contact normals".into(),
            }
            .to_string());
        };
        x.iter_mut().zip(&d).for_each(|(a, v)| *a += t * v);
        Ok(closing
            .iter()
            .filter(|c| c.1 <= t + 1e-9 * t.abs().max(f64::MIN_POSITIVE))
            .map(|c| c.0)
            .collect())
    }

    /// The first active set: the closed rows (gap within `gap_tol`) and the ties; then, while a
    /// body can move rigidly, the rows of that body that would hold the free motion and lie
    /// at its smallest open gap (within `1e-9` of the model size) are closed too, level by
    /// level: a body held only by contact across a gap is brought into contact at its closest
    /// points, the same ones whatever the numbering of its nodes.
    fn first_active_set(&self, rows: &[Constraint<D>]) -> Vec<bool> {
        let gap_tol = self.gap_tol();
        let mut active: Vec<bool> = rows
            .iter()
            .zip(self.rows)
            .enumerate()
            .map(|(i, (c, r))| match &self.initial_active {
                Some(initial) => c.bilateral || initial[i],
                None => c.bilateral || r.g0 <= gap_tol,
            })
            .collect();
        let gaps: Vec<f64> = self.rows.iter().map(|r| r.g0).collect();
        self.modes
            .close_free_bodies(rows, &gaps, self.model.size(), &mut active);
        active
    }

    /// The refusal when the active-set loop settles on a set that leaves a rigid motion free:
    /// the answer would be one of a family that differ by that motion.
    fn not_unique(&self, active: &[bool], gaps: &[f64]) -> String {
        let free = &self.free.as_ref().expect("a free motion").mode;
        let body = &self.model.bodies[free.body];
        let range = body.dof_offset..body.dof_offset + body.dof_count();
        let open: Vec<usize> = (0..self.rows.len())
            .filter(|&i| !active[i] && self.constraints[i].dofs.iter().any(|d| range.contains(d)))
            .collect();
        let open_text = match open.iter().min_by(|&&a, &&b| gaps[a].total_cmp(&gaps[b])) {
            None => "it has no other contact rows".to_string(),
            Some(&i) => {
                let p = self.constraints[i].point;
                format!(
                    "its other {} contact row(s) stay open (the smallest gap {:.3e} at ({}, {}))",
                    open.len(),
                    gaps[i],
                    p[0],
                    p[1]
                )
            }
        };
        Error::Solver {
            path: self.model.source.clone(),
            problem: format!(
                "the solution is not unique: body '{}' can {} ({}); at the end of the active-set iterations {open_text}, so the equilibrium does not fix this motion and any answer would be arbitrary",
                body.name, free.motion(), free.why
            ),
            hint: "hold this motion with a support (e.g. prescribe u_x at a second node off the line of action of the first, or u_y at a node away from the contact), or bring more of the body into contact (a finer mesh at the contact, a larger load)".into(),
        }
        .to_string()
    }

    /// `Err` naming the first non-finite entry of the iterate `x` or of the contact `forces`.
    fn check_iterate(&self, x: &[f64], forces: &[f64], it: usize) -> Result<()> {
        let stage = format!(
            "in contact iteration {it} (linear solver {})",
            self.linear_solver
        );
        self.sys
            .check_finite(self.model, x, "the displacement", &stage)?;
        if let Some(i) = forces.iter().position(|v| !v.is_finite()) {
            let r = &self.constraints[i];
            return Err(crate::solver::linear::non_finite_at(
                self.model,
                "the contact force",
                forces[i],
                &format!(
                    "the slave node at ({}, {}) of contact '{}'",
                    r.point[0], r.point[1], self.model.contact[r.pair].name
                ),
                &stage,
            ));
        }
        Ok(())
    }

    /// Why the active set cycled, naming the rows in `flipping` (those that changed status at
    /// least twice), and what to change.
    fn cycling_diagnosis(
        &self,
        rows: &[Constraint<D>],
        flipping: &[usize],
        it: usize,
        remedy: CyclingRemedy,
        remedied: bool,
    ) -> String {
        let mut points: Vec<String> = flipping
            .iter()
            .take(5)
            .map(|&i| {
                let r = &rows[i];
                format!(
                    "({:.6}, {:.6}) of contact '{}'",
                    r.point[0], r.point[1], self.model.contact[r.pair].name
                )
            })
            .collect();
        if flipping.len() > 5 {
            points.push(format!("and {} more", flipping.len() - 5));
        }
        let which = if points.is_empty() {
            "several points".to_string()
        } else {
            format!("the slave points at {}", points.join(", "))
        };
        let cause = format!(
            "the active set of iteration {it} repeats an earlier one (the loop would cycle): {which} switch between open and closed, their force and gap both near zero (a point at the edge of the contact zone, or a body held by a point that carries no force)"
        );
        if remedy == CyclingRemedy::Off {
            format!("{cause}; the remedy is off (solver.cycling_remedy \"off\"): remove that setting to hold such points closed while their force is not tensile")
        } else if remedied {
            format!("{cause}, and it still cycles with those points held closed while their force is not tensile: apply the load in more load steps (solver.load_steps), use Lagrange multipliers, or refine the slave surface near those points")
        } else {
            format!("{cause}; apply the load in more load steps (solver.load_steps) or use Lagrange multipliers")
        }
    }

    /// The active-set loop. Before each solve the rigid modes are tested with the active rows
    /// ([`Kernel::prepare`]); a set that leaves one free is solved stabilized and never counts
    /// as converged: if the loop settles on it, it ends with [`Termination::Singular`] saying
    /// which body, which mode and why. A non-finite iterate is an error naming where it
    /// appeared.
    fn active_set_loop(&mut self, method: Method, rows: &[Constraint<D>]) -> Result<LoopResult> {
        let nrows = self.rows.len();
        let gap_tol = self.gap_tol();
        let size = self.model.size();
        let mut active = self.first_active_set(rows);
        // the method of each row (its pair's) and its penalty weight kappa A
        let row_methods: Vec<Method> = rows
            .iter()
            .map(|r| enforcement_method(&self.model.contact[r.pair].enforcement).kernel())
            .collect();
        let row_w: Vec<f64> = rows
            .iter()
            .zip(&row_methods)
            .map(|(r, m)| {
                m.kappa().unwrap_or(0.0) * self.model.contact[r.pair].penalty_share() * r.area
            })
            .collect();
        let iterative: Vec<bool> = row_methods
            .iter()
            .map(|m| {
                matches!(
                    m,
                    Method::AugmentedLagrange { .. } | Method::PerturbedTangent { .. }
                )
            })
            .collect();
        let owners: Vec<usize> = rows.iter().map(|r| self.sys.eq(r.owner)).collect();
        // perturbed Lagrangian rows with a consistent multiplier mass: a saddle-point solve
        let coupled = self.perturbation.iter().any(|c| !c.is_empty());
        let mut lambda_k = vec![0.0; nrows];
        let mut x = vec![0.0; self.sys.n];
        let mut forces = vec![0.0; nrows];
        // cycling: the sets chosen so far (hashed), how often each row changed status, and the
        // rows the remedy holds closed once a set repeated
        let mut seen: HashSet<Vec<bool>> = HashSet::new();
        seen.insert(active.clone());
        let mut flips = vec![0usize; nrows];
        let mut held: Vec<usize> = Vec::new();
        let remedy = self.model.solver.cycling_remedy;
        // the iteration limit, and the work limit: iterations times the size of the system
        let dofs = self.sys.n.max(1);
        let affordable = (self.model.iteration_dofs / dofs as u64).max(1) as usize;
        let max_iterations = self.model.solver.max_iterations.min(affordable);
        let mut work_bound = affordable < self.model.solver.max_iterations;
        // the work done: dofs per solve (an iteration of the minimum-norm Schur path solves
        // once per active row, so a long loop of those reaches the limit sooner)
        let mut work: u64 = 0;
        // the penalty predictor of the set (Lagrange and elimination), used once
        let mut predicted = false;
        let mut it = 0;
        while it < max_iterations {
            it += 1;
            let iteration_start = Instant::now();
            let previous_forces = forces.clone();
            self.iteration = it;
            self.prepare(&active);
            // the penalty family refines an iterate only when its set turns out stable (the
            // others' sets decide the next iterate at any accuracy): a set that changes
            // leaves its iterate unrefined, and a stable one solves the step again, refined
            let mut refine = false;
            let (gaps, force_tol, gaps_closed, mut new_active, stable) = loop {
                let step: Step<(Vec<f64>, Vec<f64>)> = match method {
                    Method::Lagrange => self.lagrange(&active),
                    Method::Elimination => self.eliminate(&active, &owners),
                    Method::Regularized { .. }
                    | Method::PerturbedLagrange { .. }
                    | Method::AugmentedLagrange { .. }
                        if coupled =>
                    {
                        self.perturbed(&active, &row_w, &lambda_k)
                    }
                    Method::Regularized { .. }
                    | Method::PerturbedLagrange { .. }
                    | Method::AugmentedLagrange { .. } => {
                        let w = &row_w;
                        self.regularized(&active, w, &lambda_k, refine).map(|x| {
                            let f = (0..nrows)
                                .map(|i| {
                                    if active[i] {
                                        lambda_k[i]
                                            - w[i] * (self.rows[i].g0 + self.rows[i].dot(&x))
                                    } else {
                                        0.0
                                    }
                                })
                                .collect();
                            (x, f)
                        })
                    }
                    Method::PerturbedTangent { .. } => {
                        // Newton on the Lagrange residual with the perturbed tangent
                        let w = row_w.clone();
                        let mut ku = vec![0.0; self.sys.n];
                        self.sys.pattern.mul(&self.sys.k, &x, &mut ku);
                        let mut b = vec![0.0; self.sys.n];
                        for j in 0..self.sys.n {
                            b[j] = self.rhs[j] - ku[j];
                        }
                        for (i, row) in self.rows.iter().enumerate() {
                            if active[i] {
                                row.add_to(forces[i], &mut b);
                                let r_g = -(row.g0 + row.dot(&x));
                                row.add_to(w[i] * r_g, &mut b);
                            }
                        }
                        match self.factor(&active, &w) {
                            Ok(f) => {
                                f.solve_in_place(&mut b);
                                let xn: Vec<f64> = x.iter().zip(&b).map(|(a, d)| a + d).collect();
                                let f = (0..nrows)
                                    .map(|i| {
                                        if active[i] {
                                            let r_g = -(self.rows[i].g0 + self.rows[i].dot(&x));
                                            forces[i] + w[i] * (r_g - self.rows[i].dot(&b))
                                        } else {
                                            0.0
                                        }
                                    })
                                    .collect();
                                Ok((xn, f))
                            }
                            Err(e) => Err(e.into()),
                        }
                    }
                };
                let (xn, fnew) = match step {
                    Ok(v) => v,
                    Err(StepError::Singular(msg)) => {
                        return Ok((x, forces, active, Termination::Singular(msg), it))
                    }
                    Err(StepError::Fatal(e)) => return Err(e),
                };
                self.check_iterate(&xn, &fnew, it)?;
                x = xn;
                forces = fnew;
                let closing = match self.push_to_contact(&mut x, &active) {
                    Ok(c) => c,
                    Err(msg) => return Ok((x, forces, active, Termination::Singular(msg), it)),
                };
                let gaps: Vec<f64> = self.rows.iter().map(|r| r.g0 + r.dot(&x)).collect();
                let fmax = forces.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let force_tol = 1e-10 * fmax;
                // the iterative methods stop when the multiplier update kappa A g of every active
                // row is negligible against the contact forces (1e-12 of the largest), or the gap is
                // at the round-off floor (1e-15 of the model size)
                // (only the rows of iterative methods: a penalty row's gap stays open by design)
                let gaps_closed = (0..nrows).filter(|&i| active[i] && iterative[i]).all(|i| {
                    let update = (row_w[i] * gaps[i]).abs();
                    update <= 1e-12 * fmax || gaps[i].abs() <= 1e-15 * size
                });
                // ties (bilateral rows) stay active whatever the sign of their force
                let new_active: Vec<bool> = match method {
                    Method::Lagrange | Method::Elimination | Method::PerturbedTangent { .. } => (0
                        ..nrows)
                        .map(|i| {
                            rows[i].bilateral
                                || if active[i] {
                                    forces[i] >= -force_tol
                                } else {
                                    gaps[i] < -gap_tol
                                }
                        })
                        .collect(),
                    // rows with multipliers (the consistent perturbed Lagrangian): complementarity of
                    // lambda >= 0 and g + C lambda >= 0; the others by their trial force
                    Method::Regularized { .. }
                    | Method::PerturbedLagrange { .. }
                    | Method::AugmentedLagrange { .. } => (0..nrows)
                        .map(|i| {
                            rows[i].bilateral
                                || if !self.perturbation[i].is_empty() {
                                    if active[i] {
                                        forces[i] >= -force_tol
                                    } else {
                                        let c_lambda: f64 = self.perturbation[i]
                                            .iter()
                                            .map(|&(j, c)| c * forces[j])
                                            .sum();
                                        gaps[i] + c_lambda < -gap_tol
                                    }
                                } else {
                                    lambda_k[i] - row_w[i] * gaps[i] > force_tol
                                }
                        })
                        .collect(),
                };
                let mut new_active = new_active;
                for i in closing {
                    new_active[i] = true;
                }
                // the cycling remedy: a held row stays closed while its force (the multiplier, or
                // a penalty row's trial force) is not tensile beyond the tolerance
                for &i in &held {
                    if active[i] && !new_active[i] && forces[i] >= -force_tol {
                        new_active[i] = true;
                    }
                }
                let stable = new_active == active;
                if stable && !refine && self.unrefined.is_some() {
                    refine = true;
                    continue;
                }
                self.unrefined = None;
                break (gaps, force_tol, gaps_closed, new_active, stable);
            };
            for i in 0..nrows {
                if new_active[i] != active[i] {
                    flips[i] += 1;
                }
            }
            // the loops without a multiplier iteration of their own determine the iterate by
            // the set alone: a set chosen before repeats its iterate (the residual cannot have
            // decreased), a cycle
            let cycles = matches!(
                method,
                Method::Lagrange
                    | Method::Elimination
                    | Method::Regularized { .. }
                    | Method::PerturbedLagrange { .. }
            ) && !iterative.iter().any(|&it| it);
            let repeated = cycles && !stable && seen.contains(&new_active);
            self.history.push(IterationRecord {
                step: 0,
                geometry_update: 0,
                iteration: it,
                residual: self.equilibrium_residual(&x, &forces, &active),
                active: active.iter().filter(|&&a| a).count(),
                status_changes: new_active
                    .iter()
                    .zip(&active)
                    .filter(|(a, b)| a != b)
                    .count(),
                max_gap_violation: largest_penetration(rows, &gaps),
                multiplier_change: largest_change(&forces, &previous_forces),
                linear_solver: self.linear_solver,
                condition_estimate: self.condition,
                seconds: iteration_start.elapsed().as_secs_f64(),
                repeated_set: repeated,
                cycling_remedy: !held.is_empty(),
                stability: None,
                step_length: 1.0,
            });
            let converged = match method {
                Method::Lagrange | Method::Elimination => stable,
                Method::PerturbedTangent { .. } => stable && gaps_closed,
                Method::Regularized { .. }
                | Method::PerturbedLagrange { .. }
                | Method::AugmentedLagrange { .. } => {
                    let done = stable && gaps_closed;
                    // Uzawa on the augmented Lagrangian rows: lambda_k <- max(0, lambda_k -
                    // kappa A g), after every iteration or (outer loop) once the set is stable
                    if !done {
                        for i in 0..nrows {
                            let Method::AugmentedLagrange { update, .. } = row_methods[i] else {
                                continue;
                            };
                            if update == MultiplierUpdate::PerIteration || stable {
                                let next = lambda_k[i] - row_w[i] * gaps[i];
                                // ties carry forces of either sign; contact only compression
                                lambda_k[i] = if rows[i].bilateral {
                                    next
                                } else {
                                    next.max(0.0)
                                };
                            }
                        }
                    }
                    done
                }
            };
            if converged {
                if self.free.is_some() {
                    let msg = self.not_unique(&active, &gaps);
                    return Ok((x, forces, active, Termination::Singular(msg), it));
                }
                return Ok((x, forces, active, Termination::Converged, it));
            }
            if repeated {
                let flipping: Vec<usize> = (0..nrows).filter(|&i| flips[i] >= 2).collect();
                if remedy == CyclingRemedy::Off || !held.is_empty() || flipping.is_empty() {
                    let msg = self.cycling_diagnosis(rows, &flipping, it, remedy, !held.is_empty());
                    return Ok((x, forces, active, Termination::ActiveSetCycling(msg), it));
                }
                // hold the flip-flopping rows from now on; the sets of the new rule start afresh
                held = flipping;
                seen.clear();
                for &i in &held {
                    if active[i] && forces[i] >= -force_tol {
                        new_active[i] = true;
                    }
                }
            }
            // a set-determined method that must grow its set lets a penalty predictor choose the
            // next one (see [`Kernel::penalty_predictor`])
            let grows = (0..nrows).any(|i| new_active[i] && !active[i]);
            if grows
                && !predicted
                && matches!(method, Method::Lagrange | Method::Elimination)
                && held.is_empty()
            {
                predicted = true;
                let (predicted_set, used) =
                    self.penalty_predictor(new_active.clone(), rows, it, max_iterations);
                it += used;
                if predicted_set != new_active {
                    for i in 0..nrows {
                        if predicted_set[i] != new_active[i] {
                            flips[i] += 1;
                        }
                    }
                    new_active = predicted_set;
                }
            }
            seen.insert(new_active.clone());
            active = new_active;
            work += dofs as u64 * (1 + std::mem::take(&mut self.extra_solves) as u64);
            if work >= self.model.iteration_dofs && it < max_iterations {
                work_bound = true;
                break;
            }
        }
        let termination = if work_bound {
            let changes = self.history.last().map_or(0, |h| h.status_changes);
            Termination::WorkLimit(format!(
                "the active set had not settled after {it} iterations ({changes} rows still changing status): {it} iterations ({} solves) of {dofs} dofs reach the work limit of {} iteration-dofs (limits.iteration_dofs); raise \"limits\": {{\"iteration_dofs\": N}} if the machine has the time, use a coarser mesh, or apply the load in more load steps (solver.load_steps) so that each step changes the set less",
                work.max(it as u64 * dofs as u64) / dofs as u64,
                self.model.iteration_dofs
            ))
        } else {
            Termination::IterationLimit
        };
        Ok((x, forces, active, termination, it))
    }

    /// The penalty predictor of the active set of a set-determined method (Lagrange
    /// multipliers, elimination). When a set is too small, the body penetrates the master
    /// far beyond the contact zone it will have, and the next set closes every penetrating
    /// row: a set far too large. With multipliers its iterate is held by tensile forces only at
    /// the two edges of the zone (the stress singularity of a gap forced shut), so the loop
    /// opens a row or two per iteration, and the number of iterations grows with the mesh.
    /// A penalty regularization spreads the tension of a too-large set over many rows and
    /// sheds them together. The predictor solves `(K + sum_active w_i b_i b_i^T) u = f -
    /// sum_active w_i g0_i b_i` with the rule "active while the trial force `-w_i g_i` is
    /// compressive", from `start`, at weights `w_i = kappa A_i` with `kappa = E / L` (the
    /// largest Young's modulus over the model size) and [`PREDICTOR_STEP`] times stiffer per
    /// level, up to the level whose largest weight reaches the stiffness scale `rho`; each level
    /// starts from the set of the one before, hands it on once at most one in
    /// [`PREDICTOR_SETTLED`] active rows changes (the last level: none), and its zone is closer
    /// to the Lagrange one. Its iterations are recorded in the history (linear solver
    /// `penalty-predictor`, no condition estimate: its systems are never the answer's) and count
    /// against the loop's iteration limit `max_iterations`; it returns the set and the number of
    /// iterations it took. A step that fails (a singular system) ends it with the last set.
    fn penalty_predictor(
        &mut self,
        start: Vec<bool>,
        rows: &[Constraint<D>],
        after: usize,
        max_iterations: usize,
    ) -> (Vec<bool>, usize) {
        self.estimate_condition = false;
        self.cache = None;
        self.low_rank = None;
        let set = self.predictor_levels(start, rows, after, max_iterations);
        self.estimate_condition = true;
        self.cache = None;
        self.low_rank = None;
        self.condition = None;
        set
    }

    /// The levels of [`Kernel::penalty_predictor`] (its early returns leave the flags to it).
    fn predictor_levels(
        &mut self,
        start: Vec<bool>,
        rows: &[Constraint<D>],
        after: usize,
        max_iterations: usize,
    ) -> (Vec<bool>, usize) {
        let nrows = self.rows.len();
        let rho = self.stiffness_scale();
        let modulus = self
            .model
            .bodies
            .iter()
            .map(|b| K::youngs_modulus(&b.material))
            .fold(0.0f64, f64::max);
        let zero = vec![0.0; nrows];
        let mut active = start;
        let mut used = 0;
        let mut previous_forces = vec![0.0; nrows];
        let mut kappa = modulus / self.model.size();
        for _level in 0..PREDICTOR_LEVELS {
            let w: Vec<f64> = rows.iter().map(|r| kappa * r.area).collect();
            // the sets this level has solved: one that comes back would cycle to the level's
            // iteration cap (measured: a support moved by 1e12 cycled with period 6 through
            // 90 predictor iterations), so the level ends there and the next one goes on
            let mut seen: Vec<Vec<bool>> = Vec::new();
            for _ in 0..PREDICTOR_LEVEL_ITERATIONS {
                if after + used >= max_iterations {
                    return (active, used);
                }
                used += 1;
                let iteration_start = Instant::now();
                self.prepare(&active);
                let Ok(x) = self.regularized(&active, &w, &zero, true) else {
                    return (active, used);
                };
                let gaps: Vec<f64> = self.rows.iter().map(|r| r.g0 + r.dot(&x)).collect();
                let forces: Vec<f64> = (0..nrows)
                    .map(|i| if active[i] { -w[i] * gaps[i] } else { 0.0 })
                    .collect();
                let fmax = forces.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let force_tol = 1e-10 * fmax;
                let next: Vec<bool> = (0..nrows)
                    .map(|i| rows[i].bilateral || -w[i] * gaps[i] > force_tol)
                    .collect();
                let changes = next.iter().zip(&active).filter(|(a, b)| a != b).count();
                self.history.push(IterationRecord {
                    step: 0,
                    geometry_update: 0,
                    iteration: after + used,
                    residual: self.equilibrium_residual(&x, &forces, &active),
                    active: active.iter().filter(|&&a| a).count(),
                    status_changes: changes,
                    max_gap_violation: largest_penetration(rows, &gaps),
                    multiplier_change: largest_change(&forces, &previous_forces),
                    linear_solver: "penalty-predictor",
                    condition_estimate: self.condition,
                    seconds: iteration_start.elapsed().as_secs_f64(),
                    repeated_set: false,
                    cycling_remedy: false,
                    stability: None,
                    step_length: 1.0,
                });
                previous_forces = forces;
                seen.push(std::mem::replace(&mut active, next));
                if changes > 0 && seen.contains(&active) {
                    break;
                }
                let last_level = w.iter().fold(0.0f64, |m, &v| m.max(v)) >= rho;
                let settled = if last_level {
                    changes == 0
                } else {
                    changes * PREDICTOR_SETTLED <= active.iter().filter(|&&a| a).count()
                };
                if settled {
                    break;
                }
            }
            if w.iter().fold(0.0f64, |m, &v| m.max(v)) >= rho {
                break;
            }
            kappa *= PREDICTOR_STEP;
        }
        (active, used)
    }
}

/// Systems of at least this many equations update the last factorization by low rank in the
/// `auto` mode; below it a factorization costs about as much as the update's solves.
pub const LOW_RANK_MIN_EQUATIONS: usize = 20_000;

/// The most rows a low-rank update may change, and the most memory its columns `A^-1 b_i`
/// may take (8 bytes per value, `n` values per column).
pub const MAX_UPDATE_RANK: usize = 64;
pub const MAX_UPDATE_BYTES: f64 = 0.5e9;

/// The rank bound of the low-rank updates for `n` equations under `mode` (0: none).
fn update_rank(mode: FactorUpdate, n: usize) -> usize {
    let by_memory = (MAX_UPDATE_BYTES / (8.0 * n.max(1) as f64)) as usize;
    match mode {
        FactorUpdate::Refactor => 0,
        FactorUpdate::Auto if n < LOW_RANK_MIN_EQUATIONS => 0,
        FactorUpdate::Auto | FactorUpdate::LowRank => MAX_UPDATE_RANK.min(by_memory),
    }
}

/// The most new columns `A^-1 b_i` one update may solve for, from the factorization's size:
/// a column costs a forward and a backward solve, about `2 entries` multiply-adds run at
/// about half the rate of the factorization's dense blocks (measured: 61 columns 1.7 s against
/// a factorization of 1.4 s at 250k equations), so `operations / (4 entries)` columns cost
/// about one factorization; an update may take half that, leaving time for its other solves.
fn new_columns_bound(work: &crate::solver::sparse::FactorWork) -> usize {
    (work.operations / (8.0 * work.entries.max(1) as f64)) as usize
}

/// The equations the factorization eliminates last so that an active-set change is a change of
/// its trailing block alone ([`crate::solver::low_rank::TrailingUpdate`]): every equation a row
/// has a nonzero coefficient on, in the `auto` mode from [`LOW_RANK_MIN_EQUATIONS`] on and up to
/// [`crate::solver::low_rank::MAX_TRAILING_EQUATIONS`] of them; else none (the AMD order).
fn trailing_equations(rows: &[EqRow], mode: FactorUpdate, n: usize) -> Vec<usize> {
    if mode != FactorUpdate::Auto || n < LOW_RANK_MIN_EQUATIONS {
        return Vec::new();
    }
    let mut eqs: Vec<usize> = rows
        .iter()
        .flat_map(|r| {
            r.eqs
                .iter()
                .zip(&r.coeffs)
                .filter(|(_, &c)| c != 0.0)
                .map(|(&e, _)| e)
        })
        .collect();
    eqs.sort_unstable();
    eqs.dedup();
    if eqs.len() > crate::solver::low_rank::MAX_TRAILING_EQUATIONS {
        return Vec::new();
    }
    eqs
}

/// The weight each row adds to the matrix: `w_i` when active, else 0.
fn effective_weights(active: &[bool], w: &[f64]) -> Vec<f64> {
    active
        .iter()
        .zip(w)
        .map(|(&a, &wi)| if a { wi } else { 0.0 })
        .collect()
}

/// The largest penetration `-g` over the contact rows (ties excluded) of an iteration.
fn largest_penetration<const D: usize>(rows: &[Constraint<D>], gaps: &[f64]) -> f64 {
    rows.iter()
        .zip(gaps)
        .filter(|(r, _)| !r.bilateral)
        .fold(0.0f64, |m, (_, g)| m.max(-g))
}

/// The largest change of a row force between two iterations.
fn largest_change(forces: &[f64], previous: &[f64]) -> f64 {
    forces
        .iter()
        .zip(previous)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
}

/// Minimum-norm solution of the symmetric positive semi-definite system `S x = r` (`m x m`,
/// row-major) by Jacobi eigen-decomposition; fails when `r` is not in the range of `S`.
fn pseudo_solve(s: &[f64], r: &[f64], m: usize) -> std::result::Result<Vec<f64>, String> {
    if m == 0 {
        return Ok(Vec::new());
    }
    let (eig, v) = symmetric_eigen(s, m);
    let max = eig.iter().fold(0.0f64, |a, &e| a.max(e.abs()));
    let mut x = vec![0.0; m];
    let mut residual_in_null = 0.0f64;
    let rnorm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
    for k in 0..m {
        let proj: f64 = (0..m).map(|i| v[i * m + k] * r[i]).sum();
        if eig[k].abs() > 1e-10 * max {
            for i in 0..m {
                x[i] += v[i * m + k] * proj / eig[k];
            }
        } else {
            residual_in_null = residual_in_null.max(proj.abs());
        }
    }
    if residual_in_null > 1e-8 * rnorm.max(f64::MIN_POSITIVE) && residual_in_null > 1e-14 {
        return Err(format!(
            "the active constraints contradict each other (the multiplier system is singular and inconsistent, residual {residual_in_null:.2e})"
        ));
    }
    Ok(x)
}

/// Number of dependent rows among `rows`: null eigenvalues of the Gram matrix `B B^T`.
fn rank_deficiency(rows: &[&EqRow], n: usize) -> usize {
    let m = rows.len();
    if m == 0 {
        return 0;
    }
    let mut dense = vec![0.0; n];
    let mut g = vec![0.0; m * m];
    for a in 0..m {
        rows[a].add_to(1.0, &mut dense);
        for b in 0..m {
            g[a * m + b] = rows[b].dot(&dense);
        }
        for &e in &rows[a].eqs {
            dense[e] = 0.0;
        }
    }
    let (eig, _) = symmetric_eigen(&g, m);
    let max = eig.iter().fold(0.0f64, |a, &e| a.max(e.abs()));
    eig.iter().filter(|e| e.abs() <= 1e-10 * max).count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::dense::jacobi_eigen;

    #[test]
    fn jacobi_recovers_a_rank_deficient_spectrum() {
        // S = v v^T + w w^T in 3D: eigenvalues {0, |v|^2-ish, ...}, one null direction
        let v = [1.0, 2.0, 0.5];
        let w = [0.0, 1.0, -1.0];
        let mut s = vec![0.0; 9];
        for i in 0..3 {
            for j in 0..3 {
                s[i * 3 + j] = v[i] * v[j] + w[i] * w[j];
            }
        }
        let (eig, vecs) = jacobi_eigen(&s, 3);
        let (eig2, _) = symmetric_eigen(&s, 3);
        let mut sorted = eig.clone();
        sorted.sort_by(f64::total_cmp);
        assert!(
            sorted.iter().zip(&eig2).all(|(a, b)| (a - b).abs() < 1e-12),
            "{sorted:?} vs {eig2:?}"
        );
        assert_eq!(eig.iter().filter(|e| e.abs() < 1e-12).count(), 1);
        for k in 0..3 {
            for i in 0..3 {
                let sv: f64 = (0..3).map(|j| s[i * 3 + j] * vecs[j * 3 + k]).sum();
                assert!((sv - eig[k] * vecs[i * 3 + k]).abs() < 1e-12);
            }
        }
        // a consistent right-hand side is solved with the minimum-norm solution
        let r: Vec<f64> = (0..3).map(|i| 2.0 * s[i * 3] + s[i * 3 + 1]).collect();
        let x = pseudo_solve(&s, &r, 3).unwrap();
        let back: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| s[i * 3 + j] * x[j]).sum())
            .collect();
        assert!(back.iter().zip(&r).all(|(a, b)| (a - b).abs() < 1e-12));
        // an inconsistent one is refused
        let null: Vec<f64> = (0..3)
            .map(|i| vecs[i * 3 + eig.iter().position(|e| e.abs() < 1e-12).unwrap()])
            .collect();
        assert!(pseudo_solve(&s, &null, 3).is_err());
    }
}
