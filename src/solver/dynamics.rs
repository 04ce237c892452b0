//! Time integration of `M a + K d = f + B^T lambda` by Newmark's method, with contact, and three
//! treatments of impact and release (`physics.dynamics`, validated in
//! [`crate::model::dynamics`]).
//!
//! **Newmark** (Newmark 1959; Hughes, *The Finite Element Method* (1987), 9.1): with the
//! predictor `d~ = d_n + dt v_n + dt^2 (1/2 - beta) a_n`,
//!
//! `d_{n+1} = d~ + beta dt^2 a_{n+1}`, `v_{n+1} = v_n + dt ((1 - gamma) a_n + gamma a_{n+1})`.
//!
//! *Implicit* (`beta > 0`): with `c0 = 1 / (beta dt^2)` the step is the static contact problem
//! `(K + c0 M) d_{n+1} = f + c0 M d~ + B^T lambda`, solved by the Newton core on the contact
//! system of [`super::contact_newton`] with the inertia added to its stiffness and right-hand
//! side (every enforcement and discretization the Newton scheme has: Lagrange multipliers,
//! penalty, the perturbed and augmented Lagrangian, the perturbed tangent; node-to-node,
//! node-to-surface, mortar, rigid masters); then `a_{n+1} = c0 (d_{n+1} - d~)`. The matrix
//! `K + c0 M` does not change between steps: with linear bodies and an unchanged active set a step is one evaluation and
//! one back-substitution with the factorization of an earlier step ([`newton::solve_with`];
//! the history counts factorizations and reuses). *Explicit* (`beta = 0`, lumped mass, penalty
//! contact): `d_{n+1} = d~`, `a_{n+1} = M^-1 (f - K d_{n+1} + B^T lambda(d_{n+1}))`.
//! `a_0 = M^-1 (f - K d_0)`: the bodies start undeformed, contact forces zero.
//!
//! **Coulomb friction** (implicit, `plain` or `post_impact`, every enforcement the Newton scheme
//! has; [`crate::model::dynamics`] refuses the rest): each step's Newton solve runs the return
//! map of [`crate::contact::friction`] against the slip history committed after the last step,
//! as a load step does against the last load step; the step's frictional points are then
//! committed (`ContactSystem::commit_friction`, with the Uzawa multipliers of the augmented
//! Lagrangian and the perturbed tangent, which start the next step from them) and their
//! tangential forces enter the reported equilibrium. With every closed point slipping one way, Newmark's momentum balance gives
//! `Delta p_t = -mu (Delta p_n + P T)` over the steps (the contact forces are zero at `t = 0`).
//!
//! **Impact and release.** At impact plain Newmark leaves the two nodes of a contacting pair with
//! different velocities and accelerations (Taylor 2004, "1974-77: The Foundations": "this
//! violates the physics"; Hughes, Taylor, Sackman, Curnier & Kanoknukulchai, CMAME 8 (1976)
//! 249-276). Per case:
//!
//! * `plain`: Newmark's values as they are.
//! * `post_impact`: the seed's correction, after every step for the active rows `B` (free
//!   dofs): the accelerations are made to satisfy `B a_+ = 0` with the least change in the mass
//!   norm, `a_+ = a_- - M^-1 B^T S^-1 B a_-`, `S = B M^-1 B^T`, and the contact forces change by
//!   `c_+ - c_- = -S^-1 B a_-` (for one node pair with lumped masses
//!   `a_+ = (M1 a1 + M2 a2) / (M1 + M2)`, `c_+ = c_- - M1 M2 / (M1 + M2) (a2 - a1)`, a rigid
//!   master `M2 -> infinity`); the velocities are set by the 1D wave (impedance) solution,
//!   `v_+ = v_- - Z^-1 B^T (B Z^-1 B^T)^-1 B v_-` with `Z` the impedance `rho c_p` of each dof's
//!   body (`c_p` the dilatational wave speed), which for a node pair is
//!   `v_+ = (Z1 v1 + Z2 v2) / (Z1 + Z2)` and for a rigid master `0`. A row that opens carries no
//!   force and is not corrected: its nodes separate with their own velocities; so is a row
//!   whose corrected force would pull (`c_+ < 0`: it is opening), the others corrected again.
//!   The correction is dense in the active rows (`m` columns of `M^-1 B^T`, the `m x m`
//!   matrix `S` and its eigen-decomposition); above the case's factorization limits it is
//!   refused, naming them.
//! * `contact_stabilized`: the contact-stabilized Newmark method of Deuflhard, Krause & Ertel,
//!   "A contact-stabilized Newmark method for dynamical contact problems", IJNME 73 (2008)
//!   1274-1290, on the trapezoidal rule: the predictor `d_n + dt v_n` is first projected onto
//!   the admissible set in the mass norm, `d^ = argmin_{g(d) >= 0} |d - d_n - dt v_n|_M` (the
//!   same contact rows, with `c0 M` as the only stiffness), then
//!   `(K + c0 M) d_{n+1} = c0 M d^ + 2 f - K d_n + B^T lambda` (`c0 = 4 / dt^2`; `lambda / 2` is
//!   the step's mean contact force) and `v_{n+1} = v_n + (2 / dt)(d_{n+1} - d^)`. Without
//!   contact it is the trapezoidal rule (energy conserved); with contact the projection removes
//!   the velocity into the obstacle, so the discrete energy does not grow where the
//!   constraints hold exactly (their theorem, for Lagrange multipliers: the history shows the
//!   drift, about 1e-14) and the contact nodes do not chatter. A penalty's penetration stores
//!   energy the projection does not see and can give it back: the bar on a rigid wall with
//!   `kappa = E / h` gains 8.6 % (`tests/stable_step.rs`), and such a run warns
//!   ([`crate::harness::stability::energy_growth`]). The method's equilibrium holds at the
//!   step's mean displacement, `K (d_n + d_{n+1}) / 2 + M a = f + B^T lambda / 2`; the recorded
//!   acceleration is the step's mean `(v_{n+1} - v_n) / dt` and the recorded contact force the
//!   step's mean `lambda / 2`, and the residual of the solution is that equation's.

