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
//!   `max_penetration`, `force_balance`): from the results' point fields `contact_force`,
//!   `contact_pressure` (compression positive) and `contact_gap` on the pairs' surfaces, as
//!   [`crate::harness::outside_contact`] states (in the configuration the case's contact
//!   geometry names, as our run); a check whose field is missing is listed as not judged, naming
//!   the field. With contact forces `f_c`, `f_int(u) - f - f_c` is the residual (the run's
//!   [`crate::solver::linear::residual`]). A failed `force_balance` names its largest term and
//!   says when the results balance with the moments in the other configuration.
//!
//! The field names are matched without regard to case
//! ([`crate::harness::outside_results`]), and the `.vtu` may be in any encoding VTK writes
//! ([`crate::io::vtu_read`]). The case may be given as the folder `contact-patch export`
//! wrote, which carries it ([`crate::io::export::exported_case`]).
//!
//! `table --results DIR` makes one table cell per swept case from the results in `DIR`
//! ([`outside_cells`]), judged as the sweep judges an exact method: the stress criterion
//! `max_qp max_i |sigma_i(u) - sigma_exact,i| / p <= tol` (the contact patch test's uniform
//! stress) and, where the results carry them, the pressure error, the total contact force
//! (load error) within `tol` and the force balance within the case's `force_balance` tolerance;
//! the note names what was judged and what the results lack.

use crate::contact::forces::PairForces;
use crate::error::{Error, Result};
use crate::harness::checks::{
    evaluate_with, force_balance_of, force_balance_terms, pressure_error_of, CheckResult,
    Magnitudes,
};
pub use crate::harness::outside_contact::PressureArea;
use crate::harness::outside_contact::{self, OutsideContact, Source};
use crate::harness::outside_results::field;
pub use crate::harness::outside_results::{
    load_results, Results, ResultsFile, CONTACT_FORCE_FIELD, CONTACT_GAP_FIELD,
    CONTACT_PRESSURE_FIELD, CONTACT_STATUS_FIELD, DISPLACEMENT_FIELD, STRESS_FIELD,
};
use crate::io::paths::file_name;
use crate::io::scene::{Check, ContactGeometry};
use crate::io::vtu_read::PointGrid;
use crate::model::Model;
use crate::solver::linear::{Solution, Timings};
use std::collections::HashMap;
use std::path::Path;

/// Default node-matching distance, relative to the model size.
pub const DEFAULT_MATCH_SHARE: f64 = 1e-8;

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
    /// The solution the results define (`u`, `K u - f - f_c`).
    pub solution: Solution,
    /// The contact fields read (empty without contact pairs).
    pub contact: OutsideContact,
}

impl Judgement {
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| !c.fails_the_case())
    }
}

/// Why a check cannot be judged from point results, or `None` when it can.
pub(crate) fn unjudgeable(check: &Check) -> Option<&'static str> {
    match check {
        Check::UniformStress { .. }
        | Check::ExactDisplacement { .. }
        | Check::Reaction { .. }
        | Check::Displacement { .. } => None,
        // judged from the results' contact fields (crate::harness::outside_contact)
        Check::ContactPressure { .. }
        | Check::ContactForce { .. }
        | Check::MaxContactPressure { .. }
        | Check::MaxPenetration { .. }
        | Check::ForceBalance { .. } => None,
        Check::UniformStress3d { .. } => {
            Some("it is a check of 3D cases, which are not judged here yet")
        }
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

/// How to fix a node without a result point. When some result point minus its displacement
/// lands on the node, the results were written at the deformed positions `X + u` (a common
/// default of codes that solve in the current configuration), and the hint says so.
pub(crate) fn unmatched_node_hint(
    grid: &crate::io::vtu_read::PointGrid,
    displacement: &crate::io::vtu_read::PointField,
    x: &[f64],
    delta: f64,
    mesh: &str,
) -> String {
    let deformed = grid.points.iter().enumerate().any(|(k, p)| {
        let u = displacement.at(k);
        let distance2: f64 = x
            .iter()
            .enumerate()
            .map(|(i, xi)| (p[i] - u.get(i).copied().unwrap_or(0.0) - xi).powi(2))
            .sum();
        distance2.sqrt() <= delta
    });
    if deformed {
        format!(
            "the results' points are the deformed positions X + u (a point minus its displacement \
             lands on this node): write the points at the reference coordinates X of {mesh}'s \
             nodes (the undeformed configuration) and the displacement as point data"
        )
    } else {
        format!(
            "solve on {mesh} and write the results at the reference coordinates X of its nodes \
             (not X + u); or raise --match-tol (a share of the model size)"
        )
    }
}

/// How another code's results are read: the node-matching distance (a share of the model
/// size) and the area its `contact_pressure` is per.
#[derive(Clone, Copy, Debug)]
pub struct ReadOptions {
    pub match_share: f64,
    pub pressure_area: PressureArea,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            match_share: DEFAULT_MATCH_SHARE,
            pressure_area: PressureArea::Case,
        }
    }
}

