//! One run of a 3D case (bodies with `block3d` meshes): validate into a [`Model3`], solve
//! small-strain elasticity, with contact when the case has pairs, judge the checks, write
//! `summary.json` and one `.vtu` per body.
//!
//! The 3D side of the dimension seam (issue 13): the mesher ([`crate::mesh::block3`]) and
//! kernels ([`crate::solid`]) are 3D; the case format, the Gmsh reader
//! ([`crate::io::gmsh_read::body_mesh`]), the user sets, supports and loads
//! ([`crate::model::Model::apply_supports`], [`crate::model::Model::apply_loads`]), the model
//! ([`crate::model::Model`]`<3, SolidKind>`), the assembly and elastic solve
//! ([`crate::solver::linear`]), the rigid-mode check ([`crate::model::admit::check_rigid_modes`])
//! and the active-set contact solve with every enforcement method
//! ([`crate::solver::active_set`]) are the 2D code paths, generic over the dimension. What is
//! not built in 3D yet is refused here with the reason (an invalid-case error, exit 2), never
//! computed wrongly: dynamics, the current contact geometry under small strain, friction
//! sweeps, exact solutions and the checks against them (`uniform_stress`, `exact_displacement`,
//! `contact_pressure`); a sweep judges its cells against the stress of the case's
//! `uniform_stress_3d` check ([`sweep_stress3`]). The 3D discretizations refuse what they do
//! not treat ([`crate::contact::discretization::Discretize`]).
//!
//! **Finite strain** (`physics.kinematics: "finite"`, hyperelastic materials
//! [`crate::solid_finite`]) runs the 2D driver [`crate::solver::finite`] (load steps of
//! Newton's method with cuts, the same convergence rules and messages) on the 3D model,
//! through the dimension-generic Newton contact system
//! ([`crate::solver::contact_newton`]): frictionless contact against rigid planes and spheres
//! in the current geometry (the sphere's gap second derivative in the tangent), and between 3D
//! bodies by node-to-surface with master normals, one or two passes, each row carrying the
//! second derivative of its gap over the slave node and the master facet's nodes (closest
//! points inside facets, on edges and at corners,
//! [`crate::contact::discretization::facet_gap_hessian`]; Wriggers 2006, section 4.3), by
//! node-to-node on interfaces that match in the reference configuration (the gap along the
//! master's nodal normal, its variation included,
//! [`crate::contact::discretization::nodal_normal3`]) and by segment-based mortar, standard
//! and dual, on Quad4, Tri3 and Quad9 facets (the weighted gap's exact gradient and Hessian
//! through the auxiliary plane, the clipping and the projections,
//! `contact::discretization::mortar3_linearization`), every enforcement method of the 2D
//! Newton scheme. Refused with the reason: tied pairs under finite kinematics, mortar on
//! Tri6 facets (Tet10 bodies) under finite kinematics, contact without the Newton scheme, the current geometry or the geometric stiffness. The stress of the checks and the `.vtu` is
//! then the Cauchy stress `F S F^T / J`, at the reference positions of the points.
//!
//! Coulomb friction (issue 13, build item 4) runs through the 2D code path: the Newton scheme
//! ([`crate::solver::contact_newton`], generic over the dimension) with the return map on the
//! disc ([`crate::contact::friction`]) and two tangential rows per pair row, node-based or
//! mortar, standard and dual (the weighted tangential slip,
//! [`crate::contact::discretization::pair3`]), with every normal law the 2D scheme takes for
//! friction: the penalty-type ones and Lagrange multipliers (two tangential multipliers per
//! row, the semi-smooth stick/slip sets on the disc with the consistent turn of the slip
//! direction, [`crate::contact::friction::multiplier_status`]); load paths (`path` on supports
//! and pressures, steps with committed slip) are the 2D model's
//! ([`crate::model::Model::at_load`]).
//!
//! The guards of a 2D run hold here, through the same functions: the solver's counts and
//! tolerances ([`crate::model::check_solver_settings`]), finite nodal stresses
//! ([`crate::post::check_finite_nodal_stresses`]), and the largest penetration of each pair
//! relative to the contact element size ([`crate::contact::forces::pair_penetration`]): a
//! warning above [`crate::harness::checks::PENETRATION_WARNING_SHARE`], the fields
//! `max_penetration` and `max_penetration_share` of `summary.json` (`contact`, and per pair
//! under `contact.pairs`), and the check `max_penetration`. Supports are the 2D model's
//! ([`crate::model::Model::apply_supports`]: one conflict rule, one load path), and
//! `summary.json` lists each support set's reaction (`reactions`, x, y and z, every prescribed
//! dof counted in one set: [`crate::post::ReactionSummary`]). Contact output is the 2D one,
//! from the same functions generic over the dimension: per pair the summary of
//! [`crate::post::PairSummary`] (forces, normal force, closed area, largest pressure,
//! point counts), the `<pair>.contact.csv`, `.json` and `.vtu` files of
//! [`crate::io::contact_output`] (pressure, shear, gap, status, slip and forces per point,
//! [`crate::contact::results`]) and the contact fields of the body `.vtu` files.
//!
//! The check `uniform_stress_3d` is the 3D uniform-stress check: the largest difference over
//! the quadrature points of the stiffness rule and the six components, relative to the
//! largest component of the expected stress. The `.vtu` holds the displacement (3
//! components) and the nodal stress `[xx, yy, zz, yz, xz, xy]` (Cauchy under finite
//! kinematics), the mean over the cells
//! around each node of the stress at the cell's natural centre.

