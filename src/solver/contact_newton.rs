//! Frictionless contact with penalty-type enforcement as a [`System`] for the Newton core
//! ([`super::newton`]): `solver.scheme: "newton"`.
//!
//! Unknowns: the free displacements `x` (prescribed values folded in, [`LinearSystem`]). Each
//! contact row `i` (a [`Constraint`]: gap `g_i(u)`, gradient `b_i`, tributary area `A_i`) with
//! penalty weight `w_i = kappa A_i` and augmentation `lambda_bar_i` (zero for penalty and the
//! perturbed Lagrangian, the Uzawa multiplier for the augmented Lagrangian) carries the force
//! `lambda_i = max(0, lambda_bar_i - w_i g_i)` (ties: no max). The residual and tangent are
//!
//! `R(x) = K x - f - sum_i lambda_i b_i`,
//! `K_T(x) = K + sum_{i active} (w_i b_i b_i^T - lambda_i H_i)`,
//!
//! with `H_i` the second derivative of the gap where the row provides it (rigid circles in the
//! current geometry, [`gap_second_derivative`]). In the current geometry the rows are searched
//! again at every iterate (`x = X + u`), so the geometry updates and the active-set iterations of
//! the active-set scheme are one Newton loop here. Rows whose gradient lacks its own variation
//! (node-to-surface and mortar against deformable masters: no `delta xi` and normal terms yet)
//! give a tangent that is not exact, and Newton converges linearly on them; the history shows it.
//!
//! The augmented Lagrangian updates `lambda_bar_i <- max(0, lambda_bar_i - w_i g_i)` after every
//! iteration or, in an outer loop, after Newton has converged ([`MultiplierUpdate`]), until
//! every update is negligible (`|w_i g_i| <= 1e-12` of the largest force, or the gap is at the
//! round-off floor `1e-15` of the model size), the stopping rule of the active-set scheme.
//!
//! A body held by nothing but contact rows that are open at the start has a singular tangent:
//! in the first evaluation the rows that would hold it are closed, nearest first
//! ([`RigidModes::close_free_bodies`]), as in the active-set scheme; their forces may then be
//! tensile, which pulls the body onto the surface, and the next evaluation decides their status
//! from the gaps.

use super::active_set::{row_key, rows_at, RowKey};
use super::linear::{assemble, finish, LinearSystem, Solution, Timings, NO_EQUATION};
use super::newton::{self, Evaluation, System, Tangent};
use super::sparse::{GeneralPattern, SymmetricPattern};
use crate::contact::discretization::gap_second_derivative;
use crate::contact::enforcement::{method, Method};
use crate::contact::state::{ContactState, Termination};
use crate::contact::Constraint;
use crate::error::Result;
use crate::io::scene::{ContactGeometry, MultiplierUpdate};
use crate::model::rigid::RigidModes;
use crate::model::Model;
use std::collections::{HashMap, HashSet};
use std::time::Instant;

/// Residual tolerance of the Newton solve, relative to the largest applied or contact force.
pub const RESIDUAL_TOLERANCE: f64 = 1e-10;

/// The penalty-type contact problem of one load step.
pub(crate) struct PenaltyContact<'a> {
    model: &'a Model,
    sys: LinearSystem,
    version: usize,
    /// Rows of the last evaluation (current geometry) or of the reference configuration.
    rows: Vec<Constraint>,
    /// Per point: the Uzawa multiplier, the status and the force of the last evaluation.
    augmentation: HashMap<RowKey, f64>,
    active: HashMap<RowKey, bool>,
    forces: HashMap<RowKey, f64>,
    /// Rows closed in the first evaluation to hold bodies that would otherwise float.
    closed_at_start: HashSet<RowKey>,
    evaluations: usize,
    pub(crate) search_seconds: f64,
}

