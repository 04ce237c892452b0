//! `contact-patch export`: a case as files other contact codes read, so that they can solve the
//! same problem on the same meshes and be judged by `contact-patch judge`.
//!
//! Per case, a folder `<case name>/` (an [`OutputFolder`], replaced as a whole) holding
//!
//! * `<case name>.msh`: every body's mesh in one Gmsh MSH 4.1 file, with physical groups for
//!   the bodies, node sets and facet sets ([`crate::io::gmsh`]);
//! * `<body>.vtu`: each body's mesh as a VTK XML unstructured grid with the point field
//!   `node` (our node number) and no results;
//! * `<case name>.json`: the problem in data: analysis, materials, bodies (element, node and
//!   facet sets with their group names, node-tag offsets), supports, loads, contact pairs (with
//!   discretization and enforcement), the checks with their tolerances, the exact solution as
//!   a closed form (`sigma = const`, `u = [e_xx x + g/2 y, g/2 x + e_yy y]` with `e = D^-1
//!   sigma`, or Timoshenko & Goodier's cantilever, see `src/harness/exact.rs`), and the same
//!   data resolved on the mesh: every prescribed dof with its value and every nonzero
//!   consistent nodal load (`f_a = int N_a t ds`), by body, node number and Gmsh node tag;
//!   and under `problem` the case itself as a case file states it, so that the folder alone is
//!   enough to judge results (`contact-patch judge <folder or sidecar> RESULTS`, read back by
//!   [`exported_case`]): a body meshed from a Gmsh file becomes an `explicit` mesh with its
//!   nodes and cells as built (the same numbering) and its node and facet sets as lists; every
//!   other body is as written.

use crate::error::{Error, Result};
use crate::harness::exact::ExactField;
use crate::io::gmsh;
use crate::io::paths::{file_name, OutputFolder, ReportFolder};
use crate::io::scene::{Case, MeshSpec, Plane};
use crate::model::admit::admit;
use crate::model::{parse, Model};
use serde_json::{json, Value};
use std::fs;
use std::path::Path;

/// The version of the sidecar's layout.
pub const SIDECAR_FORMAT: &str = "contact-patch export 1";

/// The parsed case file and its validated model.
pub fn load_case(path: &Path) -> Result<(Case, Model)> {
    let source = path.display().to_string();
    let text = fs::read_to_string(path).map_err(|e| Error::io(&source, "reading the case", e))?;
    let case = parse(&text, &source)?;
    let model = admit(Model::build(&case, &source)?)?;
    Ok((case, model))
}

/// The closed form of the exact field in words, with its parameters.
fn exact_description(model: &Model) -> Value {
    match &model.exact {
        None => Value::Null,
        Some(ExactField::UniformStress { stress }) => {
            let strains: serde_json::Map<String, Value> = model
                .bodies
                .iter()
                .map(|b| {
                    let e = b.material.strain_of_stress(*stress);
                    (
                        b.name.clone(),
                        json!({"eps_xx": e[0], "eps_yy": e[1], "gamma_xy": e[2]}),
                    )
                })
                .collect();
            json!({
                "kind": "uniform_stress",
                "stress": {"xx": stress[0], "yy": stress[1], "xy": stress[2]},
                "closed_form": "sigma(x, y) = stress everywhere; strain e = D^-1 sigma (plane strain or stress as in analysis.plane, material of the body); u_x = eps_xx x + gamma_xy / 2 y, u_y = gamma_xy / 2 x + eps_yy y (no rigid motion)",
                "strain_by_body": strains,
                "traction": "t = sigma n on a boundary with outward normal n",
            })
        }
        Some(ExactField::TimoshenkoCantilever {
            load,
            length,
            depth,
        }) => json!({
            "kind": "timoshenko_cantilever",
            "load": load, "length": length, "depth": depth,
            "closed_form": "Timoshenko & Goodier (1970) sec. 21, x in [0, L], y in [-D/2, D/2], I = D^3/12, plane stress E, nu (plane strain: E/(1-nu^2), nu/(1-nu)): u_x = -P y / (6 E I) [(6L - 3x) x + (2 + nu)(y^2 - D^2/4)], u_y = P / (6 E I) [3 nu y^2 (L - x) + (4 + 5 nu) D^2 x / 4 + (3L - x) x^2], sigma_xx = -P (L - x) y / I, sigma_yy = 0, sigma_xy = P / (2 I) (D^2/4 - y^2)",
        }),
    }
}

