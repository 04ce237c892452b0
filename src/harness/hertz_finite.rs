//! Hertz at loads where geometric nonlinearity matters (issue 12): `contact-patch
//! hertz-finite` writes `reports/hertz-finite.{md,json}` and its plots.
//!
//! **Problem** (the setup of `cases/contact/block-on-rigid-cylinder-lagrange.json`): a block
//! `[-4, 4] x [0, 4]` (E = 200, nu = 0.3, plane strain, Q4 on a uniform mesh of size `h`)
//! pressed by a uniform pressure on its top (total force `P` per unit thickness, a dead load)
//! onto a rigid cylinder of radius `R = 10` touching it at the origin, pinned in x at the top
//! centre; frictionless node-to-surface rows with Lagrange multipliers, in the current
//! configuration (Newton, searched again at every iterate). Solved with small-strain linear
//! elasticity and with finite kinematics (compressible neo-Hookean, the same Lamé constants,
//! so that both laws agree to first order in the strain); the contact treatment is the same
//! in both, so the two differ only in the solid's kinematics and law.
//!
//! **Reference values** (not used as the truth at large load): Hertz's half-space solution of a
//! rigid cylinder, `a^2 = 4 P R / (pi E*)`, `p_0 = 2 P / (pi a)`, `E* = E / (1 - nu^2)`; the
//! contact strain scale is `a / R`.
//!
//! **Expected.** The finite-strain residual is the small-strain one plus terms quadratic in
//! the displacement gradient, so the two solutions differ by `O(|grad u|^2)`: relative to the
//! displacement, by `O(|grad u|)`, first order in the strain (second order in the load scale
//! of the displacement). Under Hertz contact the strain near the contact grows like
//! `a / R ~ P^(1/2)` and in the bulk like `P / (E w)`, so the relative difference of the
//! approach falls at least like `P^(1/2)` as the load falls. **Measured**, per load: the
//! approach (the downward displacement of the top centre), the contact half-width (the
//! outermost slave node carrying force, in the current configuration), the largest nodal
//! pressure, the net contact force (equal to `P` by balance); the relative difference of
//! the approach between the two kinematics; and, at the largest load, the finite-strain
//! approach on refined meshes with the differences between successive meshes.

use super::load_path::{build, follow};
use crate::contact::forces::pair_forces;
use crate::error::Result;
use crate::io::svg::{line_plot, Series};
use crate::model::Model;
use crate::solver::linear::Solution;
use serde::Serialize;
use serde_json::{json, Value};

const E: f64 = 200.0;
const NU: f64 = 0.3;
/// Radius of the rigid cylinder.
pub const RADIUS: f64 = 10.0;
/// Width and height of the block.
const WIDTH: f64 = 8.0;
const HEIGHT: f64 = 4.0;

/// The loads `P` of the sweep (total force per unit thickness), smallest first.
pub const LOADS: [f64; 8] = [0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0];

/// Hertz's half-width and peak pressure at the load `p`.
pub fn hertz(p: f64) -> (f64, f64) {
    let e_star = E / (1.0 - NU * NU);
    let a = (4.0 * p * RADIUS / (std::f64::consts::PI * e_star)).sqrt();
    (a, 2.0 * p / (std::f64::consts::PI * a))
}

