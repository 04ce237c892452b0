//! Coulomb friction at one contact point: the penalty return map, and the open/stick/slip sets
//! of Lagrange multipliers.
//!
//! Reference: P. Wriggers, *Computational Contact Mechanics* (2nd ed., Springer 2006),
//! section 5.2 (elasto-plastic analogy of friction) and 6.3 (penalty return map); T. A.
//! Laursen, *Computational Contact and Impact Mechanics* (Springer 2002), ch. 5; Taylor's talk
//! (2004), "1988: Friction": Coulomb's law `|lambda_t| <= mu |lambda_n|`, stick `g_t = 0`, slip
//! `|lambda_t| = mu |lambda_n|`, an unsymmetric tangent.
//!
//! A contact row carries its normal force `lambda_n >= 0` (compression positive) and its
//! tangential slip measure `g_t(u) = t . (u_s - sum_m N_m u_m)` ([`super::TangentRow`]). The
//! slip splits into an elastic part (the penalty spring) and a plastic part `g_t^p` (the
//! sliding), committed at the end of every converged load step (`g_t^{p,n}`). With the
//! tangential weight `w_t = kappa_t A` (tributary area `A`):
//!
//! ```text
//! trial:  lambda_t^tr = -w_t (g_t - g_t^{p,n})
//! stick:  |lambda_t^tr| <= mu lambda_n    =>  lambda_t = lambda_t^tr,            g_t^p = g_t^{p,n}
//! slip:   otherwise, s = sign(lambda_t^tr) =>  lambda_t = s mu lambda_n,
//!                                             g_t^p = g_t + lambda_t / w_t
//! open:   lambda_n inactive               =>  lambda_t = 0,                      g_t^p = g_t
//! ```
//!
//! The tangential force on the row's dofs is `lambda_t b_t` (`b_t = dg_t/du`), like the normal
//! force `lambda_n b_n`, so the residual `R = K u - f - lambda_n b_n - lambda_t b_t` has the
//! tangent contributions
//!
//! ```text
//! stick:  + w_t b_t b_t^T
//! slip:   - b_t (d lambda_t / du)^T = - s mu b_t (d lambda_n / du)^T = + s mu w_n b_t b_n^T
//! ```
//!
//! (penalty normal law `lambda_n = lambda_bar - w_n g_n`): unsymmetric in slip (Ju & Taylor
//! 1988). The open branch resets the elastic slip, so a point that closes again starts to
//! stick where it lands. The frictional dissipation of a step is `D = -lambda_t (g_t^p -
//! g_t^{p,n}) = mu lambda_n (|lambda_t^tr| - mu lambda_n) / w_t >= 0` in slip (zero in stick).
//!
//! **Lagrange multipliers** (no tangential penalty, [`multiplier_status`]): the tangential
//! force `lambda_t` is an unknown, and the sets of the semi-smooth Newton method follow from the
//! complementarity function of Alart & Curnier (1991, *Comput. Methods Appl. Mech. Engrg.* 92,
//! 353-375) in the active-set form of Hüeber, Stadler & Wohlmuth (2008, *SIAM J. Sci. Comput.*
//! 30, 572-596), with the slip increment `dg_t = g_t - g_t^n` from the tangential position
//! `g_t^n` committed at the start of the load step and a constant `c > 0`:
//!
//! ```text
//! trial:  tau = lambda_t - c dg_t
//! open:   lambda_n inactive      =>  lambda_t = 0
//! stick:  |tau| <= mu lambda_n   =>  dg_t = 0
//! slip:   otherwise, s = sign(tau) =>  lambda_t = s mu lambda_n
//! ```
//!
//! At a solution of the slip branch `tau = s (mu lambda_n + c |dg_t|)`: the slip runs against
//! the force and the dissipation `-lambda_t dg_t = mu lambda_n |dg_t|` is non-negative.
//!
//! **Augmented Lagrangian** ([`augmented_return_map`]; Simo & Laursen 1992, *Comput. Struct.*
//! 42, 97-116; Laursen & Simo 1993, *Int. J. Numer. Meth. Engng.* 36, 3451-3485): the normal
//! force `lambda_n = max(0, lambda_bar_n - w_n g_n)` and the tangential trial force are
//! augmented by Uzawa multipliers `lambda_bar_n`, `lambda_bar_t`, the slip measured from the
//! stick point `g_t^n` committed at the end of the last load step (not from a plastic slip:
//! the multiplier, not a spring, carries the force):
//!
//! ```text
//! trial:  lambda_t^tr = lambda_bar_t - w_t (g_t - g_t^n)
//! stick:  |lambda_t^tr| <= mu lambda_n^b  =>  lambda_t = lambda_t^tr     (stick point kept)
//! slip:   otherwise                       =>  lambda_t = s mu lambda_n^b (stick point g_t)
//! Uzawa:  lambda_bar_n <- lambda_n,  lambda_bar_t <- lambda_t = proj_{|.| <= mu lambda_n^b}(lambda_t^tr)
//! ```
//!
//! with the bound `lambda_n^b = lambda_n` (the consistent form: `d lambda_t / du = s mu w_n
//! b_n` in slip, unsymmetric) or `lambda_n^b = lambda_bar_n`, the multiplier held fixed during
//! Newton (`friction_tangent: "laursen_simo"`): the slip force is then constant in a Newton
//! solve and the tangent symmetric; at a converged Uzawa iteration `lambda_bar_n = lambda_n`
//! and both forms have the same solution. At that solution a stick point does not move
//! (`lambda_bar_t = lambda_t` needs `g_t = g_t^n`) and a slip point carries exactly `mu
//! lambda_n`: the Lagrange answer, for any `w_t`. The multipliers are carried from one load
//! step to the next with the stick point ([`Committed`]): restarting `lambda_bar_n` from zero
//! drops the bound `mu lambda_n` of a closed point to its penalty part, about zero once the
//! gap has closed, and the next step's first iterations then released every point into slip
//! while its slip history was committed against a stick point (the cycling of the first
//! attempt).

