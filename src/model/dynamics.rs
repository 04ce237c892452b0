//! `physics.dynamics` validated once into [`Dynamics`]: Newmark's parameters `(beta, gamma)`,
//! the step `dt` and the number of steps, the mass matrix kind, the impact treatment, the
//! density of every body and the initial velocity of every dof.
//!
//! The admissible members of Newmark's family (Newmark, J. Eng. Mech. Div. ASCE 85 (1959)
//! 67-94; Hughes, *The Finite Element Method* (1987), section 9.1) are `0 <= beta <= 1/2`,
//! `gamma >= 1/2`; `beta = 0` is explicit and needs the lumped (diagonal) mass. The time loop
//! itself is [`crate::solver::dynamics`]. A scene without `physics.dynamics` resolves to `None`
//! and builds nothing of this.

use crate::error::{Error, Result};
use crate::io::scene::{Case, ContactGeometry, EnforcementSpec, ImpactTreatment, Interaction};
use crate::io::scene::{MassKind, Scheme};
use crate::model::Model;

/// Most time steps a case may ask for.
pub const MAX_TIME_STEPS: usize = 1_000_000;
/// Most `.vtu` frames (per body) a run writes.
pub const MAX_FRAMES: usize = 1000;
/// Most frames times dofs a run keeps and writes (80 MB of displacements).
pub const MAX_FRAME_DOFS: usize = 10_000_000;

/// A validated `physics.dynamics`.
#[derive(Clone, Debug)]
pub struct Dynamics {
    pub beta: f64,
    pub gamma: f64,
    pub dt: f64,
    pub steps: usize,
    pub mass: MassKind,
    pub impact: ImpactTreatment,
    /// Mass per unit volume of each body.
    pub density: Vec<f64>,
    /// Initial velocity of every global dof (zero at supported dofs).
    pub initial_velocity: Vec<f64>,
    /// A `.vtu` frame every this many steps (and at the last step).
    pub frame_every: usize,
}

impl Dynamics {
    /// Whether the integrator is explicit (`beta = 0`).
    pub fn explicit(&self) -> bool {
        self.beta == 0.0
    }
}

