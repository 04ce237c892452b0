//! A case's `expected_failures`, judged like pytest's strict `xfail` by the binary: a listed
//! check that fails is an expected failure (the case passes, exit 0, the reason reported on the
//! terminal, in `summary.json` and as a JUnit `<skipped>`); a listed check that passes fails the
//! case (exit 1, "remove it from expected_failures"); a list naming a check the case does not
//! declare is bad input (exit 2). 2D and 3D cases go through the same run; `judge` judges
//! another code's results as plain checks and notes the statement. The repository's catalogues
//! of the patch test pass as they state them.

use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_contact-patch");
const PATCH_C: &str = "cases/patch/patch-C-nu0.3.json";
const REASON: &str = "node-to-surface one-pass with the punch as slave on a non-matching mesh \
                      does not pass the contact patch test (Taylor & Papadopoulos 1991)";

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn contact_patch(args: &[&str]) -> Output {
    Command::new(BIN)
        .current_dir(root())
        .args(args)
        .output()
        .unwrap()
}

fn say(o: &Output) -> String {
    format!(
        "exit {:?}\nstdout:\n{}\nstderr:\n{}",
        o.status.code(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The repository's case `case` with `expected_failures` set to `list`, written into `dir`.
fn stating(case: &str, list: Value, dir: &Path) -> PathBuf {
    let mut v: Value =
        serde_json::from_str(&std::fs::read_to_string(root().join(case)).unwrap()).unwrap();
    v["expected_failures"] = list;
    let path = dir.join(Path::new(case).file_name().unwrap());
    std::fs::write(&path, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    path
}

fn entry(check: &str) -> Value {
    json!({"check": check, "reason": REASON})
}

fn summary(folder: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(folder.join("summary.json")).unwrap()).unwrap()
}

/// The check entry of `summary.json` whose words start with `start`.
fn summary_check<'a>(s: &'a Value, start: &str) -> &'a Value {
    s["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["check"].as_str().unwrap().starts_with(start))
        .unwrap_or_else(|| panic!("no check '{start}' in {s}"))
}

/// Mesh C with one-pass node-to-surface, punch slave, fails `uniform_stress` and
/// `contact_pressure` (errors of a few per cent against 1e-10): listed, they are expected
/// failures and the case passes, everywhere its verdict is written.
#[test]
fn a_listed_check_that_fails_is_an_expected_failure_and_the_case_passes() {
    let dir = tempfile::tempdir().unwrap();
    let case = stating(
        PATCH_C,
        json!([entry("uniform_stress"), entry("contact_pressure")]),
        dir.path(),
    );
    let case = case.to_str().unwrap();
    let xml = dir.path().join("check.xml");
    let o = contact_patch(&["check", case, "--junit", xml.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", say(&o));
    let out = stdout(&o);
    assert!(
        out.contains(&format!("pass {case} (3 checks, 2 expected failures, ")),
        "{}",
        say(&o)
    );
    for check in [
        "uniform stress [0.0, -10.0, 0.0]",
        "contact pressure of 'interface'",
    ] {
        let line = out
            .lines()
            .find(|l| {
                l.trim_start()
                    .starts_with(&format!("expected failure {check}"))
            })
            .unwrap_or_else(|| panic!("{check} is not listed: {}", say(&o)));
        assert!(line.ends_with(REASON), "{line}");
    }
    assert!(
        out.contains("all 1 cases pass; 2 expected failures in 1 case"),
        "{}",
        say(&o)
    );
    // JUnit: an expected failure is skipped with its reason, not a failure
    let text = std::fs::read_to_string(&xml).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let suites = doc.root_element();
    assert_eq!(suites.attribute("failures"), Some("0"), "{text}");
    assert_eq!(suites.attribute("skipped"), Some("2"), "{text}");
    let skipped: Vec<&str> = doc
        .descendants()
        .filter(|n| n.has_tag_name("skipped"))
        .map(|n| n.attribute("message").unwrap())
        .collect();
    assert_eq!(skipped.len(), 2, "{text}");
    for message in skipped {
        assert!(message.starts_with("expected failure (error "), "{message}");
        assert!(message.ends_with(REASON), "{message}");
    }
    // run: exit 0, and summary.json records each expected failure with its reason
    let out = dir.path().join("out");
    let o = contact_patch(&["run", case, "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", say(&o));
    let s = summary(&out);
    assert_eq!(s["passed"], true, "{s}");
    let stress = summary_check(&s, "uniform stress");
    assert_eq!(stress["passed"], false, "{stress}");
    assert_eq!(
        stress["expected_failure"],
        json!({"reason": REASON, "verdict": "failed as expected"}),
        "{stress}"
    );
    let balance = summary_check(&s, "force balance");
    assert_eq!(balance["passed"], true, "{balance}");
    assert!(balance.get("expected_failure").is_none(), "{balance}");
}

/// `force_balance` passes on mesh C (5.5e-15 against 1e-12): listed as expected to fail, it
/// fails the case, saying to remove it, so that the statement cannot go stale.
#[test]
fn a_listed_check_that_passes_fails_the_case() {
    let dir = tempfile::tempdir().unwrap();
    let case = stating(
        PATCH_C,
        json!([
            entry("uniform_stress"),
            entry("contact_pressure"),
            entry("force_balance")
        ]),
        dir.path(),
    );
    let case = case.to_str().unwrap();
    let xml = dir.path().join("check.xml");
    let o = contact_patch(&["check", case, "--junit", xml.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", say(&o));
    let out = stdout(&o);
    assert!(out.contains(&format!("FAIL {case} (3 checks, 2 expected failures, ")));
    let row = out
        .lines()
        .find(|l| l.starts_with(&format!("| {case} | force balance")))
        .unwrap_or_else(|| panic!("no failure row: {}", say(&o)));
    assert!(
        row.contains(&format!(
            "<= tol 1.0e-12): expected to fail ({REASON}) but passed: remove it from \
             expected_failures"
        )),
        "{row}"
    );
    assert!(out.contains("1 of 1 cases failed"), "{}", say(&o));
    let text = std::fs::read_to_string(&xml).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    assert_eq!(
        doc.root_element().attribute("failures"),
        Some("1"),
        "{text}"
    );
    let failure = doc
        .descendants()
        .find(|n| n.has_tag_name("failure"))
        .unwrap();
    assert!(
        failure
            .attribute("message")
            .unwrap()
            .ends_with("but passed: remove it from expected_failures"),
        "{text}"
    );
    // run: exit 1, the case failed, the check's entry says why
    let out = dir.path().join("out");
    let o = contact_patch(&["run", case, "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", say(&o));
    let s = summary(&out);
    assert_eq!(s["passed"], false, "{s}");
    let balance = summary_check(&s, "force balance");
    assert_eq!(balance["passed"], true, "{balance}");
    assert_eq!(
        balance["expected_failure"]["verdict"], "passed, but expected to fail",
        "{balance}"
    );
}

/// A list that names a check the case does not declare (a misspelt kind) is bad input: exit 2,
/// with where, what and how to fix it.
#[test]
fn a_listed_kind_the_case_does_not_declare_is_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let case = stating(PATCH_C, json!([entry("uniform_strss")]), dir.path());
    let case = case.to_str().unwrap();
    let unused = dir.path().join("out");
    for args in [
        vec!["check", case],
        vec!["run", case, "--out", unused.to_str().unwrap()],
    ] {
        let o = contact_patch(&args);
        assert_eq!(o.status.code(), Some(2), "{}", say(&o));
        let all = say(&o);
        assert!(
            all.contains(
                "expected_failures[0]: the case declares no check of kind 'uniform_strss' (its \
                 checks are: uniform_stress, contact_pressure, force_balance)"
            ),
            "{all}"
        );
        assert!(
            all.contains("hint: name the kind of one of the case's checks"),
            "{all}"
        );
    }
    // a reason is required and not empty
    let case = stating(
        PATCH_C,
        json!([{"check": "uniform_stress", "reason": " "}]),
        dir.path(),
    );
    let o = contact_patch(&["check", case.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", say(&o));
    assert!(
        say(&o).contains("expected_failures[0]: the reason is empty"),
        "{}",
        say(&o)
    );
    let case = stating(PATCH_C, json!([{"check": "uniform_stress"}]), dir.path());
    let o = contact_patch(&["check", case.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", say(&o));
    assert!(say(&o).contains("missing field `reason`"), "{}", say(&o));
}

/// A 3D case runs through the same checks: the Hex8 patch test passes `uniform_stress_3d` to
/// round-off, so listing it fails the case (exit 1, in `check` and in `run`'s summary), and a
/// 2D kind it does not declare is bad input.
#[test]
fn a_3d_case_judges_its_expected_failures_the_same_way() {
    let dir = tempfile::tempdir().unwrap();
    let case = stating(
        "cases/3d/patch-hex8.json",
        json!([entry("uniform_stress_3d")]),
        dir.path(),
    );
    let case = case.to_str().unwrap();
    let o = contact_patch(&["check", case]);
    assert_eq!(o.status.code(), Some(1), "{}", say(&o));
    assert!(
        stdout(&o).contains("but passed: remove it from expected_failures"),
        "{}",
        say(&o)
    );
    let out = dir.path().join("out");
    let o = contact_patch(&["run", case, "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", say(&o));
    assert!(
        stdout(&o).contains(
            "FAIL uniform stress [0.0, 0.0, -2.0, 0.0, 0.0, 0.0] (3D: xx, yy, zz, yz, xz, xy) \
             (error"
        ),
        "{}",
        say(&o)
    );
    let s = summary(&out);
    assert_eq!(s["passed"], false, "{s}");
    assert_eq!(
        summary_check(&s, "uniform stress")["expected_failure"],
        json!({"reason": REASON, "verdict": "passed, but expected to fail"}),
        "{s}"
    );
    let case = stating(
        "cases/3d/patch-hex8.json",
        json!([entry("uniform_stress")]),
        dir.path(),
    );
    let o = contact_patch(&["check", case.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", say(&o));
    assert!(
        say(&o).contains("the case declares no check of kind 'uniform_stress' (its checks are: uniform_stress_3d)"),
        "{}",
        say(&o)
    );
}

/// `judge` judges another code's results, whose method the case does not state, as plain
/// checks: our own one-pass results on mesh C fail the patch test there (exit 1), and the
/// case's statement is printed as a note.
#[test]
fn judge_judges_listed_checks_as_plain_checks_with_a_note() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ours");
    let o = contact_patch(&["run", PATCH_C, "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", say(&o));
    let o = contact_patch(&["judge", PATCH_C, out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", say(&o));
    let text = stdout(&o);
    assert!(
        text.contains("  FAIL uniform stress [0.0, -10.0, 0.0] (error"),
        "{}",
        say(&o)
    );
    assert!(
        text.contains(
            "  note: the case expects its uniform_stress check to fail with the pair it states \
             (node-to-surface one-pass"
        ),
        "{}",
        say(&o)
    );
}

/// The repository's patch-test catalogues (2D frictionless and frictional) and 3D patch tests
/// pass `check` as their cases state them: meshes C and E fail their uniform stress (and contact
/// pressure) as expected, with the reason, and nothing else fails.
#[test]
fn the_patch_test_catalogues_pass_as_stated() {
    let o = contact_patch(&["check", "cases/patch", "cases/friction", "cases/3d"]);
    assert_eq!(o.status.code(), Some(0), "{}", say(&o));
    let text = stdout(&o);
    assert!(
        text.contains("all 69 cases pass; 16 expected failures in 10 cases"),
        "{}",
        say(&o)
    );
    for mesh in ["C", "E"] {
        for nu in ["0.0", "0.3", "0.4"] {
            assert!(
                text.contains(&format!(
                    "pass cases/patch/patch-{mesh}-nu{nu}.json (3 checks, 2 expected failures, "
                )),
                "{mesh} {nu}: {text}"
            );
        }
        for status in ["slip", "stick"] {
            assert!(
                text.contains(&format!(
                    "pass cases/friction/friction-{mesh}-{status}.json (2 checks, 1 expected \
                     failure, "
                )),
                "{mesh} {status}: {text}"
            );
        }
    }
    assert!(
        text.contains("Taylor & Papadopoulos 1991"),
        "the reason is printed: {text}"
    );
}
