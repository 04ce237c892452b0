//! The case's choice of linear solver (`solver.linear_solver`) and the iterative one,
//! conjugate gradients preconditioned by smoothed-aggregation AMG ([`crate::solver::amg`]),
//! applied to the systems of a model.
//!
//! CG needs a symmetric positive definite matrix (Saad, *Iterative Methods for Sparse Linear
//! Systems*, 2003, sec. 6.7), so `"cg_amg"` is admitted for small-strain elasticity and for the
//! active-set loop of the penalty family (penalty, augmented Lagrangian, perturbed Lagrangian
//! with a lumped multiplier mass), whose matrices `K + sum_i w_i b_i b_i^T` with `w_i > 0`
//! are SPD; Lagrange multipliers and a consistent perturbed Lagrangian (saddle points,
//! indefinite), constraint elimination (a reduced system of its own), the perturbed tangent,
//! Coulomb friction and the Newton scheme (unsymmetric tangents), finite kinematics and
//! dynamics are refused with the reason ([`refuse_unless_admitted`]).
//!
//! The near-null space of the AMG is built from the model: the rigid-body modes of every
//! node with a free dof, at its coordinates ([`crate::solver::amg::rigid_body_modes`]); the
//! nodal blocks are the free dofs of one node.
//!
//! Reuse in the active-set loop ([`AmgSolver::solve`]): each solve starts from the last
//! iterate (warm start, `||b - A x|| <= tol ||b||` measured against the new `b`); the hierarchy
//! of the first matrix is kept while the matrix changes in at most [`REBUILD_SHARE`] of its
//! rows (only its finest level and smoother are replaced), else built anew.

use crate::contact::enforcement::{method, Method};
use crate::error::{Error, Result};
use crate::io::scene::{Interaction, LinearSolver, Scheme};
use crate::model::space::SolidCell;
use crate::model::Model;
use crate::solver::amg::{
    conjugate_gradient, rigid_body_modes, AmgOptions, CgOutcome, CsrMatrix, Hierarchy,
    NearNullSpace, NodalBlocks,
};
use crate::solver::sparse::SymmetricPattern;
use std::time::Instant;

/// The share of changed rows of the matrix above which the active-set loop builds a new
/// hierarchy instead of replacing the finest level of the last one.
pub const REBUILD_SHARE: f64 = 0.05;

/// What the iterative solves of a run did (`summary.json`, `linear_solver`).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct IterativeRecord {
    /// `"cg_amg"`.
    pub solver: String,
    /// The relative residual each solve had to reach.
    pub tolerance: f64,
    /// Linear solves (one per active-set iteration, plus refinements).
    pub solves: usize,
    /// CG iterations of all solves, and of the longest one.
    pub iterations: usize,
    pub max_iterations: usize,
    /// `||b - A x|| / ||b||` of the last solve and the largest over all solves.
    pub relative_residual: f64,
    pub worst_relative_residual: f64,
    /// Hierarchies built, and solves that kept a hierarchy with a new finest level.
    pub setups: usize,
    pub finest_updates: usize,
    /// Equations of each level of the last hierarchy, finest first.
    pub levels: Vec<usize>,
    /// `sum_l nnz(A_l) / nnz(A_0)` of the last hierarchy.
    pub operator_complexity: f64,
    /// Seconds in the setups and in CG.
    pub setup_seconds: f64,
    pub cg_seconds: f64,
}

impl IterativeRecord {
    /// `total` with the solves of `part` added (load steps, geometry updates).
    pub fn merge(total: &mut Option<IterativeRecord>, part: &Option<IterativeRecord>) {
        let Some(part) = part else {
            return;
        };
        let Some(t) = total.as_mut() else {
            *total = Some(part.clone());
            return;
        };
        t.solves += part.solves;
        t.iterations += part.iterations;
        t.max_iterations = t.max_iterations.max(part.max_iterations);
        t.relative_residual = part.relative_residual;
        t.worst_relative_residual = t.worst_relative_residual.max(part.worst_relative_residual);
        t.setups += part.setups;
        t.finest_updates += part.finest_updates;
        t.levels = part.levels.clone();
        t.operator_complexity = part.operator_complexity;
        t.setup_seconds += part.setup_seconds;
        t.cg_seconds += part.cg_seconds;
    }

    /// One line for the messages.
    pub fn describe(&self) -> String {
        format!(
            "CG + smoothed-aggregation AMG ({} levels of {:?} equations, operator complexity {:.2}): {} solve(s), {} iterations (at most {} in one), relative residual {:.2e} (tolerance {:.0e}), {} setup(s) {:.2} s, CG {:.2} s",
            self.levels.len(),
            self.levels,
            self.operator_complexity,
            self.solves,
            self.iterations,
            self.max_iterations,
            self.relative_residual,
            self.tolerance,
            self.setups,
            self.setup_seconds,
            self.cg_seconds
        )
    }
}

