//! The block-drop study (`contact-patch impact-report --study block-drop`, issue 11): a 2D
//! elastic block given a downward velocity touches a foundation (elastic, by node-to-surface or
//! mortar rows, or rigid) at `t = 0`, is stopped by the contact force and leaves again; run with
//! every impact treatment of [`crate::solver::dynamics`] and both masses at the case's `dt` and
//! at `dt / 2`, `dt / 4`, `dt / 8` on the same mesh.
//!
//! There is no closed form for the 2D block (the 1D estimate `2 H / c_p` of the contact time
//! of the block alone ignores the foundation's compliance and the lateral expansion). What is
//! measured, from the history of [`crate::solver::history`]:
//!
//! * the **release time**: the time of the first step after contact began with no active row
//!   (the block has left); with a time-step sequence `dt / 2^k` it converges when successive
//!   values differ by at most a step and the difference shrinks (a discrete event time is
//!   known only to within the step: `t_release` lies in `(t_last contact, t_release]`);
//! * the **energy**: the largest gain `max_n E_n / E_0 - 1` and the drift `E_end / E_0 - 1` of
//!   the total (kinetic + strain) energy; Newmark's trapezoidal rule conserves it without
//!   contact, so every change is the contact treatment's;
//! * the **peak contact force** (sum of the row forces) and the block's **rebound velocity**
//!   `p_y / m` after the run (momentum over mass of body 0).
//!
//! The refinement keeps the mesh: it shows the time discretization converging, not the space
//! discretization (which the bar cases of [`super::impact`] and [`super::impact_cost`] refine).

use crate::error::{Error, Result};
use crate::io::scene::{Case, ImpactTreatment, Integrator, MassKind};
use crate::io::svg::{line_plot, Series};
use crate::solver::history::DynamicHistory;
use serde::Serialize;
use std::path::Path;

use super::impact::{each_case, run, variant, MASSES, TREATMENTS};

/// The time-step divisors of the study.
pub const DT_DIVISORS: [usize; 4] = [1, 2, 4, 8];

/// What one run of a block-drop case measured (see the module doc).
#[derive(Clone, Debug, Serialize)]
pub struct DropMeasure {
    pub case: String,
    /// The pair's discretization (and `rigid` master) as the case names it.
    pub discretization: String,
    pub impact: String,
    pub mass: String,
    pub dt: f64,
    pub steps: usize,
    /// First step after contact began with no active row; `None` if the block never left.
    pub release_time: Option<f64>,
    /// Last step with an active row.
    pub last_contact: Option<f64>,
    pub peak_force: f64,
    pub largest_energy_gain: f64,
    pub energy_drift: f64,
    /// `p_y / m` of body 0 at the last step.
    pub rebound_velocity: f64,
    pub seconds: f64,
    /// `(t, total contact force)` of every step (for the plots; not in the JSON).
    #[serde(skip)]
    pub force_history: Vec<(f64, f64)>,
}

/// Measure the history of a block-drop run.
pub fn measure(
    case: &str,
    discretization: &str,
    history: &DynamicHistory,
    seconds: f64,
) -> DropMeasure {
    let steps = &history.steps;
    let started = steps.iter().position(|s| s.active > 0);
    let release_time =
        started.and_then(|k| steps[k..].iter().find(|s| s.active == 0).map(|s| s.time));
    let last_contact = steps.iter().rev().find(|s| s.active > 0).map(|s| s.time);
    let e0 = steps[0].total;
    let last = steps.last().expect("step 0 is recorded");
    DropMeasure {
        case: case.to_string(),
        discretization: discretization.to_string(),
        impact: history.impact.clone(),
        mass: history.mass.clone(),
        dt: history.dt,
        steps: steps.len() - 1,
        release_time,
        last_contact,
        peak_force: steps.iter().map(|s| s.contact_force).fold(0.0, f64::max),
        largest_energy_gain: steps.iter().map(|s| s.total / e0 - 1.0).fold(0.0, f64::max),
        energy_drift: last.total / e0 - 1.0,
        rebound_velocity: last.body_momentum[0][1] / history.body_mass[0],
        seconds,
        force_history: steps.iter().map(|s| (s.time, s.contact_force)).collect(),
    }
}

