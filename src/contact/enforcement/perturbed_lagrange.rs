//! Perturbed Lagrangian: `g_i + lambda_i / (kappa A_i) = 0`, a multiplier per row regularized by
//! the perturbation `C = diag(1 / (kappa A_i))`. With a diagonal `C` the multipliers can be
//! eliminated and the numbers are the penalty method's; Taylor 2004 notes the two are "not always
//! same" (a consistent, non-diagonal `C` for standard mortar multipliers differs). With the
//! diagonal `C` the multipliers are eliminated: no unknowns of their own.

use super::{Enforcement, Method};
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
    fn kernel(&self) -> Method {
        Method::Regularized { kappa: self.kappa }
    }
}
