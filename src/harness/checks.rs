//! Checks declared by a case, judged against a solution.
//!
//! Each check measures one error and compares it with the case's own tolerance:
//! * `uniform_stress`: `max_qp max_i |sigma_i - s_i| / max_i |s_i|` over the stiffness
//!   quadrature points of the chosen bodies;
//! * `exact_displacement`: relative L2 displacement error against the case's exact solution;
//! * `reaction`: sum of `K u - f` over a node set, one component;
//! * `displacement`: one component at the node nearest to a point;
//! * `contact_pressure`, `force_balance`, `contact_force`, `max_contact_pressure`,
//!   `max_penetration`: contact forces, pressures and penetrations as
//!   [`crate::contact::forces`] computes them (one function for every discretization).
//!
//! A value is judged relative to itself, `|got - value| / |value|`. A value of 0 has no
//! magnitude of its own, so it is judged relative to the magnitude of the problem, and the
//! check's text says which: forces relative to the applied load `F` (the larger of the summed
//! |external forces| and the summed |reactions|), stresses and pressures to `F / (t L)` with `L`
//! the model size and `t` the thickness, displacements to the largest |u|. A verdict then does
//! not change with the units (defect D19: a reaction expected to be 0 failed at 7.6e-6 once E
//! and the loads were scaled by 1e9, while the stress was exact to 1.5e-15).

use crate::contact::discretization::Discretize;
use crate::contact::forces::{pair_forces, PairForces, Penetration};
use crate::contact::state::{ContactState, Termination};
use crate::io::scene::{Check, Interaction, TerminationReason};
use crate::model::space::SolidCell;
use crate::model::{MasterSide, Model};
use crate::post::{for_each_quadrature_stress, relative_l2_displacement_error};
use crate::solver::linear::Solution;
use serde::Serialize;

/// The verdict of one check.
#[derive(Clone, Debug)]
pub struct CheckResult {
    /// What was checked, in words.
    pub check: String,
    /// The measured error.
    pub error: f64,
    pub tol: f64,
    /// The error is within the tolerance. Whether the case passes also depends on
    /// `expected_failure`: see [`CheckResult::verdict`].
    pub passed: bool,
    /// The reason the case gives for expecting this check to fail (its `expected_failures`);
    /// `None` for a check it does not list.
    pub expected_failure: Option<String>,
}

/// How one check ended, the case's expected failures taken into account (like pytest's strict
/// `xfail`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CheckVerdict {
    /// Within the tolerance, and not listed as expected to fail.
    Passed,
    /// Beyond the tolerance (or not measured: NaN), and not listed; or listed, but its error
    /// is not a measurement (NaN or infinite: the check could not be judged).
    Failed,
    /// Listed as expected to fail, and failed by a measured error: the case passes.
    ExpectedFailure,
    /// Listed as expected to fail, but within the tolerance: the case fails, so that the
    /// statement cannot go stale.
    UnexpectedPass,
}

impl CheckResult {
    /// A check judged `error` against `tol` (passed when `error <= tol`; a NaN error fails),
    /// not listed as expected to fail.
    pub fn judged(check: String, error: f64, tol: f64) -> CheckResult {
        CheckResult {
            check,
            error,
            tol,
            passed: error <= tol,
            expected_failure: None,
        }
    }

    /// The check as the case expects it: `reason` is the case's reason for expecting it to
    /// fail, `None` when the case does not list it.
    pub fn expected_to_fail(self, reason: Option<&str>) -> CheckResult {
        CheckResult {
            expected_failure: reason.map(str::to_string),
            ..self
        }
    }

    pub fn verdict(&self) -> CheckVerdict {
        match (&self.expected_failure, self.passed) {
            (None, true) => CheckVerdict::Passed,
            (None, false) => CheckVerdict::Failed,
            (Some(_), true) => CheckVerdict::UnexpectedPass,
            (Some(_), false) if self.error.is_finite() => CheckVerdict::ExpectedFailure,
            (Some(_), false) => CheckVerdict::Failed,
        }
    }

    /// Whether the check fails its case: it failed and was not expected to, or it was
    /// expected to fail and passed.
    pub fn fails_the_case(&self) -> bool {
        matches!(
            self.verdict(),
            CheckVerdict::Failed | CheckVerdict::UnexpectedPass
        )
    }

    /// The measured error against the tolerance, e.g. `error 4.016e-2 > tol 1.0e-10`.
    pub fn measured(&self) -> String {
        let sign = if self.passed { "<=" } else { ">" };
        format!("error {:.3e} {sign} tol {:.1e}", self.error, self.tol)
    }

    /// What the verdict says beyond the measurement: the case's reason for an expected
    /// failure, or why a listed check fails its case; empty for a check the case does not list.
    pub fn expectation(&self) -> String {
        let Some(reason) = &self.expected_failure else {
            return String::new();
        };
        match self.verdict() {
            CheckVerdict::ExpectedFailure => reason.clone(),
            CheckVerdict::UnexpectedPass => {
                format!("expected to fail ({reason}) but passed: remove it from expected_failures")
            }
            _ => format!(
                "expected to fail ({reason}), but its error was not measured ({}): a check \
                 that cannot be judged fails the case",
                self.error
            ),
        }
    }

