//! The seed's tied example, measured: a surface load on a layer tied to a base across a
//! non-matching interface (Taylor 2004, "2002-2004: Mortar Methods for Tied Surfaces"), solved
//! with a node-to-surface tie, a standard and a dual mortar tie, and meshed as one body with no
//! interface. Cases: `cases/tied-layer/` (Q4 and Q9). Each level `k` multiplies every uniform
//! division of both cases by `k`.
//!
//! Distances to the one-body solution at the same level, over two sample lines (the interface
//! `y = 4`, sampled just inside the layer, at 201 points; and the vertical `x = 1` through the
//! layer, 51 points):
//! `du = max |u_y - u_y,ref| / max |u_y,ref|` and `ds = max |sigma_yy - sigma_yy,ref| / p`.
//! Both meshes converge to the same continuum solution, so a consistent tie shows distances
//! that shrink under refinement.

use crate::error::{Error, Result};
use crate::io::scene::{Breaks, Case, DiscretizationSpec, MeshSpec, MultiplierSpace, NormalChoice};
use crate::io::svg::{line_plot, Series};
use crate::model::admit::admit;
use crate::model::{parse, Model};
use crate::post::CellLocator;
use crate::solver::linear::Solution;
use crate::solver::solve_static;
use serde::Serialize;
use std::path::Path;

/// The load on the layer top (the cases' pressure).
pub const PRESSURE: f64 = 1.0;

/// The tie variants compared with the one-body mesh.
pub fn variants() -> Vec<(&'static str, DiscretizationSpec)> {
    vec![
        (
            "node-to-surface",
            DiscretizationSpec::NodeToSurface {
                passes: 1,
                normal: NormalChoice::Master,
                slave_normal_variation: None,
            },
        ),
        (
            "mortar",
            DiscretizationSpec::Mortar {
                multiplier: MultiplierSpace::Standard,
            },
        ),
        (
            "dual mortar",
            DiscretizationSpec::Mortar {
                multiplier: MultiplierSpace::Dual,
            },
        ),
    ]
}

/// One solve of the study and its distance to the one-body solution.
#[derive(Clone, Debug, Serialize)]
pub struct LayerRun {
    pub element: String,
    pub level: usize,
    pub variant: String,
    pub dofs: usize,
    pub du: f64,
    pub ds: f64,
}

/// Curves along the sample lines: `(coordinate, u_y, sigma_yy)` per point.
#[derive(Clone, Debug)]
pub struct Lines {
    pub interface: Vec<(f64, f64, f64)>,
    pub through: Vec<(f64, f64, f64)>,
}

fn refine(case: &Case, k: usize) -> Case {
    let mut c = case.clone();
    for b in &mut c.bodies {
        if let MeshSpec::Block(block) = &mut b.mesh {
            for breaks in [&mut block.x, &mut block.y] {
                if let Breaks::Uniform(u) = breaks {
                    u.divisions = u.divisions.saturating_mul(k);
                }
            }
        }
    }
    c
}

fn load_case(path: &Path) -> Result<Case> {
    let source = path.display().to_string();
    let text =
        std::fs::read_to_string(path).map_err(|e| Error::io(&source, "reading the case", e))?;
    parse(&text, &source)
}

/// Sample the solution of the body named `body` on both lines.
fn lines(model: &Model, solution: &Solution, body: &str) -> Result<Lines> {
    let b = model.body(body).ok_or_else(|| {
        Error::invalid(
            &model.source,
            "bodies",
            format!("no body '{body}'"),
            "the tied-layer cases name their bodies 'layer' and 'body'",
        )
    })?;
    let locator = CellLocator::new(b);
    let at = |p: [f64; 2]| {
        locator.sample(&solution.u, p).ok_or_else(|| {
            Error::invalid(
                &model.source,
                format!("body '{body}'"),
                format!("the sample point ({}, {}) is outside the body", p[0], p[1]),
                "keep the tied-layer geometry",
            )
        })
    };
    let mut interface = Vec::new();
    for i in 0..=200 {
        let x = 10.0 * i as f64 / 200.0;
        let (u, s) = at([x, 4.0 + 1e-6])?;
        interface.push((x, u[1], s[1]));
    }
    let mut through = Vec::new();
    for i in 0..=50 {
        let y = 4.0 + 1e-6 + (1.0 - 2e-6) * i as f64 / 50.0;
        let (u, s) = at([1.0, y])?;
        through.push((y, u[1], s[1]));
    }
    Ok(Lines { interface, through })
}

fn distance(a: &Lines, reference: &Lines) -> (f64, f64) {
    let pairs = || {
        a.interface
            .iter()
            .zip(&reference.interface)
            .chain(a.through.iter().zip(&reference.through))
    };
    let umax = pairs().fold(0.0f64, |m, (_, r)| m.max(r.1.abs()));
    let du = pairs().fold(0.0f64, |m, (p, r)| m.max((p.1 - r.1).abs())) / umax;
    let ds = pairs().fold(0.0f64, |m, (p, r)| m.max((p.2 - r.2).abs())) / PRESSURE;
    (du, ds)
}

/// Everything the study produced for one element kind.
pub struct Study {
    pub runs: Vec<LayerRun>,
    /// Curves at `plot_level`: `(name, lines)`, the one-body solution first.
    pub curves: Vec<(String, Lines)>,
    /// Models and solutions at `plot_level` (for `.vtu` output): `(name, model, solution)`.
    pub solved: Vec<(String, Model, Solution)>,
}

