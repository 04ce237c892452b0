//! The patch-test harness: expand each case's sweep (discretizations x enforcements), run every
//! cell, judge it, and render the tables.
//!
//! **Verdicts** (Taylor & Papadopoulos 1991; data in `shared/design/benchmarks.md` s. 1):
//! * `stress_error`: max over the quadrature points of both bodies and over `xx, yy, xy` of
//!   `|sigma - sigma_exact| / p`.
//! * `pressure_error`: max over the interface nodes that carry rows of the difference between
//!   the nodal traction `f_a / A_a` (`f = B^T lambda`, see [`crate::contact::forces`]) and the
//!   exact one, over `p` (the normal component for contact, the whole traction for ties).
//! * `force_balance`: net contact force and moment, and the equilibrium residual.
//! * `load_error`: the total interaction force (all rows, both passes) against the exact
//!   traction integrated over the interface.
//! * Exact methods (Lagrange, elimination, perturbed tangent, augmented Lagrangian) pass when
//!   the stress error, the load error and the pressure error (from `B^T lambda`, unique even
//!   for dependent rows) are
//!   within the sweep's tolerance, the force balance within the case's `force_balance`
//!   tolerance (1e-12 if it declares none), and the active-set loop converged.
//! * The perturbed Lagrangian on standard mortar rows (a consistent, non-diagonal multiplier
//!   mass) is also compared with the penalty method at the same kappa (`vs_penalty`, in the
//!   note); elsewhere the two are the same method.
//! * Penalty-type methods (penalty, perturbed Lagrangian) satisfy the gap only approximately;
//!   they run at `kappa` and at `penalty_factor * kappa` (both runs must converge and carry the
//!   load) and are judged on the stress error: a
//!   pass when it is round-off at both (`round-off`) or falls at least `penalty_factor / 10`
//!   times (`1/kappa`, a consistent method converging as the penalty grows); a fail when it
//!   does not fall (`no fall`: a consistency failure).
//! * **Stability** (its own column, next to the consistency verdict): `rank_deficiency` counts
//!   dependent active constraints; for the methods with a multiplier system (Lagrange,
//!   elimination) a singular one is `unstable` even when the displacements pass.
//! * `n/a` cells say why the combination does not apply.

pub mod baseline;
pub mod block_drop;
pub mod cattaneo;
pub mod cattaneo3d;
pub mod checks;
pub(crate) mod exact;
pub mod finite_patch;
pub mod finite_sliding;
pub mod friction;
pub mod friction_convergence;
pub mod hard;
pub mod hertz3d;
pub mod hertz_finite;
pub mod impact;
pub mod impact_cost;
pub mod index_page;
pub mod ironing;
pub mod judge;
pub mod judge3;
pub mod junit;
pub mod layer;
pub mod load_path;
pub mod outside_contact;
pub mod outside_results;
pub mod profile;
pub mod report;
pub mod shard;
pub mod stability;
pub mod study;

use crate::contact::enforcement::method;
use crate::contact::forces::{pair_forces, PairForces};
use crate::error::Result;
use crate::fe::ElementKind;
use crate::fe3d::SolidKind;
use crate::io::scene::{
    Catalogue, DiscretizationSpec, EnforcementSpec, FrictionTangent, MultiplierSpace,
    TwoPassPenalty,
};
use crate::model::admit::load;
use crate::model::space::SolidCell;
use crate::model::Model;
use crate::post::for_each_quadrature_stress;
use crate::run::RunDimension;
use crate::solver::active_set::Termination;
use crate::solver::linear::Solution;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::time::Instant;

