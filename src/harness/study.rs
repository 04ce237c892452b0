//! Studies (`contact-patch study STUDY.json`): a base case run over the cartesian grid of a few
//! axes, each cell measured against the case's own references, so that accuracy can be set
//! against what it costs in time.
//!
//! A study is data ([`StudySpec`]): a base case file; axes, each setting one or more fields of
//! the case file (dotted paths such as `contact.0.enforcement.kappa`, array indices as numbers)
//! to each of its values, or refining every block mesh (`refine: k` splits every interval of
//! every block axis into `k` equal ones, the tied-layer study's levels); the metrics; a limit on
//! the grid's size. Axes apply in their order, so a later axis may overwrite a field an earlier
//! one set (a method, then its penalty). Before anything runs, each value of each axis is
//! applied after the first value of every earlier axis and the case read: a path the base does
//! not have, a field the case format does not know or drops, or a value it refuses is an error
//! naming the axis and the value. The grid's cell `i` is the mixed-radix number of its
//! axis values, the last axis fastest: a cell's index depends only on the study file, which
//! shards rely on ([`crate::harness::shard`]).
//!
//! A 3D base case (a body with a 3D mesh, [`crate::run3d::is_3d`]) runs in 3D: each cell is
//! built by [`crate::run3d::build3`] and solved by the same [`run_model`]; `refine` splits the
//! x, y and z breaks of `block3d` meshes. The Hertz metrics read a 2D contact line and are
//! refused for a 3D base ([`StudyDimension`]).
//!
//! Metrics, each against a reference that is not our own output:
//! * `checks`: the case's declared checks (closed forms, loads); the worst `error / tol`.
//! * `check`: one declared check's error (as the check measures it).
//! * Hertz (half-space, rigid cylinder; Johnson, *Contact Mechanics*, 1985, sec. 4.3, the
//!   closed form of `harness::exact`): with `P` the pair's normal force, `a` and `p0`
//!   from `P`, `R` and `E*`: `hertz_peak = |max_a p_a - p0| / p0`, `hertz_half_width =
//!   |s_max - a| / a` (`s_max` the outermost closed slave point), `hertz_profile = max |p_a -
//!   p(s_a)| / p0` over `|s_a| <= 0.8 a` (as `contact-patch profile` measures it).
//!
//! Every cell also records its dofs, the contact iterations and termination, the last
//! condition estimate (Hager-Higham, [`crate::solver::conditioning`]), the phase times of
//! `summary.json` and the peak resident memory of the run (Linux: `VmHWM` of
//! `/proc/self/status` after resetting it through `/proc/self/clear_refs`; absent elsewhere).
//! The reset sets the peak to the resident size at the cell's start, which includes what the
//! allocator kept from earlier cells, so a small cell after a large one shows the large one's
//! leftover: the figure bounds the cell's peak from above.
//!
//! Derived (from the cells, never written by hand):
//! * the Pareto front of every error metric against total time: the cells that no other cell
//!   beats in both (`t' <= t`, `e' <= e`, one strictly);
//! * a window along one axis (`window`): per combination of the other axes, the values where
//!   the run converged, every declared check passed, the iterations and the condition estimate
//!   stayed within the study's bounds; the longest run of consecutive such values is the
//!   recommended window and the first value outside it on either side is where the method
//!   breaks down, with the reason.

use crate::error::{Error, Result};
use crate::harness::checks::CheckVerdict;
use crate::io::scene::{Breaks, Case, MeshSpec};
use crate::io::svg::{line_plot, Series};
use crate::model::admit::admit;
use crate::model::{parse, Model};
use crate::run::{run_model, Outcome};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The grid size a study may ask for unless it states `max_cells`.
pub const DEFAULT_MAX_CELLS: usize = 1000;
/// The largest `max_cells` a study may state.
pub const MAX_CELLS_CEILING: usize = 100_000;
/// The largest refinement factor of a `refine` axis.
pub const MAX_REFINE: usize = 64;

/// A study file.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StudySpec {
    /// The JSON Schema the file follows, for editors; not read.
    #[serde(rename = "$schema", default, skip_serializing_if = "Option::is_none")]
    pub schema: Option<String>,
    /// The study's name: its reports are `<name>.md`, `<name>.json` and `<name>.*.svg`.
    pub name: String,
    #[serde(default)]
    pub description: String,
    /// The base case file, relative to the study file.
    pub base: PathBuf,
    /// The axes of the grid (at least one, none empty).
    pub axes: Vec<AxisSpec>,
    /// What is measured in every cell besides dofs, iterations, condition estimate, phase
    /// times and peak memory (always recorded).
    pub metrics: Vec<Metric>,
    /// The axis whose values a curve of the error-versus-time plots connects (default: the
    /// first `refine` axis, else the last axis).
    #[serde(default)]
    pub along: Option<String>,
    /// A recommended window along one axis (see the module).
    #[serde(default)]
    pub window: Option<WindowSpec>,
    /// The most cells the grid may have (default 1000, at most 100,000).
    #[serde(default)]
    pub max_cells: Option<usize>,
}

impl StudySpec {
    /// The number of cells of the grid (saturating).
    pub fn cell_count(&self) -> usize {
        self.axes
            .iter()
            .map(|a| a.values.len().max(a.refine.len()))
            .fold(1usize, |n, m| n.saturating_mul(m))
    }

    /// The number of cells of the grid, when it is within the study's `max_cells` (and that
    /// within [`MAX_CELLS_CEILING`]); `source` names the study in the refusal.
    pub fn checked_cells(&self, source: &str) -> Result<usize> {
        let cells = self.cell_count();
        let limit = self.max_cells.unwrap_or(DEFAULT_MAX_CELLS);
        if limit > MAX_CELLS_CEILING {
            return Err(refused(
                source,
                "max_cells",
                format!("{limit} is above the ceiling {MAX_CELLS_CEILING}"),
                "split the study into several files",
            ));
        }
        if cells > limit {
            return Err(refused(
                source,
                "axes",
                format!("the grid has {cells} cells, more than the limit {limit}"),
                "remove values, or raise `max_cells` in the study file (at most 100,000)",
            ));
        }
        Ok(cells)
    }
}