use crate::contact::forces::{pair_forces, Penetration};
use crate::contact::results::{pair_results, PairResults};
use crate::error::{Error, Result};
use crate::fe::displacement_gradient_at;
use crate::fe::ReferenceCell;
use crate::fe3d::SolidKind;
use crate::harness::checks::CheckResult;
use crate::io::contact_output::{body_point_arrays, write_pair_files};
use crate::io::paths::{file_name, name_problem, OutputFolder, NAME_RULE};
use crate::io::scene::{
    Case, Check, ContactGeometry, DiscretizationSpec, Interaction, Kinematics, MaterialModel,
    MeshSpec, Scheme,
};
use crate::io::vtu::{write_grid, PointArray};
use crate::mesh::block3;
use crate::model::{Body3, MasterSide, Model3};
use crate::post::pair_summaries;
use crate::solid::{strain_at, Elasticity, Voigt};
use crate::solid_finite::Hyperelastic;
use std::path::Path;

/// Whether the case read from `source` has a 3D body (and so runs here): a `block3d` mesh, or
/// a Gmsh file with tetrahedra or hexahedra (the file named relative to `source`'s folder; a
/// file that cannot be read is left to the 2D model, which names what is wrong with it).
pub fn is_3d(case: &Case, source: &str) -> bool {
    case.bodies.iter().any(|b| match &b.mesh {
        MeshSpec::Block3d(_) => true,
        MeshSpec::Explicit(e) => e.element.solid().is_some(),
        MeshSpec::Gmsh(g) => crate::model::gmsh_file_is_3d(g, source),
        _ => false,
    })
}

/// The case at `path` when it parses and is 3D; `None` otherwise (the 2D path reads it again
/// and reports what is wrong with it).
pub fn read_3d_case(path: &Path) -> Option<Case> {
    let text = std::fs::read_to_string(path).ok()?;
    let source = path.display().to_string();
    let case = crate::model::parse(&text, &source).ok()?;
    is_3d(&case, &source).then_some(case)
}

/// What a 3D run produced: the one [`crate::outcome::Outcome`] of both dimensions.
pub type Outcome3 = crate::outcome::Outcome<3, SolidKind>;

/// The 3D checks of the stress; those against a 2D stress or exact field fail saying so (the
/// model refuses them in a 3D case before a run).
impl crate::harness::checks::DimensionChecks<3> for SolidKind {
    fn judge_by_dimension(
        model: &Model3,
        solution: &crate::solver::linear::Solution<3>,
        _contact_forces: Option<&[crate::contact::forces::PairForces<3>]>,
        _magnitudes: &crate::harness::checks::Magnitudes,
        check: &Check,
    ) -> Option<(String, f64, f64)> {
        match check {
            Check::UniformStress3d { stress, tol } => {
                let r = uniform_stress_check3(model, &solution.u, stress, *tol);
                Some((r.check, r.error, r.tol))
            }
            Check::UniformStress { .. }
            | Check::ExactDisplacement { .. }
            | Check::ContactPressure { .. } => {
                Some(crate::harness::checks::not_judged_in("3D", check))
            }
            _ => None,
        }
    }
}