impl<'a> PenaltyContact<'a> {
    /// The problem at the start of a load step: `previous` are the active points of the last
    /// step, `u` its displacement.
    pub(crate) fn new(
        model: &'a Model,
        u: Option<&[f64]>,
        previous: Option<&HashSet<RowKey>>,
    ) -> Result<Self> {
        let current = model.physics.contact_geometry == ContactGeometry::Current;
        let t = Instant::now();
        let rows = rows_at(model, if current { u } else { None })?;
        let search_seconds = t.elapsed().as_secs_f64();
        let blocks: Vec<Vec<usize>> = rows.iter().map(|r| r.dofs.clone()).collect();
        let sys = assemble(model, &blocks);
        sys.check_assembled(model)?;
        let zero = vec![0.0; model.dof_count];
        let u = u.unwrap_or(&zero);
        let size = model.size();
        let gaps: Vec<f64> = rows.iter().map(|r| r.gap(u)).collect();
        let mut closed: Vec<bool> = rows
            .iter()
            .zip(&gaps)
            .map(|(r, &g)| {
                r.bilateral
                    || g <= 1e-14 * size
                    || previous.is_some_and(|p| p.contains(&row_key(r)))
            })
            .collect();
        RigidModes::new(model).close_free_bodies(&rows, &gaps, size, &mut closed);
        let closed_at_start = rows
            .iter()
            .zip(&closed)
            .filter(|(_, &c)| c)
            .map(|(r, _)| row_key(r))
            .collect();
        Ok(PenaltyContact {
            model,
            sys,
            version: 0,
            rows,
            augmentation: HashMap::new(),
            active: HashMap::new(),
            forces: HashMap::new(),
            closed_at_start,
            evaluations: 0,
            search_seconds,
        })
    }

    /// `(kappa A, Uzawa rule)` of row `r`.
    fn weight(&self, r: &Constraint) -> (f64, Option<MultiplierUpdate>) {
        match method(&self.model.contact[r.pair].enforcement).kernel() {
            Method::Regularized { kappa } => (kappa * r.area, None),
            Method::AugmentedLagrange { kappa, update } => (kappa * r.area, Some(update)),
            other => unreachable!("the model refuses {other:?} with the Newton scheme"),
        }
    }

    /// The force of row `r` at the displacement `u`, and whether it is active.
    fn force(&self, r: &Constraint, u: &[f64]) -> (f64, bool) {
        let key = row_key(r);
        let (w, _) = self.weight(r);
        let trial = self.augmentation.get(&key).copied().unwrap_or(0.0) - w * r.gap(u);
        let closed = self.evaluations == 0 && self.closed_at_start.contains(&key);
        if r.bilateral || closed || trial > 0.0 {
            (trial, true)
        } else {
            (0.0, false)
        }
    }

    /// Grow the pattern when a row couples equations it does not hold (a slave node that slid
    /// onto new master nodes): assemble again with every row's block.
    fn cover(&mut self) {
        let eq = &self.sys.eq;
        let covered = self.rows.iter().all(|r| {
            let eqs: Vec<usize> = r
                .dofs
                .iter()
                .map(|&d| eq[d])
                .filter(|&e| e != NO_EQUATION)
                .collect();
            eqs.iter().all(|&a| {
                eqs.iter()
                    .all(|&b| self.sys.pattern.position(a.min(b), a.max(b)).is_some())
            })
        });
        if !covered {
            let blocks: Vec<Vec<usize>> = self.rows.iter().map(|r| r.dofs.clone()).collect();
            self.sys = assemble(self.model, &blocks);
            self.version += 1;
        }
    }

    /// The contact state at the displacement `u` (after the solve).
    fn state(&self, u: &[f64]) -> (Vec<bool>, Vec<f64>, Vec<f64>) {
        let mut active = Vec::with_capacity(self.rows.len());
        let mut forces = Vec::with_capacity(self.rows.len());
        for r in &self.rows {
            let (f, a) = self.force(r, u);
            active.push(a);
            forces.push(f);
        }
        let gaps = self.rows.iter().map(|r| r.gap(u)).collect();
        (active, forces, gaps)
    }
}

