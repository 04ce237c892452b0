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
//! **The return map on a disc** (3D; Wriggers 2006, s. 5.2; Laursen 2002, ch. 5): a point
//! has `k = D - 1` orthonormal tangents `t_1, .., t_k` (the rows of [`super::TangentRow`]), and
//! slip, plastic slip and force are vectors of `k` components in that frame. The cone
//! `|lambda_t| <= mu lambda_n` is a disc, and the map returns radially:
//!
//! ```text
//! trial:  lambda_t^tr = -w_t (g_t - g_t^{p,n})                       (k components)
//! stick:  |lambda_t^tr| <= mu lambda_n  =>  lambda_t = lambda_t^tr,   d lambda_t / d g_t = -w_t I
//! slip:   s = lambda_t^tr / |lambda_t^tr|  =>  lambda_t = mu lambda_n s,  g_t^p = g_t + lambda_t / w_t,
//!         d lambda_t / d g_t = -w_t mu lambda_n (I - s s^T) / |lambda_t^tr|,
//!         d lambda_t / d lambda_n = mu s
//! ```
//!
//! The `(I - s s^T)` term is the derivative of the slip direction: it is symmetric, so the
//! tangent's tangential block stays symmetric and only the normal coupling `mu s w_n b_t b_n^T`
//! is not. With `k = 1`, `|x| = sqrt(x^2)` and `s = +-1`, so `I - s s^T = 0` and the map is the
//! scalar one above to the last bit (the 2D path runs through the same function). The
//! dissipation of a step is `-lambda_t . (g_t^p - g_t^{p,n}) >= 0`.
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
//! On the disc (3D, `k = 2` tangents; Hüeber, Stadler & Wohlmuth 2008; Wriggers 2006,
//! s. 5.2) the same sets hold with vectors: `tau = lambda_t - c dg_t`, stick `|tau| <= mu
//! lambda_n` (then `dg_t = 0`), slip `lambda_t = mu lambda_n s` with `s = tau / |tau|` the radial
//! return of the trial force, whose consistent linearization carries the turn of the direction
//!
//! ```text
//! d (mu lambda_n s) = mu s d lambda_n + T d tau,   T = mu lambda_n (I - s s^T) / |tau|,
//! d tau = d lambda_t - c d(dg_t)
//! ```
//!
//! ([`MultiplierSet::turn`]). With one tangent `s = sign(tau)`, `I - s s^T = 0`, and the sets are
//! the scalar ones above to the last bit (one function serves both).
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

/// The most tangent directions a point has: two in 3D (the tangent plane), one in 2D.
pub const MAX_TANGENTS: usize = 2;

/// A tangential vector (slip, force) as its components along a point's orthonormal tangents
/// `t_1, t_2` ([`super::TangentRow`]); a point with one tangent (2D) uses the first component
/// only, the second stays zero.
pub type Tangential = [f64; MAX_TANGENTS];

/// The frictional status of a contact point.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    Open,
    Stick,
    Slip,
}

/// The return map at one point with `k` tangents (components past `k` are zero).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ReturnMap {
    pub status: Status,
    /// The tangential force `lambda_t` (components along the row's tangents, on the slave node).
    pub force: Tangential,
    /// The plastic slip after the map, `g_t^p`.
    pub plastic_slip: Tangential,
    /// `d lambda_t / d g_t` (`k x k`, symmetric): `-w_t I` in stick, `-w_t mu lambda_n (I - s
    /// s^T) / |lambda_t^tr|` in slip (zero with one tangent), zero open.
    pub d_slip: [Tangential; MAX_TANGENTS],
    /// `d lambda_t / d lambda_n` (`mu s` in slip, zero otherwise).
    pub d_normal: Tangential,
}

impl ReturnMap {
    fn open(g_t: Tangential) -> Self {
        ReturnMap {
            status: Status::Open,
            force: [0.0; MAX_TANGENTS],
            plastic_slip: g_t,
            d_slip: [[0.0; MAX_TANGENTS]; MAX_TANGENTS],
            d_normal: [0.0; MAX_TANGENTS],
        }
    }
}

/// The length of the first `k` components of `v` (`|v_1|` for one component, exactly).
pub fn length(k: usize, v: &Tangential) -> f64 {
    if k == 1 {
        v[0].abs()
    } else {
        v[..k].iter().map(|x| x * x).sum::<f64>().sqrt()
    }
}

