//! The contact patch test at finite strain (issue 12): meshes A-E of the patch catalogue
//! (`shared/design/benchmarks.md` s. 1, `cases/patch/`), both bodies neo-Hookean and
//! compressed by 20 % across a frictionless flat interface, where the homogeneous deformation
//! `F = diag(a, 0.8)` is exact. `reports/finite-patch-table.md` and `.json`, written by
//! `contact-patch finite-patch`.
//!
//! **The exact state.** Neo-Hookean, `sigma = (mu (b - I) + lambda ln J I) / J` with
//! `b = F F^T`, `J = det F`. With `F = diag(a, s)` and `sigma_xx = 0` (the free sides),
//! `mu (a^2 - 1) + lambda ln(a s) = 0` fixes `a` (solved by bisection: the left side grows
//! with `a`), and `sigma_yy = (mu (s^2 - 1) + lambda ln(a s)) / (a s)`.
//!
//! **The case.** The catalogue's case of each mesh (`nu = 0.3`) with
//! `physics: {kinematics: "finite", contact_geometry: "current"}` and Newton in 4 load steps
//! along the homogeneous states of 5, 10, 15 and 20 % compression:
//! - the foundation's exposed top carries the nominal (dead) pressure `p = -a sigma_yy` of
//!   each state;
//! - the punch's top is moved down to where that state puts it (`-7 c`, the punch is 7 tall,
//!   less the penalty's uniform penetration `p / (passes kappa)`), and its top-left corner is
//!   held in x where the state puts it (`4 (a - 1)`), so the ends of the interface stay aligned
//!   (a dead load on the punch's top tips the punch, pinned at one corner on a frictionless
//!   interface, over before 20 %).
//!
//! **The verdict.** A cell passes when Newton converges and the Cauchy stress of every
//! quadrature point of both bodies is `[0, sigma_yy, 0]` to `1e-10 |sigma_yy|`, and `F` is
//! exact to `1e-10` at every quadrature point. Each cell also gives the small-strain verdict of
//! the same mesh, discretization and enforcement (the catalogue case as written, reference
//! geometry, a separate code path).
//!
//! **The stability of the exact state.** For every cell whose small-strain test passes, the
//! exact state is an equilibrium of the discrete system (its residual relative to the largest
//! internal force is reported). Its stability is the inertia of the symmetric tangent there
//! (Sylvester): the number of negative pivots of `L D L^T` without pivoting, the directions in
//! which the energy decreases. For a penalty cell, the tangent of its own penalty; for a
//! Lagrange cell, that of a penalty of `kappa = 1e8` (`STIFF_PENALTY`): as `kappa` grows, the
//! penalty tangent `K - lambda H + kappa B^T B` has the negative directions of the constrained
//! problem (`K - lambda H` on the null space of `B`) and no others. A penalty cell with an
//! unstable direction is at a bifurcation before 20 % and converges elsewhere or not at all;
//! Newton with Lagrange multipliers can converge to an unstable equilibrium, and the report
//! shows where it does.

use crate::error::{Error, Result};
use crate::model::{parse, Model};
use crate::post::{cell_displacements, for_each_quadrature_stress};
use crate::run::run_model;
use crate::solid_finite::deformation_gradient_at;
use crate::solver::contact_newton::Probe;
use serde::Serialize;
use serde_json::{json, Value};
use std::path::Path;
use std::time::Instant;

/// The meshes of the catalogue.
pub const MESHES: [&str; 5] = ["A", "B", "C", "D", "E"];

/// The compression at the last load step.
const COMPRESSION: f64 = 0.2;
/// Load steps along the homogeneous states.
const STEPS: usize = 4;
/// The punch's height (the catalogue's punch spans y in [5, 12]).
const PUNCH_HEIGHT: f64 = 7.0;
/// The x of the punch's left side (the catalogue's punch spans x in [4, 6]).
const PUNCH_LEFT: f64 = 4.0;
/// The penalty that stands for Lagrange multipliers in the stability of the exact state.
pub const STIFF_PENALTY: f64 = 1e8;
/// Pass tolerance of the stress (relative to `|sigma_yy|`) and of `F`.
pub const TOLERANCE: f64 = 1e-10;

