//! The contact rows of a model at a configuration: every pair's [`Constraint`]s from its
//! discretization ([`Discretize::pair_rows`]), evaluated in the reference configuration or at
//! the current positions `x = X + u` and linearized there (Wriggers 2006, *Computational
//! Contact Mechanics*, ch. 4: the gap `g(u) = g(u_k) + B_k (u - u_k)` about the configuration
//! `u_k`, so a row evaluated at `u` carries `g0 = g(u) - B u`).
//!
//! A row's area stays its reference area where the point has a reference row
//! ([`reference_areas`]): the penalty acts per unit reference area (a nominal pressure).
//!
//! Used by every solver scheme (the active-set loop and the Newton scheme); it depends on the
//! model and the discretization, and on no solver.

use super::discretization::Discretize;
use super::{row_key, Constraint, RowKey};
use crate::error::{Error, Result};
use crate::model::Model;
use std::collections::HashMap;

/// The tributary area of every row of the reference configuration, by point: computed once per
/// solve and handed to [`rows_at`] for the current configuration.
pub(crate) type ReferenceAreas = HashMap<RowKey, f64>;

/// The rows' areas in the reference configuration.
pub(crate) fn reference_areas<const D: usize, K: Discretize<D>>(
    model: &Model<D, K>,
) -> Result<ReferenceAreas> {
    Ok(rows_at(model, None)?
        .iter()
        .map(|r| (row_key(r), r.area))
        .collect())
}

/// The contact rows of every pair, evaluated at `X + u` for `current = Some((u, areas))`
/// (the reference configuration if `None`) and linearized there. A row's `area`, the weight of
/// a penalty (`kappa A`), stays its area in the reference configuration (`areas`, from
/// [`reference_areas`]) when the point has a row there: the penalty acts per unit
/// reference area (a nominal pressure), so the penalty force `kappa A_0 g(u)` has the exact
/// derivative `kappa A_0 dg/du` (the current area would add the variation of the tributary
/// lengths, which no tangent carries, and Newton would converge only linearly).
pub(crate) fn rows_at<const D: usize, K: Discretize<D>>(
    model: &Model<D, K>,
    current: Option<(&[f64], &ReferenceAreas)>,
) -> Result<Vec<Constraint<D>>> {
    let u = current.map(|(u, _)| u);
    let moved;
    let geometry = match u {
        None => model,
        Some(u) => {
            let mut m = model.clone();
            for b in &mut m.bodies {
                let offset = b.dof_offset;
                for (n, p) in b.mesh.nodes.iter_mut().enumerate() {
                    for (i, x) in p.iter_mut().enumerate() {
                        *x += u[offset + D * n + i];
                    }
                }
            }
            moved = m;
            &moved
        }
    };
    let mut rows = Vec::new();
    for (k, pair) in geometry.contact.iter().enumerate() {
        let r = K::pair_rows(geometry, pair).map_err(|reason| {
            Error::invalid(
                &model.source,
                format!("contact '{}'", pair.name),
                format!("the discretization does not apply: {reason}"),
                "choose another discretization for this pair",
            )
        })?;
        rows.extend(r.into_iter().map(|mut c| {
            c.pair = k;
            if let Some(u) = u {
                c.g0 -= c
                    .dofs
                    .iter()
                    .zip(&c.coeffs)
                    .map(|(&d, &w)| w * u[d])
                    .sum::<f64>();
                c.point = model.bodies[c.slave_body].mesh.nodes[c.slave_node];
            }
            c
        }));
    }
    if let Some((_, reference)) = current {
        for r in &mut rows {
            if let Some(&area) = reference.get(&row_key(r)) {
                r.area = area;
            }
        }
    }
    Ok(rows)
}