    /// One line of a report: the verdict (`pass`, `FAIL`, `expected failure`), the check, the
    /// measurement and, for a listed check, [`CheckResult::expectation`].
    pub fn report_line(&self) -> String {
        let verdict = match self.verdict() {
            CheckVerdict::Passed => "pass",
            CheckVerdict::Failed | CheckVerdict::UnexpectedPass => "FAIL",
            CheckVerdict::ExpectedFailure => "expected failure",
        };
        let expectation = self.expectation();
        let expectation = if expectation.is_empty() {
            String::new()
        } else {
            format!(": {expectation}")
        };
        format!(
            "{verdict} {} (error {:.3e}, tol {:.1e}){expectation}",
            self.check, self.error, self.tol
        )
    }
}

/// A check's entry in `summary.json`: `check`, `error`, `tol` and `passed` (the error is within
/// the tolerance), and for a check the case lists as expected to fail, `expected_failure`:
/// `{"reason", "verdict"}` with the verdict `"failed as expected"`, `"passed, but expected to
/// fail"` (the case fails) or `"not measured"` (the case fails).
impl Serialize for CheckResult {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        #[derive(Serialize)]
        struct Expected<'a> {
            reason: &'a str,
            verdict: &'static str,
        }
        #[derive(Serialize)]
        struct Entry<'a> {
            check: &'a str,
            error: f64,
            tol: f64,
            passed: bool,
            #[serde(skip_serializing_if = "Option::is_none")]
            expected_failure: Option<Expected<'a>>,
        }
        Entry {
            check: &self.check,
            error: self.error,
            tol: self.tol,
            passed: self.passed,
            expected_failure: self.expected_failure.as_deref().map(|reason| Expected {
                reason,
                verdict: match self.verdict() {
                    CheckVerdict::ExpectedFailure => "failed as expected",
                    CheckVerdict::UnexpectedPass => "passed, but expected to fail",
                    _ => "not measured",
                },
            }),
        }
        .serialize(serializer)
    }
}

/// The magnitudes a value of 0 is judged against.
#[derive(Clone, Copy, Debug)]
pub struct Magnitudes {
    /// The applied load `F`: the larger of sum |f_ext| and sum |reactions at prescribed dofs|.
    pub force: f64,
    /// `F / (t L)`.
    pub stress: f64,
    /// The largest |u|.
    pub displacement: f64,
}

impl Magnitudes {
    pub fn of<const D: usize, K: SolidCell<D>>(
        model: &Model<D, K>,
        solution: &Solution<D>,
    ) -> Magnitudes {
        let applied: f64 = model.external_force.iter().map(|f| f.abs()).sum();
        let reactions: f64 = model
            .prescribed
            .iter()
            .zip(&solution.reactions)
            .filter(|(p, _)| p.is_some())
            .map(|(_, r)| r.abs())
            .sum();
        let force = applied.max(reactions);
        Magnitudes {
            force,
            stress: force / (model.thickness * model.size()),
            displacement: solution.u.iter().fold(0.0, |m: f64, v| m.max(v.abs())),
        }
    }
}

/// `|got - value| / |value|`, or relative to `magnitude` (named `what`) when `value` is 0;
/// also the words that say which.
fn judged(got: f64, value: f64, magnitude: f64, what: &str) -> (f64, String) {
    if value != 0.0 {
        (
            (got - value).abs() / value.abs(),
            format!("expected {value}"),
        )
    } else {
        (
            got.abs() / magnitude.max(f64::MIN_POSITIVE),
            format!("expected 0, judged relative to {what} {magnitude:.3e}"),
        )
    }
}

/// The words, error and tolerance of the check `reaction`: the sum of the reactions
/// `K u - f` in `component` over the nodes of `body.set`, against `value` (relative to it, or
/// to the applied load when it is 0); 2D and 3D.
pub fn reaction_check<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
    magnitudes: &Magnitudes,
    (body, set): (&str, &str),
    component: crate::io::scene::Component,
    value: f64,
    tol: f64,
) -> (String, f64, f64) {
    let b = model.body(body).expect("resolved when the model was built");
    let comp = component.index();
    let got: f64 = b.mesh.node_sets[set]
        .iter()
        .map(|&n| solution.reactions[b.dof(n, comp)])
        .sum();
    let (error, expected) = judged(got, value, magnitudes.force, "the applied load");
    (
        format!("reaction {component:?} on {body}.{set} = {got:.6e} ({expected})"),
        error,
        tol,
    )
}

/// The check `reaction` (`None` for any other check) as a result, judged against the
/// magnitudes of `solution`: the 3D run and the 3D judge.
pub fn reaction_result<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
    check: &Check,
) -> Option<CheckResult> {
    let Check::Reaction {
        body,
        set,
        component,
        value,
        tol,
    } = check
    else {
        return None;
    };
    let magnitudes = Magnitudes::of(model, solution);
    let (check, error, tol) = reaction_check(
        model,
        solution,
        &magnitudes,
        (body, set),
        *component,
        *value,
        *tol,
    );
    Some(CheckResult::judged(check, error, tol))
}

