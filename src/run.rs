//! One run of one case: load and validate, solve, judge the checks, time every stage; a
//! contact solve that ended singular is a failed solve ([`Outcome::failed_solve`]). One
//! [`Outcome`] for both dimensions ([`crate::outcome`]; `D = 2` by default; a 3D case runs
//! through [`crate::run3d::run_case3`]); [`run_checked`] runs a case file of either dimension
//! for the harness commands that only need its verdicts.

use crate::error::Result;
use crate::harness::checks::{evaluate, warnings};
use crate::model::admit::load;
use crate::model::Model;
use crate::solver::solve_static;
use std::path::Path;
use std::time::Instant;

pub use crate::outcome::{Outcome, Verdicts};

/// Run the case file at `path`, 2D or 3D, for its verdicts.
pub fn run_checked(path: &Path, progress: &mut dyn FnMut(&str)) -> Result<Verdicts> {
    match crate::run3d::read_3d_case(path) {
        Some(case) => {
            progress("solving");
            crate::run3d::run_case3(&case, &path.display().to_string()).map(|o| o.verdicts())
        }
        None => run_case(path, progress).map(|o| o.verdicts()),
    }
}

/// Run the case file at `path`; `progress` hears the name of each stage.
pub fn run_case(path: &Path, progress: &mut dyn FnMut(&str)) -> Result<Outcome> {
    let start = Instant::now();
    progress("meshing");
    let model = load(path)?;
    let mesh_time = start.elapsed().as_secs_f64();
    run_model(model, mesh_time, start, progress)
}

/// Solve an already built model (`mesh_time` and `start` feed the timing breakdown).
pub fn run_model(
    model: Model,
    mesh_time: f64,
    start: Instant,
    progress: &mut dyn FnMut(&str),
) -> Result<Outcome> {
    let mut solution = solve_static(&model, progress)?;
    crate::post::check_finite_stresses(&model, &solution.u)?;
    progress("checking");
    let checks = evaluate(&model, &solution);
    let warnings = model
        .warnings
        .iter()
        .cloned()
        .chain(warnings(&model, &solution))
        .collect();
    solution.timings.mesh = mesh_time;
    solution.timings.total = start.elapsed().as_secs_f64();
    Ok(Outcome {
        warnings,
        model,
        solution,
        checks,
    })
}