/// One axis: either `paths` with `values`, or `refine`.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AxisSpec {
    pub name: String,
    /// Dotted paths of case-file fields, e.g. `contact.0.enforcement` (array indices as
    /// numbers). With one path each value is that field's value; with several, each value is an
    /// array with one entry per path.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub paths: Vec<String>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub values: Vec<Value>,
    /// Labels of the values in tables and plots (default: the value as JSON, or its `kind`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub labels: Option<Vec<String>>,
    /// Multiplies every numeric value (e.g. `E / h`, so that the values are factors of it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
    /// Refinement factors: `k` splits every interval of every block mesh axis into `k`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub refine: Vec<usize>,
}

/// A measured quantity.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "metric", rename_all = "snake_case", deny_unknown_fields)]
pub enum Metric {
    /// The worst `error / tol` of the case's declared checks (at most 1: all pass).
    Checks,
    /// The error of the case's declared check number `index` (from 0).
    Check { index: usize },
    /// `|max p - p0| / p0` against Hertz for the pair (rigid circle master).
    HertzPeak { pair: String },
    /// `|s_max - a| / a` against Hertz's half-width.
    HertzHalfWidth { pair: String },
    /// `max |p - p_Hertz| / p0` over `|s| <= 0.8 a`.
    HertzProfile { pair: String },
}

impl Metric {
    /// The metric's column name.
    pub fn name(&self) -> String {
        match self {
            Metric::Checks => "checks".into(),
            Metric::Check { index } => format!("check{index}"),
            Metric::HertzPeak { .. } => "hertz_peak".into(),
            Metric::HertzHalfWidth { .. } => "hertz_half_width".into(),
            Metric::HertzProfile { .. } => "hertz_profile".into(),
        }
    }
}

/// The bounds of a recommended window along `axis`.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WindowSpec {
    pub axis: String,
    /// The most contact iterations of a cell inside the window.
    pub max_iterations: usize,
    /// The largest condition estimate of a cell inside the window.
    pub max_condition: f64,
}

/// The phase times of one cell, in seconds (as in `summary.json`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PhaseTimes {
    pub mesh: f64,
    pub assembly: f64,
    pub factorization: f64,
    pub solve: f64,
    pub contact_search: f64,
    pub total: f64,
}

/// One cell of a study.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyCell {
    /// The cell's place in the grid (the last axis fastest).
    pub index: usize,
    /// The label of each axis's value, in axis order.
    pub labels: Vec<String>,
    /// `None` when the cell could not run; `error` says why.
    pub dofs: Option<usize>,
    pub error: Option<String>,
    /// Every declared check passed.
    pub checks_passed: bool,
    /// The declared checks that failed: what each checks and its `error / tol`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub failed_checks: Vec<String>,
    /// The metrics, by name (a metric that could not be measured is absent).
    pub metrics: BTreeMap<String, f64>,
    pub iterations: Option<usize>,
    pub termination: Option<String>,
    pub condition_estimate: Option<f64>,
    pub times: PhaseTimes,
    /// Peak resident memory of the run in MB (Linux only).
    pub peak_memory_mb: Option<f64>,
}

/// A study read from its file, its axes checked, ready to run.
#[derive(Clone, Debug)]
pub struct Study {
    pub spec: StudySpec,
    /// The study file, as given.
    pub source: String,
    /// The base case file (resolved against the study file's folder).
    pub base_path: PathBuf,
    base: Value,
    /// The labels of each axis's values.
    pub labels: Vec<Vec<String>>,
}

fn refused(
    study: &str,
    location: impl std::fmt::Display,
    problem: impl std::fmt::Display,
    hint: impl std::fmt::Display,
) -> Error {
    Error::invalid(study, location, problem, hint)
}

/// Read a study file, its base case, and check every axis against the base case.
pub fn load_study(path: &Path) -> Result<Study> {
    let source = path.display().to_string();
    let text =
        std::fs::read_to_string(path).map_err(|e| Error::io(&source, "reading the study", e))?;
    crate::model::refuse_non_object(
        &text,
        &source,
        "study file",
        "the studies under cases/studies/",
    )?;
    let spec: StudySpec = serde_json::from_str(&text).map_err(|e| {
        refused(
            &source,
            format!("line {} column {}", e.line(), e.column()),
            e,
            "see `contact-patch study --schema` for the study format",
        )
    })?;
    let base_path = path.parent().unwrap_or(Path::new("")).join(&spec.base);
    let base_text = std::fs::read_to_string(&base_path)
        .map_err(|e| Error::io(base_path.display(), "reading the study's base case", e))?;
    // the base case must be a case as it stands
    parse(&base_text, &base_path.display().to_string())?;
    let base: Value = serde_json::from_str(&base_text).expect("parsed above");
    let study = Study {
        labels: Vec::new(),
        spec,
        source,
        base_path,
        base,
    };
    study.checked()
}

/// A study as its shards recorded it (for `merge`): the spec gets every check of a study file
/// that does not need the base case (errors name `shown`, the partial file it came from), the
/// labels come from the spec, and the base case is not read again (nothing is run).
pub fn from_parts(spec: StudySpec, source: String, shown: &str) -> Result<Study> {
    let base_path = Path::new(&source)
        .parent()
        .unwrap_or(Path::new(""))
        .join(&spec.base);
    let mut study = Study {
        spec,
        source,
        base_path,
        base: Value::Null,
        labels: Vec::new(),
    };
    study.check_spec(shown)?;
    study.labels = study
        .spec
        .axes
        .iter()
        .map(|a| {
            (0..a.values.len().max(a.refine.len()))
                .map(|j| label(a, j))
                .collect()
        })
        .collect();
    Ok(study)
}

impl Study {
    /// Cells recorded by a shard (read from the partial file `shown`) must be cells of this
    /// study: each cell's labels are the labels of its grid coordinates (so one per axis).
    pub fn check_recorded_cells(&self, cells: &[StudyCell], shown: &str) -> Result<()> {
        for (i, c) in cells.iter().enumerate() {
            let want: Vec<&String> = self
                .coordinates(c.index)
                .iter()
                .zip(&self.labels)
                .map(|(&j, l)| &l[j])
                .collect();
            let got: Vec<&String> = c.labels.iter().collect();
            if got != want {
                return Err(refused(
                    shown,
                    format!("cells[{i}].labels"),
                    format!(
                        "{got:?} are not the labels of cell {} of the study's grid, {want:?}",
                        c.index
                    ),
                    "give the files the shards wrote (`study --shard K/N`), unedited",
                ));
            }
        }
        Ok(())
    }