/// `Ok` when the model's systems may be solved by `"cg_amg"` (or the case asks for the direct
/// solver), else the refusal with the reason and what to change.
pub fn refuse_unless_admitted<const D: usize, K: SolidCell<D>>(model: &Model<D, K>) -> Result<()> {
    if model.solver.linear_solver != LinearSolver::CgAmg {
        return Ok(());
    }
    let refuse = |at: String, why: &str| {
        Err(Error::invalid(
            &model.source,
            at,
            format!("\"linear_solver\": \"cg_amg\" is not built for {why}: conjugate gradients need a symmetric positive definite matrix"),
            "use \"linear_solver\": \"direct\" (the default) for this case",
        ))
    };
    if model.physics.kinematics == crate::io::scene::Kinematics::Finite {
        return refuse(
            "physics.kinematics".into(),
            "finite kinematics (its tangents may be indefinite)",
        );
    }
    if model.physics.dynamics.is_some() {
        return refuse("physics.dynamics".into(), "time integration");
    }
    for (k, pair) in model.contact.iter().enumerate() {
        if matches!(pair.interaction, Interaction::Coulomb { .. }) {
            return refuse(
                format!("contact[{k}] '{}'.interaction", pair.name),
                "Coulomb friction (an unsymmetric tangent)",
            );
        }
        let enforcement = method(&pair.enforcement);
        match enforcement.kernel() {
            Method::Regularized { .. }
            | Method::AugmentedLagrange { .. }
            | Method::PerturbedLagrange { .. } => {}
            Method::Lagrange => {
                return refuse(
                    format!("contact[{k}] '{}'.enforcement", pair.name),
                    "Lagrange multipliers (a saddle-point system, indefinite)",
                )
            }
            Method::Elimination => {
                return refuse(
                    format!("contact[{k}] '{}'.enforcement", pair.name),
                    "constraint elimination (its reduced system is factored directly)",
                )
            }
            Method::PerturbedTangent { .. } => {
                return refuse(
                    format!("contact[{k}] '{}'.enforcement", pair.name),
                    "the perturbed tangent (Newton on the Lagrange residual)",
                )
            }
        }
    }
    if model.solver.scheme == Scheme::Newton {
        return refuse(
            "solver.scheme".into(),
            "the Newton scheme (its contact tangents may be unsymmetric)",
        );
    }
    Ok(())
}

/// The refusal of a perturbed Lagrangian whose consistent multiplier mass keeps the
/// multipliers (a saddle-point system).
pub fn refuse_saddle_point<const D: usize, K: SolidCell<D>>(model: &Model<D, K>) -> Error {
    Error::invalid(
        &model.source,
        "solver.linear_solver",
        "\"linear_solver\": \"cg_amg\" is not built for a perturbed Lagrangian with a consistent multiplier mass (its multipliers stay unknowns of a saddle-point system, which is indefinite)",
        "use \"linear_solver\": \"direct\" (the default), or a lumped multiplier mass, for this case",
    )
}

/// CG + AMG on the free equations of one model, with its hierarchy kept between solves.
pub struct AmgSolver {
    blocks: NodalBlocks,
    null: NearNullSpace,
    options: AmgOptions,
    tolerance: f64,
    max_iterations: usize,
    hierarchy: Option<Hierarchy>,
    /// The upper-triangle values the hierarchy was built for (to count changed rows).
    origin: Vec<f64>,
    pub record: IterativeRecord,
}

impl AmgSolver {
    /// The solver of the free equations `free_dofs` (global dof of each equation) of `model`.
    pub fn new<const D: usize, K: SolidCell<D>>(model: &Model<D, K>, free_dofs: &[usize]) -> Self {
        let mut block_of_dof = vec![usize::MAX; model.dof_count];
        let mut block_of = Vec::with_capacity(free_dofs.len());
        let mut points = Vec::with_capacity(free_dofs.len());
        let mut components = Vec::with_capacity(free_dofs.len());
        let mut blocks = 0;
        for &d in free_dofs {
            let (point, component, first) = match model.dof_owner(d) {
                Some(owner) => {
                    let p = model.bodies[owner.body].mesh.nodes[owner.node];
                    let mut point = [0.0; 3];
                    point[..D].copy_from_slice(&p);
                    (point, owner.component, d - owner.component)
                }
                None => ([0.0; 3], 0, d),
            };
            if block_of_dof[first] == usize::MAX {
                block_of_dof[first] = blocks;
                blocks += 1;
            }
            block_of.push(block_of_dof[first]);
            points.push(point);
            components.push(component);
        }
        AmgSolver {
            blocks: NodalBlocks::from_block_of(&block_of),
            null: rigid_body_modes(&points, &components, D),
            options: AmgOptions {
                factor_limit: model.factor_limit,
                ..AmgOptions::default()
            },
            tolerance: model.solver.linear_tolerance,
            max_iterations: model.solver.linear_max_iterations,
            hierarchy: None,
            origin: Vec::new(),
            record: IterativeRecord {
                solver: "cg_amg".into(),
                tolerance: model.solver.linear_tolerance,
                ..IterativeRecord::default()
            },
        }
    }