/// One cell of the patch table.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Cell {
    /// `patch` or `tied` (the sweep's catalogue).
    pub catalogue: Catalogue,
    /// 2 or 3: the case's dimension (3D cells go to `<catalogue>-table-3d.*`); left out of the
    /// table files in 2D.
    #[serde(default = "two", skip_serializing_if = "is_two")]
    pub dimension: u8,
    pub case: String,
    pub mesh: String,
    pub nu: f64,
    pub discretization: String,
    pub passes: Option<u8>,
    pub slave: Option<String>,
    pub enforcement: String,
    pub kappa: Option<f64>,
    /// The sweep's load scale (errors are relative to it).
    pub pressure: f64,
    pub verdict: String,
    pub stress_error: Option<f64>,
    /// Penalty-type methods: the stress error at `penalty_factor * kappa`.
    pub stress_error_stiff: Option<f64>,
    /// Penalty-type methods: `round-off`, `1/kappa` or `no fall`.
    pub penalty_trend: Option<String>,
    pub pressure_error: Option<f64>,
    pub force_balance: Option<f64>,
    /// `|F - F_exact| / (p A)`: the total interaction force on the pass-1 slave body (all rows,
    /// both passes) against the exact traction integrated over its interface nodes, relative
    /// to the sweep's pressure times the interface area.
    pub load_error: Option<f64>,
    pub max_penetration: Option<f64>,
    pub rank_deficiency: Option<usize>,
    /// Stability of the multiplier system: `stable`, `unstable` (dependent constraints, the
    /// multipliers are not unique) or `-` (the method has no multiplier system).
    pub stability: String,
    pub newton_iterations: Option<usize>,
    pub termination: Option<String>,
    /// `cholesky`, `ldlt` or `schur-pseudo-inverse` (see `contact::solver::ContactState`).
    pub linear_solver: Option<String>,
    /// Methods that use the rows' multiplier mass (the perturbed Lagrangian) on rows that carry
    /// a consistent one (standard mortar): the largest stress difference from the penalty
    /// method at the same kappa, over `p` (zero for a lumped mass, where the two coincide).
    pub vs_penalty: Option<f64>,
    /// Wall-clock time of the cell's solves; `None` when nothing was solved here (an `n/a`
    /// cell, or another code's results judged by `table --results`).
    pub time_ms: Option<f64>,
    pub note: String,
    /// The frictional patch test's own measures (catalogue `friction`, see [`friction`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction: Option<FrictionCell>,
    /// The sweep's tolerance (relative to `pressure`); not in the table files (their cells are
    /// compared by `table --baseline`), shown in JUnit messages.
    #[serde(skip)]
    pub tol: f64,
}

impl Cell {
    /// A cell of `case` (mesh `mesh`, judged at `tol`) with nothing measured yet: verdict
    /// `n/a`, every measure absent; the sweep and the outside-results table fill it in.
    pub fn unmeasured(catalogue: Catalogue, case: String, mesh: String, tol: f64) -> Cell {
        Cell {
            catalogue,
            dimension: 2,
            case,
            mesh,
            nu: 0.0,
            discretization: String::new(),
            passes: None,
            slave: None,
            enforcement: String::new(),
            kappa: None,
            pressure: 0.0,
            verdict: "n/a".into(),
            stress_error: None,
            stress_error_stiff: None,
            penalty_trend: None,
            pressure_error: None,
            force_balance: None,
            load_error: None,
            max_penetration: None,
            rank_deficiency: None,
            stability: "-".into(),
            newton_iterations: None,
            termination: None,
            linear_solver: None,
            vs_penalty: None,
            time_ms: None,
            note: String::new(),
            friction: None,
            tol,
        }
    }
}

fn two() -> u8 {
    2
}

fn is_two(d: &u8) -> bool {
    *d == 2
}

/// The friction part of a cell of the friction table ([`friction`]).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FrictionCell {
    /// `stick` or `slip`: the status every point must end in.
    pub expect: String,
    /// How many points ended the last step in that status, of all: `slip 3/3`.
    pub statuses: Option<String>,
    /// Largest error of the nodal tangential traction over `p`.
    pub tangential_error: Option<f64>,
    /// Largest `|lambda_t| / (mu lambda_n)` over the closed points of every step (<= 1).
    pub cone_ratio: Option<f64>,
    /// Smallest frictional dissipation of a load step (>= 0).
    pub min_dissipation: Option<f64>,
}

/// What one solve measured.
struct Measured {
    stress_error: f64,
    /// `None` where the dimension has no exact traction to judge ([`SweepDimension`]).
    pressure_error: Option<f64>,
    force_balance: f64,
    load_error: Option<f64>,
    max_penetration: f64,
    rank_deficiency: Option<usize>,
    iterations: usize,
    termination: Termination,
    linear_solver: &'static str,
}