/// `case` with its time step divided by `divisor` (same end time; frames every
/// `divisor`-th step, so each run keeps about as many).
pub fn with_dt_divided(case: &Case, divisor: usize) -> Case {
    let mut c = case.clone();
    if let Some(d) = c.physics.dynamics.as_mut() {
        d.dt /= divisor as f64;
        d.frame_every = d.frame_every.map(|f| f * divisor);
    }
    c
}

/// The discretization of the case's first pair, as a label.
fn discretization_label(case: &Case, source: &str) -> Result<String> {
    let pair = case.contact.first().ok_or_else(|| {
        Error::invalid(
            source,
            "contact",
            "the case has no contact pair",
            "the block-drop study runs a block against a foundation (cases/dynamics/block-drop-*.json)",
        )
    })?;
    let kind = serde_json::to_value(&pair.discretization)
        .ok()
        .and_then(|v| v["kind"].as_str().map(str::to_string))
        .unwrap_or_else(|| "?".into());
    Ok(if pair.master.rigid.is_some() {
        format!("{kind}, rigid foundation")
    } else {
        kind
    })
}

/// Every treatment, mass and time step of [`DT_DIVISORS`] on one case.
pub fn study_case(case: &Case, source: &str) -> Result<Vec<DropMeasure>> {
    let label = discretization_label(case, source)?;
    let mut out = Vec::new();
    for impact in TREATMENTS {
        for mass in MASSES {
            for divisor in DT_DIVISORS {
                let c = with_dt_divided(
                    &variant(case, impact, mass, Integrator::AverageAcceleration),
                    divisor,
                );
                let (_, history, seconds) = run(&c, source)?;
                out.push(measure(&case.name, &label, &history, seconds));
            }
        }
    }
    Ok(out)
}

/// The study on each case file of `paths`.
pub fn study(paths: &[&Path]) -> Result<Vec<DropMeasure>> {
    each_case(paths, study_case)
}

fn opt(t: Option<f64>) -> String {
    t.map_or("-".into(), |t| format!("{t:.5}"))
}

fn label(impact: ImpactTreatment, mass: MassKind) -> (String, String) {
    let name = |v: serde_json::Value| v.as_str().unwrap_or("?").to_string();
    (
        name(serde_json::to_value(impact).unwrap_or_default()),
        name(serde_json::to_value(mass).unwrap_or_default()),
    )
}