use super::contact_newton::ContactSystem;
use super::history::{DynamicHistory, StepRecord};
use super::linear::{finish, Solution, Timings, NO_EQUATION};
use super::newton::{self, LinearSolver, System, Tangent};
use super::sparse::{Cholesky, Factor, GeneralPattern, PatternBuilder, SymmetricPattern};
use crate::contact::enforcement::{method, Method};
use crate::contact::state::{ContactState, Termination};
use crate::error::{Error, Result};
use crate::io::scene::{ImpactTreatment, Interaction, MassKind};
use crate::model::dynamics::Dynamics;
use crate::model::stable_step::{
    critical_omega_dt, largest_frequency_bound, penalty_frequency_bound,
};
use crate::model::Model;
use crate::solid::{element_mass, lumped_mass};
use std::time::Instant;

/// The mass matrix over every global dof (both components alike).
pub struct MassMatrix {
    pub pattern: SymmetricPattern,
    /// Upper triangle on `pattern`.
    pub values: Vec<f64>,
    /// Total mass of each body.
    pub body_mass: Vec<f64>,
}

impl MassMatrix {
    /// `y = M x`.
    pub fn mul(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; x.len()];
        self.pattern.mul(&self.values, x, &mut y);
        y
    }

    /// The diagonal entry of dof `d`.
    pub fn diagonal(&self, d: usize) -> f64 {
        self.pattern.position(d, d).map_or(0.0, |k| self.values[k])
    }
}

/// The consistent or lumped (HRZ) mass of `model` with the densities `density` per body.
pub fn mass_matrix(model: &Model, density: &[f64], kind: MassKind) -> MassMatrix {
    let n = model.dof_count;
    let mut builder = PatternBuilder::new(n);
    let mut dofs = Vec::new();
    if kind == MassKind::Consistent {
        for body in &model.bodies {
            for c in 0..body.mesh.cell_count() {
                body.cell_dofs(c, &mut dofs);
                builder.add_block(&dofs);
            }
        }
    }
    let pattern = builder.build();
    let mut values = vec![0.0; pattern.nnz()];
    let mut body_mass = Vec::with_capacity(model.bodies.len());
    for (body, &rho) in model.bodies.iter().zip(density) {
        let kind_e = body.mesh.kind;
        let nn = kind_e.node_count();
        let mut me = vec![0.0; nn * nn];
        let mut total = 0.0;
        for c in 0..body.mesh.cell_count() {
            element_mass(
                kind_e,
                &body.mesh.cell_coords(c),
                rho,
                model.thickness,
                &mut me,
            );
            let nodes = body.mesh.cell(c);
            total += me.iter().sum::<f64>();
            match kind {
                MassKind::Lumped => {
                    for (a, m) in lumped_mass(&me, nn).into_iter().enumerate() {
                        for comp in 0..2 {
                            let d = body.dof(nodes[a], comp);
                            values[pattern.position(d, d).expect("diagonal")] += m;
                        }
                    }
                }
                MassKind::Consistent => {
                    for a in 0..nn {
                        for b in a..nn {
                            for comp in 0..2 {
                                let (da, db) = (body.dof(nodes[a], comp), body.dof(nodes[b], comp));
                                let k = pattern.position(da, db).expect("cell block");
                                // a diagonal pair of a repeated node adds once per element
                                values[k] += me[a * nn + b];
                                if a != b && da == db {
                                    values[k] += me[b * nn + a];
                                }
                            }
                        }
                    }
                }
            }
        }
        body_mass.push(total);
    }
    MassMatrix {
        pattern,
        values,
        body_mass,
    }
}

/// The dilatational wave speed `c_p = sqrt((lambda + 2 mu) / rho)` of plane strain (of the
/// plane-stress modulus `E / (1 - nu^2)` in plane stress); with `nu = 0` the bar speed
/// `sqrt(E / rho)`.
pub fn wave_speed(model: &Model, body: usize, density: f64) -> f64 {
    // D_xx: lambda + 2 mu in plane strain, E / (1 - nu^2) in plane stress
    (model.bodies[body].material.d[(0, 0)] / density).sqrt()
}

/// The energies of the state `(d, v)` and the penalty energy of the rows.
struct Energies {
    kinetic: f64,
    strain: f64,
    contact: f64,
    load: f64,
}

impl Energies {
    fn total(&self) -> f64 {
        self.kinetic + self.strain + self.contact + self.load
    }
}

/// Time-step `model` (which has `physics.dynamics`); `progress` hears the stages.
pub fn solve(model: &Model, progress: &mut dyn FnMut(&str)) -> Result<Solution> {
    let dynamics = model
        .dynamics
        .as_ref()
        .expect("solve is called for dynamic models");
    Integrator::new(model, dynamics, progress)?.run(progress)
}

