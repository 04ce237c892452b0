//! Judging another code's results of a 3D case (`contact-patch judge` on a case with `block3d`
//! bodies; issue 13): the 3D side of [`crate::harness::judge`].
//!
//! The case is validated into a [`Model3`] by [`crate::run3d::build3`] (what it refuses is
//! refused here too). The results are a `.vtu` file with every body, or a folder with one
//! `<body>.vtu` per body ([`load_results_of`]). Each node of each body is matched to the result
//! point within `delta = share * L` of it in space (`L` the model size); a node with no point
//! that close, or with two points that close carrying different displacements, is an error
//! that names the node. The matched `displacement` (3 components) gives the global vector `u`,
//! and the case's `uniform_stress_3d` checks are judged (a `max_penetration` check, which needs
//! our contact rows, is listed as not judged):
//!
//! * from `u` with our element kinematics, exactly as the run judges them
//!   ([`crate::run3d::uniform_stress_check3`]: the largest difference over the quadrature
//!   points of the stiffness rule and the six components, relative to the largest expected
//!   component), so that the same field gives the same error;
//! * when the results carry a point field `stress` (`xx, yy, zz, yz, xz, xy`, or a symmetric
//!   3x3 tensor row by row), the same measure over the matched points of that field (the
//!   results' own nodal stress).

use crate::error::{Error, Result};
use crate::harness::checks::CheckResult;
use crate::harness::judge::NotJudged;
use crate::harness::outside_results::{
    field, load_results_of, Results, DISPLACEMENT_FIELD, STRESS_FIELD,
};
use crate::io::scene::Check;
use crate::model::Model3;
use crate::run3d::{uniform_stress_check3, uniform_stress_words3};
use std::collections::HashMap;
use std::path::Path;

/// What `judge` found on a 3D case.
#[derive(Clone, Debug)]
pub struct Judgement3 {
    /// Judged checks, in the case's order, then the results-stress checks.
    pub checks: Vec<CheckResult>,
    pub not_judged: Vec<NotJudged>,
    /// Whether the results carry a `stress` field (and it was judged).
    pub stress_field: bool,
    /// Nodes matched, the largest node-to-point distance, and the matching distance.
    pub nodes: usize,
    pub largest_distance: f64,
    pub match_distance: f64,
    /// The displacement the results define (global dofs of the model).
    pub u: Vec<f64>,
}

impl Judgement3 {
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| !c.fails_the_case())
    }
}

/// Read the results at `path` for the bodies of `model` (see the module docs).
pub fn load_results3(model: &Model3, path: &Path) -> Result<Results> {
    load_results_of(model.bodies.iter().map(|b| b.name.as_str()), path)
}

/// Points hashed into cubes of side `h`, to find the points near a node.
struct PointIndex3<'a> {
    points: &'a [[f64; 3]],
    h: f64,
    cells: HashMap<[i64; 3], Vec<usize>>,
}

impl<'a> PointIndex3<'a> {
    fn new(points: &'a [[f64; 3]], h: f64) -> Self {
        let mut cells: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        for (k, p) in points.iter().enumerate() {
            cells
                .entry(p.map(|c| (c / h).floor() as i64))
                .or_default()
                .push(k);
        }
        PointIndex3 { points, h, cells }
    }

    fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
        (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
    }

    /// Points within `h` of `x`, nearest first.
    fn near(&self, x: [f64; 3]) -> Vec<(usize, f64)> {
        let c = x.map(|v| (v / self.h).floor() as i64);
        let mut found = Vec::new();
        for di in -1..=1 {
            for dj in -1..=1 {
                for dk in -1..=1 {
                    let key = [c[0] + di, c[1] + dj, c[2] + dk];
                    for &k in self.cells.get(&key).into_iter().flatten() {
                        let d = Self::distance(self.points[k], x);
                        if d <= self.h {
                            found.push((k, d));
                        }
                    }
                }
            }
        }
        found.sort_by(|a, b| a.1.total_cmp(&b.1));
        found
    }

