//! What accuracy costs (`contact-patch impact-report --study cost`, issue 11): the 1D wave
//! cases of [`super::impact`] (benchmarks.md section 6) at four levels of refinement, with
//! every impact treatment and mass, their errors against the exact wave solution set against
//! the wall time of the run.
//!
//! **Refinements** (level `k = 1, 2, 4, 8`): `mesh and step` divides every uniform axis of the
//! bars along `x` by `k` and `dt` by `k` (the Courant number `c dt / h` of the case kept);
//! `step only` divides `dt` alone on the case's mesh (the Courant number falls as `1 / k`).
//!
//! **Errors** against [`super::impact::WaveSolution`] (contact stress `sigma`, duration
//! `T = 2 L1 / c1`, velocities after separation `v_i`, striker speed `v0`, end area `A`):
//!
//! * plateau stress: `|sigma_h / sigma - 1|` (`sigma_h` as in [`super::impact::measure`]);
//! * contact duration: `|t_last - T| / T`, `t_last` the time of the last step with an active
//!   row;
//! * rebound velocity: `max_i |v_i,h - v_i| / |v0|` over the bodies after the run;
//! * contact force in `L2(0, t_end)`: `||F_h - F|| / ||F||`, `F(t) = sigma A` on `(0, T)` and
//!   `0` after (`sigma A / 2` at the two jumps), `||g||^2 = int_0^t_end g^2 dt` by the
//!   trapezoidal rule on the steps (`F_h` is the force recorded at each step). The exact force
//!   is a step in time, so no method converges faster than `dt^(1/2)` in this norm.
//!
//! **Wall time**: the shortest of [`REPEATS`] runs of the solve (the time stepping, not reading
//! or building the model), measured on the machine that runs the command, never asserted.

use crate::error::{Error, Result};
use crate::io::scene::{Breaks, Case, Integrator, MeshSpec};
use crate::io::svg::{line_plot, Series};
use serde::Serialize;
use std::path::Path;

use super::impact::{each_case, measure, run, variant, wave_solution, MASSES, TREATMENTS};

/// Refinement levels (divisors of `h` and `dt`).
pub const LEVELS: [usize; 4] = [1, 2, 4, 8];
/// Runs per measurement; the shortest wall time is kept.
pub const REPEATS: usize = 3;

/// How a level refines the case.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Refinement {
    MeshAndStep,
    StepOnly,
}

impl Refinement {
    fn label(self) -> &'static str {
        match self {
            Refinement::MeshAndStep => "mesh and step",
            Refinement::StepOnly => "step only",
        }
    }
}

/// The errors and cost of one run (see the module doc).
#[derive(Clone, Debug, Serialize)]
pub struct CostMeasure {
    pub case: String,
    pub impact: String,
    pub mass: String,
    pub refinement: Refinement,
    pub level: usize,
    pub elements: usize,
    pub dt: f64,
    pub steps: usize,
    pub plateau_error: f64,
    pub duration_error: f64,
    pub rebound_error: f64,
    pub force_l2_error: f64,
    pub seconds: f64,
}

/// `case` refined to `level` (see the module doc); an axis given as a list of breaks cannot be
/// refined and is refused.
pub fn refined(case: &Case, refinement: Refinement, level: usize, source: &str) -> Result<Case> {
    let mut c = case.clone();
    if let Some(d) = c.physics.dynamics.as_mut() {
        d.dt /= level as f64;
        d.frame_every = Some(usize::MAX / 2);
    }
    if refinement == Refinement::MeshAndStep {
        for (k, body) in c.bodies.iter_mut().enumerate() {
            match &mut body.mesh {
                MeshSpec::Block(block) => match &mut block.x {
                    Breaks::Uniform(u) => u.divisions *= level,
                    Breaks::List(_) => return Err(Error::invalid(
                        source,
                        format!("bodies[{k}].mesh.block.x"),
                        "the cost study refines uniform divisions; this axis is a list of breaks",
                        "give the axis as {\"from\": .., \"to\": .., \"divisions\": N}",
                    )),
                },
                MeshSpec::Explicit(_) | MeshSpec::Gmsh(_) | MeshSpec::Block3d(_) => {
                    return Err(Error::invalid(
                        source,
                        format!("bodies[{k}].mesh"),
                        "the cost study refines block meshes; this mesh is explicit or read from a Gmsh file",
                        "give the bar as a \"block\" mesh with uniform divisions",
                    ))
                }
            }
        }
    }
    Ok(c)
}