impl System for PenaltyContact<'_> {
    fn pattern(&self) -> &SymmetricPattern {
        &self.sys.pattern
    }

    fn pattern_version(&self) -> usize {
        self.version
    }

    fn evaluate(
        &mut self,
        x: &[f64],
        general: &GeneralPattern,
        residual: &mut [f64],
        tangent: &mut Tangent,
    ) -> Result<Evaluation> {
        let u = self.sys.expand(x);
        let current = self.model.physics.contact_geometry == ContactGeometry::Current;
        if current && self.evaluations > 0 {
            let t = Instant::now();
            self.rows = rows_at(self.model, Some(&u))?;
            self.search_seconds += t.elapsed().as_secs_f64();
            let version = self.version;
            self.cover();
            if self.version != version {
                return Ok(Evaluation::default());
            }
        }
        self.sys.pattern.mul(&self.sys.k, x, residual);
        residual
            .iter_mut()
            .zip(&self.sys.rhs)
            .for_each(|(r, f)| *r -= f);
        tangent.values = general.symmetric_values(&self.sys.k);
        tangent.symmetric = true;
        let eq = &self.sys.eq;
        let mut eval = Evaluation {
            force_scale: super::linear::max_abs(&self.sys.rhs),
            ..Evaluation::default()
        };
        let geometric = current && self.model.solver.geometric_stiffness;
        let mut active = HashMap::with_capacity(self.rows.len());
        let mut forces = HashMap::with_capacity(self.rows.len());
        let mut eqs = Vec::new();
        for r in &self.rows {
            let key = row_key(r);
            let (lambda, on) = self.force(r, &u);
            let (w, _) = self.weight(r);
            if self.active.get(&key).copied().unwrap_or(false) != on && self.evaluations > 0 {
                eval.status_changes += 1;
            }
            eval.multiplier_change = eval
                .multiplier_change
                .max((lambda - self.forces.get(&key).copied().unwrap_or(0.0)).abs());
            if !r.bilateral {
                eval.max_gap_violation = eval.max_gap_violation.max(-r.gap(&u));
            }
            active.insert(key, on);
            forces.insert(key, lambda);
            if !on {
                continue;
            }
            eval.active += 1;
            eqs.clear();
            eqs.extend(r.dofs.iter().map(|&d| eq[d]));
            for (&e, &c) in eqs.iter().zip(&r.coeffs) {
                if e != NO_EQUATION {
                    residual[e] -= lambda * c;
                    eval.force_scale = eval.force_scale.max((lambda * c).abs());
                }
            }
            for (a, (&ea, &ca)) in eqs.iter().zip(&r.coeffs).enumerate() {
                if ea == NO_EQUATION {
                    continue;
                }
                for (&eb, &cb) in eqs.iter().zip(&r.coeffs).skip(a) {
                    if eb == NO_EQUATION {
                        continue;
                    }
                    let v = w * ca * cb;
                    tangent.values[general.position(ea, eb).expect("covered")] += v;
                    if ea != eb {
                        tangent.values[general.position(eb, ea).expect("covered")] += v;
                    }
                }
            }
            if geometric && lambda != 0.0 {
                let b = &self.model.bodies[r.slave_body];
                let dofs = [b.dof(r.slave_node, 0), b.dof(r.slave_node, 1)];
                let x_s = [
                    b.mesh.nodes[r.slave_node][0] + u[dofs[0]],
                    b.mesh.nodes[r.slave_node][1] + u[dofs[1]],
                ];
                if let Some(h) = gap_second_derivative(self.model, r, x_s) {
                    for a in 0..2 {
                        for c in 0..2 {
                            let (ea, ec) = (eq[dofs[a]], eq[dofs[c]]);
                            if ea != NO_EQUATION && ec != NO_EQUATION {
                                tangent.values[general.position(ea, ec).expect("node block")] -=
                                    lambda * h[2 * a + c];
                            }
                        }
                    }
                }
            }
        }
        self.active = active;
        self.forces = forces;
        self.evaluations += 1;
        Ok(eval)
    }

    fn augment(&mut self, x: &[f64], converged: bool) -> bool {
        let u = self.sys.expand(x);
        let size = self.model.size();
        let fmax = self.forces.values().fold(0.0f64, |m, f| m.max(f.abs()));
        let mut moved = false;
        let mut updates = Vec::new();
        for r in &self.rows {
            let (w, rule) = self.weight(r);
            let Some(rule) = rule else { continue };
            let key = row_key(r);
            if !self.active.get(&key).copied().unwrap_or(false) {
                continue;
            }
            if rule == MultiplierUpdate::OuterLoop && !converged {
                continue;
            }
            let g = r.gap(&u);
            if (w * g).abs() <= 1e-12 * fmax || g.abs() <= 1e-15 * size {
                continue;
            }
            let next = self.augmentation.get(&key).copied().unwrap_or(0.0) - w * g;
            updates.push((key, if r.bilateral { next } else { next.max(0.0) }));
            moved = true;
        }
        self.augmentation.extend(updates);
        moved
    }
}

