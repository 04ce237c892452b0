//! Perturbed Lagrangian (Taylor 2004, "1985: Solution Methods"): the interface term
//! `int lambda_h g_h dGamma + (1 / (2 kappa)) int lambda_h^2 dGamma` with its own multipliers.
//! Stationarity in the multiplier field, tested with the multiplier functions `Phi_j`, reads
//!
//! ```text
//! int Phi_j (g_h + p_h / kappa) dGamma = 0,    p_h = sum_k Phi_k p_k   (compression positive)
//! ```
//!
//! With the row conventions of [`crate::contact::Constraint`] (a row's gap `g_j` is the
//! weighted gap `int Phi_j g_h / A_j`, its force `lambda_j = A_j p_j` is the nodal force,
//! `A_j = int Phi_j`) this is, divided by `A_j`,
//!
//! ```text
//! g_j + sum_k C_jk lambda_k = 0,   C = A^-1 M A^-1 / kappa,   M_jk = int Phi_j Phi_k dGamma
//! ```
//!
//! on the active rows, with `lambda >= 0`, `g + C lambda >= 0` and their product zero (the
//! KKT conditions of the maximum over `lambda >= 0`). `M` is the rows' multiplier mass
//! ([`crate::contact::Constraint::mass`]), given by the discretization:
//!
//! * **Lumped** (node-to-node, node-to-surface, rigid masters, dual mortar, whose
//!   biorthogonality makes the pairing `int Phi_j N_k = delta_jk A_j`): `M = diag(A)`,
//!   `C = diag(1 / (kappa A_j))`, so `lambda_j = -kappa A_j g_j`: the multipliers are eliminated
//!   and the numbers are exactly the penalty method's.
//! * **Consistent** (standard mortar, `Phi = N`): `M_jk = D_jk`, banded (each node with the
//!   nodes of its facets); the multipliers stay unknowns of the saddle-point system
//!   `[[K, -B^T], [-B, -C]] [u; lambda] = [f; g0]` over the active rows (solved in
//!   [`crate::solver::active_set`] with an augmentation that keeps it symmetric and its pivots
//!   of known sign). This is the case where Taylor's slide says the penalty form is "not always
//!   same as perturbed lagrangian form": the two agree when the contact pressure is uniform
//!   (then `(C lambda)_j = p / kappa` for every row, as penalty's `lambda_j / (kappa A_j)`), and
//!   differ when it is not; as kappa grows both tend to the Lagrange-multiplier solution, the
//!   perturbed Lagrangian like `1/kappa`.
//!
//! This unit is the one place that decides to use the mass: its kernel is
//! [`Method::PerturbedLagrange`], and the solver keeps multipliers exactly for the rows that
//! carry a consistent mass. The penalty method, with the same kappa, ignores the mass.

use super::{Enforcement, Method};
use crate::contact::Constraint;
use crate::io::scene::EnforcementSpec;

pub struct PerturbedLagrange {
    pub kappa: f64,
}

impl Enforcement for PerturbedLagrange {
    fn name(&self) -> &'static str {
        "perturbed_lagrange"
    }
    fn title(&self) -> &'static str {
        "the perturbed Lagrangian"
    }
    fn penalty_like(&self) -> bool {
        true
    }
    fn kappa(&self) -> Option<f64> {
        Some(self.kappa)
    }
    fn scaled(&self, factor: f64) -> EnforcementSpec {
        EnforcementSpec::PerturbedLagrange {
            kappa: self.kappa * factor,
        }
    }
    fn uses_multiplier_mass(&self) -> bool {
        true
    }
    fn unknowns_per_row(&self, row: &Constraint) -> usize {
        usize::from(!row.mass.is_empty())
    }
    fn kernel(&self) -> Method {
        Method::PerturbedLagrange { kappa: self.kappa }
    }
}