/// NaN-keeping maximum: a NaN error must fail, so it is kept rather than dropped by `max`.
fn worst(a: f64, e: f64) -> f64 {
    if e.is_nan() || e > a {
        e
    } else {
        a
    }
}

/// Max over the nodes of `pair` (all pairs if `None`) that carry rows, in the forces `forces`
/// of the solution (from [`pair_forces`]), of
/// `|t_a - sigma_exact n_a| / scale`, `t_a` the recovered nodal traction of
/// [`crate::contact::forces`] (`f_a / A_a` where the node's tributary is wholly covered; ties:
/// the whole traction; frictionless pairs: its
/// normal component, the pressure), with `scale` the given one or, if `None`, `max |sigma_exact|`
/// at the node (the problem's stress magnitude where that is 0). Infinite when the solve
/// produced no contact state.
pub fn pressure_error(
    model: &Model,
    solution: &Solution,
    forces: &[PairForces],
    exact: &crate::harness::exact::ExactField,
    pair: Option<usize>,
    scale: Option<f64>,
) -> f64 {
    if solution.contact.is_none() {
        return f64::INFINITY;
    }
    pressure_error_of(model, solution, forces, exact, pair, scale)
}

/// [`pressure_error`] of the given nodal forces, whatever produced them (our solve, or another
/// code's results read by [`crate::harness::outside_contact`]).
pub fn pressure_error_of(
    model: &Model,
    solution: &Solution,
    forces: &[PairForces],
    exact: &crate::harness::exact::ExactField,
    pair: Option<usize>,
    scale: Option<f64>,
) -> f64 {
    let fallback = Magnitudes::of(model, solution).stress;
    let mut error = 0.0f64;
    for pf in forces {
        if pair.is_some_and(|k| k != pf.pair) {
            continue;
        }
        let tied = model.contact[pf.pair].interaction == Interaction::Tied;
        for n in pf.nodes.iter().filter(|n| n.carries_rows) {
            let body = &model.bodies[n.body];
            let s = exact.stress(body.mesh.nodes[n.node]);
            let at_node = s.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let scale = scale
                .unwrap_or(if at_node > 0.0 { at_node } else { fallback })
                .max(f64::MIN_POSITIVE);
            let nn = n.normal;
            let exact_traction = [s[0] * nn[0] + s[2] * nn[1], s[2] * nn[0] + s[1] * nn[1]];
            let traction = n.traction;
            let e = if tied {
                (traction[0] - exact_traction[0])
                    .abs()
                    .max((traction[1] - exact_traction[1]).abs())
            } else {
                let normal = |t: [f64; 2]| t[0] * nn[0] + t[1] * nn[1];
                (normal(traction) - normal(exact_traction)).abs()
            };
            error = worst(error, e / scale);
        }
    }
    error
}

/// Largest over the pairs between deformable bodies of: the net force `|F_s + F_m|` (largest
/// component) and net moment `|M| / L` the pair puts on its two bodies, relative to the applied
/// load `F` of [`Magnitudes`] (the larger of the summed |external forces| and the summed
/// |reactions|; `L` the model size; moments about the origin of the points where the forces
/// act, in the configuration of the rows), and the out-of-balance force of the solve,
/// `sum |K u - f - B^T lambda|` over the free dofs, relative to the same `F` (`forces` from
/// [`pair_forces`]). A pair that carries nothing is skipped. (Until issue 16 the pairs' terms
/// were relative to the sum of the nodal |contact forces| and the residual to the largest nodal
/// force, scales that depend on the mesh rather than on the load the user applied.)
pub fn force_balance<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
    forces: &[PairForces<D>],
) -> f64 {
    if solution.contact.is_none() {
        return f64::INFINITY;
    }
    force_balance_of(model, solution, forces)
}

/// The force [`force_balance`] divides by: the applied load `F` of [`Magnitudes`], or, where
/// `F` is below `sqrt(eps)` of the stiffness terms' magnitude [`Solution::force_scale`] (a
/// motion without load, such as a rigid lift, whose reactions are round-off of those terms),
/// that magnitude, the scale of the solve's round-off.
pub fn balance_scale<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
) -> f64 {
    let load = Magnitudes::of(model, solution).force;
    if load < f64::EPSILON.sqrt() * solution.force_scale {
        solution.force_scale
    } else {
        load
    }
}

/// [`force_balance`] of the given nodal forces; `solution.reactions` must already hold
/// `K u - f - f_contact` (the out-of-balance force at the free dofs).
pub fn force_balance_of<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
    forces: &[PairForces<D>],
) -> f64 {
    force_balance_terms(model, solution, forces).0
}