/// `case.physics.dynamics` checked against the built `model` (bodies, sets, supports, contact).
pub fn resolve(case: &Case, model: &Model) -> Result<Option<Dynamics>> {
    let Some(spec) = &case.physics.dynamics else {
        return Ok(None);
    };
    let source = &model.source;
    let invalid = |at: &str, problem: String, hint: &str| Error::invalid(source, at, problem, hint);
    let (beta, gamma) = spec.integrator.parameters();
    if !(beta.is_finite() && (0.0..=0.5).contains(&beta)) {
        return Err(invalid(
            "physics.dynamics.integrator",
            format!("Newmark's beta must lie in [0, 1/2], got {beta}"),
            "use \"average_acceleration\" (beta 1/4, gamma 1/2) or \"central_difference\" (0, 1/2)",
        ));
    }
    if !(gamma.is_finite() && (0.5..=1.0).contains(&gamma)) {
        return Err(invalid(
            "physics.dynamics.integrator",
            format!("Newmark's gamma must lie in [1/2, 1], got {gamma} (below 1/2 the method is unstable)"),
            "use gamma = 1/2 (no numerical damping) or a little above it to damp high frequencies",
        ));
    }
    let (dt, end) = (spec.dt, spec.end_time);
    if !(dt.is_finite() && dt > 0.0) {
        return Err(invalid(
            "physics.dynamics.dt",
            format!("the time step must be a positive number, got {dt}"),
            "give dt > 0 (a fraction of the time a wave needs to cross an element)",
        ));
    }
    if !(end.is_finite() && end > 0.0) {
        return Err(invalid(
            "physics.dynamics.end_time",
            format!("the end time must be a positive number, got {end}"),
            "give end_time > 0",
        ));
    }
    let ratio = end / dt;
    if ratio > MAX_TIME_STEPS as f64 {
        return Err(invalid(
            "physics.dynamics",
            format!("end_time / dt = {ratio:.3e} steps, more than the limit {MAX_TIME_STEPS}"),
            "take a larger dt or a shorter end_time",
        ));
    }
    // a step count that is an integer up to round-off is that integer
    let steps = ((ratio - 1e-9 * ratio).ceil() as usize).max(1);
    let work = steps as u128 * model.dof_count as u128;
    if work > case.limits.step_dofs as u128 {
        return Err(invalid(
            "physics.dynamics",
            format!(
                "{steps} time steps of {} dofs ({work} step-dofs) are more than the limit {}",
                model.dof_count, case.limits.step_dofs
            ),
            "take a larger dt, a shorter end_time or a coarser mesh, or raise \"limits\": {\"step_dofs\": N}",
        ));
    }
    if beta == 0.0 && spec.mass != MassKind::Lumped {
        return Err(invalid(
            "physics.dynamics.mass",
            "the explicit member (beta = 0, central difference) needs the lumped mass: with the consistent mass every step solves a system anyway".into(),
            "set \"mass\": \"lumped\", or an implicit integrator such as \"average_acceleration\"",
        ));
    }
    if spec.impact == ImpactTreatment::ContactStabilized && (beta, gamma) != (0.25, 0.5) {
        return Err(invalid(
            "physics.dynamics.impact",
            format!("the contact-stabilized Newmark method is built on the trapezoidal rule (beta 1/4, gamma 1/2), not beta {beta}, gamma {gamma}"),
            "use \"integrator\": \"average_acceleration\", or another impact treatment",
        ));
    }
    if model.solver.load_steps != 1 || !model.load_path.is_empty() {
        return Err(invalid(
            "physics.dynamics",
            "loads and supports are constant in time in a dynamic run; load steps and load paths do not apply".into(),
            "remove solver.load_steps and every \"path\"",
        ));
    }
    if model.physics.contact_geometry != ContactGeometry::Reference {
        return Err(invalid(
            "physics.contact_geometry",
            "dynamics is solved with the contact geometry of the reference configuration only (so far)".into(),
            "set \"contact_geometry\": \"reference\" or leave it out",
        ));
    }
    if !model.contact.is_empty() && model.solver.scheme != Scheme::Newton {
        return Err(invalid(
            "solver.scheme",
            "dynamics with contact runs on the Newton core".into(),
            "set \"solver\": {\"scheme\": \"newton\"}",
        ));
    }
    for (k, pair) in model.contact.iter().enumerate() {
        let at = format!("contact[{k}] '{}'", pair.name);
        if matches!(pair.interaction, Interaction::Coulomb { .. }) {
            // the frictional history (and the Uzawa multipliers of the augmented Lagrangian and
            // the perturbed tangent) is committed after every time step, as after a load step;
            // the explicit member has no Newton solve to return-map in, the contact-stabilized
            // projection has no tangential rows
            if beta == 0.0 {
                return Err(invalid(
                    &at,
                    "Coulomb friction in time needs an implicit integrator (the return map runs in the Newton solve of each step)".into(),
                    "use \"integrator\": \"average_acceleration\", or a frictionless interaction",
                ));
            }
            if spec.impact == ImpactTreatment::ContactStabilized {
                return Err(invalid(
                    &at,
                    "the contact-stabilized projection holds the normal contact only; with Coulomb friction it would project without the tangential forces".into(),
                    "use \"impact\": \"plain\" or \"post_impact\" with friction",
                ));
            }
        }
        if beta == 0.0 && !matches!(pair.enforcement, EnforcementSpec::Penalty { .. }) {
            return Err(invalid(
                &format!("{at}.enforcement"),
                "the explicit member (beta = 0) takes contact forces from the positions alone: penalty only".into(),
                "use {\"kind\": \"penalty\", \"kappa\": ..}, or an implicit integrator",
            ));
        }
    }
    let mut density = Vec::with_capacity(model.bodies.len());
    for b in &model.bodies {
        let at = format!("materials.{}.density", b.material_name);
        let rho = case
            .materials
            .get(&b.material_name)
            .and_then(|m| m.density)
            .ok_or_else(|| {
                invalid(
                    &at,
                    format!(
                        "body '{}' has no density, which a dynamic run needs",
                        b.name
                    ),
                    "give the material a \"density\" (mass per unit volume)",
                )
            })?;
        if !(rho.is_finite() && rho > 0.0) {
            return Err(invalid(
                &at,
                format!("the density must be positive and finite, got {rho}"),
                "give density > 0",
            ));
        }
        // the inertia of a time step, 4 rho A t / dt^2 over the body's bounding box, bounds
        // every entry the mass adds to the step's matrix: beyond double precision it is
        // infinite (and the factorization meets NaN pivots far from the cause)
        let side = b.mesh.size();
        let inertia = 4.0 * rho * side * side * model.thickness / (dt * dt);
        if !inertia.is_finite() {
            return Err(invalid(
                &at,
                format!(
                    "the density {rho:e} gives body '{}' an inertia per time step 4 rho A t / dt^2 \
                     of {inertia:e} (side {side:e}, dt {dt:e}), beyond double precision",
                    b.name
                ),
                "rescale the units (e.g. t/mm^3 with N and mm, or kg/m^3 with N and m) so that \
                 density, size and time step stay far from 1e308",
            ));
        }
        density.push(rho);
    }
    let mut velocity = vec![0.0; model.dof_count];
    for (k, iv) in spec.initial_velocity.iter().enumerate() {
        let at = format!("physics.dynamics.initial_velocity[{k}]");
        let Some(bi) = model.body_index(&iv.body) else {
            let known: Vec<&str> = model.bodies.iter().map(|b| b.name.as_str()).collect();
            return Err(invalid(
                &at,
                format!("body '{}' does not exist", iv.body),
                &format!("use one of the bodies {known:?}"),
            ));
        };
        let body = &model.bodies[bi];
        if iv.velocity.iter().any(|v| !v.is_finite()) {
            return Err(invalid(
                &at,
                format!("the velocity must be finite, got {:?}", iv.velocity),
                "give two finite components [vx, vy]",
            ));
        }
        let nodes: Vec<usize> = match &iv.set {
            None => (0..body.mesh.nodes.len()).collect(),
            Some(set) => body.mesh.node_sets.get(set).cloned().ok_or_else(|| {
                let known: Vec<&String> = body.mesh.node_sets.keys().collect();
                invalid(
                    &at,
                    format!("body '{}' has no node set '{set}'", body.name),
                    &format!("use one of {known:?}"),
                )
            })?,
        };
        for n in nodes {
            for (c, &v) in iv.velocity.iter().enumerate() {
                let d = body.dof(n, c);
                if model.prescribed[d].is_some() {
                    if v != 0.0 {
                        return Err(invalid(
                            &at,
                            format!(
                                "node {n} of body '{}' has its u_{} supported, so its velocity is zero, not {v}",
                                body.name,
                                ["x", "y"][c]
                            ),
                            "give that component 0, or remove the support",
                        ));
                    }
                    continue;
                }
                velocity[d] = v;
            }
        }
    }
    let frame_every = match spec.frame_every {
        Some(0) => {
            return Err(invalid(
                "physics.dynamics.frame_every",
                "must be at least 1".into(),
                "leave it out for about 50 frames",
            ))
        }
        Some(n) => n,
        None => steps.div_ceil(50).max(1),
    };
    if steps.div_ceil(frame_every) > MAX_FRAMES {
        return Err(invalid(
            "physics.dynamics.frame_every",
            format!(
                "{} frames per body, more than the limit {MAX_FRAMES}",
                steps.div_ceil(frame_every)
            ),
            &format!(
                "take frame_every of at least {}",
                steps.div_ceil(MAX_FRAMES)
            ),
        ));
    }
    let frames = steps.div_ceil(frame_every) + 1;
    if frames.saturating_mul(model.dof_count) > MAX_FRAME_DOFS {
        return Err(invalid(
            "physics.dynamics.frame_every",
            format!(
                "{frames} frames of {} dofs are more than the {MAX_FRAME_DOFS} values a run keeps for its .vtu frames",
                model.dof_count
            ),
            &format!(
                "take frame_every of at least {}",
                steps.div_ceil((MAX_FRAME_DOFS / model.dof_count.max(1)).saturating_sub(1).max(1))
            ),
        ));
    }
    Ok(Some(Dynamics {
        beta,
        gamma,
        dt,
        steps,
        mass: spec.mass,
        impact: spec.impact,
        density,
        initial_velocity: velocity,
        frame_every,
    }))
}