/// One discretization of the table: a label, the pair's discretization as written in a case
/// file, and the body that is the slave.
#[derive(Clone, Debug)]
pub struct PatchDiscretization {
    pub label: &'static str,
    pub spec: Value,
    pub slave: &'static str,
}

/// The discretizations of the table: node-to-surface with master normals (`node_to_segment`),
/// with slave normals in the consistent and the smooth-sliding form and node-to-node
/// (`nodal_normal`), standard and dual mortar (`mortar_linearization`). A discretization that
/// does not apply to a mesh (node-to-node on non-matching interfaces) is listed with the
/// model's reason.
pub fn discretizations() -> Vec<PatchDiscretization> {
    let nts = |label, spec, slave| PatchDiscretization { label, spec, slave };
    let slave_normals = |passes: u8, form: &str| json!({"kind": "node_to_surface", "passes": passes, "normal": "slave", "slave_normal_variation": form});
    vec![
        nts(
            "node-to-surface 1p, punch slave",
            json!({"kind": "node_to_surface", "passes": 1}),
            "punch",
        ),
        nts(
            "node-to-surface 1p, foundation slave",
            json!({"kind": "node_to_surface", "passes": 1}),
            "foundation",
        ),
        nts(
            "node-to-surface 2p",
            json!({"kind": "node_to_surface", "passes": 2}),
            "punch",
        ),
        nts(
            "slave normals 1p, punch slave",
            slave_normals(1, "consistent"),
            "punch",
        ),
        nts(
            "slave normals 1p, foundation slave",
            slave_normals(1, "consistent"),
            "foundation",
        ),
        nts("slave normals 2p", slave_normals(2, "consistent"), "punch"),
        nts(
            "slave normals smooth sliding 1p, punch slave",
            slave_normals(1, "smooth_sliding"),
            "punch",
        ),
        nts(
            "slave normals smooth sliding 1p, foundation slave",
            slave_normals(1, "smooth_sliding"),
            "foundation",
        ),
        nts(
            "slave normals smooth sliding 2p",
            slave_normals(2, "smooth_sliding"),
            "punch",
        ),
        nts("node-to-node", json!({"kind": "node_to_node"}), "punch"),
        nts(
            "mortar standard",
            json!({"kind": "mortar", "multiplier": "standard"}),
            "punch",
        ),
        nts(
            "mortar dual",
            json!({"kind": "mortar", "multiplier": "dual"}),
            "punch",
        ),
    ]
}

/// The enforcement methods of the table (as written in a case file). Lagrange multipliers of
/// two passes are dependent rows (the small-strain table shows their rank deficiency), so the
/// two-pass cells run the penalty only.
pub fn enforcements(discretization: &PatchDiscretization) -> Vec<Value> {
    let lagrange = json!({"kind": "lagrange"});
    let penalty = json!({"kind": "penalty", "kappa": 1e4});
    if discretization.spec["passes"].as_u64() == Some(2) {
        vec![penalty]
    } else {
        vec![lagrange, penalty]
    }
}

/// How the finite-strain solve of a cell ended.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum FiniteOutcome {
    /// Newton converged in every load step: the largest Cauchy stress error of both bodies
    /// (relative to `|sigma_yy|`, the uniform-stress check included) and the largest
    /// deviation of `F` from `diag(a, 0.8)` over every quadrature point.
    Converged {
        stress_error: f64,
        deformation_gradient_error: f64,
        /// Newton iterations per load step (cut steps included).
        iterations: Vec<usize>,
    },
    /// The solve stopped; the solver's message.
    Stopped { reason: String },
}

