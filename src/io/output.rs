//! Run output: `summary.json` and one VTK XML unstructured grid (`<body>.vtu`) per body (and,
//! for a time integration, the files of [`crate::io::timeline`]).
//!
//! The folder is an [`OutputFolder`]: written under a temporary name next to the target and
//! renamed into place only when every file is complete, so a folder named like the target is
//! always a whole run, and only a previous output is ever replaced (see [`crate::io::paths`]).
//! The `.vtu` files are ASCII VTK XML (version 0.1) with point data `displacement` (3
//! components, z = 0) and `stress` (`xx, yy, xy`, averaged at nodes), `stress_zz`, and cell
//! data `stress` at cell centres; VTK cell types 9 (Q4), 28 (Q9), 5 (T3), 22 (T6), whose node
//! orders match ours. A scene with contact adds the contact point data and the per-pair files
//! of [`crate::io::contact_output`] (`<pair>.contact.vtu`, `.csv`, `.json`); a scene without
//! contact writes exactly what it wrote before.
//!
//! **Reactions per support set** (`summary.json` `reactions`, [`ReactionSummary`]): with the
//! nodal reactions `r = K u - f` at the prescribed dofs, set `S` reports per component `c`
//!
//! ```text
//! R_S,c = sum of r_d over the dofs d = (node of S, c) that a support naming S prescribes
//!         and that no earlier support (in the case's order) prescribes
//! ```
//!
//! so every prescribed dof counts in exactly one set and the sets' reactions add up to the
//! total reaction. A node held in x by one set and in y by another gives each set its own
//! component; a dof held in the same component by two sets counts in the first, and the later
//! set lists it under `shared` (the component, the set that counts it, how many nodes). A
//! component a set does not hold reads 0 and is absent from its `held`.

use crate::contact::enforcement::method;
use crate::contact::forces::pair_forces;
use crate::contact::results::{pair_results, PairResults};
use crate::error::{Error, Result};
use crate::harness::checks::CheckResult;
use crate::io::contact_output::{body_point_arrays, write_pair_files};
use crate::io::paths::{file_name, OutputFolder};
use crate::io::vtu::{lines_in_parallel, PointArray};
use crate::model::Body;
use crate::post::{
    cell_stresses, nodal_stresses, pair_summaries, reaction_summaries, PairSummary, ReactionSummary,
};
use crate::run::Outcome;
use crate::solver::linear::Timings;
use serde::Serialize;
use std::io::{BufWriter, Write};
use std::path::Path;

#[derive(Serialize)]
pub struct Summary {
    pub case: String,
    pub source: String,
    pub description: String,
    pub passed: bool,
    pub dofs: usize,
    pub equations: usize,
    pub matrix_nonzeros: usize,
    pub relative_residual: f64,
    pub bodies: Vec<BodySummary>,
    pub reactions: Vec<ReactionSummary>,
    pub checks: Vec<CheckResult>,
    /// What the run says although no check failed (e.g. penetration beyond a share of the
    /// contact element size).
    pub warnings: Vec<String>,
    /// What the contact solve found (absent without contact).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact: Option<ContactSummary>,
    /// The conditioning and equilibrium of the answer (absent without contact), see
    /// [`crate::harness::stability`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub conditioning: Option<crate::harness::stability::Conditioning>,
    /// The load stepping of a finite-kinematics solve (every attempt, the cut ones with their
    /// reasons, and the Newton residuals); absent with small strain.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub finite: Option<crate::solver::history::FiniteHistory>,
    /// What the iterative linear solves did (`solver.linear_solver: "cg_amg"`: iterations,
    /// final relative residual, hierarchy); absent with the direct solver.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub linear_solver: Option<crate::solver::iterative::IterativeRecord>,
    pub timings: Timings,
    /// The effects the scene asked for and simulated, with the time each took.
    pub effects: Vec<EffectSummary>,
}

/// One simulated effect: what it was, and its time (phases that belong to it alone).
#[derive(Serialize)]
pub struct EffectSummary {
    pub effect: String,
    pub detail: String,
    /// Seconds and share of the total, where the effect has phases of its own.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seconds: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub share: Option<f64>,
}

