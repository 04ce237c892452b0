//! The largest stable time step of a conditionally stable Newmark member (central difference,
//! `beta = 0`, and any `2 beta < gamma`), checked before a dynamic run starts.
//!
//! Without damping, Newmark's method is stable for `omega dt <= Omega_crit` with
//! `Omega_crit = 1 / sqrt(gamma / 2 - beta)` (Hughes, *The Finite Element Method* (1987),
//! 9.1.2; `2` for central difference), `omega` the largest natural frequency of
//! `K_ff phi = omega^2 M_ff phi` over the free dofs `f`. The element eigenvalue inequality
//! (Irons 1970; Hughes & Tezduyar 1981; Belytschko, Liu & Moran, *Nonlinear Finite Elements*
//! (2000), 6.3.3) bounds it by the elements: `K_ff = sum_e K_e,ff` and the lumped
//! `M_ff = sum_e M_e,ff` restricted alike to each element's free dofs, so
//! `omega_max^2 <= max_e lambda_max(M_e,ff^-1/2 K_e,ff M_e,ff^-1/2)`. The bound is sharp for one
//! element and within the element's share of the mesh otherwise; `dt_crit = Omega_crit /
//! omega_bound` is then safe.
//!
//! Penalty contact rows add `C = sum_r w_r b_r b_r^T` (`w_r = kappa A_r`) to the stiffness, and
//! `lambda_max(M^-1/2 (K + C) M^-1/2) <= lambda_max(M^-1/2 K M^-1/2) + lambda_max(M^-1/2 C
//! M^-1/2)`, the second bounded by Gershgorin's row sums `max_i sum_r w_r |c_ri| sum_j |c_rj|`,
//! `c_r = M^-1/2 b_r` over the free dofs ([`penalty_frequency_bound`], the candidate rows of
//! the start of the run). [`crate::solver::dynamics`] refuses a `dt` above the limit.

use crate::model::Model;
use crate::solid::{element_mass, element_stiffness, lumped_mass};
use crate::solver::dense::symmetric_eigen;

/// The element that bounds the largest frequency, and the bound.
#[derive(Clone, Debug, PartialEq)]
pub struct FrequencyBound {
    /// Upper bound of the largest natural frequency `omega_max` (rad per unit time).
    pub omega: f64,
    pub body: usize,
    pub cell: usize,
}

/// The element bound of the largest natural frequency of `model` over its free dofs, with the
/// lumped (HRZ) mass of the densities `density` per body; `None` when no element has a free
/// dof.
pub fn largest_frequency_bound(model: &Model, density: &[f64]) -> Option<FrequencyBound> {
    let mut best: Option<FrequencyBound> = None;
    for (bi, (body, &rho)) in model.bodies.iter().zip(density).enumerate() {
        let kind = body.mesh.kind;
        let nn = kind.node_count();
        let nd = 2 * nn;
        let rule = kind.stiffness_rule();
        let mut ke = vec![0.0; nd * nd];
        let mut me = vec![0.0; nn * nn];
        for c in 0..body.mesh.cell_count() {
            let coords = body.mesh.cell_coords(c);
            element_stiffness(
                kind,
                &coords,
                &body.material,
                model.thickness,
                &rule,
                &mut ke,
            );
            element_mass(kind, &coords, rho, model.thickness, &mut me);
            let masses = lumped_mass(&me, nn);
            let nodes = body.mesh.cell(c);
            // the element's free dofs (local index) with their lumped masses
            let free: Vec<(usize, f64)> = (0..nd)
                .filter(|&a| model.prescribed[body.dof(nodes[a / 2], a % 2)].is_none())
                .map(|a| (a, masses[a / 2]))
                .collect();
            if free.is_empty() {
                continue;
            }
            let m = free.len();
            let mut scaled = vec![0.0; m * m];
            for (i, &(a, ma)) in free.iter().enumerate() {
                for (j, &(b, mb)) in free.iter().enumerate() {
                    scaled[i * m + j] = ke[a * nd + b] / (ma * mb).sqrt();
                }
            }
            let lambda = symmetric_eigen(&scaled, m)
                .0
                .into_iter()
                .fold(0.0f64, f64::max);
            let omega = lambda.max(0.0).sqrt();
            if best.as_ref().is_none_or(|b| omega > b.omega) {
                best = Some(FrequencyBound {
                    omega,
                    body: bi,
                    cell: c,
                });
            }
        }
    }
    best
}

/// The Gershgorin bound of `lambda_max(M^-1/2 C M^-1/2)` of penalty rows `(w, terms)` (terms:
/// free dof and coefficient of the row's gradient), with the lumped mass `mass(dof)`.
pub fn penalty_frequency_bound(
    rows: &[(f64, Vec<(usize, f64)>)],
    mass: impl Fn(usize) -> f64,
) -> f64 {
    let mut row_sums: std::collections::HashMap<usize, f64> = std::collections::HashMap::new();
    for (w, terms) in rows {
        let scaled: Vec<(usize, f64)> = terms
            .iter()
            .map(|&(d, c)| (d, (c / mass(d).sqrt()).abs()))
            .collect();
        let total: f64 = scaled.iter().map(|&(_, c)| c).sum();
        for &(d, c) in &scaled {
            *row_sums.entry(d).or_insert(0.0) += w * c * total;
        }
    }
    row_sums.into_values().fold(0.0, f64::max)
}

/// `Omega_crit` of Newmark's `(beta, gamma)` without damping: `None` when the member is
/// unconditionally stable (`2 beta >= gamma`).
pub fn critical_omega_dt(beta: f64, gamma: f64) -> Option<f64> {
    (2.0 * beta < gamma).then(|| 1.0 / (gamma / 2.0 - beta).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Central difference: `Omega_crit = 2`; Fox-Goodwin-like `beta = 1/12`: `sqrt(6)`; the
    /// trapezoidal rule has none.
    #[test]
    fn critical_values_of_newmark_members() {
        assert_eq!(critical_omega_dt(0.0, 0.5), Some(2.0));
        assert!((critical_omega_dt(1.0 / 12.0, 0.5).unwrap() - 6f64.sqrt()).abs() < 1e-14);
        assert_eq!(critical_omega_dt(0.25, 0.5), None);
    }

    /// One penalty row on one free dof of mass m: omega^2 = w / m exactly; a row coupling two
    /// dofs of masses m (gradient [1, -1]): the eigenvalue 2 w / m, which the bound meets.
    #[test]
    fn penalty_bound_is_exact_for_a_spring_to_ground_and_a_spring_between_masses() {
        let one = penalty_frequency_bound(&[(8.0, vec![(3, 1.0)])], |_| 2.0);
        assert!((one - 4.0).abs() < 1e-14);
        let two = penalty_frequency_bound(&[(8.0, vec![(0, 1.0), (1, -1.0)])], |_| 2.0);
        assert!((two - 8.0).abs() < 1e-14);
    }
}