/// Judge `results` with the checks of `model`; nodes are matched within
/// `match_share * model.size()`, the pressure read per area of the case's configuration.
pub fn judge(model: &Model, results: &Results, match_share: f64) -> Result<Judgement> {
    judge_with(
        model,
        results,
        ReadOptions {
            match_share,
            ..ReadOptions::default()
        },
    )
}

/// [`judge`] with the results read as `options` says.
pub fn judge_with(model: &Model, results: &Results, options: ReadOptions) -> Result<Judgement> {
    let ReadOptions {
        match_share,
        pressure_area,
    } = options;
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
                    unmatched_node_hint(
                        &file.grid,
                        displacement,
                        &x,
                        delta,
                        "the exported mesh (contact-patch export)",
                    ),
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
    let contact = if model.contact.is_empty() {
        OutsideContact::default()
    } else {
        outside_contact::read(model, results, &matched, &u, pressure_area)?
    };
    let solution = solution_of(model, u, contact.nodal_force.as_deref());
    let mut checks = Vec::new();
    let mut not_judged = Vec::new();
    for check in &model.checks {
        let stated = || serde_json::to_string(check).expect("checks serialize");
        if let Some(why) = unjudgeable(check) {
            not_judged.push(NotJudged {
                check: stated(),
                why: why.to_string(),
            });
            continue;
        }
        let mut one = model.clone();
        one.checks = vec![check.clone()];
        match contact.source(model, check) {
            Source::NoContact => checks.extend(evaluate_with(&one, &solution, None)),
            Source::NotJudged(why) => not_judged.push(NotJudged {
                check: stated(),
                why,
            }),
            Source::Forces(forces, from) => checks.extend(
                evaluate_with(&one, &solution, Some(&forces))
                    .into_iter()
                    .map(|mut c| {
                        c.check += &format!(" [from the results' '{from}']");
                        if let (false, Check::ForceBalance { tol }, CONTACT_FORCE_FIELD) =
                            (c.passed, check, from)
                        {
                            c.check += &balance_elsewhere(model, &solution, &forces, *tol);
                        }
                        c
                    }),
            ),
        }
    }
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
            checks.push(CheckResult::judged(
                format!("uniform stress {stress:?}{on} in the results' own nodal 'stress' field"),
                error,
                *tol,
            ));
        }
    }
    let contact_use = |found: bool, what: &str| {
        if found {
            what.to_string()
        } else {
            format!("missing: not used for {what}")
        }
    };
    let mut fields = vec![
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
    ];
    if !model.contact.is_empty() {
        fields.extend([
            FieldUse {
                field: CONTACT_PRESSURE_FIELD.into(),
                found: contact.pressure_field,
                use_: contact_use(
                    contact.pressure_field,
                    "the contact pressure checks; the forces -p A n of frictionless pairs",
                ),
            },
            FieldUse {
                field: CONTACT_FORCE_FIELD.into(),
                found: contact.force_field,
                use_: contact_use(
                    contact.force_field,
                    "the contact force and force balance checks; the tractions of ties",
                ),
            },
            FieldUse {
                field: CONTACT_GAP_FIELD.into(),
                found: contact.gap_field,
                use_: contact_use(contact.gap_field, "the penetration checks"),
            },
        ]);
    }
    Ok(Judgement {
        checks,
        not_judged,
        fields,
        nodes: matched.iter().map(Vec::len).sum(),
        largest_distance,
        match_distance: delta,
        solution,
        contact,
    })
}

