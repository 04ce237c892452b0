//! The impact study (`contact-patch impact-report`): the 1D wave cases of `benchmarks.md`
//! section 6 run with every impact treatment and mass, measured against the exact solutions.
//!
//! **Exact solutions** (elastic bars, `c = sqrt(E / rho)`, impedance `Z = rho c`): a striker at
//! `v1` touching a target at `v2` (or a rigid wall, `Z2 -> infinity`, `v2 = 0`) at `t = 0`
//! sends waves that set the interface to `v* = (Z1 v1 + Z2 v2) / (Z1 + Z2)` (the seed's
//! post-impact velocity) under the contact stress `sigma = Z1 Z2 (v1 - v2) / (Z1 + Z2)` (rigid:
//! `Z1 v1`). With equal transit times `L1 / c1 = L2 / c2` (or a wall) the waves return together
//! at `t = 2 L1 / c1`, the bars separate, and each leaves at the uniform velocity
//! `2 v* - v_i` (rigid wall: `-v1`; identical bars: the striker stops, the target takes `v1`).
//!
//! **Measured** from the history of [`crate::solver::history`]: the plateau stress is the mean
//! contact force over the steps in `(0, 2 L1 / c1]`, divided by the striker's end area
//! (height x thickness); the first release is the first step after contact began with no
//! active row, the last contact the last step with one; the velocity after separation of a
//! body is its momentum over its mass at the last step; the energy drift is `E_end / E_0 - 1`
//! and the largest gain `max_n E_n / E_0 - 1`.

use crate::error::{Error, Result};
use crate::io::scene::{Case, ImpactTreatment, Integrator, MassKind};
use crate::model::admit::admit;
use crate::model::{parse, MasterSide, Model};
use crate::solver::dynamics::wave_speed;
use crate::solver::history::DynamicHistory;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// The 1D wave solution of a case (see the module doc).
#[derive(Clone, Debug, Serialize)]
pub struct WaveSolution {
    pub striker_velocity: f64,
    pub target_velocity: f64,
    /// `None` for a rigid wall.
    pub target_impedance: Option<f64>,
    pub striker_impedance: f64,
    pub interface_velocity: f64,
    pub contact_stress: f64,
    pub contact_duration: f64,
    /// Velocity after separation of each body.
    pub velocity_after: Vec<f64>,
    /// Contact area (striker height x thickness).
    pub area: f64,
}

/// The wave solution of a two-bar or bar-on-wall `model` with `physics.dynamics`: body 0 is the
/// striker, body 1 (if any) the target; the initial velocity of each body is its mean `v_x`.
pub fn wave_solution(model: &Model) -> Result<WaveSolution> {
    let dynamics = model.dynamics.as_ref().ok_or_else(|| {
        Error::invalid(
            &model.source,
            "physics",
            "the case has no physics.dynamics",
            "the impact study runs dynamic cases (cases/dynamics)",
        )
    })?;
    let refuse = |problem: String| {
        Err(Error::invalid(
            &model.source,
            "bodies",
            problem,
            "the impact study takes a striker bar (body 0) against a rigid wall or a target bar (body 1)",
        ))
    };
    let rigid = model
        .contact
        .first()
        .is_some_and(|p| matches!(p.master, MasterSide::Rigid(_)));
    if model.bodies.len() != if rigid { 1 } else { 2 } {
        return refuse(format!("{} bodies", model.bodies.len()));
    }
    let mean_vx = |b: usize| {
        let body = &model.bodies[b];
        let n = body.mesh.nodes.len();
        (0..n)
            .map(|k| dynamics.initial_velocity[body.dof(k, 0)])
            .sum::<f64>()
            / n as f64
    };
    let extent = |b: usize| {
        let bb = model.bodies[b].mesh.bounding_box();
        (bb[1][0] - bb[0][0], bb[1][1] - bb[0][1])
    };
    let (l1, h1) = extent(0);
    let c1 = wave_speed(model, 0, dynamics.density[0]);
    let z1 = dynamics.density[0] * c1;
    let v1 = mean_vx(0);
    let (z2, v2) = if rigid {
        (None, 0.0)
    } else {
        let c2 = wave_speed(model, 1, dynamics.density[1]);
        let (l2, _) = extent(1);
        if ((l1 / c1) - (l2 / c2)).abs() > 1e-12 * (l1 / c1) {
            return refuse(format!(
                "the transit times differ (L1/c1 = {}, L2/c2 = {}): the bars do not separate cleanly",
                l1 / c1,
                l2 / c2
            ));
        }
        (Some(dynamics.density[1] * c2), mean_vx(1))
    };
    let (interface, stress) = match z2 {
        None => (0.0, z1 * v1),
        Some(z2) => (
            (z1 * v1 + z2 * v2) / (z1 + z2),
            z1 * z2 * (v1 - v2) / (z1 + z2),
        ),
    };
    let mut velocity_after = vec![2.0 * interface - v1];
    if !rigid {
        velocity_after.push(2.0 * interface - v2);
    }
    Ok(WaveSolution {
        striker_velocity: v1,
        target_velocity: v2,
        target_impedance: z2,
        striker_impedance: z1,
        interface_velocity: interface,
        contact_stress: stress,
        contact_duration: 2.0 * l1 / c1,
        velocity_after,
        area: h1 * model.thickness,
    })
}

