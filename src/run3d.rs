//! One run of a 3D case (a body with a `block3d` mesh): validate, solve small-strain
//! elasticity, judge the checks, write `summary.json` and the body's `.vtu`.
//!
//! The 3D floor of the dimension seam (issue 13): the case format, mesher
//! ([`crate::mesh::block3`]), kernels ([`crate::solid3d`]) and solve
//! ([`crate::solver::elastic3d::Solid3`]) work in 3D; what is not built in 3D yet is refused
//! here with the reason (an invalid-case error, exit 2), never computed wrongly: contact
//! (`"contact in 3D is not built yet"`), dynamics, finite strain, sweeps, exact solutions,
//! load paths, user-defined sets, more than one body, loads other than pressure, checks other
//! than `uniform_stress_3d`.
//!
//! The check `uniform_stress_3d` is the 3D uniform-stress check: the largest difference over
//! the quadrature points of the stiffness rule and the six components, relative to the
//! largest component of the expected stress. The `.vtu` holds the displacement (3
//! components) and the nodal stress `[xx, yy, zz, yz, xz, xy]`, the mean over the cells
//! around each node of the stress at the cell's natural centre.

use crate::error::{Error, Result};
use crate::fe::ReferenceCell;
use crate::fe3d::SolidKind;
use crate::harness::checks::CheckResult;
use crate::io::paths::{file_name, name_problem, OutputFolder, NAME_RULE};
use crate::io::scene::{Case, Check, Kinematics, MeshSpec, Prescribed};
use crate::io::vtu::{write_grid, PointArray};
use crate::mesh::block3;
use crate::solid3d::{check_geometry3, strain_at3, Elasticity3};
use crate::solver::elastic3d::Solid3;
use crate::solver::sparse::WorkLimit;
use std::path::Path;

/// Whether the case has a 3D body (and so runs here).
pub fn is_3d(case: &Case) -> bool {
    case.bodies
        .iter()
        .any(|b| matches!(b.mesh, MeshSpec::Block3d(_)))
}

/// The case at `path` when it parses and is 3D; `None` otherwise (the 2D path reads it again
/// and reports what is wrong with it).
pub fn read_3d_case(path: &Path) -> Option<Case> {
    let text = std::fs::read_to_string(path).ok()?;
    let case = crate::model::parse(&text, &path.display().to_string()).ok()?;
    is_3d(&case).then_some(case)
}

/// Everything a 3D run produced.
#[derive(Clone, Debug)]
pub struct Outcome3 {
    pub name: String,
    pub body_name: String,
    pub solid: Solid3,
    pub u: Vec<f64>,
    pub checks: Vec<CheckResult>,
}

impl Outcome3 {
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| c.passed)
    }
}

/// Run the 3D case `case` read from `source`.
pub fn run_case3(case: &Case, source: &str) -> Result<Outcome3> {
    let (solid, body_name) = build3(case, source)?;
    let limit = WorkLimit {
        gigabytes: case.limits.factor_gigabytes,
        operations: case.limits.factor_operations,
    };
    let u = solid.solve(&limit).map_err(|e| {
        Error::invalid(
            source,
            format!("bodies[0] '{body_name}'"),
            format!("the stiffness cannot be factored ({e:?})"),
            "support the body against all six rigid motions (three translations, three rotations), or raise \"limits\" if the factor is too large",
        )
    })?;
    if let Some(d) = u.iter().position(|v| !v.is_finite()) {
        return Err(Error::invalid(
            source,
            format!("bodies[0] '{body_name}'"),
            format!("the displacement of dof {d} is not finite"),
            "rescale the loads and moduli (e.g. N and mm)",
        ));
    }
    let checks = case
        .checks
        .iter()
        .map(|check| match check {
            Check::UniformStress3d { stress, tol } => {
                let largest = stress.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let scale = if largest > 0.0 { largest } else { 1.0 };
                let error = solid
                    .stresses(&u)
                    .iter()
                    .flat_map(|(_, s)| (0..6).map(move |i| (s[i] - stress[i]).abs()))
                    .fold(0.0, f64::max)
                    / scale;
                CheckResult {
                    check: format!("uniform stress {stress:?} (3D: xx, yy, zz, yz, xz, xy)"),
                    error,
                    tol: *tol,
                    passed: error <= *tol,
                }
            }
            _ => unreachable!("build3 refuses every other check"),
        })
        .collect();
    Ok(Outcome3 {
        name: case.name.clone(),
        body_name,
        solid,
        u,
        checks,
    })
}

