//! Cattaneo-Mindlin in 3D (issue 13): an elastic sphere pressed onto an elastic half-space of
//! the same material by `P`, then sheared by `Q < mu P` with the approach held (a load path),
//! measured against the closed form under mesh refinement.
//!
//! **Closed form** (Johnson, *Contact Mechanics*, 1985, s. 4.2 and s. 7.2; Mindlin 1949).
//! Hertz: `1/E* = (1 - nu_1^2)/E_1 + (1 - nu_2^2)/E_2`, `a = (3 P R / (4 E*))^(1/3)`,
//! `p0 = 3 P / (2 pi a^2)`, `p(r) = p0 sqrt(1 - r^2/a^2)`. Cattaneo-Mindlin, `Q` along `x`
//! increased monotonically from 0 at constant `P`:
//!
//! ```text
//! c = a (1 - Q/(mu P))^(1/3)                                  (stick radius)
//! q(r) = (mu p0 / a) [sqrt(a^2 - r^2) - sqrt(c^2 - r^2)]      r < c   (stick)
//! q(r) = (mu p0 / a) sqrt(a^2 - r^2) = mu p(r)                c <= r < a (slip)
//! ```
//!
//! a traction along `x` everywhere (Johnson eqs 7.42-7.45). Its two conditions:
//!
//! * **Normal-tangential uncoupling.** The normal pressure causes no relative tangential
//!   displacement of the surfaces, and the shear no relative normal one, only when Dundurs'
//!   `beta = [(1 - 2 nu_1)/G_1 - (1 - 2 nu_2)/G_2] / (2 [(1 - nu_1)/G_1 + (1 - nu_2)/G_2])`
//!   vanishes (Goodman 1962; Johnson s. 5.3): for identical materials or `nu = 0.5` on both.
//!   A rigid sphere on an elastic block (`beta = (1 - 2 nu) / (2 (1 - nu))`, 0.29 at
//!   `nu = 0.3`) would shear the interface already while it is pressed (Spence's inward slip:
//!   radial tractions up to `mu p` near the edge), so this study presses two bodies of the
//!   **same material**: `beta = 0` exactly.
//! * **Slip parallel to Q.** The traction is assumed along `x`; with it the displacement
//!   across `x` is `u_y ~ nu x y` (Johnson eq. 3.92), so for `nu > 0` the slip in the annulus
//!   is not quite parallel to `Q` (Mindlin's approximation; the error is small, Johnson s. 7.2).
//!   At **`nu = 0`** `u_y = 0` and the closed form is exact: this study uses `nu = 0`.
//!
//! * **Small slopes.** Hertz's and Mindlin's half-spaces are flat: the faces' slope at the
//!   contact edge, `a / R`, must be small. At `a / R = 0.1` (R = 1) the shear traction came
//!   out with an odd part of about 0.1 of `q` (the drag has a component along the inclined
//!   face's normal of order `a / R`); this study takes `R = 10` ([`RADIUS`], `a / R = 0.01`),
//!   where it is below 0.01.
//!
//! So the expected discrepancy is the discretization's, the slope's (order `a / R`), and the
//! finite bodies standing for half-spaces (each block is `12 a` wide and `6 a` deep: the near
//! field `a(P)`, `q(r) / (mu p0)` depends little on them, the approach more: it is not
//! compared; `P` and `Q` are measured).
//!
//! **Model.** A half model, symmetric about the plane `y = 0` that holds `Q` and the normal
//! (a quarter is not symmetric under a load along `x`): `u_y = 0` on `y = 0` (`u_x`, `u_z`
//! even in `y`, `u_y` odd). Lower body ("foundation", the sphere): the block
//! `[-L, L] x [0, L] x [-L, 0]` whose top is lowered to `z = -f(r)`, `f(r) = r^2 / (2 R)` for
//! `r <= r1 = 2 a_t` (`a_t` the target radius [`TARGET_RADIUS`]), continued smoothly and
//! monotonically beyond, `f = r1^2/(2R) + (r1^2/R) (1 - exp(-(r - r1)/r1))` (the contact
//! never reaches it; interior nodes follow the top linearly to the fixed bottom). Upper body
//! ("half-space"): the flat block `[-L, L] x [0, L] x [0, L]`. Both Hex8 on the same graded
//! breaks in `x` and `y` (uniform `h` up to `1.5 a_t`, then each element [`GROWTH`] times the
//! previous), so the interface nodes face each other. The foundation's bottom is held; the
//! half-space's top is moved down by the approach `a_t^2 / R` in every step and along `x` by
//! the drag [`DRAG`] in the second (load path `[0, 1]`): press, then shear with the press's
//! committed slip carried (about `Q = 0.45 mu P`). Node-to-surface rows, one pass, the
//! **foundation's curved top the slave** and the flat bottom of the half-space the master:
//! with the curved face as the master, the slave nodes on the symmetry plane project onto its
//! free edge there and get no row (small strain: a node beyond the master's free boundary has
//! left it), so the line `y = 0` would not be held. Coulomb friction `mu` ([`MU`]), the Newton
//! scheme, the penalty [`KAPPA`] (normal and tangential): its penetration `p0 / kappa` is
//! `3e-7`, `3e-4` of the approach `1e-3`, and its elastic slip in the stick zone
//! `q / kappa <= 4e-8`, `4e-4` of the drag. With Lagrange multipliers (the symmetry plane's
//! rows are solved: `tests/friction3d.rs`, `a_half_model_on_its_symmetry_plane_..`) this scene
//! at `h = a_t / 2` converges, but the press's semi-smooth Newton iteration cycles (12 points
//! flip between stick and slip at every iteration) until the cycle remedy has lowered the
//! stick/slip constant `c` to `1e-12` of the stiffness scale: 64 iterations, against 2 for the
//! penalty (measured 2026-11-28 by `contact-patch run` on this case with
//! `"enforcement": {"kind": "lagrange"}`; the shear step took 4, and `P`, `Q` agreed with the
//! penalty's to 2.1e-4 and 5.2e-5). The study keeps the penalty.
//!
//! **Measured** at each mesh, from the rows at the end of the shear step, with `x_i` the slave
//! node's reference position, `lambda_i` its normal force, `f_i` its tangential force (on the
//! foundation) and `A_i` its tributary area: `P = |2 sum lambda_i n_z|`,
//! `Q = |2 sum f_i . e_x|` (both halves); the closed form at the measured `P`, `Q`; the
//! centre `x0`, the pressure centroid `sum lambda_i x_i / sum lambda_i` on the line `y = 0`,
//! and `r_i` from it; nodal tractions `p_i = lambda_i / A_i`, `q_i = f_i . e_x / A_i` (signed
//! along `Q`); the stick radius `c_h`: on the line `y = 0` on each side of the centre, the
//! midpoint between the outermost node of the central stick run and the next node, averaged
//! over the two sides (the boundary lies between two nodes: `|c_h - c| <= h/2` plus the
//! solution's error); the contact radius `a_h` likewise from the closed nodes, and from the
//! pressure's second moment `a_m = sqrt(5/2 sum lambda r^2 / sum lambda)` (Hertz:
//! `int p r^2 dA / int p dA = 2 a^2 / 5`); discrete L2 errors (weights `A_i`):
//! `||q_h - q|| / ||q||` over the points `r <= a`, the same farther than `2 h` from the cusp
//! of `q` at `c`, `||p_h - p|| / ||p||` over `r <= 0.8 a`, and against the closed form's
//! consistent nodal values `int N_i q dA / int N_i dA` ([`nodal_value`]; a row's force over
//! its area converges to it, the point value differs by `O(h^2 q'')`, `O(1)` next to the
//! cusp and the edge) over every row with `r < a + h`; the traction across `Q`,
//! `||f . e_y / A|| / ||q||`, and the odd part of `q` on `y = 0` (both zero in the closed
//! form); the largest Coulomb ratio `|f_i| / (mu lambda_i)`; the dissipation of each step.