/// The effects of `outcome`'s scene. Elasticity owns meshing and the element assembly; with
/// contact, the contact solve owns the search, the factorizations and the solves of its loop
/// (whose matrices hold the elastic stiffness too); without contact those belong to
/// elasticity. Current geometry and load steps are parts of the contact solve (no time of
/// their own).
fn effects(outcome: &Outcome) -> Vec<EffectSummary> {
    let (model, t) = (&outcome.model, &outcome.solution.timings);
    let share = |s: f64| (t.total > 0.0).then(|| s / t.total);
    let contact = outcome.solution.contact.as_ref();
    let elastic = t.mesh
        + t.assembly
        + if contact.is_none() {
            t.factorization + t.solve
        } else {
            0.0
        };
    let kinds: std::collections::BTreeSet<String> = model
        .bodies
        .iter()
        .map(|b| format!("{:?}", b.mesh.kind))
        .collect();
    let mut out = vec![EffectSummary {
        effect: "elasticity".into(),
        detail: format!(
            "{}, plane {:?}, {} bodies ({})",
            match &outcome.solution.finite {
                None => "small strain".to_string(),
                Some(h) => format!(
                    "finite deformation (total Lagrangian, hyperelastic), {} load steps, {} cut",
                    h.steps.len() - h.cuts,
                    h.cuts
                ),
            },
            model.plane,
            model.bodies.len(),
            kinds.into_iter().collect::<Vec<_>>().join(", ")
        )
        .to_lowercase(),
        seconds: Some(elastic),
        share: share(elastic),
    }];
    if let Some(c) = contact {
        let pairs: Vec<String> = model
            .contact
            .iter()
            .map(|p| {
                // in the case file's words
                let words = |v: serde_json::Value| v.to_string().replace('"', "");
                let halved = if p.penalty_share() < 1.0 {
                    ", two-pass penalty halved"
                } else {
                    ""
                };
                format!(
                    "'{}': {}, {}, {}{halved}",
                    p.name,
                    words(serde_json::json!(p.interaction)),
                    words(serde_json::json!(p.discretization)),
                    method(&p.enforcement).name()
                )
            })
            .collect();
        let seconds = t.contact_search + t.factorization + t.solve;
        out.push(EffectSummary {
            effect: "contact".into(),
            detail: pairs.join("; "),
            seconds: Some(seconds),
            share: share(seconds),
        });
        if c.configuration.is_some() {
            out.push(EffectSummary {
                effect: "current contact geometry".into(),
                detail: format!(
                    "{} geometry updates in the last load step",
                    c.geometry_updates
                ),
                seconds: None,
                share: None,
            });
        }
        if c.steps.len() > 1 {
            out.push(EffectSummary {
                effect: "load steps".into(),
                detail: format!("{} steps", c.steps.len()),
                seconds: None,
                share: None,
            });
        }
    }
    out
}

/// The contact solve in numbers (forces, pressures and penetrations from
/// [`crate::contact::forces`]).
#[derive(Serialize)]
pub struct ContactSummary {
    pub termination: String,
    pub iterations: usize,
    pub linear_solver: String,
    pub constraints: usize,
    pub active: usize,
    /// Multipliers the enforcement methods added to the linear system (Lagrange: one per
    /// active row; methods that eliminate or regularize them: none).
    pub multiplier_unknowns: usize,
    pub rank_deficiency: Option<usize>,
    /// Sum over the pairs of the force each pair puts on its slave body, `[x, y]`.
    pub total_force: [f64; 2],
    /// Largest nodal contact pressure `-f_a . n_a / A_a` of any pair.
    pub max_pressure: f64,
    /// Extent `[min, max]` of the active slave nodes along x and y.
    pub active_extent: [[f64; 2]; 2],
    /// Largest penetration (zero when nothing penetrates).
    pub max_penetration: f64,
    /// Largest penetration relative to the contact element size at the node.
    pub max_penetration_share: f64,
    /// Per pair.
    pub pairs: Vec<PairSummary>,
    /// The load steps: load factor, termination, iterations and geometry updates of each.
    pub steps: Vec<crate::solver::active_set::StepRecord>,
    /// Every iteration: residual, active rows, status changes, largest gap violation,
    /// multiplier change, linear solver, time.
    pub history: Vec<crate::solver::active_set::IterationRecord>,
}

#[derive(Serialize)]
pub struct BodySummary {
    pub name: String,
    pub element: String,
    pub material: String,
    pub nodes: usize,
    pub cells: usize,
    /// `[min, max]` of u_x, u_y and of the nodal stresses xx, yy, xy.
    pub u_x: [f64; 2],
    pub u_y: [f64; 2],
    pub stress_xx: [f64; 2],
    pub stress_yy: [f64; 2],
    pub stress_xy: [f64; 2],
}

fn range(values: impl Iterator<Item = f64>) -> [f64; 2] {
    values.fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], v| {
        [lo.min(v), hi.max(v)]
    })
}

pub fn summary(outcome: &Outcome, nodal: &[Vec<[f64; 3]>]) -> Summary {
    summary_with(outcome, nodal, &contact_results(outcome))
}

/// The per-point contact results of `outcome` (none without contact).
fn contact_results(outcome: &Outcome) -> Vec<PairResults> {
    outcome
        .solution
        .contact
        .as_ref()
        .map(|c| pair_results(&outcome.model, c, &outcome.solution.u))
        .unwrap_or_default()
}

