//! Frictionless small-strain contact: two orthogonal axes that meet in one small type.
//!
//! **The meeting point.** Every discretization turns a contact pair into a list of
//! [`Constraint`]s: a gap that is affine in the displacements,
//!
//! ```text
//! g_i(u) = g0_i + sum_k c_ik u_{d_ik}        (g >= 0 open, g < 0 penetration)
//! ```
//!
//! with its tributary area `A_i` (the slave node's share of the slave surface times the
//! thickness), its normal, and the slave dof an elimination may solve for. With small-strain
//! kinematics the geometry (closest points, normals, weights) is taken once, in the reference
//! configuration; the rows are then fixed for the whole solve, so the sparsity pattern and the
//! symbolic factorization are computed once from all candidate rows.
//!
//! **The discretization axis** ([`discretization`]): node-to-node, node-to-surface one-pass and
//! two-pass (master or slave normals, the corner condition), rigid analytic masters.
//!
//! **The enforcement axis** ([`enforcement`], [`crate::solver::active_set`]): with the contact force `lambda_i`
//! (compression positive) equilibrium reads `K u = f + B^T lambda`, `B_ik = dg_i/du_k`, and
//!
//! * Lagrange multiplier: `g_i = 0` on the active set (an indefinite saddle-point system),
//! * perturbed Lagrangian: `g_i + lambda_i / (kappa A_i) = 0`,
//! * penalty: `lambda_i = -kappa A_i g_i` eliminated up front,
//! * perturbed tangent: the Lagrange residual with the perturbed Lagrangian tangent,
//! * augmented Lagrangian: `lambda_i = lambda_k,i - kappa A_i g_i` with the Uzawa update
//!   `lambda_k <- lambda` per Newton iteration or in an outer loop,
//! * constraint elimination: each active row solved for its own slave dof.
//!
//! All six are written once against [`Constraint`] (Taylor 2004, "1985: Solution Methods":
//! the augmented perturbed form "can reduce to all other forms").

pub mod discretization;
pub mod enforcement;
pub mod forces;
pub mod state;

/// One linearized contact constraint (a row of `B`).
#[derive(Clone, Debug, PartialEq)]
pub struct Constraint {
    /// Global dofs of the gradient row.
    pub dofs: Vec<usize>,
    /// `dg/du` for each of `dofs`.
    pub coeffs: Vec<f64>,
    /// Gap at `u = 0`.
    pub g0: f64,
    /// Tributary area of the slave node (length x thickness); 1 for lumped node-to-node pairs
    /// on a surface without facets.
    pub area: f64,
    /// The gradient of the gap with respect to the slave node's displacement (points from
    /// master to slave): the unit normal for master normals, rigid surfaces and mortar,
    /// `n_m / (n_m . nu)` for slave normals, `e_x` or `e_y` for tied rows. The row's force on
    /// the slave node is `lambda * normal`.
    pub normal: [f64; 2],
    /// Outward unit normal of the slave surface at the slave node (zero for rigid slaves).
    pub slave_normal: [f64; 2],
    /// Body and local node of the slave node, and its reference position.
    pub slave_body: usize,
    pub slave_node: usize,
    pub point: [f64; 2],
    /// 1 for the first pass, 2 for the second pass of a two-pass discretization.
    pub pass: u8,
    /// The slave dof this constraint may be solved for (largest |c| among the slave dofs).
    pub owner: usize,
    /// Index of the contact pair in the model.
    pub pair: usize,
    /// A tie: always active, its force may have either sign.
    pub bilateral: bool,
    /// The row's line of the multiplier mass `M_jk = int Phi_j Phi_k dGamma` (length x
    /// thickness) over the slave nodes `k` of the same pair, pass and direction (`j` is this
    /// row's slave node, listed too), when the discretization's multipliers are not lumped;
    /// empty when the mass is the lumped `diag(area)` (node-based rows, dual mortar). Its
    /// entries sum to `area`. Only the perturbed Lagrangian uses it (see
    /// [`enforcement`]): `C = A^-1 M A^-1 / kappa`.
    pub mass: Vec<(usize, f64)>,
}

impl Constraint {
    /// Gap for the displacement `u`.
    pub fn gap(&self, u: &[f64]) -> f64 {
        self.g0
            + self
                .dofs
                .iter()
                .zip(&self.coeffs)
                .map(|(&d, c)| c * u[d])
                .sum::<f64>()
    }
}