/// One cell of the table.
#[derive(Clone, Debug, Serialize)]
pub struct FinitePatchCell {
    pub mesh: String,
    pub discretization: String,
    pub slave: String,
    pub enforcement: String,
    /// The small-strain stress error of the same cell (relative to the load); `None` where
    /// the discretization does not apply to the mesh (see `not_applicable`).
    pub small_strain_error: Option<f64>,
    pub small_strain_pass: bool,
    /// Why the discretization does not apply to the mesh (the model's message), if it does not.
    pub not_applicable: Option<String>,
    pub finite: FiniteOutcome,
    pub finite_pass: bool,
    /// Penalty cells whose small-strain test passes: the residual of the discrete system at
    /// the exact state (relative to the largest internal force) and the number of negative
    /// pivots of its symmetric tangent there.
    pub exact_state: Option<ExactState>,
    /// Wall-clock time of the finite-strain solve.
    pub seconds: f64,
}

/// The discrete system at the exact homogeneous state.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ExactState {
    pub residual: f64,
    pub unstable_directions: usize,
    /// The most negative pivots of the tangent with the punch moved `SIDEWAYS` to either side
    /// of the exact state (not an equilibrium there): where the gap's second derivative jumps
    /// at the exact state (a slave node on a master node), its inertia on either side.
    pub unstable_directions_beside: usize,
}

/// How far the punch is moved sideways to probe the tangent beside the exact state.
pub const SIDEWAYS: f64 = 1e-7;

/// The exact state's residual and the inertia of the tangent at it and beside it.
fn stability(model: &Model, a: f64, shift: f64) -> Result<ExactState> {
    let (residual, unstable_directions) = inertia(model, a, shift, 0.0)?;
    let left = inertia(model, a, shift, -SIDEWAYS)?.1;
    let right = inertia(model, a, shift, SIDEWAYS)?.1;
    Ok(ExactState {
        residual,
        unstable_directions,
        unstable_directions_beside: left.max(right),
    })
}

/// `a` with `sigma_xx = 0` for `F = diag(a, stretch)` of the neo-Hookean law with Lamé
/// constants `lambda`, `mu`, and `sigma_yy` there.
pub fn uniaxial_state(lambda: f64, mu: f64, stretch: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (1.0, 3.0);
    for _ in 0..200 {
        let m = 0.5 * (lo + hi);
        if mu * (m * m - 1.0) + lambda * (stretch * m).ln() > 0.0 {
            hi = m;
        } else {
            lo = m;
        }
    }
    let a = 0.5 * (lo + hi);
    let j = stretch * a;
    (a, (mu * (stretch * stretch - 1.0) + lambda * j.ln()) / j)
}

/// The catalogue's case of `mesh` (`nu = 0.3`) with its pair replaced by `discretization`
/// and `enforcement` (the slave and master swapped when the foundation is the slave); the
/// small-strain case as written, its sweep removed.
fn catalogue_case(
    root: &Path,
    mesh: &str,
    discretization: &PatchDiscretization,
    enforcement: &Value,
) -> Result<Value> {
    let path = root.join(format!("cases/patch/patch-{mesh}-nu0.3.json"));
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(&path).map_err(|source| Error::Io {
        path: shown.clone(),
        action: "reading the patch catalogue",
        source,
    })?;
    let mut v: Value = serde_json::from_str(&text).map_err(|e| {
        Error::invalid(
            &shown,
            "the file",
            format!("not JSON ({e})"),
            "regenerate the catalogue with `python3 cases/patch/make_cases.py`",
        )
    })?;
    // the cell's pair replaces the case's: the case's expected failures are statements about
    // its own pair, and go with it
    if let Some(o) = v.as_object_mut() {
        o.remove("sweep");
        o.remove("expected_failures");
    }
    let pair = &mut v["contact"][0];
    // the small-strain rows have one linearization: the choice of the finite-strain form of
    // slave normals is refused there
    pair["discretization"] = discretization.spec.clone();
    if let Some(d) = pair["discretization"].as_object_mut() {
        d.remove("slave_normal_variation");
    }
    pair["enforcement"] = enforcement.clone();
    if discretization.slave == "foundation" {
        let (s, m) = (pair["slave"].clone(), pair["master"].clone());
        pair["slave"] = m;
        pair["master"] = s;
    }
    Ok(v)
}