/// The study's case at element size `h` under the loads `loads` (one per load step, a load
/// path), `finite` choosing the kinematics.
pub fn case(h: f64, loads: &[f64], finite: bool) -> Value {
    let largest = loads.iter().fold(0.0f64, |m, p| m.max(*p));
    let path: Vec<f64> = loads.iter().map(|p| p / largest).collect();
    let mut material = json!({"E": E, "nu": NU});
    let mut physics = json!({"contact_geometry": "current"});
    if finite {
        material["model"] = json!("neo_hookean");
        physics["kinematics"] = json!("finite");
    }
    json!({
        "name": "hertz-finite",
        "description": "a block pressed onto a rigid cylinder (src/harness/hertz_finite.rs)",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": material},
        "bodies": [{"name": "block", "material": "m",
            "mesh": {"block": {"element": "Q4",
                "x": {"from": -WIDTH / 2.0, "to": WIDTH / 2.0, "divisions": (WIDTH / h).round() as usize},
                "y": {"from": 0.0, "to": HEIGHT, "divisions": (HEIGHT / h).round() as usize}}},
            "node_sets": {"centre_top": {"point": [0.0, HEIGHT]}}}],
        "physics": physics,
        "solver": {"scheme": "newton", "load_steps": loads.len()},
        "supports": [{"body": "block", "set": "centre_top", "x": 0.0}],
        "loads": [{"body": "block", "set": "top", "pressure": largest / WIDTH, "path": path}],
        "contact": [{
            "name": "cylinder",
            "slave": {"body": "block", "set": "bottom"},
            "master": {"rigid": {"kind": "circle", "centre": [0.0, -RADIUS], "radius": RADIUS}},
            "discretization": {"kind": "node_to_surface", "passes": 1},
            "enforcement": {"kind": "lagrange"}
        }]
    })
}

/// What one solve measured at one load.
#[derive(Clone, Debug, Serialize)]
pub struct Measure {
    pub load: f64,
    /// Downward displacement of the top centre.
    pub approach: f64,
    /// Largest `|x|` of a slave node carrying force (current configuration).
    pub half_width: f64,
    /// Largest nodal contact pressure.
    pub peak_pressure: f64,
    /// Net vertical contact force on the block.
    pub contact_force: f64,
    /// Newton iterations of the step.
    pub iterations: usize,
}

fn measure(model: &Model, load: f64, solution: &Solution) -> Measure {
    let body = &model.bodies[0];
    let top = body
        .mesh
        .nodes
        .iter()
        .position(|p| p[0].abs() < 1e-12 && (p[1] - HEIGHT).abs() < 1e-12)
        .expect("a node at the top centre");
    let state = solution.contact.as_ref().expect("a contact solve");
    let forces = &pair_forces(model, state)[0];
    let carrying = forces
        .nodes
        .iter()
        .filter(|n| n.carries_rows && (n.force[0] != 0.0 || n.force[1] != 0.0));
    Measure {
        load,
        approach: -solution.u[body.dof(top, 1)],
        half_width: carrying.fold(0.0f64, |m, n| m.max(n.point[0].abs())),
        peak_pressure: forces.max_pressure(),
        contact_force: forces.on_slave[1],
        iterations: state.iterations,
    }
}

/// The finite-strain solve at element size `h` along `loads` (one load step each; a step
/// that needs cuts is measured where it ends): the measure at every load.
pub fn finite_path(h: f64, loads: &[f64]) -> Result<Vec<Measure>> {
    let model = build(&case(h, loads, true), "hertz-finite")?;
    let n = loads.len() as f64;
    let seen = follow(&model, |factor, solution| {
        let step = factor * n;
        let k = step.round();
        ((step - k).abs() < 1e-9).then(|| measure(&model, loads[k as usize - 1], solution))
    })?;
    Ok(seen.into_iter().flatten().collect())
}

/// The small-strain solve at element size `h` under the load `p` (one step: the small-strain
/// problem with contact has no path dependence without friction).
pub fn small_strain(h: f64, p: f64) -> Result<Measure> {
    let model = build(&case(h, &[p], false), "hertz-finite")?;
    let solution = crate::solver::solve_static(&model, &mut |_| {})?;
    Ok(measure(&model, p, &solution))
}

