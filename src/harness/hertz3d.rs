//! Hertz in 3D (issue 13): `contact-patch hertz-3d` writes `reports/hertz-3d.{md,json}` and a
//! plot of the pressure profile.
//!
//! **Problem.** A rigid sphere of radius `R` (centre `(0, 0, R)`) touches the top `z = 0` of an
//! elastic block (E, nu, small strain, Hex8) at the origin; the block stands for a half-space.
//! By symmetry a quarter is modelled: the block `[0, L]^2 x [-L, 0]` with `u_x = 0` on `x = 0`,
//! `u_y = 0` on `y = 0`, and its bottom moved up by the approach `delta` (`u_z = delta`, free
//! in x and y). The breaks are graded: uniform of size `h` up to `1.5 a` from the contact
//! (x, y and depth), then growing by a factor [`GROWTH`] per element up to `L`. Frictionless
//! node-to-surface rows (one pass, the block's top the slave) against the rigid sphere,
//! Lagrange multipliers, the active-set solve of [`crate::run3d`].
//!
//! **Closed form** (Johnson, *Contact Mechanics*, s. 4.2; `shared/design/benchmarks.md` s. 8):
//! a rigid sphere on an elastic half-space is Hertz's problem of an elastic sphere of the same
//! `R` on a rigid plane with `E* = E / (1 - nu^2)`: at the load `P`,
//! `a = (3 P R / (4 E*))^(1/3)`, `p0 = 3 P / (2 pi a^2)`, `p(r) = p0 sqrt(1 - r^2 / a^2)`,
//! approach `delta = a^2 / R` (of points far from the contact).
//!
//! **Measured** at each mesh: the load `P = 4 sum lambda_i` (the rows' forces on the quarter's
//! slave nodes); the closed-form `a` and `p0` at that `P`; the peak pressure
//! `lambda / area` of the row at the centre node (consistent nodal force over its tributary
//! area); the contact radius two ways: (i) the bracket of the active nodes on the symmetry
//! line `y = 0`, the outermost closed node `r_in` and the next, open, node `r_out` (the exact
//! `a` must lie in it), with `(r_in + r_out) / 2` as the estimate; (ii) from the pressure
//! profile's second moment, `a_m = sqrt(5/2 sum lambda_i r_i^2 / sum lambda_i)` (for Hertz's
//! profile `int p r^2 dA / int p dA = 2 a^2 / 5`). The relative errors of `a_m` and of the
//! peak against the closed form at the measured `P` are the convergence measures.
//!
//! **Half-space assumption.** The block is `L = 20 a` deep and wide (`a` the target radius
//! [`TARGET_RADIUS`]); its bottom is held in z, so the prescribed `delta` (set to the
//! half-space approach `a^2 / R` of the target) is not the half-space approach and the load
//! is compared through `a(P)` and `p0(P)`, which depend on the near field. The report also
//! states `delta` against `a^2 / R` at the measured load (the far-field part of the approach
//! is not that of a half-space).

use crate::error::Result;
use crate::io::svg::{line_plot, Series};
use crate::run::run_case3;
use crate::run3d::Outcome3;
use serde::Serialize;
use serde_json::{json, Value};

/// Young's modulus and Poisson's ratio of the block.
pub const E: f64 = 1000.0;
pub const NU: f64 = 0.3;
/// Radius of the rigid sphere.
pub const RADIUS: f64 = 1.0;
/// The contact radius the approach is chosen for (`delta = a^2 / R`) and the mesh is graded to.
pub const TARGET_RADIUS: f64 = 0.1;
/// Width, breadth and depth of the quarter block, `20 a`.
pub const SIZE: f64 = 20.0 * TARGET_RADIUS;
/// Growth factor of the element size outside the fine zone.
pub const GROWTH: f64 = 1.5;
/// Extent of the uniform fine zone, in units of the target radius.
pub const FINE_EXTENT: f64 = 1.5;

/// The effective modulus `E* = E / (1 - nu^2)` of a rigid sphere on an elastic half-space.
pub fn effective_modulus() -> f64 {
    E / (1.0 - NU * NU)
}

/// Hertz's contact radius, peak pressure and approach at the load `p` (whole sphere).
pub fn hertz(p: f64) -> (f64, f64, f64) {
    let a = (3.0 * p * RADIUS / (4.0 * effective_modulus())).cbrt();
    (
        a,
        3.0 * p / (2.0 * std::f64::consts::PI * a * a),
        a * a / RADIUS,
    )
}

