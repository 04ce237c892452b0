//! Contact results written for users: per pair a contact-surface `.vtu`, a CSV and a JSON file,
//! and contact point data in the body `.vtu` files (the quantities of
//! [`crate::contact::results`]).
//!
//! * `<pair>.contact.vtu`: the pair's surfaces (slave, and the master body's) as Line2/Line3
//!   cells at reference positions, with point data `displacement`, `normal`, `area`,
//!   `contact_force`, `contact_pressure`, `contact_shear`, `contact_gap`, `contact_status`
//!   (0 unmeasured, 1 open, 2 closed, 3 stick, 4 slip), `contact_slip`, `side` (0 slave,
//!   1 master) and `node` (the body's local node number). VTK readers take no NaN in ASCII
//!   data, so an unmeasured gap or slip is written as 0: `contact_status` says which points
//!   have one (a slip only at stick and slip points: an open point has none).
//! * `<pair>.contact.csv`: one row per point, columns [`CSV_HEADER`]; an unmeasured gap or
//!   slip is an empty field (the slip of open points and of frictionless pairs too).
//! * `<pair>.contact.json`: the pair's totals and every point (`null` where unmeasured).
//! * Body `.vtu` files of a scene with contact get `contact_force`, `contact_pressure`,
//!   `contact_gap`, `contact_status` and `contact_slip`, zero away from contact surfaces; a
//!   node on the surfaces of several pairs gets the sum of their forces and pressures, the
//!   smallest measured gap, the highest status code and the slip of the last pair naming it.

use crate::contact::results::{ContactPoint, PairResults, PointStatus, Side};
use crate::error::Result;
use crate::fe::EdgeKind;
use crate::io::paths::file_name;
use crate::io::scene::RigidSurface;
use crate::io::vtu::{number, write_grid, PointArray};
use crate::model::{MasterSide, Model};
use serde::Serialize;
use std::path::Path;

/// The columns of a pair's CSV file.
pub const CSV_HEADER: &str = "side,body,node,x,y,u_x,u_y,normal_x,normal_y,area,force_x,force_y,pressure,shear,gap,status,slip,plastic_slip";

/// The file names of pair `name`'s results (contact `.vtu`, CSV, JSON).
pub fn pair_file_names(name: &str) -> Result<[String; 3]> {
    Ok([
        file_name("pair name", name, ".contact.vtu")?,
        file_name("pair name", name, ".contact.csv")?,
        file_name("pair name", name, ".contact.json")?,
    ])
}

/// Write the three files of every pair into `dir`.
pub fn write_pair_files(dir: &Path, model: &Model, results: &[PairResults]) -> Result<()> {
    for r in results {
        let [vtu, csv, json] = pair_file_names(&r.name)?;
        write_surface_vtu(&dir.join(vtu), r)?;
        let path = dir.join(csv);
        crate::io::paths::write_new_file(&path, &csv_text(r))?;
        let path = dir.join(json);
        let text = serde_json::to_string_pretty(&json_value(model, r))
            .expect("the contact results serialize");
        crate::io::paths::write_new_file(&path, &(text + "\n"))?;
    }
    Ok(())
}

fn side_code(s: Side) -> i32 {
    match s {
        Side::Slave => 0,
        Side::Master => 1,
    }
}

fn write_surface_vtu(path: &Path, r: &PairResults) -> Result<()> {
    let p = &r.points;
    let points: Vec<[f64; 2]> = p.iter().map(|q| q.x).collect();
    let cells: Vec<(u8, Vec<usize>)> = r
        .surfaces
        .iter()
        .flat_map(|s| {
            let kind = match s.kind {
                EdgeKind::Line2 => 3u8,
                EdgeKind::Line3 => 21u8,
            };
            s.facets.iter().map(move |f| (kind, f.clone()))
        })
        .collect();
    let vec3 = |f: fn(&ContactPoint) -> [f64; 2]| {
        p.iter()
            .flat_map(|q| {
                let v = f(q);
                [v[0], v[1], 0.0]
            })
            .collect::<Vec<f64>>()
    };
    let scalar = |f: fn(&ContactPoint) -> f64| p.iter().map(f).collect::<Vec<f64>>();
    let arrays = vec![
        PointArray::float("displacement", 3, vec3(|q| q.u)),
        PointArray::float("normal", 3, vec3(|q| q.normal)),
        PointArray::float("area", 1, scalar(|q| q.area)),
        PointArray::float("contact_force", 3, vec3(|q| q.force)),
        PointArray::float("contact_pressure", 1, scalar(|q| q.pressure)),
        PointArray::float("contact_shear", 1, scalar(|q| q.shear)),
        PointArray::float("contact_gap", 1, scalar(|q| q.gap.unwrap_or(0.0))),
        PointArray::int(
            "contact_status",
            p.iter().map(|q| q.status.code()).collect(),
        ),
        PointArray::float("contact_slip", 1, scalar(|q| q.slip.unwrap_or(0.0))),
        PointArray::int("side", p.iter().map(|q| side_code(q.side)).collect()),
        PointArray::int(
            "node",
            p.iter()
                .map(|q| i32::try_from(q.node).unwrap_or(i32::MAX))
                .collect(),
        ),
    ];
    write_grid(path, &points, &cells, &arrays)
}

