//! The static solve of small-strain elasticity: `K u = f` with prescribed dofs eliminated.
//!
//! The prescribed dofs are the Dirichlet lines of an [`AffineConstraints`] set built from the
//! model's prescribed values; it owns the equation numbering (free dofs only) and the
//! prescribed values. With `u = [u_f; u_p]` and `u_p` prescribed,
//! `K_ff u_f = f_f - K_fp u_p` is assembled element by element through the set's
//! [`crate::solver::constraints::LocalAssembler`] (a scatter of each element's free block and
//! its `K_fp u_p` term: no `T^T K T` product for Dirichlet data), factored by sparse Cholesky
//! and solved (with two steps of iterative refinement). Reactions are the residual of
//! the full system, `r = f_int(u) - f` (`= K u - f`), with the internal force evaluated element
//! by element (`internal_force`, from the solids' residual kernel); at free dofs it is the
//! equilibrium error (reported as `residual`), at prescribed dofs it is the support reaction.
//!
//! Every number a run reports must be finite: the assembled loads, stiffness and right-hand
//! side, each solution and the reactions are checked, and the first non-finite value is an
//! error naming its dof (body, node, component, coordinates) and the stage it appeared at.
//! Maxima propagate NaN (`max_abs`), so that a NaN can never pass as a zero residual.

use crate::error::{Error, Result};
use crate::model::space::SolidCell;
use crate::model::Model;
use crate::solid::MAX_DOFS;
use crate::solver::constraints::AffineConstraints;
pub use crate::solver::constraints::NO_EQUATION;
use crate::solver::sparse::{Cholesky, FactorError, PatternBuilder, SymmetricPattern};
use std::time::Instant;

/// Wall-clock seconds of each stage of a run.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Timings {
    /// Reading, validating and meshing the case.
    pub mesh: f64,
    /// Sparsity pattern, element kernels and scatter; for the static linear and active-set
    /// solves also the factor's ordering and symbolic analysis, which run on a second thread
    /// beside the element kernels ([`assemble_with`]).
    pub assembly: f64,
    /// Numeric Cholesky factorization, and the symbolic analysis where it is not overlapped
    /// with the assembly (with `"cg_amg"`: the multigrid setups).
    pub factorization: f64,
    /// Triangular solves and reactions (with `"cg_amg"`: the CG iterations).
    pub solve: f64,
    /// Contact search and row evaluation (every geometry update and load step); 0 without
    /// contact.
    pub contact_search: f64,
    pub total: f64,
}

impl Timings {
    /// Add the phases of another solve (a geometry update or load step) to these.
    pub fn accumulate(&mut self, other: &Timings) {
        self.assembly += other.assembly;
        self.factorization += other.factorization;
        self.solve += other.solve;
        self.contact_search += other.contact_search;
    }
}

/// The displacement solution and what the solve measured.
#[derive(Clone, Debug)]
pub struct Solution<const D: usize = 2> {
    /// Global displacement vector (prescribed values included).
    pub u: Vec<f64>,
    /// `K u - f` at every dof: reactions at prescribed dofs, equilibrium error elsewhere.
    pub reactions: Vec<f64>,
    pub equations: usize,
    pub matrix_nonzeros: usize,
    /// Largest |K u - f| at a free dof relative to [`Solution::force_scale`].
    pub relative_residual: f64,
    /// The force the residual is measured against: the largest external, contact or support
    /// force, or the largest sum of magnitudes `sum_j |K_ij| |u_j|` that makes up a row of
    /// `K u` (its round-off is the residual's floor), whichever is larger. A body moved
    /// without load (a rigid lift) has no load to divide by, but has those terms.
    pub force_scale: f64,
    pub timings: Timings,
    /// What the contact solve found, when the model has contact pairs.
    pub contact: Option<crate::contact::state::ContactState<D>>,
    /// The record of a time integration (`physics.dynamics`); `None` for a static run.
    pub dynamics: Option<Box<crate::solver::history::DynamicHistory>>,
    /// The load stepping of a finite-kinematics solve (every attempt, cuts with their
    /// reasons); `None` with small strain.
    pub finite: Option<Box<crate::solver::history::FiniteHistory>>,
    /// What the iterative linear solves did (`solver.linear_solver: "cg_amg"`); `None` with
    /// the direct solver.
    pub iterative: Option<crate::solver::iterative::IterativeRecord>,
}

