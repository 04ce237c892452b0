//! Box sets say when their tolerance decides (issue 16, item 3): a node or facet taken into a
//! `box` set only because it lies within 1e-9 x the body size outside the box is named in a
//! warning (stderr and `summary.json`), with the set, the node and its distance; a box that
//! holds its nodes says nothing; a box that catches nothing is refused naming the set. A box
//! facet set that catches facets away from the side it was drawn around says so: facets in
//! separate pieces, or a turn sharper than 45 degrees between consecutive facets, are named in
//! a warning.

mod common;
use common::run_case;

use std::path::Path;
use std::process::Output;

/// The Signorini block (x in [0, 3], y in [0, 2]) with the node set `sets` and facet set
/// `facets` added, run into a scratch folder.
fn run(node_box: [[f64; 2]; 2], facet_box: [[f64; 2]; 2]) -> (Output, Option<serde_json::Value>) {
    run_edited(node_box, facet_box, |_| {})
}

/// [`run`] on the case after `edit`.
fn run_edited(
    node_box: [[f64; 2]; 2],
    facet_box: [[f64; 2]; 2],
    edit: impl FnOnce(&mut serde_json::Value),
) -> (Output, Option<serde_json::Value>) {
    let dir = tempfile::tempdir().unwrap();
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("cases/contact/signorini-block-on-rigid-line.json");
    let mut c: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    edit(&mut c);
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
    // that facet box reaches up to y = 1, so it also holds the lowest facet of each side
    // (y in [0, 0.8]), which the corner warning names
    assert_eq!(w.len(), 3, "{w:?}");
    assert!(
        w[0].contains("node_sets.tip: 1 node(s) lie outside the box"),
        "{}",
        w[0]
    );
    assert!(w[0].contains("at (3, 2), 1.000e-12 outside"), "{}", w[0]);
    assert!(w[1].contains("facet_sets.base: 9 node(s)"), "{}", w[1]);
    assert!(
        w[2].contains("facet_sets.base: the box's facets turn 2 corner(s)"),
        "{}",
        w[2]
    );
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

#[test]
fn a_box_around_the_base_that_reaches_up_the_sides_names_its_corners() {
    // the box takes the base and the lowest facet (y in [0, 0.8]) of each side
    let (o, summary) = run([[2.9, 1.9], [3.0, 2.0]], [[-1.0, -1.0], [4.0, 0.9]]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let w = warnings(&summary.unwrap());
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].contains("facet_sets.base: the box's facets turn 2 corner(s) sharper than 45 degrees"),
        "{}",
        w[0]
    );
    assert!(w[0].contains("90 degrees at (0, 0)"), "{}", w[0]);
    assert!(w[0].contains("90 degrees at (3, 0)"), "{}", w[0]);
}

#[test]
fn a_box_across_the_middle_names_its_separate_pieces() {
    // with y breaks 0, 0.8, 1.4, 2 a box over y in [0.5, 1.9] holds the middle facet of each side
    let (o, summary) = run_edited([[2.9, 1.9], [3.0, 2.0]], [[-1.0, 0.5], [4.0, 1.9]], |c| {
        c["bodies"][0]["mesh"]["block"]["y"] = serde_json::json!([0, 0.8, 1.4, 2]);
    });
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let w = warnings(&summary.unwrap());
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].contains("facet_sets.base: the box takes in 2 separate pieces of boundary"),
        "{}",
        w[0]
    );
    assert!(
        w[0].contains("1 facet(s) in [0, 0] x [0.8, 1.4]"),
        "{}",
        w[0]
    );
    assert!(
        w[0].contains("1 facet(s) in [3, 3] x [0.8, 1.4]"),
        "{}",
        w[0]
    );
}