/// What one run measured (see the module doc).
#[derive(Clone, Debug, Serialize)]
pub struct ImpactMeasure {
    pub case: String,
    pub impact: String,
    pub mass: String,
    pub dt: f64,
    pub steps: usize,
    pub plateau_stress: f64,
    pub first_release: Option<f64>,
    pub last_contact: Option<f64>,
    pub velocity_after: Vec<f64>,
    /// Total momentum at the start and the end.
    pub momentum_start: f64,
    pub momentum_end: f64,
    pub energy_drift: f64,
    pub largest_energy_gain: f64,
    /// Largest relative normal velocity and acceleration of an active row, before and after
    /// the treatment, over all steps.
    pub velocity_jump: [f64; 2],
    pub acceleration_jump: [f64; 2],
    pub factorizations: usize,
    pub reused_factorizations: usize,
    pub seconds: f64,
    pub exact: WaveSolution,
}

/// Measure `history` against `exact`.
pub fn measure(
    case: &str,
    history: &DynamicHistory,
    exact: &WaveSolution,
    seconds: f64,
) -> ImpactMeasure {
    let steps = &history.steps;
    let dt = history.dt;
    let in_contact: Vec<&_> = steps
        .iter()
        .filter(|s| s.step > 0 && s.time <= exact.contact_duration + 1e-9 * dt)
        .collect();
    let plateau = in_contact.iter().map(|s| s.contact_force).sum::<f64>()
        / in_contact.len().max(1) as f64
        / exact.area;
    let started = steps.iter().position(|s| s.active > 0);
    let first_release =
        started.and_then(|k| steps[k..].iter().find(|s| s.active == 0).map(|s| s.time));
    let last_contact = steps.iter().rev().find(|s| s.active > 0).map(|s| s.time);
    let last = steps.last().expect("step 0 is recorded");
    let first = &steps[0];
    let velocity_after = last
        .body_momentum
        .iter()
        .zip(&history.body_mass)
        .map(|(p, m)| p[0] / m)
        .collect();
    let e0 = first.total;
    let most = |f: &dyn Fn(&crate::solver::history::StepRecord) -> f64| {
        steps.iter().map(f).fold(0.0f64, f64::max)
    };
    ImpactMeasure {
        case: case.to_string(),
        impact: history.impact.clone(),
        mass: history.mass.clone(),
        dt,
        steps: steps.len() - 1,
        plateau_stress: plateau,
        first_release,
        last_contact,
        velocity_after,
        momentum_start: first.momentum[0],
        momentum_end: last.momentum[0],
        energy_drift: last.total / e0 - 1.0,
        largest_energy_gain: steps.iter().map(|s| s.total / e0 - 1.0).fold(0.0, f64::max),
        velocity_jump: [most(&|s| s.velocity_jump[0]), most(&|s| s.velocity_jump[1])],
        acceleration_jump: [
            most(&|s| s.acceleration_jump[0]),
            most(&|s| s.acceleration_jump[1]),
        ],
        factorizations: last.factorizations,
        reused_factorizations: last.reused_factorizations,
        seconds,
        exact: exact.clone(),
    }
}

/// `case` with the impact treatment, mass and integrator replaced.
pub fn variant(
    case: &Case,
    impact: ImpactTreatment,
    mass: MassKind,
    integrator: Integrator,
) -> Case {
    let mut c = case.clone();
    if let Some(d) = c.physics.dynamics.as_mut() {
        d.impact = impact;
        d.mass = mass;
        d.integrator = integrator;
    }
    c
}

/// Build, admit and run `case` (from `source`); its history and wall time.
pub fn run(case: &Case, source: &str) -> Result<(Model, DynamicHistory, f64)> {
    let model = admit(Model::build(case, source)?)?;
    let start = Instant::now();
    let solution = crate::solver::solve_static(&model, &mut |_| {})?;
    let seconds = start.elapsed().as_secs_f64();
    let history = solution.dynamics.ok_or_else(|| {
        Error::invalid(
            source,
            "physics",
            "the case has no physics.dynamics",
            "the impact study runs dynamic cases",
        )
    })?;
    Ok((model, *history, seconds))
}