/// The reason a feature is refused in 3D.
fn not_built(source: &str, at: impl std::fmt::Display, what: &str, hint: &str) -> Error {
    Error::invalid(source, at, format!("{what} in 3D is not built yet"), hint)
}

/// Validate the 3D case into its body (see the module docs for what is refused).
pub fn build3(case: &Case, source: &str) -> Result<(Solid3, String)> {
    if let Some(problem) = name_problem(&case.name) {
        return Err(Error::invalid(source, "name", problem, NAME_RULE));
    }
    if let Some(pair) = case.contact.first() {
        return Err(not_built(
            source,
            format!("contact[0] '{}'", pair.name),
            "contact",
            "3D bodies run without contact for now: remove \"contact\", or give the bodies 2D meshes",
        ));
    }
    if case.physics.dynamics.is_some() {
        return Err(not_built(
            source,
            "physics.dynamics",
            "dynamics",
            "remove physics.dynamics",
        ));
    }
    if case.physics.kinematics == Kinematics::Finite {
        return Err(not_built(
            source,
            "physics.kinematics",
            "finite strain",
            "use small strain (remove physics.kinematics)",
        ));
    }
    if case.sweep.is_some() {
        return Err(not_built(source, "sweep", "a sweep", "remove the sweep"));
    }
    if case.exact.is_some() {
        return Err(not_built(
            source,
            "exact",
            "an exact solution",
            "remove \"exact\"; give the supports numbers and judge with uniform_stress_3d",
        ));
    }
    if case.bodies.len() != 1 {
        return Err(Error::invalid(
            source,
            "bodies",
            format!(
                "a 3D case has one body for now (3D bodies do not meet 2D ones), got {}",
                case.bodies.len()
            ),
            "run each 3D body as a case of its own",
        ));
    }
    let spec = &case.bodies[0];
    let at = format!("bodies[0] '{}'", spec.name);
    if let Some(problem) = name_problem(&spec.name) {
        return Err(Error::invalid(
            source,
            format!("{at}.name"),
            problem,
            NAME_RULE,
        ));
    }
    let MeshSpec::Block3d(block) = &spec.mesh else {
        unreachable!("a 3D case has a block3d body")
    };
    if !spec.node_sets.is_empty() || !spec.facet_sets.is_empty() {
        return Err(not_built(
            source,
            &at,
            "user-defined node and facet sets",
            "use the automatic sets: left/right (x), front/back (y), bottom/top (z), the corners such as bottom_front_left, and all",
        ));
    }
    let Some(mat) = case.materials.get(&spec.material) else {
        let known: Vec<&String> = case.materials.keys().collect();
        return Err(Error::invalid(
            source,
            format!("{at}.material"),
            format!("material '{}' is not defined", spec.material),
            format!("define it under \"materials\" or use one of {known:?}"),
        ));
    };
    if !(mat.youngs_modulus.is_finite() && mat.youngs_modulus > 0.0) {
        return Err(Error::invalid(
            source,
            format!("materials.{}.E", spec.material),
            format!(
                "Young's modulus must be positive and finite, got {}",
                mat.youngs_modulus
            ),
            "give E > 0",
        ));
    }
    if !(mat.nu.is_finite() && mat.nu > -1.0 && mat.nu < 0.5) {
        return Err(Error::invalid(
            source,
            format!("materials.{}.nu", spec.material),
            format!("Poisson's ratio must lie in (-1, 0.5), got {}", mat.nu),
            "nu = 0.5 (incompressible) is not supported by displacement elements; use e.g. 0.499",
        ));
    }
    if !mat.model.is_linear() {
        return Err(not_built(
            source,
            format!("materials.{}.model", spec.material),
            "a hyperelastic material",
            "use \"model\": \"linear_elastic\"",
        ));
    }
    crate::model::check_size(case, source)?;
    let (xs, ys, zs) = (block.x.values(), block.y.values(), block.z.values());
    let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    if !(finite(&xs) && finite(&ys) && finite(&zs))
        || block
            .moves
            .iter()
            .any(|m| !(finite(&m.from) && finite(&m.to)))
    {
        return Err(Error::invalid(
            source,
            format!("{at}.mesh.block3d"),
            "a break or a move is not finite",
            "give finite coordinates",
        ));
    }
    let moves: Vec<_> = block.moves.iter().map(|m| (m.from, m.to)).collect();
    let mesh = block3(block.element, &xs, &ys, &zs, &moves).map_err(|e| {
        Error::invalid(
            source,
            format!("{at}.mesh.block3d"),
            e,
            "fix the breaks or moves",
        )
    })?;
    for c in 0..mesh.cell_count() {
        if let Err(bad) = check_geometry3(mesh.kind, &mesh.cell_coords(c)) {
            return Err(Error::invalid(
                source,
                format!("{at}: element {c} (nodes {:?})", mesh.cell(c)),
                format!(
                    "the element is inverted or degenerate: det J = {:.3e} at ({:.6}, {:.6}, {:.6})",
                    bad.det_j, bad.at[0], bad.at[1], bad.at[2]
                ),
                "keep the moves small against the element size",
            ));
        }
    }
    let mut solid = Solid3::new(mesh, Elasticity3::new(mat.youngs_modulus, mat.nu));
    let node_set = |solid: &Solid3, body: &str, set: &str, at: &str| -> Result<Vec<usize>> {
        if body != spec.name {
            return Err(Error::invalid(
                source,
                at,
                format!("body '{body}' does not exist"),
                format!("use the body '{}'", spec.name),
            ));
        }
        solid.mesh.node_sets.get(set).cloned().ok_or_else(|| {
            let known: Vec<&String> = solid.mesh.node_sets.keys().collect();
            Error::invalid(
                source,
                at,
                format!("body '{body}' has no node set '{set}'"),
                format!("use one of {known:?}"),
            )
        })
    };
    for (k, s) in case.supports.iter().enumerate() {
        let at = format!("supports[{k}]");
        let nodes = node_set(&solid, &s.body, &s.set, &at)?;
        if s.path.is_some() {
            return Err(not_built(
                source,
                format!("{at}.path"),
                "a load path",
                "remove \"path\"",
            ));
        }
        if s.x.is_none() && s.y.is_none() && s.z.is_none() {
            return Err(Error::invalid(
                source,
                &at,
                "the support fixes no component",
                "add \"x\", \"y\" and/or \"z\" (numbers)",
            ));
        }
        for (comp, value) in [(0, s.x), (1, s.y), (2, s.z)] {
            let v = match value {
                None => continue,
                Some(Prescribed::Value(v)) if v.is_finite() => v,
                Some(Prescribed::Value(_)) => {
                    return Err(Error::invalid(
                        source,
                        &at,
                        "the prescribed value is not finite",
                        "give a finite number",
                    ))
                }
                Some(Prescribed::Exact(_)) => {
                    return Err(not_built(
                        source,
                        &at,
                        "\"exact\" as a prescribed value",
                        "give a number",
                    ))
                }
            };
            for &n in &nodes {
                let dof = solid.dof(n, comp);
                match solid.prescribed[dof] {
                    Some(old) if old != v => {
                        return Err(Error::invalid(
                            source,
                            &at,
                            format!(
                                "node {n} gets u_{} = {v} here but {old} from an earlier support",
                                ["x", "y", "z"][comp]
                            ),
                            "remove one of the conflicting supports or make their values agree",
                        ))
                    }
                    _ => solid.prescribed[dof] = Some(v),
                }
            }
        }
    }
    for (k, load) in case.loads.iter().enumerate() {
        let at = format!("loads[{k}]");
        if load.path.is_some() {
            return Err(not_built(
                source,
                format!("{at}.path"),
                "a load path",
                "remove \"path\"",
            ));
        }
        let (Some(p), None, None, None) =
            (load.pressure, &load.traction, load.body_force, load.force)
        else {
            return Err(not_built(
                source,
                &at,
                "a traction, force or body force (their components are 2D in the case format)",
                "give a \"pressure\" on a facet set",
            ));
        };
        if !p.is_finite() {
            return Err(Error::invalid(
                source,
                &at,
                "the pressure is not finite",
                "give a finite number",
            ));
        }
        if load.body != spec.name {
            return Err(Error::invalid(
                source,
                &at,
                format!("body '{}' does not exist", load.body),
                format!("use the body '{}'", spec.name),
            ));
        }
        let Some(set) = &load.set else {
            return Err(Error::invalid(
                source,
                &at,
                "a pressure needs a facet \"set\"",
                "add \"set\": e.g. \"top\"",
            ));
        };
        let Some(facets) = solid.mesh.facet_sets.get(set).cloned() else {
            let known: Vec<&String> = solid.mesh.facet_sets.keys().collect();
            return Err(Error::invalid(
                source,
                &at,
                format!("body '{}' has no facet set '{set}'", spec.name),
                format!("use one of {known:?}"),
            ));
        };
        solid.add_traction(&facets, &|_, n| n.map(|v| -p * v));
    }
    for (k, check) in case.checks.iter().enumerate() {
        let at = format!("checks[{k}]");
        match check {
            Check::UniformStress3d { stress, tol } => {
                if !(stress.iter().all(|v| v.is_finite()) && tol.is_finite() && *tol > 0.0) {
                    return Err(Error::invalid(
                        source,
                        &at,
                        "the stress and the tolerance must be finite, the tolerance positive",
                        "give six finite components [xx, yy, zz, yz, xz, xy] and e.g. \"tol\": 1e-10",
                    ));
                }
            }
            _ => {
                return Err(not_built(
                    source,
                    &at,
                    "this check",
                    "use \"uniform_stress_3d\"",
                ))
            }
        }
    }
    Ok((solid, spec.name.clone()))
}