/// [`summary`] with the contact results already computed.
fn summary_with(outcome: &Outcome, nodal: &[Vec<[f64; 3]>], results: &[PairResults]) -> Summary {
    let Outcome {
        model,
        solution,
        checks,
        ..
    } = outcome;
    let u = &solution.u;
    let bodies = model
        .bodies
        .iter()
        .zip(nodal)
        .map(|(b, s)| {
            let n = b.mesh.nodes.len();
            BodySummary {
                name: b.name.clone(),
                element: format!("{:?}", b.mesh.kind),
                material: b.material_name.clone(),
                nodes: n,
                cells: b.mesh.cell_count(),
                u_x: range((0..n).map(|k| u[b.dof(k, 0)])),
                u_y: range((0..n).map(|k| u[b.dof(k, 1)])),
                stress_xx: range(s.iter().map(|v| v[0])),
                stress_yy: range(s.iter().map(|v| v[1])),
                stress_xy: range(s.iter().map(|v| v[2])),
            }
        })
        .collect();
    let reactions = reaction_summaries(model, &solution.reactions);
    let contact = solution.contact.as_ref().map(|c| {
        let forces = pair_forces(model, c);
        let mut extent = [[f64::INFINITY, f64::NEG_INFINITY]; 2];
        for (r, _) in c.rows.iter().zip(&c.active).filter(|(_, &a)| a) {
            for k in 0..2 {
                extent[k][0] = extent[k][0].min(r.point[k]);
                extent[k][1] = extent[k][1].max(r.point[k]);
            }
        }
        let pairs = pair_summaries(model, c, &forces, results);
        let most = |get: fn(&PairSummary) -> f64| pairs.iter().map(get).fold(0.0, f64::max);
        ContactSummary {
            termination: match &c.termination {
                crate::solver::active_set::Termination::Singular(m) => format!("singular: {m}"),
                crate::solver::active_set::Termination::ActiveSetCycling(m) => {
                    format!("ActiveSetCycling: {m}")
                }
                crate::solver::active_set::Termination::WorkLimit(m) => {
                    format!("WorkLimit: {m}")
                }
                t => format!("{t:?}"),
            },
            iterations: c.iterations,
            linear_solver: c.linear_solver.to_string(),
            constraints: c.rows.len(),
            active: c.active.iter().filter(|&&a| a).count(),
            multiplier_unknowns: c
                .rows
                .iter()
                .zip(&c.active)
                .filter(|(_, &a)| a)
                .map(|(r, _)| method(&model.contact[r.pair].enforcement).unknowns_per_row(r))
                .sum(),
            rank_deficiency: c.rank_deficiency,
            total_force: pairs.iter().fold([0.0; 2], |t, p| {
                [t[0] + p.force_on_slave[0], t[1] + p.force_on_slave[1]]
            }),
            max_pressure: most(|p| p.max_pressure),
            active_extent: extent,
            max_penetration: most(|p| p.max_penetration),
            max_penetration_share: most(|p| p.max_penetration_share),
            pairs,
            steps: c.steps.clone(),
            history: c.history.clone(),
        }
    });
    Summary {
        contact,
        finite: solution.finite.as_deref().cloned(),
        case: model.name.clone(),
        source: model.source.clone(),
        description: model.description.clone(),
        passed: outcome.passed(),
        dofs: model.dof_count,
        equations: solution.equations,
        matrix_nonzeros: solution.matrix_nonzeros,
        relative_residual: solution.relative_residual,
        bodies,
        reactions,
        checks: checks.clone(),
        warnings: outcome.warnings.clone(),
        conditioning: solution
            .contact
            .as_ref()
            .map(|_| crate::harness::stability::conditioning(model, solution)),
        timings: solution.timings.clone(),
        linear_solver: solution.iterative.clone(),
        effects: effects(outcome),
    }
}

/// Write `summary.json` and one `.vtu` file per body into `folder` (replaced as a whole).
pub fn write_run(folder: &OutputFolder, outcome: &Outcome) -> Result<()> {
    let nodal: Vec<Vec<[f64; 3]>> = outcome
        .model
        .bodies
        .iter()
        .map(|b| nodal_stresses(b, &outcome.solution.u))
        .collect();
    let results = contact_results(outcome);
    let summary = summary_with(outcome, &nodal, &results);
    folder.write(|tmp| {
        let path = tmp.join("summary.json");
        let text = serde_json::to_string_pretty(&summary).expect("the summary serializes");
        crate::io::paths::write_new_file(&path, &(text + "\n"))?;
        for (k, (b, s)) in outcome.model.bodies.iter().zip(&nodal).enumerate() {
            let path = tmp.join(file_name("body name", &b.name, ".vtu")?);
            let contact = body_point_arrays(&outcome.model, k, &results);
            write_vtu_with(&path, b, &outcome.solution.u, s, &contact)?;
        }
        write_pair_files(tmp, &outcome.model, &results)?;
        if let Some(history) = &outcome.solution.dynamics {
            crate::io::timeline::write_history(tmp, &outcome.model, history, &|path, body, u| {
                write_vtu(path, body, u, &nodal_stresses(body, u))
            })?;
        }
        Ok(())
    })
}