/// The treatments and masses of the study.
pub const TREATMENTS: [ImpactTreatment; 3] = [
    ImpactTreatment::Plain,
    ImpactTreatment::PostImpact,
    ImpactTreatment::ContactStabilized,
];
pub const MASSES: [MassKind; 2] = [MassKind::Lumped, MassKind::Consistent];

/// The study `study_case` on each case file of `paths` (read and parsed), concatenated.
pub fn each_case<T>(
    paths: &[&Path],
    mut study_case: impl FnMut(&Case, &str) -> Result<Vec<T>>,
) -> Result<Vec<T>> {
    let mut out = Vec::new();
    for path in paths {
        let source = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|e| Error::io(&source, "reading the case", e))?;
        out.extend(study_case(&parse(&text, &source)?, &source)?);
    }
    Ok(out)
}

/// Every treatment and mass (average acceleration) on each case file of `paths`.
pub fn study(paths: &[&Path]) -> Result<Vec<ImpactMeasure>> {
    each_case(paths, |case, source| {
        let mut out = Vec::new();
        for impact in TREATMENTS {
            for mass in MASSES {
                let c = variant(case, impact, mass, Integrator::AverageAcceleration);
                let (model, history, seconds) = run(&c, source)?;
                let exact = wave_solution(&model)?;
                out.push(measure(&case.name, &history, &exact, seconds));
            }
        }
        Ok(out)
    })
}

fn opt(t: Option<f64>) -> String {
    t.map_or("-".into(), |t| format!("{t:.4}"))
}

/// The study as Markdown.
pub fn report(measures: &[ImpactMeasure]) -> String {
    let mut md = String::from(
        "# Impact: Newmark (average acceleration) against the 1D wave solutions\n\n\
         Written by `contact-patch impact-report` from the cases in `cases/dynamics/` \
         (benchmarks.md section 6; the exact values and how each number is measured are in \
         `src/harness/impact.rs`). Every case runs with each impact treatment (`plain` Newmark, \
         the seed's `post_impact` correction, the `contact_stabilized` Newmark method of \
         Deuflhard, Krause & Ertel 2008) and each mass (lumped HRZ, consistent), Lagrange \
         multipliers, dt at Courant number 1 of the lumped mesh.\n",
    );
    let mut cases: Vec<&str> = measures.iter().map(|m| m.case.as_str()).collect();
    cases.dedup();
    for case in cases {
        let rows: Vec<&ImpactMeasure> = measures.iter().filter(|m| m.case == case).collect();
        let e = &rows[0].exact;
        md.push_str(&format!(
            "\n## {case}\n\nExact: contact stress {:.6}, contact duration {:.4}, velocity after separation {}; interface velocity {:.6}. dt = {}, {} steps.\n\n",
            e.contact_stress,
            e.contact_duration,
            e.velocity_after.iter().map(|v| format!("{v:.6}")).collect::<Vec<_>>().join(" / "),
            e.interface_velocity,
            rows[0].dt,
            rows[0].steps,
        ));
        md.push_str("| treatment | mass | plateau stress (error) | first release | last contact | velocity after (error) | momentum start / end | energy drift | largest gain | velocity jump before / after | acceleration jump before / after | factorizations / reused | seconds |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
        for m in rows {
            let after: Vec<String> = m
                .velocity_after
                .iter()
                .zip(&m.exact.velocity_after)
                .map(|(v, x)| format!("{v:.6} ({:+.1e})", v - x))
                .collect();
            md.push_str(&format!(
                "| {} | {} | {:.6} ({:+.2}%) | {} | {} | {} | {:.3e} / {:.3e} | {:+.2e} | {:.2e} | {:.2e} / {:.2e} | {:.2e} / {:.2e} | {} / {} | {:.3} |\n",
                m.impact,
                m.mass,
                m.plateau_stress,
                100.0 * (m.plateau_stress / m.exact.contact_stress - 1.0),
                opt(m.first_release),
                opt(m.last_contact),
                after.join(" / "),
                m.momentum_start,
                m.momentum_end,
                m.energy_drift,
                m.largest_energy_gain,
                m.velocity_jump[0],
                m.velocity_jump[1],
                m.acceleration_jump[0],
                m.acceleration_jump[1],
                m.factorizations,
                m.reused_factorizations,
                m.seconds,
            ));
        }
    }
    md.push_str("\nThe velocity and acceleration jumps are the largest `|b . v|` and `|b . a|` of an active contact row (the relative normal velocity and acceleration of the two sides, zero for the physics): `post_impact` removes them at every contact step; `contact_stabilized` leaves the contact nodes' velocities as the projection finds them (its point is the energy). Seconds are wall time of one run on this machine, for comparison within the table only.\n");
    md
}