/// Refuse a conditionally stable member (central difference) whose `dt` is above its
/// stability limit: the element bound of the bodies' largest frequency plus the bound of the
/// candidate penalty rows ([`crate::model::stable_step`]).
fn check_stable_step(
    model: &Model,
    dynamics: &Dynamics,
    system: &ContactSystem,
    mass: &MassMatrix,
) -> Result<()> {
    let (beta, gamma, dt) = (dynamics.beta, dynamics.gamma, dynamics.dt);
    let Some(omega_dt) = critical_omega_dt(beta, gamma) else {
        return Ok(());
    };
    let Some(bodies) = largest_frequency_bound(model, &dynamics.density) else {
        return Ok(());
    };
    let rows: Vec<(f64, Vec<(usize, f64)>)> = system
        .rows()
        .iter()
        .filter_map(|r| {
            let w = system.penalty_weight(r)?;
            let terms = r
                .dofs
                .iter()
                .zip(&r.coeffs)
                .filter(|(&d, _)| model.prescribed[d].is_none())
                .map(|(&d, &c)| (d, c))
                .collect();
            Some((w, terms))
        })
        .collect();
    let contact = penalty_frequency_bound(&rows, |d| mass.diagonal(d));
    let omega = (bodies.omega * bodies.omega + contact).sqrt();
    let limit = omega_dt / omega;
    if dt <= limit {
        return Ok(());
    }
    let body = &model.bodies[bodies.body];
    let penalty = if contact > 0.0 {
        format!(
            " and by {:.4e} from the penalty contact rows (kappa A over the nodal masses)",
            contact.sqrt()
        )
    } else {
        String::new()
    };
    Err(Error::invalid(
        &model.source,
        "physics.dynamics.dt",
        format!(
            "dt = {dt:.4e} is above the stability limit {limit:.4e} of this integrator (beta {beta}, gamma {gamma}: omega dt <= {omega_dt:.4}, the largest natural frequency omega bounded by {:.4e} from element {} of body '{}'{penalty}); the run would blow up",
            bodies.omega, bodies.cell, body.name
        ),
        format!(
            "take dt <= {:.3e} (0.9 of the limit){}, or an unconditionally stable integrator such as \"average_acceleration\"",
            0.9 * limit,
            if contact > bodies.omega * bodies.omega { ", or a softer penalty" } else { "" }
        ),
    ))
}

/// The state of a time integration.
struct Integrator<'a> {
    model: &'a Model,
    dynamics: &'a Dynamics,
    system: ContactSystem<'a>,
    linear: LinearSolver,
    mass: MassMatrix,
    /// The contact-stabilized method's projection: its system (stiffness `c0 M`), linear
    /// solver and unknowns.
    projection: Option<(ContactSystem<'a>, LinearSolver, Vec<f64>)>,
    /// Cholesky factor of `M_ff` (for `M^-1` of accelerations and corrections).
    mass_factor: Factor,
    /// `f_f - K_fp u_p` of the system as built.
    rhs0: Vec<f64>,
    c0: f64,
    /// Impedance `rho c_p` of each global dof's body.
    impedance: Vec<f64>,
    d: Vec<f64>,
    /// `d_n`, the displacement at the start of the last step (the contact-stabilized
    /// method's equilibrium holds at the step's mean displacement, see [`Integrator::finish`]).
    d_before: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    /// Unknowns of the system (free displacements, then multipliers).
    x: Vec<f64>,
    /// Row forces (after the treatment) of the last step.
    forces: Vec<f64>,
    /// The frictional points at the end of the last step (`None` for frictionless rows).
    friction: Vec<Option<crate::contact::friction::FrictionPoint>>,
    timings: Timings,
    history: Vec<StepRecord>,
    frames: Vec<(f64, Vec<f64>)>,
    iterations: usize,
}

impl<'a> Integrator<'a> {
    fn new(
        model: &'a Model,
        dynamics: &'a Dynamics,
        progress: &mut dyn FnMut(&str),
    ) -> Result<Self> {
        let t = Instant::now();
        progress("assembling");
        let mut system = ContactSystem::new(model, None, None, Default::default())?;
        let mass = mass_matrix(model, &dynamics.density, dynamics.mass);
        check_stable_step(model, dynamics, &system, &mass)?;
        let sys = system.linear_system();
        // M_ff on the pattern of K_ff (every mass entry lies in a cell block)
        let mut mass_ff = vec![0.0; sys.pattern.nnz()];
        for j in 0..model.dof_count {
            for k in mass.pattern.col_ptr[j]..mass.pattern.col_ptr[j + 1] {
                let i = mass.pattern.row_idx[k];
                let (ei, ej) = (sys.eq(i), sys.eq(j));
                if ei != NO_EQUATION && ej != NO_EQUATION {
                    let p = sys.pattern.position(ei, ej).expect("cell block");
                    mass_ff[p] += mass.values[k];
                }
            }
        }
        let mass_factor = Cholesky::analyse(&sys.pattern, &model.factor_limit)
            .and_then(|c| c.factor(&sys.pattern, &mass_ff))
            .map_err(|e| sys.factor_error(model, e))?;
        let rhs0 = sys.rhs.clone();
        let c0 = if dynamics.explicit() {
            0.0
        } else {
            1.0 / (dynamics.beta * dynamics.dt * dynamics.dt)
        };
        if c0 > 0.0 {
            let scaled: Vec<f64> = mass_ff.iter().map(|m| c0 * m).collect();
            system.add_to_stiffness(&scaled);
        }
        let mut impedance = vec![0.0; model.dof_count];
        for (b, body) in model.bodies.iter().enumerate() {
            let rho = dynamics.density[b];
            let z = rho * wave_speed(model, b, rho);
            for d in body.dof_offset..body.dof_offset + body.dof_count() {
                impedance[d] = z;
            }
        }
        let projection = if dynamics.impact == ImpactTreatment::ContactStabilized {
            let mut p = ContactSystem::new(model, None, None, Default::default())?;
            p.replace_stiffness(mass_ff.iter().map(|m| c0 * m).collect());
            let linear = LinearSolver::new(p.pattern(), model.factor_limit);
            let x = vec![0.0; p.pattern().n];
            Some((p, linear, x))
        } else {
            None
        };
        let linear = LinearSolver::new(system.pattern(), model.factor_limit);
        let n_unknowns = system.pattern().n;
        let d = system
            .linear_system()
            .expand(&vec![0.0; system.linear_system().n]);
        let v = dynamics.initial_velocity.clone();
        let mut timings = Timings {
            assembly: t.elapsed().as_secs_f64(),
            ..Timings::default()
        };
        timings.contact_search = system.search_seconds;
        let rows = system.rows().len();
        let mut integrator = Integrator {
            model,
            dynamics,
            system,
            linear,
            mass,
            projection,
            mass_factor,
            rhs0,
            c0,
            impedance,
            a: vec![0.0; model.dof_count],
            d_before: d.clone(),
            d,
            v,
            x: vec![0.0; n_unknowns],
            forces: vec![0.0; rows],
            friction: vec![None; rows],
            timings,
            history: Vec::new(),
            frames: Vec::new(),
            iterations: 0,
        };
        // a_0 = M^-1 (f - K d_0)
        let residual = integrator.static_residual()?;
        integrator.a = integrator.solve_mass(&residual.iter().map(|r| -r).collect::<Vec<_>>());
        Ok(integrator)
    }