/// The first `k` components of `v` as a [`Tangential`] (the rest zero).
pub fn tangential(v: &[f64]) -> Tangential {
    assert!(
        (1..=MAX_TANGENTS).contains(&v.len()),
        "a point has one or two tangents, not {}",
        v.len()
    );
    let mut out = [0.0; MAX_TANGENTS];
    out[..v.len()].copy_from_slice(v);
    out
}

/// The relative round-off of the cone `|lambda_t| <= mu lambda_n` a trial force may exceed it by
/// and still stick: a force put on the cone by the radial return, `mu lambda_n s` with `|s| =
/// 1` to a few ulps, is on it.
pub const CONE_ROUND_OFF: f64 = 8.0 * f64::EPSILON;

/// The slip branch of the radial return: the force `bound s` along the unit direction `s`,
/// `d lambda_t / d lambda_n = mu s` when `couples` (the bound is `mu lambda_n` of a compressed
/// point), and, when the direction follows the trial force (`trial_length`: `Some(|lambda_t^tr|)`,
/// `None` when the direction is held), `d lambda_t / d g_t = -w_t bound (I - s s^T) /
/// |lambda_t^tr|` (the derivative of the direction; zero with one tangent).
fn slip_branch(
    k: usize,
    s: Tangential,
    bound: f64,
    w_t: f64,
    mu: f64,
    couples: bool,
    trial_length: Option<f64>,
) -> (Tangential, [Tangential; MAX_TANGENTS], Tangential) {
    let mut force = [0.0; MAX_TANGENTS];
    let mut d_slip = [[0.0; MAX_TANGENTS]; MAX_TANGENTS];
    let mut d_normal = [0.0; MAX_TANGENTS];
    for a in 0..k {
        force[a] = s[a] * bound;
        if couples {
            d_normal[a] = s[a] * mu;
        }
    }
    if let (true, Some(length)) = (k > 1, trial_length) {
        let scale = -w_t * bound / length;
        for a in 0..k {
            for b in 0..k {
                let identity = if a == b { 1.0 } else { 0.0 };
                d_slip[a][b] = scale * (identity - s[a] * s[b]);
            }
        }
    }
    (force, d_slip, d_normal)
}

/// The unit direction of the first `k` components of `v` (`sign(v_1)` for one component).
fn direction(k: usize, v: &Tangential, length: f64) -> Tangential {
    let mut s = [0.0; MAX_TANGENTS];
    if k == 1 {
        s[0] = v[0].signum();
    } else {
        for a in 0..k {
            s[a] = v[a] / length;
        }
    }
    s
}

/// The stick branch's `d lambda_t / d g_t = -w_t I`.
fn stick_derivative(k: usize, w_t: f64) -> [Tangential; MAX_TANGENTS] {
    let mut d = [[0.0; MAX_TANGENTS]; MAX_TANGENTS];
    for (a, row) in d.iter_mut().enumerate().take(k) {
        row[a] = -w_t;
    }
    d
}