/// The case as data that builds the same model without any other file (module notes): the
/// case serialized, each body meshed from a Gmsh file replaced by its explicit mesh and sets.
fn self_sufficient(case: &Case, model: &Model, source: &str) -> Result<Value> {
    let mut scene = serde_json::to_value(case).expect("a case serializes");
    for (spec, body) in case.bodies.iter().zip(&model.bodies) {
        if !matches!(spec.mesh, MeshSpec::Gmsh(_)) {
            continue;
        }
        let mesh = &body.mesh;
        let cells: Vec<&[usize]> = (0..mesh.cell_count()).map(|c| mesh.cell(c)).collect();
        // the sets an explicit mesh of the same nodes and cells has by itself
        let built_in =
            crate::mesh::Mesh::new(mesh.kind, mesh.nodes.clone(), mesh.connectivity.clone());
        let mut node_sets = serde_json::Map::new();
        for (name, nodes) in &mesh.node_sets {
            match built_in.node_sets.get(name) {
                Some(same) if same == nodes => {}
                Some(_) => return Err(clash(source, &body.name, "node", name)),
                None => {
                    node_sets.insert(name.clone(), json!({ "nodes": nodes }));
                }
            }
        }
        let mut facet_sets = serde_json::Map::new();
        for (name, facets) in &mesh.facet_sets {
            match built_in.facet_sets.get(name) {
                Some(same) if same == facets => {}
                Some(_) => return Err(clash(source, &body.name, "facet", name)),
                None => {
                    let list: Vec<[usize; 2]> = facets.iter().map(|f| [f.cell, f.edge]).collect();
                    facet_sets.insert(name.clone(), json!({ "facets": list }));
                }
            }
        }
        let at = scene["bodies"]
            .as_array_mut()
            .expect("bodies serialize as a list")
            .iter_mut()
            .find(|b| b["name"] == body.name.as_str())
            .expect("every body is in the case");
        at["mesh"] =
            json!({"explicit": {"element": mesh.kind, "nodes": mesh.nodes, "cells": cells}});
        at["node_sets"] = Value::Object(node_sets);
        at["facet_sets"] = Value::Object(facet_sets);
    }
    Ok(scene)
}

/// The refusal of a Gmsh set whose name is that of a built-in set with other members.
fn clash(source: &str, body: &str, kind: &str, name: &str) -> Error {
    Error::invalid(
        source,
        format!("body '{body}', {kind} set '{name}'"),
        format!(
            "the Gmsh file's {kind} set '{name}' differs from the built-in set of that name, \
             which an explicit mesh of the same nodes would have"
        ),
        "rename the physical group in the .msh file (the built-in sets are the sides, corners \
         and 'all')",
    )
}

/// The case of an export at `path` (its folder, or the sidecar `<case>.json` in it) and the
/// sidecar's path, or `None` when `path` is not an export (a case file).
pub fn exported_case(path: &Path) -> Result<Option<(std::path::PathBuf, Case)>> {
    let sidecar = if path.is_dir() {
        let name = path.file_name().map(|n| n.to_string_lossy().to_string());
        let file = name.map(|n| path.join(format!("{n}.json")));
        match file.filter(|f| f.is_file()) {
            Some(f) => f,
            None => {
                return Err(Error::invalid(
                    path.display(),
                    "export folder",
                    "no sidecar <folder name>.json in the folder",
                    "give the folder `contact-patch export` wrote for the case (<out>/<case \
                     name>/), its <case name>.json, or the case file",
                ))
            }
        }
    } else {
        path.to_path_buf()
    };
    let source = sidecar.display().to_string();
    let Ok(text) = fs::read_to_string(&sidecar) else {
        return Ok(None);
    };
    let Ok(value) = serde_json::from_str::<Value>(&text) else {
        return Ok(None);
    };
    let is_export = value
        .get("format")
        .and_then(Value::as_str)
        .is_some_and(|f| f.starts_with("contact-patch export"));
    if !is_export {
        return Ok(None);
    }
    let Some(problem) = value.get("problem") else {
        return Err(Error::invalid(
            &source,
            "problem",
            format!(
                "the sidecar ({}) holds no 'problem': it was written before the export carried \
                 the case",
                value["format"]
            ),
            format!(
                "export the case again (contact-patch export CASE --out DIR), or judge with the \
                 case file it names: {}",
                value["case_file"]
            ),
        ));
    };
    let case = parse(&problem.to_string(), &format!("{source} (problem)"))?;
    Ok(Some((sidecar, case)))
}