    /// `K x - f - B^T lambda(x)` over the free equations at the current unknowns `x` (the
    /// inertia taken out).
    fn static_residual(&mut self) -> Result<Vec<f64>> {
        let n = self.system.linear_system().n;
        let mut rhs = self.rhs0.clone();
        if self.c0 > 0.0 {
            let m_x = mass_times(&self.mass, self.system.linear_system(), &self.x[..n]);
            rhs.iter_mut()
                .zip(&m_x)
                .for_each(|(r, m)| *r += self.c0 * m);
        }
        self.system.set_right_hand_side(rhs);
        let general = GeneralPattern::from_symmetric(self.system.pattern());
        let mut residual = vec![0.0; self.x.len()];
        let mut tangent = Tangent {
            values: vec![0.0; general.nnz()],
            symmetric: true,
            multipliers: 0,
            scale: 1.0,
            elimination: None,
            indefinite_block: false,
        };
        self.system
            .evaluate(&self.x, &general, &mut residual, &mut tangent)?;
        residual.truncate(n);
        Ok(residual)
    }

    /// The global vector whose free part is `M_ff^-1 r` (zero at prescribed dofs).
    fn solve_mass(&self, r: &[f64]) -> Vec<f64> {
        let sys = self.system.linear_system();
        let mut y = r.to_vec();
        self.mass_factor.solve_in_place(&mut y);
        let mut full = vec![0.0; self.model.dof_count];
        for (e, &d) in sys.constraints.free_dofs().iter().enumerate() {
            full[d] = y[e];
        }
        full
    }

    fn run(mut self, progress: &mut dyn FnMut(&str)) -> Result<Solution> {
        let dyn_ = self.dynamics;
        progress("time steps");
        self.record(0, 0.0, [0.0; 2], [0.0; 2], 0);
        self.frames.push((0.0, self.d.clone()));
        for step in 1..=dyn_.steps {
            let time = step as f64 * dyn_.dt;
            let iterations = self.step(step, time)?;
            self.iterations += iterations;
            let (active, mut forces, _) = self.system.row_state(&self.x);
            // the step's frictional points, and their history committed for the next step
            self.friction = self.system.friction_state(&self.x);
            if self.friction.iter().any(Option::is_some) {
                self.system.commit_friction(&self.friction);
            }
            let active_rows: Vec<usize> = (0..active.len()).filter(|&i| active[i]).collect();
            let jumps_before = (
                self.largest_rate(&active_rows, &self.v),
                self.largest_rate(&active_rows, &self.a),
            );
            match dyn_.impact {
                ImpactTreatment::Plain => {}
                ImpactTreatment::PostImpact => {
                    self.post_impact(&active_rows, &mut forces)?;
                }
                ImpactTreatment::ContactStabilized => {
                    // the system's force is twice the step's mean contact force
                    forces.iter_mut().for_each(|f| *f *= 0.5);
                }
            }
            self.forces = forces;
            let jumps_after = (
                self.largest_rate(&active_rows, &self.v),
                self.largest_rate(&active_rows, &self.a),
            );
            self.record(
                step,
                time,
                [jumps_before.0, jumps_after.0],
                [jumps_before.1, jumps_after.1],
                iterations,
            );
            if step % dyn_.frame_every == 0 || step == dyn_.steps {
                self.frames.push((time, self.d.clone()));
            }
        }
        self.finish()
    }