/// The Lamé constants of the catalogue's material `m`.
fn lame(case: &Value) -> Result<(f64, f64)> {
    let m = &case["materials"]["m"];
    let (Some(e), Some(nu)) = (m["E"].as_f64(), m["nu"].as_f64()) else {
        return Err(Error::invalid(
            "cases/patch",
            "materials.m",
            "the patch catalogue's material `m` has no E and nu",
            "regenerate the catalogue with `python3 cases/patch/make_cases.py`",
        ));
    };
    Ok((
        e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        e / (2.0 * (1.0 + nu)),
    ))
}

/// How many cells the table has.
pub fn cell_count() -> usize {
    MESHES.len()
        * discretizations()
            .iter()
            .map(|d| enforcements(d).len())
            .sum::<usize>()
}

/// Run every cell of the table (`root`: the repository, for `cases/patch/`).
pub fn run(root: &Path, progress: &mut dyn FnMut(&str)) -> Result<Vec<FinitePatchCell>> {
    let mut cells = Vec::new();
    for mesh in MESHES {
        for d in discretizations() {
            for enforcement in enforcements(&d) {
                cells.push(cell(root, mesh, &d, &enforcement)?);
                progress(&format!("{mesh} {} {}", d.label, enforcement["kind"]));
            }
        }
    }
    Ok(cells)
}

/// The stress error of a small-strain run.
fn small_strain_error(case: &Value) -> Result<f64> {
    let model = Model::build(&parse(&case.to_string(), "patch")?, "patch")?;
    let outcome = run_model(model, 0.0, Instant::now(), &mut |_| {})?;
    outcome
        .checks
        .iter()
        .find(|c| c.check.starts_with("uniform stress"))
        .map(|c| c.error)
        .ok_or_else(|| {
            Error::invalid(
                "cases/patch",
                "checks",
                "the patch catalogue's case has no uniform_stress check",
                "regenerate the catalogue with `python3 cases/patch/make_cases.py`",
            )
        })
}

/// The homogeneous state at the last load step and the finite-strain case that follows the
/// homogeneous states to it.
struct FiniteCase {
    case: Value,
    /// `F_xx` of the exact state.
    a: f64,
    sigma_yy: f64,
    /// How far the punch is lowered besides the compression (the penalty's penetration).
    penetration: f64,
}

