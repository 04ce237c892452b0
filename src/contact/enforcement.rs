//! The enforcement axis: the six methods a user names, as parameters of one kernel.
//!
//! Every method solves, on the active set, linear systems with the matrix
//! `M = K + sum_i w_i b_i b_i^T` (`b_i` the gradient row of constraint `i`), factored by sparse
//! Cholesky with one symbolic analysis for the whole solve:
//!
//! | method | weights `w_i` | multipliers | residual |
//! |---|---|---|---|
//! | Lagrange | `rho` (augmentation only) | Schur complement `B M^-1 B^T`, pseudo-inverse | `g = 0` |
//! | perturbed Lagrangian | `kappa A_i` | `lambda = -kappa A g` | `g + lambda/(kappa A) = 0` |
//! | penalty | `kappa A_i` | eliminated | same solution as perturbed Lagrangian |
//! | perturbed tangent | `kappa A_i` | Newton update | `g = 0` with the perturbed tangent |
//! | augmented Lagrangian | `kappa A_i` | Uzawa `lambda_k <- lambda_k - kappa A g` | `g = 0` in the limit |
//! | elimination | none | from the residual at the owned dof | `g = 0` exactly |
//!
//! With node-based rows the perturbation matrix `C = diag(1/(kappa A_i))` is diagonal, so the
//! perturbed Lagrangian and the penalty method give identical numbers (Taylor 2004 notes they
//! differ in general, e.g. for mortar multipliers with a consistent `C`).

use super::Constraint;
use crate::scene::{EnforcementSpec, MultiplierUpdate};

/// What the solver does for one enforcement method.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Method {
    Lagrange,
    /// Penalty-regularized methods: perturbed Lagrangian and penalty.
    Regularized {
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

impl Method {
    pub fn from_spec(spec: &EnforcementSpec) -> Method {
        match *spec {
            EnforcementSpec::Lagrange => Method::Lagrange,
            EnforcementSpec::PerturbedLagrange { kappa } | EnforcementSpec::Penalty { kappa } => {
                Method::Regularized { kappa }
            }
            EnforcementSpec::PerturbedTangent { kappa } => Method::PerturbedTangent { kappa },
            EnforcementSpec::AugmentedLagrange { kappa, update } => {
                Method::AugmentedLagrange { kappa, update }
            }
            EnforcementSpec::Elimination => Method::Elimination,
        }
    }

    /// Whether the converged gap is only approximately zero (it depends on kappa).
    pub fn is_penalty_type(&self) -> bool {
        matches!(self, Method::Regularized { .. })
    }
}

/// The short name of an enforcement, as tables show it.
pub fn name(spec: &EnforcementSpec) -> &'static str {
    match spec {
        EnforcementSpec::Lagrange => "lagrange",
        EnforcementSpec::PerturbedLagrange { .. } => "perturbed_lagrange",
        EnforcementSpec::Penalty { .. } => "penalty",
        EnforcementSpec::PerturbedTangent { .. } => "perturbed_tangent",
        EnforcementSpec::AugmentedLagrange {
            update: MultiplierUpdate::PerIteration,
            ..
        } => "augmented_lagrange",
        EnforcementSpec::AugmentedLagrange {
            update: MultiplierUpdate::OuterLoop,
            ..
        } => "augmented_lagrange_outer",
        EnforcementSpec::Elimination => "elimination",
    }
}

/// The penalty parameter of an enforcement, if it has one.
pub fn kappa(spec: &EnforcementSpec) -> Option<f64> {
    match *spec {
        EnforcementSpec::PerturbedLagrange { kappa }
        | EnforcementSpec::Penalty { kappa }
        | EnforcementSpec::PerturbedTangent { kappa }
        | EnforcementSpec::AugmentedLagrange { kappa, .. } => Some(kappa),
        EnforcementSpec::Lagrange | EnforcementSpec::Elimination => None,
    }
}

/// The same enforcement with its penalty multiplied by `factor`.
pub fn scaled(spec: &EnforcementSpec, factor: f64) -> EnforcementSpec {
    let mut s = spec.clone();
    match &mut s {
        EnforcementSpec::PerturbedLagrange { kappa }
        | EnforcementSpec::Penalty { kappa }
        | EnforcementSpec::PerturbedTangent { kappa }
        | EnforcementSpec::AugmentedLagrange { kappa, .. } => *kappa *= factor,
        EnforcementSpec::Lagrange | EnforcementSpec::Elimination => {}
    }
    s
}

/// Why constraint elimination cannot treat these rows, if it cannot: every constraint must own
/// a slave dof that is free and appears in no other constraint.
pub fn elimination_obstacle(rows: &[Constraint], prescribed: &[Option<f64>]) -> Option<String> {
    use std::collections::HashMap;
    let mut count: HashMap<usize, usize> = HashMap::new();
    for r in rows {
        for &d in &r.dofs {
            *count.entry(d).or_default() += 1;
        }
    }
    for r in rows {
        if prescribed[r.owner].is_some() {
            return Some(format!(
                "the slave dof of the constraint at ({}, {}) is prescribed",
                r.point[0], r.point[1]
            ));
        }
        if count[&r.owner] > 1 {
            return Some(format!(
                "the slave dof of the constraint at ({}, {}) also appears in another constraint (two-pass rows, or standard mortar rows whose D is not diagonal), so no constraint owns it",
                r.point[0], r.point[1]
            ));
        }
    }
    None
}