/// Calls `visit(dofs, ke)` for every cell of every body.
pub fn for_each_element_stiffness<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    mut visit: impl FnMut(&[usize], &[f64]),
) {
    let mut dofs = Vec::with_capacity(MAX_DOFS);
    let mut ke = Vec::new();
    for body in &model.bodies {
        let kind = body.mesh.kind;
        let rule = kind.stiffness_rule();
        let nd = D * kind.node_count();
        ke.resize(nd * nd, 0.0);
        for c in 0..body.mesh.cell_count() {
            let coords = body.mesh.cell_coords(c);
            kind.element_stiffness(&coords, &body.material, model.thickness, &rule, &mut ke);
            body.cell_dofs(c, &mut dofs);
            visit(&dofs, &ke[..nd * nd]);
        }
    }
}

/// The assembled stiffness over the free equations: `K_ff` and `f_f - K_fp u_p`.
pub struct LinearSystem {
    /// The Dirichlet data as affine constraints: the equation of each global dof
    /// ([`AffineConstraints::equations`], `NO_EQUATION` when prescribed), the dof of each
    /// equation and the prescribed values ([`AffineConstraints::constants`]).
    pub constraints: AffineConstraints,
    pub n: usize,
    pub pattern: SymmetricPattern,
    /// Values of `K_ff` on `pattern`.
    pub k: Vec<f64>,
    /// `f_f - K_fp u_p`.
    pub rhs: Vec<f64>,
}

impl LinearSystem {
    /// Global displacement from the free-equation solution `x` (prescribed values included).
    pub fn expand(&self, x: &[f64]) -> Vec<f64> {
        self.constraints.expand(x)
    }

    /// The equation of global dof `d` (`NO_EQUATION` when prescribed).
    pub fn eq(&self, d: usize) -> usize {
        self.constraints.equations()[d]
    }

    /// The global dof of equation `e`.
    pub fn dof_of(&self, e: usize) -> Option<usize> {
        self.constraints.free_dofs().get(e).copied()
    }

    /// The error for a stiffness that cannot be factored: `equation` is where the first bad
    /// pivot was found (in the caller's numbering), `what` says what was wrong with it.
    pub fn singular<const D: usize, K: SolidCell<D>>(
        &self,
        model: &Model<D, K>,
        equation: Option<usize>,
        what: &str,
    ) -> Error {
        let dof = equation.and_then(|e| self.dof_of(e));
        let where_ = dof
            .map(|d| describe_dof(model, d))
            .unwrap_or_else(|| "an unknown equation".into());
        let hint = match dof.and_then(|d| orphan_node(model, d)) {
            Some((body, node)) => format!(
                "node {node} of body '{body}' belongs to no cell, so nothing holds it: remove it from the node list or use it in a cell"
            ),
            None => "a part of a body may be disconnected from the supports (a mechanism), or a body held only by contact lost it; add supports or connect it".into(),
        };
        Error::Solver {
            path: model.source.clone(),
            problem: format!(
                "the stiffness matrix is singular or not positive definite ({what} at {where_})"
            ),
            hint,
        }
    }

