//! Large sliding at finite strain (issue 12, "a block pressed and slid over a non-matching
//! foundation by several element lengths; compare the discretizations by the oscillation of the
//! tangential and normal contact forces along the path"): `contact-patch finite-sliding`
//! writes `reports/finite-sliding.{md,json}` and the force paths as SVG plots.
//!
//! **Problem.** A neo-Hookean foundation `[0, 6] x [0, 1]` (E = 1000, nu = 0.3, plane strain,
//! Q4, 12 x 4 cells: master facets 0.5 long) clamped at its bottom, and a neo-Hookean block
//! `[0.5, 1.7] x [1, 1.8]` (3 x 2 cells: slave nodes 0.4 apart, not matching the facets) whose
//! top is driven: pressed down by 0.1 in 2 load steps, then moved right by 3.0 (six master
//! facets, 7.5 slave spacings) in 60 steps of 0.05, frictionless, finite kinematics, contact in
//! the current configuration searched again at every Newton iterate.
//!
//! **What is measured**, at every accepted load step: the net contact force on the block
//! (normal `F_n = f_y`, tangential `F_t = f_x`, from the nodal contact forces of
//! [`crate::contact::forces`]) and the reaction at its driven top (the sum of `K u - f` over its
//! supported dofs), which must balance it. For a frictionless, quasi-static slide over a long
//! uniform foundation the exact forces vary smoothly with the slide (the foundation's ends are
//! far: a slow drift), and the exact tangential force is zero in a steady slide (no
//! dissipation: `F_t ds = dW`, the stored energy constant); the discrete forces oscillate with
//! the facet length, as node-to-surface rows jump from facet to facet. The **oscillation** of
//! `F` is the largest deviation `max |F - q|` of the force from the least-squares quadratic `q`
//! in the slide over the steady part (slide >= 0.5, one facet past the start), relative to the
//! mean normal force, and the peak-to-peak `max (F - q) - min (F - q)` likewise.
//!
//! **Newton's rate**: the residual history of the first, the middle and the last sliding step,
//! and `r_{k+1} / r_k^2` over all steps ([`super::load_path::quadratic_ratio`]).
//!
//! **Discretizations** are the entries of [`entries`]: node-to-surface with master normals, one
//! and two passes, today; slave normals and mortar are listed too and, while finite kinematics
//! refuses them, reported as refused with the model's reason. A discretization added at finite
//! strain is a new entry of that list.

use super::load_path::{build, follow, quadratic_ratio};
use crate::contact::forces::pair_forces;
use crate::io::svg::{line_plot, Series};
use crate::solver::contact_newton::FINITE_RESIDUAL_TOLERANCE;
use serde::Serialize;
use serde_json::{json, Value};

/// Young's modulus and Poisson's ratio of both bodies.
const E: f64 = 1000.0;
const NU: f64 = 0.3;
/// The press of the block's top, its load steps, the slide and its load steps.
pub const PRESS: f64 = 0.1;
pub const PRESS_STEPS: usize = 2;
pub const SLIDE: f64 = 3.0;
pub const SLIDE_STEPS: usize = 60;
/// Where the steady part of the path starts (slide).
pub const STEADY_FROM: f64 = 0.5;
/// The master facet length and the slave node spacing.
pub const FACET: f64 = 0.5;
pub const SLAVE_SPACING: f64 = 0.4;

/// One discretization of the study: a label, the pair's `discretization` and `enforcement`
/// as the case format writes them.
pub struct Entry {
    pub label: &'static str,
    pub discretization: Value,
    pub enforcement: Value,
}

