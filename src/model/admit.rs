//! Admission of a built model: the checks that need more than the case's data, run once before
//! any solve. [`Model::build`] resolves names, meshes and numbers; here the contact rows of
//! every pair are built (with every candidate row counted as closed) to find a body that no
//! support and no contact can hold against a rigid motion (`crate::model::rigid`), which would
//! otherwise surface as a singular matrix. Under finite kinematics a node-to-node pair's
//! reference interface must also match node for node (its nodes are then paired by proximity
//! in the current configuration, `crate::contact::discretization::nodal_normal`).

use crate::contact::discretization::{check_matched_nodes, Discretize};
use crate::error::{Error, Result};
use crate::io::scene::{DiscretizationSpec, Kinematics};
use crate::model::{parse, ContactPair, MasterSide, Model};
use std::path::Path;

/// Read, parse, build and admit a case file.
pub fn load(path: &Path) -> Result<Model> {
    let source = path.display().to_string();
    let text =
        std::fs::read_to_string(path).map_err(|e| Error::io(&source, "reading the case", e))?;
    let case = parse(&text, &source)?;
    admit(Model::build(&case, &source)?)
}

/// `model`, when it passes the checks of this module.
pub fn admit(model: Model) -> Result<Model> {
    // finite kinematics pairs node-to-node contact by proximity in the current configuration:
    // the reference configuration must match node for node
    if model.physics.kinematics == Kinematics::Finite {
        for pair in &model.contact {
            if pair.discretization == DiscretizationSpec::NodeToNode {
                check_matched_nodes(&model, pair)
                    .map_err(|reason| not_applicable(&model, pair, reason))?;
            }
        }
    }
    // in a dynamic run the mass holds every rigid motion
    if model.dynamics.is_none() {
        check_rigid_modes(&model)?;
    }
    Ok(model)
}

/// The error of a pair whose discretization does not apply, for `reason`.
fn not_applicable<const D: usize, K: crate::model::space::SolidCell<D>>(
    model: &Model<D, K>,
    pair: &ContactPair,
    reason: String,
) -> Error {
    Error::invalid(
        &model.source,
        format!("contact '{}'", pair.name),
        format!("the discretization does not apply: {reason}"),
        "choose another discretization for this pair",
    )
}

/// Every rigid mode of every body must be held by the prescribed dofs and the contact rows
/// together, every candidate row counted as closed (see `crate::model::rigid`).
pub fn check_rigid_modes<const D: usize, K: Discretize<D>>(model: &Model<D, K>) -> Result<()> {
    let mut rows = Vec::new();
    for pair in &model.contact {
        rows.extend(
            K::pair_rows(model, pair).map_err(|reason| not_applicable(model, pair, reason))?,
        );
    }
    let rows: Vec<&crate::contact::Constraint<D>> = rows.iter().collect();
    let Some(free) = crate::model::rigid::free_rigid_mode(model, &rows) else {
        return Ok(());
    };
    let in_contact = model.contact.iter().any(|p| {
        p.slave.0 == free.body
            || matches!(&p.master, MasterSide::Body { body, .. } if *body == free.body)
    });
    let (problem, hint) = if in_contact {
        (
            format!("the body is not held against rigid motion even with every contact closed: it can {} ({})", free.motion(), free.why),
            "add supports; frictionless contact holds a body only along the contact normals (e.g. fix u_x at one node of a punch)",
        )
    } else {
        (
            format!("the body is not held against rigid motion: it can {} ({})", free.motion(), free.why),
            "add supports (e.g. \"y\": 0 on a side and \"x\": 0 at one corner) so that it can neither translate nor rotate",
        )
    };
    Err(Error::invalid(
        &model.source,
        format!("body '{}'", model.bodies[free.body].name),
        problem,
        hint,
    ))
}