use crate::contact::friction::Status;
use crate::error::{Error, Result};

use crate::run::run_case3;
use crate::run3d::Outcome3;
use serde::Serialize;
use serde_json::{json, Value};

/// Young's modulus and Poisson's ratio of both bodies (`nu = 0`: see the module notes).
pub const E: f64 = 1000.0;
pub const NU: f64 = 0.0;
/// Radius of the sphere (the gap profile `r^2 / (2 R)`).
pub const RADIUS: f64 = 10.0;
/// Coulomb's coefficient.
pub const MU: f64 = 0.3;
/// The contact radius the approach is chosen for and the mesh is graded to.
pub const TARGET_RADIUS: f64 = 0.1;
/// Half-width, breadth and depth of each block, `6 a_t`.
pub const SIZE: f64 = 6.0 * TARGET_RADIUS;
/// Growth factor of the element size outside the fine zone.
pub const GROWTH: f64 = 2.0;
/// Extent of the uniform fine zone, in units of the target radius.
pub const FINE_EXTENT: f64 = 1.5;
/// The penalty of the rows, normal and tangential (module notes, **Model**).
pub const KAPPA: f64 = 1e7;
/// The drag of the half-space's top along `x` in the shear step (about `Q = mu P / 2`).
pub const DRAG: f64 = 1.1e-4;