/// The discretizations compared. Add an entry here when a discretization is built at finite
/// strain; one the model refuses is reported with its reason.
pub fn entries() -> Vec<Entry> {
    let lagrange = json!({"kind": "lagrange"});
    let penalty = json!({"kind": "penalty", "kappa": 1e5});
    let soft = json!({"kind": "penalty", "kappa": 1e4});
    vec![
        Entry {
            label: "node-to-surface, master normals, 1 pass, Lagrange",
            discretization: json!({"kind": "node_to_surface", "passes": 1}),
            enforcement: lagrange.clone(),
        },
        Entry {
            label: "node-to-surface, master normals, 1 pass, penalty 1e5",
            discretization: json!({"kind": "node_to_surface", "passes": 1}),
            enforcement: penalty.clone(),
        },
        Entry {
            label: "node-to-surface, master normals, 2 passes, penalty 1e5",
            discretization: json!({"kind": "node_to_surface", "passes": 2}),
            enforcement: penalty.clone(),
        },
        Entry {
            label: "node-to-surface, master normals, 1 pass, penalty 1e4",
            discretization: json!({"kind": "node_to_surface", "passes": 1}),
            enforcement: soft.clone(),
        },
        Entry {
            label: "node-to-surface, master normals, 2 passes, penalty 1e4",
            discretization: json!({"kind": "node_to_surface", "passes": 2}),
            enforcement: soft,
        },
        Entry {
            label: "node-to-surface, master normals, 2 passes, Lagrange",
            discretization: json!({"kind": "node_to_surface", "passes": 2}),
            enforcement: lagrange.clone(),
        },
        Entry {
            label: "node-to-surface, slave normals, 1 pass, Lagrange",
            discretization: json!({"kind": "node_to_surface", "passes": 1, "normal": "slave"}),
            enforcement: lagrange.clone(),
        },
        Entry {
            label: "node-to-surface, slave normals smooth sliding, 1 pass, Lagrange",
            discretization: json!({"kind": "node_to_surface", "passes": 1, "normal": "slave", "slave_normal_variation": "smooth_sliding"}),
            enforcement: lagrange.clone(),
        },
        Entry {
            label: "mortar, standard multipliers, Lagrange",
            discretization: json!({"kind": "mortar", "multiplier": "standard"}),
            enforcement: lagrange.clone(),
        },
        Entry {
            label: "mortar, dual multipliers, Lagrange",
            discretization: json!({"kind": "mortar", "multiplier": "dual"}),
            enforcement: lagrange,
        },
    ]
}

/// The case of the study with the pair's `discretization` and `enforcement`.
pub fn case(discretization: &Value, enforcement: &Value) -> Value {
    let steps = PRESS_STEPS + SLIDE_STEPS;
    let press_path: Vec<f64> = (1..=steps)
        .map(|k| (k.min(PRESS_STEPS)) as f64 / PRESS_STEPS as f64)
        .collect();
    let slide_path: Vec<f64> = (1..=steps)
        .map(|k| k.saturating_sub(PRESS_STEPS) as f64 / SLIDE_STEPS as f64)
        .collect();
    let base_x: Vec<f64> = (0..=12).map(|i| FACET * i as f64).collect();
    let top_x: Vec<f64> = (0..=3).map(|i| 0.5 + SLAVE_SPACING * i as f64).collect();
    json!({
        "name": "finite-sliding",
        "description": "a neo-Hookean block pressed and slid over a non-matching neo-Hookean foundation (src/harness/finite_sliding.rs)",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": E, "nu": NU, "model": "neo_hookean"}},
        "bodies": [
            {"name": "foundation", "material": "m", "mesh": {"block": {
                "element": "Q4", "x": base_x, "y": [0.0, 0.25, 0.5, 0.75, 1.0]}}},
            {"name": "block", "material": "m", "mesh": {"block": {
                "element": "Q4", "x": top_x, "y": [1.0, 1.4, 1.8]}}}
        ],
        "physics": {"kinematics": "finite", "contact_geometry": "current"},
        "solver": {"scheme": "newton", "load_steps": steps},
        "supports": [
            {"body": "foundation", "set": "bottom", "x": 0.0, "y": 0.0},
            {"body": "block", "set": "top", "y": -PRESS, "path": press_path},
            {"body": "block", "set": "top", "x": SLIDE, "path": slide_path}
        ],
        "loads": [],
        "contact": [{
            "name": "interface",
            "slave": {"body": "block", "set": "bottom"},
            "master": {"body": "foundation", "set": "top"},
            "discretization": discretization,
            "enforcement": enforcement
        }]
    })
}