/// Where the force balance of the results fails in the configuration of the case: whether it
/// holds with the moments taken in the other one (`X + u` for a reference-geometry case, `X` for
/// a current-geometry one), in words to append to the check (empty when it does not hold there
/// either). A code that evaluates contact in the deformed geometry balances its moments about
/// `X + u`, which a small-sliding case judged about `X` does not credit.
fn balance_elsewhere(
    model: &Model,
    solution: &Solution,
    forces: &[PairForces],
    tol: f64,
) -> String {
    let current = model.physics.contact_geometry == ContactGeometry::Current;
    let moved: Vec<PairForces> = forces
        .iter()
        .map(|pf| {
            let mut pf = pf.clone();
            let moment: f64 = pf
                .nodes
                .iter()
                .map(|t| {
                    let body = &model.bodies[t.body];
                    let x = body.mesh.nodes[t.node];
                    let p = if current {
                        x
                    } else {
                        [
                            x[0] + solution.u[body.dof(t.node, 0)],
                            x[1] + solution.u[body.dof(t.node, 1)],
                        ]
                    };
                    p[0] * t.force[1] - p[1] * t.force[0]
                })
                .sum();
            pf.net_moment = [0.0, 0.0, moment];
            pf
        })
        .collect();
    let (error, _) = force_balance_terms(model, solution, &moved);
    if error > tol || error.is_nan() {
        return String::new();
    }
    let (other, geometry) = if current {
        ("reference positions X", "current")
    } else {
        ("deformed positions X + u", "reference")
    };
    format!(
        "; with the moments about the {other} the results balance (error {error:.3e}): their \
         contact forces act in the other configuration than the case's \
         physics.contact_geometry \"{geometry}\""
    )
}