/// [`force_balance_of`] and the words naming its largest term: the out-of-balance force, or a
/// pair's net force x, y (or z), or its net moment / L (a NaN term is the largest); 2D and 3D.
pub fn force_balance_terms<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
    forces: &[PairForces<D>],
) -> (f64, String) {
    let size = model.size();
    let load = balance_scale(model, solution).max(f64::MIN_POSITIVE);
    let out_of_balance: f64 = model
        .prescribed
        .iter()
        .zip(&solution.reactions)
        .filter(|(p, _)| p.is_none())
        .map(|(_, r)| r.abs())
        .sum();
    let mut error = out_of_balance / load;
    let mut largest = "the out-of-balance force sum |K u - f - f_c| over the free dofs".to_string();
    for pf in forces {
        if !matches!(model.contact[pf.pair].master, MasterSide::Body { .. })
            || pf.force_scale == 0.0
        {
            continue;
        }
        let name = &model.contact[pf.pair].name;
        let net_force = (0..D).map(|i| {
            (
                pf.on_slave[i] + pf.on_master[i],
                format!("net force {}", ["x", "y", "z"][i]),
            )
        });
        let moment = (
            crate::contact::forces::length(&pf.net_moment) / size,
            "net moment / L".to_string(),
        );
        for (value, what) in net_force.chain([moment]) {
            let e = value.abs() / load;
            if e > error || e.is_nan() && !error.is_nan() {
                error = e;
                largest = format!("the {what} of pair '{name}'");
            }
        }
    }
    (error, largest)
}

/// A point's coordinates as a message writes them: `(x, y)` or `(x, y, z)`, six decimals.
pub(crate) fn point_text(x: &[f64]) -> String {
    let x: Vec<String> = x.iter().map(|v| format!("{v:.6}")).collect();
    format!("({})", x.join(", "))
}

/// Penetration above this share of the contact element size makes a run warn.
pub const PENETRATION_WARNING_SHARE: f64 = 0.05;

/// What a run should say even when every check passes: slave nodes that slid off the master
/// surface (contact geometry in the current configuration), and penetration beyond
/// [`PENETRATION_WARNING_SHARE`] of the contact element size.
pub fn warnings<const D: usize, K: Discretize<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
) -> Vec<String> {
    warnings_with(model, solution, None)
}

/// [`warnings`] with the pairs' contact forces of the solve already at hand (`None`: computed
/// here from `solution.contact`), so that a run computes them once for its checks and its
/// warnings.
pub fn warnings_with<const D: usize, K: Discretize<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
    contact_forces: Option<&[PairForces<D>]>,
) -> Vec<String> {
    let Some(state) = &solution.contact else {
        return Vec::new();
    };
    let computed;
    let forces = match contact_forces {
        Some(forces) => forces,
        None => {
            computed = pair_forces(model, state);
            &computed
        }
    };
    let departures = state.departures.iter().map(|d| {
        format!(
            "contact '{}': slave node {} of body '{}' left the master surface at {} \
             (geometry update {}: no master facet under it, past the end of the master \
             surface); it carries no contact force from there on",
            model.contact[d.pair].name,
            d.node,
            model.bodies[d.body].name,
            point_text(&d.point),
            d.update
        )
    });
    let penetrations = penetration_warnings(
        model,
        state,
        forces.iter().map(|f| (f.pair, f.penetration.clone())),
    );
    departures
        .chain(untied_slave_nodes(model, state))
        .chain(penetrations)
        .chain(crate::harness::stability::warnings(model, solution))
        .collect()
}

/// The warnings of the pairs whose penetration is above [`PENETRATION_WARNING_SHARE`] of the
/// contact element size, in any dimension: `penetrations` holds each pair's index and its
/// largest penetration ([`crate::contact::forces::pair_penetration`]).
pub fn penetration_warnings<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    state: &ContactState<D>,
    penetrations: impl IntoIterator<Item = (usize, Penetration<D>)>,
) -> Vec<String> {
    penetrations
        .into_iter()
        .filter(|(_, p)| p.share_of_element > PENETRATION_WARNING_SHARE)
        .map(|(pair, p)| {
            let at =
                p.at.map(|(b, n, x)| {
                    format!(
                        " at node {n} of body '{}' {}",
                        model.bodies[b].name,
                        point_text(&x)
                    )
                })
                .unwrap_or_default();
            // an unfinished loop leaves an iterate that need not close its gaps, whatever the
            // method
            let cause = if state.termination == Termination::Converged {
                "the answer is that of a soft interface: raise the penalty kappa (about 10 E / h \
                 or more) or use Lagrange multipliers"
            } else {
                "the contact iterations stopped before the active set settled (see how the \
                 contact solve ended), and this iterate is not the answer"
            };
            format!(
                "contact '{}': penetration {:.3e}{at} is {:.3} times the contact element size \
                 (warning above {PENETRATION_WARNING_SHARE}); {cause}; a `max_penetration` \
                 check makes this a failure",
                model.contact[pair].name, p.depth, p.share_of_element
            )
        })
        .collect()
}