    /// The checks of the spec that need no base case (errors name `src`): a usable name, axes
    /// with values, labels and names, the grid within its limit, `along` and `window` naming
    /// axes.
    fn check_spec(&self, src: &str) -> Result<()> {
        let s = &self.spec;
        let src = src.to_string();
        if crate::io::paths::name_problem(&s.name).is_some() {
            crate::io::paths::file_name("study name", &s.name, "")?;
        }
        if s.axes.is_empty() {
            return Err(refused(
                &src,
                "axes",
                "the study has no axes",
                "give at least one axis, e.g. {\"name\": \"level\", \"refine\": [1, 2]}",
            ));
        }
        let mut names = std::collections::BTreeSet::new();
        for (k, a) in s.axes.iter().enumerate() {
            let at = format!("axes[{k}] '{}'", a.name);
            if !names.insert(a.name.clone()) {
                return Err(refused(
                    &src,
                    at,
                    "names an axis twice",
                    "give each axis its own name",
                ));
            }
            match (a.paths.is_empty(), a.refine.is_empty()) {
                (false, false) => return Err(refused(&src, at, "has both `paths` and `refine`", "an axis either sets fields (`paths` + `values`) or refines the meshes (`refine`)")),
                (true, true) => return Err(refused(&src, at, "is empty: no `paths` with `values` and no `refine` factors", "give the axis its values")),
                (false, true) if a.values.is_empty() => return Err(refused(&src, at, "has paths but no values", "list the values the fields take")),
                _ => {}
            }
            if a.refine.iter().any(|&f| f == 0 || f > MAX_REFINE) {
                return Err(refused(
                    &src,
                    at,
                    format!(
                        "refine factors must be from 1 to {MAX_REFINE}, got {:?}",
                        a.refine
                    ),
                    "e.g. \"refine\": [1, 2, 4, 8]",
                ));
            }
            if let Some(scale) = a.scale {
                if !(scale.is_finite() && scale > 0.0) {
                    return Err(refused(
                        &src,
                        at,
                        format!("scale {scale} is not a positive number"),
                        "e.g. the case's E / h",
                    ));
                }
            }
            let count = a.values.len().max(a.refine.len());
            if let Some(l) = &a.labels {
                if l.len() != count {
                    return Err(refused(
                        &src,
                        at,
                        format!("{} labels for {count} values", l.len()),
                        "give one label per value",
                    ));
                }
            }
        }
        s.checked_cells(&src)?;
        for name in s.along.iter().chain(s.window.as_ref().map(|w| &w.axis)) {
            if !names.contains(name) {
                return Err(refused(
                    &src,
                    "along / window.axis",
                    format!("names no axis: '{name}'"),
                    format!(
                        "name one of: {}",
                        names.iter().cloned().collect::<Vec<_>>().join(", ")
                    ),
                ));
            }
        }
        if let Some(w) = &s.window {
            if !(w.max_condition.is_finite() && w.max_condition >= 1.0) {
                return Err(refused(
                    &src,
                    "window.max_condition",
                    format!(
                        "{} is not a condition number (a finite number of at least 1)",
                        w.max_condition
                    ),
                    "e.g. 1e12",
                ));
            }
        }
        Ok(())
    }

    fn checked(mut self) -> Result<Study> {
        let src = self.source.clone();
        self.check_spec(&src)?;
        let s = &self.spec;
        // the Hertz metrics read a pressure profile along a 2D contact line
        let base_source = self.base_path.display().to_string();
        if let Ok(base) = parse(&self.base.to_string(), &base_source) {
            if crate::run3d::is_3d(&base, &base_source) {
                if let Some(k) = s.metrics.iter().position(|m| {
                    matches!(
                        m,
                        Metric::HertzPeak { .. }
                            | Metric::HertzHalfWidth { .. }
                            | Metric::HertzProfile { .. }
                    )
                }) {
                    return Err(refused(
                        &src,
                        format!("metrics[{k}]"),
                        format!(
                            "'{}' reads a pressure profile along a 2D contact line, and the base case is 3D",
                            s.metrics[k].name()
                        ),
                        "measure a 3D study by its checks: \"checks\" or {\"check\": N}",
                    ));
                }
            }
        }
        // every value of every axis, applied to the base after the first value of each
        // earlier axis (a later axis may set a field of an earlier one's value), must give a
        // case
        let mut labels = Vec::new();
        let mut prefix = self.base.clone();
        for (k, a) in s.axes.iter().enumerate() {
            let mut l = Vec::new();
            for j in 0..a.values.len().max(a.refine.len()) {
                if !a.paths.is_empty() {
                    let mut case = prefix.clone();
                    apply(&mut case, a, j).map_err(|why| refused(&src, format!("axes[{k}] '{}' value {j}", a.name), why, "paths are dotted case-file fields, e.g. contact.0.enforcement.kappa; see cases/case.schema.json"))?;
                    let text = serde_json::to_string_pretty(&case).expect("a JSON value");
                    let parsed = parse(
                        &text,
                        &format!(
                            "{} with axis '{}' value {j}",
                            self.base_path.display(),
                            a.name
                        ),
                    )
                    .map_err(|e| {
                        refused(
                            &src,
                            format!("axes[{k}] '{}' value {j}", a.name),
                            format!("the base case does not accept it: {e}"),
                            "check the path and the value against the case format",
                        )
                    })?;
                    // a field the case format ignores (e.g. a `kappa` on a method without one)
                    // does not survive reading the case: refused as unknown
                    let read_back = serde_json::to_value(&parsed).expect("a case serializes");
                    if let Some(path) = a.paths.iter().find(|p| get_path(&read_back, p).is_none()) {
                        return Err(refused(&src, format!("axes[{k}] '{}' value {j}", a.name), format!("unknown path '{path}': the case format has no such field here (it is dropped when the case is read)"), "check the path against the case format (cases/case.schema.json)"));
                    }
                }
                l.push(label(a, j));
            }
            if !a.paths.is_empty() {
                apply(&mut prefix, a, 0).map_err(|why| {
                    refused(
                        &src,
                        format!("axes[{k}] '{}'", a.name),
                        why,
                        "check the axis",
                    )
                })?;
            }
            labels.push(l);
        }
        self.labels = labels;
        Ok(self)
    }

