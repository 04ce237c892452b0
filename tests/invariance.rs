//! Invariance and determinism of the answers:
//! * units: the contact patch test (mesh C, Lagrange multipliers and penalty) in SI (m, N, Pa,
//!   E = 2e11) and in mm-N-MPa gives the same displacements after conversion
//!   (`u_mm = 1e3 u_m`) to 1e-12 of the largest;
//! * numbering: the same two meshes written as explicit meshes with their nodes and cells
//!   renumbered by a permutation (and each cell's node list rotated) give the same displacement
//!   at every node (matched by its coordinates) to 1e-12 of the largest;
//! * determinism: two runs of one case write bit-identical `.vtu` files and `summary.json`
//!   files that differ only in their timings.

use contact_patch::model::{parse, Model};
use contact_patch::run::run_model;
use serde_json::{json, Value};
use std::path::Path;
use std::process::Command;
use std::time::Instant;

const CASE: &str = "cases/patch/patch-C-nu0.3.json";

fn patch_c() -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(CASE);
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    v.as_object_mut().unwrap().remove("sweep");
    v["checks"] = json!([]);
    // the case's expected failures name the checks removed here
    v.as_object_mut().unwrap().remove("expected_failures");
    v
}

/// A node: its body and coordinates (bodies touch, so coordinates alone do not name it).
type Node = (usize, [f64; 2]);

/// Run a case given as JSON; the displacement of every node of every body with its body and
/// coordinates.
fn solve(v: &Value) -> Vec<(Node, [f64; 2])> {
    let path = format!("{}/{CASE}", env!("CARGO_MANIFEST_DIR"));
    let case = parse(&v.to_string(), &path).unwrap();
    let model = Model::build(&case, &path).unwrap();
    let o = run_model(model, 0.0, Instant::now(), &mut |_| {}).unwrap();
    assert_eq!(
        o.solution.contact.as_ref().unwrap().termination,
        contact_patch::contact::state::Termination::Converged
    );
    let mut out = Vec::new();
    for (k, b) in o.model.bodies.iter().enumerate() {
        for (n, p) in b.mesh.nodes.iter().enumerate() {
            out.push((
                (k, *p),
                [o.solution.u[b.dof(n, 0)], o.solution.u[b.dof(n, 1)]],
            ));
        }
    }
    out
}

fn scale_list(v: &mut Value, s: f64) {
    for x in v.as_array_mut().unwrap() {
        *x = json!(x.as_f64().unwrap() * s);
    }
}

/// The case in other units: lengths times `length`, stresses (E, pressures, kappa times
/// length) times `stress`.
fn rescaled(v: &Value, length: f64, stress: f64) -> Value {
    let mut v = v.clone();
    v["analysis"]["thickness"] = json!(v["analysis"]["thickness"].as_f64().unwrap() * length);
    for m in v["materials"].as_object_mut().unwrap().values_mut() {
        m["E"] = json!(m["E"].as_f64().unwrap() * stress);
    }
    for b in v["bodies"].as_array_mut().unwrap() {
        scale_list(&mut b["mesh"]["block"]["x"], length);
        scale_list(&mut b["mesh"]["block"]["y"], length);
        if let Some(sets) = b.get_mut("facet_sets") {
            for set in sets.as_object_mut().unwrap().values_mut() {
                scale_list(&mut set["box"]["min"], length);
                scale_list(&mut set["box"]["max"], length);
            }
        }
    }
    for l in v["loads"].as_array_mut().unwrap() {
        l["pressure"] = json!(l["pressure"].as_f64().unwrap() * stress);
    }
    scale_list(&mut v["exact"]["stress"], stress);
    let e = &mut v["contact"][0]["enforcement"];
    if let Some(k) = e.get("kappa").and_then(Value::as_f64) {
        e["kappa"] = json!(k * stress / length);
    }
    v
}

fn largest(u: &[(Node, [f64; 2])]) -> f64 {
    u.iter()
        .flat_map(|(_, d)| d.iter())
        .fold(0.0f64, |m, v| m.max(v.abs()))
}

#[test]
fn si_and_mm_n_mpa_give_the_same_answer() {
    for enforcement in [
        json!({"kind": "lagrange"}),
        json!({"kind": "penalty", "kappa": 10.0}),
        json!({"kind": "elimination"}),
    ] {
        let mut base = patch_c();
        base["contact"][0]["enforcement"] = enforcement.clone();
        // SI: E = 2e11 Pa, p = 2e9 Pa, lengths in m (the catalogue's numbers times 2e8)
        let si = rescaled(&base, 1.0, 2e8);
        // mm-N-MPa: lengths 1e3 times, stresses 1e-6 times
        let mm = rescaled(&si, 1e3, 1e-6);
        let (u_si, u_mm) = (solve(&si), solve(&mm));
        let scale = largest(&u_mm);
        assert!(scale > 0.0);
        let mut worst = 0.0f64;
        for (((_, p), a), ((_, q), b)) in u_si.iter().zip(&u_mm) {
            assert!((p[0] * 1e3 - q[0]).abs() <= 1e-9 && (p[1] * 1e3 - q[1]).abs() <= 1e-9);
            for k in 0..2 {
                worst = worst.max((a[k] * 1e3 - b[k]).abs() / scale);
            }
        }
        assert!(worst <= 1e-12, "{enforcement}: {worst:e}");
    }
}

