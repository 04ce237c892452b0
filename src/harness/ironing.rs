//! The ironing problem at finite strain (issue 12, "an ironing problem from the literature
//! with its published force curve if one can be found, else its convergence under
//! refinement"): `contact-patch ironing` writes `reports/ironing.{md,json,svg}`.
//!
//! **Reference and why no published curve is used.** The ironing problem of Puso & Laursen
//! (2004, CMAME 193, "A mortar segment-to-segment frictional contact method for large
//! deformations", example 2) and of Yang, Laursen & Meng (2005, IJNME 62, "Two dimensional
//! mortar contact methods for large deformation frictional sliding") presses a stiff die with a
//! circular bottom into a soft neo-Hookean slab and slides it along the slab; Puso & Laursen's
//! slab has E = 1, nu = 0.3 and the die E = 1000 (both neo-Hookean), the die radius 3. Their
//! force curves are frictional (mu = 0.3), and friction at finite strain is refused by this
//! tool, so the study is **frictionless** and its reference is its own **convergence under
//! mesh refinement**, not the published curves (no numerical data of the curves was found
//! either). The geometry is a smaller one of the same kind, documented here.
//!
//! **Problem.** Plane strain, finite kinematics, contact in the current configuration searched
//! again at every Newton iterate, `solver.scheme: "newton"`. A neo-Hookean slab
//! `[0, 6] x [0, 1]` (E = 1, nu = 0.3) clamped at its bottom; a neo-Hookean die (E = 10,
//! nu = 0.3) of half-width 0.6 whose bottom is the arc of the circle of radius 1 touching the
//! slab at `x = 1.2` (the arc drops by `1 - sqrt(1 - 0.36) = 0.2` at the die's sides) and whose
//! flat top is 0.6 above the touch point. The die is an explicit Q4 mesh generated here: a
//! grid of `n_x x n_y` cells between the arc and the top, its bottom nodes on the arc. The
//! die's top is driven: pressed down by [`PRESS`] in [`PRESS_STEPS`] load steps, then moved
//! right by [`SLIDE`] (2.5 die widths) in [`SLIDE_STEPS`] steps of 0.025. The die is the
//! slave, the slab the master. The die is 10 times stiffer than the slab, not Puso & Laursen's
//! 1000 times: with E = 1000 every level's Newton solve fails during the press (a trial
//! iterate inverts a slab cell and ten step cuts do not cure it), and with E = 100 the slide
//! fails on every level at 60 steps (tried on this geometry; the die's stiffness is not what
//! the study measures).
//!
//! **Refinement.** [`LEVELS`]: slab 12 x 2, 24 x 4, 48 x 8 cells (facets 0.5, 0.25, 0.125) and
//! die 6 x 2, 12 x 4, 24 x 8 (slave nodes 0.2, 0.1, 0.05 apart in x): h halves per level.
//!
//! **What is measured**, at every accepted load step: the net contact force on the die,
//! horizontal `F_x` and vertical `F_y` (from [`crate::contact::forces`]), and the reaction at
//! its driven top, which must balance it. The **refinement difference** of a force between two
//! levels is `max |F_h - F_{h/2}|` over the nominal load steps (linear between accepted steps
//! where a step cut moved them, [`force_at`]), relative to the
//! finer level's mean vertical force over the steady part; for a converging discretization the
//! differences shrink from level to level. The **oscillation** about a least-squares quadratic
//! in the slide over the steady part (slide >= [`STEADY_FROM`]) is the measure of
//! [`super::finite_sliding::oscillation`]. The exact horizontal force of a quasi-static
//! frictionless slide over a uniform slab is zero (the stored energy is invariant under the
//! translation; the slab's ends make a slow drift): its discrete value measures the error.
//! **Newton's rate**: `r_{k+1} / r_k^2` over every step ([`super::load_path::quadratic_ratio`]).