    /// The number of cells of the grid.
    pub fn cell_count(&self) -> usize {
        self.spec.cell_count()
    }

    /// The value index of each axis of cell `index`.
    pub fn coordinates(&self, mut index: usize) -> Vec<usize> {
        let sizes: Vec<usize> = self
            .spec
            .axes
            .iter()
            .map(|a| a.values.len().max(a.refine.len()))
            .collect();
        let mut out = vec![0; sizes.len()];
        for k in (0..sizes.len()).rev() {
            out[k] = index % sizes[k];
            index /= sizes[k];
        }
        out
    }

    /// The case of cell `index` and the source its messages name.
    fn cell_case(&self, index: usize) -> Result<(Case, String)> {
        let coords = self.coordinates(index);
        let mut value = self.base.clone();
        let mut refine = 1usize;
        for (a, &j) in self.spec.axes.iter().zip(&coords) {
            if a.refine.is_empty() {
                apply(&mut value, a, j)
                    .map_err(|why| refused(&self.source, &a.name, why, "check the axis"))?;
            } else {
                refine = refine.saturating_mul(a.refine[j]);
            }
        }
        let source = format!(
            "{} [{}]",
            self.base_path.display(),
            self.cell_labels(index).join(", ")
        );
        let text = serde_json::to_string_pretty(&value).expect("a JSON value");
        let mut case = parse(&text, &source)?;
        if refine > 1 {
            refine_case(&mut case, refine);
        }
        Ok((case, source))
    }

    /// Build, solve and judge cell `index` in its case's dimension (3D when a body is 3D,
    /// [`crate::run3d::is_3d`]), measured into `cell`.
    fn solve_cell(&self, index: usize, start: Instant, cell: &mut StudyCell) -> Result<()> {
        let (case, source) = self.cell_case(index)?;
        if crate::run3d::is_3d(&case, &source) {
            let model = crate::run3d::build3(&case, &source)?;
            crate::model::admit::check_rigid_modes(&model)?;
            let mesh = start.elapsed().as_secs_f64();
            self.measure(&run_model(model, mesh, start, &mut |_| {})?, cell);
        } else {
            let model = admit(Model::build(&case, &source)?)?;
            let mesh = start.elapsed().as_secs_f64();
            self.measure(&run_model(model, mesh, start, &mut |_| {})?, cell);
        }
        Ok(())
    }

    /// The labels of cell `index`, in axis order.
    pub fn cell_labels(&self, index: usize) -> Vec<String> {
        self.coordinates(index)
            .iter()
            .zip(&self.labels)
            .map(|(&j, l)| l[j].clone())
            .collect()
    }

    /// Run cell `index`; a cell that cannot run is a cell with its `error`.
    pub fn run_cell(&self, index: usize) -> StudyCell {
        let mut cell = StudyCell {
            index,
            labels: self.cell_labels(index),
            dofs: None,
            error: None,
            checks_passed: false,
            failed_checks: Vec::new(),
            metrics: BTreeMap::new(),
            iterations: None,
            termination: None,
            condition_estimate: None,
            times: PhaseTimes::default(),
            peak_memory_mb: None,
        };
        let memory = reset_peak_memory();
        let start = Instant::now();
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            self.solve_cell(index, start, &mut cell)
        }));
        match outcome {
            Err(_) => {
                cell.error = Some(
                    "internal error (a bug in contact-patch; please report it with this study)"
                        .into(),
                )
            }
            Ok(Err(e)) => {
                cell.error = Some(e.to_string().lines().next().unwrap_or_default().to_string())
            }
            Ok(Ok(())) => {}
        }
        if memory {
            cell.peak_memory_mb = peak_memory_mb();
        }
        cell
    }

    fn measure<const D: usize, K: StudyDimension<D>>(
        &self,
        o: &Outcome<D, K>,
        cell: &mut StudyCell,
    ) {
        let t = &o.solution.timings;
        cell.times = PhaseTimes {
            mesh: t.mesh,
            assembly: t.assembly,
            factorization: t.factorization,
            solve: t.solve,
            contact_search: t.contact_search,
            total: t.total,
        };
        cell.dofs = Some(o.model.dof_count);
        cell.checks_passed = o.passed();
        cell.failed_checks = o
            .checks
            .iter()
            .filter(|c| c.fails_the_case())
            .map(|c| match c.verdict() {
                CheckVerdict::UnexpectedPass => {
                    format!("{} passed, but expected to fail", check_kind(&c.check))
                }
                _ => format!("{} {:.1e} x tol", check_kind(&c.check), c.error / c.tol),
            })
            .collect();
        if let Some(state) = &o.solution.contact {
            cell.iterations = Some(state.iterations);
            cell.termination = Some(match serde_json::to_value(&state.termination) {
                Ok(Value::String(s)) => s,
                Ok(Value::Object(m)) => m.keys().next().cloned().unwrap_or_default(),
                _ => String::new(),
            });
            cell.condition_estimate = state.history.last().and_then(|r| r.condition_estimate);
        }
        for m in &self.spec.metrics {
            let value = match m {
                Metric::Checks => o
                    .checks
                    .iter()
                    .map(|c| {
                        if c.tol > 0.0 {
                            c.error / c.tol
                        } else if c.passed {
                            0.0
                        } else {
                            f64::INFINITY
                        }
                    })
                    .reduce(f64::max),
                Metric::Check { index } => o.checks.get(*index).map(|c| c.error),
                Metric::HertzPeak { .. }
                | Metric::HertzHalfWidth { .. }
                | Metric::HertzProfile { .. } => K::hertz_metric(o, m),
            };
            if let Some(v) = value {
                cell.metrics.insert(m.name(), v);
            }
        }
    }

    /// The error metrics (every metric: each is an error against a reference).
    pub fn error_metrics(&self) -> Vec<String> {
        self.spec.metrics.iter().map(Metric::name).collect()
    }

    /// The axis a curve follows in the plots.
    pub fn along(&self) -> usize {
        let axes = &self.spec.axes;
        match &self.spec.along {
            Some(n) => axes.iter().position(|a| &a.name == n).expect("checked"),
            None => axes
                .iter()
                .position(|a| !a.refine.is_empty())
                .unwrap_or(axes.len() - 1),
        }
    }
}