/// Breaks from 0 to `length`: uniform of size `h` up to `fine` (rounded up to whole
/// elements), then each element [`GROWTH`] times the previous; the last element ends at
/// `length` (merged with the one before when it would be less than half the previous size).
pub fn graded_breaks(h: f64, fine: f64, length: f64) -> Vec<f64> {
    graded_breaks_growing(h, fine, length, GROWTH)
}

/// [`graded_breaks`] with each element `growth` times the previous one past `fine`.
pub fn graded_breaks_growing(h: f64, fine: f64, length: f64, growth: f64) -> Vec<f64> {
    let mut breaks = vec![0.0];
    let fine_elements = (fine / h).ceil() as usize;
    for k in 1..=fine_elements {
        breaks.push(k as f64 * h);
    }
    let mut size = h;
    loop {
        let last = *breaks.last().expect("starts at 0");
        size *= growth;
        if last + size >= length {
            if length - last < 0.5 * size / growth && breaks.len() > 2 {
                breaks.pop();
            }
            breaks.push(length);
            break;
        }
        breaks.push(last + size);
    }
    breaks
}

/// The closed form's nodal pressure at the centre node of a quarter mesh of fine size `h`
/// (one Quad4 facet `[0, h]^2` at the node): the consistent nodal force of Hertz's pressure,
/// `int N p dA` with `N = (1 - x/h)(1 - y/h)`, over the node's area `int N dA = h^2 / 4`.
/// A row's multiplier is that nodal force in the limit; `p0 (1 - h^2 / (6 a^2))` to leading
/// order, so the mesh-dependent averaging is not counted as error. 16 x 16 Gauss points,
/// exact to round-off while the facet lies inside the contact circle (`h sqrt 2 < a`).
pub fn centre_nodal_pressure(a: f64, p0: f64, h: f64) -> f64 {
    let rule = crate::fe::gauss_legendre(16);
    let mut force = 0.0;
    for &(s, ws) in &rule {
        for &(t, wt) in &rule {
            let (x, y) = (0.5 * h * (s + 1.0), 0.5 * h * (t + 1.0));
            let shape = (1.0 - x / h) * (1.0 - y / h);
            let pressure = p0 * (1.0 - (x * x + y * y) / (a * a)).max(0.0).sqrt();
            force += ws * wt * 0.25 * h * h * shape * pressure;
        }
    }
    force / (0.25 * h * h)
}

/// The case of the mesh with fine element size `h`.
pub fn case(h: f64) -> Value {
    let plan = graded_breaks(h, FINE_EXTENT * TARGET_RADIUS, SIZE);
    let depth: Vec<f64> = plan.iter().rev().map(|z| -z).collect();
    let approach = TARGET_RADIUS * TARGET_RADIUS / RADIUS;
    json!({
        "name": "hertz-3d",
        "description": "a rigid sphere pressed into a quarter block (src/harness/hertz3d.rs)",
        "materials": {"m": {"E": E, "nu": NU}},
        "bodies": [{"name": "block", "material": "m",
            "mesh": {"block3d": {"element": "Hex8", "x": plan, "y": plan, "z": depth}}}],
        "supports": [
            {"body": "block", "set": "left", "x": 0.0},
            {"body": "block", "set": "front", "y": 0.0},
            {"body": "block", "set": "bottom", "z": approach}
        ],
        "loads": [],
        "contact": [{
            "name": "sphere",
            "slave": {"body": "block", "set": "top"},
            "master": {"rigid": {"kind": "sphere", "centre": [0.0, 0.0, RADIUS], "radius": RADIUS}},
            "discretization": {"kind": "node_to_surface", "passes": 1},
            "enforcement": {"kind": "lagrange"}
        }]
    })
}