/// The CSV text of one pair (header [`CSV_HEADER`], one line per point).
pub fn csv_text(r: &PairResults) -> String {
    let opt = |v: Option<f64>| v.map(number).unwrap_or_default();
    let mut s = String::from(CSV_HEADER);
    s.push('\n');
    for q in &r.points {
        let side = match q.side {
            Side::Slave => "slave",
            Side::Master => "master",
        };
        let fields = [
            side.to_string(),
            q.body.clone(),
            q.node.to_string(),
            number(q.x[0]),
            number(q.x[1]),
            number(q.u[0]),
            number(q.u[1]),
            number(q.normal[0]),
            number(q.normal[1]),
            number(q.area),
            number(q.force[0]),
            number(q.force[1]),
            number(q.pressure),
            number(q.shear),
            opt(q.gap),
            q.status.word().to_string(),
            opt(q.slip),
            opt(q.plastic_slip),
        ];
        s += &fields.join(",");
        s.push('\n');
    }
    s
}

#[derive(Serialize)]
struct PairFile<'a> {
    pair: &'a str,
    slave: &'a str,
    /// The master body's name, or `rigid line` / `rigid circle`.
    master: String,
    totals: &'a crate::contact::results::PairTotals,
    points: &'a [ContactPoint],
}

fn json_value<'a>(model: &'a Model, r: &'a PairResults) -> PairFile<'a> {
    let pair = &model.contact[r.pair];
    PairFile {
        pair: &r.name,
        slave: &model.bodies[pair.slave.0].name,
        master: match &pair.master {
            MasterSide::Body { body, .. } => model.bodies[*body].name.clone(),
            MasterSide::Rigid(RigidSurface::Line { .. }) => "rigid line".into(),
            MasterSide::Rigid(RigidSurface::Circle { .. }) => "rigid circle".into(),
            MasterSide::Rigid(RigidSurface::Plane { .. }) => "rigid plane".into(),
            MasterSide::Rigid(RigidSurface::Sphere { .. }) => "rigid sphere".into(),
        },
        totals: &r.totals,
        points: &r.points,
    }
}

/// The contact point data of body `body` (empty when the model has no contact pair).
pub fn body_point_arrays(model: &Model, body: usize, results: &[PairResults]) -> Vec<PointArray> {
    if model.contact.is_empty() {
        return Vec::new();
    }
    let b = &model.bodies[body];
    let n = b.mesh.nodes.len();
    let mut force = vec![0.0; 3 * n];
    let mut pressure = vec![0.0; n];
    let mut gap: Vec<Option<f64>> = vec![None; n];
    let mut status = vec![PointStatus::Unmeasured; n];
    let mut slip = vec![0.0; n];
    for q in results.iter().flat_map(|r| &r.points) {
        if q.body != b.name {
            continue;
        }
        let k = q.node;
        force[3 * k] += q.force[0];
        force[3 * k + 1] += q.force[1];
        pressure[k] += q.pressure;
        if let Some(g) = q.gap {
            gap[k] = Some(gap[k].map_or(g, |m: f64| m.min(g)));
        }
        status[k] = status[k].max(q.status);
        if let Some(s) = q.slip {
            slip[k] = s;
        }
    }
    vec![
        PointArray::float("contact_force", 3, force),
        PointArray::float("contact_pressure", 1, pressure),
        PointArray::float(
            "contact_gap",
            1,
            gap.into_iter().map(|g| g.unwrap_or(0.0)).collect(),
        ),
        PointArray::int("contact_status", status.iter().map(|s| s.code()).collect()),
        PointArray::float("contact_slip", 1, slip),
    ]
}