/// What a level's scene is made of besides its fine size (the study's values are
/// [`Scene::STUDY`]).
#[derive(Copy, Clone, Debug, PartialEq, Serialize)]
pub struct Scene {
    /// Half-width, breadth and depth of each block.
    pub size: f64,
    /// Growth factor of the element size outside the fine zone.
    pub growth: f64,
    /// The penalty, normal and tangential.
    pub kappa: f64,
    /// The drag of the half-space's top along `x` in the shear step.
    pub drag: f64,
    /// Load steps of the shear (after the one of the press).
    pub shear_steps: usize,
}

impl Scene {
    pub const STUDY: Scene = Scene {
        size: SIZE,
        growth: GROWTH,
        kappa: KAPPA,
        drag: DRAG,
        shear_steps: 1,
    };
}

/// `E*` of two bodies of the material (`E`, `NU`).
pub fn effective_modulus() -> f64 {
    E / (2.0 * (1.0 - NU * NU))
}

/// Hertz's and Cattaneo-Mindlin's closed forms at the loads `P`, `Q`.
#[derive(Copy, Clone, Debug, PartialEq, Serialize)]
pub struct Mindlin {
    /// Normal load `P` (whole sphere).
    pub load: f64,
    /// Tangential load `Q` (along `x`, `0 <= Q`).
    pub shear: f64,
    pub mu: f64,
    pub radius: f64,
    /// `E*`.
    pub modulus: f64,
}

impl Mindlin {
    /// Hertz's contact radius `a`.
    pub fn contact_radius(&self) -> f64 {
        (3.0 * self.load * self.radius / (4.0 * self.modulus)).cbrt()
    }

    /// The peak pressure `p0 = 3 P / (2 pi a^2)`.
    pub fn peak(&self) -> f64 {
        let a = self.contact_radius();
        3.0 * self.load / (2.0 * std::f64::consts::PI * a * a)
    }

    /// The stick radius `c = a (1 - Q/(mu P))^(1/3)` (0 when `Q >= mu P`).
    pub fn stick_radius(&self) -> f64 {
        self.contact_radius() * (1.0 - self.shear / (self.mu * self.load)).max(0.0).cbrt()
    }

    /// Hertz's `p(r)`.
    pub fn pressure(&self, r: f64) -> f64 {
        let a = self.contact_radius();
        self.peak() * (1.0 - (r / a).powi(2)).max(0.0).sqrt()
    }

    /// Cattaneo-Mindlin's `q(r)` along `Q`.
    pub fn traction(&self, r: f64) -> f64 {
        let (a, c) = (self.contact_radius(), self.stick_radius());
        let scale = self.mu * self.peak() / a;
        scale * ((a * a - r * r).max(0.0).sqrt() - (c * c - r * r).max(0.0).sqrt())
    }
}