/// `||F_h - F|| / ||F||` in `L2(0, t_end)` (module doc) of the `(t, F_h)` history against the
/// force `force` on `(0, duration)`.
pub fn force_l2_error(history: &[(f64, f64)], force: f64, duration: f64, dt: f64) -> f64 {
    let exact = |t: f64| {
        let tol = 1e-9 * dt;
        if t.abs() <= tol || (t - duration).abs() <= tol {
            0.5 * force
        } else if t > 0.0 && t < duration {
            force
        } else {
            0.0
        }
    };
    let n = history.len();
    let mut error = 0.0;
    for (k, &(t, f)) in history.iter().enumerate() {
        let w = if k == 0 || k + 1 == n { 0.5 * dt } else { dt };
        error += w * (f - exact(t)).powi(2);
    }
    (error / (force * force * duration)).sqrt()
}

/// One case at every level, treatment and mass, for both refinements.
pub fn study_case(case: &Case, source: &str) -> Result<Vec<CostMeasure>> {
    let mut out = Vec::new();
    for refinement in [Refinement::MeshAndStep, Refinement::StepOnly] {
        for impact in TREATMENTS {
            for mass in MASSES {
                for level in LEVELS {
                    let c = refined(
                        &variant(case, impact, mass, Integrator::AverageAcceleration),
                        refinement,
                        level,
                        source,
                    )?;
                    let (model, history, mut seconds) = run(&c, source)?;
                    for _ in 1..REPEATS {
                        seconds = seconds.min(run(&c, source)?.2);
                    }
                    let exact = wave_solution(&model)?;
                    let m = measure(&case.name, &history, &exact, seconds);
                    let v0 = exact.striker_velocity.abs();
                    let forces: Vec<(f64, f64)> = history
                        .steps
                        .iter()
                        .map(|s| (s.time, s.contact_force))
                        .collect();
                    out.push(CostMeasure {
                        case: case.name.clone(),
                        impact: m.impact.clone(),
                        mass: m.mass.clone(),
                        refinement,
                        level,
                        elements: model.bodies.iter().map(|b| b.mesh.cell_count()).sum(),
                        dt: history.dt,
                        steps: m.steps,
                        plateau_error: (m.plateau_stress / exact.contact_stress - 1.0).abs(),
                        duration_error: m.last_contact.map_or(1.0, |t| {
                            (t - exact.contact_duration).abs() / exact.contact_duration
                        }),
                        rebound_error: m
                            .velocity_after
                            .iter()
                            .zip(&exact.velocity_after)
                            .map(|(a, b)| (a - b).abs() / v0)
                            .fold(0.0, f64::max),
                        force_l2_error: force_l2_error(
                            &forces,
                            exact.contact_stress * exact.area,
                            exact.contact_duration,
                            history.dt,
                        ),
                        seconds,
                    });
                }
            }
        }
    }
    Ok(out)
}

/// The study on each case file of `paths`.
pub fn study(paths: &[&Path]) -> Result<Vec<CostMeasure>> {
    each_case(paths, study_case)
}

/// The observed order `log2(e_first / e_last) / log2(level_last / level_first)` of a sequence.
fn rate(first: f64, last: f64, levels: f64) -> f64 {
    (first / last).log2() / levels.log2()
}