/// One warning per tied pair whose slave surface has nodes with no tie row: no master facet
/// under them (a slave surface longer than the master's), so they are not glued and carry no
/// interface force. Named so that a tie that covers less than the user's set is never silent.
fn untied_slave_nodes<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    state: &ContactState<D>,
) -> Vec<String> {
    let mut out = Vec::new();
    for (k, pair) in model.contact.iter().enumerate() {
        if pair.interaction != Interaction::Tied {
            continue;
        }
        let (body, facets) = &pair.slave;
        let mesh = &model.bodies[*body].mesh;
        let tied: std::collections::HashSet<usize> = state
            .rows
            .iter()
            .filter(|r| r.pair == k && r.pass == 1 && r.slave_body == *body)
            .map(|r| r.slave_node)
            .collect();
        let mut loose: Vec<usize> = facets
            .iter()
            .flat_map(|&f| mesh.facet_nodes(f))
            .filter(|n| !tied.contains(n))
            .collect();
        loose.sort_unstable();
        loose.dedup();
        if loose.is_empty() {
            continue;
        }
        let named: Vec<String> = loose
            .iter()
            .map(|&n| format!("{n} {}", point_text(&mesh.nodes[n])))
            .collect();
        out.push(format!(
            "tied pair '{}': {} slave node(s) of body '{}' have no master facet under them and \
             are not tied (they carry no interface force): {}; shorten the slave set to the \
             master's extent if they should not be on the interface",
            pair.name,
            loose.len(),
            model.bodies[*body].name,
            named.join(", ")
        ));
    }
    out
}

/// The check `max_penetration` in any dimension: its words and the largest penetration
/// relative to the contact element size over the pair `pair` (every pair without), from each
/// pair's name and share; NaN (a failure) without contact forces (`shares` is `None`).
pub fn max_penetration_check<'a>(
    pair: Option<&str>,
    shares: Option<impl Iterator<Item = (&'a str, f64)>>,
) -> (String, f64) {
    let got = match shares {
        Some(shares) => shares
            .filter(|(name, _)| pair.is_none_or(|p| *name == p))
            .fold(0.0, |m, (_, share)| worst(m, share)),
        None => f64::NAN,
    };
    let of = pair.map(|p| format!(" of '{p}'")).unwrap_or_default();
    (
        format!("largest penetration{of} relative to the contact element size"),
        got,
    )
}

fn pair_of<'a, const D: usize, K: SolidCell<D>>(
    forces: &'a [PairForces<D>],
    model: &Model<D, K>,
    name: &str,
) -> Option<&'a PairForces<D>> {
    let k = model.contact.iter().position(|p| p.name == name)?;
    forces.iter().find(|f| f.pair == k)
}

/// Judge every check of the model (names were resolved when the model was built). A contact
/// solve that did not converge adds a failing check of its own, so that no declared check can
/// pass on an unconverged solution.
pub fn evaluate<const D: usize, K: DimensionChecks<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
) -> Vec<CheckResult> {
    let forces: Option<Vec<PairForces<D>>> = solution
        .contact
        .as_ref()
        .map(|state| pair_forces(model, state));
    evaluate_with(model, solution, forces.as_deref())
}

/// The checks whose judging depends on the dimension: the stress checks (`uniform_stress` over
/// `[xx, yy, xy]` in 2D, `uniform_stress_3d` over six components in 3D) and those against the
/// case's exact field (`exact_displacement`, `contact_pressure`; exact fields are 2D). Every
/// other check is judged once for both dimensions by [`evaluate_with`].
pub trait DimensionChecks<const D: usize>: Discretize<D> {
    /// The words, error and tolerance of `check` when it is one of the checks above (a check
    /// of the other dimension fails, saying so; the model refuses it before a run), `None`
    /// for any other check.
    fn judge_by_dimension(
        model: &Model<D, Self>,
        solution: &Solution<D>,
        contact_forces: Option<&[PairForces<D>]>,
        magnitudes: &Magnitudes,
        check: &Check,
    ) -> Option<(String, f64, f64)>;
}

/// The words, an infinite error and the tolerance of a check of the other dimension (or of a
/// field this dimension has not built), for [`DimensionChecks::judge_by_dimension`].
pub fn not_judged_in(dimension: &str, check: &Check) -> (String, f64, f64) {
    let tol = match check {
        Check::UniformStress { tol, .. }
        | Check::UniformStress3d { tol, .. }
        | Check::ExactDisplacement { tol }
        | Check::ContactPressure { tol, .. } => *tol,
        _ => 0.0,
    };
    // the check's name is its tag in the case file
    let name = serde_json::to_value(check)
        .ok()
        .and_then(|v| v.get("check").and_then(|c| c.as_str()).map(String::from))
        .unwrap_or_else(|| "this check".into());
    (
        format!("{name}: not judged in {dimension}"),
        f64::INFINITY,
        tol,
    )
}