/// The solution `u` defines: `f_int(u) - f - f_c` at every dof (reactions at the prescribed
/// ones; `f_int = K u` under small strain, the finite-strain internal force under finite
/// kinematics, by the run's own [`crate::solver::linear::residual`]), and the largest free-dof
/// residual relative to the largest external force or reaction.
pub(crate) fn solution_of<const D: usize, K: crate::model::space::SolidCell<D>>(
    model: &crate::model::Model<D, K>,
    u: Vec<f64>,
    contact_force: Option<&[f64]>,
) -> crate::solver::linear::Solution<D> {
    let mut r = crate::solver::linear::residual(model, &u);
    if let Some(fc) = contact_force {
        for (r, f) in r.iter_mut().zip(fc) {
            *r -= f;
        }
    }
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
        force_scale: scale,
        timings: Timings::default(),
        contact: None,
        dynamics: None,
        finite: None,
        iterative: None,
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

/// The file by which another code says it cannot solve a case: `DIR/<case>/not-applicable.txt`,
/// its text the reason (e.g. "no 3-node contact facets"); the cell is `n/a` with that reason.
pub const NOT_APPLICABLE_FILE: &str = "not-applicable.txt";

/// The folders of a penalty code's kappa series: `DIR/<case>/kappa-<value>/`, each a results
/// set of the case at that penalty parameter (`<case>.vtu`, or one `<body>.vtu` per body).
pub const KAPPA_FOLDER_PREFIX: &str = "kappa-";

/// The longest reason [`NOT_APPLICABLE_FILE`] may give, in bytes.
const LONGEST_REASON: u64 = 2000;

/// The smallest ratio of the largest to the smallest kappa of a series: the trend rule
/// (the error falls by at least a tenth of the ratio) says nothing over a narrower span.
pub const SMALLEST_KAPPA_SPAN: f64 = 100.0;

/// What one results set of a swept case measured (see [`outside_cells`]).
struct Measured {
    stress_error: f64,
    pressure_error: Option<f64>,
    /// The load error and the force balance, from the results' contact forces.
    forces: Option<(f64, f64)>,
    judged_on: Vec<&'static str>,
    missing: Vec<&'static str>,
}

impl Measured {
    /// The note's words: what was judged, and what the results lack.
    fn words(&self) -> String {
        let missing = if self.missing.is_empty() {
            String::new()
        } else {
            format!(
                "; not in the results: {} (fields '{CONTACT_PRESSURE_FIELD}', '{CONTACT_FORCE_FIELD}')",
                self.missing.join(", ")
            )
        };
        format!("judged on {}{missing}", self.judged_on.join(", "))
    }
}

/// Judge the results at `path` of the swept case `model` as the sweep judges an exact method.
fn measure_outside(
    model: &Model,
    sweep: &crate::io::scene::SweepSpec,
    path: &Path,
    options: ReadOptions,
) -> Result<Measured> {
    let results = load_results(model, path)?;
    let judged = judge_with(model, &results, options)?;
    let mut measured = Measured {
        stress_error: crate::harness::stress_error(model, &judged.solution.u, sweep.pressure),
        pressure_error: None,
        forces: None,
        judged_on: vec!["the stress of its displacement"],
        missing: Vec::new(),
    };
    let pairs = &judged.contact.pairs;
    let pressures: Option<Vec<PairForces>> = pairs
        .iter()
        .map(|p| p.pressures().map(|(f, _)| f.clone()))
        .collect();
    match (pressures, model.exact.as_ref()) {
        (Some(p), Some(exact)) if !pairs.is_empty() => {
            measured.pressure_error = Some(pressure_error_of(
                model,
                &judged.solution,
                &p,
                exact,
                None,
                Some(sweep.pressure.abs()),
            ));
            measured.judged_on.push("the contact pressure");
        }
        _ => measured.missing.push("pressure"),
    }
    let forces: Option<Vec<PairForces>> = pairs
        .iter()
        .map(|p| p.forces().map(|(f, _)| f.clone()))
        .collect();
    match forces {
        Some(f) if !pairs.is_empty() => {
            let first_pass: std::collections::HashSet<(usize, usize, usize)> = f
                .iter()
                .flat_map(|pf| {
                    let slave = model.contact[pf.pair].slave.0;
                    pf.nodes
                        .iter()
                        .filter(move |n| n.carries_rows && n.body == slave)
                        .map(move |n| (pf.pair, n.body, n.node))
                })
                .collect();
            let load = crate::harness::load_error(model, &f, sweep.pressure, &|k, b, n| {
                first_pass.contains(&(k, b, n))
            });
            let balance = force_balance_of(model, &judged.solution, &f);
            measured.forces = Some((load, balance));
            measured
                .judged_on
                .push("the total contact force and the force balance");
        }
        _ => measured.missing.push("contact forces"),
    }
    Ok(measured)
}

/// Results of the case given outside a kappa series: `DIR/<case>.vtu` (`file`), or a `.vtu`
/// file directly in `DIR/<case>/` (`folder`); `None` when there are none.
fn direct_results(file: &Path, folder: &Path) -> Result<Option<std::path::PathBuf>> {
    if file.is_file() {
        return Ok(Some(file.to_path_buf()));
    }
    let shown = folder.display().to_string();
    let entries = std::fs::read_dir(folder).map_err(|e| Error::io(&shown, "listing", e))?;
    let mut found = Vec::new();
    for entry in entries {
        let path = entry.map_err(|e| Error::io(&shown, "listing", e))?.path();
        if path.is_file()
            && path
                .extension()
                .is_some_and(|x| x.eq_ignore_ascii_case("vtu"))
        {
            found.push(path);
        }
    }
    found.sort();
    Ok(found.into_iter().next())
}

/// The reason in `DIR/<case>/not-applicable.txt`, when the outside code gave one.
fn not_applicable_reason(folder: &Path) -> Result<Option<String>> {
    let file = folder.join(NOT_APPLICABLE_FILE);
    if !file.is_file() {
        return Ok(None);
    }
    let shown = file.display().to_string();
    let size = std::fs::metadata(&file)
        .map_err(|e| Error::io(&shown, "reading its size", e))?
        .len();
    if size > LONGEST_REASON {
        return Err(Error::invalid(
            &shown,
            "the reason",
            format!("{size} bytes; a reason is at most {LONGEST_REASON}"),
            "say in a sentence why the code cannot solve the case",
        ));
    }
    let text = std::fs::read(&file).map_err(|e| Error::io(&shown, "reading", e))?;
    let text = String::from_utf8(text).map_err(|_| {
        Error::invalid(
            &shown,
            "the reason",
            "not UTF-8 text",
            "write the reason as plain text",
        )
    })?;
    let reason = text.split_whitespace().collect::<Vec<_>>().join(" ");
    if reason.is_empty() {
        return Err(Error::invalid(
            &shown,
            "the reason",
            "the file is empty",
            "say why the code cannot solve the case, e.g. \"no 3-node contact facets\"",
        ));
    }
    Ok(Some(reason))
}

/// The kappa series in `DIR/<case>/`: `(kappa, results path)` sorted by kappa; empty when the
/// folder holds no `kappa-*` folder.
fn kappa_series(folder: &Path, case: &str) -> Result<Vec<(f64, std::path::PathBuf)>> {
    let shown = folder.display().to_string();
    let entries = std::fs::read_dir(folder).map_err(|e| Error::io(&shown, "listing", e))?;
    let mut series = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|e| Error::io(&shown, "listing", e))?;
        let name = entry.file_name().to_string_lossy().to_string();
        let Some(value) = name.strip_prefix(KAPPA_FOLDER_PREFIX) else {
            continue;
        };
        let path = entry.path();
        if !path.is_dir() {
            continue;
        }
        let kappa: f64 = value
            .parse()
            .ok()
            .filter(|k: &f64| k.is_finite() && *k > 0.0)
            .ok_or_else(|| {
                Error::invalid(
                    &shown,
                    format!("folder '{name}'"),
                    format!("'{value}' is not a positive number"),
                    "name each folder of a kappa series kappa-<value>, e.g. kappa-1e6",
                )
            })?;
        let file = path.join(file_name("case name", case, ".vtu")?);
        series.push((kappa, if file.is_file() { file } else { path }));
    }
    series.sort_by(|a, b| a.0.total_cmp(&b.0));
    if series.len() == 1 {
        return Err(Error::invalid(
            &shown,
            format!("folder '{}'", series[0].1.display()),
            "a kappa series of one kappa: the trend of the error needs two or more",
            format!(
                "add the same case solved at a kappa {SMALLEST_KAPPA_SPAN:e} times larger (or \
                 more), or put the results directly in {shown}/"
            ),
        ));
    }
    if let (Some(first), Some(last)) = (series.first(), series.last()) {
        if last.0 < SMALLEST_KAPPA_SPAN * first.0 {
            return Err(Error::invalid(
                &shown,
                "the kappa series",
                format!(
                    "kappa spans {:e} to {:e}, a factor {:.3}; the trend needs at least {SMALLEST_KAPPA_SPAN}",
                    first.0,
                    last.0,
                    last.0 / first.0
                ),
                "add a kappa at least 100 times the smallest",
            ));
        }
        if let Some(w) = series.windows(2).find(|w| w[0].0 == w[1].0) {
            return Err(Error::invalid(
                &shown,
                "the kappa series",
                format!("two folders give kappa {:e}", w[0].0),
                "give each kappa once",
            ));
        }
    }
    Ok(series)
}

