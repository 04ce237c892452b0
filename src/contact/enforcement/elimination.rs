//! Constraint elimination: each active row is solved for its own slave dof (the largest
//! coefficient among its slave dofs), `u_owner = -(g0 + sum_{k != owner} c_k u_k) / c_owner`,
//! substituted into the equilibrium equations; the multiplier follows from the residual at the
//! owned dof. It needs every row to own a free slave dof no other row touches.

use super::{Enforcement, Method};
use crate::contact::RowSite;
use crate::io::scene::EnforcementSpec;

pub struct Elimination;

impl Enforcement for Elimination {
    fn name(&self) -> &'static str {
        "elimination"
    }
    fn title(&self) -> &'static str {
        "constraint elimination"
    }
    fn has_multiplier_system(&self) -> bool {
        true
    }
    fn scaled(&self, _factor: f64) -> EnforcementSpec {
        EnforcementSpec::Elimination
    }
    fn kernel(&self) -> Method {
        Method::Elimination
    }
    fn obstacle(&self, rows: &[RowSite], prescribed: &[Option<f64>]) -> Option<String> {
        obstacle(rows, prescribed)
    }
}

/// Why constraint elimination cannot treat these rows, if it cannot: every constraint must own
/// a slave dof that is free and appears in no other constraint.
fn obstacle(rows: &[RowSite], prescribed: &[Option<f64>]) -> Option<String> {
    use std::collections::HashMap;
    let mut count: HashMap<usize, usize> = HashMap::new();
    for r in rows {
        for &d in r.dofs {
            *count.entry(d).or_default() += 1;
        }
    }
    for r in rows {
        if prescribed[r.owner].is_some() {
            return Some(format!(
                "the slave dof of the constraint at {} is prescribed",
                r.at()
            ));
        }
        if count[&r.owner] > 1 {
            return Some(format!(
                "the slave dof of the constraint at {} also appears in another constraint (two-pass rows, or standard mortar rows whose D is not diagonal), so no constraint owns it",
                r.at()
            ));
        }
    }
    None
}
