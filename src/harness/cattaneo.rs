//! The Cattaneo-Mindlin study (`contact-patch cattaneo`): a cylinder pressed by `P`, then sheared
//! by `Q < mu P`, measured against the closed forms under mesh refinement.
//!
//! Closed forms (plane strain, elastically similar bodies so that Dundurs' `beta = 0` and the
//! normal and tangential problems uncouple; Johnson, *Contact Mechanics*, 1985, sections 4.3,
//! 7.1; Hills & Nowell, *Mechanics of Fretting Fatigue*, 1994, chapter 3):
//!
//! ```text
//! Hertz:     1/E* = sum_bodies (1 - nu^2)/E,  a = sqrt(4 P R / (pi E*)),  p0 = 2 P / (pi a)
//!            p(s) = p0 sqrt(1 - s^2/a^2)
//! Cattaneo:  c = a sqrt(1 - |Q| / (mu P))   (stick zone |s| < c)
//!            q(s) = sign(Q) mu p0 [sqrt(1 - s^2/a^2) - (c/a) sqrt(1 - s^2/c^2)]   |s| < c
//!            q(s) = sign(Q) mu p(s)                                             c <= |s| < a
//! Dundurs:   beta = [G1 (k2 - 1) - G2 (k1 - 1)] / [G1 (k2 + 1) + G2 (k1 + 1)],
//!            k = 3 - 4 nu (plane strain), (3 - nu)/(1 + nu) (plane stress)
//! ```
//!
//! Measured per run, on the pair's first-pass slave surface, in the frame of the master surface
//! where the slave is pressed hardest (a body's facets, or a rigid line), with `n` the master's
//! unit normal there (towards the slave) and `t = (n_y, -n_x)`:
//!
//! * `p_a = f_a . n / A'_a`, `q_a = f_a . t / A'_a`: the nodal contact force `f_a` of
//!   [`crate::contact::results`] per projected tributary area `A'_a = A_a |n_a . n|` (the closed
//!   forms are tractions on the plane of the half-space);
//! * `P = sum f_a . n / thickness`, `Q = sum f_a . t / thickness`, and the tangential force the
//!   slave body's supports carry, `Q_s = -sum_d r_d t_d / thickness` over its prescribed dofs
//!   (`r = K u - f`, the reactions; equal to `Q` when the slave body carries no other load);
//! * positions `s_a = X_a . t - s0`, `s0` the pressure centroid `sum f_a . n X_a . t / sum f_a . n`;
//! * `R`: Hertz's radius of the gap, `1/R = 1/R_s + 1/R_m`, each face's curvature from the
//!   least-squares fit `X_a . n = h0 + s^2 / (2 R_face)` (signed; the master's is negative for a
//!   face convex towards the slave) over its points with `|s|` up to the outermost closed point
//!   (a rigid line: `1/R_m = 0`);
//! * the contact and stick half-widths `a_h`, `c_h`: on each side, the midpoint between the
//!   outermost closed (stick) point and the next point outward, averaged over the two sides
//!   (the boundary lies between two nodes, so `|c_h - c| <= h/2` plus the solution error);
//! * errors against the closed forms over `|s| <= a`: `||q_h - q|| / ||q||` and
//!   `||p_h - p|| / ||p||` (discrete L2, weights `A'_a`); the same for `p` over `|s| <= 0.8 a`
//!   (the edge nodes depend on where `a` falls between two nodes) and for `q` away from the
//!   stick/slip boundary (`||s| - c| > 2 h`: `q` has a cusp at `c`, and the nodes next to it
//!   depend on where `c` falls); the part of `q_h` odd in `s`
//!   (`||(q_h(s) - q_h(-s))/2|| / ||q||` over the points with a point within `h/20` of `-s`:
//!   zero in the closed form),
//!   and the largest Coulomb ratio `|q_a| / (mu p_a)`.

use crate::contact::results::{pair_results, PointStatus, Side};
use crate::error::{Error, Result};
use crate::harness::exact::HertzCylinder;
use crate::io::paths::ReportFolder;
use crate::io::scene::{Plane, RigidSurface};
use crate::io::svg::{line_plot, Series};
use crate::model::{MasterSide, Model};
use crate::run::Outcome;
use crate::solid::Elasticity;
use serde::Serialize;