/// The consistent nodal value of `f(r)` at a node `(x, y)` of a uniform grid of spacing `h`:
/// `int N f dA / int N dA` with the node's bilinear hat `N` over its four cells (what a
/// row's force over its area is in the limit), by 8 x 8 Gauss points on each of 4 x 4
/// sub-cells of each cell (`f` has square-root edges at `r = a` and `r = c`). At a node on
/// the symmetry plane the half hat gives the same value (`f` is even in `y`).
pub fn nodal_value(f: &dyn Fn(f64) -> f64, x: f64, y: f64, h: f64) -> f64 {
    let rule = crate::fe::gauss_legendre(8);
    let sub = 4;
    let step = h / sub as f64;
    let (mut integral, mut weight) = (0.0, 0.0);
    for i in 0..2 * sub {
        for j in 0..2 * sub {
            let (u0, v0) = (-h + i as f64 * step, -h + j as f64 * step);
            for &(s, ws) in &rule {
                for &(t, wt) in &rule {
                    let (u, v) = (u0 + 0.5 * step * (s + 1.0), v0 + 0.5 * step * (t + 1.0));
                    let hat = (1.0 - u.abs() / h) * (1.0 - v.abs() / h);
                    let w = ws * wt * 0.25 * step * step * hat;
                    integral += w * f((x + u).hypot(y + v));
                    weight += w;
                }
            }
        }
    }
    integral / weight
}

/// The lift of the foundation's top below the plane `z = 0` at the distance `r` from the
/// axis (module notes): `r^2/(2R)` up to `r1 = 2 a_t`, continued with the same slope and a
/// decaying one beyond.
pub fn gap_profile(r: f64) -> f64 {
    let r1 = 2.0 * TARGET_RADIUS;
    if r <= r1 {
        r * r / (2.0 * RADIUS)
    } else {
        r1 * r1 / (2.0 * RADIUS) + r1 * r1 / RADIUS * (1.0 - (-(r - r1) / r1).exp())
    }
}

/// The case of the mesh with fine element size `h` and the shear step's drag `drag`.
pub fn case(h: f64, scene: &Scene) -> Value {
    let size = scene.size;
    let half = crate::harness::hertz3d::graded_breaks_growing(
        h,
        FINE_EXTENT * TARGET_RADIUS,
        size,
        scene.growth,
    );
    let xs: Vec<f64> = half
        .iter()
        .rev()
        .map(|x| -x)
        .chain(half.iter().skip(1).copied())
        .collect();
    let below: Vec<f64> = half.iter().rev().map(|z| -z).collect();
    let mut moves = Vec::new();
    for &x in &xs {
        for &y in &half {
            let lift = gap_profile(x.hypot(y));
            for &z in &below {
                if lift > 0.0 && z > -size {
                    moves.push(
                        json!({"from": [x, y, z], "to": [x, y, z - lift * (z + size) / size]}),
                    );
                }
            }
        }
    }
    let approach = TARGET_RADIUS * TARGET_RADIUS / RADIUS;
    let steps = scene.shear_steps.max(1);
    let drag_path: Vec<f64> = (0..=steps).map(|k| k as f64 / steps as f64).collect();
    json!({
        "name": "cattaneo-mindlin-3d",
        "description": "an elastic sphere pressed onto a half-space of its material, then sheared (src/harness/cattaneo3d.rs)",
        "materials": {"m": {"E": E, "nu": NU}},
        "bodies": [
            {"name": "foundation", "material": "m",
                "mesh": {"block3d": {"element": "Hex8", "x": xs, "y": half, "z": below, "moves": moves}}},
            {"name": "half-space", "material": "m",
                "mesh": {"block3d": {"element": "Hex8", "x": xs, "y": half, "z": half}}}
        ],
        "supports": [
            {"body": "foundation", "set": "bottom", "x": 0.0, "y": 0.0, "z": 0.0},
            {"body": "foundation", "set": "front", "y": 0.0},
            {"body": "half-space", "set": "front", "y": 0.0},
            {"body": "half-space", "set": "top", "z": -approach, "path": vec![1.0; steps + 1]},
            {"body": "half-space", "set": "top", "x": scene.drag, "path": drag_path}
        ],
        "loads": [],
        "contact": [{
            "name": "interface",
            "slave": {"body": "foundation", "set": "top"},
            "master": {"body": "half-space", "set": "bottom"},
            "discretization": {"kind": "node_to_surface", "passes": 1},
            "enforcement": {"kind": "penalty", "kappa": scene.kappa},
            "interaction": {"coulomb": {"mu": MU}}
        }],
        "solver": {"scheme": "newton", "load_steps": steps + 1}
    })
}