/// `max |sigma(u) - sigma_exact| / |p|` over the stiffness quadrature points of every body and
/// over `xx, yy, xy` (0 without an exact field; NaN kept).
pub(crate) fn stress_error(model: &Model, u: &[f64], pressure: f64) -> f64 {
    let mut stress_error = 0.0f64;
    if let Some(exact) = model.exact.as_ref() {
        for body in &model.bodies {
            for_each_quadrature_stress(body, u, |_, x, s| {
                let se = exact.stress(x);
                for i in 0..3 {
                    let e = (s[i] - se[i]).abs() / pressure.abs();
                    stress_error = if e.is_nan() || e > stress_error {
                        e
                    } else {
                        stress_error
                    };
                }
            });
        }
    }
    stress_error
}

/// The case's own force-balance tolerance (its `force_balance` check), 1e-12 if it declares
/// none.
pub(crate) fn balance_tol<const D: usize, K: SolidCell<D>>(model: &Model<D, K>) -> f64 {
    model
        .checks
        .iter()
        .find_map(|c| match c {
            crate::io::scene::Check::ForceBalance { tol } => Some(*tol),
            _ => None,
        })
        .unwrap_or(1e-12)
}

/// The total interaction force on the pass-1 slave bodies against the exact traction
/// integrated over the slave nodes that carry first-pass rows (`first_pass(pair, body, node)`),
/// relative to the load scale `|p|` x (that interface area): a zero exact force (parallel
/// stress across a tie) is judged too.
pub(crate) fn load_error(
    model: &Model,
    forces: &[PairForces],
    pressure: f64,
    first_pass: &dyn Fn(usize, usize, usize) -> bool,
) -> f64 {
    let exact = model.exact.as_ref();
    let (mut f, mut f_exact, mut length) = ([0.0f64; 2], [0.0f64; 2], 0.0f64);
    for pf in forces {
        f[0] += pf.on_slave[0];
        f[1] += pf.on_slave[1];
        for n in &pf.nodes {
            if !first_pass(pf.pair, n.body, n.node) {
                continue;
            }
            length += n.area;
            if let Some(e) = exact {
                let s = e.stress(model.bodies[n.body].mesh.nodes[n.node]);
                let nn = n.normal;
                f_exact[0] += n.area * (s[0] * nn[0] + s[2] * nn[1]);
                f_exact[1] += n.area * (s[2] * nn[0] + s[1] * nn[1]);
            }
        }
    }
    (f[0] - f_exact[0]).hypot(f[1] - f_exact[1]) / (pressure.abs() * length)
}

fn measure<const D: usize, K: SweepDimension<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
    pressure: f64,
) -> Measured {
    let stress_error = K::stress_error(model, &solution.u, pressure);
    let state = solution.contact.as_ref().expect("a contact solve");
    let forces = pair_forces(model, state);
    let mut first_pass = std::collections::HashSet::new();
    for r in state.rows.iter().filter(|r| r.pass == 1) {
        first_pass.insert((r.pair, r.slave_body, r.slave_node));
    }
    let (pressure_error, load_error) =
        K::traction_errors(model, solution, &forces, pressure, &|pair, body, node| {
            first_pass.contains(&(pair, body, node))
        });
    let max_penetration = forces
        .iter()
        .fold(0.0f64, |m, p| m.max(p.penetration.depth));
    Measured {
        stress_error,
        pressure_error,
        load_error,
        force_balance: crate::harness::checks::force_balance(model, solution, &forces),
        max_penetration,
        rank_deficiency: state.rank_deficiency,
        iterations: state.iterations,
        termination: state.termination.clone(),
        linear_solver: state.linear_solver,
    }
}

/// The largest difference between the stresses of `a` and `b` over the quadrature points of
/// every body, over `|p|`.
fn stress_difference(model: &Model, a: &Solution, b: &Solution, pressure: f64) -> f64 {
    let mut d = 0.0f64;
    for body in &model.bodies {
        let mut sa = Vec::new();
        for_each_quadrature_stress(body, &a.u, |_, _, s| sa.push(s));
        let mut k = 0;
        for_each_quadrature_stress(body, &b.u, |_, _, s| {
            for i in 0..3 {
                let e = (s[i] - sa[k][i]).abs() / pressure.abs();
                d = if e.is_nan() || e > d { e } else { d };
            }
            k += 1;
        });
    }
    d
}