use serde::Serialize;

/// The frictional status of a contact point.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    Open,
    Stick,
    Slip,
}

/// The return map at one point.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ReturnMap {
    pub status: Status,
    /// The tangential force `lambda_t` (along the row's tangent, on the slave node).
    pub force: f64,
    /// The plastic slip after the map, `g_t^p`.
    pub plastic_slip: f64,
    /// `d lambda_t / d g_t` (`-w_t` in stick, zero otherwise).
    pub d_slip: f64,
    /// `d lambda_t / d lambda_n` (`s mu` in slip, zero otherwise).
    pub d_normal: f64,
}

/// The return map of a point with normal force `lambda_n` (`active`: the normal row carries
/// force), slip `g_t`, committed plastic slip `committed`, friction coefficient `mu` and
/// tangential weight `w_t = kappa_t A`. A tensile normal force (a row closed at the start of a
/// step) bounds nothing: it counts as zero.
pub fn return_map(
    mu: f64,
    w_t: f64,
    lambda_n: f64,
    active: bool,
    g_t: f64,
    committed: f64,
) -> ReturnMap {
    if !active {
        return ReturnMap {
            status: Status::Open,
            force: 0.0,
            plastic_slip: g_t,
            d_slip: 0.0,
            d_normal: 0.0,
        };
    }
    let trial = -w_t * (g_t - committed);
    let bound = mu * lambda_n.max(0.0);
    if trial.abs() <= bound {
        return ReturnMap {
            status: Status::Stick,
            force: trial,
            plastic_slip: committed,
            d_slip: -w_t,
            d_normal: 0.0,
        };
    }
    let s = trial.signum();
    let force = s * bound;
    ReturnMap {
        status: Status::Slip,
        force,
        plastic_slip: g_t + force / w_t,
        d_slip: 0.0,
        d_normal: if lambda_n > 0.0 { s * mu } else { 0.0 },
    }
}

