//! The static solve of small-strain elasticity: `K u = f` with prescribed dofs eliminated.
//!
//! Equations are numbered over the free dofs only. With `u = [u_f; u_p]` and `u_p` prescribed,
//! `K_ff u_f = f_f - K_fp u_p` is assembled element by element (the `K_fp u_p` term from each
//! element's own block), factored by sparse Cholesky and solved (with two steps of iterative
//! refinement). Reactions are the residual of
//! the full system, `r = K u - f`, evaluated element by element; at free dofs it is the
//! equilibrium error (reported as `residual`), at prescribed dofs it is the support reaction.

use crate::error::{Error, Result};
use crate::model::Model;
use crate::solid::{element_stiffness, MAX_DOFS};
use crate::sparse::{Cholesky, FactorError, PatternBuilder, SymmetricPattern};
use std::time::Instant;

/// Marks a dof that has no equation (it is prescribed).
pub const NO_EQUATION: usize = usize::MAX;

/// Wall-clock seconds of each stage of a run.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Timings {
    /// Reading, validating and meshing the case.
    pub mesh: f64,
    /// Sparsity pattern, element kernels and scatter.
    pub assembly: f64,
    /// Symbolic analysis and numeric Cholesky factorization.
    pub factorization: f64,
    /// Triangular solves and reactions.
    pub solve: f64,
    pub total: f64,
}

/// The displacement solution and what the solve measured.
#[derive(Clone, Debug)]
pub struct Solution {
    /// Global displacement vector (prescribed values included).
    pub u: Vec<f64>,
    /// `K u - f` at every dof: reactions at prescribed dofs, equilibrium error elsewhere.
    pub reactions: Vec<f64>,
    pub equations: usize,
    pub matrix_nonzeros: usize,
    /// Largest |K u - f| at a free dof relative to the largest external or reaction force.
    pub relative_residual: f64,
    pub timings: Timings,
    /// What the contact solve found, when the model has contact pairs.
    pub contact: Option<crate::contact::solver::ContactState>,
}

/// Equation number of each global dof (`NO_EQUATION` for prescribed dofs).
pub fn number_equations(model: &Model) -> (Vec<usize>, usize) {
    let mut count = 0;
    let eq = model
        .prescribed
        .iter()
        .map(|p| {
            if p.is_some() {
                NO_EQUATION
            } else {
                count += 1;
                count - 1
            }
        })
        .collect();
    (eq, count)
}

/// Calls `visit(dofs, ke)` for every cell of every body.
pub fn for_each_element_stiffness(model: &Model, mut visit: impl FnMut(&[usize], &[f64])) {
    let mut dofs = Vec::with_capacity(MAX_DOFS);
    let mut ke = [0.0; MAX_DOFS * MAX_DOFS];
    for body in &model.bodies {
        let kind = body.mesh.kind;
        let rule = kind.stiffness_rule();
        let nd = 2 * kind.node_count();
        for c in 0..body.mesh.cell_count() {
            let coords = body.mesh.cell_coords(c);
            element_stiffness(
                kind,
                &coords,
                &body.material,
                model.thickness,
                &rule,
                &mut ke,
            );
            body.cell_dofs(c, &mut dofs);
            visit(&dofs, &ke[..nd * nd]);
        }
    }
}

/// The assembled stiffness over the free equations: `K_ff` and `f_f - K_fp u_p`.
pub struct LinearSystem {
    /// Equation of each global dof (`NO_EQUATION` when prescribed).
    pub eq: Vec<usize>,
    pub n: usize,
    pub pattern: SymmetricPattern,
    /// Values of `K_ff` on `pattern`.
    pub k: Vec<f64>,
    /// `f_f - K_fp u_p`.
    pub rhs: Vec<f64>,
    /// Global vector holding the prescribed values (zero at free dofs).
    pub u_prescribed: Vec<f64>,
}