/// What a check's text says it checks, without its numbers: the text up to the first `:`,
/// `=`, `(`, `[`, ` of ` or ` against`.
fn check_kind(text: &str) -> &str {
    let end = [":", "=", "(", "[", " of ", " against"]
        .iter()
        .filter_map(|m| text.find(m))
        .min()
        .unwrap_or(text.len());
    text[..end].trim()
}

/// The label of value `j` of axis `a`.
fn label(a: &AxisSpec, j: usize) -> String {
    if let Some(l) = &a.labels {
        return l[j].clone();
    }
    if !a.refine.is_empty() {
        return format!("x{}", a.refine[j]);
    }
    match &a.values[j] {
        Value::String(s) => s.clone(),
        Value::Object(m) if m.get("kind").is_some_and(Value::is_string) => {
            m["kind"].as_str().expect("a string").to_string()
        }
        v => v.to_string(),
    }
}

/// Set the fields of axis `a` to its value `j` in `case`.
fn apply(case: &mut Value, a: &AxisSpec, j: usize) -> std::result::Result<(), String> {
    let value = &a.values[j];
    let values: Vec<Value> = if a.paths.len() == 1 {
        vec![value.clone()]
    } else {
        match value {
            Value::Array(v) if v.len() == a.paths.len() => v.clone(),
            _ => {
                return Err(format!(
                    "with {} paths each value must be an array of {} values, got {value}",
                    a.paths.len(),
                    a.paths.len()
                ))
            }
        }
    };
    for (path, v) in a.paths.iter().zip(values) {
        let v = match (a.scale, &v) {
            (Some(s), Value::Number(n)) => {
                serde_json::Number::from_f64(n.as_f64().unwrap_or(f64::NAN) * s)
                    .map(Value::Number)
                    .ok_or_else(|| format!("{n} times the scale {s} is not a finite number"))?
            }
            _ => v,
        };
        set_path(case, path, v)?;
    }
    Ok(())
}

/// Set the field at the dotted `path`: every step but the last must exist; the last may be a
/// field the base leaves at its default (the case format then decides whether it exists).
pub fn set_path(root: &mut Value, path: &str, value: Value) -> std::result::Result<(), String> {
    let steps: Vec<&str> = path.split('.').collect();
    if path.is_empty() || steps.iter().any(|s| s.is_empty()) {
        return Err(format!("the path '{path}' has an empty step"));
    }
    let mut at = root;
    for (k, step) in steps.iter().enumerate() {
        let last = k + 1 == steps.len();
        let walked = steps[..k].join(".");
        let here = if walked.is_empty() {
            "the case".to_string()
        } else {
            format!("'{walked}'")
        };
        at = match at {
            Value::Object(map) => {
                if last {
                    map.insert(step.to_string(), value);
                    return Ok(());
                }
                if !map.contains_key(*step) {
                    return Err(format!(
                        "unknown path '{path}': {here} has no field '{step}' (its fields: {})",
                        map.keys().cloned().collect::<Vec<_>>().join(", ")
                    ));
                }
                map.get_mut(*step).expect("present")
            }
            Value::Array(items) => {
                let len = items.len();
                let i: usize = step.parse().map_err(|_| {
                    format!("unknown path '{path}': {here} is a list, '{step}' is not an index")
                })?;
                if i >= len {
                    return Err(format!(
                        "unknown path '{path}': {here} has {len} entries, no index {i}"
                    ));
                }
                if last {
                    items[i] = value;
                    return Ok(());
                }
                &mut items[i]
            }
            _ => {
                return Err(format!(
                    "unknown path '{path}': {here} is a value, it has no field '{step}'"
                ))
            }
        };
    }
    unreachable!("the loop returns at the last step")
}

/// The value at the dotted `path`, if there is one.
fn get_path<'a>(root: &'a Value, path: &str) -> Option<&'a Value> {
    path.split('.').try_fold(root, |at, step| match at {
        Value::Object(map) => map.get(step),
        Value::Array(items) => items.get(step.parse::<usize>().ok()?),
        _ => None,
    })
}

/// Split every interval of every block mesh axis (`block`, `block3d`) into `k` equal intervals
/// (the breaks stay grid vertices, so a block's moves still apply).
pub fn refine_case(case: &mut Case, k: usize) {
    for b in &mut case.bodies {
        let axes = match &mut b.mesh {
            MeshSpec::Block(block) => vec![&mut block.x, &mut block.y],
            MeshSpec::Block3d(block) => vec![&mut block.x, &mut block.y, &mut block.z],
            _ => Vec::new(),
        };
        for breaks in axes {
            match breaks {
                Breaks::Uniform(u) => u.divisions = u.divisions.saturating_mul(k),
                Breaks::List(list) => {
                    let mut out = Vec::with_capacity(list.len() * k);
                    for w in list.windows(2) {
                        for i in 0..k {
                            out.push(w[0] + (w[1] - w[0]) * i as f64 / k as f64);
                        }
                    }
                    out.extend(list.last().copied());
                    *list = out;
                }
            }
        }
    }
}

/// What a study measures differently by dimension: the Hertz metrics read a pressure profile
/// along a 2D contact line ([`crate::harness::profile`]); a 3D study is refused them when it is
/// loaded.
pub trait StudyDimension<const D: usize>: crate::run::RunDimension<D> {
    /// The value of a Hertz metric of `o` (`None` where it cannot be measured).
    fn hertz_metric(o: &Outcome<D, Self>, m: &Metric) -> Option<f64>;
}

impl StudyDimension<2> for crate::fe::ElementKind {
    fn hertz_metric(o: &Outcome, m: &Metric) -> Option<f64> {
        let (Metric::HertzPeak { pair }
        | Metric::HertzHalfWidth { pair }
        | Metric::HertzProfile { pair }) = m
        else {
            return None;
        };
        crate::harness::profile::pressure_profile(o, pair)
            .ok()
            .and_then(|p| {
                let h = p.hertz?;
                let (a, p0) = (h.half_width(), h.peak());
                match m {
                    Metric::HertzPeak { .. } => {
                        let peak = p
                            .points
                            .iter()
                            .map(|x| x.1)
                            .fold(f64::NEG_INFINITY, f64::max);
                        Some((peak - p0).abs() / p0)
                    }
                    Metric::HertzHalfWidth { .. } => Some((p.contact_extent() - a).abs() / a),
                    _ => p.deviation(crate::harness::profile::INTERIOR_SHARE),
                }
            })
    }
}