/// The return map on the disc (see the module doc) of a point with normal force `lambda_n`
/// (`active`: the normal row carries force) and slip `g_t` (`k` components, `k = g_t.len()`,
/// one or two), which started its step (`start`) at the slip `g_t^n` with the tangential
/// force `lambda_t^n` and the plastic slip `g_t^{p,n}`, friction coefficient `mu` and
/// tangential weight `w_t = kappa_t A`.
/// A tensile normal force (a row closed at the start of a step) bounds nothing: it counts as
/// zero.
///
/// The trial force is `lambda_t^n - w_t (g_t - g_t^n)`, which is `-w_t (g_t - g_t^{p,n})`
/// with the committed plastic slip `g_t^{p,n} = g_t^n + lambda_t^n / w_t`, written so that at
/// the start of a step (`g_t = g_t^n`) it is the committed force to the last bit: a point that
/// slipped starts the next step on the cone, in stick, not on the slip branch by a round-off
/// of `w_t |g_t|` (the plastic-slip form lost `eps w_t |g_t|`, which over a long slide is far
/// more than the cone's own round-off). A trial force within [`CONE_ROUND_OFF`] of the bound
/// (the radial return's `|s| = 1` to round-off, in 3D) sticks, and keeps the committed
/// plastic slip exactly (no dissipation). A start without force
/// ([`Committed::at_plastic_slip`]) is the plastic-slip form.
pub fn return_map(
    mu: f64,
    w_t: f64,
    lambda_n: f64,
    active: bool,
    g_t: &[f64],
    start: &Committed,
) -> ReturnMap {
    let k = g_t.len();
    let g = tangential(g_t);
    if !active {
        return ReturnMap::open(g);
    }
    let mut trial = [0.0; MAX_TANGENTS];
    for a in 0..k {
        trial[a] = start.tangential_force[a] - w_t * (g[a] - start.start_slip[a]);
    }
    let mut c = [0.0; MAX_TANGENTS];
    c[..k].copy_from_slice(&start.slip[..k]);
    let bound = mu * lambda_n.max(0.0);
    let trial_length = length(k, &trial);
    if trial_length <= bound * (1.0 + CONE_ROUND_OFF) {
        return ReturnMap {
            status: Status::Stick,
            force: trial,
            plastic_slip: c,
            d_slip: stick_derivative(k, w_t),
            d_normal: [0.0; MAX_TANGENTS],
        };
    }
    let s = direction(k, &trial, trial_length);
    let (force, d_slip, d_normal) =
        slip_branch(k, s, bound, w_t, mu, lambda_n > 0.0, Some(trial_length));
    let mut plastic_slip = [0.0; MAX_TANGENTS];
    for a in 0..k {
        plastic_slip[a] = g[a] + force[a] / w_t;
    }
    ReturnMap {
        status: Status::Slip,
        force,
        plastic_slip,
        d_slip,
        d_normal,
    }
}

/// The return map of the augmented Lagrangian (see the module doc) at a point with Uzawa
/// multiplier `lambda_bar_t`, stick point `stick_point` (committed at the end of the last load
/// step), slip `g_t` (`k` components each), and the bound's normal force `bound_force`
/// (`lambda_n`, or `lambda_bar_n` for Laursen & Simo's form). `bound_varies`: the bound is the
/// current normal force `lambda_n = lambda_bar_n - w_n g_n` (a slip then couples `d_normal =
/// mu s`); with the multiplier held fixed it does not (`d_normal = 0`). The returned
/// `plastic_slip` is the point's stick point after the map: `stick_point` in stick, `g_t`
/// otherwise.
///
/// `held`: the branch to take regardless of the trial force (stick, or slip along the unit
/// direction `s`), as in the Newton iteration right after a Uzawa update (see
/// [`crate::solver::contact_newton`]); `None` (or open) decides from the trial force.
#[allow(clippy::too_many_arguments)]
pub fn augmented_return_map(
    mu: f64,
    w_t: f64,
    bound_force: f64,
    bound_varies: bool,
    active: bool,
    g_t: &[f64],
    stick_point: &[f64],
    lambda_bar_t: &[f64],
    held: Option<(Status, Tangential)>,
) -> ReturnMap {
    let k = g_t.len();
    let (g, p, lambda_bar) = (
        tangential(g_t),
        tangential(stick_point),
        tangential(lambda_bar_t),
    );
    if !active {
        return ReturnMap::open(g);
    }
    let mut trial = [0.0; MAX_TANGENTS];
    for a in 0..k {
        trial[a] = lambda_bar[a] - w_t * (g[a] - p[a]);
    }
    let bound = mu * bound_force.max(0.0);
    let trial_length = length(k, &trial);
    let (stick, s, follows_trial) = match held {
        Some((Status::Stick, _)) => (true, [0.0; MAX_TANGENTS], false),
        Some((Status::Slip, s)) => (false, s, false),
        // on the cone to round-off: stick, as the penalty map (a point that slipped starts
        // its next step with the committed force, on the cone)
        _ => (
            trial_length <= bound * (1.0 + CONE_ROUND_OFF),
            direction(k, &trial, trial_length),
            true,
        ),
    };
    if stick {
        return ReturnMap {
            status: Status::Stick,
            force: trial,
            plastic_slip: p,
            d_slip: stick_derivative(k, w_t),
            d_normal: [0.0; MAX_TANGENTS],
        };
    }
    let (force, d_slip, d_normal) = slip_branch(
        k,
        s,
        bound,
        w_t,
        mu,
        bound_varies && bound_force > 0.0,
        follows_trial.then_some(trial_length),
    );
    ReturnMap {
        status: Status::Slip,
        force,
        plastic_slip: g,
        d_slip,
        d_normal,
    }
}

