//! Hertz at loads where geometric nonlinearity matters (issue 12): `contact-patch
//! hertz-finite` writes `reports/hertz-finite.{md,json}` and its plots.
//!
//! **Problem** (the block and cylinder of `cases/contact/block-on-rigid-cylinder-lagrange.json`,
//! driven by displacement): a block `[-4, 4] x [0, 4]` (E = 200, nu = 0.3, plane strain, Q4
//! on a uniform mesh of size `h`) whose top is moved down by the approach `delta` (held in x
//! too: a flat rigid punch bonded to it) onto a rigid cylinder of radius `R = 10` touching it
//! at the origin; the load `P` is the contact force it takes (per unit thickness). The drive
//! keeps every Newton iterate held: under a dead pressure the finite-strain solve stopped at
//! its first iteration with a singular tangent (the block held by rows that opened, the step
//! cut to 1.2e-4 of the load in vain), and with the top free in x but at its centre the
//! finite-strain tangent turned singular near the approach 0.3 on the finest mesh (a zero
//! pivot in x at a top corner: the block rocking on the cylinder). Frictionless node-to-surface rows with Lagrange multipliers, in the current
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
//! the displacement gradient, so the two solutions differ by `O(|grad u|^2)`: the loads at a
//! given approach differ by a relative `O(|grad u|)`, first order in the strain, and by an
//! absolute amount of second order. At the smallest approaches only the nodes nearest the
//! first touch carry force: with that active set fixed the small-strain problem is linear in
//! `delta` and the difference of the loads is `O(delta^2)`, order 2 in `P`. Under Hertz contact
//! the strain near the contact grows like `a / R ~ P^(1/2)` and in the bulk like
//! `P / (E w)`; the two contributions need not have one sign. **Measured**, per
//! approach: the load `P` (the net contact force on the block, which balances the reaction
//! at its top), the contact half-width (the outermost slave node carrying force, in the
//! current configuration) and the largest nodal pressure; the relative difference of the
//! load between the two kinematics; and, at the largest approach, the finite-strain load on
//! refined meshes with the differences between successive meshes.

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

/// The approaches `delta` of the sweep (the top's downward displacement), smallest first.
pub const APPROACHES: [f64; 10] = [
    0.000625, 0.00125, 0.0025, 0.005, 0.01, 0.02, 0.04, 0.08, 0.16, 0.32,
];

/// Hertz's half-width and peak pressure at the load `p`.
pub fn hertz(p: f64) -> (f64, f64) {
    let e_star = E / (1.0 - NU * NU);
    let a = (4.0 * p * RADIUS / (std::f64::consts::PI * e_star)).sqrt();
    (a, 2.0 * p / (std::f64::consts::PI * a))
}

/// The study's case at element size `h` driven through the approaches `approaches` (one per
/// load step, a load path), `finite` choosing the kinematics.
pub fn case(h: f64, approaches: &[f64], finite: bool) -> Value {
    let largest = approaches.iter().fold(0.0f64, |m, d| m.max(*d));
    let path: Vec<f64> = approaches.iter().map(|d| d / largest).collect();
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
                "y": {"from": 0.0, "to": HEIGHT, "divisions": (HEIGHT / h).round() as usize}}}}],
        "physics": physics,
        "solver": {"scheme": "newton", "load_steps": approaches.len()},
        "supports": [
            {"body": "block", "set": "top", "x": 0.0},
            {"body": "block", "set": "top", "y": -largest, "path": path}
        ],
        "loads": [],
        "contact": [{
            "name": "cylinder",
            "slave": {"body": "block", "set": "bottom"},
            "master": {"rigid": {"kind": "circle", "centre": [0.0, -RADIUS], "radius": RADIUS}},
            "discretization": {"kind": "node_to_surface", "passes": 1},
            "enforcement": {"kind": "lagrange"}
        }]
    })
}

/// What one solve measured at one approach.
#[derive(Clone, Debug, Serialize)]
pub struct Measure {
    pub approach: f64,
    /// The load: the net vertical contact force on the block.
    pub load: f64,
    /// The reaction at the driven top, summed (balances the load).
    pub top_reaction: f64,
    /// Largest `|x|` of a slave node carrying force (current configuration), and how many
    /// slave nodes carry force.
    pub half_width: f64,
    pub closed_nodes: usize,
    /// Largest nodal contact pressure.
    pub peak_pressure: f64,
    /// Newton iterations of the step.
    pub iterations: usize,
}