/// Hertz's pressure and Cattaneo-Mindlin's shear traction for given `P`, `Q`, `mu`, `R`, `E*`.
#[derive(Copy, Clone, Debug, PartialEq, Serialize)]
pub struct CattaneoMindlin {
    /// Normal load per unit thickness `P`.
    pub load: f64,
    /// Tangential load per unit thickness `Q` (signed along `t`).
    pub shear: f64,
    pub mu: f64,
    pub radius: f64,
    /// `E*`.
    pub modulus: f64,
}

impl CattaneoMindlin {
    fn hertz(&self) -> HertzCylinder {
        HertzCylinder {
            load: self.load,
            radius: self.radius,
            modulus: self.modulus,
        }
    }

    /// The contact half-width `a`.
    pub fn half_width(&self) -> f64 {
        self.hertz().half_width()
    }

    /// The peak pressure `p0`.
    pub fn peak(&self) -> f64 {
        self.hertz().peak()
    }

    /// The stick half-width `c = a sqrt(1 - |Q|/(mu P))` (0 when `|Q| >= mu P`).
    pub fn stick_half_width(&self) -> f64 {
        self.half_width()
            * (1.0 - self.shear.abs() / (self.mu * self.load))
                .max(0.0)
                .sqrt()
    }

    /// Hertz's `p(s)`.
    pub fn pressure(&self, s: f64) -> f64 {
        self.hertz().pressure(s)
    }

    /// Cattaneo-Mindlin's `q(s)`, with the sign of `Q`.
    pub fn traction(&self, s: f64) -> f64 {
        let (a, c, p0) = (self.half_width(), self.stick_half_width(), self.peak());
        let mut q = self.mu * self.pressure(s);
        if s.abs() < c {
            q -= self.mu * p0 * (c / a) * (1.0 - (s / c).powi(2)).sqrt();
        }
        q * self.shear.signum()
    }
}

/// Dundurs' second parameter `beta` of two materials (`None` for the second: rigid).
pub fn dundurs_beta(one: &Elasticity, two: Option<&Elasticity>) -> f64 {
    let kolosov = |m: &Elasticity| match m.plane() {
        Plane::Strain => 3.0 - 4.0 * m.nu,
        Plane::Stress => (3.0 - m.nu) / (1.0 + m.nu),
    };
    let shear_modulus = |m: &Elasticity| m.youngs_modulus / (2.0 * (1.0 + m.nu));
    let (g1, k1) = (shear_modulus(one), kolosov(one));
    match two {
        // G2 -> infinity
        None => -(k1 - 1.0) / (k1 + 1.0),
        Some(m) => {
            let (g2, k2) = (shear_modulus(m), kolosov(m));
            (g1 * (k2 - 1.0) - g2 * (k1 - 1.0)) / (g1 * (k2 + 1.0) + g2 * (k1 + 1.0))
        }
    }
}

/// One measured point of the interface.
#[derive(Clone, Debug, Serialize)]
pub struct InterfacePoint {
    pub s: f64,
    pub pressure: f64,
    pub traction: f64,
    /// Projected tributary area `A'_a`.
    pub area: f64,
    pub status: PointStatus,
}

/// What one run of a Cattaneo-Mindlin case measured.
#[derive(Clone, Debug, Serialize)]
pub struct CattaneoLevel {
    pub case: String,
    pub pair: String,
    /// The largest spacing of adjacent slave points within the contact zone.
    pub spacing: f64,
    /// Dundurs' beta of the pair (0 for the closed form to hold).
    pub dundurs_beta: f64,
    /// The closed forms with the measured `P`, `Q` and the fitted `R`.
    pub closed_form: CattaneoMindlin,
    pub half_width: f64,
    pub peak: f64,
    pub stick_half_width: f64,
    /// Tangential force of the slave body's supports, `Q_s`.
    pub support_shear: f64,
    pub measured_half_width: f64,
    pub measured_stick_half_width: f64,
    /// The two ends of the central stick zone (`s`).
    pub stick_ends: [f64; 2],
    pub traction_error: f64,
    pub pressure_error: f64,
    /// `||p_h - p|| / ||p||` over `|s| <= 0.8 a` (away from the edges of the contact zone).
    pub pressure_error_interior: f64,
    /// `||q_h - q|| / ||q||` over the points of `|s| <= a` farther than `2 h` from `|s| = c`
    /// (away from the cusp of `q` at the stick/slip boundary).
    pub traction_error_off_boundary: f64,
    pub odd_traction: f64,
    pub max_cone_ratio: f64,
    pub points: Vec<InterfacePoint>,
}