    /// One Newmark step to `time`; returns the Newton iterations.
    fn step(&mut self, step: usize, time: f64) -> Result<usize> {
        let dyn_ = self.dynamics;
        let (beta, gamma, dt) = (dyn_.beta, dyn_.gamma, dyn_.dt);
        let free: Vec<usize> = self.system.linear_system().constraints.free_dofs().to_vec();
        let n = free.len();
        let at = format!("time step {step} (t = {time:e})");
        if let Some((projection, linear, x_p)) = &mut self.projection {
            // contact-stabilized: project d_n + dt v_n onto the admissible set (mass norm)
            let predictor: Vec<f64> = (0..self.d.len())
                .map(|k| self.d[k] + dt * self.v[k])
                .collect();
            let target: Vec<f64> = free.iter().map(|&d| predictor[d]).collect();
            let m_t = mass_times(&self.mass, projection.linear_system(), &target);
            projection.set_right_hand_side(m_t.iter().map(|m| self.c0 * m).collect());
            x_p[..n].copy_from_slice(&target);
            newton_step(
                self.model,
                projection,
                x_p,
                linear,
                &mut self.timings,
                &format!("the projection of {at}"),
            )?;
            let projected = projection.linear_system().expand(&x_p[..n]);
            // (K + c0 M) d_{n+1} = c0 M d^ + 2 f - K d_n + B^T lambda
            let k_d = super::linear::internal_force(self.model, &self.d);
            let projected_free: Vec<f64> = free.iter().map(|&d| projected[d]).collect();
            let m_p = mass_times(&self.mass, self.system.linear_system(), &projected_free);
            let rhs: Vec<f64> = (0..n)
                .map(|e| {
                    let d = free[e];
                    self.rhs0[e] + self.model.external_force[d] - k_d[d] + self.c0 * m_p[e]
                })
                .collect();
            self.system.set_right_hand_side(rhs);
            self.x[..n].copy_from_slice(&projected_free);
            let iterations = newton_step(
                self.model,
                &mut self.system,
                &mut self.x,
                &mut self.linear,
                &mut self.timings,
                &at,
            )?;
            let d_new = self.system.linear_system().expand(&self.x[..n]);
            self.d_before = std::mem::replace(&mut self.d, d_new);
            for k in 0..self.v.len() {
                let v_new = self.v[k] + 2.0 / dt * (self.d[k] - projected[k]);
                self.a[k] = (v_new - self.v[k]) / dt;
                self.v[k] = v_new;
            }
            return Ok(iterations);
        }
        let predictor: Vec<f64> = (0..self.d.len())
            .map(|k| self.d[k] + dt * self.v[k] + dt * dt * (0.5 - beta) * self.a[k])
            .collect();
        for (e, &d) in free.iter().enumerate() {
            self.x[e] = predictor[d];
        }
        let mut iterations = 0;
        let a_new = if self.c0 > 0.0 {
            let target: Vec<f64> = free.iter().map(|&d| predictor[d]).collect();
            let m_t = mass_times(&self.mass, self.system.linear_system(), &target);
            let rhs: Vec<f64> = self
                .rhs0
                .iter()
                .zip(&m_t)
                .map(|(r, m)| r + self.c0 * m)
                .collect();
            self.system.set_right_hand_side(rhs);
            iterations = newton_step(
                self.model,
                &mut self.system,
                &mut self.x,
                &mut self.linear,
                &mut self.timings,
                &at,
            )?;
            self.d = self.system.linear_system().expand(&self.x[..n]);
            self.d
                .iter()
                .zip(&predictor)
                .map(|(d, p)| self.c0 * (d - p))
                .collect::<Vec<f64>>()
        } else {
            self.d = self.system.linear_system().expand(&self.x[..n]);
            let t = Instant::now();
            let r = self.static_residual()?;
            self.timings.solve += t.elapsed().as_secs_f64();
            self.solve_mass(&r.iter().map(|v| -v).collect::<Vec<_>>())
        };
        for k in 0..self.v.len() {
            self.v[k] += dt * ((1.0 - gamma) * self.a[k] + gamma * a_new[k]);
        }
        self.a = a_new;
        self.system.linear_system().check_finite(
            self.model,
            &self.x[..n],
            "the displacement",
            &format!("in {at}"),
        )?;
        Ok(iterations)
    }

    /// The largest `|b . y|` over the rows `rows`.
    fn largest_rate(&self, rows: &[usize], y: &[f64]) -> f64 {
        let all = self.system.rows();
        rows.iter()
            .map(|&i| {
                all[i]
                    .dofs
                    .iter()
                    .zip(&all[i].coeffs)
                    .map(|(&d, c)| c * y[d])
                    .sum::<f64>()
                    .abs()
            })
            .fold(0.0, f64::max)
    }

    /// The rows `rows` restricted to free equations: `(equation, coefficient)` lists.
    fn free_rows(&self, rows: &[usize]) -> Vec<Vec<(usize, f64)>> {
        let sys = self.system.linear_system();
        let all = self.system.rows();
        rows.iter()
            .map(|&i| {
                all[i]
                    .dofs
                    .iter()
                    .zip(&all[i].coeffs)
                    .filter_map(|(&d, &c)| {
                        let e = sys.eq(d);
                        (e != NO_EQUATION).then_some((e, c))
                    })
                    .collect()
            })
            .collect()
    }