/// The return map of the augmented Lagrangian (see the module doc) at a point with Uzawa
/// multiplier `lambda_bar_t`, stick point `stick_point` (committed at the end of the last load
/// step), slip `g_t`, and the bound's normal force `bound_force` (`lambda_n`, or
/// `lambda_bar_n` for Laursen & Simo's form). `bound_varies`: the bound is the current normal
/// force `lambda_n = lambda_bar_n - w_n g_n` (a slip then couples `d_normal = s mu`); with the
/// multiplier held fixed it does not (`d_normal = 0`). The returned `plastic_slip` is the
/// point's stick point after the map: `stick_point` in stick, `g_t` otherwise.
///
/// `held`: the branch to take regardless of the trial force (stick, or slip with its sign `s`),
/// as in the Newton iteration right after a Uzawa update (see [`crate::solver::contact_newton`]);
/// `None` (or open) decides from the trial force.
#[allow(clippy::too_many_arguments)]
pub fn augmented_return_map(
    mu: f64,
    w_t: f64,
    bound_force: f64,
    bound_varies: bool,
    active: bool,
    g_t: f64,
    stick_point: f64,
    lambda_bar_t: f64,
    held: Option<(Status, f64)>,
) -> ReturnMap {
    if !active {
        return ReturnMap {
            status: Status::Open,
            force: 0.0,
            plastic_slip: g_t,
            d_slip: 0.0,
            d_normal: 0.0,
        };
    }
    let trial = lambda_bar_t - w_t * (g_t - stick_point);
    let bound = mu * bound_force.max(0.0);
    let (stick, s) = match held {
        Some((Status::Stick, _)) => (true, 0.0),
        Some((Status::Slip, s)) => (false, s),
        _ => (trial.abs() <= bound, trial.signum()),
    };
    if stick {
        return ReturnMap {
            status: Status::Stick,
            force: trial,
            plastic_slip: stick_point,
            d_slip: -w_t,
            d_normal: 0.0,
        };
    }
    ReturnMap {
        status: Status::Slip,
        force: s * bound,
        plastic_slip: g_t,
        d_slip: 0.0,
        d_normal: if bound_varies && bound_force > 0.0 {
            s * mu
        } else {
            0.0
        },
    }
}

/// What a frictional point carries from one load step to the next: its committed slip (the
/// plastic slip of the penalty map, the stick point of the multiplier methods) and its forces
/// at the end of the step (the Uzawa multipliers the augmented Lagrangian starts the next step
/// from; unused by the other methods).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct Committed {
    pub slip: f64,
    pub normal_force: f64,
    pub tangential_force: f64,
}

/// The frictional status of a point with Lagrange multipliers (see the module doc): normal force
/// `lambda_n` (`active`: the normal row is in the active set), tangential force `lambda_t`, slip
/// increment `dg_t` of the step and the constant `c` (a stiffness). Returns the status and, in
/// slip, the sign `s` of the force `lambda_t = s mu lambda_n` (`0.0` otherwise).
pub fn multiplier_status(
    mu: f64,
    lambda_n: f64,
    active: bool,
    lambda_t: f64,
    increment: f64,
    c: f64,
) -> (Status, f64) {
    if !active {
        return (Status::Open, 0.0);
    }
    let trial = lambda_t - c * increment;
    if trial.abs() <= mu * lambda_n.max(0.0) {
        (Status::Stick, 0.0)
    } else {
        (Status::Slip, trial.signum())
    }
}

/// What a solve found at one frictional contact point (aligned with the rows of
/// [`super::state::ContactState`]).
#[derive(Copy, Clone, Debug, PartialEq, Serialize)]
pub struct FrictionPoint {
    pub status: Status,
    /// Tangential force `lambda_t` along the row's tangent `t`, on the slave node.
    pub force: f64,
    /// The unit tangent `t`.
    pub direction: [f64; 2],
    /// The friction coefficient of the point's pair.
    pub mu: f64,
    /// The normal force bounding it, `lambda_n` (zero when open).
    pub normal_force: f64,
    /// Slip measure `g_t` and plastic slip `g_t^p` at the end of the step, and the plastic slip
    /// committed at the start of the step.
    pub slip: f64,
    pub plastic_slip: f64,
    pub committed: f64,
    /// Frictional dissipation of the step, `-lambda_t (g_t^p - g_t^{p,n})` (>= 0; zero open).
    pub dissipation: f64,
}

/// The frictional totals of one pair at the end of a solve.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrictionSummary {
    /// Sum of the tangential forces `lambda_t t` on the slave nodes, `[x, y]` (the pair's
    /// `force_on_slave` holds the normal and the tangential forces together).
    pub tangential_force: [f64; 2],
    pub open: usize,
    pub stick: usize,
    pub slip: usize,
    /// Frictional dissipation of the last load step (sum over the points, >= 0).
    pub dissipation: f64,
    /// Largest `|lambda_t| / (mu lambda_n)` over the closed points (<= 1: Coulomb's cone).
    pub max_cone_ratio: f64,
}

/// The frictional totals of all pairs of `state` (`None`: no frictional row).
pub fn step_summary<const D: usize>(
    state: &super::state::ContactState<D>,
) -> Option<FrictionSummary> {
    summarize(state, None)
}

/// The frictional totals of pair `pair` of `state` (`None`: no frictional row).
pub fn pair_summary<const D: usize>(
    state: &super::state::ContactState<D>,
    pair: usize,
) -> Option<FrictionSummary> {
    summarize(state, Some(pair))
}

