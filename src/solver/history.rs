//! What a time integration ([`crate::solver::dynamics`]) records: one [`StepRecord`] per time
//! step (time, contact force, gap, kinetic, strain, contact and total energy, linear momentum,
//! the work of the linear solver) and the displacement at the frames written as `.vtu` files.
//!
//! The energies are those of the discrete system: kinetic `T = v^T M v / 2`, strain
//! `U = u^T K u / 2`, the penalty springs `Phi = sum_i w_i g_i^2 / 2` over active penalty rows,
//! and the potential of the (constant) loads `-f^T u`; `total = T + U + Phi - f^T u` is constant
//! for the exact solution of an elastic, frictionless problem. Momentum is `p = sum_d M v` per
//! component (over every body, and per body).
//!
//! A finite-kinematics solve ([`crate::solver::finite`]) records every attempted load step
//! ([`FiniteStep`]: load factors, termination, iterations, and why a cut step was cut) and the
//! Newton residual of every iteration ([`FiniteHistory`]).

use serde::Serialize;

/// One time step (step 0 is the initial state).
#[derive(Clone, Debug, Serialize)]
pub struct StepRecord {
    pub step: usize,
    pub time: f64,
    /// Sum of the contact forces of the active rows (compression positive), after the impact
    /// treatment.
    pub contact_force: f64,
    /// Smallest gap of a contact row (`None` without contact rows).
    pub min_gap: Option<f64>,
    pub active: usize,
    pub kinetic: f64,
    pub strain: f64,
    /// Energy of the penalty springs of active penalty rows.
    pub contact_energy: f64,
    /// `-f^T u`.
    pub load_potential: f64,
    pub total: f64,
    /// Linear momentum `[p_x, p_y]` of all bodies.
    pub momentum: [f64; 2],
    /// Momentum of each body.
    pub body_momentum: Vec<[f64; 2]>,
    /// Largest relative normal velocity `|b . v|` and acceleration `|b . a|` of an active row
    /// before the impact treatment (Newmark's values) and after it: the seed's "violates the
    /// physics" measured.
    pub velocity_jump: [f64; 2],
    pub acceleration_jump: [f64; 2],
    /// Newton iterations of the step, and the linear solver's work so far.
    pub iterations: usize,
    pub factorizations: usize,
    pub reused_factorizations: usize,
}

/// The record of a whole time integration.
#[derive(Clone, Debug, Serialize)]
pub struct DynamicHistory {
    pub integrator: String,
    pub beta: f64,
    pub gamma: f64,
    pub dt: f64,
    pub mass: String,
    pub impact: String,
    /// Total mass of each body (`sum M` of one component).
    pub body_mass: Vec<f64>,
    pub body_names: Vec<String>,
    pub steps: Vec<StepRecord>,
    /// `(time, global displacement)` of every frame.
    #[serde(skip)]
    pub frames: Vec<(f64, Vec<f64>)>,
}

impl DynamicHistory {
    /// The per-step table as CSV (one header line, one line per step).
    pub fn csv(&self) -> String {
        let mut out = String::from(
            "step,time,contact_force,min_gap,active,kinetic,strain,contact_energy,load_potential,total,momentum_x,momentum_y,velocity_jump_before,velocity_jump_after,acceleration_jump_before,acceleration_jump_after,iterations,factorizations,reused_factorizations",
        );
        for name in &self.body_names {
            out.push_str(&format!(",momentum_x_{name},momentum_y_{name}"));
        }
        out.push('\n');
        for s in &self.steps {
            let gap = s.min_gap.map_or(String::new(), |g| format!("{g:e}"));
            out.push_str(&format!(
                "{},{:e},{:e},{},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{},{},{}",
                s.step,
                s.time,
                s.contact_force,
                gap,
                s.active,
                s.kinetic,
                s.strain,
                s.contact_energy,
                s.load_potential,
                s.total,
                s.momentum[0],
                s.momentum[1],
                s.velocity_jump[0],
                s.velocity_jump[1],
                s.acceleration_jump[0],
                s.acceleration_jump[1],
                s.iterations,
                s.factorizations,
                s.reused_factorizations
            ));
            for p in &s.body_momentum {
                out.push_str(&format!(",{:e},{:e}", p[0], p[1]));
            }
            out.push('\n');
        }
        out
    }
}

/// One attempted load step.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FiniteStep {
    /// Attempt number (1-based), and the load factors it went from and to.
    pub attempt: usize,
    pub from: f64,
    pub to: f64,
    pub termination: crate::contact::state::Termination,
    pub iterations: usize,
    pub accepted: bool,
    /// Why the step was cut (absent for an accepted step).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cut_because: Option<String>,
}

/// The load stepping of a finite-kinematics solve: every attempt, and the Newton residual
/// history of every attempt (`step` is the attempt number).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct FiniteHistory {
    pub steps: Vec<FiniteStep>,
    pub history: Vec<crate::contact::state::IterationRecord>,
    /// How many attempts were cut.
    pub cuts: usize,
}