/// The finite-strain case of `small_case` with `enforcement` on its pair.
fn finite_case(
    small_case: &Value,
    discretization: &PatchDiscretization,
    enforcement: &Value,
) -> Result<FiniteCase> {
    let (lambda, mu) = lame(small_case)?;
    // the homogeneous state after each load step k: F = diag(a_k, 1 - 0.2 k / STEPS), the
    // nominal pressure p_k = -a_k sigma_yy, the punch's top-left corner at 4 (a_k - 1) in x
    // and its top at -7 c_k - p_k / (passes kappa) in y (the penalty's uniform penetration:
    // both passes' rows press)
    let passes = discretization.spec["passes"].as_f64().unwrap_or(1.0);
    let states: Vec<(f64, f64, f64, f64)> = (1..=STEPS)
        .map(|k| {
            let compression = COMPRESSION * k as f64 / STEPS as f64;
            let (a, sigma_yy) = uniaxial_state(lambda, mu, 1.0 - compression);
            let p = -a * sigma_yy;
            let penetration = enforcement["kappa"]
                .as_f64()
                .map_or(0.0, |kappa| p / (passes * kappa));
            (
                p,
                PUNCH_LEFT * (a - 1.0),
                -PUNCH_HEIGHT * compression - penetration,
                a,
            )
        })
        .collect();
    let (p, pin, top, a) = states[STEPS - 1];
    let sigma_yy = -p / a;
    let path = |pick: fn(&(f64, f64, f64, f64)) -> f64, last: f64| -> Vec<f64> {
        states.iter().map(|s| pick(s) / last).collect()
    };
    let mut v = small_case.clone();
    v["contact"][0]["enforcement"] = enforcement.clone();
    v["contact"][0]["discretization"] = discretization.spec.clone();
    v["materials"]["m"]["model"] = json!("neo_hookean");
    v["physics"] = json!({"kinematics": "finite", "contact_geometry": "current"});
    v["solver"] = json!({"scheme": "newton", "load_steps": STEPS});
    let pressure_path = path(|s| s.0, p);
    v["loads"] = json!([
        {"body": "foundation", "set": "exposed_left", "pressure": p, "path": pressure_path},
        {"body": "foundation", "set": "exposed_right", "pressure": p, "path": pressure_path}
    ]);
    v["supports"] = json!([
        {"body": "foundation", "set": "bottom", "y": 0.0},
        {"body": "foundation", "set": "bottom_left", "x": 0.0},
        {"body": "punch", "set": "top_left", "x": pin, "path": path(|s| s.1, pin)},
        {"body": "punch", "set": "top", "y": top, "path": path(|s| s.2, top)}
    ]);
    if let Some(o) = v.as_object_mut() {
        o.remove("exact");
    }
    v["checks"] = json!([
        {"check": "uniform_stress", "stress": [0.0, sigma_yy, 0.0], "tol": TOLERANCE},
        {"check": "force_balance", "tol": TOLERANCE}
    ]);
    Ok(FiniteCase {
        case: v,
        a,
        sigma_yy,
        penetration: -(top + PUNCH_HEIGHT * COMPRESSION),
    })
}

/// The finite-strain case file of a cell (to run it alone: `contact-patch run`).
pub fn case(
    root: &Path,
    mesh: &str,
    discretization: &PatchDiscretization,
    enforcement: &Value,
) -> Result<Value> {
    let small_case = catalogue_case(root, mesh, discretization, enforcement)?;
    Ok(finite_case(&small_case, discretization, enforcement)?.case)
}