    pub fn factor_error<const D: usize, K: SolidCell<D>>(
        &self,
        model: &Model<D, K>,
        e: FactorError,
    ) -> Error {
        match e {
            FactorError::NotPositiveDefinite { equation } => {
                self.singular(model, Some(equation), "first bad pivot")
            }
            FactorError::ZeroPivot {
                equation,
                ratio,
                regularized,
            } => {
                let what = if regularized > 0 {
                    format!("{regularized} pivot(s) needed regularization, the first")
                } else {
                    format!("a pivot is zero relative to its diagonal (ratio {ratio:.1e})")
                };
                match self.singular(model, Some(equation), &what) {
                    Error::Solver {
                        path,
                        problem,
                        hint,
                    } => Error::Solver {
                        path,
                        problem,
                        hint: format!("{hint}; a penalty far stiffer than the bodies (kappa above about 1e10 E / h) also makes the matrix singular to working precision"),
                    },
                    other => other,
                }
            }
            FactorError::TooLarge { work, limit } => Error::Solver {
                path: model.source.clone(),
                problem: work.refusal(&limit),
                hint: crate::solver::sparse::TOO_LARGE_HINT.into(),
            },
            FactorError::Other(msg) => Error::Solver {
                path: model.source.clone(),
                problem: format!("the factorization failed: {msg}"),
                hint: "the problem may be too large for the memory of this machine".into(),
            },
        }
    }

    /// `Ok` when every entry of `x` (one per equation) is finite, else the error naming the
    /// first non-finite one: `what` names the vector, `stage` when it was computed.
    pub fn check_finite<const D: usize, K: SolidCell<D>>(
        &self,
        model: &Model<D, K>,
        x: &[f64],
        what: &str,
        stage: &str,
    ) -> Result<()> {
        match x.iter().position(|v| !v.is_finite()) {
            None => Ok(()),
            Some(e) => Err(non_finite(model, what, x[e], self.dof_of(e), stage)),
        }
    }
}

/// The body and node of global dof `d` when that node belongs to no cell.
fn orphan_node<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    d: usize,
) -> Option<(String, usize)> {
    let owner = model.dof_owner(d)?;
    let (body, node) = (&model.bodies[owner.body], owner.node);
    let used = (0..body.mesh.cell_count()).any(|c| body.mesh.cell(c).contains(&node));
    (!used).then(|| (body.name.clone(), node))
}

/// The largest `|v|`, or NaN when a value is NaN (`f64::max` would drop it).
pub fn max_abs<'a>(values: impl IntoIterator<Item = &'a f64>) -> f64 {
    values.into_iter().fold(0.0f64, |m, v| {
        if m.is_nan() || v.is_nan() {
            f64::NAN
        } else {
            m.max(v.abs())
        }
    })
}

/// The error for a non-finite `value` of `what` at global dof `dof`, computed at `stage`.
pub fn non_finite<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    what: &str,
    value: f64,
    dof: Option<usize>,
    stage: &str,
) -> Error {
    let at = dof.map_or_else(|| "an unknown dof".into(), |d| describe_dof(model, d));
    non_finite_at(model, what, value, &at, stage)
}

/// The error for a non-finite `value` of `what` at the place `at` (in words).
pub fn non_finite_at<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    what: &str,
    value: f64,
    at: &str,
    stage: &str,
) -> Error {
    let moduli = model
        .bodies
        .iter()
        .map(|b| K::youngs_modulus(&b.material))
        .fold(0.0f64, f64::max);
    let loads = max_abs(&model.external_force);
    Error::Solver {
        path: model.source.clone(),
        problem: format!(
            "{what} is not finite ({value}) at {at}, first seen {stage}; the results would hold NaN or infinity"
        ),
        hint: format!(
            "the loads (nodal forces up to {loads:.3e}), prescribed values or moduli (E up to {moduli:.3e}) are beyond double precision (about 1e308, with products of two such numbers): rescale the units (e.g. N and mm) so that they stay far from it"
        ),
    }
}

/// Assemble `K_ff` and the right-hand side. `extra_blocks` (global dofs) are added to the
/// sparsity pattern, e.g. the dofs coupled by contact constraints.
pub fn assemble<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    extra_blocks: &[Vec<usize>],
) -> LinearSystem {
    let constraints = AffineConstraints::dirichlet(&model.prescribed);
    assemble_with(model, constraints, extra_blocks, |_| ()).0
}