fn refuse(model: &Model, what: impl std::fmt::Display, hint: impl std::fmt::Display) -> Error {
    Error::invalid(&model.source, "--pair", what, hint)
}

/// Measure pair `pair` of `outcome` (see the module notes).
pub fn measure(outcome: &Outcome, pair: &str) -> Result<CattaneoLevel> {
    let model = &outcome.model;
    let names: Vec<&str> = model.contact.iter().map(|p| p.name.as_str()).collect();
    let Some(k) = names.iter().position(|n| *n == pair) else {
        return Err(refuse(
            model,
            format!("names no contact pair of the case: '{pair}'"),
            format!("name one of: {}", names.join(", ")),
        ));
    };
    let spec = &model.contact[k];
    let Some(mu) = spec.interaction.friction() else {
        return Err(refuse(
            model,
            format!("pair '{pair}' has no Coulomb friction"),
            "give the pair `interaction: {\"coulomb\": {\"mu\": ..}}`",
        ));
    };
    let state = outcome.solution.contact.as_ref().ok_or_else(|| {
        refuse(
            model,
            "the case has no contact solution",
            "cattaneo needs a case with a frictional contact pair",
        )
    })?;
    let results = pair_results(model, state, &outcome.solution.u);
    let r = &results[k];
    let slave_body = &model.bodies[spec.slave.0];
    let slave: Vec<_> = r
        .points
        .iter()
        .filter(|p| p.side == Side::Slave && p.status != PointStatus::Unmeasured)
        .collect();
    let master: Vec<_> = r.points.iter().filter(|p| p.side == Side::Master).collect();
    // the frame: the master's normal where the slave is pressed hardest
    let top = slave
        .iter()
        .max_by(|a, b| a.pressure.total_cmp(&b.pressure))
        .ok_or_else(|| refuse(model, format!("pair '{pair}' has no slave points"), ""))?;
    let distance = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    let (normal, master_material) = match &spec.master {
        MasterSide::Rigid(RigidSurface::Line { normal, .. }) => {
            let l = normal[0].hypot(normal[1]);
            ([normal[0] / l, normal[1] / l], None)
        }
        MasterSide::Rigid(
            RigidSurface::Circle { .. } | RigidSurface::Plane { .. } | RigidSurface::Sphere { .. },
        ) => {
            return Err(refuse(
                model,
                format!("pair '{pair}' has a rigid circle master"),
                "cattaneo measures two bodies (or a body on a rigid line) whose profiles \
                 together make Hertz's gap s^2 / (2 R)",
            ))
        }
        MasterSide::Body { body, .. } => {
            let facing = master
                .iter()
                .min_by(|a, b| distance(a.x, top.x).total_cmp(&distance(b.x, top.x)))
                .ok_or_else(|| refuse(model, format!("pair '{pair}' has no master points"), ""))?;
            (facing.normal, Some(&model.bodies[*body].material))
        }
    };
    let tangent = [normal[1], -normal[0]];
    let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
    let t = model.thickness;
    let load: f64 = slave.iter().map(|p| dot(p.force, normal)).sum::<f64>() / t;
    let shear: f64 = slave.iter().map(|p| dot(p.force, tangent)).sum::<f64>() / t;
    if load.is_nan() || load <= 0.0 {
        return Err(refuse(
            model,
            format!("pair '{pair}' carries no normal load"),
            "press the bodies together",
        ));
    }
    let s0 = slave
        .iter()
        .map(|p| dot(p.force, normal) * dot(p.x, tangent))
        .sum::<f64>()
        / (load * t);
    let mut points: Vec<InterfacePoint> = slave
        .iter()
        .map(|p| {
            let area = p.area * dot(p.normal, normal).abs();
            InterfacePoint {
                s: dot(p.x, tangent) - s0,
                pressure: dot(p.force, normal) / area,
                traction: dot(p.force, tangent) / area,
                area,
                status: p.status,
            }
        })
        .collect();
    points.sort_by(|a, b| a.s.total_cmp(&b.s));
    let closed = |p: &InterfacePoint| p.status > PointStatus::Open;
    // the gap profile: the curvature of each face over the closed zone, by least squares of
    // the height along n against s^2 (a rigid line has none)
    let closed_reach = slave
        .iter()
        .filter(|p| p.status > PointStatus::Open)
        .fold(0.0f64, |m, p| m.max((dot(p.x, tangent) - s0).abs()));
    let curvature_of = |face: &[&crate::contact::results::ContactPoint]| {
        let heights: Vec<(f64, f64)> = face
            .iter()
            .map(|p| ((dot(p.x, tangent) - s0).powi(2), dot(p.x, normal)))
            .filter(|(s2, _)| s2.sqrt() <= closed_reach)
            .collect();
        let n = heights.len() as f64;
        let (sx, sy) = heights
            .iter()
            .fold((0.0, 0.0), |(a, b), &(x, y)| (a + x, b + y));
        let (sxx, sxy) = heights
            .iter()
            .fold((0.0, 0.0), |(a, b), &(x, y)| (a + x * x, b + x * y));
        if heights.len() < 3 {
            f64::NAN
        } else {
            (n * sxy - sx * sy) / (n * sxx - sx * sx)
        }
    };
    let curvature = curvature_of(&slave)
        - if master_material.is_some() {
            curvature_of(&master)
        } else {
            0.0
        };
    if curvature.is_nan() || curvature <= 0.0 {
        return Err(refuse(
            model,
            format!("the faces of pair '{pair}' do not open a gap s^2 / (2 R) around the contact"),
            "cattaneo needs convex (cylindrical) faces with at least three closed points",
        ));
    }
    let modulus = 1.0
        / (1.0 / slave_body.material.plane_stress_equivalent().0
            + master_material.map_or(0.0, |m| 1.0 / m.plane_stress_equivalent().0));
    let closed_form = CattaneoMindlin {
        load,
        shear,
        mu,
        radius: 1.0 / (2.0 * curvature),
        modulus,
    };
    let (a, c) = (closed_form.half_width(), closed_form.stick_half_width());
    let spacing = points
        .windows(2)
        .filter(|w| w[0].s.abs() <= a && w[1].s.abs() <= a)
        .fold(0.0f64, |m, w| m.max(w[1].s - w[0].s));
    let zone = |inside: &dyn Fn(&InterfacePoint) -> bool| -> ([f64; 2], f64) {
        // the run of `inside` points through the one nearest s = 0
        let centre = points
            .iter()
            .enumerate()
            .min_by(|x, y| x.1.s.abs().total_cmp(&y.1.s.abs()))
            .map_or(0, |(i, _)| i);
        if !inside(&points[centre]) {
            return ([0.0, 0.0], 0.0);
        }
        let (mut lo, mut hi) = (centre, centre);
        while lo > 0 && inside(&points[lo - 1]) {
            lo -= 1;
        }
        while hi + 1 < points.len() && inside(&points[hi + 1]) {
            hi += 1;
        }
        let left = if lo > 0 {
            0.5 * (points[lo].s + points[lo - 1].s)
        } else {
            points[lo].s
        };
        let right = if hi + 1 < points.len() {
            0.5 * (points[hi].s + points[hi + 1].s)
        } else {
            points[hi].s
        };
        ([points[lo].s, points[hi].s], 0.5 * (right - left))
    };
    let (_, measured_half_width) = zone(&closed);
    let (stick_ends, measured_stick_half_width) =
        zone(&|p: &InterfacePoint| p.status == PointStatus::Stick);
    let norm_over = |keep: &dyn Fn(f64) -> bool, f: &dyn Fn(&InterfacePoint) -> f64| {
        points
            .iter()
            .filter(|p| keep(p.s))
            .map(|p| f(p).powi(2) * p.area)
            .sum::<f64>()
            .sqrt()
    };
    let relative = |keep: &dyn Fn(f64) -> bool, exact: &dyn Fn(f64) -> f64, pressure: bool| {
        let value = |p: &InterfacePoint| if pressure { p.pressure } else { p.traction };
        norm_over(keep, &|p| value(p) - exact(p.s)) / norm_over(keep, &|p| exact(p.s))
    };
    let traction = |s: f64| closed_form.traction(s);
    let pressure = |s: f64| closed_form.pressure(s);
    let in_zone = |s: f64| s.abs() <= a;
    let traction_error = relative(&in_zone, &traction, false);
    let pressure_error = relative(&in_zone, &pressure, true);
    let pressure_error_interior = relative(&|s: f64| s.abs() <= 0.8 * a, &pressure, true);
    let traction_error_off_boundary = relative(
        &|s: f64| s.abs() <= a && (s.abs() - c).abs() > 2.0 * spacing,
        &traction,
        false,
    );
    let norm = |f: &dyn Fn(&InterfacePoint) -> f64| norm_over(&in_zone, f);
    // the odd part of q where a point faces a point about s = 0 (within h / 20: s0 moves a
    // little under the shear)
    let mirror = |p: &InterfacePoint| {
        points
            .iter()
            .find(|m| (m.s + p.s).abs() <= 0.05 * spacing.max(f64::MIN_POSITIVE))
    };
    let odd_traction = points
        .iter()
        .filter(|p| p.s.abs() <= a)
        .filter_map(|p| mirror(p).map(|m| (0.5 * (p.traction - m.traction)).powi(2) * p.area))
        .sum::<f64>()
        .sqrt()
        / norm(&|p| closed_form.traction(p.s));
    let max_cone_ratio = points
        .iter()
        .filter(|p| closed(p) && p.pressure > 0.0)
        .fold(0.0f64, |m, p| m.max(p.traction.abs() / (mu * p.pressure)));
    // the slave body's supports
    let support_shear = -(0..slave_body.mesh.nodes.len())
        .flat_map(|node| (0..2).map(move |c| (node, c)))
        .filter(|&(node, c)| model.prescribed[slave_body.dof(node, c)].is_some())
        .map(|(node, c)| outcome.solution.reactions[slave_body.dof(node, c)] * tangent[c])
        .sum::<f64>()
        / t;
    Ok(CattaneoLevel {
        case: model.name.clone(),
        pair: pair.to_string(),
        spacing,
        dundurs_beta: dundurs_beta(&slave_body.material, master_material),
        closed_form,
        half_width: a,
        peak: closed_form.peak(),
        stick_half_width: c,
        support_shear,
        measured_half_width,
        measured_stick_half_width,
        stick_ends,
        traction_error,
        pressure_error,
        pressure_error_interior,
        traction_error_off_boundary,
        odd_traction,
        max_cone_ratio,
        points,
    })
}