/// One load step by Newton's method, from the active points `previous` and the displacement
/// `start` of the last step.
pub(crate) fn solve_step(
    model: &Model,
    previous: Option<HashSet<RowKey>>,
    start: Option<Vec<f64>>,
    progress: &mut dyn FnMut(&str),
) -> Result<Solution> {
    let mut timings = Timings::default();
    let t = Instant::now();
    progress("assembling");
    let mut system = PenaltyContact::new(model, start.as_deref(), previous.as_ref())?;
    timings.assembly = (t.elapsed().as_secs_f64() - system.search_seconds).max(0.0);
    let mut x: Vec<f64> = match &start {
        Some(u) => system
            .sys
            .eq
            .iter()
            .enumerate()
            .filter(|(_, &e)| e != NO_EQUATION)
            .map(|(d, _)| u[d])
            .collect(),
        None => vec![0.0; system.sys.n],
    };
    let t = Instant::now();
    progress("newton iterations");
    let outcome = newton::solve(
        &mut system,
        &mut x,
        newton::Settings {
            max_iterations: model.solver.max_iterations,
            tolerance: RESIDUAL_TOLERANCE,
        },
    )?;
    timings.factorization = outcome.factorization_seconds;
    timings.contact_search = system.search_seconds;
    timings.solve =
        (t.elapsed().as_secs_f64() - outcome.factorization_seconds - timings.contact_search)
            .max(0.0);
    let u = system.sys.expand(&x);
    let (active, forces, gaps) = system.state(&u);
    let mut contact_force = vec![0.0; model.dof_count];
    for (r, &f) in system.rows.iter().zip(&forces) {
        for (&d, &c) in r.dofs.iter().zip(&r.coeffs) {
            contact_force[d] += c * f;
        }
    }
    let current = model.physics.contact_geometry == ContactGeometry::Current;
    let mut solution = finish(model, &system.sys, u.clone(), &contact_force, timings)?;
    let termination = outcome.termination;
    let iterations = outcome.iterations;
    solution.contact = Some(ContactState {
        rows: std::mem::take(&mut system.rows),
        active,
        forces,
        gaps,
        termination: match termination {
            Termination::Singular(why) => Termination::Singular(format!(
                "{why}; a body may be held by contact rows that opened (check its supports)"
            )),
            t => t,
        },
        iterations,
        rank_deficiency: None,
        linear_solver: outcome.linear_solver,
        geometry_updates: if current { iterations } else { 1 },
        configuration: current.then_some(u),
        departures: Vec::new(),
        steps: Vec::new(),
        history: outcome.history,
        geometry_changes: Vec::new(),
    });
    Ok(solution)
}
