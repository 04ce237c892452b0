//! The frictional patch test (issue 10): the judge of one cell of `reports/friction-table.*`.
//!
//! Data: the contact patch test of `shared/design/benchmarks.md` s. 1 (meshes A-E) with
//! Coulomb friction (s. 4): the uniform field `sigma = [0, -p, q]` loaded by its own tractions
//! on every free boundary, normal load first, tangential load in the later load steps.
//!
//! * **stick** (`q < mu p`, the shear traction on the punch top): the bodies move together and
//!   the uniform field is the exact solution; every contact point sticks.
//! * **slip** (the punch top dragged along `x`, `q = mu p`): every contact point slips with
//!   `|lambda_t| = mu lambda_n` against the motion, and the tangential traction is `mu p` at
//!   every node, the uniform field again exact.
//!
//! Besides the patch table's measures (`harness::measure`: stress, normal pressure, the total
//! interaction force, which now includes the tangential forces, force balance) a friction cell
//! records
//!
//! * `tangential_error`: max over the interface nodes that carry rows of
//!   `|t . f_a / A_a - t . sigma_exact n_a| / p` (nodal forces `B^T lambda + B_t^T lambda_t`,
//!   [`crate::contact::forces`], `t = (-n_y, n_x)`);
//! * `statuses`: how many contact points end the last step in the expected status, of all;
//! * `cone_ratio`: the largest `|lambda_t| / (mu lambda_n)` over the closed points of every
//!   load step (Coulomb's inequality: at most 1);
//! * `min_dissipation`: the smallest frictional dissipation of a load step (never negative).
//!
//! A cell passes the friction part when every point ends in the expected status, Coulomb's
//! inequality holds in every step (`<= 1 + 1e-12`), no step dissipates a negative energy, and,
//! for the methods judged on their exact multipliers, the tangential traction is exact within
//! the sweep's tolerance (the penalty-type methods are judged on their stress trend, as in the
//! patch table).

use crate::contact::forces::PairForces;
use crate::contact::friction::Status;
use crate::io::scene::{ExpectedFriction, Interaction};
use crate::model::space::SolidCell;
use crate::model::{coulomb_obstacle, newton_mortar_obstacle, ContactPair, Model};
use crate::solver::linear::Solution;

/// What the friction judge measured in one solve.
#[derive(Clone, Debug)]
pub struct FrictionMeasured {
    pub tangential_error: f64,
    /// Points in the expected status at the end of the last step, and all frictional points.
    pub expected: usize,
    pub points: usize,
    pub cone_ratio: f64,
    pub min_dissipation: f64,
}

impl FrictionMeasured {
    /// The status column: `slip 3/3`.
    pub fn statuses(&self, expect: ExpectedFriction) -> String {
        format!("{} {}/{}", name(expect), self.expected, self.points)
    }

    /// Whether the friction part of the cell passes (see the module documentation); `exact`:
    /// the tangential traction is judged too.
    pub fn passes(&self, exact: bool, tol: f64) -> bool {
        self.points > 0
            && self.expected == self.points
            && self.cone_ratio <= 1.0 + 1e-12
            && self.min_dissipation >= 0.0
            && (!exact || self.tangential_error <= tol)
    }

    /// Notes for the cell: what failed, and by how much.
    pub fn notes(&self, expect: ExpectedFriction) -> Vec<String> {
        let mut notes = Vec::new();
        if self.expected != self.points {
            notes.push(format!(
                "{} of {} points {}",
                self.points - self.expected,
                self.points,
                match expect {
                    ExpectedFriction::Stick => "do not stick",
                    ExpectedFriction::Slip => "do not slip",
                }
            ));
        }
        if self.cone_ratio > 1.0 + 1e-12 {
            notes.push(format!(
                "Coulomb's inequality violated: |lambda_t| / (mu lambda_n) = 1 + {:.1e}",
                self.cone_ratio - 1.0
            ));
        }
        if self.min_dissipation < 0.0 {
            notes.push(format!(
                "negative dissipation {:.1e} in a step",
                self.min_dissipation
            ));
        }
        notes
    }
}

/// `stick` or `slip`.
pub fn name(expect: ExpectedFriction) -> &'static str {
    match expect {
        ExpectedFriction::Stick => "stick",
        ExpectedFriction::Slip => "slip",
    }
}

/// Why the friction of `pair` cannot be solved in `model` (an `n/a` cell), if it cannot.
pub(crate) fn obstacle<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    pair: &ContactPair,
) -> Option<String> {
    if !matches!(pair.interaction, Interaction::Coulomb { .. }) {
        return None;
    }
    if let Some(o) = coulomb_obstacle(
        model.solver.scheme,
        model.physics.contact_geometry,
        &pair.enforcement,
        pair.has_flat_rigid_master(),
    ) {
        return Some(o.why);
    }
    (model.solver.scheme == crate::io::scene::Scheme::Newton
        && newton_mortar_obstacle(&pair.enforcement, &pair.discretization))
    .then(|| "the Newton scheme does not yet solve the perturbed Lagrangian's consistent (non-diagonal) coupling of standard mortar multipliers".to_string())
}