impl LinearSystem {
    /// Global displacement from the free-equation solution `x`.
    pub fn expand(&self, x: &[f64]) -> Vec<f64> {
        let mut u = self.u_prescribed.clone();
        for (d, &e) in self.eq.iter().enumerate() {
            if e != NO_EQUATION {
                u[d] = x[e];
            }
        }
        u
    }

    /// The global dof of equation `e`.
    pub fn dof_of(&self, e: usize) -> Option<usize> {
        self.eq.iter().position(|&x| x == e)
    }

    /// The error for a stiffness that cannot be factored: `equation` is where the first bad
    /// pivot was found (in the caller's numbering), `what` says what was wrong with it.
    pub fn singular(&self, model: &Model, equation: Option<usize>, what: &str) -> Error {
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

    pub fn factor_error(&self, model: &Model, e: FactorError) -> Error {
        match e {
            FactorError::NotPositiveDefinite { equation } => {
                self.singular(model, Some(equation), "first bad pivot")
            }
            FactorError::Other(msg) => Error::Solver {
                path: model.source.clone(),
                problem: format!("the factorization failed: {msg}"),
                hint: "the problem may be too large for the memory of this machine".into(),
            },
        }
    }
}

/// The body and node of global dof `d` when that node belongs to no cell.
fn orphan_node(model: &Model, d: usize) -> Option<(String, usize)> {
    let body = model
        .bodies
        .iter()
        .find(|b| d >= b.dof_offset && d < b.dof_offset + b.dof_count())?;
    let node = (d - body.dof_offset) / 2;
    let used = (0..body.mesh.cell_count()).any(|c| body.mesh.cell(c).contains(&node));
    (!used).then(|| (body.name.clone(), node))
}

/// Assemble `K_ff` and the right-hand side. `extra_blocks` (global dofs) are added to the
/// sparsity pattern, e.g. the dofs coupled by contact constraints.
pub fn assemble(model: &Model, extra_blocks: &[Vec<usize>]) -> LinearSystem {
    let (eq, n) = number_equations(model);
    let u_prescribed: Vec<f64> = model.prescribed.iter().map(|p| p.unwrap_or(0.0)).collect();
    let mut builder = PatternBuilder::new(n);
    let mut dofs = Vec::with_capacity(MAX_DOFS);
    let mut eqs = Vec::with_capacity(MAX_DOFS);
    for body in &model.bodies {
        for c in 0..body.mesh.cell_count() {
            body.cell_dofs(c, &mut dofs);
            eqs.clear();
            eqs.extend(dofs.iter().map(|&d| eq[d]));
            builder.add_block(&eqs);
        }
    }
    for block in extra_blocks {
        let eqs: Vec<usize> = block.iter().map(|&d| eq[d]).collect();
        builder.add_block(&eqs);
    }
    let pattern = builder.build();
    let mut k = vec![0.0; pattern.nnz()];
    let mut rhs = vec![0.0; n];
    for (d, &e) in eq.iter().enumerate() {
        if e != NO_EQUATION {
            rhs[e] = model.external_force[d];
        }
    }
    for_each_element_stiffness(model, |dofs, ke| {
        eqs.clear();
        eqs.extend(dofs.iter().map(|&d| eq[d]));
        pattern.scatter(&eqs, ke, &mut k);
        // move K_fp u_p to the right-hand side
        let m = dofs.len();
        for (b, &db) in dofs.iter().enumerate() {
            if eqs[b] != NO_EQUATION || u_prescribed[db] == 0.0 {
                continue;
            }
            for a in 0..m {
                if eqs[a] != NO_EQUATION {
                    rhs[eqs[a]] -= ke[a * m + b] * u_prescribed[db];
                }
            }
        }
    });
    LinearSystem {
        eq,
        n,
        pattern,
        k,
        rhs,
        u_prescribed,
    }
}

/// Solve the static problem (with contact when the model has contact pairs). `progress` is
/// told the name of each stage as it starts.
pub fn solve_static(model: &Model, progress: &mut dyn FnMut(&str)) -> Result<Solution> {
    if !model.contact.is_empty() {
        return crate::contact::solver::solve(model, progress);
    }
    let mut timings = Timings::default();
    let t = Instant::now();
    progress("assembling");
    let sys = assemble(model, &[]);
    timings.assembly = t.elapsed().as_secs_f64();

    let t = Instant::now();
    progress("factorizing");
    let mut x = sys.rhs.clone();
    if sys.n > 0 {
        let chol = Cholesky::analyse(&sys.pattern).map_err(|e| sys.factor_error(model, e))?;
        let factor = chol
            .factor(&sys.pattern, &sys.k)
            .map_err(|e| sys.factor_error(model, e))?;
        timings.factorization = t.elapsed().as_secs_f64();
        let t = Instant::now();
        progress("solving");
        factor.solve_in_place(&mut x);
        // two steps of iterative refinement: on ill-conditioned meshes they bring the solution
        // from about cond(K) eps down to the accuracy of the residual
        let mut r = vec![0.0; sys.n];
        for _ in 0..2 {
            sys.pattern.mul(&sys.k, &x, &mut r);
            r.iter_mut().zip(&sys.rhs).for_each(|(a, b)| *a = b - *a);
            factor.solve_in_place(&mut r);
            x.iter_mut().zip(&r).for_each(|(a, d)| *a += d);
        }
        timings.solve = t.elapsed().as_secs_f64();
    }
    if x.iter().any(|v| !v.is_finite()) {
        return Err(sys.singular(model, None, "a non-finite solution"));
    }
    let u = sys.expand(&x);
    let t = Instant::now();
    let mut solution = finish(model, &sys, u, &[], timings);
    solution.timings.solve += t.elapsed().as_secs_f64();
    Ok(solution)
}

/// Reactions and the equilibrium residual of `u`, given contact nodal forces `contact_force`
/// (global, possibly empty).
pub fn finish(
    model: &Model,
    sys: &LinearSystem,
    u: Vec<f64>,
    contact_force: &[f64],
    timings: Timings,
) -> Solution {
    let mut reactions = residual(model, &u);
    for (r, c) in reactions.iter_mut().zip(contact_force) {
        *r -= c;
    }
    let eq = &sys.eq;
    let scale = model
        .external_force
        .iter()
        .chain(contact_force)
        .chain(
            reactions
                .iter()
                .enumerate()
                .filter(|(d, _)| eq[*d] == NO_EQUATION)
                .map(|(_, r)| r),
        )
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = reactions
        .iter()
        .enumerate()
        .filter(|(d, _)| eq[*d] != NO_EQUATION)
        .fold(0.0f64, |m, (_, r)| m.max(r.abs()));
    Solution {
        u,
        reactions,
        equations: sys.n,
        matrix_nonzeros: sys.pattern.nnz(),
        relative_residual: if scale > 0.0 { worst / scale } else { worst },
        timings,
        contact: None,
    }
}

/// `K u - f`, element by element.
pub fn residual(model: &Model, u: &[f64]) -> Vec<f64> {
    let mut r: Vec<f64> = model.external_force.iter().map(|f| -f).collect();
    for_each_element_stiffness(model, |dofs, ke| {
        let m = dofs.len();
        for a in 0..m {
            let mut s = 0.0;
            for b in 0..m {
                s += ke[a * m + b] * u[dofs[b]];
            }
            r[dofs[a]] += s;
        }
    });
    r
}

/// "body 'x', node n at (x, y), u_x" for a global dof.
pub fn describe_dof(model: &Model, dof: usize) -> String {
    for body in &model.bodies {
        if dof >= body.dof_offset && dof < body.dof_offset + body.dof_count() {
            let local = dof - body.dof_offset;
            let node = local / 2;
            let p = body.mesh.nodes[node];
            return format!(
                "body '{}', node {node} at ({}, {}), u_{}",
                body.name,
                p[0],
                p[1],
                ["x", "y"][local % 2]
            );
        }
    }
    format!("dof {dof}")
}