/// The file names the study writes.
pub const REPORT_FILES: [&str; 3] = [
    "cattaneo-mindlin.md",
    "cattaneo-mindlin.json",
    "cattaneo-mindlin.svg",
];

/// Write `cattaneo-mindlin.md/.json/.svg` into `folder` (the plot shows the last level).
pub fn write_report(folder: &ReportFolder, levels: &[CattaneoLevel]) -> Result<()> {
    let Some(last) = levels.last() else {
        return Ok(());
    };
    let cf = last.closed_form;
    let sign = cf.shear.signum();
    let shown: Vec<&InterfacePoint> = last
        .points
        .iter()
        .filter(|p| p.s.abs() <= 1.25 * last.half_width)
        .collect();
    let n = 400;
    let reach = 1.25 * last.half_width;
    let curve = |f: &dyn Fn(f64) -> f64| {
        (0..=n)
            .map(|i| {
                let s = -reach + 2.0 * reach * i as f64 / n as f64;
                (s, f(s))
            })
            .collect::<Vec<_>>()
    };
    let series = vec![
        Series {
            name: "q (nodal)".into(),
            points: shown.iter().map(|p| (p.s, sign * p.traction)).collect(),
        },
        Series {
            name: "mu p (nodal)".into(),
            points: shown.iter().map(|p| (p.s, cf.mu * p.pressure)).collect(),
        },
        Series {
            name: "q closed form".into(),
            points: curve(&|s| sign * cf.traction(s)),
        },
        Series {
            name: "mu p Hertz".into(),
            points: curve(&|s| cf.mu * cf.pressure(s)),
        },
    ];
    let title = format!("{}: shear traction and mu p along the contact", last.case);
    folder.write_file(
        REPORT_FILES[2],
        &line_plot(&title, "s", "traction (along Q)", &series),
    )?;
    folder.write_file(REPORT_FILES[0], &markdown(levels))?;
    let json = serde_json::to_string_pretty(levels).expect("levels serialize") + "\n";
    folder.write_file(REPORT_FILES[1], &json)
}

