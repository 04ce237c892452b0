//! Judging another code's results with a case's checks (`contact-patch judge`).
//!
//! Another code solves the exported case (`contact-patch export`) on the same meshes and writes
//! a `.vtu` file with the point field `displacement` (and, where it has them, `stress`). Each
//! node of each body is matched to the result point within `delta = share * L` of it (`L` the
//! model size, [`DEFAULT_MATCH_SHARE`] by default); a node with no point that close, or with
//! two points that close carrying different displacements (the two sides of an interface in
//! one file), is an error that names the node. The matched displacements give the global
//! vector `u`, and the case's checks are judged by [`crate::harness::checks::evaluate`] on
//! the solution they define:
//!
//! * `uniform_stress`, `exact_displacement`, `displacement`: from `u` with our element
//!   kinematics (the same mesh and element family give the same strain field);
//! * `reaction`: `r = K u - f` at the support's prescribed dofs with our stiffness `K` and
//!   consistent loads `f` (the nodal reactions of `u` on this mesh);
//! * a results `stress` field (`xx, yy, xy`; or a 2x2 or 3x3 tensor, row by row) adds, for each
//!   `uniform_stress` check, `max_nodes max_i |s_i - sigma_i| / scale` with the check's scale;
//! * the contact checks (`contact_pressure`, `contact_force`, `max_contact_pressure`,
//!   `max_penetration`, `force_balance`) need the contact forces of the solve and are listed as
//!   not judged, with that reason.
//!
//! `table --results DIR` makes one table cell per swept case from the results in `DIR`
//! ([`outside_cells`]): its verdict is the sweep's stress criterion,
//! `max_qp max_i |sigma_i(u) - sigma_exact,i| / p <= tol` (the contact patch test's uniform
//! stress), the other columns of a cell being contact quantities that results do not carry.

use crate::error::{Error, Result};
use crate::harness::checks::{evaluate, CheckResult, Magnitudes};
use crate::io::paths::file_name;
use crate::io::scene::Check;
use crate::io::vtu_read::{read_vtu, PointField, PointGrid};
use crate::model::Model;
use crate::solver::linear::{for_each_element_stiffness, Solution, Timings};
use std::collections::HashMap;
use std::path::Path;

/// Default node-matching distance, relative to the model size.
pub const DEFAULT_MATCH_SHARE: f64 = 1e-8;

/// The point field names read.
pub const DISPLACEMENT_FIELD: &str = "displacement";
pub const STRESS_FIELD: &str = "stress";
pub const CONTACT_PRESSURE_FIELD: &str = "contact_pressure";

/// One results file.
#[derive(Clone, Debug)]
pub struct ResultsFile {
    pub shown: String,
    pub grid: PointGrid,
}

/// Another code's results: one file for every body, or one file per body.
#[derive(Clone, Debug)]
pub enum Results {
    Shared(ResultsFile),
    /// In the order of the model's bodies.
    PerBody(Vec<ResultsFile>),
}

impl Results {
    fn of_body(&self, b: usize) -> &ResultsFile {
        match self {
            Results::Shared(f) => f,
            Results::PerBody(files) => &files[b],
        }
    }

    fn files(&self) -> Vec<&ResultsFile> {
        match self {
            Results::Shared(f) => vec![f],
            Results::PerBody(files) => files.iter().collect(),
        }
    }
}

/// Read the results at `path`: a `.vtu` file (for every body), or a folder with `<body>.vtu`
/// for each body of `model` (the layout `contact-patch run` writes).
pub fn load_results(model: &Model, path: &Path) -> Result<Results> {
    if path.is_dir() {
        let mut files = Vec::new();
        for body in &model.bodies {
            let file = path.join(file_name("body name", &body.name, ".vtu")?);
            if !file.is_file() {
                return Err(Error::invalid(
                    path.display(),
                    format!("body '{}'", body.name),
                    format!("the folder holds no {}", file.display()),
                    "a results folder holds one <body name>.vtu per body of the case; or give \
                     one .vtu file that holds every body",
                ));
            }
            files.push(ResultsFile {
                shown: file.display().to_string(),
                grid: read_vtu(&file)?,
            });
        }
        Ok(Results::PerBody(files))
    } else if path.is_file() {
        Ok(Results::Shared(ResultsFile {
            shown: path.display().to_string(),
            grid: read_vtu(path)?,
        }))
    } else {
        Err(Error::invalid(
            path.display(),
            "results",
            "no such file or folder",
            "give a .vtu file, or a folder with one <body name>.vtu per body",
        ))
    }
}