    fn nearest(&self, x: [f64; 3]) -> Option<(usize, f64)> {
        self.points
            .iter()
            .enumerate()
            .map(|(k, &p)| (k, Self::distance(p, x)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }
}

/// `[xx, yy, zz, yz, xz, xy]` of a stress value: 6 components as they are, 9 as a symmetric
/// 3x3 tensor row by row (within `1e-10` of its largest entry).
fn stress6_of(v: &[f64]) -> std::result::Result<[f64; 6], String> {
    let largest = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let same = |a: f64, b: f64| (a - b).abs() <= 1e-10 * largest;
    match v.len() {
        6 => Ok([v[0], v[1], v[2], v[3], v[4], v[5]]),
        9 if same(v[1], v[3]) && same(v[2], v[6]) && same(v[5], v[7]) => {
            Ok([v[0], v[4], v[8], v[5], v[2], v[1]])
        }
        9 => Err(format!(
            "9 components {v:?} are not a symmetric 3x3 tensor row by row"
        )),
        n => Err(format!(
            "{n} components per point (a 3D stress has 6: xx, yy, zz, yz, xz, xy, or 9)"
        )),
    }
}

/// Judge `results` with the checks of the 3D `model`; nodes are matched within
/// `match_share * model.size()`.
pub fn judge3(model: &Model3, results: &Results, match_share: f64) -> Result<Judgement3> {
    if !(match_share.is_finite() && match_share > 0.0 && match_share < 1.0) {
        return Err(Error::invalid(
            &model.source,
            "--match-tol",
            format!("{match_share} is not a share of the model size in (0, 1)"),
            "give e.g. --match-tol 1e-8 (the default)",
        ));
    }
    let delta = match_share * model.size();
    let mut u = vec![0.0; model.dof_count];
    let mut matched: Vec<Vec<usize>> = Vec::new();
    let mut largest_distance = 0.0f64;
    for (b, body) in model.bodies.iter().enumerate() {
        let file = results.of_body(b);
        let index = PointIndex3::new(&file.grid.points, delta);
        let displacement = field(file, DISPLACEMENT_FIELD, 3)?.ok_or_else(|| {
            Error::invalid(
                &file.shown,
                "point data",
                format!(
                    "no point field '{DISPLACEMENT_FIELD}' (the file has: {})",
                    file.grid
                        .fields
                        .keys()
                        .cloned()
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
                "write the displacement (3 components) as point data named 'displacement'",
            )
        })?;
        let mut points = Vec::with_capacity(body.mesh.nodes.len());
        for (n, &x) in body.mesh.nodes.iter().enumerate() {
            let at = || {
                format!(
                    "node {n} of body '{}' at ({}, {}, {})",
                    body.name, x[0], x[1], x[2]
                )
            };
            let near = index.near(x);
            let Some(&(k, d)) = near.first() else {
                let nearest = index
                    .nearest(x)
                    .map(|(k, d)| {
                        let p = file.grid.points[k];
                        format!(
                            "the nearest is point {k} at ({}, {}, {}), {d:.3e} away",
                            p[0], p[1], p[2]
                        )
                    })
                    .unwrap_or_else(|| "the file has no points".into());
                return Err(Error::invalid(
                    &file.shown,
                    at(),
                    format!("no result point within {delta:.3e} of the node; {nearest}"),
                    crate::harness::judge::unmatched_node_hint(
                        &file.grid,
                        displacement,
                        &x,
                        delta,
                        "the mesh our tool wrote (<body>.vtu of `contact-patch run`)",
                    ),
                ));
            };
            let value = displacement.at(k);
            let scale = value[..3]
                .iter()
                .fold(f64::MIN_POSITIVE, |m, v| m.max(v.abs()));
            if let Some(&(other, _)) = near[1..].iter().find(|&&(j, _)| {
                let w = displacement.at(j);
                (0..3).any(|i| (w[i] - value[i]).abs() > 1e-12 * scale)
            }) {
                return Err(Error::invalid(
                    &file.shown,
                    at(),
                    format!(
                        "points {k} and {other} are both within {delta:.3e} of the node and \
                         carry different displacements (two bodies meet here)"
                    ),
                    "write one .vtu per body, named <body name>.vtu, into a folder and give the \
                     folder",
                ));
            }
            largest_distance = largest_distance.max(d);
            for (i, &v) in value.iter().take(3).enumerate() {
                u[body.dof(n, i)] = v;
            }
            points.push(k);
        }
        matched.push(points);
    }

    let mut checks = Vec::new();
    let mut not_judged = Vec::new();
    for check in &model.checks {
        match check {
            Check::UniformStress3d { stress, tol } => {
                checks.push(uniform_stress_check3(model, &u, stress, *tol))
            }
            Check::MaxPenetration { .. }
            | Check::ContactForce { .. }
            | Check::MaxContactPressure { .. }
            | Check::ForceBalance { .. } => not_judged.push(NotJudged {
                check: serde_json::to_string(check).expect("checks serialize"),
                why: "the contact forces and penetrations of a 3D pair are judged from our \
                      contact rows only (a run of the case), not from another code's results"
                    .to_string(),
            }),
            Check::Reaction { .. } if model.contact.is_empty() => {
                // the reactions K u - f of the results' displacements on this mesh
                let solution = crate::harness::judge::solution_of(model, u.clone(), None);
                checks.extend(crate::harness::checks::reaction_result(
                    model, &solution, check,
                ))
            }
            Check::Reaction { .. } => not_judged.push(NotJudged {
                check: serde_json::to_string(check).expect("checks serialize"),
                why: "with contact, K u - f at a support holds the contact forces of the \
                      results, which a 3D judgement does not read"
                    .to_string(),
            }),
            Check::Displacement { .. } => {
                let solution = crate::harness::judge::solution_of(model, u.clone(), None);
                let magnitudes = crate::harness::checks::Magnitudes::of(model, &solution);
                checks.push(crate::harness::checks::judge_check(
                    model,
                    &solution,
                    None,
                    &magnitudes,
                    check,
                ))
            }
            Check::TerminatesWith { .. }
            | Check::Equilibrium { .. }
            | Check::StatusChanges { .. }
            | Check::Warns { .. } => not_judged.push(NotJudged {
                check: serde_json::to_string(check).expect("checks serialize"),
                why: crate::harness::judge::unjudgeable(check)
                    .expect("a check of our own solve")
                    .to_string(),
            }),
            Check::UniformStress { .. }
            | Check::ExactDisplacement { .. }
            | Check::ContactPressure { .. } => {
                unreachable!("Model::resolve_checks refuses these checks in 3D")
            }
        }
    }
    // the results' own stress field
    let files = results.files();
    let mut stress_field = !files.is_empty();
    for f in &files {
        stress_field &= field(f, STRESS_FIELD, 6)?.is_some();
    }
    if stress_field {
        for check in &model.checks {
            let Check::UniformStress3d { stress, tol } = check else {
                continue;
            };
            let largest = stress.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let scale = if largest > 0.0 { largest } else { 1.0 };
            let mut error = 0.0f64;
            for (b, points) in matched.iter().enumerate() {
                let file = results.of_body(b);
                let s = field(file, STRESS_FIELD, 6)?.expect("found above");
                for &k in points {
                    let v = stress6_of(s.at(k)).map_err(|why| {
                        Error::invalid(
                            &file.shown,
                            format!("point field '{STRESS_FIELD}' at point {k}"),
                            why,
                            "write the stress as xx, yy, zz, yz, xz, xy (6 components) or as a \
                             symmetric 3x3 tensor row by row (9)",
                        )
                    })?;
                    for i in 0..6 {
                        let e = (v[i] - stress[i]).abs() / scale;
                        if e.is_nan() || e > error {
                            error = e;
                        }
                    }
                }
            }
            checks.push(CheckResult::judged(
                format!(
                    "{} in the results' own nodal 'stress' field",
                    uniform_stress_words3(stress)
                ),
                error,
                *tol,
            ));
        }
    }
    Ok(Judgement3 {
        checks,
        not_judged,
        stress_field,
        nodes: matched.iter().map(Vec::len).sum(),
        largest_distance,
        match_distance: delta,
        u,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stress_values_of_six_and_nine_components() {
        let six = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        assert_eq!(stress6_of(&six).unwrap(), six);
        // row by row: [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]
        let nine = [1.0, 6.0, 5.0, 6.0, 2.0, 4.0, 5.0, 4.0, 3.0];
        assert_eq!(stress6_of(&nine).unwrap(), six);
        let mut skew = nine;
        skew[3] = -6.0;
        assert!(stress6_of(&skew).unwrap_err().contains("symmetric"));
        assert!(stress6_of(&[1.0, 2.0, 3.0])
            .unwrap_err()
            .contains("3 components"));
    }

    #[test]
    fn points_are_found_within_the_matching_distance_only() {
        let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1e-9]];
        let index = PointIndex3::new(&points, 1e-8);
        let near = index.near([0.0, 0.0, 0.0]);
        assert_eq!(near.iter().map(|p| p.0).collect::<Vec<_>>(), vec![0, 2]);
        assert!(index.near([0.5, 0.0, 0.0]).is_empty());
        assert_eq!(index.nearest([0.9, 0.0, 0.0]).unwrap().0, 1);
    }
}