/// The stress of a 3D case's `uniform_stress_3d` check: what its sweep judges the stress
/// against.
pub(crate) fn sweep_stress3(model: &Model3) -> Option<[f64; 6]> {
    model.checks.iter().find_map(|c| match c {
        Check::UniformStress3d { stress, .. } => Some(*stress),
        _ => None,
    })
}

/// The words of the `uniform_stress_3d` check with the expected `stress` (shared by the run and
/// `contact-patch judge`, whose report matches checks by their words).
pub fn uniform_stress_words3(stress: &[f64; 6]) -> String {
    format!("uniform stress {stress:?} (3D: xx, yy, zz, yz, xz, xy)")
}

/// The check `uniform_stress_3d` on the displacement `u` (global) of `model`: the largest
/// difference over every body's quadrature points (stiffness rule) and the six components of
/// `sigma(u)` from `stress`, relative to the largest component of `stress` (1 when it is zero).
pub fn uniform_stress_check3(
    model: &Model3,
    u: &[f64],
    stress: &[f64; 6],
    tol: f64,
) -> CheckResult {
    let largest = stress.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let scale = if largest > 0.0 { largest } else { 1.0 };
    let error = model
        .bodies
        .iter()
        .flat_map(|b| body_stresses(b, u))
        .flat_map(|(_, s)| (0..6).map(move |i| (s[i] - stress[i]).abs()))
        .fold(0.0, f64::max)
        / scale;
    CheckResult::judged(uniform_stress_words3(stress), error, tol)
}

/// The stress at the natural point `xi` of a cell with reference nodes `coords` under the
/// element displacement `u_e`, with the reference position of the point: the small-strain
/// stress, or the Cauchy stress `F S F^T / J` of a hyperelastic body (finite kinematics).
fn stress_at(body: &Body3, coords: &[[f64; 3]], u_e: &[f64], xi: [f64; 3]) -> ([f64; 3], [f64; 6]) {
    let kind = body.mesh.kind;
    match &body.hyperelastic {
        Some(law) => {
            let (h, x) = displacement_gradient_at(kind, coords, u_e, xi);
            (x, Voigt::<3>::symmetric_components(&law.cauchy(&h)))
        }
        None => {
            let (eps, x) = strain_at(kind, coords, u_e, xi);
            (x, body.material.stress(eps))
        }
    }
}

/// The stress of the displacement `u` (global) in `body` at every quadrature point of the
/// stiffness rule, with the point: `(x, sigma)` (see [`stress_at`]).
pub fn body_stresses(body: &Body3, u: &[f64]) -> Vec<([f64; 3], [f64; 6])> {
    let kind = body.mesh.kind;
    let rule = kind.stiffness_rule();
    let mut dofs = Vec::new();
    let mut out = Vec::new();
    for c in 0..body.mesh.cell_count() {
        let coords = body.mesh.cell_coords(c);
        body.cell_dofs(c, &mut dofs);
        let u_e: Vec<f64> = dofs.iter().map(|&d| u[d]).collect();
        for q in &rule {
            out.push(stress_at(body, &coords, &u_e, q.xi));
        }
    }
    out
}

/// The reason a feature is refused in 3D.
fn not_built(source: &str, at: impl std::fmt::Display, what: &str, hint: &str) -> Error {
    Error::invalid(source, at, format!("{what} in 3D is not built yet"), hint)
}