impl DimensionChecks<2> for crate::fe::ElementKind {
    fn judge_by_dimension(
        model: &Model,
        solution: &Solution,
        contact_forces: Option<&[PairForces]>,
        magnitudes: &Magnitudes,
        check: &Check,
    ) -> Option<(String, f64, f64)> {
        let u = &solution.u;
        Some(match check {
            Check::UniformStress {
                body,
                stress,
                tol,
                per_condition,
            } => {
                let (tol, stated) = conditioned_tolerance(model, solution, *tol, *per_condition);
                let largest = stress.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let (scale, against) = if largest > 0.0 {
                    (largest, String::new())
                } else {
                    (
                        magnitudes.stress,
                        format!(
                            ", judged relative to the load's stress {:.3e}",
                            magnitudes.stress
                        ),
                    )
                };
                let scale = scale.max(f64::MIN_POSITIVE);
                let mut error = 0.0f64;
                for b in model
                    .bodies
                    .iter()
                    .filter(|b| body.as_ref().is_none_or(|n| *n == b.name))
                {
                    for_each_quadrature_stress(b, u, |_, _, s| {
                        for i in 0..3 {
                            error = worst(error, (s[i] - stress[i]).abs() / scale);
                        }
                    });
                }
                let on = body
                    .as_deref()
                    .map(|b| format!(" in body '{b}'"))
                    .unwrap_or_default();
                (
                    format!("uniform stress {stress:?}{on}{against}{stated}"),
                    error,
                    tol,
                )
            }
            Check::UniformStress3d { .. } => not_judged_in("2D", check),
            Check::ExactDisplacement { tol } => {
                let exact = model
                    .exact
                    .as_ref()
                    .expect("resolved when the model was built");
                (
                    "relative L2 displacement error against the exact solution".to_string(),
                    relative_l2_displacement_error(model, u, exact),
                    *tol,
                )
            }
            Check::ContactPressure { pair, tol } => {
                let exact = model
                    .exact
                    .as_ref()
                    .expect("resolved when the model was built");
                let k = model
                    .contact
                    .iter()
                    .position(|p| p.name == *pair)
                    .expect("resolved when the model was built");
                let error = match contact_forces {
                    Some(forces) => {
                        pressure_error_of(model, solution, forces, exact, Some(k), None)
                    }
                    None => f64::INFINITY,
                };
                (
                    format!("contact pressure of '{pair}' against the exact stress"),
                    error,
                    *tol,
                )
            }
            _ => return None,
        })
    }
}

/// The failing check a contact solve that did not converge adds to the declared `checks` (2D
/// and 3D), so that none of them can pass on an unconverged solution; `None` when it converged,
/// without contact, or when the case names its expected termination (it judges it itself).
pub fn unconverged<const D: usize>(
    checks: &[Check],
    solution: &crate::solver::linear::Solution<D>,
) -> Option<CheckResult> {
    let expects_termination = checks
        .iter()
        .any(|c| matches!(c, Check::TerminatesWith { .. }));
    solution
        .contact
        .as_ref()
        .filter(|_| !expects_termination)
        .and_then(|c| match &c.termination {
            crate::solver::active_set::Termination::Converged => None,
            t => Some(CheckResult::judged(
                format!("the contact solve converged (it ended: {t:?})"),
                f64::INFINITY,
                0.0,
            )),
        })
}

/// The checks of the pairs' contact forces, 2D and 3D: `contact_force` (the pair's total force
/// on its slave body, one component), `max_contact_pressure`, `max_penetration` and
/// `force_balance`, each as words, error and tolerance, from `forces` (our solve's, or another
/// code's read by [`crate::harness::outside_contact`]; `None`: no contact forces, the check
/// fails). `None` for any other check.
pub fn contact_force_check<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
    contact_forces: Option<&[PairForces<D>]>,
    magnitudes: &Magnitudes,
    check: &Check,
) -> Option<(String, f64, f64)> {
    let has_forces = contact_forces.is_some();
    let forces: &[PairForces<D>] = contact_forces.unwrap_or(&[]);
    Some(match check {
        Check::ContactForce {
            pair,
            component,
            value,
            tol,
        } => {
            let got = pair_of(forces, model, pair)
                .map(|f| f.on_slave[component.index()])
                .unwrap_or(f64::NAN);
            let (error, expected) = judged(got, *value, magnitudes.force, "the applied load");
            (
                format!("total contact force {component:?} of '{pair}' on its slave body = {got:.6e} ({expected})"),
                error,
                *tol,
            )
        }
        Check::MaxContactPressure { pair, value, tol } => {
            let got = pair_of(forces, model, pair)
                .map(|f| f.max_pressure())
                .unwrap_or(f64::NAN);
            let (error, expected) = judged(got, *value, magnitudes.stress, "the load's stress");
            (
                format!("max contact pressure of '{pair}' = {got:.6e} ({expected})"),
                error,
                *tol,
            )
        }
        Check::MaxPenetration { pair, share } => {
            let shares = forces.iter().map(|f| {
                (
                    model.contact[f.pair].name.as_str(),
                    f.penetration.share_of_element,
                )
            });
            let (words, got) = max_penetration_check(pair.as_deref(), has_forces.then_some(shares));
            (words, got, *share)
        }
        Check::ForceBalance { tol } => {
            let (error, largest) = if has_forces {
                force_balance_terms(model, solution, forces)
            } else {
                (f64::INFINITY, "no contact forces".to_string())
            };
            let against = if balance_scale(model, solution) != magnitudes.force {
                format!(
                    "the magnitude of the stiffness terms {:.3e} (the applied load {:.3e} is round-off of it)",
                    solution.force_scale, magnitudes.force
                )
            } else {
                format!("the applied load {:.3e}", magnitudes.force)
            };
            (
                format!(
                    "force balance: net force and net moment / L (L = {:.3e}) of each pair between bodies and the out-of-balance force, relative to {against}; largest: {largest}",
                    model.size()
                ),
                error,
                *tol,
            )
        }
        _ => return None,
    })
}