/// The study as Markdown (the plots are [`plots`]).
pub fn report(measures: &[DropMeasure]) -> String {
    let mut md = String::from(
        "# A block dropped on a foundation: contact force, energy and release time\n\n\
         Written by `contact-patch impact-report --study block-drop` from \
         `cases/dynamics/block-drop-*.json` (generated by `cases/dynamics/make_cases.py`; \
         what each number means is in `src/harness/block_drop.rs`). A block \
         [0.5, 1.5] x [1, 2] (Q4 8 x 8) at v = (0, -0.01) touches the foundation at t = 0; \
         E = 100, nu = 0.3, rho = 1, plane strain (c_p = 11.60; the 1D estimate of the contact \
         time of the block alone is 2 H / c_p = 0.172). Lagrange multipliers, Newmark's average \
         acceleration, each treatment and mass at dt = 0.01, 0.005, 0.0025, 0.00125 on the same \
         mesh. Energy: E = kinetic + strain; gain = max_n E_n / E_0 - 1, drift = E_end / E_0 - 1.\n",
    );
    let mut cases: Vec<&str> = measures.iter().map(|m| m.case.as_str()).collect();
    cases.dedup();
    for case in cases {
        let rows: Vec<&DropMeasure> = measures.iter().filter(|m| m.case == case).collect();
        md.push_str(&format!(
            "\n## {case} ({})\n\n| treatment | mass | dt | release time | last contact | peak force | largest energy gain | energy drift | rebound velocity | seconds |\n|---|---|---|---|---|---|---|---|---|---|\n",
            rows[0].discretization
        ));
        for m in &rows {
            md.push_str(&format!(
                "| {} | {} | {} | {} | {} | {:.5} | {:.2e} | {:+.2e} | {:+.6} | {:.3} |\n",
                m.impact,
                m.mass,
                m.dt,
                opt(m.release_time),
                opt(m.last_contact),
                m.peak_force,
                m.largest_energy_gain,
                m.energy_drift,
                m.rebound_velocity,
                m.seconds,
            ));
        }
        md.push_str("\nRelease times under dt refinement (dt, dt/2, dt/4, dt/8) and the last difference against the finest step:\n\n| treatment | mass | release times | last difference / finest dt |\n|---|---|---|---|\n");
        for impact in TREATMENTS {
            for mass in MASSES {
                let (i, m) = label(impact, mass);
                let seq: Vec<&&DropMeasure> = rows
                    .iter()
                    .filter(|r| r.impact == i && r.mass == m)
                    .collect();
                let times: Vec<String> = seq.iter().map(|r| opt(r.release_time)).collect();
                let last_two = seq
                    .iter()
                    .rev()
                    .take(2)
                    .filter_map(|r| r.release_time)
                    .collect::<Vec<_>>();
                let diff = if last_two.len() == 2 {
                    format!(
                        "{:.2}",
                        (last_two[0] - last_two[1]).abs() / seq.last().map_or(1.0, |r| r.dt)
                    )
                } else {
                    "-".into()
                };
                md.push_str(&format!("| {i} | {m} | {} | {diff} |\n", times.join(", ")));
            }
        }
    }
    md.push_str(
        "\n`plain` Newmark lets the contact nodes bounce off after one step and come back \
         (the release time is 2 dt at every dt) and gains energy; the seed's `post_impact` \
         correction with the lumped mass and the `contact_stabilized` method with either mass \
         never gain energy beyond round-off and release at a time that converges as dt is \
         halved. `post_impact` with the consistent mass does gain energy here (the largest gain \
         column): its velocity correction is weighted by the impedance per dof, which with a \
         non-diagonal mass is no projection in the mass norm, so it can raise the kinetic \
         energy. Seconds are the wall time of one run on this machine. Plots: \
         `block-drop-force-dt.svg` (node-to-surface, post_impact, lumped, four dt) and \
         `block-drop-force.svg` (every foundation, dt/8).\n",
    );
    md
}

/// The contact force histories: `(file stem, SVG)`.
pub fn plots(measures: &[DropMeasure]) -> Vec<(String, String)> {
    let pick = |case_has: &str, impact: &str, mass: &str| {
        measures
            .iter()
            .filter(|m| m.case.ends_with(case_has) && m.impact == impact && m.mass == mass)
            .collect::<Vec<_>>()
    };
    let series = |m: &DropMeasure, name: String| Series {
        name,
        points: m.force_history.clone(),
    };
    let mut out = Vec::new();
    let by_dt: Vec<Series> = pick("node-to-surface", "post_impact", "lumped")
        .into_iter()
        .map(|m| series(m, format!("dt = {}", m.dt)))
        .collect();
    if !by_dt.is_empty() {
        out.push((
            "block-drop-force-dt".to_string(),
            line_plot(
                "Block drop, node-to-surface, post_impact, lumped: contact force",
                "time",
                "contact force",
                &by_dt,
            ),
        ));
    }
    let mut finest = Vec::new();
    for (case, impact, name) in [
        (
            "node-to-surface",
            "post_impact",
            "node-to-surface, post_impact",
        ),
        ("mortar", "post_impact", "mortar, post_impact"),
        ("rigid", "post_impact", "rigid, post_impact"),
        (
            "node-to-surface",
            "contact_stabilized",
            "node-to-surface, stabilized",
        ),
        ("rigid", "contact_stabilized", "rigid, stabilized"),
    ] {
        if let Some(m) = pick(case, impact, "lumped").last() {
            finest.push(series(m, name.to_string()));
        }
    }
    if !finest.is_empty() {
        out.push((
            "block-drop-force".to_string(),
            line_plot(
                "Block drop, lumped mass, dt/8: contact force",
                "time",
                "contact force",
                &finest,
            ),
        ));
    }
    out
}