/// Validate the 3D case into its model (see the module docs for what is refused).
pub fn build3(case: &Case, source: &str) -> Result<Model3> {
    if let Some(problem) = name_problem(&case.name) {
        return Err(Error::invalid(source, "name", problem, NAME_RULE));
    }
    if case.physics.dynamics.is_some() {
        return Err(not_built(
            source,
            "physics.dynamics",
            "dynamics",
            "remove physics.dynamics",
        ));
    }
    let finite = case.physics.kinematics == Kinematics::Finite;
    if !finite && case.physics.contact_geometry == ContactGeometry::Current {
        return Err(not_built(
            source,
            "physics.contact_geometry",
            "contact in the current geometry under small strain",
            "remove physics.contact_geometry (contact in the reference geometry), or use \"kinematics\": \"finite\"",
        ));
    }
    if case.sweep.as_ref().is_some_and(|s| s.expect.is_some()) {
        return Err(not_built(
            source,
            "sweep.expect",
            "a friction sweep",
            "remove \"expect\" and the Coulomb interaction, or sweep the case in 2D",
        ));
    }
    if case.exact.is_some() {
        return Err(not_built(
            source,
            "exact",
            "an exact solution",
            "remove \"exact\"; give the supports numbers and judge with uniform_stress_3d",
        ));
    }
    if let Some(k) = case.bodies.iter().position(|b| match &b.mesh {
        MeshSpec::Block(_) => true,
        MeshSpec::Explicit(e) => e.element.plane().is_some(),
        _ => false,
    }) {
        return Err(Error::invalid(
            source,
            format!("bodies[{k}] '{}'", case.bodies[k].name),
            "the body is 2D and another body of the case 3D; 2D and 3D bodies do not meet",
            "give every body a \"block3d\" mesh, an explicit mesh of 3D cells or a Gmsh mesh of tetrahedra or hexahedra, or run the 2D bodies as a case of their own",
        ));
    }
    crate::model::check_size(case, source)?;
    crate::model::check_solver_settings(case, source)?;
    let mut bodies: Vec<Body3> = Vec::new();
    let mut set_warnings = Vec::new();
    for (bi, spec) in case.bodies.iter().enumerate() {
        let at = format!("bodies[{bi}] '{}'", spec.name);
        if let Some(problem) = name_problem(&spec.name) {
            return Err(Error::invalid(
                source,
                format!("{at}.name"),
                problem,
                NAME_RULE,
            ));
        }
        if bodies.iter().any(|b| b.name == spec.name) {
            return Err(Error::invalid(
                source,
                &at,
                format!("a second body is named '{}'", spec.name),
                "give every body a unique name",
            ));
        }
        let (material, hyperelastic) = material3(case, &spec.material, source, &at)?;
        let mut mesh = match &spec.mesh {
            MeshSpec::Block3d(block) => block_mesh3(block, source, &at)?,
            MeshSpec::Gmsh(g) => {
                let (mesh, _) = crate::model::read_gmsh_mesh::<3, SolidKind>(g, source, &at)?;
                crate::model::check_read_size(case, &bodies, &mesh, source, &at)?;
                mesh
            }
            MeshSpec::Explicit(e) => {
                let kind = e
                    .element
                    .solid()
                    .expect("every body was checked to be 3D above");
                let mesh = crate::model::explicit_mesh(e, kind, source, &at)?;
                crate::model::check_read_size(case, &bodies, &mesh, source, &at)?;
                mesh
            }
            _ => unreachable!("every body was checked to be 3D above"),
        };
        crate::model::check_cells(&mesh, source, &at)?;
        set_warnings.extend(crate::model::add_user_sets(&mut mesh, spec, source, &at)?);
        bodies.push(Body3 {
            name: spec.name.clone(),
            material_name: spec.material.clone(),
            material,
            hyperelastic,
            mesh,
            dof_offset: 0,
        });
    }
    let mut model = Model3::with_bodies(&case.name, source, bodies);
    model.warnings = set_warnings;
    model.sweep = case.sweep.clone();
    model.description = case.description.clone();
    model.plane = case.analysis.plane;
    model.physics = case.physics.clone();
    model.solver = case.solver.clone();
    model.factor_limit = crate::solver::sparse::WorkLimit {
        gigabytes: case.limits.factor_gigabytes,
        operations: case.limits.factor_operations,
    };
    model.iteration_dofs = case.limits.iteration_dofs;
    model.apply_supports(case)?;
    model.apply_loads(case)?;
    model.resolve_contact(case)?;
    if finite {
        check_finite3(&model, case)?;
    }
    model.resolve_checks(case)?;
    if model.sweep.is_some() && sweep_stress3(&model).is_none() {
        return Err(Error::invalid(
            source,
            "sweep",
            "a 3D sweep judges every cell's stress against the stress of the case's uniform_stress_3d check, and the case has none",
            "add {\"check\": \"uniform_stress_3d\", \"stress\": [xx, yy, zz, yz, xz, xy], \"tol\": 1e-10} with the exact stress of the case",
        ));
    }
    Ok(model)
}

/// The mesh of a `block3d` spec, its breaks and moves finite.
fn block_mesh3(
    block: &crate::io::scene::Block3dSpec,
    source: &str,
    at: &str,
) -> Result<crate::mesh::Mesh3> {
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
    block3(block.element, &xs, &ys, &zs, &moves).map_err(|e| {
        Error::invalid(
            source,
            format!("{at}.mesh.block3d"),
            e,
            "fix the breaks or moves",
        )
    })
}