/// [`assemble`] under the Dirichlet `constraints`, with `analyse` run on the sparsity pattern
/// on a second thread while the element values are assembled on this one (the ordering and
/// symbolic analysis of a sparse factorization need the pattern only), and its result.
pub fn assemble_with<const D: usize, K: SolidCell<D>, R: Send>(
    model: &Model<D, K>,
    constraints: AffineConstraints,
    extra_blocks: &[Vec<usize>],
    analyse: impl FnOnce(&SymmetricPattern) -> R + Send,
) -> (LinearSystem, R) {
    let n = constraints.free_count();
    let mut local = constraints.local();
    let mut builder = PatternBuilder::new(n);
    let mut dofs = Vec::with_capacity(MAX_DOFS);
    for body in &model.bodies {
        for c in 0..body.mesh.cell_count() {
            body.cell_dofs(c, &mut dofs);
            local.add_pattern(&dofs, &mut builder);
        }
    }
    for block in extra_blocks {
        local.add_pattern(block, &mut builder);
    }
    let pattern = builder.build();
    let (k, rhs, analysis) = std::thread::scope(|scope| {
        let analysis = scope.spawn(|| analyse(&pattern));
        let mut k = vec![0.0; pattern.nnz()];
        let mut rhs = constraints.reduce_vector(&model.external_force);
        for_each_element_stiffness(model, |dofs, ke| {
            local.distribute(dofs, ke, &pattern, &mut k, &mut rhs);
        });
        let analysis = analysis
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (k, rhs, analysis)
    });
    let sys = LinearSystem {
        constraints,
        n,
        pattern,
        k,
        rhs,
    };
    (sys, analysis)
}

/// Solve the static elastic problem without contact (see [`crate::solver`] for the entry that
/// adds contact when the scene asks for it). `progress` is told the name of each stage.
pub fn solve_elastic<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    progress: &mut dyn FnMut(&str),
) -> Result<Solution<D>> {
    let mut timings = Timings::default();
    let t = Instant::now();
    progress("assembling");
    // the factor's ordering and symbolic analysis run beside the assembly of the values
    let use_amg = model.solver.linear_solver == crate::io::scene::LinearSolver::CgAmg;
    let constraints = AffineConstraints::dirichlet(&model.prescribed);
    let points = (!use_amg && constraints.free_count() > 0)
        .then(|| model.equation_points(constraints.free_dofs()));
    let (sys, analysis) = assemble_with(model, constraints, &[], |pattern| {
        points.map(|points| Cholesky::analyse_at(pattern, Some(&points), &model.factor_limit))
    });
    sys.check_assembled(model)?;
    timings.assembly = t.elapsed().as_secs_f64();

    if use_amg {
        crate::solver::iterative::refuse_unless_admitted(model)?;
        progress("multigrid setup and CG");
        let mut amg = crate::solver::iterative::AmgSolver::new(model, sys.constraints.free_dofs());
        let mut x = vec![0.0; sys.n];
        if sys.n > 0 {
            amg.solve(&sys.pattern, &sys.k, &sys.rhs, &mut x)
                .map_err(|why| Error::Solver {
                    path: model.source.clone(),
                    problem: format!("the elastic solve is {why}"),
                    hint: "a mechanism (a part not held by the supports) also stops CG; check the supports".into(),
                })?;
            sys.check_finite(model, &x, "the displacement", "in the CG solve of K u = f")?;
        }
        timings.factorization = amg.record.setup_seconds;
        timings.solve = amg.record.cg_seconds;
        let u = sys.expand(&x);
        let t = Instant::now();
        let mut solution = finish(model, &sys, u, &[], timings)?;
        solution.timings.solve += t.elapsed().as_secs_f64();
        solution.iterative = Some(amg.record);
        return Ok(solution);
    }
    let t = Instant::now();
    progress("factorizing");
    let mut x = sys.rhs.clone();
    if let Some(analysis) = analysis {
        let chol = analysis.map_err(|e| sys.factor_error(model, e))?;
        let factor = chol
            .factor(&sys.pattern, &sys.k)
            .map_err(|e| sys.factor_error(model, e))?;
        timings.factorization = t.elapsed().as_secs_f64();
        let t = Instant::now();
        progress("solving");
        factor.solve_in_place(&mut x);
        sys.check_finite(model, &x, "the displacement", "in the solve of K u = f")?;
        // two steps of iterative refinement: on ill-conditioned meshes they bring the solution
        // from about cond(K) eps down to the accuracy of the residual
        let mut r = vec![0.0; sys.n];
        for step in 1..=2 {
            sys.pattern.mul(&sys.k, &x, &mut r);
            r.iter_mut().zip(&sys.rhs).for_each(|(a, b)| *a = b - *a);
            factor.solve_in_place(&mut r);
            x.iter_mut().zip(&r).for_each(|(a, d)| *a += d);
            sys.check_finite(
                model,
                &x,
                "the displacement",
                &format!("in step {step} of the iterative refinement"),
            )?;
        }
        timings.solve = t.elapsed().as_secs_f64();
    }
    let u = sys.expand(&x);
    let t = Instant::now();
    let mut solution = finish(model, &sys, u, &[], timings)?;
    solution.timings.solve += t.elapsed().as_secs_f64();
    Ok(solution)
}