/// One cell: the small-strain verdict, the finite-strain solve and, for penalty cells, the
/// discrete system at the exact state.
pub fn cell(
    root: &Path,
    mesh: &str,
    discretization: &PatchDiscretization,
    enforcement: &Value,
) -> Result<FinitePatchCell> {
    let small_case = catalogue_case(root, mesh, discretization, enforcement)?;
    let small_strain_error = match small_strain_error(&small_case) {
        Ok(error) => error,
        // the discretization does not apply to this mesh (node-to-node on non-matching nodes)
        Err(e @ Error::Invalid { .. }) => {
            return Ok(FinitePatchCell {
                mesh: mesh.into(),
                discretization: discretization.label.into(),
                slave: discretization.slave.into(),
                enforcement: enforcement["kind"].as_str().unwrap_or("?").into(),
                small_strain_error: None,
                small_strain_pass: false,
                not_applicable: Some(e.to_string()),
                finite: FiniteOutcome::Stopped {
                    reason: "the discretization does not apply".into(),
                },
                finite_pass: false,
                exact_state: None,
                seconds: 0.0,
            })
        }
        Err(e) => return Err(e),
    };
    let small_strain_pass = small_strain_error <= TOLERANCE;
    let FiniteCase {
        case,
        a,
        sigma_yy,
        penetration,
    } = finite_case(&small_case, discretization, enforcement)?;
    let model = Model::build(&parse(&case.to_string(), "patch")?, "patch")?;
    // the stability of the exact state: the penalty's tangent there; for Lagrange multipliers
    // that of a penalty stiff enough to stand for the constraint (the inertia of the
    // constrained problem is the penalty tangent's as kappa grows)
    let exact_state = if !small_strain_pass {
        None
    } else if enforcement["kind"] == "penalty" {
        Some(stability(&model, a, -penetration)?)
    } else {
        let stiff = json!({"kind": "penalty", "kappa": STIFF_PENALTY});
        let probe = finite_case(&small_case, discretization, &stiff)?;
        let model = Model::build(&parse(&probe.case.to_string(), "patch")?, "patch")?;
        Some(stability(&model, a, -probe.penetration)?)
    };
    let start = Instant::now();
    let solved = run_model(model, 0.0, start, &mut |_| {});
    let seconds = start.elapsed().as_secs_f64();
    let finite = match solved {
        Err(e) => FiniteOutcome::Stopped {
            reason: e.to_string(),
        },
        Ok(o) => {
            let check = o
                .checks
                .iter()
                .find(|c| c.check.starts_with("uniform stress"))
                .map_or(f64::INFINITY, |c| c.error);
            let target = [a, 0.0, 0.0, 1.0 - COMPRESSION];
            let mut spread = 0.0f64;
            let mut worst = 0.0f64;
            let mut ue = Vec::new();
            for body in &o.model.bodies {
                for c in 0..body.mesh.cell_count() {
                    cell_displacements(body, &o.solution.u, c, &mut ue);
                    for q in body.mesh.kind.stiffness_rule() {
                        let (f, _) = deformation_gradient_at(
                            body.mesh.kind,
                            &body.mesh.cell_coords(c),
                            &ue,
                            q.xi,
                        );
                        let f = [f[(0, 0)], f[(0, 1)], f[(1, 0)], f[(1, 1)]];
                        for i in 0..4 {
                            spread = spread.max((f[i] - target[i]).abs());
                        }
                    }
                }
                for_each_quadrature_stress(body, &o.solution.u, |_, _, s| {
                    let exact = [0.0, sigma_yy, 0.0];
                    for i in 0..3 {
                        worst = worst.max((s[i] - exact[i]).abs() / sigma_yy.abs());
                    }
                });
            }
            FiniteOutcome::Converged {
                stress_error: check.max(worst),
                deformation_gradient_error: spread,
                iterations: o
                    .solution
                    .finite
                    .as_ref()
                    .map(|h| h.steps.iter().map(|s| s.iterations).collect())
                    .unwrap_or_default(),
            }
        }
    };
    let finite_pass = matches!(
        finite,
        FiniteOutcome::Converged { stress_error, deformation_gradient_error, .. }
            if stress_error <= TOLERANCE && deformation_gradient_error <= TOLERANCE
    );
    Ok(FinitePatchCell {
        mesh: mesh.into(),
        discretization: discretization.label.into(),
        slave: discretization.slave.into(),
        enforcement: enforcement["kind"].as_str().unwrap_or("?").into(),
        small_strain_error: Some(small_strain_error),
        small_strain_pass,
        not_applicable: None,
        finite,
        finite_pass,
        exact_state,
        seconds,
    })
}

/// The penalty system at the exact homogeneous state (`u = ((a - 1) X, -0.2 Y)`, the punch
/// lowered by `shift`, its penetration, and moved sideways by `slide`): the largest residual
/// relative to the largest internal force there, and the number of negative pivots of
/// `L D L^T` (no pivoting) of its symmetric part.
fn inertia(model: &Model, a: f64, shift: f64, slide: f64) -> Result<(f64, usize)> {
    let mut u = vec![0.0; model.dof_count];
    for body in &model.bodies {
        let (lowered, slid) = if body.name == "punch" {
            (shift, slide)
        } else {
            (0.0, 0.0)
        };
        for (n, x) in body.mesh.nodes.iter().enumerate() {
            u[body.dof(n, 0)] = (a - 1.0) * x[0] + slid;
            u[body.dof(n, 1)] = -COMPRESSION * x[1] + lowered;
        }
    }
    let mut probe = Probe::new(model, 0.0)?;
    let x = probe.unknowns(&u);
    // the first evaluation finds the active set at that state, the second is evaluated with it
    probe.evaluate(&x)?;
    let at = probe.evaluate(&x)?;
    let internal = crate::solver::finite_assembly::internal_force(model, &u).map_err(|e| {
        Error::invalid(
            &model.source,
            "the exact homogeneous state",
            e,
            "the exact state inverts no element; check the catalogue's meshes",
        )
    })?;
    let scale = internal.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let residual = at.residual.iter().fold(0.0f64, |m, v| m.max(v.abs())) / scale;
    let n = at.residual.len();
    let mut k: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| 0.5 * (at.tangent[i][j] + at.tangent[j][i]))
                .collect()
        })
        .collect();
    let mut unstable_directions = 0;
    for c in 0..n {
        let pivot = k[c][c];
        unstable_directions += usize::from(pivot < 0.0);
        for i in c + 1..n {
            let f = k[i][c] / pivot;
            for j in c..n {
                k[i][j] -= f * k[c][j];
            }
        }
    }
    Ok((residual, unstable_directions))
}

