//! The enforcement axis: the six methods a user names, as parameters of one kernel.
//!
//! Every method solves, on the active set, linear systems with the matrix
//! `M = K + sum_i w_i b_i b_i^T` (`b_i` the gradient row of constraint `i`), factored by sparse
//! Cholesky with one symbolic analysis for the whole solve:
//!
//! | method | weights `w_i` | multipliers | residual |
//! |---|---|---|---|
//! | Lagrange | `rho` (augmentation only) | Schur complement `B M^-1 B^T`, pseudo-inverse | `g = 0` |
//! | perturbed Lagrangian | `kappa A_i` (lumped mass) | `lambda = -kappa A g` | `g + C lambda = 0` |
//! | penalty | `kappa A_i` | eliminated | same solution as perturbed Lagrangian |
//! | perturbed tangent | `kappa A_i` | Newton update | `g = 0` with the perturbed tangent |
//! | augmented Lagrangian | `kappa A_i` | Uzawa `lambda_k <- lambda_k - kappa A g` | `g = 0` in the limit |
//! | elimination | none | from the residual at the owned dof | `g = 0` exactly |
//!
//! The perturbed Lagrangian's perturbation is `C = A^-1 M A^-1 / kappa` with the rows'
//! multiplier mass `M` ([`Constraint::mass`]). With node-based rows and dual mortar `M` is the
//! lumped `diag(A)`, `C = diag(1/(kappa A_i))`, and the perturbed Lagrangian and the penalty
//! method give identical numbers; with standard mortar multipliers `M` is the consistent,
//! non-diagonal mass, the multipliers are unknowns of a saddle-point system (the weights of
//! the rows are then not `kappa A_i`), and the two differ wherever the contact pressure is not
//! uniform (Taylor 2004: "not always same"); see `perturbed_lagrange`.

use super::{Constraint, RowSite};
use crate::io::scene::{EnforcementSpec, MultiplierUpdate};

mod augmented_lagrange;
mod elimination;
mod lagrange;
mod penalty;
mod perturbed_lagrange;
mod perturbed_tangent;

/// The questions the harness, the reports and the solver ask of an enforcement method. Each
/// method answers them in its own module; nothing else classifies methods.
pub trait Enforcement {
    /// The short name tables show.
    fn name(&self) -> &'static str;
    /// The method's name in prose (messages, reports).
    fn title(&self) -> &'static str;
    /// Whether the method solves a multiplier system (Lagrange multipliers, constraint
    /// elimination), whose singularity is a stability failure. (The perturbed Lagrangian's
    /// multipliers on standard mortar rows solve a system regularized by `C`, which dependent
    /// rows cannot make singular: it answers no.)
    fn has_multiplier_system(&self) -> bool {
        false
    }
    /// Whether the converged gap is only approximately zero and depends on the penalty (judged
    /// by the trend of the error as kappa grows).
    fn penalty_like(&self) -> bool {
        false
    }
    /// The penalty parameter, if the method has one.
    fn kappa(&self) -> Option<f64> {
        None
    }
    /// The same method with its penalty multiplied by `factor` (unchanged without one).
    fn scaled(&self, factor: f64) -> EnforcementSpec;
    /// Unknowns the method adds to the linear system for the active row `row` (multipliers).
    fn unknowns_per_row(&self, _row: &Constraint) -> usize {
        0
    }
    /// Whether the method regularizes with the multiplier mass the rows carry
    /// ([`Constraint::mass`]; the perturbed Lagrangian), so that it differs from the penalty
    /// method where the discretization's mass is not lumped.
    fn uses_multiplier_mass(&self) -> bool {
        false
    }
    /// What the solver runs.
    fn kernel(&self) -> Method;
    /// Why the method cannot treat `rows`, if it cannot.
    fn obstacle(&self, _rows: &[RowSite], _prescribed: &[Option<f64>]) -> Option<String> {
        None
    }
}

/// The enforcement method of `spec`.
pub fn method(spec: &EnforcementSpec) -> Box<dyn Enforcement> {
    match *spec {
        EnforcementSpec::Lagrange => Box::new(lagrange::Lagrange),
        EnforcementSpec::PerturbedLagrange { kappa } => {
            Box::new(perturbed_lagrange::PerturbedLagrange { kappa })
        }
        EnforcementSpec::Penalty { kappa } => Box::new(penalty::Penalty { kappa }),
        EnforcementSpec::PerturbedTangent { kappa } => {
            Box::new(perturbed_tangent::PerturbedTangent { kappa })
        }
        EnforcementSpec::AugmentedLagrange { kappa, update } => {
            Box::new(augmented_lagrange::AugmentedLagrange { kappa, update })
        }
        EnforcementSpec::Elimination => Box::new(elimination::Elimination),
    }
}

/// Which enforcement methods one contact solve can combine, a method per pair: the loop is
/// driven by one family. Penalty, perturbed Lagrangian and augmented Lagrangian rows (any
/// kappa, either Uzawa update) share the penalty-regularized loop (whose linear solve becomes
/// a saddle-point system when perturbed Lagrangian rows carry a consistent multiplier mass,
/// the other rows entering it with their penalty weights); Lagrange multipliers,
/// the perturbed tangent and constraint elimination each need their own.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Family {
    LagrangeMultipliers,
    PenaltyRegularized,
    PerturbedTangent,
    Elimination,
}

impl Method {
    /// The penalty parameter the kernel uses, if any.
    pub fn kappa(self) -> Option<f64> {
        match self {
            Method::Regularized { kappa }
            | Method::PerturbedLagrange { kappa }
            | Method::PerturbedTangent { kappa }
            | Method::AugmentedLagrange { kappa, .. } => Some(kappa),
            Method::Lagrange | Method::Elimination => None,
        }
    }

    /// The family of methods it can be combined with in one solve.
    pub fn family(self) -> Family {
        match self {
            Method::Lagrange => Family::LagrangeMultipliers,
            Method::Regularized { .. }
            | Method::PerturbedLagrange { .. }
            | Method::AugmentedLagrange { .. } => Family::PenaltyRegularized,
            Method::PerturbedTangent { .. } => Family::PerturbedTangent,
            Method::Elimination => Family::Elimination,
        }
    }
}

impl Family {
    pub fn describe(self) -> &'static str {
        match self {
            Family::LagrangeMultipliers => "Lagrange multipliers",
            Family::PenaltyRegularized => {
                "penalty, perturbed Lagrangian and augmented Lagrangian (any mix)"
            }
            Family::PerturbedTangent => "the perturbed tangent",
            Family::Elimination => "constraint elimination",
        }
    }
}

/// What the solver does for one enforcement method.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Method {
    Lagrange,
    /// Penalty: `lambda_i = -kappa A_i g_i` eliminated up front.
    Regularized {
        kappa: f64,
    },
    /// Perturbed Lagrangian: `g + C lambda = 0` with `C = A^-1 M A^-1 / kappa` from the rows'
    /// multiplier mass; rows with a lumped mass are eliminated as penalty rows, rows with a
    /// consistent one keep their multipliers (a saddle-point system).
    PerturbedLagrange {
        kappa: f64,
    },
    PerturbedTangent {
        kappa: f64,
    },
    AugmentedLagrange {
        kappa: f64,
        update: MultiplierUpdate,
    },
    Elimination,
}