/// A check that could not be judged, and why.
#[derive(Clone, Debug, serde::Serialize)]
pub struct NotJudged {
    /// The check as the case file states it.
    pub check: String,
    pub why: String,
}

/// Whether the results hold a field, and what it was used for.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FieldUse {
    pub field: String,
    pub found: bool,
    pub use_: String,
}

/// What `judge` found.
#[derive(Clone, Debug)]
pub struct Judgement {
    /// Judged checks, in the case's order (then the results-stress checks).
    pub checks: Vec<CheckResult>,
    pub not_judged: Vec<NotJudged>,
    pub fields: Vec<FieldUse>,
    /// Nodes matched, the largest node-to-point distance, and the matching distance.
    pub nodes: usize,
    pub largest_distance: f64,
    pub match_distance: f64,
    /// The solution the results define (`u`, `K u - f`).
    pub solution: Solution,
}

impl Judgement {
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| c.passed)
    }
}

/// Why a check cannot be judged from point results, or `None` when it can.
fn unjudgeable(check: &Check) -> Option<&'static str> {
    match check {
        Check::UniformStress { .. }
        | Check::ExactDisplacement { .. }
        | Check::Reaction { .. }
        | Check::Displacement { .. } => None,
        Check::ContactPressure { .. }
        | Check::ContactForce { .. }
        | Check::MaxContactPressure { .. }
        | Check::MaxPenetration { .. }
        | Check::ForceBalance { .. } => Some(
            "it is judged from the contact forces and gaps of the solve's contact rows, which \
             point results do not carry (a 'contact_pressure' field is not read for it yet)",
        ),
        Check::TerminatesWith { .. }
        | Check::Equilibrium { .. }
        | Check::StatusChanges { .. }
        | Check::Warns { .. } => Some(
            "it is a check of how our own solve ran (its termination, conditioning, status \
             changes or warnings), which another code's results do not describe",
        ),
    }
}

/// Points of a grid hashed into square cells of side `h`, to find the points near a node.
struct PointIndex<'a> {
    grid: &'a PointGrid,
    h: f64,
    cells: HashMap<(i64, i64), Vec<usize>>,
}

impl<'a> PointIndex<'a> {
    fn new(grid: &'a PointGrid, h: f64) -> Self {
        let mut cells: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
        for (k, p) in grid.points.iter().enumerate() {
            cells
                .entry(((p[0] / h).floor() as i64, (p[1] / h).floor() as i64))
                .or_default()
                .push(k);
        }
        PointIndex { grid, h, cells }
    }

    /// Points within `h` of `x` (in the plane; z is ignored), nearest first.
    fn near(&self, x: [f64; 2]) -> Vec<(usize, f64)> {
        let (i, j) = (
            (x[0] / self.h).floor() as i64,
            (x[1] / self.h).floor() as i64,
        );
        let mut found = Vec::new();
        for di in -1..=1 {
            for dj in -1..=1 {
                for &k in self.cells.get(&(i + di, j + dj)).into_iter().flatten() {
                    let p = self.grid.points[k];
                    let d = (p[0] - x[0]).hypot(p[1] - x[1]);
                    if d <= self.h {
                        found.push((k, d));
                    }
                }
            }
        }
        found.sort_by(|a, b| a.1.total_cmp(&b.1));
        found
    }

    fn nearest(&self, x: [f64; 2]) -> Option<(usize, f64)> {
        self.grid
            .points
            .iter()
            .enumerate()
            .map(|(k, p)| (k, (p[0] - x[0]).hypot(p[1] - x[1])))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }
}

/// A named point field with at least `min_components` components, or `None` when absent.
fn field<'a>(
    file: &'a ResultsFile,
    name: &str,
    min_components: usize,
) -> Result<Option<&'a PointField>> {
    let Some(f) = file.grid.fields.get(name) else {
        return Ok(None);
    };
    if f.components < min_components {
        return Err(Error::invalid(
            &file.shown,
            format!("point field '{name}'"),
            format!(
                "{} components per point (at least {min_components} expected)",
                f.components
            ),
            "write displacement as a 2- or 3-component vector (x, y[, 0])",
        ));
    }
    if let Some(k) = f.values.iter().position(|v| !v.is_finite()) {
        return Err(Error::invalid(
            &file.shown,
            format!("point field '{name}'"),
            format!(
                "value {} of point {} is {}",
                k % f.components + 1,
                k / f.components,
                f.values[k]
            ),
            "the results hold a non-finite number; the other code's solve failed",
        ));
    }
    Ok(Some(f))
}