/// One load of the sweep.
#[derive(Clone, Debug, Serialize)]
pub struct LoadPoint {
    pub load: f64,
    pub hertz_half_width: f64,
    pub hertz_peak: f64,
    /// `a / R` of Hertz: the contact strain scale.
    pub strain_scale: f64,
    pub small: Measure,
    pub finite: Measure,
    /// `|approach_finite - approach_small| / approach_small`.
    pub relative_difference: f64,
    /// `log(d_k / d_{k-1}) / log(P_k / P_{k-1})` of the relative difference (none at the first).
    pub observed_order: Option<f64>,
}

/// One mesh of the refinement at the largest load.
#[derive(Clone, Debug, Serialize)]
pub struct RefinementPoint {
    pub h: f64,
    pub finite: Measure,
    /// `|approach_h - approach_{2h}|` relative to the approach (none on the first mesh).
    pub difference_to_coarser: Option<f64>,
}

/// The whole study.
#[derive(Clone, Debug, Serialize)]
pub struct HertzFinite {
    /// Element size of the load sweep.
    pub sweep_h: f64,
    pub loads: Vec<LoadPoint>,
    pub refinement_load: f64,
    pub refinement: Vec<RefinementPoint>,
}

/// The load sweep at element size `h` over `loads`.
pub fn sweep(h: f64, loads: &[f64]) -> Result<Vec<LoadPoint>> {
    let finite = finite_path(h, loads)?;
    let mut points: Vec<LoadPoint> = Vec::new();
    for f in finite {
        let small = small_strain(h, f.load)?;
        let (a, p0) = hertz(f.load);
        let relative_difference = (f.approach - small.approach).abs() / small.approach;
        let observed_order = points.last().map(|last| {
            (relative_difference / last.relative_difference).ln() / (f.load / last.load).ln()
        });
        points.push(LoadPoint {
            load: f.load,
            hertz_half_width: a,
            hertz_peak: p0,
            strain_scale: a / RADIUS,
            small,
            finite: f,
            relative_difference,
            observed_order,
        });
    }
    Ok(points)
}

/// The finite-strain solve at the load `p` on the meshes `sizes` (coarse to fine), each in the
/// load steps `steps` (a prefix of the sweep's loads ending at `p`).
pub fn refinement(sizes: &[f64], steps: &[f64]) -> Result<Vec<RefinementPoint>> {
    let mut points: Vec<RefinementPoint> = Vec::new();
    for &h in sizes {
        let finite = finite_path(h, steps)?
            .pop()
            .expect("a finite-strain path ends at its last load");
        let difference_to_coarser = points
            .last()
            .map(|c| (finite.approach - c.finite.approach).abs() / finite.approach);
        points.push(RefinementPoint {
            h,
            finite,
            difference_to_coarser,
        });
    }
    Ok(points)
}

/// The study of the report: the sweep on the mesh of size 0.1, the refinement at the largest
/// load on sizes 0.4, 0.2, 0.1 and 0.05.
pub fn study() -> Result<HertzFinite> {
    let sweep_h = 0.1;
    Ok(HertzFinite {
        sweep_h,
        loads: sweep(sweep_h, &LOADS)?,
        refinement_load: LOADS[LOADS.len() - 1],
        refinement: refinement(&[0.4, 0.2, 0.1, 0.05], &LOADS)?,
    })
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |v| format!("{v:.digits$}"))
}