/// [`evaluate`] with the contact forces given: those of our solve (`solution.contact`), or,
/// for another code's results, the ones [`crate::harness::outside_contact`] read (then
/// `solution.contact` is `None`). `None`: no contact forces, every contact check fails. The
/// checks are plain ones: the case's `expected_failures` are the run's ([`evaluate_run`]).
pub fn evaluate_with<const D: usize, K: DimensionChecks<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
    contact_forces: Option<&[PairForces<D>]>,
) -> Vec<CheckResult> {
    judge_declared(model, solution, contact_forces, |_| None)
}

/// The verdicts of a run of `model` ([`crate::run::run_model`], both dimensions): the checks
/// of [`evaluate_with`], each one the case lists in `expected_failures` carrying the case's
/// reason ([`CheckResult::verdict`]). `judge` does not state them: the results it judges come
/// from another code, whose method the case does not state.
pub fn evaluate_run<const D: usize, K: DimensionChecks<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
    contact_forces: Option<&[PairForces<D>]>,
) -> Vec<CheckResult> {
    judge_declared(model, solution, contact_forces, |check| {
        model.expected_failure(check)
    })
}

/// The failing check of an unconverged solve ([`unconverged`]), then each declared check
/// judged, carrying the reason `expected` gives for expecting it to fail.
fn judge_declared<'m, const D: usize, K: DimensionChecks<D>>(
    model: &'m Model<D, K>,
    solution: &Solution<D>,
    contact_forces: Option<&[PairForces<D>]>,
    expected: impl Fn(&Check) -> Option<&'m str>,
) -> Vec<CheckResult> {
    let magnitudes = Magnitudes::of(model, solution);
    let convergence = unconverged(&model.checks, solution);
    let declared = model.checks.iter().map(|check| {
        judge_check(model, solution, contact_forces, &magnitudes, check)
            .expected_to_fail(expected(check))
    });
    convergence.into_iter().chain(declared).collect()
}

/// One declared check of `model` judged on `solution` (see [`evaluate_with`] for
/// `contact_forces`), in either dimension.
pub fn judge_check<const D: usize, K: DimensionChecks<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
    contact_forces: Option<&[PairForces<D>]>,
    magnitudes: &Magnitudes,
    check: &Check,
) -> CheckResult {
    let u = &solution.u;
    let by_dimension = K::judge_by_dimension(model, solution, contact_forces, magnitudes, check);
    let (check_name, error, tol) = if let Some(judged) = by_dimension {
        judged
    } else {
        match check {
            Check::Reaction {
                body,
                set,
                component,
                value,
                tol,
            } => reaction_check(
                model,
                solution,
                magnitudes,
                (body, set),
                *component,
                *value,
                *tol,
            ),
            Check::ContactForce { .. }
            | Check::MaxContactPressure { .. }
            | Check::MaxPenetration { .. } => {
                contact_force_check(model, solution, contact_forces, magnitudes, check)
                    .expect("a contact force check")
            }
            Check::TerminatesWith { reason, contains } => {
                let (got, text) = match solution.contact.as_ref().map(|c| &c.termination) {
                    Some(Termination::Converged) => {
                        (Some(TerminationReason::Converged), String::new())
                    }
                    Some(Termination::IterationLimit) => {
                        (Some(TerminationReason::IterationLimit), String::new())
                    }
                    Some(Termination::ActiveSetCycling(m)) => {
                        (Some(TerminationReason::ActiveSetCycling), m.clone())
                    }
                    Some(Termination::Singular(m)) => {
                        (Some(TerminationReason::Singular), m.clone())
                    }
                    Some(Termination::WorkLimit(m)) => {
                        (Some(TerminationReason::WorkLimit), m.clone())
                    }
                    None => (None, String::new()),
                };
                // the message of the stop and the run's warnings (diagnoses) are searched
                let said = format!(
                    "{text}\n{}",
                    warnings_with(model, solution, contact_forces).join("\n")
                );
                let found = contains.as_ref().is_none_or(|c| said.contains(c.as_str()));
                let with = contains
                    .as_ref()
                    .map(|c| format!(" with a message containing {c:?}"))
                    .unwrap_or_default();
                let how = if text.is_empty() {
                    String::new()
                } else {
                    format!(": {text}")
                };
                (
                    format!("the contact solve ends {reason:?}{with} (it ended {got:?}{how})"),
                    if got == Some(*reason) && found {
                        0.0
                    } else {
                        f64::INFINITY
                    },
                    0.0,
                )
            }
            Check::Equilibrium { tol, per_condition } => {
                let (tol, stated) = conditioned_tolerance(model, solution, *tol, *per_condition);
                (
                    format!("relative equilibrium residual{stated}"),
                    solution.relative_residual,
                    tol,
                )
            }
            Check::StatusChanges {
                per_iteration,
                per_step,
            } => {
                let (it, step) = solution
                    .contact
                    .as_ref()
                    .map(crate::harness::stability::status_changes)
                    .unwrap_or((usize::MAX, usize::MAX));
                let over = (it as f64 / (*per_iteration).max(1) as f64)
                    .max(step as f64 / (*per_step).max(1) as f64);
                let within = it <= *per_iteration && step <= *per_step;
                (
                format!("status changes {it} per iteration (at most {per_iteration}) and {step} per step (at most {per_step})"),
                if within { 0.0 } else { over },
                0.0,
            )
            }
            Check::Warns { contains } => {
                let found = warnings_with(model, solution, contact_forces)
                    .iter()
                    .any(|w| w.contains(contains.as_str()));
                (
                    format!("the run warns {contains:?}"),
                    if found { 0.0 } else { f64::INFINITY },
                    0.0,
                )
            }
            Check::ForceBalance { .. } => {
                contact_force_check(model, solution, contact_forces, magnitudes, check)
                    .expect("a contact force check")
            }
            Check::Displacement {
                body,
                point,
                component,
                value,
                tol,
            } => {
                let b = model.body(body).expect("resolved when the model was built");
                let at: [f64; D] = std::array::from_fn(|i| point.0[i]);
                let (n, _) = b.mesh.nearest_node(at).expect("a body has nodes");
                let got = u[b.dof(n, component.index())];
                let (error, expected) = judged(
                    got,
                    *value,
                    magnitudes.displacement,
                    "the largest displacement",
                );
                let at: Vec<String> = point.0.iter().map(|x| x.to_string()).collect();
                (
                    format!(
                        "displacement {component:?} of {body} at ({}) = {got:.6e} ({expected})",
                        at.join(", ")
                    ),
                    error,
                    *tol,
                )
            }
            Check::UniformStress { .. }
            | Check::UniformStress3d { .. }
            | Check::ExactDisplacement { .. }
            | Check::ContactPressure { .. } => {
                unreachable!("judged by the dimension (DimensionChecks)")
            }
        }
    };
    CheckResult::judged(check_name, error, tol)
}
/// A check's tolerance stated relative to the conditioning: with `per_condition = c`,
/// `max(tol, c eps kappa)` with `kappa` the condition estimate of the last factored system
/// ([`crate::harness::stability::conditioning`]): a backward-stable solve loses up to
/// `eps kappa` relative accuracy (Higham 2002, ch. 7). Also the words that say so.
fn conditioned_tolerance<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    solution: &Solution<D>,
    tol: f64,
    per_condition: Option<f64>,
) -> (f64, String) {
    let kappa = crate::harness::stability::conditioning(model, solution).condition_estimate;
    match (per_condition, kappa) {
        (Some(c), Some(k)) => {
            let t = tol.max(c * f64::EPSILON * k);
            (
                t,
                format!(", tol max({tol:.1e}, {c} eps kappa) with kappa {k:.2e}"),
            )
        }
        (Some(_), None) => (tol, ", no condition estimate".to_string()),
        _ => (tol, String::new()),
    }
}