impl LinearSystem {
    /// `Ok` when the external forces, the assembled stiffness and the right-hand side
    /// `f_f - K_fp u_p` are finite, else the error naming the first dof where they are not.
    pub fn check_assembled<const D: usize, K: SolidCell<D>>(
        &self,
        model: &Model<D, K>,
    ) -> Result<()> {
        if let Some(d) = model.external_force.iter().position(|v| !v.is_finite()) {
            return Err(non_finite(
                model,
                "the external force",
                model.external_force[d],
                Some(d),
                "when the loads were assembled",
            ));
        }
        for j in 0..self.n {
            let column = self.pattern.col_ptr[j]..self.pattern.col_ptr[j + 1];
            if let Some(k) = column.clone().find(|&k| !self.k[k].is_finite()) {
                return Err(non_finite(
                    model,
                    "the stiffness",
                    self.k[k],
                    self.dof_of(j),
                    "when the stiffness was assembled",
                ));
            }
        }
        self.check_finite(
            model,
            &self.rhs,
            "the right-hand side f - K u_prescribed",
            "when the prescribed values were moved to the right-hand side",
        )
    }
}

/// Reactions and the equilibrium residual of `u`, given contact nodal forces `contact_force`
/// (global, possibly empty). Every one of them must be finite: the error names the first dof
/// where one is not.
pub fn finish<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    sys: &LinearSystem,
    u: Vec<f64>,
    contact_force: &[f64],
    timings: Timings,
) -> Result<Solution<D>> {
    if let Some(d) = u.iter().position(|v| !v.is_finite()) {
        return Err(non_finite(
            model,
            "the displacement",
            u[d],
            Some(d),
            "in the solution",
        ));
    }
    if let Some(d) = contact_force.iter().position(|v| !v.is_finite()) {
        return Err(non_finite(
            model,
            "the contact force",
            contact_force[d],
            Some(d),
            "in the nodal contact forces of the solution",
        ));
    }
    let mut reactions = residual(model, &u);
    for (r, c) in reactions.iter_mut().zip(contact_force) {
        *r -= c;
    }
    if let Some(d) = reactions.iter().position(|v| !v.is_finite()) {
        return Err(non_finite(
            model,
            "the reaction K u - f",
            reactions[d],
            Some(d),
            "in the reactions of the solution",
        ));
    }
    // the support reactions are the forces of the Dirichlet constraints
    let supports = sys.constraints.forces(&reactions);
    // sum_j |K_ij| |u_j| over the free equations (the prescribed values' terms |K_fp| |u_p|
    // are in the right-hand side's magnitude)
    let mut terms = vec![0.0; sys.n];
    let abs_k: Vec<f64> = sys.k.iter().map(|v| v.abs()).collect();
    let abs_u: Vec<f64> = sys
        .constraints
        .free_dofs()
        .iter()
        .map(|&d| u[d].abs())
        .collect();
    sys.pattern.mul(&abs_k, &abs_u, &mut terms);
    let scale = max_abs(
        model
            .external_force
            .iter()
            .chain(contact_force)
            .chain(&supports)
            .chain(&terms)
            .chain(&sys.rhs),
    );
    let worst = max_abs(sys.constraints.free_dofs().iter().map(|&d| &reactions[d]));
    Ok(Solution {
        u,
        reactions,
        equations: sys.n,
        matrix_nonzeros: sys.pattern.nnz(),
        relative_residual: if scale > 0.0 { worst / scale } else { worst },
        force_scale: scale,
        timings,
        contact: None,
        dynamics: None,
        finite: None,
        iterative: None,
    })
}

