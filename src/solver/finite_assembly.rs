//! Assembly of finite-kinematics solids: the internal force `f_int(u) = assemble_e f_e(u_e)`
//! and the tangent `K_T(u) = assemble_e K_e(u_e)` from the total-Lagrangian hyperelastic
//! kernels of [`crate::solid_finite`] (plane strain in 2D, and 3D) behind
//! [`SolidCell::finite_residual_and_tangent`] (`f_a = sum_q w F S grad_0 N_a`, material +
//! geometric tangent), in 2D and 3D alike, over the free equations of the Dirichlet constraints (prescribed dofs eliminated,
//! [`crate::solver::constraints::AffineConstraints`]: the residual is `f_int(u) - f_ext`
//! restricted to the free dofs, `u` holding the prescribed values). An element with
//! `det F <= 0` at a quadrature point stops the assembly with its body and cell named
//! ([`InvertedElement`]).

use crate::model::space::SolidCell;
use crate::model::Model;
use crate::solid_finite::Inverted;
use crate::solver::constraints::AffineConstraints;
use crate::solver::sparse::SymmetricPattern;

/// An element inverted at a state: its body, cell and quadrature point.
#[derive(Clone, Debug)]
pub struct InvertedElement<const D: usize = 2> {
    pub body: String,
    pub cell: usize,
    pub inverted: Inverted<D>,
}

impl<const D: usize> std::fmt::Display for InvertedElement<D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "cell {} of body '{}' is inverted: {}",
            self.cell, self.body, self.inverted
        )
    }
}

/// Calls `visit(dofs, f_e, K_e)` (`K_e` row-major when `with_tangent`) for every cell of every
/// body at the displacement `u`; stops at the first inverted cell.
fn for_each_element<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    u: &[f64],
    with_tangent: bool,
    mut visit: impl FnMut(&[usize], &[f64], &[f64]),
) -> std::result::Result<(), InvertedElement<D>> {
    let largest = model
        .bodies
        .iter()
        .map(|b| D * b.mesh.kind.node_count())
        .max()
        .unwrap_or(0);
    let mut dofs = Vec::with_capacity(largest);
    let mut ue = vec![0.0; largest];
    let mut fe = vec![0.0; largest];
    let mut ke = vec![0.0; largest * largest];
    for body in &model.bodies {
        let law = body
            .hyperelastic
            .as_ref()
            .expect("the model gives every body a hyperelastic law under finite kinematics");
        let kind = body.mesh.kind;
        let rule = kind.stiffness_rule();
        for c in 0..body.mesh.cell_count() {
            body.cell_dofs(c, &mut dofs);
            let nd = dofs.len();
            for (v, &d) in ue.iter_mut().zip(&dofs) {
                *v = u[d];
            }
            kind.finite_residual_and_tangent(
                &body.mesh.cell_coords(c),
                &ue[..nd],
                law,
                model.thickness,
                &rule,
                with_tangent,
                &mut fe,
                &mut ke,
            )
            .map_err(|inverted| InvertedElement {
                body: body.name.clone(),
                cell: c,
                inverted,
            })?;
            visit(&dofs, &fe[..nd], &ke[..nd * nd]);
        }
    }
    Ok(())
}

/// The internal force `f_int(u)` of every body at the global displacement `u`.
pub fn internal_force<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    u: &[f64],
) -> std::result::Result<Vec<f64>, InvertedElement<D>> {
    let mut out = vec![0.0; u.len()];
    for_each_element(model, u, false, |dofs, f, _| {
        for (&d, v) in dofs.iter().zip(f) {
            out[d] += v;
        }
    })?;
    Ok(out)
}

/// The tangent `K_T(u)` on `pattern` (the free equations of `constraints`) and the residual
/// `f_int(u) - f_ext` at the free equations, `u` the global displacement (prescribed values
/// included).
pub(crate) fn tangent_and_residual<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    constraints: &AffineConstraints,
    pattern: &SymmetricPattern,
    u: &[f64],
) -> std::result::Result<(Vec<f64>, Vec<f64>), InvertedElement<D>> {
    let mut local = constraints.local();
    let mut k = vec![0.0; pattern.nnz()];
    // the constant part -K_fp u_p of the distribution is not part of the residual
    let mut unused = vec![0.0; constraints.free_count()];
    let mut f_int = vec![0.0; u.len()];
    for_each_element(model, u, true, |dofs, f, ke| {
        local.distribute(dofs, ke, pattern, &mut k, &mut unused);
        for (&d, v) in dofs.iter().zip(f) {
            f_int[d] += v;
        }
    })?;
    for (r, f) in f_int.iter_mut().zip(&model.external_force) {
        *r -= f;
    }
    Ok((k, constraints.restrict(&f_int)))
}
