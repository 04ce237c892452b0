//! Contact results written for users: per pair a contact-surface `.vtu`, a CSV and a JSON file,
//! and contact point data in the body `.vtu` files (the quantities of
//! [`crate::contact::results`]).
//!
//! The same files in 2D and 3D, from one writer generic over the dimension: vectors have the
//! body's components (`x, y` or `x, y, z` in the CSV), and in 3D `shear` and `slip` are lengths
//! in the tangent plane where in 2D they are signed along `t = (-n_y, n_x)`.
//!
//! * `<pair>.contact.vtu`: the pair's surfaces (slave, and the master body's) as Line2/Line3
//!   cells in 2D, Quad4/Quad9/Tri3/Tri6 cells in 3D, at reference positions, with point data `displacement`, `normal`, `area`,
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
use crate::io::paths::file_name;
use crate::io::scene::RigidSurface;
use crate::io::vtu::{number, write_grid, PointArray};
use crate::model::space::SolidCell;
use crate::model::{MasterSide, Model};
use serde::Serialize;
use std::path::Path;

/// The columns of a pair's CSV file in `D` dimensions (2D: `side,body,node,x,y,u_x,u_y,
/// normal_x,normal_y,area,force_x,force_y,pressure,shear,gap,status,slip,plastic_slip`; 3D adds
/// the z components).
pub fn csv_header<const D: usize>() -> String {
    let axes = &["x", "y", "z"][..D];
    let vector = |name: &str| -> Vec<String> {
        axes.iter()
            .map(|a| {
                if name.is_empty() {
                    a.to_string()
                } else {
                    format!("{name}_{a}")
                }
            })
            .collect()
    };
    let mut columns: Vec<String> = ["side", "body", "node"].map(String::from).to_vec();
    columns.extend(vector(""));
    columns.extend(vector("u"));
    columns.extend(vector("normal"));
    columns.push("area".into());
    columns.extend(vector("force"));
    for c in ["pressure", "shear", "gap", "status", "slip", "plastic_slip"] {
        columns.push(c.into());
    }
    columns.join(",")
}

/// The file names of pair `name`'s results (contact `.vtu`, CSV, JSON).
pub fn pair_file_names(name: &str) -> Result<[String; 3]> {
    Ok([
        file_name("pair name", name, ".contact.vtu")?,
        file_name("pair name", name, ".contact.csv")?,
        file_name("pair name", name, ".contact.json")?,
    ])
}

/// Write the three files of every pair into `dir`.
pub fn write_pair_files<const D: usize, K: SolidCell<D>>(
    dir: &Path,
    model: &Model<D, K>,
    results: &[PairResults<D>],
) -> Result<()> {
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

/// `v` with three components (`z = 0` in 2D), as VTK wants its vectors.
fn in_3d<const D: usize>(v: [f64; D]) -> [f64; 3] {
    std::array::from_fn(|i| if i < D { v[i] } else { 0.0 })
}

fn write_surface_vtu<const D: usize>(path: &Path, r: &PairResults<D>) -> Result<()> {
    let p = &r.points;
    let points: Vec<[f64; D]> = p.iter().map(|q| q.x).collect();
    let cells: Vec<(u8, Vec<usize>)> = r
        .surfaces
        .iter()
        .flat_map(|s| s.facets.iter().map(move |f| (s.vtk_type, f.clone())))
        .collect();
    let vec3 = |f: fn(&ContactPoint<D>) -> [f64; D]| {
        p.iter().flat_map(|q| in_3d(f(q))).collect::<Vec<f64>>()
    };
    let scalar = |f: fn(&ContactPoint<D>) -> f64| p.iter().map(f).collect::<Vec<f64>>();
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

/// The CSV text of one pair (header [`csv_header`], one line per point).
pub fn csv_text<const D: usize>(r: &PairResults<D>) -> String {
    let opt = |v: Option<f64>| v.map(number).unwrap_or_default();
    let mut s = csv_header::<D>();
    s.push('\n');
    for q in &r.points {
        let side = match q.side {
            Side::Slave => "slave",
            Side::Master => "master",
        };
        let mut fields = vec![side.to_string(), q.body.clone(), q.node.to_string()];
        for v in [q.x, q.u, q.normal] {
            fields.extend(v.map(number));
        }
        fields.push(number(q.area));
        fields.extend(q.force.map(number));
        fields.extend([
            number(q.pressure),
            number(q.shear),
            opt(q.gap),
            q.status.word().to_string(),
            opt(q.slip),
            opt(q.plastic_slip),
        ]);
        s += &fields.join(",");
        s.push('\n');
    }
    s
}

#[derive(Serialize)]
struct PairFile<'a, const D: usize> {
    pair: &'a str,
    slave: &'a str,
    /// The master body's name, or `rigid line` / `rigid circle` / `rigid plane` / `rigid
    /// sphere`.
    master: String,
    totals: &'a crate::contact::results::PairTotals<D>,
    points: &'a [ContactPoint<D>],
}

fn json_value<'a, const D: usize, K: SolidCell<D>>(
    model: &'a Model<D, K>,
    r: &'a PairResults<D>,
) -> PairFile<'a, D> {
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
pub fn body_point_arrays<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    body: usize,
    results: &[PairResults<D>],
) -> Vec<PointArray> {
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
        for (c, f) in q.force.iter().enumerate() {
            force[3 * k + c] += f;
        }
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