/// The internal force `f_int(u)` of every body at the global displacement `u`, element by
/// element (small strain: `K u`; finite kinematics: [`crate::solver::finite_assembly::internal_force`]).
pub fn internal_force<const D: usize, K: SolidCell<D>>(model: &Model<D, K>, u: &[f64]) -> Vec<f64> {
    if model.physics.kinematics == crate::io::scene::Kinematics::Finite {
        // an inverted element has no internal force: NaN, which every caller refuses by name
        return crate::solver::finite_assembly::internal_force(model, u)
            .unwrap_or_else(|_| vec![f64::NAN; u.len()]);
    }
    let mut f = vec![0.0; u.len()];
    let mut dofs = Vec::with_capacity(MAX_DOFS);
    let mut ue = Vec::new();
    let mut fe = Vec::new();
    for body in &model.bodies {
        let kind = body.mesh.kind;
        let rule = kind.stiffness_rule();
        for c in 0..body.mesh.cell_count() {
            body.cell_dofs(c, &mut dofs);
            ue.clear();
            ue.extend(dofs.iter().map(|&d| u[d]));
            fe.clear();
            fe.resize(dofs.len(), 0.0);
            kind.add_internal_force(
                &body.mesh.cell_coords(c),
                &ue,
                &body.material,
                model.thickness,
                &rule,
                &mut fe,
            );
            for (a, &d) in dofs.iter().enumerate() {
                f[d] += fe[a];
            }
        }
    }
    f
}

/// `f_int(u) - f`, element by element.
pub fn residual<const D: usize, K: SolidCell<D>>(model: &Model<D, K>, u: &[f64]) -> Vec<f64> {
    let mut r = internal_force(model, u);
    for (r, f) in r.iter_mut().zip(&model.external_force) {
        *r -= f;
    }
    r
}

/// "body 'x', node n at (x, y), u_x" for a global dof.
pub fn describe_dof<const D: usize, K: SolidCell<D>>(model: &Model<D, K>, dof: usize) -> String {
    match model.dof_owner(dof) {
        Some(r) => {
            let body = &model.bodies[r.body];
            let p = body.mesh.nodes[r.node];
            let at: Vec<String> = p.iter().map(|x| x.to_string()).collect();
            format!(
                "body '{}', node {} at ({}), u_{}",
                body.name,
                r.node,
                at.join(", "),
                K::axis_name(r.component)
            )
        }
        None => format!("dof {dof}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_largest_magnitude_keeps_nan() {
        assert_eq!(max_abs(&[1.0, -3.0, 2.0]), 3.0);
        assert!(max_abs(&[1.0, f64::NAN, 2.0]).is_nan());
        assert!(max_abs(&[f64::NAN, 1.0]).is_nan());
        assert_eq!(max_abs(&[1.0, f64::NEG_INFINITY]), f64::INFINITY);
        assert_eq!(max_abs(&[]), 0.0);
    }
}