/// The state after one accepted load step.
#[derive(Clone, Debug, Serialize)]
pub struct PathPoint {
    /// Load factor of the step, and the slide of the block's top there.
    pub load_factor: f64,
    pub slide: f64,
    /// Net contact force on the block `[f_x, f_y]` (tangential, normal).
    pub contact_force: [f64; 2],
    /// The reaction at the block's driven top (sum over its supported dofs).
    pub reaction: [f64; 2],
    pub iterations: usize,
}

/// The oscillation of one force component over the steady part (see the module doc).
#[derive(Clone, Debug, Serialize)]
pub struct Oscillation {
    /// `max |F - q|` relative to the mean normal force.
    pub max_deviation: f64,
    /// `max (F - q) - min (F - q)` relative to the mean normal force.
    pub peak_to_peak: f64,
}

/// A Newton residual history of one step.
#[derive(Clone, Debug, Serialize)]
pub struct StepResiduals {
    pub slide: f64,
    pub residuals: Vec<f64>,
}

/// One discretization's run.
#[derive(Clone, Debug, Serialize)]
pub struct SlidingRun {
    pub label: String,
    pub discretization: Value,
    pub enforcement: Value,
    /// `ran`, or `refused: <the model's reason>`, or `failed: <the solver's reason>`.
    pub outcome: String,
    pub path: Vec<PathPoint>,
    /// Mean normal force over the steady part.
    pub mean_normal: f64,
    pub normal: Option<Oscillation>,
    pub tangential: Option<Oscillation>,
    /// Largest `|contact force + reaction|` relative to the largest contact force.
    pub balance: f64,
    /// Residual histories of the first, middle and last sliding step.
    pub histories: Vec<StepResiduals>,
    /// The largest `r_{k+1} / r_k^2` over every step, and how many pairs were judged.
    pub quadratic_ratio: f64,
    pub quadratic_pairs: usize,
    /// Load-step cuts of the solve.
    pub cuts: usize,
}

/// Least-squares polynomial of degree 2 through `(x, y)`, evaluated at each `x`.
fn quadratic_fit(points: &[(f64, f64)]) -> Vec<f64> {
    // normal equations in the shifted, scaled variable t = (x - mid) / half (well conditioned)
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p.0), h.max(p.0))
        });
    let (mid, half) = (0.5 * (lo + hi), (0.5 * (hi - lo)).max(f64::MIN_POSITIVE));
    let mut a = [[0.0f64; 3]; 3];
    let mut b = [0.0f64; 3];
    for &(x, y) in points {
        let t = (x - mid) / half;
        let phi = [1.0, t, t * t];
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] += phi[i] * phi[j];
            }
            b[i] += phi[i] * y;
        }
    }
    let c = solve3(a, b);
    points
        .iter()
        .map(|&(x, _)| {
            let t = (x - mid) / half;
            c[0] + c[1] * t + c[2] * t * t
        })
        .collect()
}

/// `a c = b` for a 3 x 3 matrix by Cramer's rule (zero when `a` is singular: fewer than three
/// distinct abscissae).
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&a);
    if d == 0.0 || !d.is_finite() {
        return [0.0; 3];
    }
    let mut c = [0.0; 3];
    for (k, ck) in c.iter_mut().enumerate() {
        let mut m = a;
        for i in 0..3 {
            m[i][k] = b[i];
        }
        *ck = det(&m) / d;
    }
    c
}

/// The oscillation of `points` about their quadratic fit, relative to `scale`.
pub fn oscillation(points: &[(f64, f64)], scale: f64) -> Oscillation {
    let fit = quadratic_fit(points);
    let deviations: Vec<f64> = points.iter().zip(&fit).map(|(p, q)| p.1 - q).collect();
    let max = deviations.iter().fold(f64::NEG_INFINITY, |m, d| m.max(*d));
    let min = deviations.iter().fold(f64::INFINITY, |m, d| m.min(*d));
    Oscillation {
        max_deviation: max.max(-min) / scale,
        peak_to_peak: (max - min) / scale,
    }
}

