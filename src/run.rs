//! One run of one case: load and validate, solve, judge the checks, time every stage; a
//! contact solve that ended singular is a failed solve ([`Outcome::failed_solve`]). One
//! [`run_model`] and one [`Outcome`] for both dimensions ([`crate::outcome`]; `D = 2` by
//! default): a 2D case file is read by [`run_case`], a 3D case by [`run_case3`], and both solve,
//! guard and judge through [`run_model`]; what differs by dimension is behind
//! [`RunDimension`]. [`run_checked`] runs a case file of either dimension for the harness
//! commands that only need its verdicts.

use crate::contact::forces::pair_forces;
use crate::error::Result;
use crate::fe::ElementKind;
use crate::fe3d::SolidKind;
use crate::harness::checks::{evaluate_run, warnings_with, DimensionChecks};
use crate::io::scene::Case;
use crate::model::admit::load;
use crate::model::Model;
use crate::solver::active_set::ContactStep;
use crate::solver::contact_newton::NewtonDimension;
use crate::solver::linear::Solution;
use std::path::Path;
use std::time::Instant;

pub use crate::outcome::{Outcome, Verdicts};

/// Run the case file at `path`, 2D or 3D, for its verdicts.
pub fn run_checked(path: &Path, progress: &mut dyn FnMut(&str)) -> Result<Verdicts> {
    match crate::run3d::read_3d_case(path) {
        Some(case) => {
            progress("solving");
            run_case3(&case, &path.display().to_string()).map(|o| o.verdicts())
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

/// Run the 3D case `case` read from `source` (built by [`crate::run3d::build3`]).
pub fn run_case3(case: &Case, source: &str) -> Result<crate::run3d::Outcome3> {
    let start = Instant::now();
    let model = crate::run3d::build3(case, source)?;
    let mesh_time = start.elapsed().as_secs_f64();
    crate::model::admit::check_rigid_modes(&model)?;
    run_model(model, mesh_time, start, &mut |_| {})
}

/// What a run does differently by dimension: the solve (2D adds time integration) and the
/// nodal stresses the output writes, which must be finite.
pub trait RunDimension<const D: usize>:
    NewtonDimension<D> + ContactStep<D> + DimensionChecks<D>
{
    /// The static, load-stepped or time-integrated solve of `model`.
    fn solve(model: &Model<D, Self>, progress: &mut dyn FnMut(&str)) -> Result<Solution<D>>;

    /// An error naming the first body, node and value whose nodal stress is not finite.
    fn check_finite_stresses(model: &Model<D, Self>, u: &[f64]) -> Result<()>;
}

impl RunDimension<2> for ElementKind {
    fn solve(model: &Model, progress: &mut dyn FnMut(&str)) -> Result<Solution> {
        crate::solver::solve_static(model, progress)
    }

    fn check_finite_stresses(model: &Model, u: &[f64]) -> Result<()> {
        crate::post::check_finite_stresses(model, u)
    }
}

impl RunDimension<3> for SolidKind {
    fn solve(model: &crate::model::Model3, progress: &mut dyn FnMut(&str)) -> Result<Solution<3>> {
        // no time integration in 3D: the model refuses a dynamics block
        crate::solver::solve_quasi_static(model, progress)
    }

    fn check_finite_stresses(model: &crate::model::Model3, u: &[f64]) -> Result<()> {
        crate::post::check_finite_nodal_stresses(model, u, crate::run3d::nodal_stress)
    }
}

/// Solve an already built model of either dimension (`mesh_time` and `start` feed the timing
/// breakdown): the solve, the guard against stresses that are not finite (a finite
/// displacement can give overflowing stresses), the checks and the warnings.
pub fn run_model<const D: usize, K: RunDimension<D>>(
    model: Model<D, K>,
    mesh_time: f64,
    start: Instant,
    progress: &mut dyn FnMut(&str),
) -> Result<Outcome<D, K>> {
    let mut solution = K::solve(&model, progress)?;
    K::check_finite_stresses(&model, &solution.u)?;
    progress("checking");
    // the pairs' contact forces, once for the checks and the warnings
    let forces = solution
        .contact
        .as_ref()
        .map(|state| pair_forces(&model, state));
    let checks = evaluate_run(&model, &solution, forces.as_deref());
    let warnings = model
        .warnings
        .iter()
        .cloned()
        .chain(warnings_with(&model, &solution, forces.as_deref()))
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