/// The Markdown report.
pub fn report(s: &HertzFinite) -> String {
    let mut r = format!(
        "# Hertz at finite strain: a block on a rigid cylinder, small against finite strain\n\n\
         Generated by `contact-patch hertz-finite` (do not edit by hand); the problem and the \
         measures are described in `src/harness/hertz_finite.rs`. Block 8 x 4, E = {E}, nu = {NU} \
         (neo-Hookean at finite strain with the same Lamé constants), rigid cylinder R = {RADIUS}, \
         node-to-surface Lagrange rows in the current configuration for both kinematics, Q4, \
         element size {} for the load sweep. `approach`: downward displacement of the top \
         centre; `half-width`: outermost slave node carrying force; `peak`: largest nodal \
         pressure; Hertz's a and p0 are the small-strain half-space values. The order is \
         `log(d_k / d_k-1) / log(P_k / P_k-1)` of the relative difference d of the approach \
         (first order in the strain: at least 1/2 in P, since a / R ~ P^(1/2)).\n\n\
         | P | Hertz a | a / R | Hertz p0 | approach, small | approach, finite | relative difference | order | half-width small / finite | peak small / finite | contact force finite | Newton iterations finite |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n",
        s.sweep_h
    );
    for p in &s.loads {
        r += &format!(
            "| {} | {:.4} | {:.4} | {:.3} | {:.6e} | {:.6e} | {:.2e} | {} | {:.3} / {:.3} | {:.3} / {:.3} | {:.6} | {} |\n",
            p.load,
            p.hertz_half_width,
            p.strain_scale,
            p.hertz_peak,
            p.small.approach,
            p.finite.approach,
            p.relative_difference,
            opt(p.observed_order, 2),
            p.small.half_width,
            p.finite.half_width,
            p.small.peak_pressure,
            p.finite.peak_pressure,
            p.finite.contact_force,
            p.finite.iterations,
        );
    }
    r += &format!(
        "\n![approach](hertz-finite.approach.svg)\n\n![relative difference](hertz-finite.difference.svg)\n\n\
         ## Refinement of the finite-strain result at P = {}\n\n\
         | h | approach | difference to the coarser mesh (relative) | half-width | peak pressure | contact force |\n\
         |---|---|---|---|---|---|\n",
        s.refinement_load
    );
    for m in &s.refinement {
        r += &format!(
            "| {} | {:.6e} | {} | {:.3} | {:.3} | {:.6} |\n",
            m.h,
            m.finite.approach,
            m.difference_to_coarser
                .map_or("-".into(), |d| format!("{d:.2e}")),
            m.finite.half_width,
            m.finite.peak_pressure,
            m.finite.contact_force
        );
    }
    if let Some(last) = s.loads.last() {
        r += &format!(
            "\nAt P = {} the two kinematics differ by {:.2e} of the approach; the finest meshes \
             of the refinement differ by {} of it.\n",
            last.load,
            last.relative_difference,
            s.refinement
                .last()
                .and_then(|m| m.difference_to_coarser)
                .map_or("-".into(), |d| format!("{d:.2e}"))
        );
    }
    r
}

/// The plots: `(file name, SVG)`.
pub fn plots(s: &HertzFinite) -> Vec<(String, String)> {
    let approach = |pick: fn(&LoadPoint) -> f64| -> Vec<(f64, f64)> {
        s.loads.iter().map(|p| (p.load, pick(p))).collect()
    };
    vec![
        (
            "hertz-finite.approach.svg".into(),
            line_plot(
                "Approach of the top centre against the load",
                "P",
                "approach",
                &[
                    Series {
                        name: "small strain".into(),
                        points: approach(|p| p.small.approach),
                    },
                    Series {
                        name: "finite strain".into(),
                        points: approach(|p| p.finite.approach),
                    },
                ],
            ),
        ),
        (
            "hertz-finite.difference.svg".into(),
            line_plot(
                "Relative difference of the approach (log10)",
                "log10 P",
                "log10 difference",
                &[Series {
                    name: "finite vs small".into(),
                    points: s
                        .loads
                        .iter()
                        .map(|p| (p.load.log10(), p.relative_difference.log10()))
                        .collect(),
                }],
            ),
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::hertz;

    #[test]
    fn hertz_half_width_and_peak_match_the_existing_case() {
        // cases/contact/hertz-profile.json states a = 0.481383, p0 = 5.289923 at P = 4
        let (a, p0) = hertz(4.0);
        assert!((a - 0.481383).abs() < 1e-6, "{a}");
        assert!((p0 - 5.289923).abs() < 1e-6, "{p0}");
    }
}