/// What one mesh measured, against the closed form at its load.
#[derive(Clone, Debug, Serialize)]
pub struct Level {
    /// Element size in the fine zone, and `a_target / h`.
    pub h: f64,
    pub elements_per_radius: f64,
    pub dofs: usize,
    pub closed_nodes: usize,
    pub active_set_iterations: usize,
    /// The prescribed approach of the bottom.
    pub approach: f64,
    /// `P = 4 sum lambda`.
    pub load: f64,
    /// Hertz at `load`: contact radius, peak pressure, half-space approach.
    pub hertz_radius: f64,
    pub hertz_peak: f64,
    pub hertz_approach: f64,
    /// Outermost closed node and the next (open) node on `y = 0`.
    pub closed_radius: f64,
    pub open_radius: f64,
    /// `(closed_radius + open_radius) / 2` and its relative error.
    pub bracket_radius: f64,
    pub bracket_radius_error: f64,
    /// The second-moment radius `sqrt(5/2 sum lambda r^2 / sum lambda)` and its relative error.
    pub moment_radius: f64,
    pub moment_radius_error: f64,
    /// `lambda / area` at the centre node; the closed form's value of the same measure
    /// ([`centre_nodal_pressure`]); the relative error against it, and against `p0`.
    pub peak: f64,
    pub hertz_nodal_peak: f64,
    pub peak_error: f64,
    pub peak_error_to_p0: f64,
    /// Nodal pressures `lambda / area` on `y = 0`: `(x, p)`, x ascending.
    pub profile: Vec<(f64, f64)>,
}

/// Solve the case of fine size `h` and measure it.
pub fn level(h: f64) -> Result<Level> {
    let case = crate::model::parse(&case(h).to_string(), "hertz-3d")?;
    let outcome = run_case3(&case, "hertz-3d")?;
    measure(h, &outcome)
}

fn measure(h: f64, outcome: &Outcome3) -> Result<Level> {
    let state = outcome
        .solution
        .contact
        .as_ref()
        .expect("the case has a contact pair");
    if !outcome.converged() {
        return Err(crate::error::Error::Solver {
            path: "hertz-3d".into(),
            problem: format!(
                "the contact solve at h = {h} ended with {:?}",
                state.termination
            ),
            hint: "this is a defect of the study's scene; report it".into(),
        });
    }
    let radius = |p: [f64; 3]| (p[0] * p[0] + p[1] * p[1]).sqrt();
    let closed: Vec<usize> = (0..state.rows.len())
        .filter(|&i| state.active[i] && state.forces[i] > 0.0)
        .collect();
    // the rows' normals point from the sphere into the block: the vertical load is -lambda n_z
    let quarter: f64 = closed
        .iter()
        .map(|&i| -state.forces[i] * state.rows[i].normal[2])
        .sum();
    let pressure_sum: f64 = closed.iter().map(|&i| state.forces[i]).sum();
    let moment: f64 = closed
        .iter()
        .map(|&i| state.forces[i] * radius(state.rows[i].point).powi(2))
        .sum();
    let load = 4.0 * quarter;
    let (hertz_radius, hertz_peak, hertz_approach) = hertz(load);
    let on_line: Vec<usize> = (0..state.rows.len())
        .filter(|&i| state.rows[i].point[1].abs() < 1e-12)
        .collect();
    let closed_radius = on_line
        .iter()
        .filter(|&&i| closed.contains(&i))
        .map(|&i| state.rows[i].point[0])
        .fold(0.0f64, f64::max);
    let open_radius = on_line
        .iter()
        .map(|&i| state.rows[i].point[0])
        .filter(|&x| x > closed_radius)
        .fold(f64::INFINITY, f64::min);
    let centre = (0..state.rows.len())
        .find(|&i| radius(state.rows[i].point) < 1e-12)
        .expect("the block's top has a node at the origin");
    let peak = state.forces[centre] / state.rows[centre].area;
    let hertz_nodal_peak = centre_nodal_pressure(hertz_radius, hertz_peak, h);
    let mut profile: Vec<(f64, f64)> = on_line
        .iter()
        .map(|&i| (state.rows[i].point[0], state.forces[i] / state.rows[i].area))
        .filter(|&(x, _)| x <= 2.0 * TARGET_RADIUS)
        .collect();
    profile.sort_by(|a, b| a.0.total_cmp(&b.0));
    let bracket_radius = 0.5 * (closed_radius + open_radius);
    let moment_radius = (2.5 * moment / pressure_sum).sqrt();
    let relative = |v: f64, exact: f64| (v - exact) / exact;
    Ok(Level {
        h,
        elements_per_radius: TARGET_RADIUS / h,
        dofs: outcome.model.dof_count,
        closed_nodes: closed.len(),
        active_set_iterations: state.iterations,
        approach: TARGET_RADIUS * TARGET_RADIUS / RADIUS,
        load,
        hertz_radius,
        hertz_peak,
        hertz_approach,
        closed_radius,
        open_radius,
        bracket_radius,
        bracket_radius_error: relative(bracket_radius, hertz_radius),
        moment_radius,
        moment_radius_error: relative(moment_radius, hertz_radius),
        peak,
        hertz_nodal_peak,
        peak_error: relative(peak, hertz_nodal_peak),
        peak_error_to_p0: relative(peak, hertz_peak),
        profile,
    })
}