impl StudyDimension<3> for crate::fe3d::SolidKind {
    fn hertz_metric(_o: &Outcome<3, Self>, _m: &Metric) -> Option<f64> {
        None
    }
}

/// Reset the peak resident memory (Linux `clear_refs` 5); false where that is not possible.
fn reset_peak_memory() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// The peak resident memory since the last reset, in MB (`VmHWM`).
pub fn peak_memory_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// The cells of the Pareto front of `metric` against total time, by time.
pub fn pareto_front<'a>(cells: &'a [StudyCell], metric: &str) -> Vec<&'a StudyCell> {
    let points: Vec<(&StudyCell, f64, f64)> = cells
        .iter()
        .filter_map(|c| {
            let e = *c.metrics.get(metric)?;
            (c.error.is_none() && e.is_finite()).then_some((c, c.times.total, e))
        })
        .collect();
    let mut front: Vec<&StudyCell> = points
        .iter()
        .filter(|(_, t, e)| {
            !points
                .iter()
                .any(|(_, t2, e2)| t2 <= t && e2 <= e && (t2 < t || e2 < e))
        })
        .map(|p| p.0)
        .collect();
    front.sort_by(|a, b| {
        a.times
            .total
            .total_cmp(&b.times.total)
            .then(a.index.cmp(&b.index))
    });
    front
}

/// A window along one axis for one combination of the other axes.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Window {
    /// The other axes' labels.
    pub series: Vec<String>,
    /// The first and last value of the longest run of good values (`None`: no good value).
    pub window: Option<(String, String)>,
    /// Below the window: the first value outside it and why.
    pub below: Option<(String, String)>,
    /// Above the window.
    pub above: Option<(String, String)>,
}

/// Why a cell is outside the window (`None`: inside).
fn outside(cell: &StudyCell, w: &WindowSpec) -> Option<String> {
    if let Some(e) = &cell.error {
        return Some(format!("no solution ({e})"));
    }
    let mut why = Vec::new();
    if cell
        .termination
        .as_deref()
        .is_some_and(|t| t != "converged")
    {
        why.push(format!(
            "ended {}",
            cell.termination.as_deref().unwrap_or_default()
        ));
    }
    if !cell.checks_passed {
        why.push(format!("fails {}", cell.failed_checks.join(", ")));
    }
    if cell.iterations.is_some_and(|i| i > w.max_iterations) {
        why.push(format!(
            "{} iterations",
            cell.iterations.unwrap_or_default()
        ));
    }
    if cell
        .condition_estimate
        .is_some_and(|c| c.is_nan() || c > w.max_condition)
    {
        why.push(format!(
            "condition {:.1e}",
            cell.condition_estimate.unwrap_or_default()
        ));
    }
    (!why.is_empty()).then(|| why.join(", "))
}

/// The windows of a study (see the module), one per combination of the other axes.
pub fn windows(study: &Study, cells: &[StudyCell]) -> Vec<Window> {
    let Some(w) = &study.spec.window else {
        return Vec::new();
    };
    let axis = study
        .spec
        .axes
        .iter()
        .position(|a| a.name == w.axis)
        .expect("checked");
    let mut groups: BTreeMap<Vec<usize>, Vec<&StudyCell>> = BTreeMap::new();
    for c in cells {
        let mut key = study.coordinates(c.index);
        key.remove(axis);
        groups.entry(key).or_default().push(c);
    }
    let mut out = Vec::new();
    for (_, mut group) in groups {
        group.sort_by_key(|c| study.coordinates(c.index)[axis]);
        let good: Vec<Option<String>> = group.iter().map(|c| outside(c, w)).collect();
        let (mut best, mut run) = (None::<(usize, usize)>, None::<usize>);
        for i in 0..=good.len() {
            let ok = i < good.len() && good[i].is_none();
            match (ok, run) {
                (true, None) => run = Some(i),
                (false, Some(s)) => {
                    if best.is_none_or(|(a, b)| i - s > b + 1 - a) {
                        best = Some((s, i - 1));
                    }
                    run = None;
                }
                _ => {}
            }
        }
        let at = |i: usize| group[i].labels[axis].clone();
        let mut series = group[0].labels.clone();
        series.remove(axis);
        out.push(Window {
            series,
            window: best.map(|(a, b)| (at(a), at(b))),
            below: best.and_then(|(a, _)| {
                (a > 0).then(|| (at(a - 1), good[a - 1].clone().unwrap_or_default()))
            }),
            above: best.and_then(|(_, b)| {
                (b + 1 < group.len()).then(|| (at(b + 1), good[b + 1].clone().unwrap_or_default()))
            }),
        });
    }
    out
}

/// `v` in the tables: three significant digits, `-` when absent.
fn shown(v: Option<f64>) -> String {
    match v {
        None => "-".into(),
        Some(x) => format!("{x:.2e}"),
    }
}

/// The study's plots: one log-log plot of each error metric against total time, a curve per
/// combination of the axes other than `along`, and the Pareto front. `(file name, svg)`.
pub fn plots(study: &Study, cells: &[StudyCell]) -> Vec<(String, String)> {
    let along = study.along();
    let mut out = Vec::new();
    for metric in study.error_metrics() {
        let mut curves: BTreeMap<Vec<String>, Vec<(usize, f64, f64)>> = BTreeMap::new();
        for c in cells.iter().filter(|c| c.error.is_none()) {
            let Some(&e) = c.metrics.get(&metric) else {
                continue;
            };
            if !(e > 0.0 && c.times.total > 0.0) {
                continue;
            }
            let mut key = c.labels.clone();
            key.remove(along);
            curves.entry(key).or_default().push((
                study.coordinates(c.index)[along],
                c.times.total.log10(),
                e.log10(),
            ));
        }
        let mut series: Vec<Series> = curves
            .into_iter()
            .map(|(key, mut pts)| {
                pts.sort_by_key(|p| p.0);
                Series {
                    name: key.join(" "),
                    points: pts.iter().map(|p| (p.1, p.2)).collect(),
                }
            })
            .collect();
        let front: Vec<(f64, f64)> = pareto_front(cells, &metric)
            .iter()
            .filter(|c| c.metrics[&metric] > 0.0 && c.times.total > 0.0)
            .map(|c| (c.times.total.log10(), c.metrics[&metric].log10()))
            .collect();
        series.push(Series {
            name: "Pareto front".into(),
            points: front,
        });
        let title = format!("{}: {metric} against time", study.spec.name);
        let svg = line_plot(
            &title,
            "log10(total time / s)",
            &format!("log10({metric})"),
            &series,
        );
        out.push((format!("{}.{metric}.svg", study.spec.name), svg));
    }
    out
}