/// What a sweep measures differently by dimension. 2D judges a cell against the case's exact
/// field (`exact`): the stress, the nodal contact tractions and the total interface force. 3D
/// has no exact field yet; its sweeps judge the stress against that of the case's
/// `uniform_stress_3d` check (required of a 3D sweep by [`crate::run3d::build3`]) and measure
/// no traction error.
pub trait SweepDimension<const D: usize>: RunDimension<D> {
    /// Poisson's ratio of the first body (the `nu` column of the tables).
    fn poisson(model: &Model<D, Self>) -> f64;

    /// `max |sigma(u) - sigma_exact| / |p|` over the stiffness quadrature points of every body
    /// and every stress component (0 without an exact stress; NaN kept).
    fn stress_error(model: &Model<D, Self>, u: &[f64], pressure: f64) -> f64;

    /// The largest difference between the stresses of `a` and `b` over the quadrature points
    /// of every body, over `|p|`.
    fn stress_difference(
        model: &Model<D, Self>,
        a: &Solution<D>,
        b: &Solution<D>,
        pressure: f64,
    ) -> f64;

    /// The nodal traction error and the total-force error against the exact traction
    /// ([`load_error`]; `first_pass(pair, body, node)` says which slave nodes carry first-pass
    /// rows), each `None` where the dimension has no exact traction.
    fn traction_errors(
        model: &Model<D, Self>,
        solution: &Solution<D>,
        forces: &[PairForces<D>],
        pressure: f64,
        first_pass: &dyn Fn(usize, usize, usize) -> bool,
    ) -> (Option<f64>, Option<f64>);

    /// The frictional patch test's measures ([`friction::measure`]); `None` where friction
    /// sweeps are not built (3D, refused by the model).
    fn friction_measure(
        model: &Model<D, Self>,
        solution: &Solution<D>,
        forces: &[PairForces<D>],
        expect: crate::io::scene::ExpectedFriction,
        pressure: f64,
    ) -> Option<friction::FrictionMeasured>;
}

impl SweepDimension<2> for ElementKind {
    fn poisson(model: &Model) -> f64 {
        model.bodies[0].material.nu
    }

    fn stress_error(model: &Model, u: &[f64], pressure: f64) -> f64 {
        stress_error(model, u, pressure)
    }

    fn stress_difference(model: &Model, a: &Solution, b: &Solution, pressure: f64) -> f64 {
        stress_difference(model, a, b, pressure)
    }

    fn traction_errors(
        model: &Model,
        solution: &Solution,
        forces: &[PairForces],
        pressure: f64,
        first_pass: &dyn Fn(usize, usize, usize) -> bool,
    ) -> (Option<f64>, Option<f64>) {
        let pressure_error = model
            .exact
            .as_ref()
            .map(|e| {
                crate::harness::checks::pressure_error(
                    model,
                    solution,
                    forces,
                    e,
                    None,
                    Some(pressure.abs()),
                )
            })
            .unwrap_or(f64::NAN);
        (
            Some(pressure_error),
            Some(load_error(model, forces, pressure, first_pass)),
        )
    }

    fn friction_measure(
        model: &Model,
        solution: &Solution,
        forces: &[PairForces],
        expect: crate::io::scene::ExpectedFriction,
        pressure: f64,
    ) -> Option<friction::FrictionMeasured> {
        Some(friction::measure(model, solution, forces, expect, pressure))
    }
}

impl SweepDimension<3> for SolidKind {
    fn poisson(model: &crate::model::Model3) -> f64 {
        model.bodies[0].material.nu
    }

    fn stress_error(model: &crate::model::Model3, u: &[f64], pressure: f64) -> f64 {
        let Some(exact) = crate::run3d::sweep_stress3(model) else {
            return 0.0;
        };
        let mut error = 0.0f64;
        for body in &model.bodies {
            for (_, s) in crate::run3d::body_stresses(body, u) {
                for i in 0..6 {
                    let e = (s[i] - exact[i]).abs() / pressure.abs();
                    error = if e.is_nan() || e > error { e } else { error };
                }
            }
        }
        error
    }