/// One table cell for the swept case at `case_file` from another code's results in `dir`
/// (see [`results_in`]), named `code` in the enforcement column; no cell for a case without
/// a sweep. A case without results is an `n/a` cell that says so; so is one whose folder
/// `DIR/<case>/` holds [`NOT_APPLICABLE_FILE`], with the code's reason. A penalty code hands
/// in a kappa series as folders `DIR/<case>/kappa-<value>/` (two or more, spanning at least
/// [`SMALLEST_KAPPA_SPAN`]): the cell is judged as our penalty cells are, on the trend of its
/// stress error from the smallest to the largest kappa (`round-off` at both, `1/kappa` when it
/// falls by at least a tenth of the kappa ratio, else `no fall`), with the contact forces of the
/// largest kappa.
pub fn outside_cells(
    case_file: &Path,
    dir: &Path,
    code: &str,
    options: ReadOptions,
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
    let folder = dir.join(file_name("case name", &model.name, "")?);
    let file = dir.join(file_name("case name", &model.name, ".vtu")?);
    if folder.is_dir() {
        let direct = direct_results(&file, &folder)?;
        if let Some(reason) = not_applicable_reason(&folder)? {
            if let Some(results) = direct {
                return Err(Error::invalid(
                    folder.display(),
                    NOT_APPLICABLE_FILE,
                    format!(
                        "says the code cannot solve the case, yet {} holds its results",
                        results.display()
                    ),
                    "remove one of the two",
                ));
            }
            cell.note = format!("n/a ({code}): {reason}");
            return Ok(vec![cell]);
        }
        let series = kappa_series(&folder, &model.name)?;
        if !series.is_empty() {
            if let Some(results) = direct {
                return Err(Error::invalid(
                    folder.display(),
                    "the kappa series",
                    format!(
                        "{} holds results beside the kappa-<value> folders, so which of them \
                         is the code's answer is not clear",
                        results.display()
                    ),
                    "move those results into a kappa-<value> folder of their kappa, or remove \
                     the kappa folders",
                ));
            }
            return kappa_series_cell(cell, &model, &sweep, &series, options);
        }
    }
    let Some(path) = results_in(dir, &model.name)? else {
        cell.note = format!(
            "no results: neither {0}/{1}.vtu nor {0}/{1}/ exists",
            dir.display(),
            model.name
        );
        return Ok(vec![cell]);
    };
    let measured = measure_outside(&model, &sweep, &path, options)?;
    cell.stress_error = Some(measured.stress_error);
    cell.pressure_error = measured.pressure_error;
    let mut pass = measured.stress_error <= sweep.tol
        && measured.pressure_error.is_none_or(|e| e <= sweep.tol);
    if let Some((load, balance)) = measured.forces {
        cell.load_error = Some(load);
        cell.force_balance = Some(balance);
        pass &= load <= sweep.tol && balance <= crate::harness::balance_tol(&model);
    }
    cell.verdict = if pass { "pass" } else { "fail" }.into();
    cell.note = format!("{}: {}", path.display(), measured.words());
    Ok(vec![cell])
}