fn markdown(levels: &[CattaneoLevel]) -> String {
    let mut s = String::from(
        "# Cattaneo-Mindlin: a cylinder pressed by P, then sheared by Q < mu P\n\n\
         Written by `contact-patch cattaneo` (src/harness/cattaneo.rs, whose notes give every \
         formula). Per level: the spacing h at the contact, Dundurs' beta (0: the closed form \
         applies), the measured loads P and Q (contact forces) and Q_s (the slave body's \
         supports), the fitted radius R, Hertz's a and the stick half-width \
         c = a sqrt(1 - Q/(mu P)) with the measured a_h and c_h (midpoints between the last \
         closed/stick point and the next one), the discrete L2 errors of q and p against the \
         closed forms over |s| <= a (and of p over |s| <= 0.8 a, of q farther than 2 h from \
         |s| = c), the odd part of q (zero in the closed form), and the largest |q|/(mu p).\n\n\
         | case | h | beta | P | Q | Q_s | R | a | a_h | c | c_h | stick ends | (c_h - c)/h | q error | q error off c | p error | p error 0.8 a | odd q | max \\|q\\|/(mu p) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for l in levels {
        let cf = l.closed_form;
        s += &format!(
            "| {} | {:.4} | {:.1e} | {:.6} | {:.6} | {:.6} | {:.4} | {:.5} | {:.5} | {:.5} | {:.5} | [{:.4}, {:.4}] | {:+.2} | {:.3e} | {:.3e} | {:.3e} | {:.3e} | {:.3e} | {:.12} |\n",
            l.case,
            l.spacing,
            l.dundurs_beta,
            cf.load,
            cf.shear,
            l.support_shear,
            cf.radius,
            l.half_width,
            l.measured_half_width,
            l.stick_half_width,
            l.measured_stick_half_width,
            l.stick_ends[0],
            l.stick_ends[1],
            (l.measured_stick_half_width - l.stick_half_width) / l.spacing,
            l.traction_error,
            l.traction_error_off_boundary,
            l.pressure_error,
            l.pressure_error_interior,
            l.odd_traction,
            l.max_cone_ratio,
        );
    }
    if let Some(last) = levels.last() {
        s += &format!(
            "\n![q and mu p of {}]({})\n\nThe plot: the finest level's nodal q (in the \
             direction of Q) and mu p against the closed forms.\n",
            last.case, REPORT_FILES[2]
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn example() -> CattaneoMindlin {
        // benchmarks.md section 3: R = 4 (two cylinders of radius 8), E = 200, nu = 0.3, P = 10
        CattaneoMindlin {
            load: 10.0,
            shear: -1.5,
            mu: 0.3,
            radius: 4.0,
            modulus: 1.0 / (2.0 * (1.0 - 0.09) / 200.0),
        }
    }

    #[test]
    fn hertz_numbers_of_the_benchmark_sheet() {
        let cf = example();
        assert!((cf.half_width() - 0.6808).abs() < 5e-5);
        assert!((cf.peak() - 9.351).abs() < 5e-4);
        // c = a sqrt(1 - 1.5/3)
        assert!((cf.stick_half_width() - cf.half_width() * 0.5f64.sqrt()).abs() < 1e-15);
    }

    /// The shear traction integrates to Q, is continuous at c, equals mu p in the slip zone and
    /// stays inside the cone (midpoint rule on a fine grid; q is bounded, its slope singular only
    /// at the two edges).
    #[test]
    fn traction_integrates_to_q_and_meets_mu_p_at_c() {
        let cf = example();
        let (a, c) = (cf.half_width(), cf.stick_half_width());
        let n = 400_000;
        let ds = 2.0 * a / n as f64;
        let total: f64 = (0..n)
            .map(|i| cf.traction(-a + (i as f64 + 0.5) * ds) * ds)
            .sum();
        assert!((total - cf.shear).abs() < 1e-6 * cf.shear.abs(), "{total}");
        let jump = cf.traction(c * (1.0 - 1e-12)) - cf.traction(c * (1.0 + 1e-12));
        assert!(jump.abs() < 1e-5, "{jump}");
        for i in 0..=1000 {
            let s = -a + 2.0 * a * i as f64 / 1000.0;
            assert!(cf.traction(s).abs() <= cf.mu * cf.pressure(s) + 1e-14);
            if s.abs() >= c {
                assert_eq!(cf.traction(s), -cf.mu * cf.pressure(s));
            }
        }
    }

    #[test]
    fn dundurs_beta_vanishes_for_similar_bodies_and_not_on_a_rigid_flat() {
        let m = Elasticity::new(200.0, 0.3, Plane::Strain);
        assert_eq!(dundurs_beta(&m, Some(&m)), 0.0);
        // rigid master: |beta| = (1 - 2 nu) / (2 (1 - nu))
        let b = dundurs_beta(&m, None);
        assert!((b.abs() - 0.4 / 1.4).abs() < 1e-15, "{b}");
        let incompressible = Elasticity::new(200.0, 0.5, Plane::Strain);
        assert_eq!(dundurs_beta(&incompressible, None), 0.0);
    }
}