/// `xx, yy, xy` of a stress field value: 3 components as they are, 4 as a 2x2 and 9 as a 3x3
/// tensor row by row, which must be symmetric (within `1e-10` of its largest entry): a 2x2
/// tensor padded to 9 values as `xx, xy, yx, yy, 0, ..` (DOLFINx's VTK output) is not a 3x3
/// one and is refused rather than misread.
fn stress_of(v: &[f64]) -> std::result::Result<[f64; 3], String> {
    let largest = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let same = |a: f64, b: f64| (a - b).abs() <= 1e-10 * largest;
    match v.len() {
        3 => Ok([v[0], v[1], v[2]]),
        4 if same(v[1], v[2]) => Ok([v[0], v[3], v[1]]),
        9 if same(v[1], v[3]) && same(v[2], v[6]) && same(v[5], v[7]) => Ok([v[0], v[4], v[1]]),
        4 | 9 => Err(format!(
            "{} components {v:?} are not a symmetric {} tensor row by row",
            v.len(),
            if v.len() == 4 { "2x2" } else { "3x3" }
        )),
        n => Err(format!("{n} components per point")),
    }
}

/// Judge `results` with the checks of `model`; nodes are matched within
/// `match_share * model.size()`.
pub fn judge(model: &Model, results: &Results, match_share: f64) -> Result<Judgement> {
    if !(match_share.is_finite() && match_share > 0.0 && match_share < 1.0) {
        return Err(Error::invalid(
            &model.source,
            "--match-tol",
            format!("{match_share} is not a share of the model size in (0, 1)"),
            "give e.g. --match-tol 1e-8 (the default)",
        ));
    }
    if model.dynamics.is_some() {
        return Err(Error::invalid(
            &model.source,
            "physics.dynamics",
            "a dynamic case's checks concern its whole time history, which one .vtu of point \
             results does not hold",
            "judge a static case (export and judge cover the static catalogue)",
        ));
    }
    let delta = match_share * model.size();
    let mut u = vec![0.0; model.dof_count];
    // per body: the matched point of each node
    let mut matched: Vec<Vec<usize>> = Vec::new();
    let mut largest_distance = 0.0f64;
    let mut indexes: HashMap<usize, PointIndex> = HashMap::new();
    for (b, body) in model.bodies.iter().enumerate() {
        let file = results.of_body(b);
        let slot = match results {
            Results::Shared(_) => 0,
            Results::PerBody(_) => b,
        };
        let index = indexes
            .entry(slot)
            .or_insert_with(|| PointIndex::new(&file.grid, delta));
        let displacement = field(file, DISPLACEMENT_FIELD, 2)?.ok_or_else(|| {
            Error::invalid(
                &file.shown,
                "point data",
                format!(
                    "no point field '{DISPLACEMENT_FIELD}' (the file has: {})",
                    if file.grid.fields.is_empty() {
                        "no point fields".to_string()
                    } else {
                        file.grid
                            .fields
                            .keys()
                            .cloned()
                            .collect::<Vec<_>>()
                            .join(", ")
                    }
                ),
                "write the displacement as point data named 'displacement' (DOLFINx: \
                 u.name = \"displacement\" before VTKFile.write_function)",
            )
        })?;
        let mut points = Vec::with_capacity(body.mesh.nodes.len());
        for (n, &x) in body.mesh.nodes.iter().enumerate() {
            let near = index.near(x);
            let Some(&(k, d)) = near.first() else {
                let nearest = index
                    .nearest(x)
                    .map(|(k, d)| {
                        let p = file.grid.points[k];
                        format!(
                            "the nearest is point {k} at ({}, {}), {d:.3e} away",
                            p[0], p[1]
                        )
                    })
                    .unwrap_or_else(|| "the file has no points".into());
                return Err(Error::invalid(
                    &file.shown,
                    format!("node {n} of body '{}' at ({}, {})", body.name, x[0], x[1]),
                    format!("no result point within {delta:.3e} of the node; {nearest}"),
                    "solve on the exported mesh (contact-patch export) and write results at \
                     its nodes; or raise --match-tol (a share of the model size)",
                ));
            };
            let value = displacement.at(k);
            let scale = value[0].abs().max(value[1].abs()).max(f64::MIN_POSITIVE);
            if let Some(&(other, _)) = near[1..].iter().find(|&&(j, _)| {
                let w = displacement.at(j);
                (w[0] - value[0]).abs().max((w[1] - value[1]).abs()) > 1e-12 * scale
            }) {
                return Err(Error::invalid(
                    &file.shown,
                    format!("node {n} of body '{}' at ({}, {})", body.name, x[0], x[1]),
                    format!(
                        "points {k} and {other} are both within {delta:.3e} of the node and \
                         carry different displacements (two bodies meet here)"
                    ),
                    "write one .vtu per body, named <body name>.vtu, into a folder and give the \
                     folder",
                ));
            }
            largest_distance = largest_distance.max(d);
            u[body.dof(n, 0)] = value[0];
            u[body.dof(n, 1)] = value[1];
            points.push(k);
        }
        matched.push(points);
    }
    let solution = solution_of(model, u);
    let (judgeable, skipped): (Vec<Check>, Vec<Check>) = model
        .checks
        .iter()
        .cloned()
        .partition(|c| unjudgeable(c).is_none());
    let mut judged_model = model.clone();
    judged_model.checks = judgeable;
    let mut checks = evaluate(&judged_model, &solution);
    let not_judged = skipped
        .iter()
        .map(|c| NotJudged {
            check: serde_json::to_string(c).expect("checks serialize"),
            why: unjudgeable(c).unwrap_or_default().to_string(),
        })
        .collect();
    // the results' own stress field
    let files = results.files();
    let mut stress_found = !files.is_empty();
    for f in &files {
        stress_found &= field(f, STRESS_FIELD, 3)?.is_some();
    }
    if stress_found {
        let magnitudes = Magnitudes::of(model, &solution);
        for check in &model.checks {
            // another code's answer has no condition estimate here: per_condition is not used
            let Check::UniformStress {
                body, stress, tol, ..
            } = check
            else {
                continue;
            };
            let largest = stress.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let scale = if largest > 0.0 {
                largest
            } else {
                magnitudes.stress
            }
            .max(f64::MIN_POSITIVE);
            let mut error = 0.0f64;
            for (b, m) in model.bodies.iter().enumerate() {
                if body.as_ref().is_some_and(|name| *name != m.name) {
                    continue;
                }
                let file = results.of_body(b);
                let s = field(file, STRESS_FIELD, 3)?.expect("found above");
                for &k in &matched[b] {
                    let v = stress_of(s.at(k)).map_err(|why| {
                        Error::invalid(
                            &file.shown,
                            format!("point field '{STRESS_FIELD}' at point {k}"),
                            why,
                            "write stress as xx, yy, xy (3 components) or as a symmetric 2x2 or \
                             3x3 tensor (4 or 9, row by row); DOLFINx pads a 2x2 tensor to 9 \
                             values in another order: write a 3-vector (xx, yy, xy) instead",
                        )
                    })?;
                    for i in 0..3 {
                        let e = (v[i] - stress[i]).abs() / scale;
                        if e.is_nan() || e > error {
                            error = e;
                        }
                    }
                }
            }
            let on = body
                .as_deref()
                .map(|b| format!(" in body '{b}'"))
                .unwrap_or_default();
            checks.push(CheckResult {
                check: format!(
                    "uniform stress {stress:?}{on} in the results' own nodal 'stress' field"
                ),
                error,
                tol: *tol,
                passed: error <= *tol,
            });
        }
    }
    let pressure_found = files
        .iter()
        .all(|f| f.grid.fields.contains_key(CONTACT_PRESSURE_FIELD));
    let fields = vec![
        FieldUse {
            field: DISPLACEMENT_FIELD.into(),
            found: true,
            use_: "every judged check of the case".into(),
        },
        FieldUse {
            field: STRESS_FIELD.into(),
            found: stress_found,
            use_: if stress_found {
                "a uniform-stress check of the results' own nodal stress".into()
            } else {
                "missing: stresses are judged from the displacement only".into()
            },
        },
        FieldUse {
            field: CONTACT_PRESSURE_FIELD.into(),
            found: pressure_found,
            use_: "not read: the contact checks are not judged".into(),
        },
    ];
    Ok(Judgement {
        checks,
        not_judged,
        fields,
        nodes: matched.iter().map(Vec::len).sum(),
        largest_distance,
        match_distance: delta,
        solution,
    })
}