    /// `W^-1 B^T` column by column (`W` the mass, or the diagonal `weights` per equation) and
    /// the projection `y <- y - W^-1 B^T S^+ B y`, `S = B W^-1 B^T`; returns `-S^+ B y`, the
    /// change of the row forces that goes with it.
    ///
    /// The projection is dense: `m` columns of `n` free equations, `S` and its eigenvectors
    /// `m x m`, and the eigen-decomposition about `m^3` multiply-adds; above the case's
    /// factorization limits (`limits.factor_gigabytes`, `limits.factor_operations`) it is
    /// refused before anything is allocated (a strip of 8000 elements dropped on a rigid line
    /// asked for 10 GB and aborted).
    fn project(
        &self,
        rows: &[Vec<(usize, f64)>],
        weights: Option<&[f64]>,
        y: &mut [f64],
    ) -> Result<Vec<f64>> {
        let sys = self.system.linear_system();
        let n = sys.n;
        let m = rows.len();
        let (mf, nf) = (m as f64, n as f64);
        let gigabytes = mf * (nf + 2.0 * mf) * 8.0 / 1e9;
        let operations = mf.powi(3);
        let limit = &self.model.factor_limit;
        if gigabytes > limit.gigabytes || operations > limit.operations {
            return Err(Error::Solver {
                path: self.model.source.clone(),
                problem: format!(
                    "the post-impact correction would project {m} active contact rows densely \
                     over {n} equations: {gigabytes:.2} GB and about {operations:.1e} \
                     multiply-adds, above the limits of {} GB (limits.factor_gigabytes) and \
                     {:.1e} multiply-adds (limits.factor_operations)",
                    limit.gigabytes, limit.operations
                ),
                hint: "use \"impact\": \"contact_stabilized\" or \"plain\", or fewer slave \
                       nodes on the interface (a coarser mesh along it), or raise the limits if \
                       the machine has the memory and the time"
                    .into(),
            });
        }
        let free = sys.constraints.free_dofs();
        // columns of W^-1 B^T over the free equations
        let columns: Vec<Vec<f64>> = rows
            .iter()
            .map(|r| {
                let mut col = vec![0.0; n];
                for &(e, c) in r {
                    col[e] += c;
                }
                match weights {
                    Some(w) => col.iter_mut().enumerate().for_each(|(e, v)| *v /= w[e]),
                    None => self.mass_factor.solve_in_place(&mut col),
                }
                col
            })
            .collect();
        let mut s = vec![0.0; m * m];
        for (i, r) in rows.iter().enumerate() {
            for (j, col) in columns.iter().enumerate() {
                s[i * m + j] = r.iter().map(|&(e, c)| c * col[e]).sum();
            }
        }
        // symmetrize (round-off) and invert on the range of S (dependent rows: two passes)
        for i in 0..m {
            for j in 0..i {
                let avg = 0.5 * (s[i * m + j] + s[j * m + i]);
                s[i * m + j] = avg;
                s[j * m + i] = avg;
            }
        }
        let by: Vec<f64> = rows
            .iter()
            .map(|r| r.iter().map(|&(e, c)| c * y[free[e]]).sum())
            .collect();
        let (eig, vecs) = super::dense::symmetric_eigen(&s, m);
        let largest = eig.iter().fold(0.0f64, |a, e| a.max(e.abs()));
        let mut mu = vec![0.0; m];
        for k in 0..m {
            if eig[k] <= 1e-12 * largest {
                continue;
            }
            let proj: f64 = (0..m).map(|i| vecs[i * m + k] * by[i]).sum::<f64>() / eig[k];
            for i in 0..m {
                mu[i] += vecs[i * m + k] * proj;
            }
        }
        for (col, &mu_j) in columns.iter().zip(&mu) {
            for (e, &d) in free.iter().enumerate() {
                y[d] -= col[e] * mu_j;
            }
        }
        Ok(mu.iter().map(|v| -v).collect())
    }

    /// The seed's post-impact correction of the active rows (see the module doc). A row whose
    /// corrected force would pull (it is opening) is released and left out, and the others are
    /// corrected again.
    fn post_impact(&mut self, active: &[usize], forces: &mut [f64]) -> Result<()> {
        let mut rows_in = active.to_vec();
        while !rows_in.is_empty() {
            let rows = self.free_rows(&rows_in);
            let mut a = self.a.clone();
            let change = self.project(&rows, None, &mut a)?;
            let all = self.system.rows();
            let opening: Vec<usize> = rows_in
                .iter()
                .zip(&change)
                .filter(|&(&i, dc)| !all[i].bilateral && forces[i] + dc < 0.0)
                .map(|(&i, _)| i)
                .collect();
            if !opening.is_empty() {
                rows_in.retain(|i| !opening.contains(i));
                continue;
            }
            self.a = a;
            for (&i, dc) in rows_in.iter().zip(change) {
                forces[i] += dc;
            }
            let sys = self.system.linear_system();
            let weights: Vec<f64> = sys
                .constraints
                .free_dofs()
                .iter()
                .map(|&d| self.impedance[d])
                .collect();
            let mut v = std::mem::take(&mut self.v);
            self.project(&rows, Some(&weights), &mut v)?;
            self.v = v;
            return Ok(());
        }
        Ok(())
    }

    fn energies(&self) -> Energies {
        let mv = self.mass.mul(&self.v);
        let kinetic = 0.5 * self.v.iter().zip(&mv).map(|(a, b)| a * b).sum::<f64>();
        let ku = super::linear::internal_force(self.model, &self.d);
        let strain = 0.5 * self.d.iter().zip(&ku).map(|(a, b)| a * b).sum::<f64>();
        let load = -self
            .model
            .external_force
            .iter()
            .zip(&self.d)
            .map(|(f, u)| f * u)
            .sum::<f64>();
        let mut contact = 0.0;
        for (i, (r, &f)) in self.system.rows().iter().zip(&self.forces).enumerate() {
            if f == 0.0 {
                continue;
            }
            let pair = &self.model.contact[r.pair];
            if let Method::Regularized { kappa } | Method::PerturbedLagrange { kappa } =
                method(&pair.enforcement).kernel()
            {
                let g = r.gap(&self.d);
                contact += 0.5 * kappa * r.area * g * g;
                // the tangential spring of a penalty Coulomb point stores its elastic slip
                // g_t - g_t^p: 1/2 w_t (g_t - g_t^p)^2 (zero in the open state)
                if let (Some(Some(point)), Interaction::Coulomb { kappa_t, .. }) =
                    (self.friction.get(i), pair.interaction)
                {
                    for a in 0..point.tangents {
                        let elastic = point.slip[a] - point.plastic_slip[a];
                        contact += 0.5 * kappa_t.unwrap_or(kappa) * r.area * elastic * elastic;
                    }
                }
            }
        }
        Energies {
            kinetic,
            strain,
            contact,
            load,
        }
    }