use super::finite_sliding::{
    first_line, path_measures, sci, Oscillation, PathPoint, StepResiduals,
};
use super::load_path::{build, follow, quadratic_ratio};
use crate::contact::forces::pair_forces;
use crate::io::svg::{line_plot, Series};
use crate::solver::contact_newton::FINITE_RESIDUAL_TOLERANCE;
use serde::Serialize;
use serde_json::{json, Value};

/// The slab's Young's modulus and the die's, and Poisson's ratio of both.
pub const E_SLAB: f64 = 1.0;
pub const E_DIE: f64 = 10.0;
pub const NU: f64 = 0.3;
/// The slab `[0, SLAB_LENGTH] x [0, SLAB_THICKNESS]`.
pub const SLAB_LENGTH: f64 = 6.0;
pub const SLAB_THICKNESS: f64 = 1.0;
/// The die: radius of its bottom arc, half-width, height of its top above the touch point, and
/// the abscissa of the touch point.
pub const DIE_RADIUS: f64 = 1.0;
pub const DIE_HALF_WIDTH: f64 = 0.6;
pub const DIE_HEIGHT: f64 = 0.6;
pub const DIE_CENTRE: f64 = 1.2;
/// The press of the die's top, its load steps, the slide and its load steps.
pub const PRESS: f64 = 0.1;
pub const PRESS_STEPS: usize = 5;
pub const SLIDE: f64 = 3.0;
pub const SLIDE_STEPS: usize = 120;
/// Where the steady part of the path starts (slide).
pub const STEADY_FROM: f64 = 0.5;

/// One mesh level: slab cells `(n_x, n_y)` and die cells `(n_x, n_y)`.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Level {
    pub slab_cells: [usize; 2],
    pub die_cells: [usize; 2],
}

/// The refinement levels, h halving from one to the next.
pub const LEVELS: [Level; 3] = [
    Level {
        slab_cells: [12, 2],
        die_cells: [6, 2],
    },
    Level {
        slab_cells: [24, 4],
        die_cells: [12, 4],
    },
    Level {
        slab_cells: [48, 8],
        die_cells: [24, 8],
    },
];

/// One discretization of the study: a label, the pair's `discretization` and `enforcement`.
pub struct Entry {
    pub label: &'static str,
    pub discretization: Value,
    pub enforcement: Value,
}

/// The discretizations compared, all with Lagrange multipliers.
pub fn entries() -> Vec<Entry> {
    let lagrange = json!({"kind": "lagrange"});
    vec![
        Entry {
            label: "node-to-surface, master normals",
            discretization: json!({"kind": "node_to_surface", "passes": 1}),
            enforcement: lagrange.clone(),
        },
        Entry {
            label: "node-to-surface, slave normals",
            discretization: json!({"kind": "node_to_surface", "passes": 1, "normal": "slave"}),
            enforcement: lagrange.clone(),
        },
        Entry {
            label: "mortar, standard multipliers",
            discretization: json!({"kind": "mortar", "multiplier": "standard"}),
            enforcement: lagrange,
        },
    ]
}