/// What a frictional point carries from one load step to the next: its committed slip (the
/// plastic slip of the penalty map, the stick point of the multiplier methods) and its forces
/// at the end of the step (the Uzawa multipliers the augmented Lagrangian starts the next step
/// from; unused by the other methods), tangential ones as components along the row's tangents.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct Committed {
    pub slip: Tangential,
    pub normal_force: f64,
    pub tangential_force: Tangential,
    /// The slip measure `g_t^n` at the end of the step: with `tangential_force` the start of
    /// the penalty map's next trial force ([`return_map`]).
    pub start_slip: Tangential,
}

impl Committed {
    /// A point that starts from the plastic slip `slip` without force.
    pub fn at_plastic_slip(slip: Tangential) -> Self {
        Committed {
            slip,
            start_slip: slip,
            ..Committed::default()
        }
    }
}

/// The open/stick/slip set of a point with Lagrange multipliers ([`multiplier_status`]).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MultiplierSet {
    pub status: Status,
    /// In slip, the unit direction `s` of the trial force `tau = lambda_t - c dg_t` (`sign(tau)`
    /// with one tangent); zero otherwise.
    pub direction: Tangential,
    /// In slip, `T = mu lambda_n (I - s s^T) / |tau|` (`k x k`, symmetric, zero with one
    /// tangent): the slip force `mu lambda_n s(tau)` changes by `T d tau` (the turn of the
    /// direction, `d s / d tau = (I - s s^T) / |tau|`); zero otherwise.
    pub turn: [Tangential; MAX_TANGENTS],
}

/// The frictional set of a point with Lagrange multipliers (see the module doc): normal force
/// `lambda_n` (`active`: the normal row is in the active set), tangential force `lambda_t` and
/// slip increment `dg_t` of the step (`k` components each, `k = lambda_t.len()`, one or two)
/// and the constant `c` (a stiffness). With one tangent the disc is the interval and the sets
/// are the scalar ones to the last bit (`|tau| = sqrt(tau^2)` is not taken, `T = 0`).
pub fn multiplier_status(
    mu: f64,
    lambda_n: f64,
    active: bool,
    lambda_t: &[f64],
    increment: &[f64],
    c: f64,
) -> MultiplierSet {
    let k = lambda_t.len();
    let mut set = MultiplierSet {
        status: Status::Open,
        direction: [0.0; MAX_TANGENTS],
        turn: [[0.0; MAX_TANGENTS]; MAX_TANGENTS],
    };
    if !active {
        return set;
    }
    let (force, dg) = (tangential(lambda_t), tangential(increment));
    let trial: Tangential = std::array::from_fn(|a| force[a] - c * dg[a]);
    let trial_length = length(k, &trial);
    // a point on the cone whose slip does not change sticks (its force, carried from the
    // last step, may exceed the bound by the cone's round-off)
    if trial_length <= mu * lambda_n.max(0.0) * (1.0 + CONE_ROUND_OFF) {
        set.status = Status::Stick;
        return set;
    }
    set.status = Status::Slip;
    set.direction = direction(k, &trial, trial_length);
    if k > 1 {
        let scale = mu * lambda_n / trial_length;
        let s = set.direction;
        for a in 0..k {
            for b in 0..k {
                let identity = if a == b { 1.0 } else { 0.0 };
                set.turn[a][b] = scale * (identity - s[a] * s[b]);
            }
        }
    }
    set
}