    fn record(
        &mut self,
        step: usize,
        time: f64,
        velocity_jump: [f64; 2],
        acceleration_jump: [f64; 2],
        iterations: usize,
    ) {
        let e = self.energies();
        let mv = self.mass.mul(&self.v);
        let mut momentum = [0.0; 2];
        let mut body_momentum = vec![[0.0; 2]; self.model.bodies.len()];
        for (b, body) in self.model.bodies.iter().enumerate() {
            for node in 0..body.mesh.nodes.len() {
                for c in 0..2 {
                    let p = mv[body.dof(node, c)];
                    momentum[c] += p;
                    body_momentum[b][c] += p;
                }
            }
        }
        let rows = self.system.rows();
        let (_, _, gaps) = self.system.row_state(&self.x);
        let min_gap =
            (!rows.is_empty()).then(|| gaps.iter().copied().fold(f64::INFINITY, f64::min));
        self.history.push(StepRecord {
            step,
            time,
            contact_force: self.forces.iter().sum(),
            min_gap,
            active: self.forces.iter().filter(|&&f| f != 0.0).count(),
            kinetic: e.kinetic,
            strain: e.strain,
            contact_energy: e.contact,
            load_potential: e.load,
            total: e.total(),
            momentum,
            body_momentum,
            velocity_jump,
            acceleration_jump,
            iterations,
            factorizations: self.linear.factorizations,
            reused_factorizations: self.linear.reused,
        });
    }

    fn finish(self) -> Result<Solution> {
        let model = self.model;
        let (active, _, gaps) = self.system.row_state(&self.x);
        let mut contact_force = vec![0.0; model.dof_count];
        for ((r, f), fr) in self
            .system
            .rows()
            .iter()
            .zip(&self.forces)
            .zip(&self.friction)
        {
            for (&d, &c) in r.dofs.iter().zip(&r.coeffs) {
                contact_force[d] += c * f;
            }
            if let Some(fr) = fr {
                for (t, &lambda_t) in r.tangents.iter().zip(&fr.force) {
                    for (&d, &c) in t.dofs.iter().zip(&t.coeffs) {
                        contact_force[d] += c * lambda_t;
                    }
                }
            }
        }
        // dynamic equilibrium: K d - f - B^T lambda + M a = 0 at the free dofs; the
        // contact-stabilized method satisfies it at the step's mean displacement
        // (K (d_n + d_{n+1}) / 2 + M a - f - B^T lambda = 0 with the mean acceleration
        // a = (v_{n+1} - v_n) / dt and the mean contact force, from its update
        // (K + c0 M) d_{n+1} = c0 M d^ + 2 f - K d_n + B^T lambda), so K (d_{n+1} - d_n) / 2
        // is added to the applied side
        let inertia = self.mass.mul(&self.a);
        let mut applied: Vec<f64> = contact_force
            .iter()
            .zip(&inertia)
            .map(|(c, i)| c - i)
            .collect();
        if self.dynamics.impact == ImpactTreatment::ContactStabilized {
            let increment: Vec<f64> = self
                .d
                .iter()
                .zip(&self.d_before)
                .map(|(a, b)| a - b)
                .collect();
            let k_increment = super::linear::internal_force(model, &increment);
            for (a, k) in applied.iter_mut().zip(&k_increment) {
                *a += 0.5 * k;
            }
        }
        let mut solution = finish(
            model,
            self.system.linear_system(),
            self.d.clone(),
            &applied,
            self.timings.clone(),
        )?;
        if !model.contact.is_empty() {
            solution.contact = Some(ContactState {
                rows: self.system.rows().to_vec(),
                active,
                forces: self.forces.clone(),
                gaps,
                termination: Termination::Converged,
                iterations: self.iterations,
                rank_deficiency: None,
                linear_solver: self.linear.last_solver,
                geometry_updates: 1,
                configuration: None,
                departures: Vec::new(),
                steps: Vec::new(),
                history: Vec::new(),
                geometry_changes: Vec::new(),
                friction: self.friction.clone(),
            });
        }
        let dyn_ = self.dynamics;
        let integrator = if dyn_.beta == 0.25 && dyn_.gamma == 0.5 {
            "average_acceleration".to_string()
        } else if dyn_.beta == 0.0 && dyn_.gamma == 0.5 {
            "central_difference".to_string()
        } else {
            format!("newmark(beta {}, gamma {})", dyn_.beta, dyn_.gamma)
        };
        solution.dynamics = Some(Box::new(DynamicHistory {
            integrator,
            beta: dyn_.beta,
            gamma: dyn_.gamma,
            dt: dyn_.dt,
            mass: format!("{:?}", dyn_.mass).to_lowercase(),
            impact: match dyn_.impact {
                ImpactTreatment::Plain => "plain",
                ImpactTreatment::PostImpact => "post_impact",
                ImpactTreatment::ContactStabilized => "contact_stabilized",
            }
            .into(),
            body_mass: self.mass.body_mass.clone(),
            body_names: model.bodies.iter().map(|b| b.name.clone()).collect(),
            steps: self.history,
            frames: self.frames,
        }));
        Ok(solution)
    }
}