fn not_run(entry: &Entry, outcome: String) -> SlidingRun {
    SlidingRun {
        label: entry.label.into(),
        discretization: entry.discretization.clone(),
        enforcement: entry.enforcement.clone(),
        outcome,
        path: Vec::new(),
        mean_normal: f64::NAN,
        normal: None,
        tangential: None,
        balance: f64::NAN,
        histories: Vec::new(),
        quadratic_ratio: f64::NAN,
        quadratic_pairs: 0,
        cuts: 0,
    }
}

/// The first line of an error's message.
pub(crate) fn first_line(e: &crate::error::Error) -> String {
    e.to_string().lines().next().unwrap_or_default().to_string()
}

/// Run one entry.
pub fn run(entry: &Entry) -> SlidingRun {
    let model = match build(
        &case(&entry.discretization, &entry.enforcement),
        "finite-sliding",
    ) {
        Ok(m) => m,
        Err(e) => return not_run(entry, format!("refused: {}", first_line(&e))),
    };
    let block = model
        .bodies
        .iter()
        .position(|b| b.name == "block")
        .expect("the study's block");
    let steps = (PRESS_STEPS + SLIDE_STEPS) as f64;
    // the block's supported dofs (its top) and where the slide starts, in load factor
    let driven: Vec<usize> = (0..model.bodies[block].mesh.nodes.len())
        .flat_map(|n| [model.bodies[block].dof(n, 0), model.bodies[block].dof(n, 1)])
        .filter(|&d| model.prescribed[d].is_some())
        .collect();
    let mut residuals: Vec<(f64, Vec<f64>)> = Vec::new();
    let followed = follow(&model, |factor, solution| {
        let state = solution.contact.as_ref().expect("a contact solve");
        let forces = &pair_forces(&model, state)[0];
        let on_block = if forces_on_block(&model, forces.pair, block) {
            forces.on_slave
        } else {
            forces.on_master
        };
        let mut reaction = [0.0; 2];
        for &d in &driven {
            reaction[d % 2] += solution.reactions[d];
        }
        let slide = SLIDE * ((factor * steps - PRESS_STEPS as f64) / SLIDE_STEPS as f64).max(0.0);
        residuals.push((slide, state.history.iter().map(|h| h.residual).collect()));
        PathPoint {
            load_factor: factor,
            slide,
            contact_force: on_block,
            reaction,
            iterations: state.iterations,
        }
    });
    let path = match followed {
        Ok(p) => p,
        Err(e) => return not_run(entry, format!("failed: {}", first_line(&e))),
    };
    measured(entry, path, residuals)
}

/// Whether the pair's slave side is the body `block`.
fn forces_on_block(model: &crate::model::Model, pair: usize, block: usize) -> bool {
    model.contact[pair].slave.0 == block
}

/// What the path studies (this one and [`super::ironing`]) measure on a completed path: the
/// mean normal (vertical) contact force over the steady part (`slide >= steady_from`), the
/// oscillation of both components there relative to it, the balance of the contact force
/// with the driven support's reaction, the residual histories of the first, middle and last
/// sliding step, and Newton's rate over every step.
pub(crate) struct PathMeasures {
    pub mean_normal: f64,
    pub normal: Oscillation,
    pub tangential: Oscillation,
    pub balance: f64,
    pub histories: Vec<StepResiduals>,
    pub quadratic_pairs: usize,
    pub quadratic_ratio: f64,
}