/// What a solve found at one frictional contact point (aligned with the rows of
/// [`super::state::ContactState`]). Tangential quantities are components along the row's
/// tangents ([`super::Constraint::tangents`]; one in 2D, the second component zero).
#[derive(Copy, Clone, Debug, PartialEq, Serialize)]
pub struct FrictionPoint {
    pub status: Status,
    /// Tangential force `lambda_t` on the slave node.
    pub force: Tangential,
    /// The number of tangents of the point (1 in 2D, 2 in 3D).
    pub tangents: usize,
    /// The friction coefficient of the point's pair.
    pub mu: f64,
    /// The normal force bounding it, `lambda_n` (zero when open).
    pub normal_force: f64,
    /// Slip measure `g_t` and plastic slip `g_t^p` at the end of the step, and the plastic slip
    /// committed at the start of the step.
    pub slip: Tangential,
    pub plastic_slip: Tangential,
    pub committed: Tangential,
    /// Frictional dissipation of the step, `-lambda_t . (g_t^p - g_t^{p,n})` (>= 0; zero open).
    pub dissipation: f64,
}

impl FrictionPoint {
    /// `|lambda_t|`.
    pub fn force_length(&self) -> f64 {
        length(self.tangents, &self.force)
    }

    /// The tangential force as a vector in space, `sum_a lambda_t,a t_a`, with the row's
    /// tangents `tangents`.
    pub fn force_vector<const D: usize>(&self, tangents: &[super::TangentRow<D>]) -> [f64; D] {
        let mut out = [0.0; D];
        for (t, f) in tangents.iter().zip(&self.force) {
            for (o, d) in out.iter_mut().zip(&t.direction) {
                *o += f * d;
            }
        }
        out
    }
}

