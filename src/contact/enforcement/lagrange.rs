//! Lagrange multipliers: `g_i = 0` on the active set, one multiplier `lambda_i >= 0` per active
//! row, an indefinite saddle-point system `[K B^T; B 0]` (Taylor 2004, "1974-77: The
//! Foundations"). Dependent rows (two passes) make the multiplier system singular: a stability
//! failure even when the displacements are right.

use super::{Enforcement, Method};
use crate::io::scene::EnforcementSpec;

pub struct Lagrange;

impl Enforcement for Lagrange {
    fn name(&self) -> &'static str {
        "lagrange"
    }
    fn title(&self) -> &'static str {
        "Lagrange multipliers"
    }
    fn has_multiplier_system(&self) -> bool {
        true
    }
    fn scaled(&self, _factor: f64) -> EnforcementSpec {
        EnforcementSpec::Lagrange
    }
    fn unknowns_per_row(&self, _row: &crate::contact::Constraint) -> usize {
        1
    }
    fn kernel(&self) -> Method {
        Method::Lagrange
    }
}