/// The [`PathMeasures`] of `path` with the residual histories `residuals` (slide, residuals).
pub(crate) fn path_measures(
    path: &[PathPoint],
    residuals: &[(f64, Vec<f64>)],
    steady_from: f64,
) -> PathMeasures {
    let steady: Vec<&PathPoint> = path.iter().filter(|p| p.slide >= steady_from).collect();
    let mean_normal =
        steady.iter().map(|p| p.contact_force[1]).sum::<f64>() / steady.len().max(1) as f64;
    let component = |i: usize| -> Vec<(f64, f64)> {
        steady
            .iter()
            .map(|p| (p.slide, p.contact_force[i]))
            .collect()
    };
    let scale = path
        .iter()
        .flat_map(|p| p.contact_force)
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    let balance = path
        .iter()
        .flat_map(|p| {
            [
                (p.contact_force[0] + p.reaction[0]).abs(),
                (p.contact_force[1] + p.reaction[1]).abs(),
            ]
        })
        .fold(0.0f64, f64::max)
        / scale;
    let sliding: Vec<&(f64, Vec<f64>)> = residuals.iter().filter(|r| r.0 > 0.0).collect();
    let histories = if sliding.is_empty() {
        Vec::new()
    } else {
        [0, sliding.len() / 2, sliding.len() - 1]
            .iter()
            .map(|&k| StepResiduals {
                slide: sliding[k].0,
                residuals: sliding[k].1.clone(),
            })
            .collect()
    };
    let (mut pairs, mut ratio) = (0, 0.0f64);
    for (_, r) in residuals {
        let (n, largest) = quadratic_ratio(r, FINITE_RESIDUAL_TOLERANCE);
        pairs += n;
        ratio = ratio.max(largest);
    }
    let oscillation_scale = mean_normal.abs().max(f64::MIN_POSITIVE);
    PathMeasures {
        mean_normal,
        normal: oscillation(&component(1), oscillation_scale),
        tangential: oscillation(&component(0), oscillation_scale),
        balance,
        histories,
        quadratic_pairs: pairs,
        quadratic_ratio: ratio,
    }
}

/// The measures of a completed path.
fn measured(entry: &Entry, path: Vec<PathPoint>, residuals: Vec<(f64, Vec<f64>)>) -> SlidingRun {
    let m = path_measures(&path, &residuals, STEADY_FROM);
    let cuts = path.len().saturating_sub(PRESS_STEPS + SLIDE_STEPS);
    SlidingRun {
        label: entry.label.into(),
        discretization: entry.discretization.clone(),
        enforcement: entry.enforcement.clone(),
        outcome: "ran".into(),
        normal: Some(m.normal),
        tangential: Some(m.tangential),
        mean_normal: m.mean_normal,
        balance: m.balance,
        histories: m.histories,
        quadratic_ratio: m.quadratic_ratio,
        quadratic_pairs: m.quadratic_pairs,
        cuts,
        path,
    }
}

/// Run every entry of [`entries`].
pub fn study() -> Vec<SlidingRun> {
    entries().iter().map(run).collect()
}

pub(crate) fn sci(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.2e}")
    } else {
        "-".into()
    }
}

/// The Markdown report.
pub fn report(runs: &[SlidingRun]) -> String {
    let mut s = format!(
        "# Large sliding at finite strain\n\n\
         Generated by `contact-patch finite-sliding` (do not edit by hand); the problem and the \
         measures are described in `src/harness/finite_sliding.rs`. A neo-Hookean block (slave \
         nodes {SLAVE_SPACING} apart) pressed by {PRESS} into a neo-Hookean foundation (master \
         facets {FACET} long, E = {E}, nu = {NU}, plane strain, Q4) in {PRESS_STEPS} load steps, \
         then slid frictionlessly by {SLIDE} ({} facets) in {SLIDE_STEPS} steps. Forces are the \
         net contact force on the block; the oscillation is the deviation from a least-squares \
         quadratic in the slide over slide >= {STEADY_FROM}, relative to the mean normal force \
         (the exact tangential force of a steady frictionless slide is zero).\n\n\
         | discretization | outcome | mean normal force | normal: max deviation | normal: peak-to-peak | tangential: max deviation | tangential: peak-to-peak | balance with the reaction | cuts | largest r_k+1 / r_k^2 (pairs) |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
        SLIDE / FACET
    );
    for r in runs {
        let osc = |o: &Option<Oscillation>| {
            o.as_ref().map_or(("-".to_string(), "-".to_string()), |o| {
                (sci(o.max_deviation), sci(o.peak_to_peak))
            })
        };
        let (nm, np) = osc(&r.normal);
        let (tm, tp) = osc(&r.tangential);
        s += &format!(
            "| {} | {} | {} | {nm} | {np} | {tm} | {tp} | {} | {} | {} |\n",
            r.label,
            r.outcome.replace('|', "/"),
            if r.mean_normal.is_finite() {
                format!("{:.4}", r.mean_normal)
            } else {
                "-".into()
            },
            sci(r.balance),
            if r.outcome == "ran" {
                r.cuts.to_string()
            } else {
                "-".into()
            },
            if r.quadratic_pairs > 0 {
                format!("{} ({})", sci(r.quadratic_ratio), r.quadratic_pairs)
            } else {
                "-".into()
            }
        );
    }
    s += "\n![normal force](finite-sliding.normal.svg)\n\n![tangential force](finite-sliding.tangential.svg)\n\n";
    s += "## Newton's residual histories (relative residual per iteration)\n\n\
          The first, the middle and the last sliding step of each run that ran; quadratic \
          convergence shows as the exponent doubling from one iteration to the next.\n\n\
          | discretization | slide | residuals |\n|---|---|---|\n";
    for r in runs {
        for h in &r.histories {
            let list: Vec<String> = h.residuals.iter().map(|v| format!("{v:.1e}")).collect();
            s += &format!("| {} | {:.2} | {} |\n", r.label, h.slide, list.join(", "));
        }
    }
    s
}