fn measure(model: &Model, approach: f64, solution: &Solution) -> Measure {
    let body = &model.bodies[0];
    let top_reaction = (0..body.mesh.nodes.len())
        .filter(|&n| (body.mesh.nodes[n][1] - HEIGHT).abs() < 1e-12)
        .map(|n| solution.reactions[body.dof(n, 1)])
        .sum();
    let state = solution.contact.as_ref().expect("a contact solve");
    let forces = &pair_forces(model, state)[0];
    let carrying: Vec<_> = forces
        .nodes
        .iter()
        .filter(|n| n.carries_rows && (n.force[0] != 0.0 || n.force[1] != 0.0))
        .collect();
    Measure {
        approach,
        load: forces.on_slave[1],
        top_reaction,
        half_width: carrying.iter().fold(0.0f64, |m, n| m.max(n.point[0].abs())),
        closed_nodes: carrying.len(),
        peak_pressure: forces.max_pressure(),
        iterations: state.iterations,
    }
}

/// The finite-strain solve at element size `h` through `approaches` (one load step each; a
/// step that needs cuts is measured where it ends): the measure at every approach.
pub fn finite_path(h: f64, approaches: &[f64]) -> Result<Vec<Measure>> {
    let model = build(&case(h, approaches, true), "hertz-finite")?;
    let n = approaches.len() as f64;
    let seen = follow(&model, |factor, solution| {
        let step = factor * n;
        let k = step.round();
        ((step - k).abs() < 1e-9).then(|| measure(&model, approaches[k as usize - 1], solution))
    })?;
    Ok(seen.into_iter().flatten().collect())
}

/// The small-strain solve at element size `h` at the approach `delta` (one step: without
/// friction the small-strain problem has no path dependence).
pub fn small_strain(h: f64, delta: f64) -> Result<Measure> {
    let model = build(&case(h, &[delta], false), "hertz-finite")?;
    let solution = crate::solver::solve_static(&model, &mut |_| {})?;
    Ok(measure(&model, delta, &solution))
}

/// One approach of the sweep.
#[derive(Clone, Debug, Serialize)]
pub struct SweepPoint {
    pub approach: f64,
    /// Hertz's half-width and peak pressure at the small-strain load, and `a / R`.
    pub hertz_half_width: f64,
    pub hertz_peak: f64,
    pub strain_scale: f64,
    pub small: Measure,
    pub finite: Measure,
    /// `P_finite - P_small`, and relative to `P_small`.
    pub difference: f64,
    pub relative_difference: f64,
    /// `log(|D_k| / |D_k-1|) / log(P_k / P_k-1)` of the difference `D` against the small-strain
    /// load (none at the first): 2 for a difference of second order.
    pub observed_order: Option<f64>,
}

/// One mesh of the refinement at the largest approach.
#[derive(Clone, Debug, Serialize)]
pub struct RefinementPoint {
    pub h: f64,
    pub finite: Measure,
    /// `|P_h - P_2h| / P_h` (none on the first mesh).
    pub difference_to_coarser: Option<f64>,
}

/// The whole study.
#[derive(Clone, Debug, Serialize)]
pub struct HertzFinite {
    /// Element size of the sweep.
    pub sweep_h: f64,
    pub sweep: Vec<SweepPoint>,
    pub refinement_approach: f64,
    pub refinement: Vec<RefinementPoint>,
}

/// The sweep at element size `h` over `approaches`.
pub fn sweep(h: f64, approaches: &[f64]) -> Result<Vec<SweepPoint>> {
    let finite = finite_path(h, approaches)?;
    let mut points: Vec<SweepPoint> = Vec::new();
    for f in finite {
        let small = small_strain(h, f.approach)?;
        let (a, p0) = hertz(small.load);
        let difference = f.load - small.load;
        let relative_difference = difference / small.load;
        let observed_order = points.last().map(|last| {
            (difference / last.difference).abs().ln() / (small.load / last.small.load).ln()
        });
        points.push(SweepPoint {
            approach: f.approach,
            hertz_half_width: a,
            hertz_peak: p0,
            strain_scale: a / RADIUS,
            small,
            finite: f,
            difference,
            relative_difference,
            observed_order,
        });
    }
    Ok(points)
}

/// The finite-strain solve on the meshes `sizes` (coarse to fine), each through `approaches`,
/// measured at the last approach.
pub fn refinement(sizes: &[f64], approaches: &[f64]) -> Result<Vec<RefinementPoint>> {
    let mut points: Vec<RefinementPoint> = Vec::new();
    for &h in sizes {
        let finite = finite_path(h, approaches)?
            .pop()
            .expect("a finite-strain path ends at its last approach");
        let difference_to_coarser = points
            .last()
            .map(|c| (finite.load - c.finite.load).abs() / finite.load);
        points.push(RefinementPoint {
            h,
            finite,
            difference_to_coarser,
        });
    }
    Ok(points)
}

/// The study of the report: the sweep on the mesh of size 0.1, the refinement at the largest
/// approach on sizes 0.4, 0.2, 0.1 and 0.05.
pub fn study() -> Result<HertzFinite> {
    let sweep_h = 0.1;
    Ok(HertzFinite {
        sweep_h,
        sweep: sweep(sweep_h, &APPROACHES)?,
        refinement_approach: APPROACHES[APPROACHES.len() - 1],
        refinement: refinement(&[0.4, 0.2, 0.1, 0.05], &APPROACHES)?,
    })
}