/// A verdict letter: `p` pass, `f` fail, `nc` not converged, `n/a` does not apply.
fn letter(cell: &FinitePatchCell) -> &'static str {
    if cell.not_applicable.is_some() {
        return "n/a";
    }
    match (&cell.finite, cell.finite_pass) {
        (_, true) => "p",
        (FiniteOutcome::Converged { .. }, false) => "f",
        (FiniteOutcome::Stopped { .. }, _) => "nc",
    }
}

fn small_letter(cell: &FinitePatchCell) -> &'static str {
    if cell.not_applicable.is_some() {
        "n/a"
    } else if cell.small_strain_pass {
        "p"
    } else {
        "f"
    }
}

fn number(v: f64) -> String {
    if v <= TOLERANCE {
        "0".into()
    } else {
        format!("{v:.1e}")
    }
}

/// The report: the verdicts in the small-strain table's form (one-pass cells `p/f` for
/// punch slave / foundation slave), then every cell with its numbers.
pub fn report(cells: &[FinitePatchCell]) -> String {
    let mut out = String::from(
        "# The contact patch test at finite strain: meshes A-E compressed by 20 %\n\n\
         Generated by `contact-patch finite-patch` (do not edit by hand). The catalogue's cases \
         (`cases/patch/`, nu = 0.3) with neo-Hookean bodies, `kinematics: \"finite\"`, contact in \
         the current configuration searched again at every Newton iterate, 4 load steps along the \
         homogeneous states of 5-20 % compression (`src/harness/finite_patch.rs` gives the loads). \
         The exact state is `F = diag(a, 0.8)` with uniform Cauchy stress `[0, sigma_yy, 0]`. \
         A cell passes when the stress of every quadrature point of both bodies is exact to 1e-10 \
         of `|sigma_yy|` and `F` to 1e-10; `nc`: Newton did not reach 20 % (the reason is in the \
         full grid). `0` means below 1e-10.\n\n",
    );
    out.push_str(
        "## Verdicts\n\nEach entry is `small strain -> finite strain` for the same mesh, discretization and \
         enforcement (`p` pass, `f` fail, `nc` stops before 20 %). A penalty cell is judged at its kappa \
         (1e4) by the same round-off criterion, at both strains; the small-strain table \
         (`patch-table.md`) also passes a penalty cell whose error falls like 1/kappa, as two passes \
         on B and C do there.\n\n| discretization | enforcement |",
    );
    for mesh in MESHES {
        out.push_str(&format!(" {mesh} |"));
    }
    out.push_str("\n|---|---|");
    out.push_str(&"---|".repeat(MESHES.len()));
    out.push('\n');
    for d in discretizations() {
        for enforcement in enforcements(&d) {
            let kind = enforcement["kind"].as_str().unwrap_or("?");
            out.push_str(&format!("| {} | {kind} |", d.label));
            for mesh in MESHES {
                let text = cells
                    .iter()
                    .find(|c| {
                        c.mesh == mesh && c.enforcement == kind && c.discretization == d.label
                    })
                    .map_or("-".into(), |c| {
                        format!("{} -> {}", small_letter(c), letter(c))
                    });
                out.push_str(&format!(" {text} |"));
            }
            out.push('\n');
        }
    }
    let applies: Vec<&FinitePatchCell> = cells
        .iter()
        .filter(|c| c.not_applicable.is_none())
        .collect();
    let passed = applies.iter().filter(|c| c.finite_pass).count();
    let small = applies.iter().filter(|c| c.small_strain_pass).count();
    let stopped = applies
        .iter()
        .filter(|c| matches!(c.finite, FiniteOutcome::Stopped { .. }))
        .count();
    out.push_str(&format!(
        "\n{passed} of the {} cells that apply pass at finite strain ({small} at small strain); {stopped} stop \
         before 20 %; {} do not apply (node-to-node where the interface nodes do not match).\n",
        applies.len(),
        cells.len() - applies.len()
    ));
    for (enforcement, title, what) in [
        (
            "penalty",
            "The penalty cells at the exact state.",
            "the tangent of the cell's penalty (kappa = 1e4)",
        ),
        (
            "lagrange",
            "The Lagrange cells at the exact state.",
            "the tangent of a penalty of kappa = 1e8 standing for the constraint (the constrained \
             problem's inertia is the penalty tangent's as kappa grows; its residual carries kappa \
             times the round-off of the gaps)",
        ),
    ] {
        let probed: Vec<(&FinitePatchCell, ExactState)> = cells
            .iter()
            .filter(|c| c.enforcement == enforcement)
            .filter_map(|c| c.exact_state.map(|s| (c, s)))
            .collect();
        let count = |unstable: bool, pass: bool| {
            probed
                .iter()
                .filter(|(c, s)| {
                    (s.unstable_directions + s.unstable_directions_beside > 0) == unstable
                        && c.finite_pass == pass
                })
                .count()
        };
        out.push_str(&format!(
            "\n**{title}** For each of the {} {enforcement} cells whose small-strain test passes, the exact state \
             is an equilibrium of the discrete system (largest residual {:.1e}, relative to the largest internal \
             force), and the inertia of {what} there, and with the punch moved 1e-7 to either side, counts its \
             directions of decreasing energy. Stable at and beside the exact state: {} pass, {} do not; \
             unstable at or beside it: {} pass, {} do not.\n",
            probed.len(),
            probed.iter().map(|(_, s)| s.residual).fold(0.0f64, f64::max),
            count(false, true),
            count(false, false),
            count(true, true),
            count(true, false),
        ));
    }
    out.push_str(
        "\n## Every cell\n\n| mesh | discretization | enforcement | small strain | finite strain: stress | F | iterations per step | verdicts (small / finite) | unstable directions at / beside the exact state | time ms | reason it stopped |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for c in cells {
        let (stress, f, iterations, reason) = match &c.finite {
            FiniteOutcome::Converged {
                stress_error,
                deformation_gradient_error,
                iterations,
            } => (
                number(*stress_error),
                number(*deformation_gradient_error),
                format!("{iterations:?}"),
                String::new(),
            ),
            FiniteOutcome::Stopped { reason } => (
                "-".into(),
                "-".into(),
                "-".into(),
                c.not_applicable
                    .as_deref()
                    .unwrap_or(reason)
                    .lines()
                    .next()
                    .unwrap_or("")
                    .replace('|', "/"),
            ),
        };
        out.push_str(&format!(
            "| {} | {} | {} | {} | {stress} | {f} | {iterations} | {} / {} | {} | {:.0} | {reason} |\n",
            c.mesh,
            c.discretization,
            c.enforcement,
            c.small_strain_error.map_or("-".into(), number),
            small_letter(c),
            letter(c),
            c.exact_state.map_or("-".into(), |s| format!(
                "{} / {}",
                s.unstable_directions, s.unstable_directions_beside
            )),
            1e3 * c.seconds,
        ));
    }
    out
}