/// One measured slave point (module notes).
#[derive(Clone, Debug, Serialize)]
pub struct SurfacePoint {
    pub x: f64,
    pub y: f64,
    pub r: f64,
    pub pressure: f64,
    pub traction: f64,
    /// The traction across `Q` (along `y`).
    pub cross: f64,
    pub area: f64,
    pub status: Status,
}

/// What one mesh measured, against the closed form at its loads.
#[derive(Clone, Debug, Serialize)]
pub struct Level {
    pub h: f64,
    pub elements_per_radius: f64,
    pub dofs: usize,
    pub newton_iterations: usize,
    /// The closed forms at the measured `P`, `Q`.
    pub closed_form: Mindlin,
    pub contact_radius: f64,
    pub stick_radius: f64,
    pub peak: f64,
    /// `Q / (mu P)`.
    pub load_ratio: f64,
    /// The centre on `y = 0`.
    pub centre: f64,
    pub measured_contact_radius: f64,
    pub moment_radius: f64,
    pub measured_stick_radius: f64,
    /// The outermost stick nodes on `y = 0` on each side, relative to the centre.
    pub stick_ends: [f64; 2],
    pub stick_points: usize,
    pub slip_points: usize,
    pub traction_error: f64,
    pub traction_error_off_boundary: f64,
    pub pressure_error_interior: f64,
    /// Against the closed form's consistent nodal values ([`nodal_value`]) over the rows with
    /// `r < a + h` (open ones included): `||q_h - q_N|| / ||q_N||`, `||p_h - p_N|| / ||p_N||`.
    pub traction_error_nodal: f64,
    pub pressure_error_nodal: f64,
    /// `||q_y|| / ||q||` over `r <= a` (zero in the closed form).
    pub cross_traction: f64,
    pub max_cone_ratio: f64,
    /// The dissipation of the two steps.
    pub dissipation: Vec<f64>,
    /// The odd part of `q` on `y = 0`, `||(q(x) - q(-x))/2|| / ||q||` over the points with a
    /// point within `h / 20` of `-x` (zero in the closed form).
    pub odd_traction: f64,
    /// Newton iterations of each step.
    pub step_iterations: Vec<usize>,
    /// The points on `y = 0`, by `x`.
    pub line: Vec<SurfacePoint>,
    /// Every closed point.
    pub surface: Vec<SurfacePoint>,
}

/// Solve the case of fine size `h` and measure it.
pub fn level(h: f64, scene: &Scene) -> Result<Level> {
    let case = crate::model::parse(&case(h, scene).to_string(), "cattaneo-mindlin-3d")?;
    let outcome = run_case3(&case, "cattaneo-mindlin-3d")?;
    measure(h, &outcome)
}

fn defect(h: f64, problem: String) -> Error {
    Error::Solver {
        path: "cattaneo-mindlin-3d".into(),
        problem: format!("h = {h}: {problem}"),
        hint: "this is a defect of the study's scene; report it".into(),
    }
}