/// The plots: `(file name, SVG)` of the normal and the tangential force along the slide.
pub fn plots(runs: &[SlidingRun]) -> Vec<(String, String)> {
    let series = |i: usize| -> Vec<Series> {
        runs.iter()
            .filter(|r| !r.path.is_empty())
            .map(|r| Series {
                name: r
                    .label
                    .replace("node-to-surface, ", "NTS ")
                    .replace("master normals, ", ""),
                points: r
                    .path
                    .iter()
                    .filter(|p| p.slide > 0.0)
                    .map(|p| (p.slide, p.contact_force[i]))
                    .collect(),
            })
            .collect()
    };
    vec![
        (
            "finite-sliding.normal.svg".into(),
            line_plot(
                "Normal contact force on the block",
                "slide",
                "F_n",
                &series(1),
            ),
        ),
        (
            "finite-sliding.tangential.svg".into(),
            line_plot(
                "Tangential contact force on the block",
                "slide",
                "F_t",
                &series(0),
            ),
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_oscillation_of_a_quadratic_is_zero_and_of_a_sine_its_amplitude() {
        let xs: Vec<f64> = (0..=200).map(|i| 0.5 + 2.5 * i as f64 / 200.0).collect();
        let quadratic: Vec<(f64, f64)> = xs.iter().map(|&x| (x, 3.0 - x + 0.2 * x * x)).collect();
        let o = oscillation(&quadratic, 2.0);
        assert!(o.max_deviation < 1e-13 && o.peak_to_peak < 1e-13, "{o:?}");
        // a sine of many periods is nearly orthogonal to the quadratics: amplitude 0.01
        let wave: Vec<(f64, f64)> = xs
            .iter()
            .map(|&x| {
                (
                    x,
                    5.0 + 0.01 * (2.0 * std::f64::consts::PI * x / 0.05).sin(),
                )
            })
            .collect();
        let o = oscillation(&wave, 5.0);
        assert!((o.max_deviation - 0.01 / 5.0).abs() < 2e-4, "{o:?}");
        assert!((o.peak_to_peak - 0.02 / 5.0).abs() < 4e-4, "{o:?}");
    }

    #[test]
    fn the_case_drives_the_block_along_the_press_then_the_slide() {
        let v = case(
            &json!({"kind": "node_to_surface", "passes": 1}),
            &json!({"kind": "lagrange"}),
        );
        let press: Vec<f64> = serde_json::from_value(v["supports"][1]["path"].clone()).unwrap();
        let slide: Vec<f64> = serde_json::from_value(v["supports"][2]["path"].clone()).unwrap();
        assert_eq!(press.len(), PRESS_STEPS + SLIDE_STEPS);
        assert_eq!(&press[..3], &[0.5, 1.0, 1.0]);
        assert_eq!(&slide[..3], &[0.0, 0.0, 1.0 / SLIDE_STEPS as f64]);
        assert_eq!(*slide.last().unwrap(), 1.0);
    }
}
