//! Checks declared by a case, judged against a solution.
//!
//! Each check measures one error and compares it with the case's own tolerance:
//! * `uniform_stress`: `max_qp max_i |sigma_i - s_i| / max_i |s_i|` over the stiffness
//!   quadrature points of the chosen bodies (absolute when `s = 0`);
//! * `exact_displacement`: relative L2 displacement error against the case's exact solution;
//! * `reaction`: sum of `K u - f` over a node set, one component;
//! * `displacement`: one component at the node nearest to a point;
//! * `contact_pressure`, `force_balance`, `contact_force`, `max_contact_pressure`: contact
//!   forces (see the functions below).
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

/// Max over the rows of `pair` (all pairs if `None`) of `|lambda_i / A_i - p_i| / scale`,
/// with `p_i = nu . sigma_exact . n_s` the exact traction along the row's direction (for
/// contact, `nu = -n_s` and `p_i` is the contact pressure) and `scale`
/// the given one or, if `None`, `max |sigma_exact|` at the node. Infinite when the solve
/// produced no contact state.
pub fn pressure_error(
    solution: &Solution,
    exact: &crate::exact::ExactField,
    pair: Option<usize>,
    scale: Option<f64>,
) -> f64 {
    let Some(state) = &solution.contact else {
        return f64::INFINITY;
    };
    let mut worst = 0.0f64;
    for (i, r) in state.rows.iter().enumerate() {
        if pair.is_some_and(|k| k != r.pair) {
            continue;
        }
        let s = exact.stress(r.point);
        let scale = scale
            .unwrap_or_else(|| s.iter().fold(0.0f64, |m, v| m.max(v.abs())))
            .max(f64::MIN_POSITIVE);
        // the exact force per area along the row's direction nu on the slave surface (outward
        // normal n_s): nu . sigma . n_s (= -n.sigma.n = p for contact, where nu = -n_s)
        // (for a row whose force direction `normal` is not a unit vector, the multiplier that
        // reproduces the traction is normal . sigma . n_s / |normal|^2)
        let (nu, ns) = (r.normal, r.slave_normal);
        let p = (nu[0] * (s[0] * ns[0] + s[2] * ns[1]) + nu[1] * (s[2] * ns[0] + s[1] * ns[1]))
            / (nu[0] * nu[0] + nu[1] * nu[1]);
        let e = (state.forces[i] / r.area - p).abs() / scale;
        worst = if e.is_nan() || e > worst { e } else { worst };
    }
    worst
}

/// Largest of: the net contact force and moment between deformable bodies (relative to the sum
/// of |contact forces|, moments divided by the model size; rows against rigid surfaces are left
/// out, the rigid surface takes their force) and the relative equilibrium residual of the solve.
pub fn force_balance(model: &Model, solution: &Solution) -> f64 {
    let Some(state) = &solution.contact else {
        return f64::INFINITY;
    };
    let (mut fx, mut fy, mut moment, mut total) = (0.0, 0.0, 0.0, 0.0f64);
    let between_bodies = |r: &&crate::contact::Constraint| {
        matches!(
            model.contact[r.pair].master,
            crate::model::MasterSide::Body { .. }
        )
    };
    for (r, &lambda) in state
        .rows
        .iter()
        .zip(&state.forces)
        .filter(|(r, _)| between_bodies(r))
    {
        total += lambda.abs();
        for (&d, &c) in r.dofs.iter().zip(&r.coeffs) {
            let body = model
                .bodies
                .iter()
                .find(|b| d >= b.dof_offset && d < b.dof_offset + b.dof_count())
                .expect("a body owns every dof");
            let local = d - body.dof_offset;
            let p = body.mesh.nodes[local / 2];
            let f = c * lambda;
            if local % 2 == 0 {
                fx += f;
                moment -= p[1] * f;
            } else {
                fy += f;
                moment += p[0] * f;
            }
        }
    }
    let size = model.size();
    let net = if total > 0.0 {
        fx.abs().max(fy.abs()).max(moment.abs() / size) / total
    } else {
        0.0
    };
    net.max(solution.relative_residual)
}

/// Judge every check of the model (names were resolved when the model was built). A contact
/// solve that did not converge adds a failing check of its own, so that no declared check can
/// pass on an unconverged solution.
pub fn evaluate(model: &Model, solution: &Solution) -> Vec<CheckResult> {
    let u = &solution.u;
    let convergence = solution
        .contact
        .as_ref()
        .and_then(|c| match &c.termination {
            crate::contact::solver::Termination::Converged => None,
            t => Some(CheckResult {
                check: format!("the contact solve converged (it ended: {t:?})"),
                error: f64::INFINITY,
                tol: 0.0,
                passed: false,
            }),
        });
    let declared: Vec<CheckResult> = model
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
                Check::ContactPressure { pair, tol } => {
                    let exact = model.exact.as_ref().expect("resolved when the model was built");
                    let k = model.contact.iter().position(|p| p.name == *pair).expect("resolved when the model was built");
                    (format!("contact pressure of '{pair}' against the exact stress"), pressure_error(solution, exact, Some(k), None), *tol)
                }
                Check::ContactForce { pair, component, value, tol } => {
                    let k = model.contact.iter().position(|p| p.name == *pair).expect("resolved when the model was built");
                    let got: f64 = solution
                        .contact
                        .as_ref()
                        .map(|c| c.rows.iter().zip(&c.forces).filter(|(r, _)| r.pair == k).map(|(r, f)| f * r.normal[component.index()]).sum())
                        .unwrap_or(f64::NAN);
                    (format!("total contact force {component:?} of '{pair}' = {got:.6e} (expected {value})"), relative(got, *value), *tol)
                }
                Check::MaxContactPressure { pair, value, tol } => {
                    let k = model.contact.iter().position(|p| p.name == *pair).expect("resolved when the model was built");
                    let got = solution
                        .contact
                        .as_ref()
                        .map(|c| c.rows.iter().zip(&c.forces).filter(|(r, _)| r.pair == k).fold(0.0f64, |m, (r, f)| m.max(f / r.area)))
                        .unwrap_or(f64::NAN);
                    (format!("max contact pressure of '{pair}' = {got:.6e} (expected {value})"), relative(got, *value), *tol)
                }
                Check::ForceBalance { tol } => ("force balance of the contact forces and equilibrium".to_string(), force_balance(model, solution), *tol),
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
        .collect();
    convergence.into_iter().chain(declared).collect()
}
