//! The pressure profile of one contact pair (`contact-patch profile`): the nodal pressures of
//! the pair's slave surface ([`crate::contact::results`], what `<pair>.contact.csv` holds),
//! against Hertz's closed form when the master is a rigid circle.
//!
//! Hertz (`HertzCylinder` of the crate's `harness::exact`, half-space, rigid indenter): the load `P` is
//! the pair's normal force per unit thickness (`sum_a p_a A_a / t`), `R` the circle's radius,
//! `E*` from the slave body's material (`E/(1 - nu^2)` in plane strain, `E` in plane stress).
//! Points are placed by `s = (X - c) . t`, `c` the circle's centre and `t` the unit tangent
//! `(d_y, -d_x)` to the direction `d` from `c` to the slave node of largest pressure (for a
//! circle below a flat face, `s = x - c_x`).
//!
//! Reported: `a`, `p0`, and the largest `|p_a - p(s_a)| / p0` over the measured points with
//! `|s| <= 0.8 a` (away from the edges of the contact zone, where the nodal pressure of a
//! tributary area cannot follow the square-root fall to zero) and over all of them.

use crate::contact::results::{pair_results, PointStatus, Side};
use crate::error::{Error, Result};
use crate::harness::exact::HertzCylinder;
use crate::io::paths::{file_name, ReportFolder};
use crate::io::scene::RigidSurface;
use crate::io::svg::{line_plot, Series};
use crate::model::MasterSide;
use crate::run::Outcome;

/// The share of the Hertz half-width inside which the profile is compared.
pub const INTERIOR_SHARE: f64 = 0.8;

/// A pair's pressure profile and, against a rigid circle, Hertz's.
#[derive(Clone, Debug)]
pub struct Profile {
    pub case: String,
    pub pair: String,
    /// `(s, p)` of the measured slave points, by `s`.
    pub points: Vec<(f64, f64)>,
    /// The status of each point (same order).
    pub closed: Vec<bool>,
    pub hertz: Option<HertzCylinder>,
}

impl Profile {
    /// `max |p - p_H| / p0` over the points with `|s| <= share a` (`None` without Hertz).
    pub fn deviation(&self, share: f64) -> Option<f64> {
        let h = self.hertz?;
        let (a, p0) = (h.half_width(), h.peak());
        Some(
            self.points
                .iter()
                .filter(|(s, _)| s.abs() <= share * a)
                .fold(0.0f64, |m, &(s, p)| m.max((p - h.pressure(s)).abs() / p0)),
        )
    }

    /// The points plotted and tabulated: those with `|s|` up to twice the larger of Hertz's
    /// half-width and the contact extent (all points when nothing is closed).
    pub fn shown(&self) -> Vec<(f64, f64)> {
        let reach = 2.0
            * self
                .contact_extent()
                .max(self.hertz.map_or(0.0, |h| h.half_width()));
        self.points
            .iter()
            .copied()
            .filter(|(s, _)| reach == 0.0 || s.abs() <= reach)
            .collect()
    }

    /// The largest `|s|` of a closed point.
    pub fn contact_extent(&self) -> f64 {
        self.points
            .iter()
            .zip(&self.closed)
            .filter(|(_, &c)| c)
            .fold(0.0f64, |m, (&(s, _), _)| m.max(s.abs()))
    }
}

