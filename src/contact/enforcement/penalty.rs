//! Penalty: the contact force `lambda_i = -kappa A_i g_i` of every active row is eliminated up
//! front, adding `kappa A_i b_i b_i^T` to the stiffness; the gap closes only as kappa grows
//! (Taylor 2004, "1985: Solution Methods").

use super::{Enforcement, Method};
use crate::io::scene::EnforcementSpec;

pub struct Penalty {
    pub kappa: f64,
}

impl Enforcement for Penalty {
    fn name(&self) -> &'static str {
        "penalty"
    }
    fn title(&self) -> &'static str {
        "the penalty method"
    }
    fn penalty_like(&self) -> bool {
        true
    }
    fn kappa(&self) -> Option<f64> {
        Some(self.kappa)
    }
    fn scaled(&self, factor: f64) -> EnforcementSpec {
        EnforcementSpec::Penalty {
            kappa: self.kappa * factor,
        }
    }
    fn kernel(&self) -> Method {
        Method::Regularized { kappa: self.kappa }
    }
}