#[cfg(test)]
mod verdict_tests {
    use super::*;

    fn listed(error: f64) -> CheckResult {
        CheckResult::judged("c".into(), error, 1e-10).expected_to_fail(Some("known"))
    }

    /// Like pytest's strict xfail: a listed check fails as expected only by a measured error;
    /// passing, or not measured (NaN, infinite), it fails the case.
    #[test]
    fn a_listed_check_passes_its_case_only_by_failing_with_a_measured_error() {
        let plain = |error| CheckResult::judged("c".into(), error, 1e-10);
        assert_eq!(plain(1e-12).verdict(), CheckVerdict::Passed);
        assert_eq!(plain(1e-3).verdict(), CheckVerdict::Failed);
        assert_eq!(plain(f64::NAN).verdict(), CheckVerdict::Failed);
        assert_eq!(listed(1e-3).verdict(), CheckVerdict::ExpectedFailure);
        assert!(!listed(1e-3).fails_the_case());
        assert_eq!(listed(1e-12).verdict(), CheckVerdict::UnexpectedPass);
        assert!(listed(1e-12).fails_the_case());
        for error in [f64::NAN, f64::INFINITY] {
            assert_eq!(listed(error).verdict(), CheckVerdict::Failed, "{error}");
            assert!(listed(error).expectation().contains("not measured"));
        }
        assert_eq!(
            listed(1e-3).report_line(),
            "expected failure c (error 1.000e-3, tol 1.0e-10): known"
        );
        assert_eq!(
            listed(1e-12).report_line(),
            "FAIL c (error 1.000e-12, tol 1.0e-10): expected to fail (known) but passed: \
             remove it from expected_failures"
        );
        assert_eq!(
            plain(1e-12).report_line(),
            "pass c (error 1.000e-12, tol 1.0e-10)"
        );
    }

    /// `summary.json`: the four fields as before, and for a listed check its reason and verdict.
    #[test]
    fn a_summary_entry_records_the_expected_failure() {
        let plain = serde_json::to_value(CheckResult::judged("c".into(), 0.5, 1.0)).unwrap();
        assert_eq!(
            plain,
            serde_json::json!({"check": "c", "error": 0.5, "tol": 1.0, "passed": true})
        );
        let entry = serde_json::to_value(listed(1e-3)).unwrap();
        assert_eq!(
            entry["expected_failure"],
            serde_json::json!({"reason": "known", "verdict": "failed as expected"})
        );
        assert_eq!(entry["passed"], false);
    }
}
