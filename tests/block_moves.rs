//! `moves` of a block's mid-side and centre nodes (issue 16, item 3): an isoparametric Q9 patch
//! with a curved interior side and a shifted centre still represents the linear field exactly,
//! so the single-body patch test holds to round-off; a move that folds an element over is
//! refused with the element named.

mod common;
use common::run_case;

use serde_json::{json, Value};
use std::path::Path;

/// `cases/patch-single/q9-distorted.json` with `extra` moves appended, written into `dir`.
fn q9_patch_with(extra: Value, dir: &Path) -> std::path::PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/patch-single/q9-distorted.json");
    let mut c: Value = serde_json::from_str(&std::fs::read_to_string(src).unwrap()).unwrap();
    let moves = c["bodies"][0]["mesh"]["block"]["moves"]
        .as_array_mut()
        .unwrap();
    moves.extend(extra.as_array().unwrap().iter().cloned());
    let path = dir.join("case.json");
    std::fs::write(&path, c.to_string()).unwrap();
    path
}

#[test]
fn a_curved_interior_side_and_a_shifted_centre_keep_the_patch_test_exact() {
    let dir = tempfile::tempdir().unwrap();
    // the interior side from (0.62, 0.55) to (1.32, 0.82) has its mid-side node at (0.97, 0.685);
    // the first cell's centre is the mean of (0, 0), (0.5, 0), (0.62, 0.55), (0, 0.7)
    let case = q9_patch_with(
        json!([
            {"from": [0.97, 0.685], "to": [0.97, 0.76]},
            {"from": [0.28, 0.3125], "to": [0.31, 0.29]}
        ]),
        dir.path(),
    );
    let out = dir.path().join("out");
    let o = run_case(&case, &out);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    // the checks of the case (uniform stress and exact displacement to 1e-10) all passed
    assert!(!stdout.contains("FAIL"), "{stdout}");
    assert_eq!(stdout.matches("  pass ").count(), 3, "{stdout}");
    // and the moved node is where the case put it
    let vtu = std::fs::read_to_string(out.join("patch.vtu")).unwrap();
    assert!(vtu.contains("0.97 0.76 0"), "moved node not in the mesh");
}

#[test]
fn a_node_move_that_folds_an_element_is_refused_and_a_move_from_nowhere_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let case = q9_patch_with(
        json!([{"from": [0.97, 0.685], "to": [0.97, 3.0]}]),
        dir.path(),
    );
    let o = run_case(&case, &dir.path().join("out"));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("invert") || stderr.contains("Jacobian"),
        "{stderr}"
    );

    let case = q9_patch_with(json!([{"from": [0.9, 0.9], "to": [1.0, 1.0]}]), dir.path());
    let o = run_case(&case, &dir.path().join("out2"));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("(0.9, 0.9)") && stderr.contains("no node"),
        "{stderr}"
    );
}