/// The cell of a penalty code's kappa series (see [`outside_cells`]).
fn kappa_series_cell(
    mut cell: crate::harness::Cell,
    model: &Model,
    sweep: &crate::io::scene::SweepSpec,
    series: &[(f64, std::path::PathBuf)],
    options: ReadOptions,
) -> Result<Vec<crate::harness::Cell>> {
    let mut errors = Vec::with_capacity(series.len());
    let mut stiffest = None;
    for (kappa, path) in series {
        let measured = measure_outside(model, sweep, path, options)?;
        errors.push((*kappa, measured.stress_error));
        stiffest = Some(measured);
    }
    let stiffest = stiffest.expect("a series of two or more");
    let (k1, e1) = errors[0];
    let (k2, e2) = errors[errors.len() - 1];
    let ratio = k2 / k1;
    let trend = if e1 <= sweep.tol && e2 <= sweep.tol {
        "round-off"
    } else if e2 * ratio / 10.0 <= e1 {
        "1/kappa"
    } else {
        "no fall"
    };
    cell.kappa = Some(k1);
    cell.stress_error = Some(e1);
    cell.stress_error_stiff = Some(e2);
    cell.penalty_trend = Some(trend.into());
    cell.pressure_error = stiffest.pressure_error;
    let mut pass = trend != "no fall";
    if let Some((load, balance)) = stiffest.forces {
        cell.load_error = Some(load);
        cell.force_balance = Some(balance);
        pass &= load <= sweep.tol && balance <= crate::harness::balance_tol(model);
    }
    cell.verdict = if pass { "pass" } else { "fail" }.into();
    let listed: Vec<String> = errors
        .iter()
        .map(|(k, e)| format!("{k:e}: {e:.3e}"))
        .collect();
    cell.note = format!(
        "kappa series (kappa: stress error) {}: {trend} as kappa grows {ratio:e}x (the \
         'at 1000 kappa' column holds the largest kappa's); at the largest kappa {}",
        listed.join(", "),
        stiffest.words()
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
