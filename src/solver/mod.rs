//! One static analysis of a model, with only the effects its scene names: elasticity alone
//! ([`crate::solver::linear`]), or with the contact pairs it declares ([`crate::solver::active_set`]: load
//! steps, active sets, geometry updates). A scene without contact builds no contact row. A
//! scene with `physics.dynamics` is time-stepped instead ([`crate::solver::dynamics`]); a static
//! scene builds no mass matrix. A scene with `physics.kinematics: "finite"` is solved by
//! [`crate::solver::finite`] (Newton in load steps with cuts), with or without contact.

pub mod active_set;
pub mod amg;
pub mod conditioning;
pub mod constraints;
pub mod contact_newton;
pub(crate) mod dense;
pub mod dynamics;
pub mod elastic3d;
pub mod finite;
pub mod finite_assembly;
pub mod history;
pub mod iterative;
pub mod linear;
pub mod low_rank;
pub mod newton;
pub mod ordering;
pub mod sparse;

use crate::error::Result;
use crate::model::Model;
use crate::solver::linear::Solution;

/// Solve `model`; `progress` is told the name of each stage as it starts.
pub fn solve_static(model: &Model, progress: &mut dyn FnMut(&str)) -> Result<Solution> {
    if model.dynamics.is_some() {
        crate::solver::iterative::refuse_unless_admitted(model)?;
        return crate::solver::dynamics::solve(model, progress);
    }
    solve_quasi_static(model, progress)
}

/// Solve the static (load-stepped) `model` of any dimension: finite strain by Newton in load
/// steps with cuts, elasticity alone at the last load step (a linear answer depends on the
/// final load only, so the load path's last factors apply), contact in load steps. Every branch
/// applies the load path through [`Model::at_load`], so `path` is the load history in every
/// run (one step or many, with or without contact).
pub fn solve_quasi_static<
    const D: usize,
    K: crate::solver::contact_newton::NewtonDimension<D> + crate::solver::active_set::ContactStep<D>,
>(
    model: &crate::model::Model<D, K>,
    progress: &mut dyn FnMut(&str),
) -> Result<crate::solver::linear::Solution<D>> {
    crate::solver::iterative::refuse_unless_admitted(model)?;
    if model.physics.kinematics == crate::io::scene::Kinematics::Finite {
        crate::solver::finite::solve(model, progress)
    } else if model.contact.is_empty() {
        let n = model.solver.load_steps;
        crate::solver::linear::solve_elastic(&model.at_step(n, n), progress)
    } else {
        crate::solver::active_set::solve(model, progress)
    }
}

/// Refuse rows that a pair's method cannot treat ([`crate::contact::enforcement::Enforcement::obstacle`]): constraint
/// elimination needs every row to own a free slave dof no other row touches.
pub(crate) fn refuse_obstacles<const D: usize, K: crate::model::space::SolidCell<D>>(
    model: &crate::model::Model<D, K>,
    rows: &[crate::contact::Constraint<D>],
) -> crate::error::Result<()> {
    for (k, pair) in model.contact.iter().enumerate() {
        let enforcement = crate::contact::enforcement::method(&pair.enforcement);
        let of_pair: Vec<crate::contact::RowSite> = rows
            .iter()
            .filter(|r| r.pair == k)
            .map(|r| r.site())
            .collect();
        if let Some(why) = enforcement.obstacle(&of_pair, &model.prescribed) {
            return Err(crate::error::Error::invalid(
                &model.source,
                format!("contact '{}'", pair.name),
                format!("{} does not apply: {why}", enforcement.title()),
                "use another enforcement method for this pair",
            ));
        }
    }
    Ok(())
}
