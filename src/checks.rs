//! Checks declared by a case, judged against a solution.
//!
//! Each check measures one error and compares it with the case's own tolerance:
//! * `uniform_stress`: `max_qp max_i |sigma_i - s_i| / max_i |s_i|` over the stiffness
//!   quadrature points of the chosen bodies (absolute when `s = 0`);
//! * `exact_displacement`: relative L2 displacement error against the case's exact solution;
//! * `reaction`: sum of `K u - f` over a node set, one component;
//! * `displacement`: one component at the node nearest to a point.
//!
//! For the last two the error is `|got - value| / |value|`, or `|got|` when `value = 0`.

use crate::model::Model;
use crate::post::{for_each_quadrature_stress, relative_l2_displacement_error};
use crate::scene::Check;
use crate::solve::Solution;
use serde::Serialize;

/// The verdict of one check.
#[derive(Clone, Debug, Serialize)]
pub struct CheckResult {
    /// What was checked, in words.
    pub check: String,
    /// The measured error.
    pub error: f64,
    pub tol: f64,
    pub passed: bool,
}

fn relative(got: f64, value: f64) -> f64 {
    if value != 0.0 {
        (got - value).abs() / value.abs()
    } else {
        got.abs()
    }
}

/// Judge every check of the model (names were resolved when the model was built).
pub fn evaluate(model: &Model, solution: &Solution) -> Vec<CheckResult> {
    let u = &solution.u;
    model
        .checks
        .iter()
        .map(|check| {
            let (check_name, error, tol) = match check {
                Check::UniformStress { body, stress, tol } => {
                    let scale = stress.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                    let scale = if scale > 0.0 { scale } else { 1.0 };
                    let mut worst = 0.0f64;
                    for b in model.bodies.iter().filter(|b| body.as_ref().is_none_or(|n| *n == b.name)) {
                        for_each_quadrature_stress(b, u, |_, _, s| {
                            for i in 0..3 {
                                let e = (s[i] - stress[i]).abs() / scale;
                                // NaN must fail, so keep it rather than letting max() drop it
                                worst = if e.is_nan() || e > worst { e } else { worst };
                            }
                        });
                    }
                    let on = body.as_deref().map(|b| format!(" in body '{b}'")).unwrap_or_default();
                    (format!("uniform stress {stress:?}{on}"), worst, *tol)
                }
                Check::ExactDisplacement { tol } => {
                    let exact = model.exact.as_ref().expect("resolved when the model was built");
                    (
                        "relative L2 displacement error against the exact solution".to_string(),
                        relative_l2_displacement_error(model, u, exact),
                        *tol,
                    )
                }
                Check::Reaction { body, set, component, value, tol } => {
                    let b = model.body(body).expect("resolved when the model was built");
                    let comp = component.index();
                    let got: f64 = b.mesh.node_sets[set].iter().map(|&n| solution.reactions[b.dof(n, comp)]).sum();
                    (format!("reaction {component:?} on {body}.{set} = {got:.6e} (expected {value})"), relative(got, *value), *tol)
                }
                Check::Displacement { body, point, component, value, tol } => {
                    let b = model.body(body).expect("resolved when the model was built");
                    let (n, _) = b.mesh.nearest_node(*point).expect("a body has nodes");
                    let got = u[b.dof(n, component.index())];
                    (
                        format!("displacement {component:?} of {body} at ({}, {}) = {got:.6e} (expected {value})", point[0], point[1]),
                        relative(got, *value),
                        *tol,
                    )
                }
            };
            CheckResult { check: check_name, error, tol, passed: error <= tol }
        })
        .collect()
}
