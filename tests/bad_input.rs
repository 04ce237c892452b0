//! Bad input gets one clear message (what, where, how to fix it) and exit code 2: never a
//! panic, never an output folder.

use std::path::Path;
use std::process::Command;

const GOOD: &str = r#"{
  "name": "bad-input-base",
  "materials": {"m": {"E": 1000.0, "nu": 0.3}},
  "bodies": [{"name": "block", "material": "m",
              "mesh": {"block": {"element": "Q4", "x": [0, 1, 2], "y": [0, 1]}}}],
  "supports": [{"body": "block", "set": "bottom", "y": 0.0},
               {"body": "block", "set": "bottom_left", "x": 0.0}],
  "loads": [{"body": "block", "set": "top", "pressure": 1.0}],
  "checks": [{"check": "uniform_stress", "stress": [0.0, -1.0, 0.0], "tol": 1e-10}]
}"#;

/// Run `contact-patch run` on `text`; returns (exit code, stderr, whether the output exists).
fn run(text: &str) -> (i32, String, bool) {
    let dir = tempfile::tempdir().unwrap();
    let case = dir.path().join("case.json");
    std::fs::write(&case, text).unwrap();
    let out = dir.path().join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .args([
            "run",
            case.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!stderr.contains("panicked"), "panic:\n{stderr}");
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert!(
        out.exists() || leftovers.len() == 1,
        "a failed run left files behind: {leftovers:?}"
    );
    (
        o.status.code().unwrap_or(-1),
        stderr,
        Path::new(&out).join("summary.json").exists(),
    )
}

fn assert_rejected(text: &str, needles: &[&str]) {
    let (code, stderr, output) = run(text);
    assert_eq!(code, 2, "exit code for:\n{stderr}");
    assert!(!output, "an output folder was written for bad input");
    assert_eq!(
        stderr.matches("error:").count(),
        1,
        "one message expected:\n{stderr}"
    );
    assert!(stderr.contains("hint:"), "no hint:\n{stderr}");
    for n in needles {
        assert!(stderr.contains(n), "message lacks {n:?}:\n{stderr}");
    }
}

#[test]
fn the_good_case_runs() {
    let (code, stderr, output) = run(GOOD);
    assert_eq!(code, 0, "{stderr}");
    assert!(output);
}

#[test]
fn malformed_json_names_line_and_column() {
    let text = GOOD.replace("\"m\": {\"E\": 1000.0,", "\"m\": {\"E\": 1000.0");
    assert_rejected(&text, &["case.json:3:", "not valid JSON"]);
}

#[test]
fn unknown_field_is_named() {
    let text = GOOD.replace("\"nu\": 0.3", "\"nu\": 0.3, \"poisson\": 0.3");
    assert_rejected(&text, &["unknown field `poisson`", "case.json:3:"]);
}

#[test]
fn missing_set_lists_the_known_ones() {
    let text = GOOD.replace("\"set\": \"bottom\"", "\"set\": \"floor\"");
    assert_rejected(&text, &["supports[0]", "no node set 'floor'", "\"bottom\""]);
}

#[test]
fn missing_facet_set_for_a_load() {
    let text = GOOD.replace("\"set\": \"top\"", "\"set\": \"lid\"");
    assert_rejected(&text, &["loads[0]", "no facet set 'lid'"]);
}

#[test]
fn missing_material_is_named() {
    let text = GOOD.replace("\"material\": \"m\"", "\"material\": \"rubber\"");
    assert_rejected(
        &text,
        &[
            "bodies[0] 'block'.material",
            "material 'rubber' is not defined",
        ],
    );
}

#[test]
fn missing_body_is_named() {
    let text = GOOD.replace(
        "{\"body\": \"block\", \"set\": \"top\"",
        "{\"body\": \"lid\", \"set\": \"top\"",
    );
    assert_rejected(
        &text,
        &["loads[0]", "body 'lid' does not exist", "\"block\""],
    );
}

#[test]
fn inverted_element_says_which_and_where() {
    let text = GOOD.replace(
        "{\"block\": {\"element\": \"Q4\", \"x\": [0, 1, 2], \"y\": [0, 1]}}",
        "{\"explicit\": {\"element\": \"Q4\", \"nodes\": [[0,0],[1,0],[2,0],[0,1],[1,1],[2,1]], \"cells\": [[0,1,4,3],[1,4,5,2]]}}",
    );
    assert_rejected(
        &text,
        &[
            "element 1 (nodes [1, 4, 5, 2])",
            "inverted",
            "counter-clockwise",
        ],
    );
}

#[test]
fn degenerate_element_is_reported() {
    let text = GOOD.replace(
        "{\"block\": {\"element\": \"Q4\", \"x\": [0, 1, 2], \"y\": [0, 1]}}",
        "{\"explicit\": {\"element\": \"T3\", \"nodes\": [[0,0],[1,0],[2,0],[0,1]], \"cells\": [[0,1,3],[0,1,2]]}}",
    );
    assert_rejected(&text, &["element 1", "degenerate"]);
}

#[test]
fn unconstrained_body_is_explained() {
    let text = GOOD.replace(
        ",\n               {\"body\": \"block\", \"set\": \"bottom_left\", \"x\": 0.0}",
        "",
    );
    assert_rejected(
        &text,
        &[
            "body 'block'",
            "not held against rigid motion",
            "translate in x",
        ],
    );
}

#[test]
fn rotation_left_free_is_explained() {
    // u_y fixed at one node and u_x at the same node: the block can still rotate about it.
    let text = GOOD.replace(
        "\"set\": \"bottom\", \"y\": 0.0",
        "\"set\": \"bottom_left\", \"y\": 0.0",
    );
    assert_rejected(&text, &["body 'block'", "rotate"]);
}

#[test]
fn non_finite_and_out_of_range_values_are_rejected() {
    assert_rejected(
        &GOOD.replace("1000.0", "1e999"),
        &["case.json:3:", "number out of range"],
    );
    assert_rejected(
        &GOOD.replace("\"nu\": 0.3", "\"nu\": 0.5"),
        &["materials.m.nu", "(-1, 0.5)"],
    );
    assert_rejected(
        &GOOD.replace("\"E\": 1000.0", "\"E\": 0"),
        &["materials.m.E", "positive"],
    );
}

#[test]
fn missing_case_file_is_reported() {
    let o = Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .args(["run", "/nonexistent/case.json"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr.contains("/nonexistent/case.json: reading the case failed"),
        "{stderr}"
    );
}

#[test]
fn check_command_reports_failures_in_a_table() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("good.json"), GOOD).unwrap();
    // the same scene with a wrong expected stress: the check must fail
    std::fs::write(
        dir.path().join("wrong.json"),
        GOOD.replace("[0.0, -1.0, 0.0]", "[0.0, -2.0, 0.0]"),
    )
    .unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .args(["check", dir.path().to_str().unwrap()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{stdout}");
    assert!(
        stdout.contains("| case | failure |") && stdout.contains("wrong.json"),
        "{stdout}"
    );
    assert!(!stdout.contains("good.json |"), "{stdout}");
    assert!(stdout.contains("1 of 2 cases failed"), "{stdout}");

    std::fs::remove_file(dir.path().join("wrong.json")).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .args(["check", dir.path().to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
}

/// A punch on a block: contact holds the punch vertically, a support at its top-left corner
/// horizontally.
const CONTACT: &str = r#"{
  "name": "contact-base",
  "materials": {"m": {"E": 1000.0, "nu": 0.3}},
  "bodies": [{"name": "base", "material": "m", "mesh": {"block": {"element": "Q4", "x": [0, 1, 2], "y": [0, 1]}}},
             {"name": "punch", "material": "m", "mesh": {"block": {"element": "Q4", "x": [0, 1, 2], "y": [1, 2]}}}],
  "supports": [{"body": "base", "set": "bottom", "y": 0.0}, {"body": "base", "set": "bottom_left", "x": 0.0},
               {"body": "punch", "set": "top_left", "x": 0.0}],
  "loads": [{"body": "punch", "set": "top", "pressure": 1.0}],
  "contact": [{"name": "c", "slave": {"body": "punch", "set": "bottom"}, "master": {"body": "base", "set": "top"},
               "discretization": {"kind": "node_to_surface", "passes": 1}, "enforcement": {"kind": "lagrange"}}],
  "checks": [{"check": "uniform_stress", "stress": [0.0, -1.0, 0.0], "tol": 1e-10}]
}"#;

#[test]
fn the_good_contact_case_runs() {
    let (code, stderr, output) = run(CONTACT);
    assert_eq!(code, 0, "{stderr}");
    assert!(output);
}

#[test]
fn contact_with_a_missing_set_is_named() {
    let text = CONTACT.replace(
        "\"master\": {\"body\": \"base\", \"set\": \"top\"}",
        "\"master\": {\"body\": \"base\", \"set\": \"rim\"}",
    );
    assert_rejected(&text, &["contact[0] 'c'.master", "no facet set 'rim'"]);
}

/// A 2D block's side sets are geometric (the sides of its bounding box): a move that lifts
/// the base's top vertex above the rest leaves `top` without facets, which the pair refuses
/// at the set (which set, which body, why empty, how to fix), not later as a pair out of
/// reach.
#[test]
fn contact_on_an_empty_facet_set_is_named_at_the_set() {
    let text = CONTACT.replace(
        "\"x\": [0, 1, 2], \"y\": [0, 1]}",
        "\"x\": [0, 1, 2], \"y\": [0, 1], \"moves\": [{\"from\": [1, 1], \"to\": [1, 1.05]}]}",
    );
    assert_ne!(text, CONTACT);
    assert_rejected(
        &text,
        &[
            "contact[0] 'c'.master",
            "facet set 'top' of body 'base' is empty",
            "a node moved off it drops its facets",
            "\"facet_sets\"",
        ],
    );
}

#[test]
fn contact_with_an_unknown_enforcement_is_named() {
    let text = CONTACT.replace("{\"kind\": \"lagrange\"}", "{\"kind\": \"nitsche\"}");
    assert_rejected(&text, &["unknown variant `nitsche`", "case.json:"]);
}

#[test]
fn contact_with_a_bad_penalty_is_rejected() {
    let text = CONTACT.replace(
        "{\"kind\": \"lagrange\"}",
        "{\"kind\": \"penalty\", \"kappa\": -5}",
    );
    assert_rejected(
        &text,
        &["contact[0] 'c'.enforcement", "kappa must be positive"],
    );
}

#[test]
fn contact_with_a_master_that_is_neither_body_nor_rigid() {
    let text = CONTACT.replace(
        "\"master\": {\"body\": \"base\", \"set\": \"top\"}",
        "\"master\": {\"body\": \"base\"}",
    );
    assert_rejected(
        &text,
        &[
            "contact[0] 'c'.master",
            "either \"body\" and \"set\", or \"rigid\"",
        ],
    );
}

#[test]
fn a_discretization_that_does_not_apply_says_why() {
    // node-to-node on meshes whose interface nodes do not match
    let text = CONTACT
        .replace(
            "\"x\": [0, 1, 2], \"y\": [1, 2]",
            "\"x\": [0, 0.7, 2], \"y\": [1, 2]",
        )
        .replace(
            "{\"kind\": \"node_to_surface\", \"passes\": 1}",
            "{\"kind\": \"node_to_node\"}",
        );
    assert_rejected(&text, &["contact 'c'", "does not apply", "do not match"]);
}

#[test]
fn a_punch_held_only_by_frictionless_contact_is_explained() {
    let text = CONTACT.replace(
        ",\n               {\"body\": \"punch\", \"set\": \"top_left\", \"x\": 0.0}",
        "",
    );
    assert_rejected(
        &text,
        &[
            "body 'punch'",
            "even with every contact closed",
            "translate in x",
        ],
    );
}

#[test]
fn elimination_that_does_not_apply_says_why() {
    let text = CONTACT
        .replace("{\"kind\": \"lagrange\"}", "{\"kind\": \"elimination\"}")
        .replace("\"passes\": 1", "\"passes\": 2");
    assert_rejected(
        &text,
        &[
            "constraint elimination does not apply",
            "no constraint owns it",
        ],
    );
}

#[test]
fn a_pair_whose_bodies_are_out_of_reach_is_reported_not_ignored() {
    // the punch starts 1.5 above the base (facets of length 1): no candidate within reach
    let far = CONTACT.replace("\"y\": [1, 2]", "\"y\": [2.5, 3.5]");
    assert_rejected(
        &far,
        &[
            "contact 'c'",
            "no slave node lies within the search distance",
            "could never act",
        ],
    );
    // with a search distance that reaches, the case is valid (the gap stays open)
    let reach = far.replace(
        "\"enforcement\": {\"kind\": \"lagrange\"}",
        "\"enforcement\": {\"kind\": \"lagrange\"}, \"search_distance\": 2.0",
    );
    let (code, stderr, _) = run(&reach);
    assert_ne!(code, 2, "{stderr}");
    assert_rejected(
        &reach.replace("\"search_distance\": 2.0", "\"search_distance\": -1"),
        &["search_distance", "must be positive"],
    );
}

/// Defect W04 (second report): one node at (1000, 1000) used by no cell became the whole
/// built-in `top` set; the compression prescribed there moved only it, and the run ended
/// `Converged` in 0 iterations with every check passing (contact force 0 where the control,
/// W04b, carries 537). The sets chosen by position now ignore it, and the node, which has no
/// stiffness, is named by the solve's zero pivot (as an unconnected node is, defect D09):
/// exit 2, never a converged answer.
#[test]
fn a_node_used_by_no_cell_is_named_not_selected() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/defects/s4/W04a-stray-node-moves-top-set.json");
    let (code, stderr, _) = run(&std::fs::read_to_string(path).unwrap());
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("node 16 at (1000, 1000)"), "{stderr}");
    let control = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/defects/s4/W04b-control-without-stray-node.json");
    let (code, stderr, _) = run(&std::fs::read_to_string(control).unwrap());
    assert_eq!(code, 0, "{stderr}");
}
