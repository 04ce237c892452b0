//! Augmented Lagrangian: `lambda_i = lambda_k,i - kappa A_i g_i` with the Uzawa update
//! `lambda_k <- lambda` after every Newton iteration or in an outer loop around converged
//! penalty solves; the gap closes in the limit whatever kappa is (Taylor 2004, "1985: Solution
//! Methods": the augmented form "can reduce to all other forms").

use super::{Enforcement, Method};
use crate::io::scene::{EnforcementSpec, MultiplierUpdate};

pub struct AugmentedLagrange {
    pub kappa: f64,
    pub update: MultiplierUpdate,
}

impl Enforcement for AugmentedLagrange {
    fn name(&self) -> &'static str {
        match self.update {
            MultiplierUpdate::PerIteration => "augmented_lagrange",
            MultiplierUpdate::OuterLoop => "augmented_lagrange_outer",
        }
    }
    fn title(&self) -> &'static str {
        match self.update {
            MultiplierUpdate::PerIteration => {
                "the augmented Lagrangian (Uzawa update per iteration)"
            }
            MultiplierUpdate::OuterLoop => {
                "the augmented Lagrangian (Uzawa update in an outer loop)"
            }
        }
    }
    fn kappa(&self) -> Option<f64> {
        Some(self.kappa)
    }
    fn scaled(&self, factor: f64) -> EnforcementSpec {
        EnforcementSpec::AugmentedLagrange {
            kappa: self.kappa * factor,
            update: self.update,
        }
    }
    fn kernel(&self) -> Method {
        Method::AugmentedLagrange {
            kappa: self.kappa,
            update: self.update,
        }
    }
}