/// Run the study for `element` ("q4" or "q9") at `levels`; curves and solutions are kept for
/// `plot_level`.
pub fn study(dir: &Path, element: &str, levels: &[usize], plot_level: usize) -> Result<Study> {
    let tied_path = dir.join(format!("tied-layer-{element}.json"));
    let one_path = dir.join(format!("one-body-layer-{element}.json"));
    let (tied, one) = (load_case(&tied_path)?, load_case(&one_path)?);
    let mut out = Study {
        runs: Vec::new(),
        curves: Vec::new(),
        solved: Vec::new(),
    };
    for &k in levels {
        let one_model = admit(Model::build(
            &refine(&one, k),
            &one_path.display().to_string(),
        )?)?;
        let one_solution = solve_static(&one_model, &mut |_| {})?;
        let reference = lines(&one_model, &one_solution, "body")?;
        out.runs.push(LayerRun {
            element: element.to_uppercase(),
            level: k,
            variant: "one body".into(),
            dofs: one_model.dof_count,
            du: 0.0,
            ds: 0.0,
        });
        if k == plot_level {
            out.curves.push(("one body".into(), reference.clone()));
            out.solved
                .push(("one-body".into(), one_model.clone(), one_solution.clone()));
        }
        let base = admit(Model::build(
            &refine(&tied, k),
            &tied_path.display().to_string(),
        )?)?;
        for (name, disc) in variants() {
            let mut model = base.clone();
            model.contact[0].discretization = disc;
            let solution = solve_static(&model, &mut |_| {})?;
            let l = lines(&model, &solution, "layer")?;
            let (du, ds) = distance(&l, &reference);
            out.runs.push(LayerRun {
                element: element.to_uppercase(),
                level: k,
                variant: name.into(),
                dofs: model.dof_count,
                du,
                ds,
            });
            if k == plot_level {
                out.curves.push((name.into(), l));
                out.solved.push((name.replace(' ', "-"), model, solution));
            }
        }
    }
    Ok(out)
}

/// SVG plots of the curves: `(file stem, svg)`.
pub fn plots(element: &str, level: usize, curves: &[(String, Lines)]) -> Vec<(String, String)> {
    let series = |f: &dyn Fn(&Lines) -> Vec<(f64, f64)>| -> Vec<Series> {
        curves
            .iter()
            .map(|(n, l)| Series {
                name: n.clone(),
                points: f(l),
            })
            .collect()
    };
    let e = element.to_uppercase();
    vec![
        (
            format!("tied-layer-{element}-uy-interface"),
            line_plot(
                &format!("{e}, level {level}: u_y along the interface y = 4"),
                "x",
                "u_y",
                &series(&|l| l.interface.iter().map(|p| (p.0, p.1)).collect()),
            ),
        ),
        (
            format!("tied-layer-{element}-syy-interface"),
            line_plot(
                &format!("{e}, level {level}: sigma_yy along the interface y = 4"),
                "x",
                "sigma_yy",
                &series(&|l| l.interface.iter().map(|p| (p.0, p.2)).collect()),
            ),
        ),
        (
            format!("tied-layer-{element}-syy-through"),
            line_plot(
                &format!("{e}, level {level}: sigma_yy through the layer at x = 1"),
                "y",
                "sigma_yy",
                &series(&|l| l.through.iter().map(|p| (p.0, p.2)).collect()),
            ),
        ),
    ]
}

/// The Markdown report.
pub fn report(
    studies: &[(String, Study)],
    levels: &[usize],
    plot_level: usize,
    files: &[String],
) -> String {
    let mut s =
        String::from("# The tied layer: node-to-surface and mortar ties against one body\n\n");
    s += "Generated by `contact-patch tied-layer` (do not edit by hand). The seed's tied example: a layer\n";
    s += "[0,10]x[4,5] tied to a base [0,10]x[0,4] across a non-matching interface, a surface load p = 1 on the\n";
    s += "layer top over x in [0,2], rollers on the sides, the base bottom fixed (`cases/tied-layer/`). The same\n";
    s += "geometry meshed as one body with no interface is the reference at each level (every division times\n";
    s += "the level). `du` = max |u_y - u_y,ref| / max |u_y,ref| and `ds` = max |sigma_yy - sigma_yy,ref| / p over\n";
    s += "the interface (just inside the layer, 201 points) and the vertical x = 1 through the layer (51 points).\n\n";
    for (element, study) in studies {
        s += &format!(
            "## {}\n\n| level | variant | dofs | du | ds |\n|---|---|---|---|---|\n",
            element.to_uppercase()
        );
        for r in &study.runs {
            s += &format!(
                "| {} | {} | {} | {:.2e} | {:.2e} |\n",
                r.level, r.variant, r.dofs, r.du, r.ds
            );
        }
        s += "\n";
        for (name, _) in variants() {
            let d: Vec<&LayerRun> = study.runs.iter().filter(|r| r.variant == name).collect();
            let shrinks = d.windows(2).all(|w| w[1].du < w[0].du && w[1].ds < w[0].ds);
            s += &format!(
                "- {name}: du {} and ds {} from level {} to {}: {}.\n",
                d.iter()
                    .map(|r| format!("{:.1e}", r.du))
                    .collect::<Vec<_>>()
                    .join(" -> "),
                d.iter()
                    .map(|r| format!("{:.1e}", r.ds))
                    .collect::<Vec<_>>()
                    .join(" -> "),
                levels.first().unwrap_or(&0),
                levels.last().unwrap_or(&0),
                if shrinks {
                    "both shrink at every refinement"
                } else {
                    "not monotone"
                }
            );
        }
        s += "\n";
    }
    s += &format!("## Plots (level {plot_level})\n\n");
    for f in files.iter().filter(|f| f.ends_with(".svg")) {
        s += &format!("![{f}]({f})\n\n");
    }
    s += "The `.vtu` files of the plotted level (one folder per variant, with `summary.json`) are in `tied-layer/`.\n";
    s
}