fn opt(v: Option<f64>) -> String {
    v.map_or("-".into(), |v| format!("{v:.2}"))
}

/// The Markdown report.
pub fn report(s: &HertzFinite) -> String {
    let mut r = format!(
        "# Hertz at finite strain: a block on a rigid cylinder, small against finite strain\n\n\
         Generated by `contact-patch hertz-finite` (do not edit by hand); the problem and the \
         measures are described in `src/harness/hertz_finite.rs`. Block 8 x 4, E = {E}, nu = {NU} \
         (neo-Hookean at finite strain with the same Lamé constants), its top moved down by the \
         approach (and held in x), rigid cylinder R = {RADIUS}, node-to-surface Lagrange rows in the current \
         configuration for both kinematics, Q4, element size {} for the sweep. `P`: the net \
         contact force (the load); `half-width`: outermost slave node carrying force; `peak`: \
         largest nodal pressure; Hertz's a, a / R and p0 are the half-space values at the \
         small-strain load. `difference`: P finite - P small; `order`: `log(|D_k| / |D_k-1|) / \
         log(P_k / P_k-1)` of that difference D against the small-strain load (2: second order). \
         `balance`: largest |P + top reaction| / P.\n\n\
         | approach | P small | P finite | difference | relative difference | order | Hertz a | a / R | Hertz p0 | half-width small / finite | peak small / finite | Newton iterations finite |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n",
        s.sweep_h
    );
    let mut balance = 0.0f64;
    for p in &s.sweep {
        for m in [&p.small, &p.finite] {
            balance = balance.max((m.load + m.top_reaction).abs() / m.load);
        }
        r += &format!(
            "| {} | {:.6e} | {:.6e} | {:.3e} | {:.2e} | {} | {:.4} | {:.4} | {:.3} | {:.3} / {:.3} | {:.3} / {:.3} | {} |\n",
            p.approach,
            p.small.load,
            p.finite.load,
            p.difference,
            p.relative_difference,
            opt(p.observed_order),
            p.hertz_half_width,
            p.strain_scale,
            p.hertz_peak,
            p.small.half_width,
            p.finite.half_width,
            p.small.peak_pressure,
            p.finite.peak_pressure,
            p.finite.iterations,
        );
    }
    r += &format!(
        "\nbalance: {balance:.1e}\n\n![load](hertz-finite.load.svg)\n\n![relative difference](hertz-finite.difference.svg)\n\n\
         ## Refinement of the finite-strain result at the approach {}\n\n\
         | h | P | difference to the coarser mesh (relative) | half-width | peak pressure |\n\
         |---|---|---|---|---|\n",
        s.refinement_approach
    );
    for m in &s.refinement {
        r += &format!(
            "| {} | {:.6} | {} | {:.3} | {:.3} |\n",
            m.h,
            m.finite.load,
            m.difference_to_coarser
                .map_or("-".into(), |d| format!("{d:.2e}")),
            m.finite.half_width,
            m.finite.peak_pressure,
        );
    }
    if let (Some(last), Some(finest)) = (
        s.sweep.last(),
        s.refinement.last().and_then(|m| m.difference_to_coarser),
    ) {
        r += &format!(
            "\nAt the approach {} the two kinematics differ by {:.2e} of the load; the two finest \
             meshes of the refinement differ by {finest:.2e} of it.\n",
            last.approach,
            last.relative_difference.abs(),
        );
    }
    r
}

/// The plots: `(file name, SVG)`.
pub fn plots(s: &HertzFinite) -> Vec<(String, String)> {
    let load = |pick: fn(&SweepPoint) -> f64| -> Vec<(f64, f64)> {
        s.sweep.iter().map(|p| (p.approach, pick(p))).collect()
    };
    vec![
        (
            "hertz-finite.load.svg".into(),
            line_plot(
                "Load against the approach of the top",
                "approach",
                "P",
                &[
                    Series {
                        name: "small strain".into(),
                        points: load(|p| p.small.load),
                    },
                    Series {
                        name: "finite strain".into(),
                        points: load(|p| p.finite.load),
                    },
                ],
            ),
        ),
        (
            "hertz-finite.difference.svg".into(),
            line_plot(
                "Difference of the loads, finite - small strain (log10 of its size)",
                "log10 P (small strain)",
                "log10 |difference|",
                &[
                    Series {
                        name: "|P finite - P small|".into(),
                        points: s
                            .sweep
                            .iter()
                            .map(|p| (p.small.load.log10(), p.difference.abs().log10()))
                            .collect(),
                    },
                    Series {
                        name: "relative".into(),
                        points: s
                            .sweep
                            .iter()
                            .map(|p| (p.small.load.log10(), p.relative_difference.abs().log10()))
                            .collect(),
                    },
                ],
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