/// The study: one [`Level`] per fine size.
#[derive(Clone, Debug, Serialize)]
pub struct Hertz3d {
    pub radius: f64,
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
    pub effective_modulus: f64,
    pub block_size: f64,
    pub target_radius: f64,
    pub levels: Vec<Level>,
}

/// The fine element sizes of the report: `a / 2` to `a / 8` (41 472 dofs; at `a / 16` the
/// direct factorization of 148 000 equations would take 1.9e12 multiply-adds per active-set
/// iteration, above the default work limit).
pub const REPORT_SIZES: [f64; 4] = [
    TARGET_RADIUS / 2.0,
    TARGET_RADIUS / 4.0,
    TARGET_RADIUS / 6.0,
    TARGET_RADIUS / 8.0,
];

/// Run the meshes `sizes`, coarse to fine.
pub fn study(sizes: &[f64]) -> Result<Hertz3d> {
    Ok(Hertz3d {
        radius: RADIUS,
        youngs_modulus: E,
        poisson_ratio: NU,
        effective_modulus: effective_modulus(),
        block_size: SIZE,
        target_radius: TARGET_RADIUS,
        levels: sizes.iter().map(|&h| level(h)).collect::<Result<_>>()?,
    })
}

/// The Markdown report.
pub fn report(s: &Hertz3d) -> String {
    let mut r = format!(
        "# Hertz in 3D: a rigid sphere pressed into an elastic block\n\n\
         Generated by `contact-patch hertz-3d` (do not edit by hand); the problem and the \
         measures are described in `src/harness/hertz3d.rs`. Rigid sphere R = {}, block (a \
         quarter, symmetry supports on x = 0 and y = 0) of size {} = 20 a_target (a_target = \
         {}), E = {}, nu = {}, Hex8, graded breaks (uniform h up to 1.5 a_target, then growing \
         by {GROWTH}), its bottom moved up by a_target^2 / R = {:.4}; node-to-surface rows (one \
         pass), Lagrange multipliers.\n\n\
         The closed form is Hertz's elastic sphere on a rigid plane with the same R and \
         E* = E / (1 - nu^2) = {:.4}: a = (3 P R / (4 E*))^(1/3), p0 = 3 P / (2 pi a^2), \
         delta = a^2 / R, evaluated at the measured load P = 4 sum lambda. `bracket`: the \
         outermost closed node and the next open one on y = 0 (the closed form must lie \
         between); `a (bracket)`: their midpoint; `a (moment)`: sqrt(5/2 sum lambda r^2 / \
         sum lambda); `peak`: lambda / area at the centre node, its error against the closed form's value of \
         the same measure (`int N p dA / int N dA` of Hertz's pressure over the centre node's \
         facet) and against p0. Errors are relative, signed.\n\n\
         | h | a / h | dofs | closed nodes | P | Hertz a | bracket | a (bracket), error | a (moment), error | Hertz p0 | Hertz nodal | peak, error, error to p0 |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n",
        s.radius,
        s.block_size,
        s.target_radius,
        s.youngs_modulus,
        s.poisson_ratio,
        s.target_radius * s.target_radius / s.radius,
        s.effective_modulus,
    );
    for l in &s.levels {
        r += &format!(
            "| {:.5} | {:.0} | {} | {} | {:.5e} | {:.5} | [{:.5}, {:.5}] | {:.5}, {:+.2e} | {:.5}, {:+.2e} | {:.4} | {:.4} | {:.4}, {:+.2e}, {:+.2e} |\n",
            l.h,
            l.elements_per_radius,
            l.dofs,
            l.closed_nodes,
            l.load,
            l.hertz_radius,
            l.closed_radius,
            l.open_radius,
            l.bracket_radius,
            l.bracket_radius_error,
            l.moment_radius,
            l.moment_radius_error,
            l.hertz_peak,
            l.hertz_nodal_peak,
            l.peak,
            l.peak_error,
            l.peak_error_to_p0,
        );
    }
    r += "\n**Half-space assumption.** The block's bottom is held at a depth of 20 a_target: \
          the prescribed approach is not the half-space approach of the measured load (the \
          far field of a half-space is not that of a supported block of finite size), so the \
          load is compared through a(P) and p0(P), which depend on the near field. For \
          comparison only (not a check: the block's sides and bottom are not a half-space's), \
          the half-space approach less Boussinesq's displacement of a point at the block's \
          depth L on the axis under the point load P, `u_z = P (3 - 2 nu) / (4 pi G L)` \
          (Johnson s. 3.2), estimates the approach of the bottom:\n\n\
          | h | prescribed approach | Hertz approach a^2 / R at P | a^2 / R - u_z(L) |\n|---|---|---|---|\n";
    let shear_modulus = s.youngs_modulus / (2.0 * (1.0 + s.poisson_ratio));
    for l in &s.levels {
        let far = l.load * (3.0 - 2.0 * s.poisson_ratio)
            / (4.0 * std::f64::consts::PI * shear_modulus * s.block_size);
        r += &format!(
            "| {:.5} | {:.5} | {:.5} | {:.5} |\n",
            l.h,
            l.approach,
            l.hertz_approach,
            l.hertz_approach - far
        );
    }
    r += "\n![pressure profile](hertz-3d.profile.svg)\n";
    r
}

