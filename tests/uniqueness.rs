//! One answer, or a refusal that says why: the linear algebra and the solve tell the truth.
//!
//! * A failing pivot is named by the node it belongs to in the user's numbering, on faer's
//!   simplicial and supernodal paths alike (D09).

use contact_patch::model::{parse, Model};
use contact_patch::run::{run_model, Outcome};
use contact_patch::solve::assemble;
use contact_patch::sparse::Cholesky;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::Instant;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn defect(name: &str) -> PathBuf {
    let dir = root().join("tests/defects");
    std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with(&format!("{name}-"))
        })
        .unwrap_or_else(|| panic!("no reproducer {name}"))
}

fn read(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn model(case: &Value, source: &str) -> Model {
    Model::build(&parse(&case.to_string(), source).unwrap(), source).unwrap()
}

fn solve(case: &Value, source: &str) -> contact_patch::Result<Outcome> {
    run_model(model(case, source), 0.0, Instant::now(), &mut |_| {})
}

#[test]
fn d09_names_the_unconnected_node_on_the_simplicial_path() {
    let case = read(&defect("D09"));
    let m = model(&case, "D09");
    let pattern = assemble(&m, &[]).pattern;
    assert!(!Cholesky::analyse(&pattern).unwrap().is_supernodal());
    let e = solve(&case, "D09").unwrap_err().to_string();
    assert!(e.contains("body 'beam', node 9 at (6.3, 0.18)"), "{e}");
    assert!(
        e.contains("node 9 of body 'beam' belongs to no cell"),
        "{e}"
    );
}

/// A Q4 grid `n x n` on `[0, n]^2` held at the left side, with extra nodes that belong to no
/// cell inserted at `stray` (index, coordinates).
fn grid_case(n: usize, stray: &[(usize, [f64; 2])]) -> Value {
    let mut nodes: Vec<[f64; 2]> = Vec::new();
    let mut cells: Vec<[usize; 4]> = Vec::new();
    let mut block = |x0: f64| {
        let base = nodes.len();
        for j in 0..=n {
            for i in 0..=n {
                nodes.push([x0 + i as f64, j as f64]);
            }
        }
        for j in 0..n {
            for i in 0..n {
                let a = base + j * (n + 1) + i;
                cells.push([a, a + 1, a + n + 2, a + n + 1]);
            }
        }
    };
    block(0.0);
    for &(at, p) in stray {
        nodes.insert(at, p);
        for c in &mut cells {
            c.iter_mut().filter(|v| **v >= at).for_each(|v| *v += 1);
        }
    }
    json!({
        "name": "grid",
        "materials": {"m": {"E": 1000.0, "nu": 0.3}},
        "bodies": [{"name": "plate", "material": "m",
            "mesh": {"explicit": {"element": "Q4", "nodes": nodes, "cells": cells}},
            "node_sets": {"held": {"box": {"min": [0, 0], "max": [0, n]}}}}],
        "supports": [{"body": "plate", "set": "held", "x": 0.0, "y": 0.0}],
        "loads": [{"body": "plate", "set": "top", "pressure": 1.0}]
    })
}

#[test]
fn a_failing_pivot_on_the_supernodal_path_names_its_node() {
    let case = grid_case(60, &[(1900, [20.5, 31.25])]);
    let m = model(&case, "grid");
    let pattern = assemble(&m, &[]).pattern;
    assert!(Cholesky::analyse(&pattern).unwrap().is_supernodal());
    let e = solve(&case, "grid").unwrap_err().to_string();
    assert!(e.contains("node 1900 at (20.5, 31.25)"), "{e}");
    assert!(e.contains("belongs to no cell"), "{e}");
    // the same on the simplicial path
    let case = grid_case(3, &[(5, [0.5, 1.25])]);
    let m = model(&case, "small");
    assert!(!Cholesky::analyse(&assemble(&m, &[]).pattern)
        .unwrap()
        .is_supernodal());
    let e = solve(&case, "small").unwrap_err().to_string();
    assert!(e.contains("node 5 at (0.5, 1.25)"), "{e}");
}