/// What finite kinematics solves in 3D, refused otherwise with the reason: frictionless
/// contact against rigid masters and between bodies (node-to-surface with master normals, one
/// or two passes; node-to-node on interfaces that match node for node in the reference
/// configuration; mortar), by the Newton scheme in the current geometry with the full tangent.
fn check_finite3(model: &Model3, case: &Case) -> Result<()> {
    let source = &model.source;
    for (k, pair) in model.contact.iter().enumerate() {
        let at = format!("contact[{k}] '{}'", pair.name);
        if let MasterSide::Body { .. } = pair.master {
            match pair.discretization {
                DiscretizationSpec::NodeToSurface { .. } => {}
                DiscretizationSpec::NodeToNode => {
                    // the current configuration pairs the nodes by proximity: the reference
                    // configuration must match node for node
                    if let Err(reason) = reference_nodes_match(model, pair) {
                        return Err(Error::invalid(
                            source,
                            format!("{at}.discretization"),
                            format!("the discretization does not apply: {reason}"),
                            "choose another discretization for this pair",
                        ));
                    }
                }
                DiscretizationSpec::Mortar { .. } => {
                    if let Some(body) = finite_mortar_on_tri6(model, pair) {
                        return Err(not_built(
                            source,
                            format!("{at}.discretization"),
                            &format!(
                                "mortar on the Tri6 facets of body '{}' (Tet10) under finite kinematics (its rows and their derivatives are built, but Newton on the Tet10 two-block patch test leaves the uniform state: rows open)",
                                model.bodies[body].name
                            ),
                            "use node-to-surface for this pair, or Hex8, Hex27 or Tet4 bodies",
                        ));
                    }
                }
            }
        }
        if pair.interaction == Interaction::Tied {
            return Err(not_built(
                source,
                format!("{at}.interaction"),
                "a tied pair under finite kinematics",
                "use a frictionless pair, or small-strain kinematics",
            ));
        }
    }
    if model.contact.is_empty() {
        return Ok(());
    }
    if case.solver.scheme != Scheme::Newton {
        return Err(Error::invalid(
            source,
            "solver.scheme",
            "finite kinematics with contact is solved by the Newton scheme only",
            "set \"solver\": {\"scheme\": \"newton\"}",
        ));
    }
    if case.physics.contact_geometry != ContactGeometry::Current {
        return Err(Error::invalid(
            source,
            "physics.contact_geometry",
            "finite kinematics needs the contact geometry of the current configuration",
            "set \"physics\": {\"contact_geometry\": \"current\"}",
        ));
    }
    if !case.solver.geometric_stiffness {
        return Err(Error::invalid(
            source,
            "solver.geometric_stiffness",
            "finite kinematics needs the full tangent of the contact rows",
            "remove \"geometric_stiffness\": false",
        ));
    }
    Ok(())
}

/// The body of a mortar pair whose contact facets are Tri6, if any: `mortar3_linearization`
/// builds their rows with exact gradients and Hessians (checked against differences), but
/// with this refusal lifted Newton on a one-cell Tet10 two-block patch test converged to a
/// state with rows open (standard multipliers) or needed cut steps to reach the uniform one
/// (dual), at seconds a residual evaluation: not validated, so refused.
fn finite_mortar_on_tri6(model: &Model3, pair: &crate::model::ContactPair) -> Option<usize> {
    use crate::contact::discretization::mortar3::FacetSet3;
    let MasterSide::Body { body, facets } = &pair.master else {
        return None;
    };
    let (slave_body, slave_facets) = &pair.slave;
    [(*slave_body, slave_facets), (*body, facets)]
        .into_iter()
        .find(|(b, f)| {
            FacetSet3::from_mesh(&model.bodies[*b].mesh, f)
                .is_ok_and(|set| set.kind == crate::fe::ElementKind::T6)
        })
        .map(|(b, _)| b)
}