/// Measure the friction part of a solved cell.
pub(crate) fn measure(
    model: &Model,
    solution: &Solution,
    forces: &[PairForces],
    expect: ExpectedFriction,
    pressure: f64,
) -> FrictionMeasured {
    let state = solution.contact.as_ref().expect("a contact solve");
    let wanted = match expect {
        ExpectedFriction::Stick => Status::Stick,
        ExpectedFriction::Slip => Status::Slip,
    };
    let points: Vec<_> = state.friction.iter().flatten().collect();
    let expected = points.iter().filter(|p| p.status == wanted).count();
    let (mut cone_ratio, mut min_dissipation) = (0.0f64, f64::INFINITY);
    for step in &state.steps {
        if let Some(f) = &step.friction {
            cone_ratio = cone_ratio.max(f.max_cone_ratio);
            min_dissipation = min_dissipation.min(f.dissipation);
        }
    }
    let mut tangential_error = 0.0f64;
    if let Some(exact) = model.exact.as_ref() {
        for pf in forces {
            for n in pf.nodes.iter().filter(|n| n.carries_rows) {
                let s = exact.stress(model.bodies[n.body].mesh.nodes[n.node]);
                let nn = n.normal;
                let t = [-nn[1], nn[0]];
                let exact_traction = [s[0] * nn[0] + s[2] * nn[1], s[2] * nn[0] + s[1] * nn[1]];
                let along = |v: [f64; 2]| v[0] * t[0] + v[1] * t[1];
                let e = (along(n.traction) - along(exact_traction)).abs() / pressure.abs();
                tangential_error = if e.is_nan() || e > tangential_error {
                    e
                } else {
                    tangential_error
                };
            }
        }
    }
    FrictionMeasured {
        tangential_error,
        expected,
        points: points.len(),
        cone_ratio,
        min_dissipation: if min_dissipation.is_finite() {
            min_dissipation
        } else {
            f64::NAN
        },
    }
}

/// The column label of a cell's discretization variant: `node_to_surface 1p punch`.
fn variant(c: &super::Cell) -> String {
    let mut v = c.discretization.clone();
    if let Some(p) = c.passes {
        v += &format!(" {p}p");
    }
    if let (Some(s), false) = (&c.slave, c.passes == Some(2)) {
        v += &format!(" {s}");
    }
    v
}

/// Per mesh and expected status, per discretization variant: the verdicts of the enforcement
/// methods, `pass/fail/n/a` counts.
pub fn summary_markdown(cells: &[super::Cell]) -> String {
    let mut variants: Vec<String> = Vec::new();
    let mut rows: Vec<(String, String)> = Vec::new();
    for c in cells {
        let v = variant(c);
        if !variants.contains(&v) {
            variants.push(v);
        }
        let expect = c
            .friction
            .as_ref()
            .map(|f| f.expect.clone())
            .unwrap_or_default();
        let r = (c.mesh.clone(), expect);
        if !rows.contains(&r) {
            rows.push(r);
        }
    }
    let mut s = String::from("| mesh | status |");
    for v in &variants {
        s += &format!(" {v} |");
    }
    s += "\n|---|---|";
    s += &"---|".repeat(variants.len());
    s += "\n";
    for (mesh, expect) in &rows {
        s += &format!("| {mesh} | {expect} |");
        for v in &variants {
            let of: Vec<&super::Cell> = cells
                .iter()
                .filter(|c| {
                    &c.mesh == mesh
                        && c.friction.as_ref().is_some_and(|f| &f.expect == expect)
                        && &variant(c) == v
                })
                .collect();
            let passing: Vec<&str> = of
                .iter()
                .filter(|c| c.verdict == "pass")
                .map(|c| c.enforcement.as_str())
                .collect();
            let failing = of.iter().filter(|c| c.verdict == "fail").count();
            let na = of.iter().filter(|c| c.verdict == "n/a").count();
            s += &format!(
                " pass: {}; fail {failing}, n/a {na} |",
                if passing.is_empty() {
                    "-".to_string()
                } else {
                    passing.join(", ")
                }
            );
        }
        s += "\n";
    }
    s
}

/// The full friction grid as a Markdown table: verdicts and errors, no wall times (those go to
/// `<catalogue>-table.times.csv`, [`crate::harness::report::times_csv`]).
pub fn grid_markdown(cells: &[super::Cell]) -> String {
    use super::rounded;
    let mut s = String::from("| mesh | status | discretization | passes | slave | enforcement | verdict | statuses | stress error | at 1000 kappa | trend | pressure error | tangential error | load error | cone ratio | min dissipation | iterations |");
    s += " note |\n";
    s += "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|";
    s += "---|\n";
    for c in cells {
        let f = c.friction.as_ref();
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            c.mesh,
            f.map(|f| f.expect.as_str()).unwrap_or("-"),
            c.discretization,
            c.passes.map(|p| p.to_string()).unwrap_or("-".into()),
            c.slave.as_deref().unwrap_or("-"),
            c.enforcement,
            c.verdict,
            f.and_then(|f| f.statuses.as_deref()).unwrap_or("-"),
            rounded(c.stress_error),
            rounded(c.stress_error_stiff),
            c.penalty_trend.as_deref().unwrap_or("-"),
            rounded(c.pressure_error),
            rounded(f.and_then(|f| f.tangential_error)),
            rounded(c.load_error),
            f.and_then(|f| f.cone_ratio)
                .map(|r| format!("{r:.6}"))
                .unwrap_or("-".into()),
            f.and_then(|f| f.min_dissipation)
                .map(|d| if d.abs() < 1e-12 { "0".into() } else { format!("{d:.3e}") })
                .unwrap_or("-".into()),
            c.newton_iterations
                .map(|r| r.to_string())
                .unwrap_or("-".into()),
        );
        s += &format!(" {} |\n", c.note.replace('|', "/"));
    }
    s
}
