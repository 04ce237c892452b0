//! Perturbed tangent: Newton on the Lagrange residual (`g_i = 0` in the limit) with the
//! perturbed Lagrangian's tangent `K + kappa A_i b_i b_i^T`, the multipliers updated from the
//! residual each iteration (Taylor 2004, "1985: Solution Methods").

use super::{Enforcement, Method};
use crate::io::scene::EnforcementSpec;

pub struct PerturbedTangent {
    pub kappa: f64,
}

impl Enforcement for PerturbedTangent {
    fn name(&self) -> &'static str {
        "perturbed_tangent"
    }
    fn title(&self) -> &'static str {
        "the perturbed tangent"
    }
    fn kappa(&self) -> Option<f64> {
        Some(self.kappa)
    }
    fn scaled(&self, factor: f64) -> EnforcementSpec {
        EnforcementSpec::PerturbedTangent {
            kappa: self.kappa * factor,
        }
    }
    fn kernel(&self) -> Method {
        Method::PerturbedTangent { kappa: self.kappa }
    }
}