/// Whether the node-to-node pair `pair` between bodies matches node for node in the reference
/// configuration (the small-strain pairing, to `1e-9` of the master surface's size), the reason
/// where it does not.
fn reference_nodes_match(
    model: &Model3,
    pair: &crate::model::ContactPair,
) -> std::result::Result<(), String> {
    use crate::contact::discretization::geometry::Surface3;
    use crate::contact::discretization::node_based_rows::{node_to_node_rows, RowSettings};
    let MasterSide::Body { body, facets } = &pair.master else {
        return Ok(());
    };
    let (slave_body, slave_facets) = &pair.slave;
    let slave =
        Surface3::from_solid_mesh(*slave_body, &model.bodies[*slave_body].mesh, slave_facets);
    let master = Surface3::from_solid_mesh(*body, &model.bodies[*body].mesh, facets);
    let numbering = |b: usize, n: usize, c: usize| model.bodies[b].dof(n, c);
    let settings = RowSettings {
        dofs: &numbering,
        pair: 0,
        search_distance: pair.search_distance,
        current_finite: false,
    };
    node_to_node_rows(&slave, &master, &settings).map(|_| ())
}

/// The material `name` of the case, validated: its small-strain elasticity, and its
/// hyperelastic energy under finite kinematics (linear elasticity is refused there, a
/// hyperelastic material under small strain).
fn material3(
    case: &Case,
    name: &str,
    source: &str,
    at: &str,
) -> Result<(Elasticity<3>, Option<Hyperelastic>)> {
    let Some(mat) = case.materials.get(name) else {
        let known: Vec<&String> = case.materials.keys().collect();
        return Err(Error::invalid(
            source,
            format!("{at}.material"),
            format!("material '{name}' is not defined"),
            format!("define it under \"materials\" or use one of {known:?}"),
        ));
    };
    if !(mat.youngs_modulus.is_finite() && mat.youngs_modulus > 0.0) {
        return Err(Error::invalid(
            source,
            format!("materials.{name}.E"),
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
            format!("materials.{name}.nu"),
            format!("Poisson's ratio must lie in (-1, 0.5), got {}", mat.nu),
            "nu = 0.5 (incompressible) is not supported by displacement elements; use e.g. 0.499",
        ));
    }
    let hyperelastic = match (case.physics.kinematics, mat.model) {
        (Kinematics::Finite, MaterialModel::NeoHookean) => {
            Some(Hyperelastic::neo_hookean(mat.youngs_modulus, mat.nu))
        }
        (Kinematics::Finite, MaterialModel::SaintVenantKirchhoff) => Some(
            Hyperelastic::saint_venant_kirchhoff(mat.youngs_modulus, mat.nu),
        ),
        (Kinematics::Finite, _) => {
            return Err(Error::invalid(
                source,
                format!("{at}.material"),
                format!(
                    "finite kinematics needs a hyperelastic material, but '{name}' is linear elastic"
                ),
                format!("give materials.{name} \"model\": \"neo_hookean\" or \"saint_venant_kirchhoff\""),
            ))
        }
        (_, model) if !model.is_linear() => {
            return Err(Error::invalid(
                source,
                format!("materials.{name}.model"),
                format!("the hyperelastic material '{name}' needs finite kinematics"),
                "set \"physics\": {\"kinematics\": \"finite\"}, or use \"model\": \"linear_elastic\" for small strain",
            ))
        }
        _ => None,
    };
    Ok((Elasticity::solid(mat.youngs_modulus, mat.nu), hyperelastic))
}