/// The study as Markdown (the plots are [`plots`]).
pub fn report(measures: &[CostMeasure]) -> String {
    let mut md = String::from(
        "# What accuracy costs: impact errors against the 1D wave solution versus wall time\n\n\
         Written by `contact-patch impact-report --study cost` (default case \
         `cases/dynamics/bar-on-rigid-wall.json`); the refinements, the four errors and the \
         timing are defined in `src/harness/impact_cost.rs`. Newmark's average acceleration, \
         Lagrange multipliers, each impact treatment and mass (lumped HRZ, consistent), levels \
         1, 2, 4, 8: `mesh and step` divides h and dt together (Courant number 1 kept), `step \
         only` divides dt on the level-1 mesh. Errors are relative (plateau stress, contact \
         duration, rebound velocity over v0, contact force in L2 in time). Seconds: the \
         shortest of 3 runs of the time stepping on the machine that ran the command; they \
         vary from run to run and machine to machine.\n",
    );
    let mut cases: Vec<&str> = measures.iter().map(|m| m.case.as_str()).collect();
    cases.dedup();
    for case in cases {
        for refinement in [Refinement::MeshAndStep, Refinement::StepOnly] {
            let rows: Vec<&CostMeasure> = measures
                .iter()
                .filter(|m| m.case == case && m.refinement == refinement)
                .collect();
            if rows.is_empty() {
                continue;
            }
            md.push_str(&format!(
                "\n## {case}, {}\n\n| treatment | mass | level | elements | dt | plateau stress | contact duration | rebound velocity | force L2 | seconds |\n|---|---|---|---|---|---|---|---|---|---|\n",
                refinement.label()
            ));
            for m in &rows {
                md.push_str(&format!(
                    "| {} | {} | {} | {} | {:.3e} | {:.2e} | {:.2e} | {:.2e} | {:.3e} | {:.2e} |\n",
                    m.impact,
                    m.mass,
                    m.level,
                    m.elements,
                    m.dt,
                    m.plateau_error,
                    m.duration_error,
                    m.rebound_error,
                    m.force_l2_error,
                    m.seconds
                ));
            }
            md.push_str("\nObserved order from level 1 to level 8 (log2 of the error ratio over log2 8) and the cost ratio:\n\n| treatment | mass | plateau stress | rebound velocity | force L2 | seconds level 8 / level 1 |\n|---|---|---|---|---|---|\n");
            let mut groups: Vec<(&str, &str)> = rows
                .iter()
                .map(|m| (m.impact.as_str(), m.mass.as_str()))
                .collect();
            groups.dedup();
            for (impact, mass) in groups {
                let seq: Vec<&&CostMeasure> = rows
                    .iter()
                    .filter(|m| m.impact == impact && m.mass == mass)
                    .collect();
                let (a, b) = (seq[0], seq[seq.len() - 1]);
                let span = (b.level / a.level) as f64;
                md.push_str(&format!(
                    "| {impact} | {mass} | {:.2} | {:.2} | {:.2} | {:.1} |\n",
                    rate(a.plateau_error, b.plateau_error, span),
                    rate(a.rebound_error, b.rebound_error, span),
                    rate(a.force_l2_error, b.force_l2_error, span),
                    b.seconds / a.seconds,
                ));
            }
        }
    }
    md.push_str(
        "\nPlots: `impact-cost-lumped.svg` and `impact-cost-consistent.svg`, log10 of the \
         force L2 error against log10 of the seconds for each treatment and refinement.\n",
    );
    md
}

/// Log-log plots of the force L2 error against the seconds, one per mass, of the first case:
/// `(file stem, SVG)`.
pub fn plots(measures: &[CostMeasure]) -> Vec<(String, String)> {
    let Some(case) = measures.first().map(|m| m.case.clone()) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for mass in ["lumped", "consistent"] {
        let mut series = Vec::new();
        for (impact, refinement) in [
            ("plain", Refinement::MeshAndStep),
            ("post_impact", Refinement::MeshAndStep),
            ("contact_stabilized", Refinement::MeshAndStep),
            ("post_impact", Refinement::StepOnly),
            ("contact_stabilized", Refinement::StepOnly),
        ] {
            let points: Vec<(f64, f64)> = measures
                .iter()
                .filter(|m| {
                    m.case == case
                        && m.mass == mass
                        && m.impact == impact
                        && m.refinement == refinement
                        && m.seconds > 0.0
                        && m.force_l2_error > 0.0
                })
                .map(|m| (m.seconds.log10(), m.force_l2_error.log10()))
                .collect();
            if !points.is_empty() {
                series.push(Series {
                    name: format!("{impact}, {}", refinement.label()),
                    points,
                });
            }
        }
        out.push((
            format!("impact-cost-{mass}"),
            line_plot(
                &format!("{case}, {mass} mass: force L2 error against wall time"),
                "log10 seconds",
                "log10 relative L2 error of the contact force",
                &series,
            ),
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::force_l2_error;

    #[test]
    fn the_force_error_is_the_trapezoidal_l2_norm_of_the_difference() {
        // the exact history gives 0; a zero history on steps dt = T / 10 over (0, 2 T) gives
        // sqrt(dt (1/2 (F/2)^2 + 9 F^2 + (F/2)^2) / (F^2 T)) = sqrt(9.375 / 10)
        let (force, duration) = (3.0, 0.2);
        let dt = duration / 10.0;
        let times: Vec<f64> = (0..=20).map(|k| k as f64 * dt).collect();
        let exact: Vec<(f64, f64)> = times
            .iter()
            .map(|&t| {
                let f = if t == 0.0 || (t - duration).abs() < 1e-12 {
                    0.5 * force
                } else if t < duration {
                    force
                } else {
                    0.0
                };
                (t, f)
            })
            .collect();
        assert!(force_l2_error(&exact, force, duration, dt) < 1e-15);
        let zero: Vec<(f64, f64)> = times.iter().map(|&t| (t, 0.0)).collect();
        let e = force_l2_error(&zero, force, duration, dt);
        assert!((e - (9.375f64 / 10.0).sqrt()).abs() < 1e-14, "{e}");
    }
}