/// The nodal stress: the mean over the cells around each node of the stress at the cell's
/// natural centre.
fn nodal_stress(outcome: &Outcome3) -> Vec<[f64; 6]> {
    let mesh = &outcome.solid.mesh;
    let kind: SolidKind = mesh.kind;
    let mut sum = vec![[0.0; 6]; mesh.nodes.len()];
    let mut count = vec![0usize; mesh.nodes.len()];
    for c in 0..mesh.cell_count() {
        let u_e: Vec<f64> = outcome
            .solid
            .cell_dofs(c)
            .into_iter()
            .map(|d| outcome.u[d])
            .collect();
        let (eps, _) = strain_at3(kind, &mesh.cell_coords(c), &u_e, kind.centre());
        let sigma = outcome.solid.material.stress(eps);
        for &n in mesh.cell(c) {
            for i in 0..6 {
                sum[n][i] += sigma[i];
            }
            count[n] += 1;
        }
    }
    sum.iter()
        .zip(&count)
        .map(|(s, &k)| s.map(|v| v / k.max(1) as f64))
        .collect()
}

/// Write `summary.json` and `<body>.vtu` into `folder` (replaced as a whole).
pub fn write_run3(folder: &OutputFolder, outcome: &Outcome3) -> Result<()> {
    let mesh = &outcome.solid.mesh;
    let max_displacement = (0..mesh.nodes.len())
        .map(|n| {
            (0..3)
                .map(|i| outcome.u[3 * n + i].powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .fold(0.0, f64::max);
    let summary = serde_json::json!({
        "case": outcome.name,
        "dimension": 3,
        "body": outcome.body_name,
        "element": mesh.kind,
        "nodes": mesh.nodes.len(),
        "cells": mesh.cell_count(),
        "dofs": outcome.solid.dof_count(),
        "max_displacement": max_displacement,
        "passed": outcome.passed(),
        "checks": outcome.checks.iter().map(|c| serde_json::json!({
            "check": c.check, "error": c.error, "tol": c.tol, "passed": c.passed,
        })).collect::<Vec<_>>(),
    });
    let stress: Vec<f64> = nodal_stress(outcome).into_iter().flatten().collect();
    let cells: Vec<(u8, Vec<usize>)> = (0..mesh.cell_count())
        .map(|c| (mesh.kind.vtk_cell_type(), mesh.cell(c).to_vec()))
        .collect();
    folder.write(|tmp| {
        let text = serde_json::to_string_pretty(&summary).expect("the summary serializes");
        crate::io::paths::write_new_file(&tmp.join("summary.json"), &(text + "\n"))?;
        let path = tmp.join(file_name("body name", &outcome.body_name, ".vtu")?);
        write_grid(
            &path,
            &mesh.nodes,
            &cells,
            &[
                PointArray::float("displacement", 3, outcome.u.clone()),
                PointArray::float("stress", 6, stress),
            ],
        )
    })
}