    fn stress_difference(
        model: &crate::model::Model3,
        a: &Solution<3>,
        b: &Solution<3>,
        pressure: f64,
    ) -> f64 {
        let mut d = 0.0f64;
        for body in &model.bodies {
            let sa = crate::run3d::body_stresses(body, &a.u);
            let sb = crate::run3d::body_stresses(body, &b.u);
            for ((_, x), (_, y)) in sa.iter().zip(&sb) {
                for i in 0..6 {
                    let e = (x[i] - y[i]).abs() / pressure.abs();
                    d = if e.is_nan() || e > d { e } else { d };
                }
            }
        }
        d
    }

    fn traction_errors(
        _model: &crate::model::Model3,
        _solution: &Solution<3>,
        _forces: &[PairForces<3>],
        _pressure: f64,
        _first_pass: &dyn Fn(usize, usize, usize) -> bool,
    ) -> (Option<f64>, Option<f64>) {
        (None, None)
    }

    fn friction_measure(
        _model: &crate::model::Model3,
        _solution: &Solution<3>,
        _forces: &[PairForces<3>],
        _expect: crate::io::scene::ExpectedFriction,
        _pressure: f64,
    ) -> Option<friction::FrictionMeasured> {
        None
    }
}

/// Run the sweep of one case file, 2D or 3D.
pub fn run_sweep(path: &Path, progress: &mut dyn FnMut(&str)) -> Result<Vec<Cell>> {
    match crate::run3d::read_3d_case(path) {
        Some(case) => {
            let model = crate::run3d::build3(&case, &path.display().to_string())?;
            crate::model::admit::check_rigid_modes(&model)?;
            sweep_model(&model, progress)
        }
        None => sweep_model(&load(path)?, progress),
    }
}