/// The sidecar JSON of a case, or why the case cannot be stated without its files.
pub fn sidecar(case: &Case, model: &Model, case_file: &Path) -> Result<Value> {
    let scene = serde_json::to_value(case).expect("a case serializes");
    let pick = |key: &str| scene.get(key).cloned().unwrap_or(Value::Null);
    let mut offset = 0usize;
    let mut bodies = Vec::new();
    let mut prescribed = Vec::new();
    let mut forces = Vec::new();
    for body in &model.bodies {
        let mesh = &body.mesh;
        let node_sets: serde_json::Map<String, Value> = mesh
            .node_sets
            .iter()
            .map(|(set, nodes)| {
                let group = if set == gmsh::ALL_NODES_SET {
                    format!("{} (the body's physical surface)", body.name)
                } else {
                    gmsh::node_group_name(&body.name, set)
                };
                (
                    set.clone(),
                    json!({"physical_group": group, "dimension": 0, "nodes": nodes}),
                )
            })
            .collect();
        let facet_sets: serde_json::Map<String, Value> = mesh
            .facet_sets
            .iter()
            .map(|(set, facets)| {
                let nodes: Vec<Vec<usize>> =
                    facets.iter().map(|&f| mesh.facet_nodes(f)).collect();
                (
                    set.clone(),
                    json!({"physical_group": gmsh::group_name(&body.name, set), "dimension": 1, "facets": nodes}),
                )
            })
            .collect();
        bodies.push(json!({
            "name": body.name,
            "material": {"name": body.material_name, "E": body.material.youngs_modulus, "nu": body.material.nu},
            "element": format!("{:?}", mesh.kind),
            "nodes": mesh.nodes.len(),
            "cells": mesh.cell_count(),
            "physical_surface": body.name,
            "gmsh_node_tag": format!("node n of this body has Gmsh tag {} + n + 1", offset),
            "node_tag_offset": offset,
            "vtu": format!("{}.vtu", body.name),
            "node_sets": node_sets,
            "facet_sets": facet_sets,
        }));
        for n in 0..mesh.nodes.len() {
            for (c, axis) in ["x", "y"].iter().enumerate() {
                let d = body.dof(n, c);
                if let Some(v) = model.prescribed[d] {
                    prescribed.push(json!({"body": body.name, "node": n, "gmsh_node_tag": offset + n + 1, "component": axis, "value": v}));
                }
                let f = model.external_force[d];
                if f != 0.0 {
                    forces.push(json!({"body": body.name, "node": n, "gmsh_node_tag": offset + n + 1, "component": axis, "force": f}));
                }
            }
        }
        offset += mesh.nodes.len();
    }
    let problem = self_sufficient(case, model, &case_file.display().to_string())?;
    Ok(json!({
        "format": SIDECAR_FORMAT,
        "case": model.name,
        "description": model.description,
        "case_file": case_file.display().to_string(),
        "analysis": {
            "plane": match model.plane { Plane::Strain => "strain", Plane::Stress => "stress" },
            "thickness": model.thickness,
            "small_strain": true,
        },
        "mesh": {
            "gmsh": format!("{}.msh", model.name),
            "gmsh_format": "MSH 4.1 ASCII; physical surface per body, physical curve '<body>/<facet set>' per facet set, physical point group '<body>/<node set>/nodes' per node set (every physical name distinct)",
            "node_order": "element node orders as Gmsh and VTK: corners counter-clockwise, then edge midpoints (edge 0-1 first), then the centre",
            "node_sets": "bodies[].node_sets.<set>.nodes: the set's nodes as node numbers of that body (0-based; Gmsh tag = node_tag_offset + n + 1)",
            "facet_sets": "bodies[].facet_sets.<set>.facets: one list per facet, its node numbers of that body (0-based) in the order [start, end] for 2-node facets and [start, end, midpoint] for 3-node ones; start to end runs counter-clockwise around the body, so the body lies to the left and the outward normal is the tangent turned clockwise",
        },
        "materials": pick("materials"),
        "bodies": bodies,
        "supports": pick("supports"),
        "loads": pick("loads"),
        "exact": exact_description(model),
        "contact": pick("contact"),
        "sweep": pick("sweep"),
        "checks": pick("checks"),
        "words": "supports and loads as the case file states them: a value 'exact' means the exact solution's displacement at the nodes (supports) or its traction sigma n (loads); 'resolved' holds the same data on the mesh",
        "resolved": {
            "prescribed_displacements": prescribed,
            "consistent_nodal_forces": forces,
        },
        "results": {
            "judge": "contact-patch judge EXPORT_FOLDER RESULTS (this folder, or this file; or the case file named by case_file)",
            "expected": "a .vtu with point data 'displacement' (2 or 3 components) at the mesh's nodes, optionally 'stress' (xx, yy, xy, or a 2x2 / 3x3 tensor) and the contact fields below; or a folder with <body>.vtu per body when bodies touch",
            "fields": judged_fields(),
        },
        "problem": problem,
    }))
}