/// The solution `u` defines: `K u - f` at every dof (reactions at the prescribed ones), and the
/// largest free-dof residual relative to the largest external force or reaction.
fn solution_of(model: &Model, u: Vec<f64>) -> Solution {
    let mut r: Vec<f64> = model.external_force.iter().map(|f| -f).collect();
    for_each_element_stiffness(model, |dofs, ke| {
        let n = dofs.len();
        for i in 0..n {
            let mut s = 0.0;
            for j in 0..n {
                s += ke[i * n + j] * u[dofs[j]];
            }
            r[dofs[i]] += s;
        }
    });
    let free = |d: &usize| model.prescribed[*d].is_none();
    let dofs = 0..model.dof_count;
    let largest_free = dofs
        .clone()
        .filter(free)
        .fold(0.0f64, |m, d| m.max(r[d].abs()));
    let scale = dofs
        .map(|d| {
            if model.prescribed[d].is_some() {
                r[d].abs()
            } else {
                model.external_force[d].abs()
            }
        })
        .fold(0.0f64, f64::max)
        .max(f64::MIN_POSITIVE);
    Solution {
        u,
        reactions: r,
        equations: 0,
        matrix_nonzeros: 0,
        relative_residual: largest_free / scale,
        timings: Timings::default(),
        contact: None,
        dynamics: None,
    }
}