/// Measure the outcome of the case of fine size `h` (module notes).
pub fn measure(h: f64, outcome: &Outcome3) -> Result<Level> {
    let state = outcome
        .solution
        .contact
        .as_ref()
        .ok_or_else(|| defect(h, "no contact solution".into()))?;
    if !outcome.converged() {
        return Err(defect(
            h,
            format!("the solve ended with {:?}", state.termination),
        ));
    }
    let mut points = Vec::new();
    let (mut load, mut shear) = (0.0, 0.0);
    let mut max_cone = 0.0f64;
    for ((row, friction), &lambda) in state.rows.iter().zip(&state.friction).zip(&state.forces) {
        let f = friction.ok_or_else(|| defect(h, "a row without friction".into()))?;
        if f.status == Status::Open || lambda <= 0.0 {
            continue;
        }
        let v = f.force_vector(&row.tangents);
        load += 2.0 * lambda * row.normal[2];
        shear += 2.0 * v[0];
        max_cone = max_cone.max(f.force_length() / (MU * lambda));
        points.push((row.point, lambda, v, row.area, f.status));
    }
    // the rows' forces act on the foundation (the slave): down and along the drag
    let (load, sign) = (load.abs(), shear.signum());
    let shear = shear.abs();
    let on_line = |p: &[f64; 3]| p[1].abs() < 1e-12;
    let line_load: f64 = points.iter().filter(|q| on_line(&q.0)).map(|q| q.1).sum();
    let centre = points
        .iter()
        .filter(|q| on_line(&q.0))
        .map(|q| q.1 * q.0[0])
        .sum::<f64>()
        / line_load;
    let closed_form = Mindlin {
        load,
        shear,
        mu: MU,
        radius: RADIUS,
        modulus: effective_modulus(),
    };
    let (a, c) = (closed_form.contact_radius(), closed_form.stick_radius());
    let surface: Vec<SurfacePoint> = points
        .iter()
        .map(|&(x, lambda, v, area, status)| SurfacePoint {
            x: x[0] - centre,
            y: x[1],
            r: (x[0] - centre).hypot(x[1]),
            pressure: lambda / area,
            traction: sign * v[0] / area,
            cross: v[1] / area,
            area,
            status,
        })
        .collect();
    // every slave node on y = 0 (open ones too), by x
    let mut line: Vec<SurfacePoint> = state
        .rows
        .iter()
        .zip(&state.friction)
        .zip(&state.forces)
        .filter(|((row, _), _)| on_line(&row.point))
        .map(|((row, f), &lambda)| {
            let f = f.expect("every row is frictional");
            let v = f.force_vector(&row.tangents);
            SurfacePoint {
                x: row.point[0] - centre,
                y: 0.0,
                r: (row.point[0] - centre).abs(),
                pressure: lambda / row.area,
                traction: sign * v[0] / row.area,
                cross: v[1] / row.area,
                area: row.area,
                status: if lambda > 0.0 { f.status } else { Status::Open },
            }
        })
        .collect();
    line.sort_by(|p, q| p.x.total_cmp(&q.x));
    // the run of `inside` points through the one nearest the centre: its ends and the
    // radius from the midpoints to the next points, averaged over the two sides
    let run = |inside: &dyn Fn(&SurfacePoint) -> bool| -> ([f64; 2], f64) {
        let Some(mid) = (0..line.len()).min_by(|&i, &j| line[i].r.total_cmp(&line[j].r)) else {
            return ([0.0; 2], 0.0);
        };
        if !inside(&line[mid]) {
            return ([0.0; 2], 0.0);
        }
        let (mut lo, mut hi) = (mid, mid);
        while lo > 0 && inside(&line[lo - 1]) {
            lo -= 1;
        }
        while hi + 1 < line.len() && inside(&line[hi + 1]) {
            hi += 1;
        }
        let left = if lo > 0 {
            0.5 * (line[lo].x + line[lo - 1].x)
        } else {
            line[lo].x
        };
        let right = if hi + 1 < line.len() {
            0.5 * (line[hi].x + line[hi + 1].x)
        } else {
            line[hi].x
        };
        ([line[lo].x, line[hi].x], 0.5 * (right - left))
    };
    let (_, measured_contact_radius) = run(&|p| p.status != Status::Open);
    let (stick_ends, measured_stick_radius) = run(&|p| p.status == Status::Stick);
    let moment = points
        .iter()
        .map(|q| q.1 * ((q.0[0] - centre).powi(2) + q.0[1].powi(2)))
        .sum::<f64>();
    let lambda_sum: f64 = points.iter().map(|q| q.1).sum();
    let moment_radius = (2.5 * moment / lambda_sum).sqrt();
    let relative = |keep: &dyn Fn(&SurfacePoint) -> bool,
                    value: &dyn Fn(&SurfacePoint) -> f64,
                    exact: &dyn Fn(f64) -> f64| {
        let (mut error, mut norm) = (0.0, 0.0);
        for p in surface.iter().filter(|p| keep(p)) {
            error += (value(p) - exact(p.r)).powi(2) * p.area;
            norm += exact(p.r).powi(2) * p.area;
        }
        (error / norm).sqrt()
    };
    let traction = |r: f64| closed_form.traction(r);
    let pressure = |r: f64| closed_form.pressure(r);
    let traction_error = relative(&|p| p.r <= a, &|p| p.traction, &traction);
    let traction_error_off_boundary = relative(
        &|p| p.r <= a && (p.r - c).abs() > 2.0 * h,
        &|p| p.traction,
        &traction,
    );
    let pressure_error_interior = relative(&|p| p.r <= 0.8 * a, &|p| p.pressure, &pressure);
    let cross_traction = relative(&|p| p.r <= a, &|p| p.cross + traction(p.r), &traction);
    // every row near the contact, open ones included, against the consistent nodal values
    let (mut q_error, mut q_norm, mut p_error, mut p_norm) = (0.0, 0.0, 0.0, 0.0);
    for ((row, f), &lambda) in state.rows.iter().zip(&state.friction).zip(&state.forces) {
        let (x, y) = (row.point[0] - centre, row.point[1]);
        if x.hypot(y) >= a + h {
            continue;
        }
        let f = f.expect("every row is frictional");
        let (p_h, q_h) = if f.status == Status::Open || lambda <= 0.0 {
            (0.0, 0.0)
        } else {
            let v = f.force_vector(&row.tangents);
            (lambda / row.area, sign * v[0] / row.area)
        };
        let (p_n, q_n) = (
            nodal_value(&pressure, x, y, h),
            nodal_value(&traction, x, y, h),
        );
        q_error += (q_h - q_n).powi(2) * row.area;
        q_norm += q_n.powi(2) * row.area;
        p_error += (p_h - p_n).powi(2) * row.area;
        p_norm += p_n.powi(2) * row.area;
    }
    let (traction_error_nodal, pressure_error_nodal) =
        ((q_error / q_norm).sqrt(), (p_error / p_norm).sqrt());
    let (mut odd, mut even) = (0.0, 0.0);
    for p in line.iter().filter(|p| p.r <= a) {
        if let Some(m) = line.iter().find(|m| (m.x + p.x).abs() <= 0.05 * h) {
            odd += (0.5 * (p.traction - m.traction)).powi(2) * p.area;
            even += traction(p.r).powi(2) * p.area;
        }
    }
    let odd_traction = (odd / even).sqrt();
    let count = |s: Status| surface.iter().filter(|p| p.status == s).count();
    Ok(Level {
        h,
        elements_per_radius: TARGET_RADIUS / h,
        dofs: outcome.model.dof_count,
        newton_iterations: state.iterations,
        closed_form,
        contact_radius: a,
        stick_radius: c,
        peak: closed_form.peak(),
        load_ratio: shear / (MU * load),
        centre,
        measured_contact_radius,
        moment_radius,
        measured_stick_radius,
        stick_ends,
        stick_points: count(Status::Stick),
        slip_points: count(Status::Slip),
        traction_error,
        traction_error_off_boundary,
        pressure_error_interior,
        cross_traction,
        max_cone_ratio: max_cone,
        dissipation: state
            .steps
            .iter()
            .map(|s| s.friction.as_ref().map_or(0.0, |f| f.dissipation))
            .collect(),
        traction_error_nodal,
        pressure_error_nodal,
        odd_traction,
        step_iterations: state.steps.iter().map(|s| s.iterations).collect(),
        line,
        surface,
    })
}