/// The profile of pair `pair` in `outcome`.
pub fn pressure_profile(outcome: &Outcome, pair: &str) -> Result<Profile> {
    let model = &outcome.model;
    let names: Vec<&str> = model.contact.iter().map(|p| p.name.as_str()).collect();
    let Some(k) = names.iter().position(|n| *n == pair) else {
        return Err(Error::invalid(
            &model.source,
            "--pair",
            format!("names no contact pair of the case: '{pair}'"),
            format!("name one of: {}", names.join(", ")),
        ));
    };
    let state = outcome.solution.contact.as_ref().ok_or_else(|| {
        Error::invalid(
            &model.source,
            "the case",
            "has no contact solution",
            "profile needs a case with contact pairs",
        )
    })?;
    let results = pair_results(model, state, &outcome.solution.u);
    let r = &results[k];
    let slave: Vec<_> = r
        .points
        .iter()
        .filter(|p| p.side == Side::Slave && p.status != PointStatus::Unmeasured)
        .collect();
    let (place, hertz): (Box<dyn Fn([f64; 2]) -> f64>, _) = match &model.contact[k].master {
        MasterSide::Rigid(RigidSurface::Circle { centre, radius }) => {
            let top = slave
                .iter()
                .max_by(|a, b| a.pressure.total_cmp(&b.pressure))
                .map(|p| p.x)
                .unwrap_or([centre[0], centre[1] + radius]);
            let d = [top[0] - centre[0], top[1] - centre[1]];
            let l = d[0].hypot(d[1]).max(f64::MIN_POSITIVE);
            let t = [d[1] / l, -d[0] / l];
            let c = *centre;
            let body = &model.bodies[model.contact[k].slave.0];
            let hertz = HertzCylinder {
                load: r.totals.normal_force / model.thickness,
                radius: *radius,
                modulus: body.material.plane_stress_equivalent().0,
            };
            (
                Box::new(move |x: [f64; 2]| (x[0] - c[0]) * t[0] + (x[1] - c[1]) * t[1]),
                Some(hertz),
            )
        }
        _ => (Box::new(|x: [f64; 2]| x[0]), None),
    };
    let mut rows: Vec<(f64, f64, bool)> = slave
        .iter()
        .map(|p| (place(p.x), p.pressure, p.status > PointStatus::Open))
        .collect();
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(Profile {
        case: model.name.clone(),
        pair: pair.to_string(),
        points: rows.iter().map(|r| (r.0, r.1)).collect(),
        closed: rows.iter().map(|r| r.2).collect(),
        hertz,
    })
}

/// Write `<case>.<pair>.pressure.svg` and `.md` into `folder`; returns the file names.
pub fn write_profile(folder: &ReportFolder, profile: &Profile) -> Result<[String; 2]> {
    let stem = file_name(
        "case and pair name",
        &format!("{}.{}", profile.case, profile.pair),
        ".pressure",
    )?;
    let (svg, md) = (format!("{stem}.svg"), format!("{stem}.md"));
    let shown = profile.shown();
    let mut series = vec![Series {
        name: "nodal pressure".into(),
        points: shown.clone(),
    }];
    if let Some(h) = profile.hertz {
        let (lo, hi) = shown
            .iter()
            .fold((0.0f64, 0.0f64), |(lo, hi), p| (lo.min(p.0), hi.max(p.0)));
        let n = 200;
        series.push(Series {
            name: "Hertz".into(),
            points: (0..=n)
                .map(|i| {
                    let s = lo + (hi - lo) * i as f64 / n as f64;
                    (s, h.pressure(s))
                })
                .collect(),
        });
    }
    let title = format!("{}: contact pressure of '{}'", profile.case, profile.pair);
    folder.write_file(&svg, &line_plot(&title, "s", "pressure", &series))?;
    folder.write_file(&md, &markdown(profile, &shown, &svg))?;
    Ok([svg, md])
}

fn markdown(profile: &Profile, shown: &[(f64, f64)], svg: &str) -> String {
    let mut s = format!(
        "# Contact pressure of '{}' in case '{}'\n\nWritten by `contact-patch profile`: the nodal \
         pressures `-f_a . n_a / A_a` of the slave surface (the `pressure` column of \
         `{}.contact.csv` in a run folder), by position `s` along the surface, within twice \
         the contact zone's half-width.\n\n![profile]({svg})\n\n",
        profile.pair, profile.case, profile.pair
    );
    if let Some(h) = profile.hertz {
        let (a, p0) = (h.half_width(), h.peak());
        s += &format!(
            "Hertz (rigid cylinder on a half-space): P = {:.6} per unit thickness, R = {}, \
             E* = {:.6}: a = {a:.6}, p0 = {p0:.6}.\n\n\
             - largest |p - p_Hertz| / p0 with |s| <= {INTERIOR_SHARE} a: {:.3e}\n\
             - largest |p - p_Hertz| / p0 over all points: {:.3e}\n\
             - outermost closed point: |s| = {:.6} (a = {a:.6})\n\n",
            h.load,
            h.radius,
            h.modulus,
            profile.deviation(INTERIOR_SHARE).unwrap_or(f64::NAN),
            profile.deviation(f64::INFINITY).unwrap_or(f64::NAN),
            profile.contact_extent(),
        );
        s += "| s | pressure | Hertz | difference / p0 |\n|---|---|---|---|\n";
        for &(x, p) in shown {
            let e = h.pressure(x);
            s += &format!("| {x:.6} | {p:.6} | {e:.6} | {:.3e} |\n", (p - e) / p0);
        }
    } else {
        s += "No closed form for this pair (Hertz applies to a rigid circle master).\n\n\
              | s | pressure |\n|---|---|\n";
        for &(x, p) in shown {
            s += &format!("| {x:.6} | {p:.6} |\n");
        }
    }
    s
}