/// The point fields `judge` reads, with their components, meaning and use
/// ([`crate::harness::judge`], [`crate::harness::outside_contact`]).
fn judged_fields() -> Value {
    use crate::harness::outside_results::{
        CONTACT_FORCE_FIELD, CONTACT_GAP_FIELD, CONTACT_PRESSURE_FIELD, CONTACT_STATUS_FIELD,
        DISPLACEMENT_FIELD, STRESS_FIELD,
    };
    json!([
        {"name": DISPLACEMENT_FIELD, "components": "2 or 3 (x, y[, 0])", "required": true,
         "meaning": "nodal displacement", "judges": "uniform_stress, exact_displacement, displacement, reaction (K u - f with our K and f)"},
        {"name": STRESS_FIELD, "components": "3 (xx, yy, xy), or a symmetric 2x2 / 3x3 tensor row by row", "required": false,
         "meaning": "nodal stress", "judges": "an extra uniform-stress check of the results' own stress"},
        {"name": CONTACT_FORCE_FIELD, "components": "2 or 3 (x, y[, 0])", "required": false,
         "meaning": "nodal contact force the interface puts on the node's body (the assembled contact part of the residual), zero away from contact surfaces", "judges": "contact_force, force_balance (out-of-balance sum |K u - f - f_c| over the free dofs), a tie's contact_pressure (whole traction f_a / A_a)"},
        {"name": CONTACT_PRESSURE_FIELD, "components": 1, "required": false,
         "meaning": "normal contact pressure, positive in compression: -f_a . n_a / A_a (n_a outward normal, A_a = t int N_a ds), for a penalty code kappa (-g)_+", "judges": "contact_pressure, max_contact_pressure; and contact_force, force_balance of frictionless pairs when contact_force is absent (f_a = -p_a A_a n_a)"},
        {"name": CONTACT_GAP_FIELD, "components": 1, "required": false,
         "meaning": "normal gap at the slave nodes (negative: penetration)", "judges": "max_penetration ((-g)_+ over the longest slave facet at the node)"},
        {"name": CONTACT_STATUS_FIELD, "components": 1, "required": false,
         "meaning": "0 at a contact-surface node that carries no contact constraint (ours: no row); other values: a contact point", "judges": "which surface nodes the pressure and penetration checks visit (all slave-surface nodes without it)"},
    ])
}

/// One body's mesh as VTK XML with the point field `node` (our node number).
fn mesh_vtu(body: &crate::model::Body) -> String {
    use std::fmt::Write as _;
    let mesh = &body.mesh;
    let mut s = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n");
    let _ = writeln!(
        s,
        "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        mesh.nodes.len(),
        mesh.cell_count()
    );
    s += "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for p in &mesh.nodes {
        let _ = writeln!(s, "{} {} 0", p[0], p[1]);
    }
    s += "</DataArray></Points>\n<Cells><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for c in 0..mesh.cell_count() {
        let ids: Vec<String> = mesh.cell(c).iter().map(|n| n.to_string()).collect();
        let _ = writeln!(s, "{}", ids.join(" "));
    }
    s += "</DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    let nn = mesh.kind.node_count();
    for c in 0..mesh.cell_count() {
        let _ = writeln!(s, "{}", (c + 1) * nn);
    }
    s += "</DataArray><DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for _ in 0..mesh.cell_count() {
        let _ = writeln!(s, "{}", mesh.kind.vtk_cell_type());
    }
    s += "</DataArray></Cells>\n<PointData><DataArray type=\"Int64\" Name=\"node\" format=\"ascii\">\n";
    for n in 0..mesh.nodes.len() {
        let _ = writeln!(s, "{n}");
    }
    s += "</DataArray></PointData>\n</Piece></UnstructuredGrid></VTKFile>\n";
    s
}

/// Write the export of the case at `case_file` into the sub-folder of `out` named after the
/// case; returns that folder and the files written.
pub fn export_case(case_file: &Path, out: &ReportFolder) -> Result<(OutputFolder, Vec<String>)> {
    let (case, model) = load_case(case_file)?;
    let folder = out.run_folder(&model.name)?;
    let mut names = Vec::new();
    let meshes: Vec<(&str, &crate::mesh::Mesh)> = model
        .bodies
        .iter()
        .map(|b| (b.name.as_str(), &b.mesh))
        .collect();
    let msh_name = file_name("case name", &model.name, ".msh")?;
    let json_name = file_name("case name", &model.name, ".json")?;
    let mut files = vec![
        (msh_name, gmsh::msh(&meshes)),
        (
            json_name,
            serde_json::to_string_pretty(&sidecar(&case, &model, case_file)?)
                .expect("the sidecar serializes")
                + "\n",
        ),
    ];
    for b in &model.bodies {
        files.push((file_name("body name", &b.name, ".vtu")?, mesh_vtu(b)));
    }
    folder.write(|tmp| {
        for (name, text) in &files {
            let path = tmp.join(name);
            crate::io::paths::write_new_file(&path, text)?;
        }
        Ok(())
    })?;
    names.extend(files.into_iter().map(|(n, _)| n));
    Ok((folder, names))
}