fn summarize<const D: usize>(
    state: &super::state::ContactState<D>,
    pair: Option<usize>,
) -> Option<FrictionSummary> {
    let mut out = FrictionSummary {
        tangential_force: [0.0; 2],
        open: 0,
        stick: 0,
        slip: 0,
        dissipation: 0.0,
        max_cone_ratio: 0.0,
    };
    let mut any = false;
    for (r, f) in state.rows.iter().zip(&state.friction) {
        let (Some(f), true) = (f, pair.is_none_or(|p| p == r.pair)) else {
            continue;
        };
        any = true;
        for k in 0..2 {
            out.tangential_force[k] += f.force * f.direction[k];
        }
        match f.status {
            Status::Open => out.open += 1,
            Status::Stick => out.stick += 1,
            Status::Slip => out.slip += 1,
        }
        out.dissipation += f.dissipation;
        if f.status != Status::Open && f.force != 0.0 {
            out.max_cone_ratio = out
                .max_cone_ratio
                .max(f.force.abs() / (f.mu * f.normal_force.max(0.0)));
        }
    }
    any.then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stick_slip_and_open_branches() {
        let stick = return_map(0.5, 10.0, 4.0, true, 0.1, 0.0);
        assert_eq!(stick.status, Status::Stick);
        assert_eq!(stick.force, -1.0);
        let slip = return_map(0.5, 10.0, 4.0, true, 0.5, 0.0);
        assert_eq!(slip.status, Status::Slip);
        assert_eq!(slip.force, -2.0);
        // the elastic part of the slip carries the force
        assert!((-10.0 * (0.5 - slip.plastic_slip) - slip.force).abs() < 1e-15);
        let open = return_map(0.5, 10.0, 0.0, false, 0.5, 0.2);
        assert_eq!(
            (open.status, open.force, open.plastic_slip),
            (Status::Open, 0.0, 0.5)
        );
    }

    #[test]
    fn the_augmented_map_projects_the_trial_force_onto_the_cone() {
        // trial 1.0 - 10 (0.05 - 0.0) = 0.5 inside mu lambda_n = 2: stick, the point kept
        let stick = augmented_return_map(0.5, 10.0, 4.0, true, true, 0.05, 0.0, 1.0, None);
        assert_eq!(
            (stick.status, stick.force, stick.plastic_slip, stick.d_slip),
            (Status::Stick, 0.5, 0.0, -10.0)
        );
        // trial 1.0 - 10 (0.5) = -4 outside: slip at -mu lambda_n, the point moves to g_t
        let slip = augmented_return_map(0.5, 10.0, 4.0, true, true, 0.5, 0.0, 1.0, None);
        assert_eq!(
            (slip.status, slip.force, slip.plastic_slip, slip.d_normal),
            (Status::Slip, -2.0, 0.5, -0.5)
        );
        // Laursen & Simo: the bound held fixed, no coupling to the normal force
        let fixed = augmented_return_map(0.5, 10.0, 4.0, false, true, 0.5, 0.0, 1.0, None);
        assert_eq!((fixed.force, fixed.d_normal), (-2.0, 0.0));
        // held in stick the force is the trial's, even outside the cone
        let held = augmented_return_map(
            0.5,
            10.0,
            4.0,
            true,
            true,
            0.5,
            0.0,
            1.0,
            Some((Status::Stick, 0.0)),
        );
        assert_eq!((held.status, held.force), (Status::Stick, -4.0));
        let open = augmented_return_map(0.5, 10.0, 4.0, true, false, 0.5, 0.2, 1.0, None);
        assert_eq!((open.status, open.force), (Status::Open, 0.0));
    }

    #[test]
    fn multiplier_sets_follow_the_trial_force() {
        // inside the cone: stick; outside: slip against the motion; no normal force: open
        assert_eq!(
            multiplier_status(0.5, 4.0, true, 1.0, 0.0, 10.0),
            (Status::Stick, 0.0)
        );
        assert_eq!(
            multiplier_status(0.5, 4.0, true, 2.0, 0.5, 10.0),
            (Status::Slip, -1.0)
        );
        assert_eq!(
            multiplier_status(0.5, 4.0, true, 3.0, 0.0, 10.0),
            (Status::Slip, 1.0)
        );
        assert_eq!(
            multiplier_status(0.5, 4.0, false, 3.0, 0.0, 10.0),
            (Status::Open, 0.0)
        );
        // a closed point with no compression yet sticks where it is
        assert_eq!(
            multiplier_status(0.5, 0.0, true, 0.0, 0.0, 10.0),
            (Status::Stick, 0.0)
        );
    }
}