/// Run the sweep of a built model (nothing when it has none): every discretization x
/// enforcement of the sweep on the model's first contact pair, each cell judged.
pub fn sweep_model<const D: usize, K: SweepDimension<D>>(
    base: &Model<D, K>,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<Cell>> {
    let Some(sweep) = base.sweep.clone() else {
        return Ok(Vec::new());
    };
    let nu = K::poisson(base);
    let pair0 = base.contact[0].clone();
    let mut cells = Vec::new();
    for d in &sweep.discretizations {
        let slave_name = d.slave.clone();
        let mut pair = pair0.clone();
        if let Some(s) = &slave_name {
            if base.bodies[pair.slave.0].name != *s {
                pair = pair
                    .swapped()
                    .expect("validated: the slave is a body of the pair");
            }
        }
        pair.discretization = d.discretization.clone();
        let (disc_name, passes, slave) = match &d.discretization {
            DiscretizationSpec::NodeToNode => (
                "node_to_node",
                None,
                Some(base.bodies[pair.slave.0].name.clone()),
            ),
            DiscretizationSpec::NodeToSurface { passes: 2, .. } => {
                ("node_to_surface", Some(2), None)
            }
            DiscretizationSpec::NodeToSurface { passes, .. } => (
                "node_to_surface",
                Some(*passes),
                Some(base.bodies[pair.slave.0].name.clone()),
            ),
            DiscretizationSpec::Mortar { multiplier } => (
                match multiplier {
                    MultiplierSpace::Standard => "mortar",
                    MultiplierSpace::Dual => "dual_mortar",
                },
                None,
                Some(base.bodies[pair.slave.0].name.clone()),
            ),
        };
        // each enforcement with the case's friction tangent, and the augmented Lagrangian again
        // with each further tangent of the sweep (a column of its own)
        let variants: Vec<(&EnforcementSpec, Option<FrictionTangent>)> = sweep
            .enforcements
            .iter()
            .flat_map(|e| {
                let augmented = matches!(e, EnforcementSpec::AugmentedLagrange { .. });
                std::iter::once((e, None)).chain(
                    sweep
                        .friction_tangents
                        .iter()
                        .filter(move |_| augmented)
                        .map(move |&t| (e, Some(t))),
                )
            })
            .collect();
        for &(e, tangent) in &variants {
            let enforcement_name = match tangent {
                Some(t) => format!("{}+{}", method(e).name(), t.name()),
                None => method(e).name().to_string(),
            };
            progress(&format!(
                "{} {disc_name} {} {enforcement_name}",
                sweep.mesh,
                passes.map(|p| format!("{p}p")).unwrap_or_default(),
            ));
            let mut cell = Cell {
                dimension: D as u8,
                nu,
                discretization: disc_name.into(),
                passes,
                slave: slave.clone(),
                enforcement: enforcement_name,
                kappa: method(e).kappa(),
                pressure: sweep.pressure,
                friction: sweep.expect.map(|x| FrictionCell {
                    expect: friction::name(x).into(),
                    statuses: None,
                    tangential_error: None,
                    cone_ratio: None,
                    min_dissipation: None,
                }),
                ..Cell::unmeasured(
                    sweep.catalogue,
                    base.name.clone(),
                    sweep.mesh.clone(),
                    sweep.tol,
                )
            };
            let mut model = base.clone();
            if let Some(t) = tangent {
                model.solver.friction_tangent = t;
            }
            pair.enforcement = e.clone();
            model.contact = vec![pair.clone()];
            if let Some(why) = friction::obstacle(&model, &pair) {
                cell.note = why;
                cells.push(cell);
                continue;
            }
            let rows = match K::pair_rows(&model, &pair) {
                Ok(r) => r,
                Err(why) => {
                    cell.note = why;
                    cells.push(cell);
                    continue;
                }
            };
            let sites: Vec<crate::contact::RowSite> = rows.iter().map(|r| r.site()).collect();
            if let Some(why) = method(e).obstacle(&sites, &model.prescribed) {
                cell.note = why;
                cells.push(cell);
                continue;
            }
            let start = Instant::now();
            let solved = K::solve(&model, &mut |_| {});
            cell.time_ms = Some(start.elapsed().as_secs_f64() * 1e3);
            let mut frictional = None;
            let m = match solved {
                Ok(s) => {
                    // the perturbed Lagrangian with a consistent multiplier mass against the
                    // penalty method at the same kappa
                    if let (true, Some(kappa)) = (
                        method(e).uses_multiplier_mass() && rows.iter().any(|r| !r.mass.is_empty()),
                        method(e).kappa(),
                    ) {
                        let mut penalty = model.clone();
                        penalty.contact[0].enforcement = EnforcementSpec::Penalty { kappa };
                        let start = Instant::now();
                        cell.vs_penalty = Some(match K::solve(&penalty, &mut |_| {}) {
                            Ok(p) => K::stress_difference(&model, &s, &p, sweep.pressure),
                            Err(_) => f64::NAN,
                        });
                        *cell.time_ms.get_or_insert(0.0) += start.elapsed().as_secs_f64() * 1e3;
                    }
                    if let Some(expect) = sweep.expect {
                        let state = s.contact.as_ref().expect("a contact solve");
                        let forces = pair_forces(&model, state);
                        frictional =
                            K::friction_measure(&model, &s, &forces, expect, sweep.pressure);
                    }
                    measure(&model, &s, sweep.pressure)
                }
                Err(err) => {
                    cell.verdict = "fail".into();
                    cell.note = format!(
                        "no solution: {}",
                        err.to_string().lines().next().unwrap_or_default()
                    );
                    cells.push(cell);
                    continue;
                }
            };
            cell.stress_error = Some(m.stress_error);
            cell.pressure_error = m.pressure_error;
            cell.force_balance = Some(m.force_balance);
            cell.load_error = m.load_error;
            cell.max_penetration = Some(m.max_penetration);
            cell.rank_deficiency = m.rank_deficiency;
            cell.newton_iterations = Some(m.iterations);
            cell.linear_solver = Some(m.linear_solver.to_string());
            cell.termination = Some(match &m.termination {
                Termination::Singular(_) => "singular".into(),
                t => serde_json::to_value(t)
                    .ok()
                    .and_then(|v| v.as_str().map(String::from))
                    .unwrap_or_default(),
            });
            let converged = m.termination == Termination::Converged;
            let mut notes = Vec::new();
            if let Some(d) = cell.vs_penalty {
                let same = d <= sweep.tol;
                notes.push(format!(
                    "multipliers with the consistent mortar mass (non-diagonal C): stress differs from penalty's by {}{}",
                    rounded(Some(d)),
                    if same && m.pressure_error.is_some_and(|e| e <= sweep.tol) {
                        " (the interface traction is uniform, where the two coincide)"
                    } else {
                        ""
                    }
                ));
            }
            if let Termination::Singular(msg) = &m.termination {
                notes.push(msg.clone());
            } else if !converged {
                notes.push(format!("the active-set loop ended by {:?}", m.termination));
            }
            // the case's own force-balance tolerance (its `force_balance` check), 1e-12 if it
            // declares none
            let balance_tol = balance_tol(&model);
            let balanced = m.force_balance <= balance_tol;
            if !balanced {
                notes.push(format!("force balance {:.1e}", m.force_balance));
            }
            let multipliers = method(e).has_multiplier_system();
            let dependent = m.rank_deficiency.unwrap_or(0);
            let unique = dependent == 0;
            cell.stability = match (multipliers, unique) {
                (false, _) => "-".into(),
                (true, true) => "stable".into(),
                (true, false) => "unstable".into(),
            };
            if !unique {
                notes.push(if multipliers {
                    format!("multipliers not unique: {dependent} dependent constraints (fails stability)")
                } else {
                    format!("{dependent} dependent constraints (no multiplier system for them to make singular)")
                });
            }
            // where the dimension measures no exact traction, the stress alone judges
            let loaded = m.load_error.is_none_or(|e| e <= sweep.tol);
            if let (false, Some(e)) = (loaded, m.load_error) {
                notes.push(format!("total contact force off by {e:.1e}"));
            }
            let pass = if let (Some(k), true) = (method(e).kappa(), method(e).penalty_like()) {
                let mut stiff = model.clone();
                stiff.contact[0].enforcement = method(e).scaled(sweep.penalty_factor);
                let start = Instant::now();
                let s2 = K::solve(&stiff, &mut |_| {});
                *cell.time_ms.get_or_insert(0.0) += start.elapsed().as_secs_f64() * 1e3;
                let e2 = match s2 {
                    Ok(s) => {
                        let m2 = measure(&stiff, &s, sweep.pressure);
                        if m2.termination == Termination::Converged {
                            m2.stress_error
                        } else {
                            f64::INFINITY
                        }
                    }
                    Err(_) => f64::INFINITY,
                };
                cell.stress_error_stiff = Some(e2);
                let trend = if m.stress_error <= sweep.tol && e2 <= sweep.tol {
                    "round-off"
                } else if e2 * sweep.penalty_factor / 10.0 <= m.stress_error {
                    "1/kappa"
                } else {
                    "no fall"
                };
                cell.penalty_trend = Some(trend.into());
                notes.push(format!(
                    "kappa = {k:e}: stress error {trend} as kappa grows {}x",
                    sweep.penalty_factor
                ));
                if cell.passes == Some(2) {
                    notes.push(match model.contact[0].two_pass_penalty {
                        TwoPassPenalty::Full => "two-pass penalty full: kappa on each pass".into(),
                        TwoPassPenalty::Halved => {
                            format!(
                                "two-pass penalty halved: kappa/2 = {:e} on each pass",
                                k / 2.0
                            )
                        }
                    });
                }
                converged && balanced && loaded && trend != "no fall"
            } else {
                // the pressures come from the nodal forces B^T lambda, unique even where the
                // multipliers of dependent rows are not, so they are judged for every cell
                converged
                    && balanced
                    && loaded
                    && m.stress_error <= sweep.tol
                    && m.pressure_error.is_none_or(|e| e <= sweep.tol)
            };
            // the frictional patch test: statuses, Coulomb's inequality, dissipation and, for
            // the methods judged on their multipliers, the tangential traction
            let friction_pass = match (&frictional, sweep.expect, cell.friction.as_mut()) {
                (Some(f), Some(expect), Some(fc)) => {
                    fc.statuses = Some(f.statuses(expect));
                    fc.tangential_error = Some(f.tangential_error);
                    fc.cone_ratio = Some(f.cone_ratio);
                    fc.min_dissipation = Some(f.min_dissipation);
                    let exact = !method(e).penalty_like();
                    if exact && f.tangential_error > sweep.tol {
                        notes.push(format!(
                            "tangential traction off by {:.1e} p",
                            f.tangential_error
                        ));
                    }
                    notes.extend(f.notes(expect));
                    f.passes(exact, sweep.tol)
                }
                _ => true,
            };
            cell.verdict = if pass && friction_pass {
                "pass"
            } else {
                "fail"
            }
            .into();
            cell.note = notes.join("; ");
            cells.push(cell);
        }
    }
    Ok(cells)
}

/// Round an error for the snapshot: `0` below `1e-10` (round-off), else one significant digit.
pub fn rounded(e: Option<f64>) -> String {
    match e {
        None => "-".into(),
        Some(v) if v.is_nan() => "NaN".into(),
        Some(v) if v.is_infinite() => "inf".into(),
        Some(v) if v < 1e-10 => "0".into(),
        Some(v) => format!("{v:.0e}"),
    }
}

fn short(v: &str) -> &str {
    match v {
        "pass" => "p",
        "fail" => "f",
        _ => "n/a",
    }
}

/// The seed's verdict row at one `nu`, from the Lagrange-multiplier cells.
pub fn seed_row(cells: &[Cell], nu: f64) -> Vec<(String, String)> {
    let find = |mesh: &str, passes: u8, slave: Option<&str>| {
        cells
            .iter()
            .find(|c| {
                c.mesh == mesh
                    && c.nu == nu
                    && c.enforcement == "lagrange"
                    && c.passes == Some(passes)
                    && c.slave.as_deref() == slave
            })
            .map(|c| short(&c.verdict).to_string())
    };
    let one_pass = |mesh: &str| {
        let a = find(mesh, 1, Some("punch"));
        let b = find(mesh, 1, Some("foundation"));
        match (a, b) {
            (Some(a), Some(b)) if a == b => a,
            (Some(a), Some(b)) => format!("{a}/{b}"),
            _ => "?".into(),
        }
    };
    let two_pass = |mesh: &str| find(mesh, 2, None).unwrap_or_else(|| "?".into());
    vec![
        ("A".into(), one_pass("A")),
        ("B-1p".into(), one_pass("B")),
        ("B-2p".into(), two_pass("B")),
        ("C-1p".into(), one_pass("C")),
        ("C-2p".into(), two_pass("C")),
        ("D".into(), one_pass("D")),
        ("E".into(), one_pass("E")),
    ]
}

/// The seed's published row (Taylor 2004, "1991: The Contact Patch Test").
pub const SEED_ROW: [(&str, &str); 7] = [
    ("A", "p"),
    ("B-1p", "p/f"),
    ("B-2p", "p"),
    ("C-1p", "f"),
    ("C-2p", "p"),
    ("D", "p"),
    ("E", "f"),
];

/// A cell's time for the times file: milliseconds to two decimals, `-` when nothing was
/// timed (an `n/a` cell, another code's results).
pub fn time_text(time_ms: Option<f64>) -> String {
    time_ms
        .map(|t| format!("{t:.2}"))
        .unwrap_or_else(|| "-".into())
}

/// The full grid as a Markdown table: verdicts and errors, no wall times (those go to
/// `<catalogue>-table.times.csv`, [`crate::harness::report::times_csv`]).
pub fn grid_markdown(cells: &[Cell]) -> String {
    let mut s = String::from("| mesh | nu | discretization | passes | slave | enforcement | verdict | stress error | at 1000 kappa | trend | pressure error | load error | rank def. | stability | iterations |");
    s += " note |\n";
    s += "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|";
    s += "---|\n";
    for c in cells {
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            c.mesh,
            c.nu,
            c.discretization,
            c.passes.map(|p| p.to_string()).unwrap_or("-".into()),
            c.slave.as_deref().unwrap_or("-"),
            c.enforcement,
            c.verdict,
            rounded(c.stress_error),
            rounded(c.stress_error_stiff),
            c.penalty_trend.as_deref().unwrap_or("-"),
            rounded(c.pressure_error),
            rounded(c.load_error),
            c.rank_deficiency
                .map(|r| r.to_string())
                .unwrap_or("-".into()),
            c.stability,
            c.newton_iterations
                .map(|r| r.to_string())
                .unwrap_or("-".into()),
        );
        s += &format!(" {} |\n", c.note.replace('|', "/"));
    }
    s
}