/// The study's report in Markdown; `plots` names the SVG files beside it.
pub fn markdown(study: &Study, cells: &[StudyCell], plots: &[String], command: &str) -> String {
    let s = &study.spec;
    let mut md = format!("# Study `{}`\n\n{}\n\nWritten by `{command}` from `{}` (base case `{}`); {} cells. Every number below is measured by that command; times depend on the machine.\n\n## Axes\n\n| axis | sets | values |\n|---|---|---|\n", s.name, s.description, study.source, study.base_path.display(), cells.len());
    for (a, l) in s.axes.iter().zip(&study.labels) {
        let sets = if a.refine.is_empty() {
            let mut t = a.paths.join(", ");
            if let Some(sc) = a.scale {
                t += &format!(" (value x {sc:e})");
            }
            t
        } else {
            "every block mesh interval split into k".to_string()
        };
        md += &format!("| {} | {} | {} |\n", a.name, sets, l.join(", "));
    }
    md += "\nMetrics (errors against references that are not our output; see `src/harness/study.rs`): ";
    md += &study.error_metrics().join(", ");
    md += ".\n\n";
    for (metric, plot) in study.error_metrics().iter().zip(plots) {
        let front = pareto_front(cells, metric);
        md += &format!("## Pareto front of `{metric}` against time\n\n![{metric}]({plot})\n\n{} of {} cells are on the front (no other cell is both faster and more accurate):\n\n| {} | total s | {metric} |\n|{}---|---|\n", front.len(), cells.len(), s.axes.iter().map(|a| a.name.as_str()).collect::<Vec<_>>().join(" | "), "---|".repeat(s.axes.len()));
        for c in front {
            md += &format!(
                "| {} | {:.4} | {} |\n",
                c.labels.join(" | "),
                c.times.total,
                shown(c.metrics.get(metric).copied())
            );
        }
        md += "\n";
    }
    if let Some(w) = &s.window {
        md += &window_markdown(study, cells, w);
    }
    md += "## All cells\n\n| ";
    for a in &s.axes {
        md += &format!("{} | ", a.name);
    }
    md += "dofs | checks pass | ";
    for m in study.error_metrics() {
        md += &format!("{m} | ");
    }
    md += "iterations | termination | condition | assembly s | factorization s | total s | peak MB | note |\n|";
    md += &"---|".repeat(s.axes.len() + study.error_metrics().len() + 10);
    md += "\n";
    for c in cells {
        md += &format!(
            "| {} | {} | {} | ",
            c.labels.join(" | "),
            c.dofs.map_or("-".into(), |d| d.to_string()),
            if c.error.is_some() {
                "-"
            } else if c.checks_passed {
                "yes"
            } else {
                "no"
            }
        );
        for m in study.error_metrics() {
            md += &format!("{} | ", shown(c.metrics.get(&m).copied()));
        }
        md += &format!(
            "{} | {} | {} | {:.4} | {:.4} | {:.4} | {} | {} |\n",
            c.iterations.map_or("-".into(), |i| i.to_string()),
            c.termination.as_deref().unwrap_or("-"),
            shown(c.condition_estimate),
            c.times.assembly,
            c.times.factorization,
            c.times.total,
            c.peak_memory_mb.map_or("-".into(), |m| format!("{m:.0}")),
            match &c.error {
                Some(e) => e.replace('|', "/"),
                None if c.failed_checks.is_empty() => String::new(),
                None => format!("fails {}", c.failed_checks.join(", ")),
            }
        );
    }
    md
}

fn window_markdown(study: &Study, cells: &[StudyCell], w: &WindowSpec) -> String {
    let windows = windows(study, cells);
    let others: Vec<&str> = study
        .spec
        .axes
        .iter()
        .filter(|a| a.name != w.axis)
        .map(|a| a.name.as_str())
        .collect();
    let mut md = format!(
        "## Window along `{}`\n\nA value is inside when the run converged, every declared check of the case passed (its own tolerances), the contact iterations are at most {} and the condition estimate at most {:.0e}. The window is the longest run of consecutive values inside; `breaks down` is the first value outside it on each side, with the reason (computed from the cells below).\n\n| {} | window | breaks down below | breaks down above |\n|{}---|---|---|\n",
        w.axis, w.max_iterations, w.max_condition, others.join(" | "), "---|".repeat(others.len())
    );
    for win in &windows {
        md += &format!(
            "| {} | {} | {} | {} |\n",
            win.series.join(" | "),
            win.window
                .as_ref()
                .map_or("none".into(), |(a, b)| format!("{a} .. {b}")),
            win.below
                .as_ref()
                .map_or("-".into(), |(v, why)| format!("{v}: {why}")),
            win.above
                .as_ref()
                .map_or("-".into(), |(v, why)| format!("{v}: {why}")),
        );
    }
    // the values inside every window of each value of the first other axis (the method)
    let axis = study
        .spec
        .axes
        .iter()
        .position(|a| a.name == w.axis)
        .expect("checked");
    let values = &study.labels[axis];
    let inside = |win: &Window, v: &str| {
        win.window.as_ref().is_some_and(|(a, b)| {
            let (i, j, k) = (
                values.iter().position(|x| x == a),
                values.iter().position(|x| x == b),
                values.iter().position(|x| x == v),
            );
            matches!((i, j, k), (Some(i), Some(j), Some(k)) if i <= k && k <= j)
        })
    };
    if !others.is_empty() {
        md += &format!("\nRecommended window per `{}` (the values inside the window of every combination of the other axes):\n\n| {} | recommended |\n|---|---|\n", others[0], others[0]);
        let mut firsts: Vec<String> = windows.iter().map(|w| w.series[0].clone()).collect();
        firsts.dedup();
        for f in firsts {
            let common: Vec<&String> = values
                .iter()
                .filter(|v| {
                    windows
                        .iter()
                        .filter(|w| w.series[0] == f)
                        .all(|w| inside(w, v))
                })
                .collect();
            md += &format!(
                "| {f} | {} |\n",
                match (common.first(), common.last()) {
                    (Some(a), Some(b)) => format!("{a} .. {b}"),
                    _ => "none".into(),
                }
            );
        }
    }
    md + "\n"
}