/// The pressure profile on `y = 0` of each mesh against the closed form: `(file name, SVG)`.
pub fn plots(s: &Hertz3d) -> Vec<(String, String)> {
    let mut series: Vec<Series> = s
        .levels
        .iter()
        .map(|l| Series {
            name: format!("h = a/{:.0}", l.elements_per_radius),
            points: l.profile.clone(),
        })
        .collect();
    if let Some(finest) = s.levels.last() {
        let (a, p0) = (finest.hertz_radius, finest.hertz_peak);
        series.push(Series {
            name: "Hertz (finest P)".into(),
            points: (0..=100)
                .map(|k| {
                    let r = 2.0 * TARGET_RADIUS * k as f64 / 100.0;
                    (r, p0 * (1.0 - (r / a).powi(2)).max(0.0).sqrt())
                })
                .collect(),
        });
    }
    vec![(
        "hertz-3d.profile.svg".into(),
        line_plot(
            "Contact pressure on y = 0: nodal lambda / area against Hertz",
            "x",
            "p",
            &series,
        ),
    )]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hertz_closed_form_is_consistent() {
        // the load that gives a = 0.1: P = 4 E* a^3 / (3 R)
        let p = 4.0 * effective_modulus() * 1e-3 / (3.0 * RADIUS);
        let (a, p0, delta) = hertz(p);
        assert!((a - 0.1).abs() < 1e-14, "{a}");
        assert!((delta - 0.01).abs() < 1e-15, "{delta}");
        // P = int p dA = 2/3 pi a^2 p0
        let integral = 2.0 / 3.0 * std::f64::consts::PI * a * a * p0;
        assert!((integral - p).abs() < 1e-12 * p, "{integral} {p}");
        // p0 = 2 E* a / (pi R) (Johnson 4.23)
        let expected = 2.0 * effective_modulus() * a / (std::f64::consts::PI * RADIUS);
        assert!((p0 - expected).abs() < 1e-12 * p0);
    }

    #[test]
    fn centre_nodal_pressure_matches_its_expansion() {
        // sqrt(1 - u) = 1 - u/2 - u^2/8 - O(u^3), u = r^2 / a^2; under the weight N / int N
        // on [0, h]^2, E[x^2] = h^2 / 6, E[x^4] = h^4 / 15, so E[u] = h^2 / (3 a^2) and
        // E[u^2] = (2/15 + 2/36) h^4 / a^4 = 17/90 (h / a)^4
        let (a, p0) = (0.1, 2.0);
        for (h, tol) in [(0.01, 1e-7), (0.001, 1e-12)] {
            let nodal = centre_nodal_pressure(a, p0, h);
            let u1 = h * h / (3.0 * a * a);
            let u2 = 17.0 / 90.0 * (h / a).powi(4);
            let expansion = p0 * (1.0 - u1 / 2.0 - u2 / 8.0);
            assert!((nodal - expansion).abs() < tol, "{h}: {nodal} {expansion}");
        }
    }

    #[test]
    fn graded_breaks_are_uniform_then_grow_to_the_length() {
        let b = graded_breaks(0.05, 0.15, 2.0);
        assert_eq!(&b[..4], &[0.0, 0.05, 0.1, 0.15000000000000002]);
        assert_eq!(*b.last().unwrap(), 2.0);
        for w in b.windows(3) {
            let (first, second) = (w[1] - w[0], w[2] - w[1]);
            assert!(second > 0.0);
            assert!(second <= GROWTH * first * (1.0 + 1e-12) + 1e-15 || w[2] == 2.0);
        }
    }
}