/// The results of case `name` in `dir`: `<name>.vtu`, or the folder `<name>/` with one
/// `<body>.vtu` per body; `None` when neither exists.
pub fn results_in(dir: &Path, name: &str) -> Result<Option<std::path::PathBuf>> {
    let file = dir.join(file_name("case name", name, ".vtu")?);
    let folder = dir.join(file_name("case name", name, "")?);
    Ok(if file.is_file() {
        Some(file)
    } else if folder.is_dir() {
        Some(folder)
    } else {
        None
    })
}

/// One table cell for the swept case at `case_file` from another code's results in `dir`
/// (see [`results_in`]), named `code` in the enforcement column; no cell for a case without
/// a sweep. A case without results is an `n/a` cell that says so.
pub fn outside_cells(
    case_file: &Path,
    dir: &Path,
    code: &str,
    match_share: f64,
) -> Result<Vec<crate::harness::Cell>> {
    let model = crate::model::admit::load(case_file)?;
    let Some(sweep) = model.sweep.clone() else {
        return Ok(Vec::new());
    };
    let mut cell = crate::harness::Cell {
        nu: model.bodies[0].material.nu,
        discretization: "outside".into(),
        enforcement: code.to_string(),
        pressure: sweep.pressure,
        ..crate::harness::Cell::unmeasured(
            sweep.catalogue,
            model.name.clone(),
            sweep.mesh.clone(),
            sweep.tol,
        )
    };
    let Some(path) = results_in(dir, &model.name)? else {
        cell.note = format!(
            "no results: neither {0}/{1}.vtu nor {0}/{1}/ exists",
            dir.display(),
            model.name
        );
        return Ok(vec![cell]);
    };
    let results = load_results(&model, &path)?;
    let judged = judge(&model, &results, match_share)?;
    let e = crate::harness::stress_error(&model, &judged.solution.u, sweep.pressure);
    cell.stress_error = Some(e);
    cell.verdict = if e <= sweep.tol { "pass" } else { "fail" }.into();
    cell.note = format!(
        "{}: judged on the stress of its displacement; contact forces are not in the results",
        path.display()
    );
    Ok(vec![cell])
}

#[cfg(test)]
mod tests {
    use super::stress_of;

    #[test]
    fn stress_layouts_are_read_or_refused() {
        assert_eq!(stress_of(&[3.0, -10.0, 2.0]), Ok([3.0, -10.0, 2.0]));
        assert_eq!(stress_of(&[3.0, 2.0, 2.0, -10.0]), Ok([3.0, -10.0, 2.0]));
        let full = [3.0, 2.0, 0.0, 2.0, -10.0, 0.0, 0.0, 0.0, 1.5];
        assert_eq!(stress_of(&full), Ok([3.0, -10.0, 2.0]));
        // DOLFINx's padding of a 2x2 tensor
        let padded = [3.0, 2.0, 2.0, -10.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let e = stress_of(&padded).unwrap_err();
        assert!(e.contains("not a symmetric 3x3 tensor"), "{e}");
        assert!(stress_of(&[1.0, 2.0]).unwrap_err().contains("2 components"));
    }
}