/// The nodal stress of `body`: the mean over the cells around each node of the stress at the
/// cell's natural centre.
pub(crate) fn nodal_stress(body: &Body3, u: &[f64]) -> Vec<[f64; 6]> {
    let mesh = &body.mesh;
    let kind: SolidKind = mesh.kind;
    let mut sum = vec![[0.0; 6]; mesh.nodes.len()];
    let mut count = vec![0usize; mesh.nodes.len()];
    let mut dofs = Vec::new();
    for c in 0..mesh.cell_count() {
        body.cell_dofs(c, &mut dofs);
        let u_e: Vec<f64> = dofs.iter().map(|&d| u[d]).collect();
        let (_, sigma) = stress_at(body, &mesh.cell_coords(c), &u_e, kind.centre());
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

/// The contact part of the summary: how the solve ended, the rows' totals and each pair's
/// summary (the 2D one: [`crate::post::PairSummary`]) from its forces and per-point
/// `results`.
fn contact_summary(outcome: &Outcome3, results: &[PairResults<3>]) -> Option<serde_json::Value> {
    let state = outcome.solution.contact.as_ref()?;
    let active = state.active.iter().filter(|&&a| a).count();
    let mut force = [0.0; 3];
    for (r, f) in state.rows.iter().zip(&state.forces) {
        for i in 0..3 {
            force[i] += f * r.normal[i];
        }
    }
    let forces = pair_forces(&outcome.model, state);
    let penetrations: Vec<&Penetration<3>> = forces.iter().map(|f| &f.penetration).collect();
    let pairs = pair_summaries(&outcome.model, state, &forces, results);
    let most =
        |get: fn(&Penetration<3>) -> f64| penetrations.iter().map(|p| get(p)).fold(0.0, f64::max);
    let mut summary = serde_json::json!({
        "termination": format!("{:?}", state.termination),
        "iterations": state.iterations,
        "rows": state.rows.len(),
        "active": active,
        "force_on_slaves": force,
        "max_penetration": most(|p| p.depth),
        "max_penetration_share": most(|p| p.share_of_element),
        "pairs": pairs,
    });
    if let Some(friction) = state.friction_summary(None) {
        // Coulomb pairs: the tangential force, the open/stick/slip counts and the dissipation
        // of the last step, and the load steps' totals
        summary["friction"] = serde_json::to_value(friction).expect("the summary serializes");
        summary["steps"] = serde_json::to_value(&state.steps).expect("the steps serialize");
    }
    Some(summary)
}

/// Write `summary.json` and one `<body>.vtu` per body into `folder` (replaced as a whole).
pub fn write_run3(folder: &OutputFolder, outcome: &Outcome3) -> Result<()> {
    let model = &outcome.model;
    let u = &outcome.solution.u;
    let results: Vec<PairResults<3>> = outcome
        .solution
        .contact
        .as_ref()
        .map(|state| pair_results(model, state, u))
        .unwrap_or_default();
    let bodies: Vec<serde_json::Value> = model
        .bodies
        .iter()
        .map(|b| {
            let max_displacement = (0..b.mesh.nodes.len())
                .map(|n| (0..3).map(|i| u[b.dof(n, i)].powi(2)).sum::<f64>().sqrt())
                .fold(0.0, f64::max);
            serde_json::json!({
                "name": b.name,
                "element": b.mesh.kind,
                "nodes": b.mesh.nodes.len(),
                "cells": b.mesh.cell_count(),
                "max_displacement": max_displacement,
            })
        })
        .collect();
    let mut summary = serde_json::json!({
        "case": outcome.model.name,
        "dimension": 3,
        "bodies": bodies,
        "dofs": model.dof_count,
        "relative_residual": outcome.solution.relative_residual,
        "timings": outcome.solution.timings,
        "reactions": crate::post::reaction_summaries(model, &outcome.solution.reactions),
        "contact": contact_summary(outcome, &results),
        "passed": outcome.passed(),
        "warnings": outcome.warnings,
        "checks": outcome.checks,
    });
    // the iterative solves, only when the case asked for them (a direct run writes what it
    // wrote before)
    if let Some(record) = &outcome.solution.iterative {
        summary["linear_solver"] = serde_json::to_value(record).expect("the record serializes");
    }
    if let Some(finite) = outcome.solution.finite.as_deref() {
        // finite kinematics: every attempted load step and the Newton residual history
        summary["finite"] = serde_json::json!(finite);
    }
    folder.write(|tmp| {
        let text = serde_json::to_string_pretty(&summary).expect("the summary serializes");
        crate::io::paths::write_new_file(&tmp.join("summary.json"), &(text + "\n"))?;
        for (k, body) in model.bodies.iter().enumerate() {
            let mesh = &body.mesh;
            let stress: Vec<f64> = nodal_stress(body, u).into_iter().flatten().collect();
            let displacement: Vec<f64> = (0..mesh.nodes.len())
                .flat_map(|n| (0..3).map(move |i| u[body.dof(n, i)]))
                .collect();
            let cells: Vec<(u8, Vec<usize>)> = (0..mesh.cell_count())
                .map(|c| (mesh.kind.vtk_cell_type(), mesh.cell(c).to_vec()))
                .collect();
            let path = tmp.join(file_name("body name", &body.name, ".vtu")?);
            let mut arrays = vec![
                PointArray::float("displacement", 3, displacement),
                PointArray::float("stress", 6, stress),
            ];
            arrays.extend(body_point_arrays(model, k, &results));
            write_grid(&path, &mesh.nodes, &cells, &arrays)?;
        }
        write_pair_files(tmp, model, &results)
    })
}