/// The study's JSON report.
#[derive(Serialize, Deserialize)]
pub struct StudyReport {
    pub study: StudySpec,
    pub cells: Vec<StudyCell>,
    /// The Pareto front of each metric: the cells' indices, by time.
    pub pareto: BTreeMap<String, Vec<usize>>,
    pub windows: Vec<Window>,
}

/// The JSON report of `cells`.
pub fn report_json(study: &Study, cells: &[StudyCell]) -> String {
    let report = StudyReport {
        study: study.spec.clone(),
        cells: cells.to_vec(),
        pareto: study
            .error_metrics()
            .into_iter()
            .map(|m| {
                let f = pareto_front(cells, &m).iter().map(|c| c.index).collect();
                (m, f)
            })
            .collect(),
        windows: windows(study, cells),
    };
    serde_json::to_string_pretty(&report).expect("a report serializes") + "\n"
}

/// The JSON Schema of the study format.
pub fn study_schema() -> String {
    serde_json::to_string_pretty(&schemars::schema_for!(StudySpec)).expect("a schema serializes")
        + "\n"
}

/// Write `<name>.md`, `<name>.json` and the plots into `folder`; returns the file names.
pub fn write_reports(
    folder: &crate::io::paths::ReportFolder,
    study: &Study,
    cells: &[StudyCell],
    command: &str,
) -> Result<Vec<String>> {
    let mut files = Vec::new();
    let mut names = Vec::new();
    for (name, svg) in plots(study, cells) {
        folder.write_file(&name, &svg)?;
        names.push(name.clone());
        files.push(name);
    }
    let (md, js) = (
        format!("{}.md", study.spec.name),
        format!("{}.json", study.spec.name),
    );
    folder.write_file(&js, &report_json(study, cells))?;
    folder.write_file(&md, &markdown(study, cells, &names, command))?;
    files.push(md);
    files.push(js);
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn set_path_sets_existing_and_default_fields_and_names_unknown_steps() {
        let mut v = json!({"contact": [{"enforcement": {"kind": "penalty", "kappa": 1.0}}]});
        set_path(&mut v, "contact.0.enforcement.kappa", json!(5.0)).unwrap();
        assert_eq!(v["contact"][0]["enforcement"]["kappa"], json!(5.0));
        set_path(&mut v, "solver", json!({"scheme": "newton"})).unwrap();
        assert_eq!(v["solver"]["scheme"], json!("newton"));
        let e = set_path(&mut v, "contact.3.enforcement", json!(1)).unwrap_err();
        assert!(e.contains("has 1 entries, no index 3"), "{e}");
        let e = set_path(&mut v, "contacts.0.kind", json!(1)).unwrap_err();
        assert!(e.contains("has no field 'contacts'"), "{e}");
        let e = set_path(&mut v, "contact.0.enforcement.kappa.x", json!(1)).unwrap_err();
        assert!(e.contains("is a value"), "{e}");
    }

    #[test]
    fn refinement_splits_every_interval() {
        let mut case: Case = serde_json::from_value(json!({
            "name": "r", "materials": {"m": {"E": 1.0, "nu": 0.0}},
            "bodies": [{"name": "b", "material": "m", "mesh": {"block": {"element": "Q4", "x": [0.0, 1.0, 3.0], "y": {"from": 0.0, "to": 1.0, "divisions": 3}}}}]
        }))
        .unwrap();
        refine_case(&mut case, 2);
        let MeshSpec::Block(b) = &case.bodies[0].mesh else {
            panic!("a block")
        };
        match (&b.x, &b.y) {
            (Breaks::List(x), Breaks::Uniform(y)) => {
                assert_eq!(x, &vec![0.0, 0.5, 1.0, 2.0, 3.0]);
                assert_eq!(y.divisions, 6);
            }
            _ => panic!("shapes kept"),
        }
    }

    fn cell(index: usize, t: f64, e: f64) -> StudyCell {
        StudyCell {
            index,
            labels: vec![index.to_string()],
            dofs: Some(1),
            error: None,
            checks_passed: true,
            failed_checks: Vec::new(),
            metrics: [("m".to_string(), e)].into_iter().collect(),
            iterations: Some(1),
            termination: Some("converged".into()),
            condition_estimate: None,
            times: PhaseTimes {
                total: t,
                ..Default::default()
            },
            peak_memory_mb: None,
        }
    }

    #[test]
    fn check_kinds_drop_the_numbers() {
        assert_eq!(
            check_kind("force balance: net force and net moment"),
            "force balance"
        );
        assert_eq!(
            check_kind("displacement Y of punch at (4, 7) = -6.37e-2"),
            "displacement Y"
        );
        assert_eq!(
            check_kind("uniform stress [0.0, -10.0, 0.0]"),
            "uniform stress"
        );
    }

    #[test]
    fn pareto_front_keeps_the_cells_nothing_beats() {
        // (time, error): 0 (1, 1), 1 (2, 0.5), 2 (2, 0.8) dominated by 1, 3 (3, 0.5) dominated
        // by 1, 4 (0.5, 2)
        let cells = [
            cell(0, 1.0, 1.0),
            cell(1, 2.0, 0.5),
            cell(2, 2.0, 0.8),
            cell(3, 3.0, 0.5),
            cell(4, 0.5, 2.0),
        ];
        let front: Vec<usize> = pareto_front(&cells, "m").iter().map(|c| c.index).collect();
        assert_eq!(front, vec![4, 0, 1]);
    }

    #[test]
    fn peak_memory_is_read_where_linux_offers_it() {
        if reset_peak_memory() {
            let v = vec![1u8; 64 << 20];
            std::hint::black_box(&v);
            let mb = peak_memory_mb().expect("VmHWM after a reset");
            assert!(mb >= 64.0, "a 64 MB vector is resident, peak {mb} MB");
        }
    }
}