/// `M_ff y` for the free equations `y` of `sys`.
fn mass_times(mass: &MassMatrix, sys: &super::linear::LinearSystem, y: &[f64]) -> Vec<f64> {
    let free = sys.constraints.free_dofs();
    let mut full = vec![0.0; mass.pattern.n];
    for (e, &d) in free.iter().enumerate() {
        full[d] = y[e];
    }
    let m = mass.mul(&full);
    free.iter().map(|&d| m[d]).collect()
}

/// How to get a time step that did not converge through: the penalty's advice depends on the
/// method. A stiff penalty makes a step's Newton solve hard; the Uzawa updates of the augmented
/// Lagrangian and the perturbed tangent instead shrink their error by about `k / (k + kappa A)`
/// per update (`k` the stiffness a point sees, the inertia's `c0 m` included), so a soft kappa
/// makes them slow: the rigid block drop took about 830 iterations a step at kappa = 1e2 and
/// 5 at 1e6.
fn dynamic_step_hint(model: &Model) -> String {
    use crate::contact::enforcement::{method, Method};
    let uzawa = model.contact.iter().any(|p| {
        matches!(
            method(&p.enforcement).kernel(),
            Method::AugmentedLagrange { .. } | Method::PerturbedTangent { .. }
        )
    });
    if uzawa {
        "take a smaller dt, a stiffer kappa for the augmented Lagrangian or perturbed tangent (its multiplier updates converge faster the stiffer it is), or raise solver.max_iterations".into()
    } else {
        "take a smaller dt, a softer penalty, or raise solver.max_iterations".into()
    }
}

/// Newton's method on `system` from `x` with the reused `linear` solver; a step that does not
/// converge is an error naming `what`.
fn newton_step(
    model: &Model,
    system: &mut ContactSystem<'_>,
    x: &mut Vec<f64>,
    linear: &mut LinearSolver,
    timings: &mut Timings,
    what: &str,
) -> Result<usize> {
    let t = Instant::now();
    let outcome = newton::solve_with(
        system,
        x,
        newton::Settings {
            max_iterations: model.solver.max_iterations,
            tolerance: super::contact_newton::RESIDUAL_TOLERANCE,
            factor_limit: model.factor_limit,
            iteration_dofs: model.iteration_dofs,
        },
        linear,
    )?;
    timings.factorization += outcome.factorization_seconds;
    timings.solve += (t.elapsed().as_secs_f64() - outcome.factorization_seconds).max(0.0);
    if outcome.termination != Termination::Converged {
        let why = match outcome.termination {
            Termination::Singular(why) => why,
            other => format!("{other:?}"),
        };
        return Err(Error::Solver {
            path: model.source.clone(),
            problem: format!(
                "{what} did not converge after {} Newton iterations: {why}",
                outcome.iterations
            ),
            hint: dynamic_step_hint(model),
        });
    }
    Ok(outcome.iterations)
}

/// The residual and tangent of the first implicit step of a dynamic `model`,
/// `R(x) = (K + c0 M) x - f - c0 M d~ - B^T lambda(x)` (`d~` the predictor from the initial
/// state), at the free displacements `x`, for finite-difference checks of the dynamic tangent
/// (`tests/dynamics.rs`): not part of the solver's interface. Penalty-type rows only (the
/// unknowns are the free displacements). Dense, row-major: `tangent[i][j] = dR_i / dx_j`.
#[doc(hidden)]
pub fn probe_first_step(model: &Model, x: &[f64]) -> Result<(Vec<f64>, Vec<Vec<f64>>)> {
    let dynamics = model
        .dynamics
        .as_ref()
        .expect("probe_first_step takes a dynamic model");
    let mut integrator = Integrator::new(model, dynamics, &mut |_| {})?;
    let dt = dynamics.dt;
    let beta = dynamics.beta;
    let free: Vec<usize> = integrator
        .system
        .linear_system()
        .constraints
        .free_dofs()
        .to_vec();
    let target: Vec<f64> = free
        .iter()
        .map(|&d| integrator.d[d] + dt * integrator.v[d] + dt * dt * (0.5 - beta) * integrator.a[d])
        .collect();
    let m_t = mass_times(&integrator.mass, integrator.system.linear_system(), &target);
    let rhs: Vec<f64> = integrator
        .rhs0
        .iter()
        .zip(&m_t)
        .map(|(r, m)| r + integrator.c0 * m)
        .collect();
    integrator.system.set_right_hand_side(rhs);
    let general = GeneralPattern::from_symmetric(integrator.system.pattern());
    let n = general.n;
    let mut residual = vec![0.0; n];
    let mut tangent = Tangent {
        values: vec![0.0; general.nnz()],
        symmetric: true,
        multipliers: 0,
        scale: 1.0,
        elimination: None,
        indefinite_block: false,
    };
    integrator
        .system
        .evaluate(x, &general, &mut residual, &mut tangent)?;
    let mut dense = vec![vec![0.0; n]; n];
    for j in 0..n {
        for k in general.col_ptr[j]..general.col_ptr[j + 1] {
            dense[general.row_idx[k]][j] = tangent.values[k];
        }
    }
    Ok((residual, dense))
}
