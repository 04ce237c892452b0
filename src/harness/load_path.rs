//! Following a finite-kinematics solve along its load steps, for the studies of issue 12
//! ([`super::hertz_finite`], [`super::finite_sliding`]): the case built from JSON, the state of
//! every accepted load step handed to an observer ([`crate::solver::finite::solve_observed`]),
//! and the measure of Newton's asymptotic rate used in their reports.
//!
//! **Quadratic rate.** Newton's method with the consistent tangent converges quadratically near
//! the solution: `r_{k+1} <= C r_k^2` (Simo & Wriggers 1985 for the contact terms). The ratio
//! `r_{k+1} / r_k^2` is taken over the consecutive residuals of one load step with
//! `r_k < 1e-3` and both above the round-off floor (the solver's tolerance): bounded for a
//! quadratic rate, growing like `c / r_k` for a linear rate `c`.

use crate::error::Result;
use crate::model::{parse, Model};
use crate::solver::linear::Solution;
use serde_json::Value;

/// The model of the case `case` (a JSON scene), `name` naming it in messages.
pub fn build(case: &Value, name: &str) -> Result<Model> {
    let parsed = parse(&case.to_string(), name)?;
    Model::build(&parsed, name)
}

/// Solve `model` (finite kinematics) and return `observe(load_factor, state)` of every
/// accepted load step, in order (a step cut in parts gives one value per accepted part).
pub fn follow<T>(model: &Model, mut observe: impl FnMut(f64, &Solution) -> T) -> Result<Vec<T>> {
    let mut seen = Vec::new();
    crate::solver::finite::solve_observed(model, &mut |_| {}, &mut |factor, solution| {
        seen.push(observe(factor, solution))
    })?;
    Ok(seen)
}

/// The largest `r_{k+1} / r_k^2` over consecutive residuals of one step with
/// `floor < r_k < 1e-3` and `r_{k+1} > floor`, and how many pairs were judged.
pub fn quadratic_ratio(residuals: &[f64], floor: f64) -> (usize, f64) {
    let mut judged = 0;
    let mut largest = 0.0f64;
    for w in residuals.windows(2) {
        if w[0] < 1e-3 && w[0] > floor && w[1] > floor {
            judged += 1;
            largest = largest.max(w[1] / (w[0] * w[0]));
        }
    }
    (judged, largest)
}

#[cfg(test)]
mod tests {
    use super::quadratic_ratio;

    #[test]
    fn a_quadratic_sequence_has_a_bounded_ratio_and_a_linear_one_does_not() {
        // r_{k+1} = 3 r_k^2 from 1e-2: ratios 3 wherever r_k < 1e-3 and above the floor
        let quadratic = [1e-2, 3e-4, 2.7e-7, 2.187e-13];
        let (judged, largest) = quadratic_ratio(&quadratic, 1e-14);
        assert_eq!(judged, 2);
        assert!((largest - 3.0).abs() < 1e-9, "{largest}");
        // r_{k+1} = 0.5 r_k: the ratio is 0.5 / r_k, 5e3 at r_k = 1e-4
        let linear = [1e-3 * 0.9, 4.5e-4, 2.25e-4, 1.125e-4];
        let (judged, largest) = quadratic_ratio(&linear, 1e-14);
        assert_eq!(judged, 3);
        assert!((largest - 0.5 / 2.25e-4).abs() < 1e-6, "{largest}");
        // residuals at the floor say nothing of the rate
        assert_eq!(quadratic_ratio(&[1e-4, 1e-15], 1e-12), (0, 0.0));
    }
}