/// A block mesh as an explicit one: nodes at the breaks, Q4 cells counter-clockwise, then
/// nodes renumbered by `node_order` (a permutation generator) and cells listed in reverse with
/// their node lists rotated by `rotate`.
fn explicit(xs: &[f64], ys: &[f64], permute: bool) -> Value {
    let (nx, ny) = (xs.len(), ys.len());
    let count = nx * ny;
    // new id of the node (i, j): a stride permutation (coprime with the count)
    let stride = (2..count)
        .find(|s| gcd(*s, count) == 1 && *s > count / 3)
        .unwrap();
    let id = |i: usize, j: usize| {
        let k = j * nx + i;
        if permute {
            (k * stride + 3) % count
        } else {
            k
        }
    };
    let mut nodes = vec![[0.0; 2]; count];
    for j in 0..ny {
        for i in 0..nx {
            nodes[id(i, j)] = [xs[i], ys[j]];
        }
    }
    let mut cells = Vec::new();
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            let mut c = vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            if permute {
                c.rotate_left((i + 2 * j) % 4);
            }
            cells.push(c);
        }
    }
    if permute {
        cells.reverse();
    }
    json!({"explicit": {"element": "Q4", "nodes": nodes, "cells": cells}})
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

fn as_explicit(v: &Value, permute: bool) -> Value {
    let mut v = v.clone();
    for b in v["bodies"].as_array_mut().unwrap() {
        let list = |a: &Value| -> Vec<f64> {
            a.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect()
        };
        let (xs, ys) = (
            list(&b["mesh"]["block"]["x"]),
            list(&b["mesh"]["block"]["y"]),
        );
        b["mesh"] = explicit(&xs, &ys, permute);
    }
    v
}

#[test]
fn renumbering_nodes_and_cells_gives_the_same_answer() {
    for enforcement in [
        json!({"kind": "lagrange"}),
        json!({"kind": "penalty", "kappa": 1e4}),
        json!({"kind": "augmented_lagrange", "kappa": 1e4, "update": "per_iteration"}),
    ] {
        for discretization in [
            json!({"kind": "node_to_surface", "passes": 1}),
            json!({"kind": "mortar", "multiplier": "dual"}),
        ] {
            let mut base = patch_c();
            base["contact"][0]["enforcement"] = enforcement.clone();
            base["contact"][0]["discretization"] = discretization.clone();
            let plain = solve(&as_explicit(&base, false));
            let renumbered = solve(&as_explicit(&base, true));
            assert_eq!(plain.len(), renumbered.len());
            let scale = largest(&plain);
            let mut worst = 0.0f64;
            for (p, a) in &plain {
                let (_, b) = renumbered
                    .iter()
                    .find(|(q, _)| q == p)
                    .expect("the same node");
                for k in 0..2 {
                    worst = worst.max((a[k] - b[k]).abs() / scale);
                }
            }
            assert!(worst <= 1e-12, "{enforcement} {discretization}: {worst:e}");
            // the renumbering really changed the numbering
            assert!(plain.iter().zip(&renumbered).any(|(a, b)| a.0 != b.0));
        }
    }
}

/// `summary.json` without its timings: the `timings` object, every `seconds` and `share`.
fn without_timings(v: &mut Value) {
    match v {
        Value::Object(m) => {
            m.remove("timings");
            m.remove("seconds");
            m.remove("share");
            m.values_mut().for_each(without_timings);
        }
        Value::Array(a) => a.iter_mut().for_each(without_timings),
        _ => {}
    }
}

#[test]
fn a_rerun_writes_identical_files() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    for case in [
        "cases/hard/curved-master-cylinder.json",
        "cases/hard/penalty-1e9-E-over-h.json",
        "cases/contact/coulomb-patch-slip.json",
    ] {
        let mut outputs = Vec::new();
        for run in 0..2 {
            let out = dir.path().join(format!("run{run}"));
            let o = Command::new(env!("CARGO_BIN_EXE_contact-patch"))
                .arg("run")
                .arg(root.join(case))
                .arg("--out")
                .arg(&out)
                .output()
                .unwrap();
            assert!(o.status.code().unwrap() <= 1, "{case}: {o:?}");
            let mut files: Vec<_> = std::fs::read_dir(&out)
                .unwrap()
                .map(|e| e.unwrap().path())
                .collect();
            files.sort();
            let contents: Vec<(String, Vec<u8>)> = files
                .iter()
                .map(|f| {
                    (
                        f.file_name().unwrap().to_string_lossy().into_owned(),
                        std::fs::read(f).unwrap(),
                    )
                })
                .collect();
            outputs.push(contents);
        }
        assert_eq!(outputs[0].len(), outputs[1].len());
        for ((name, a), (other, b)) in outputs[0].iter().zip(&outputs[1]) {
            assert_eq!(name, other);
            if name == "summary.json" {
                let (mut x, mut y): (Value, Value) = (
                    serde_json::from_slice(a).unwrap(),
                    serde_json::from_slice(b).unwrap(),
                );
                without_timings(&mut x);
                without_timings(&mut y);
                assert_eq!(x, y, "{case}: summary.json differs beyond its timings");
            } else if name.ends_with(".vtu") {
                assert!(a == b, "{case}: {name} differs between two runs");
            }
        }
        assert!(
            outputs[0].iter().any(|(n, _)| n.ends_with(".vtu")),
            "{case}: no .vtu written"
        );
    }
}