/// One VTK XML unstructured grid for one body.
pub fn write_vtu(path: &Path, body: &Body, u: &[f64], nodal_stress: &[[f64; 3]]) -> Result<()> {
    write_vtu_with(path, body, u, nodal_stress, &[])
}

/// [`write_vtu`] with more point data (`extra`, e.g. the contact fields).
pub fn write_vtu_with(
    path: &Path,
    body: &Body,
    u: &[f64],
    nodal_stress: &[[f64; 3]],
    extra: &[PointArray],
) -> Result<()> {
    let io = |e| Error::io(path.display(), "writing", e);
    let file = crate::io::paths::create_new_file(path)?;
    let mut w = BufWriter::new(file);
    let mesh = &body.mesh;
    let cells = cell_stresses(body, u);
    let nn = mesh.kind.node_count();
    let mut text = String::new();
    use std::fmt::Write as _;
    let _ = writeln!(text, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        text,
        "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">"
    );
    let _ = writeln!(text, "<UnstructuredGrid>");
    let _ = writeln!(
        text,
        "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        mesh.nodes.len(),
        mesh.cell_count()
    );
    let _ = writeln!(
        text,
        "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">"
    );
    text += &lines_in_parallel(mesh.nodes.len(), |n, t| {
        let p = mesh.nodes[n];
        let _ = writeln!(t, "{} {} 0", p[0], p[1]);
    });
    let _ = writeln!(text, "</DataArray></Points>");
    let _ = writeln!(
        text,
        "<Cells><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">"
    );
    text += &lines_in_parallel(mesh.cell_count(), |c, t| {
        let ids: Vec<String> = mesh.cell(c).iter().map(|n| n.to_string()).collect();
        let _ = writeln!(t, "{}", ids.join(" "));
    });
    let _ = writeln!(
        text,
        "</DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">"
    );
    for c in 0..mesh.cell_count() {
        let _ = writeln!(text, "{}", (c + 1) * nn);
    }
    let _ = writeln!(
        text,
        "</DataArray><DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">"
    );
    for _ in 0..mesh.cell_count() {
        let _ = writeln!(text, "{}", mesh.kind.vtk_cell_type());
    }
    let _ = writeln!(text, "</DataArray></Cells>");
    let _ = writeln!(text, "<PointData Vectors=\"displacement\">");
    let _ = writeln!(text, "<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">");
    text += &lines_in_parallel(mesh.nodes.len(), |n, t| {
        let _ = writeln!(t, "{} {} 0", u[body.dof(n, 0)], u[body.dof(n, 1)]);
    });
    let _ = writeln!(text, "</DataArray>");
    let _ = writeln!(text, "<DataArray type=\"Float64\" Name=\"stress\" NumberOfComponents=\"3\" ComponentName0=\"xx\" ComponentName1=\"yy\" ComponentName2=\"xy\" format=\"ascii\">");
    text += &lines_in_parallel(nodal_stress.len(), |n, t| {
        let s = nodal_stress[n];
        let _ = writeln!(t, "{} {} {}", s[0], s[1], s[2]);
    });
    let _ = writeln!(text, "</DataArray>");
    let _ = writeln!(
        text,
        "<DataArray type=\"Float64\" Name=\"stress_zz\" format=\"ascii\">"
    );
    let stress_zz = crate::post::nodal_out_of_plane_stresses(body, u);
    text += &lines_in_parallel(stress_zz.len(), |n, t| {
        let _ = writeln!(t, "{}", stress_zz[n]);
    });
    if extra.is_empty() {
        let _ = writeln!(text, "</DataArray></PointData>");
    } else {
        let _ = writeln!(text, "</DataArray>");
        for a in extra {
            text += &a.xml();
        }
        let _ = writeln!(text, "</PointData>");
    }
    let _ = writeln!(text, "<CellData Tensors=\"\">");
    let _ = writeln!(text, "<DataArray type=\"Float64\" Name=\"stress\" NumberOfComponents=\"3\" ComponentName0=\"xx\" ComponentName1=\"yy\" ComponentName2=\"xy\" format=\"ascii\">");
    text += &lines_in_parallel(cells.len(), |c, t| {
        let s = cells[c];
        let _ = writeln!(t, "{} {} {}", s[0], s[1], s[2]);
    });
    let _ = writeln!(text, "</DataArray></CellData>");
    let _ = writeln!(text, "</Piece></UnstructuredGrid></VTKFile>");
    w.write_all(text.as_bytes()).map_err(io)?;
    w.flush().map_err(io)
}