    /// The hierarchy of the last solve, if any.
    pub fn hierarchy(&self) -> Option<&Hierarchy> {
        self.hierarchy.as_ref()
    }

    /// Solve `A x = b` (`A`'s upper triangle `values` on `pattern`) from the `x` given, to the
    /// case's tolerance; `Err` names why not (the hierarchy could not be built, or CG did not
    /// converge).
    pub fn solve(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[f64],
        b: &[f64],
        x: &mut [f64],
    ) -> std::result::Result<CgOutcome, String> {
        let t = Instant::now();
        self.prepare(pattern, values)?;
        self.record.setup_seconds += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let hierarchy = self.hierarchy.as_ref().expect("prepared");
        let outcome = conjugate_gradient(
            hierarchy.matrix(),
            |r, z| hierarchy.apply(r, z),
            b,
            x,
            self.tolerance,
            self.max_iterations,
        );
        self.record.cg_seconds += t.elapsed().as_secs_f64();
        let r = &mut self.record;
        r.solves += 1;
        r.iterations += outcome.iterations;
        r.max_iterations = r.max_iterations.max(outcome.iterations);
        r.relative_residual = outcome.relative_residual;
        r.worst_relative_residual = r.worst_relative_residual.max(outcome.relative_residual);
        if outcome.converged {
            Ok(outcome)
        } else {
            Err(format!(
                "not converged: CG + AMG reached the relative residual {:.3e} after {} iterations, above the tolerance {:.1e} (solver.linear_tolerance); raise solver.linear_max_iterations ({}) or use \"linear_solver\": \"direct\"",
                outcome.relative_residual, outcome.iterations, self.tolerance, self.max_iterations
            ))
        }
    }

    /// Make the hierarchy fit the matrix `values`: keep it when its matrix is this one,
    /// replace its finest level when at most [`REBUILD_SHARE`] of the rows differ from the
    /// matrix it was built for, else build anew.
    fn prepare(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[f64],
    ) -> std::result::Result<(), String> {
        if let Some(h) = self.hierarchy.as_mut() {
            if let Some(changed) = changed_rows(pattern, &self.origin, values) {
                if (changed as f64) <= REBUILD_SHARE * pattern.n as f64 {
                    let a = CsrMatrix::from_symmetric_upper(pattern, values);
                    if h.matrix().values == a.values {
                        return Ok(());
                    }
                    // a one-level hierarchy (the coarsest level alone) is rebuilt instead
                    if h.replace_finest(a).map_err(|e| e.to_string())? {
                        self.record.finest_updates += 1;
                        return Ok(());
                    }
                }
            }
        }
        let a = CsrMatrix::from_symmetric_upper(pattern, values);
        let hierarchy = Hierarchy::build(a, self.blocks.clone(), self.null.clone(), &self.options)
            .map_err(|e| format!("the multigrid setup failed: {e}"))?;
        self.record.setups += 1;
        self.record.levels = hierarchy.level_sizes();
        self.record.operator_complexity = hierarchy.operator_complexity();
        self.hierarchy = Some(hierarchy);
        self.origin = values.to_vec();
        Ok(())
    }
}

/// Rows of the symmetric matrix whose upper-triangle values differ between `old` and `new`
/// on `pattern` (`None` when the sizes differ).
fn changed_rows(pattern: &SymmetricPattern, old: &[f64], new: &[f64]) -> Option<usize> {
    if old.len() != new.len() || new.len() != pattern.nnz() {
        return None;
    }
    let mut changed = vec![false; pattern.n];
    for j in 0..pattern.n {
        for k in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
            if old[k] != new[k] {
                changed[j] = true;
                changed[pattern.row_idx[k]] = true;
            }
        }
    }
    Some(changed.iter().filter(|&&c| c).count())
}
