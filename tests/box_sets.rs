//! Box sets say when their tolerance decides (issue 16, item 3): a node or facet taken into a
//! `box` set only because it lies within 1e-9 x the body size outside the box is named in a
//! warning (stderr and `summary.json`), with the set, the node and its distance; a box that
//! holds its nodes says nothing; a box that catches nothing is refused naming the set.

mod common;
use common::run_case;

use std::path::Path;
use std::process::Output;

/// The Signorini block (x in [0, 3], y in [0, 2]) with the node set `sets` and facet set
/// `facets` added, run into a scratch folder.
fn run(node_box: [[f64; 2]; 2], facet_box: [[f64; 2]; 2]) -> (Output, Option<serde_json::Value>) {
    let dir = tempfile::tempdir().unwrap();
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("cases/contact/signorini-block-on-rigid-line.json");
    let mut c: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    c["bodies"][0]["node_sets"] =
        serde_json::json!({"tip": {"box": {"min": node_box[0], "max": node_box[1]}}});
    c["bodies"][0]["facet_sets"] =
        serde_json::json!({"base": {"box": {"min": facet_box[0], "max": facet_box[1]}}});
    let case = dir.path().join("case.json");
    std::fs::write(&case, c.to_string()).unwrap();
    let out = dir.path().join("out");
    let o = run_case(&case, &out);
    let summary = std::fs::read_to_string(out.join("summary.json"))
        .ok()
        .map(|t| serde_json::from_str(&t).unwrap());
    (o, summary)
}

fn warnings(summary: &serde_json::Value) -> Vec<String> {
    summary["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap().to_string())
        .collect()
}

#[test]
fn a_box_that_holds_its_nodes_says_nothing() {
    let (o, summary) = run([[2.9, 1.9], [3.0, 2.0]], [[0.0, 0.0], [3.0, 0.0]]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(warnings(&summary.unwrap()).is_empty());
}

#[test]
fn a_box_widened_by_its_tolerance_is_named_in_a_warning() {
    // the corner (3, 2) lies 1e-12 outside the node box; the base's nodes 1e-12 above the
    // facet box (tolerance 1e-9 x 3)
    let (o, summary) = run([[2.9, 1.9], [3.0 - 1e-12, 2.0]], [[0.0, 1e-12], [3.0, 1.0]]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let w = warnings(&summary.unwrap());
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].contains("node_sets.tip: 1 node(s) lie outside the box"),
        "{}",
        w[0]
    );
    assert!(w[0].contains("at (3, 2), 1.000e-12 outside"), "{}", w[0]);
    assert!(w[1].contains("facet_sets.base: 9 node(s)"), "{}", w[1]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("warning: ") && stderr.contains("node_sets.tip"),
        "{stderr}"
    );
}

#[test]
fn a_box_that_catches_nothing_is_refused_naming_the_set() {
    let (o, summary) = run([[5.0, 5.0], [6.0, 6.0]], [[0.0, 0.0], [3.0, 0.0]]);
    assert_eq!(o.status.code(), Some(2));
    assert!(summary.is_none());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("node_sets.tip") && stderr.contains("selects no node"),
        "{stderr}"
    );
}
