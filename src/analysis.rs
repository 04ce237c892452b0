//! One static analysis of a model, with only the effects its scene names: elasticity alone
//! ([`crate::solve`]), or with the contact pairs it declares ([`crate::contact::solver`]: load
//! steps, active sets, geometry updates). A scene without contact builds no contact row.

use crate::error::Result;
use crate::model::Model;
use crate::solve::Solution;

/// Solve `model`; `progress` is told the name of each stage as it starts.
pub fn solve_static(model: &Model, progress: &mut dyn FnMut(&str)) -> Result<Solution> {
    if model.contact.is_empty() {
        crate::solve::solve_elastic(model, progress)
    } else {
        crate::contact::solver::solve(model, progress)
    }
}