/// The frictional totals of one pair at the end of a solve.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrictionSummary {
    /// Sum of the tangential forces `lambda_t` on the slave nodes, `[x, y]` (`[x, y, z]` in
    /// 3D; the pair's `force_on_slave` holds the normal and the tangential forces together).
    pub tangential_force: Vec<f64>,
    pub open: usize,
    pub stick: usize,
    pub slip: usize,
    /// Frictional dissipation of the last load step (sum over the points, >= 0).
    pub dissipation: f64,
    /// Largest `|lambda_t| / (mu lambda_n)` over the closed points (<= 1: Coulomb's cone).
    pub max_cone_ratio: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A start at the plastic slip `slip` without force.
    fn plastic(slip: &[f64]) -> Committed {
        Committed::at_plastic_slip(tangential(slip))
    }

    #[test]
    fn stick_slip_and_open_branches() {
        let stick = return_map(0.5, 10.0, 4.0, true, &[0.1], &plastic(&[0.0]));
        assert_eq!(stick.status, Status::Stick);
        assert_eq!(stick.force, [-1.0, 0.0]);
        let slip = return_map(0.5, 10.0, 4.0, true, &[0.5], &plastic(&[0.0]));
        assert_eq!(slip.status, Status::Slip);
        assert_eq!(slip.force, [-2.0, 0.0]);
        // one tangent: the direction cannot turn, the slip branch has no slip stiffness
        assert_eq!(slip.d_slip, [[0.0; 2]; 2]);
        assert_eq!(slip.d_normal, [-0.5, 0.0]);
        // the elastic part of the slip carries the force
        assert!((-10.0 * (0.5 - slip.plastic_slip[0]) - slip.force[0]).abs() < 1e-15);
        let open = return_map(0.5, 10.0, 0.0, false, &[0.5], &plastic(&[0.2]));
        assert_eq!(
            (open.status, open.force, open.plastic_slip),
            (Status::Open, [0.0; 2], [0.5, 0.0])
        );
    }

    /// Defect N01 (second report): a point that slipped in the last step started the next one
    /// with the trial force `-w_t (g_t - g_t^p)`, which after a slide of `g_t` is the committed
    /// force only to `eps w_t |g_t|`: on the cone by +1.7e-10 it took the slip branch (no
    /// tangential stiffness in 2D) and Newton ran away. From the committed force and slip the
    /// trial force is the committed force to the last bit, and the point sticks, in 2D and on
    /// the disc, after a slide long against its elastic slip.
    #[test]
    fn a_point_that_slipped_starts_the_next_step_on_the_cone_in_stick() {
        let (mu, w_t, lambda_n) = (0.3, 1e7, 2.7);
        for slide in [[1.7e3, 0.0], [0.613, 0.0], [1.7e3, -2.9e2], [0.3, 0.7]] {
            let k = if slide[1] == 0.0 { 1 } else { 2 };
            // the end of a step that slipped
            let slipped = return_map(
                mu,
                w_t,
                lambda_n,
                true,
                &slide[..k],
                &plastic(&[0.0; 2][..k]),
            );
            assert_eq!(slipped.status, Status::Slip);
            // the next step's first evaluation, nothing moved yet
            let start = return_map(
                mu,
                w_t,
                lambda_n,
                true,
                &slide[..k],
                &Committed {
                    slip: slipped.plastic_slip,
                    normal_force: lambda_n,
                    tangential_force: slipped.force,
                    start_slip: tangential(&slide[..k]),
                },
            );
            assert_eq!(start.status, Status::Stick, "{slide:?}");
            assert_eq!(start.force, slipped.force, "{slide:?}");
            assert_eq!(start.plastic_slip, slipped.plastic_slip, "{slide:?}");
            // the plastic-slip form misses the cone by the round-off of w_t |g_t|
            let plastic = return_map(
                mu,
                w_t,
                lambda_n,
                true,
                &slide[..k],
                &plastic(&slipped.plastic_slip[..k]),
            );
            let off = (length(k, &plastic.force) - length(k, &slipped.force)).abs();
            assert!(off <= 1e-15 * w_t * length(k, &slide), "{off:e}");
        }
    }

    #[test]
    fn the_augmented_map_projects_the_trial_force_onto_the_cone() {
        // trial 1.0 - 10 (0.05 - 0.0) = 0.5 inside mu lambda_n = 2: stick, the point kept
        let stick = augmented_return_map(0.5, 10.0, 4.0, true, true, &[0.05], &[0.0], &[1.0], None);
        assert_eq!(
            (
                stick.status,
                stick.force[0],
                stick.plastic_slip[0],
                stick.d_slip[0][0]
            ),
            (Status::Stick, 0.5, 0.0, -10.0)
        );
        // trial 1.0 - 10 (0.5) = -4 outside: slip at -mu lambda_n, the point moves to g_t
        let slip = augmented_return_map(0.5, 10.0, 4.0, true, true, &[0.5], &[0.0], &[1.0], None);
        assert_eq!(
            (
                slip.status,
                slip.force[0],
                slip.plastic_slip[0],
                slip.d_normal[0]
            ),
            (Status::Slip, -2.0, 0.5, -0.5)
        );
        // Laursen & Simo: the bound held fixed, no coupling to the normal force
        let fixed = augmented_return_map(0.5, 10.0, 4.0, false, true, &[0.5], &[0.0], &[1.0], None);
        assert_eq!((fixed.force[0], fixed.d_normal[0]), (-2.0, 0.0));
        // held in stick the force is the trial's, even outside the cone
        let held = augmented_return_map(
            0.5,
            10.0,
            4.0,
            true,
            true,
            &[0.5],
            &[0.0],
            &[1.0],
            Some((Status::Stick, [0.0; 2])),
        );
        assert_eq!((held.status, held.force[0]), (Status::Stick, -4.0));
        let open = augmented_return_map(0.5, 10.0, 4.0, true, false, &[0.5], &[0.2], &[1.0], None);
        assert_eq!((open.status, open.force), (Status::Open, [0.0; 2]));
    }

    /// Central differences of the map's force in the slip and the normal force against
    /// `d_slip` and `d_normal`, at `g_t` with committed slip `c`.
    fn difference_error(map: &dyn Fn(&[f64], f64) -> ReturnMap, g: &[f64], lambda_n: f64) -> f64 {
        let k = g.len();
        let at = map(g, lambda_n);
        let h = 1e-7;
        let mut worst = 0.0f64;
        for b in 0..k {
            let (mut plus, mut minus) = (g.to_vec(), g.to_vec());
            plus[b] += h;
            minus[b] -= h;
            let (fp, fm) = (map(&plus, lambda_n), map(&minus, lambda_n));
            assert_eq!((fp.status, fm.status), (at.status, at.status), "at {g:?}");
            for a in 0..k {
                let fd = (fp.force[a] - fm.force[a]) / (2.0 * h);
                worst = worst.max((fd - at.d_slip[a][b]).abs());
            }
        }
        let (fp, fm) = (map(g, lambda_n + h), map(g, lambda_n - h));
        for a in 0..k {
            let fd = (fp.force[a] - fm.force[a]) / (2.0 * h);
            worst = worst.max((fd - at.d_normal[a]).abs());
        }
        worst
    }

    #[test]
    fn the_disc_return_map_derivatives_are_its_differences_in_stick_and_slip() {
        // mu = 0.4, w_t = 30, lambda_n = 5: the disc of radius 2; the committed slip (0.01,
        // -0.02); slips in eight directions at radii inside (stick) and outside (slip)
        let (mu, w_t, lambda_n, committed) = (0.4, 30.0, 5.0, [0.01, -0.02]);
        let penalty = |g: &[f64], n: f64| return_map(mu, w_t, n, true, g, &plastic(&committed));
        let augmented = |g: &[f64], n: f64| {
            augmented_return_map(mu, w_t, n, true, true, g, &committed, &[0.3, 0.5], None)
        };
        for (name, map) in [
            ("penalty", &penalty as &dyn Fn(&[f64], f64) -> ReturnMap),
            ("augmented", &augmented),
        ] {
            for direction in 0..8 {
                let angle = 0.3 + direction as f64 * std::f64::consts::PI / 4.0;
                for (radius, status) in [(0.02, Status::Stick), (0.4, Status::Slip)] {
                    let g = [
                        committed[0] + radius * angle.cos(),
                        committed[1] + radius * angle.sin(),
                    ];
                    let at = map(&g, lambda_n);
                    assert_eq!(at.status, status, "{name} at {g:?}");
                    let error = difference_error(map, &g, lambda_n);
                    assert!(
                        error <= 1e-6 * w_t,
                        "{name} {status:?} along {angle}: derivative error {error:e}"
                    );
                    if status == Status::Slip {
                        // on the disc, along the trial force, against the slip
                        let force = at.force;
                        assert!((length(2, &force) - mu * lambda_n).abs() <= 1e-12);
                        if name == "penalty" {
                            let slip = [g[0] - committed[0], g[1] - committed[1]];
                            let cosine = -(force[0] * slip[0] + force[1] * slip[1])
                                / (length(2, &force) * length(2, &slip));
                            assert!((cosine - 1.0).abs() <= 1e-12, "{cosine}");
                        }
                        // the direction's derivative is not zero in the plane
                        assert!(at.d_slip[0][0] != 0.0 && at.d_slip[0][1] != 0.0);
                    }
                }
            }
        }
    }

    #[test]
    fn the_disc_map_with_one_tangent_is_the_scalar_map() {
        // with k = 1 the radial return is the signed scalar map: |x| = sqrt(x^2), s = +-1
        for g in [-0.7, -0.05, 0.0, 0.03, 0.9] {
            let m = return_map(0.3, 20.0, 4.0, true, &[g], &plastic(&[0.01]));
            let trial = -20.0 * (g - 0.01);
            let bound = 0.3 * 4.0;
            // (a trial on the cone to round-off sticks: g = -0.05 gives 1.2 + 2 ulp)
            if trial.abs() <= bound * (1.0 + CONE_ROUND_OFF) {
                assert_eq!(
                    (m.status, m.force[0], m.d_slip[0][0]),
                    (Status::Stick, trial, -20.0)
                );
            } else {
                let s = trial.signum();
                assert_eq!(
                    (m.status, m.force[0], m.plastic_slip[0], m.d_normal[0]),
                    (Status::Slip, s * bound, g + s * bound / 20.0, s * 0.3)
                );
            }
            assert_eq!(
                (m.force[1], m.plastic_slip[1], m.d_slip[1]),
                (0.0, 0.0, [0.0; 2])
            );
        }
    }

    #[test]
    fn the_disc_dissipates_and_is_isotropic() {
        // rotating the slip and the committed slip about the normal rotates the force: the
        // map has no preferred tangent; and the dissipation -lambda_t . dg^p is >= 0
        let (mu, w_t, lambda_n) = (0.5, 10.0, 4.0);
        let base = return_map(mu, w_t, lambda_n, true, &[0.5, 0.2], &plastic(&[0.1, -0.1]));
        for angle in [0.4f64, 1.7, 3.0, -2.2] {
            let (c, s) = (angle.cos(), angle.sin());
            let rotate = |v: [f64; 2]| [c * v[0] - s * v[1], s * v[0] + c * v[1]];
            let rotated = return_map(
                mu,
                w_t,
                lambda_n,
                true,
                &rotate([0.5, 0.2]),
                &plastic(&rotate([0.1, -0.1])),
            );
            let expected = rotate(base.force);
            assert_eq!(rotated.status, Status::Slip);
            for a in 0..2 {
                assert!((rotated.force[a] - expected[a]).abs() <= 1e-14, "{angle}");
            }
            let committed = rotate([0.1, -0.1]);
            let dissipation = -(0..2)
                .map(|a| rotated.force[a] * (rotated.plastic_slip[a] - committed[a]))
                .sum::<f64>();
            assert!(dissipation > 0.0, "{dissipation}");
        }
    }

    #[test]
    fn multiplier_sets_follow_the_trial_force() {
        let set = |lambda_n, active, lambda_t, increment| {
            let m = multiplier_status(0.5, lambda_n, active, &[lambda_t], &[increment], 10.0);
            assert_eq!(
                m.turn, [[0.0; 2]; 2],
                "one tangent: the direction cannot turn"
            );
            (m.status, m.direction[0])
        };
        // inside the cone: stick; outside: slip against the motion; no normal force: open
        assert_eq!(set(4.0, true, 1.0, 0.0), (Status::Stick, 0.0));
        assert_eq!(set(4.0, true, 2.0, 0.5), (Status::Slip, -1.0));
        assert_eq!(set(4.0, true, 3.0, 0.0), (Status::Slip, 1.0));
        assert_eq!(set(4.0, false, 3.0, 0.0), (Status::Open, 0.0));
        // a closed point with no compression yet sticks where it is
        assert_eq!(set(0.0, true, 0.0, 0.0), (Status::Stick, 0.0));
    }

    #[test]
    fn multiplier_sets_on_the_disc_return_radially_with_the_turn_of_the_direction() {
        // mu lambda_n = 2, c = 10: the trial force lambda_t - c dg in eight directions, inside
        // (stick) and outside (slip) the disc
        let (mu, lambda_n, c) = (0.5, 4.0, 10.0);
        for direction in 0..8 {
            let angle = 0.2 + direction as f64 * std::f64::consts::PI / 4.0;
            let e = [angle.cos(), angle.sin()];
            let lambda_t = [0.3, -0.4];
            for (radius, status) in [(1.5, Status::Stick), (3.0, Status::Slip)] {
                // dg such that tau = radius e
                let dg = [
                    (lambda_t[0] - radius * e[0]) / c,
                    (lambda_t[1] - radius * e[1]) / c,
                ];
                let m = multiplier_status(mu, lambda_n, true, &lambda_t, &dg, c);
                assert_eq!(m.status, status, "{angle}");
                if status == Status::Stick {
                    assert_eq!((m.direction, m.turn), ([0.0; 2], [[0.0; 2]; 2]));
                    continue;
                }
                for a in 0..2 {
                    assert!((m.direction[a] - e[a]).abs() <= 1e-14);
                }
                // T is the derivative of mu lambda_n s(tau) in tau: central differences
                let slip_force = |tau: [f64; 2]| {
                    let l = length(2, &tau);
                    [mu * lambda_n * tau[0] / l, mu * lambda_n * tau[1] / l]
                };
                let tau = [radius * e[0], radius * e[1]];
                let h = 1e-6;
                for b in 0..2 {
                    let (mut plus, mut minus) = (tau, tau);
                    plus[b] += h;
                    minus[b] -= h;
                    let (fp, fm) = (slip_force(plus), slip_force(minus));
                    for a in 0..2 {
                        let fd = (fp[a] - fm[a]) / (2.0 * h);
                        assert!(
                            (fd - m.turn[a][b]).abs() <= 1e-9,
                            "{angle}: {fd} vs {:?}",
                            m.turn
                        );
                    }
                }
                // the direction's own derivative is zero along s: T s = 0
                for a in 0..2 {
                    let ts = m.turn[a][0] * e[0] + m.turn[a][1] * e[1];
                    assert!(ts.abs() <= 1e-15, "{ts}");
                }
            }
        }
        // a trial force along a tangent slips along it on the disc too, with the scalar's sign
        let two = multiplier_status(mu, lambda_n, true, &[2.0, 0.0], &[0.5, 0.0], c);
        assert_eq!((two.status, two.direction), (Status::Slip, [-1.0, 0.0]));
    }
}