/// The die's explicit Q4 mesh: nodes row by row from the arc (row 0) to the top, and the
/// cells counter-clockwise from their lower-left corner; the bottom facets are edge 0 of the
/// first row of cells.
pub fn die_mesh(n_x: usize, n_y: usize) -> (Vec<[f64; 2]>, Vec<Vec<usize>>) {
    let mut nodes = Vec::with_capacity((n_x + 1) * (n_y + 1));
    for j in 0..=n_y {
        for i in 0..=n_x {
            let s = DIE_HALF_WIDTH * (2.0 * i as f64 / n_x as f64 - 1.0);
            let bottom = SLAB_THICKNESS + DIE_RADIUS - (DIE_RADIUS * DIE_RADIUS - s * s).sqrt();
            let top = SLAB_THICKNESS + DIE_HEIGHT;
            let t = j as f64 / n_y as f64;
            nodes.push([DIE_CENTRE + s, bottom + (top - bottom) * t]);
        }
    }
    let id = |i: usize, j: usize| j * (n_x + 1) + i;
    let mut cells = Vec::with_capacity(n_x * n_y);
    for j in 0..n_y {
        for i in 0..n_x {
            cells.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    (nodes, cells)
}

/// The case of the study at `level` with the pair's `discretization` and `enforcement`.
pub fn case(level: &Level, discretization: &Value, enforcement: &Value) -> Value {
    let steps = PRESS_STEPS + SLIDE_STEPS;
    let press_path: Vec<f64> = (1..=steps)
        .map(|k| (k.min(PRESS_STEPS)) as f64 / PRESS_STEPS as f64)
        .collect();
    let slide_path: Vec<f64> = (1..=steps)
        .map(|k| k.saturating_sub(PRESS_STEPS) as f64 / SLIDE_STEPS as f64)
        .collect();
    let [sx, sy] = level.slab_cells;
    let slab_x: Vec<f64> = (0..=sx)
        .map(|i| SLAB_LENGTH * i as f64 / sx as f64)
        .collect();
    let slab_y: Vec<f64> = (0..=sy)
        .map(|j| SLAB_THICKNESS * j as f64 / sy as f64)
        .collect();
    let [dx, dy] = level.die_cells;
    let (nodes, cells) = die_mesh(dx, dy);
    let arc: Vec<[usize; 2]> = (0..dx).map(|c| [c, 0]).collect();
    let top = SLAB_THICKNESS + DIE_HEIGHT;
    json!({
        "name": "ironing",
        "description": "a stiff neo-Hookean die with a circular bottom pressed into a soft neo-Hookean slab and slid along it (src/harness/ironing.rs)",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {
            "slab": {"E": E_SLAB, "nu": NU, "model": "neo_hookean"},
            "die": {"E": E_DIE, "nu": NU, "model": "neo_hookean"}
        },
        "bodies": [
            {"name": "slab", "material": "slab", "mesh": {"block": {
                "element": "Q4", "x": slab_x, "y": slab_y}}},
            {"name": "die", "material": "die",
             "mesh": {"explicit": {"element": "Q4", "nodes": nodes, "cells": cells}},
             "node_sets": {"driven": {"box": {
                 "min": [DIE_CENTRE - DIE_HALF_WIDTH, top],
                 "max": [DIE_CENTRE + DIE_HALF_WIDTH, top]}}},
             "facet_sets": {"arc": {"facets": arc}}}
        ],
        "physics": {"kinematics": "finite", "contact_geometry": "current"},
        "solver": {"scheme": "newton", "load_steps": steps},
        "supports": [
            {"body": "slab", "set": "bottom", "x": 0.0, "y": 0.0},
            {"body": "die", "set": "driven", "y": -PRESS, "path": press_path},
            {"body": "die", "set": "driven", "x": SLIDE, "path": slide_path}
        ],
        "loads": [],
        "contact": [{
            "name": "ironing",
            "slave": {"body": "die", "set": "arc"},
            "master": {"body": "slab", "set": "top"},
            "discretization": discretization,
            "enforcement": enforcement
        }]
    })
}

/// One discretization at one level.
#[derive(Clone, Debug, Serialize)]
pub struct IroningRun {
    pub level: Level,
    /// `ran`, or `refused: <reason>`, or `failed: <reason>`.
    pub outcome: String,
    pub path: Vec<PathPoint>,
    /// Mean vertical force on the die over the steady part (negative: the slab pushes up on the
    /// die, `F_y > 0`; reported as it is).
    pub mean_vertical: f64,
    pub vertical: Option<Oscillation>,
    pub horizontal: Option<Oscillation>,
    /// Largest `|contact force + reaction|` relative to the largest contact force component.
    pub balance: f64,
    pub histories: Vec<StepResiduals>,
    pub quadratic_ratio: f64,
    pub quadratic_pairs: usize,
    /// The same over the pairs of iterations within a settled active set only (see
    /// [`settled_ratios`]).
    pub settled_quadratic_ratio: f64,
    pub settled_quadratic_pairs: usize,
    pub cuts: usize,
}

/// The difference of the forces between two successive levels.
#[derive(Clone, Debug, Serialize)]
pub struct RefinementDifference {
    /// The coarser level's index in [`LEVELS`].
    pub coarse: usize,
    /// `max |F_x,h - F_x,h/2|` and `max |F_y,h - F_y,h/2|` over the common steps, relative to
    /// the finer level's mean vertical force.
    pub horizontal: f64,
    pub vertical: f64,
    /// How many load steps were compared.
    pub compared: usize,
}

/// One discretization over every level.
#[derive(Clone, Debug, Serialize)]
pub struct IroningStudy {
    pub label: String,
    pub discretization: Value,
    pub enforcement: Value,
    pub runs: Vec<IroningRun>,
    pub differences: Vec<RefinementDifference>,
}

fn not_run(level: Level, outcome: String) -> IroningRun {
    IroningRun {
        level,
        outcome,
        path: Vec::new(),
        mean_vertical: f64::NAN,
        vertical: None,
        horizontal: None,
        balance: f64::NAN,
        histories: Vec::new(),
        quadratic_ratio: f64::NAN,
        quadratic_pairs: 0,
        settled_quadratic_ratio: f64::NAN,
        settled_quadratic_pairs: 0,
        cuts: 0,
    }
}

/// Run one discretization at one level.
pub fn run(entry: &Entry, level: Level) -> IroningRun {
    let model = match build(
        &case(&level, &entry.discretization, &entry.enforcement),
        "ironing",
    ) {
        Ok(m) => m,
        Err(e) => return not_run(level, format!("refused: {}", first_line(&e))),
    };
    let Some(die) = model.bodies.iter().position(|b| b.name == "die") else {
        return not_run(level, "failed: the case has no body named die".into());
    };
    let die_body = &model.bodies[die];
    let driven: Vec<usize> = (0..die_body.mesh.nodes.len())
        .flat_map(|n| [die_body.dof(n, 0), die_body.dof(n, 1)])
        .filter(|&d| model.prescribed[d].is_some())
        .collect();
    let steps = (PRESS_STEPS + SLIDE_STEPS) as f64;
    let mut residuals: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut settled: Vec<Vec<f64>> = Vec::new();
    let followed = follow(&model, |factor, solution| {
        let mut contact_force = [0.0; 2];
        let mut iterations = 0;
        let slide = SLIDE * ((factor * steps - PRESS_STEPS as f64) / SLIDE_STEPS as f64).max(0.0);
        if let Some(state) = solution.contact.as_ref() {
            let forces = &pair_forces(&model, state)[0];
            contact_force = if model.contact[forces.pair].slave.0 == die {
                forces.on_slave
            } else {
                forces.on_master
            };
            iterations = state.iterations;
            residuals.push((slide, state.history.iter().map(|h| h.residual).collect()));
            settled.push(settled_ratios(&state.history));
        }
        let mut reaction = [0.0; 2];
        for &d in &driven {
            reaction[d % 2] += solution.reactions[d];
        }
        PathPoint {
            load_factor: factor,
            slide,
            contact_force,
            reaction,
            iterations,
        }
    });
    match followed {
        Ok(path) => {
            let mut r = measured(level, path, residuals);
            let all: Vec<f64> = settled.into_iter().flatten().collect();
            r.settled_quadratic_pairs = all.len();
            r.settled_quadratic_ratio = all.into_iter().fold(0.0, f64::max);
            r
        }
        Err(e) => not_run(level, format!("failed: {}", first_line(&e))),
    }
}

/// The ratios `r_{k+1} / r_k^2` of one step's iterations (judged as
/// [`super::load_path::quadratic_ratio`] does) over the pairs where no contact row changed
/// status after iteration `k - 1` nor after iteration `k`: Newton's quadratic rate holds for
/// a smooth problem, and a row that opens or closes (the die's edges, where the contact zone
/// grows and shrinks at nearly every step) makes the iteration a semi-smooth one across the
/// change.
pub fn settled_ratios(history: &[crate::contact::state::IterationRecord]) -> Vec<f64> {
    let mut ratios = Vec::new();
    for k in 0..history.len().saturating_sub(1) {
        let steady_before = k == 0 || history[k - 1].status_changes == 0;
        if !(steady_before && history[k].status_changes == 0) {
            continue;
        }
        let pair = [history[k].residual, history[k + 1].residual];
        if quadratic_ratio(&pair, FINITE_RESIDUAL_TOLERANCE).0 == 1 {
            ratios.push(pair[1] / (pair[0] * pair[0]));
        }
    }
    ratios
}

/// The measures of a completed path ([`super::finite_sliding::path_measures`]).
fn measured(level: Level, path: Vec<PathPoint>, residuals: Vec<(f64, Vec<f64>)>) -> IroningRun {
    let m = path_measures(&path, &residuals, STEADY_FROM);
    IroningRun {
        level,
        outcome: "ran".into(),
        vertical: Some(m.normal),
        horizontal: Some(m.tangential),
        mean_vertical: m.mean_normal,
        balance: m.balance,
        histories: m.histories,
        quadratic_ratio: m.quadratic_ratio,
        quadratic_pairs: m.quadratic_pairs,
        settled_quadratic_ratio: f64::NAN,
        settled_quadratic_pairs: 0,
        cuts: path.len().saturating_sub(PRESS_STEPS + SLIDE_STEPS),
        path,
    }
}

/// The contact force of `run` at the load factor `factor`: the accepted step's force where a
/// step ends there (to 1e-9), else linear in the load factor between the two accepted steps
/// around it (a step cut in half moves the later steps off the nominal grid `k / steps`);
/// `None` outside the path.
pub fn force_at(run: &IroningRun, factor: f64) -> Option<[f64; 2]> {
    let path = &run.path;
    if let Some(p) = path.iter().find(|p| (p.load_factor - factor).abs() < 1e-9) {
        return Some(p.contact_force);
    }
    let w = path
        .windows(2)
        .find(|w| w[0].load_factor < factor && factor < w[1].load_factor)?;
    let t = (factor - w[0].load_factor) / (w[1].load_factor - w[0].load_factor);
    Some([0, 1].map(|i| (1.0 - t) * w[0].contact_force[i] + t * w[1].contact_force[i]))
}

/// The difference of the forces of two runs at the nominal load factors `k / steps`
/// ([`force_at`]), relative to the finer run's mean vertical force.
pub fn difference(
    coarse: &IroningRun,
    fine: &IroningRun,
    coarse_index: usize,
) -> RefinementDifference {
    let scale = fine.mean_vertical.abs().max(f64::MIN_POSITIVE);
    let steps = PRESS_STEPS + SLIDE_STEPS;
    let (mut horizontal, mut vertical, mut compared) = (0.0f64, 0.0f64, 0);
    for k in 1..=steps {
        let factor = k as f64 / steps as f64;
        if let (Some(p), Some(q)) = (force_at(coarse, factor), force_at(fine, factor)) {
            compared += 1;
            horizontal = horizontal.max((p[0] - q[0]).abs());
            vertical = vertical.max((p[1] - q[1]).abs());
        }
    }
    RefinementDifference {
        coarse: coarse_index,
        horizontal: horizontal / scale,
        vertical: vertical / scale,
        compared,
    }
}

/// One discretization over every level of [`LEVELS`].
pub fn study_of(entry: &Entry) -> IroningStudy {
    let runs: Vec<IroningRun> = LEVELS.iter().map(|&level| run(entry, level)).collect();
    let differences = runs
        .windows(2)
        .enumerate()
        .filter(|(_, w)| w[0].outcome == "ran" && w[1].outcome == "ran")
        .map(|(k, w)| difference(&w[0], &w[1], k))
        .collect();
    IroningStudy {
        label: entry.label.into(),
        discretization: entry.discretization.clone(),
        enforcement: entry.enforcement.clone(),
        runs,
        differences,
    }
}

/// Every entry of [`entries`] over every level.
pub fn study() -> Vec<IroningStudy> {
    entries().iter().map(study_of).collect()
}

fn level_name(level: &Level) -> String {
    format!(
        "slab {}x{}, die {}x{}",
        level.slab_cells[0], level.slab_cells[1], level.die_cells[0], level.die_cells[1]
    )
}

/// The Markdown report.
pub fn report(studies: &[IroningStudy]) -> String {
    let mut s = format!(
        "# The ironing problem at finite strain (frictionless)\n\n\
         Generated by `contact-patch ironing` (do not edit by hand); the problem and the measures \
         are described in `src/harness/ironing.rs`. A neo-Hookean die (E = {E_DIE}, circular \
         bottom of radius {DIE_RADIUS}, width {}) pressed by {PRESS} into a neo-Hookean slab \
         (E = {E_SLAB}, {SLAB_LENGTH} x {SLAB_THICKNESS}, clamped bottom; nu = {NU}, plane strain, \
         Q4) in {PRESS_STEPS} load steps, then slid by {SLIDE} in {SLIDE_STEPS} steps, \
         frictionless (the published ironing curves of Puso & Laursen 2004 and Yang, Laursen & \
         Meng 2005 are frictional, mu = 0.3, and are not a reference here: the reference is the \
         convergence under refinement). Forces are the net contact force on the die; the exact \
         horizontal force of a steady frictionless slide is zero.\n\n\
         ## Runs\n\n\
         | discretization | mesh | outcome | mean F_y (steady) | F_y oscillation: max deviation | F_x oscillation: max deviation | F_x peak-to-peak | balance with the reaction | cuts | largest r_k+1 / r_k^2 (pairs) | the same in a settled active set (pairs) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
        2.0 * DIE_HALF_WIDTH
    );
    for st in studies {
        for r in &st.runs {
            let osc = |o: &Option<Oscillation>, peak: bool| {
                o.as_ref().map_or("-".to_string(), |o| {
                    sci(if peak {
                        o.peak_to_peak
                    } else {
                        o.max_deviation
                    })
                })
            };
            s += &format!(
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                st.label,
                level_name(&r.level),
                r.outcome.replace('|', "/"),
                if r.mean_vertical.is_finite() {
                    format!("{:.5}", r.mean_vertical)
                } else {
                    "-".into()
                },
                osc(&r.vertical, false),
                osc(&r.horizontal, false),
                osc(&r.horizontal, true),
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
                },
                if r.settled_quadratic_pairs > 0 {
                    format!(
                        "{} ({})",
                        sci(r.settled_quadratic_ratio),
                        r.settled_quadratic_pairs
                    )
                } else {
                    "-".into()
                }
            );
        }
    }
    s += "\n## Differences between successive refinements\n\n\
          `max |F_h - F_h/2|` over the nominal load steps (linear between accepted steps where a step cut moved them), relative to the finer mesh's mean vertical \
          force; they shrink as the meshes converge.\n\n\
          | discretization | levels | F_y difference | F_x difference | steps compared |\n\
          |---|---|---|---|---|\n";
    for st in studies {
        for d in &st.differences {
            s += &format!(
                "| {} | {} -> {} | {} | {} | {} |\n",
                st.label,
                level_name(&LEVELS[d.coarse]),
                level_name(&LEVELS[d.coarse + 1]),
                sci(d.vertical),
                sci(d.horizontal),
                d.compared
            );
        }
    }
    s += "\n![forces on the die](ironing.svg)\n\n";
    s += "## Newton's residual histories (relative residual per iteration)\n\n\
          The first, the middle and the last sliding step on the finest mesh.\n\n\
          | discretization | slide | residuals |\n|---|---|---|\n";
    for st in studies {
        if let Some(r) = st.runs.last() {
            for h in &r.histories {
                let list: Vec<String> = h.residuals.iter().map(|v| format!("{v:.1e}")).collect();
                s += &format!("| {} | {:.2} | {} |\n", st.label, h.slide, list.join(", "));
            }
        }
    }
    s
}

/// The plot `(file name, SVG)`: the vertical and horizontal force on the die along the slide,
/// for the first discretization at every level and the others on the finest mesh.
pub fn plots(studies: &[IroningStudy]) -> Vec<(String, String)> {
    let mut series = Vec::new();
    for (k, st) in studies.iter().enumerate() {
        for (l, r) in st.runs.iter().enumerate() {
            if r.path.is_empty() || (k > 0 && l + 1 < st.runs.len()) {
                continue;
            }
            for (i, name) in [(1, "F_y"), (0, "F_x")] {
                series.push(Series {
                    name: format!(
                        "{name} {} h{}",
                        st.label
                            .replace("node-to-surface, ", "NTS ")
                            .replace(" normals", "")
                            .replace(" multipliers", ""),
                        l
                    ),
                    points: r
                        .path
                        .iter()
                        .filter(|p| p.slide > 0.0)
                        .map(|p| (p.slide, p.contact_force[i]))
                        .collect(),
                });
            }
        }
    }
    vec![(
        "ironing.svg".into(),
        line_plot("Contact force on the die", "slide", "force", &series),
    )]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_die_mesh_has_its_bottom_on_the_arc_and_counter_clockwise_cells() {
        let (nodes, cells) = die_mesh(6, 2);
        assert_eq!(nodes.len(), 21);
        assert_eq!(cells.len(), 12);
        let centre = [DIE_CENTRE, SLAB_THICKNESS + DIE_RADIUS];
        for n in &nodes[..7] {
            let r = ((n[0] - centre[0]).powi(2) + (n[1] - centre[1]).powi(2)).sqrt();
            assert!((r - DIE_RADIUS).abs() < 1e-14, "{n:?}: {r}");
        }
        // the touch point and the sides' drop 1 - sqrt(1 - 0.36) = 0.2
        assert!((nodes[3][1] - SLAB_THICKNESS).abs() < 1e-15);
        assert!((nodes[0][1] - SLAB_THICKNESS - 0.2).abs() < 1e-14);
        for c in &cells {
            // shoelace area of the quadrilateral: positive when counter-clockwise
            let area: f64 = (0..4)
                .map(|k| {
                    let (a, b) = (nodes[c[k]], nodes[c[(k + 1) % 4]]);
                    a[0] * b[1] - b[0] * a[1]
                })
                .sum::<f64>()
                / 2.0;
            assert!(area > 0.0, "{c:?}: {area}");
        }
    }

    #[test]
    fn the_case_presses_then_slides_the_die() {
        let v = case(
            &LEVELS[0],
            &json!({"kind": "node_to_surface", "passes": 1}),
            &json!({"kind": "lagrange"}),
        );
        let press: Vec<f64> = serde_json::from_value(v["supports"][1]["path"].clone()).unwrap();
        let slide: Vec<f64> = serde_json::from_value(v["supports"][2]["path"].clone()).unwrap();
        assert_eq!(press.len(), PRESS_STEPS + SLIDE_STEPS);
        assert_eq!(press[PRESS_STEPS - 1], 1.0);
        assert_eq!(*press.last().unwrap(), 1.0);
        assert_eq!(slide[PRESS_STEPS - 1], 0.0);
        assert_eq!(*slide.last().unwrap(), 1.0);
    }
}
