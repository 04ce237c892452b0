//! CI-friendly outputs (issue 17, item 3): `--junit FILE` on `check` and `table`, parsed back
//! with a standard XML parser (roxmltree), and `table --baseline OLD.json`.

use std::path::Path;
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_contact-patch");
const PATCH_CASE: &str = "cases/patch/patch-B-nu0.3.json";

fn run(args: &[&str]) -> Output {
    Command::new(BIN)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .unwrap()
}

fn code(o: &Output) -> i32 {
    o.status.code().unwrap()
}

fn say(o: &Output) -> String {
    format!(
        "exit {:?}\nstdout:\n{}\nstderr:\n{}",
        o.status.code(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn attr(node: roxmltree::Node, name: &str) -> usize {
    node.attribute(name)
        .unwrap_or_else(|| panic!("no {name} on {node:?}"))
        .parse()
        .unwrap()
}

/// The counts of a `<testsuite>` or `<testsuites>` as written, after checking them against its
/// test cases: (tests, failures, errors, skipped).
fn counts(node: roxmltree::Node) -> (usize, usize, usize, usize) {
    let cases: Vec<_> = node
        .descendants()
        .filter(|n| n.has_tag_name("testcase"))
        .collect();
    let with = |tag: &str| {
        cases
            .iter()
            .filter(|c| c.children().any(|k| k.has_tag_name(tag)))
            .count()
    };
    let written = (
        attr(node, "tests"),
        attr(node, "failures"),
        attr(node, "errors"),
        attr(node, "skipped"),
    );
    assert_eq!(
        written,
        (cases.len(), with("failure"), with("error"), with("skipped")),
        "the counts of {:?} disagree with its test cases",
        node.attribute("name")
    );
    for c in &cases {
        assert!(c.attribute("classname").is_some_and(|s| !s.is_empty()));
        assert!(c.attribute("name").is_some_and(|s| !s.is_empty()));
        let t: f64 = c.attribute("time").unwrap().parse().unwrap();
        assert!(t >= 0.0);
    }
    written
}

#[test]
fn check_writes_junit_with_one_test_case_per_check() {
    let scratch = tempfile::tempdir().unwrap();
    let xml_path = scratch.path().join("check.xml");
    let o = run(&[
        "check",
        "cases/patch-single",
        "--junit",
        xml_path.to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 0, "{}", say(&o));
    let text = std::fs::read_to_string(&xml_path).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let root = doc.root_element();
    assert!(root.has_tag_name("testsuites"));
    let suites: Vec<_> = root
        .children()
        .filter(|n| n.has_tag_name("testsuite"))
        .collect();
    let cases = std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/patch-single"))
        .unwrap()
        .count();
    assert_eq!(suites.len(), cases);
    // the number of checks `check` prints per case, "(N checks, ...)"
    let stdout = String::from_utf8_lossy(&o.stdout);
    let printed: usize = stdout
        .lines()
        .filter_map(|l| {
            l.split(" (")
                .nth(1)?
                .split(" checks")
                .next()?
                .parse::<usize>()
                .ok()
        })
        .sum();
    assert!(printed >= cases, "{stdout}");
    assert_eq!(counts(root), (printed, 0, 0, 0));
    for s in suites {
        counts(s);
    }
    // nothing else written beside the file
    assert_eq!(std::fs::read_dir(scratch.path()).unwrap().count(), 1);
}

#[test]
fn a_failing_check_is_a_failure_with_error_and_tol_and_a_broken_case_an_error() {
    let scratch = tempfile::tempdir().unwrap();
    let cases = scratch.path().join("cases");
    std::fs::create_dir(&cases).unwrap();
    let original = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/patch-single/q4-distorted.json"),
    )
    .unwrap();
    let mut case: serde_json::Value = serde_json::from_str(&original).unwrap();
    case["checks"][0]["tol"] = serde_json::json!(1e-30);
    std::fs::write(
        cases.join("strict.json"),
        serde_json::to_string_pretty(&case).unwrap(),
    )
    .unwrap();
    let xml_path = scratch.path().join("check.xml");
    let o = run(&[
        "check",
        cases.to_str().unwrap(),
        "--junit",
        xml_path.to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 1, "{}", say(&o));
    let text = std::fs::read_to_string(&xml_path).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let (tests, failures, errors, _) = counts(doc.root_element());
    assert_eq!((failures, errors), (1, 0), "{text}");
    assert!(tests > 1);
    let failure = doc
        .descendants()
        .find(|n| n.has_tag_name("failure"))
        .unwrap();
    let message = failure.attribute("message").unwrap();
    assert!(
        message.contains("error ") && message.contains("tol 1.0e-30"),
        "{message}"
    );
    let body = failure.text().unwrap();
    assert!(body.contains("tolerance: 1e-30"), "{body}");

    // a case that cannot run is an <error> (and the exit code 2)
    std::fs::write(cases.join("broken.json"), "{ \"name\": <oops> }").unwrap();
    let o = run(&[
        "check",
        cases.to_str().unwrap(),
        "--junit",
        xml_path.to_str().unwrap(),
    ]);
    assert_eq!(code(&o), 2, "{}", say(&o));
    let text = std::fs::read_to_string(&xml_path).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let (_, failures, errors, _) = counts(doc.root_element());
    assert_eq!((failures, errors), (1, 1), "{text}");
    let error = doc.descendants().find(|n| n.has_tag_name("error")).unwrap();
    assert!(
        error.attribute("message").unwrap().contains("broken.json"),
        "{text}"
    );
}

#[test]
fn junit_paths_that_are_folders_or_in_missing_folders_are_refused_before_any_work() {
    let scratch = tempfile::tempdir().unwrap();
    let missing = scratch.path().join("no/such/junit.xml");
    for target in [scratch.path().to_path_buf(), missing] {
        let o = run(&[
            "check",
            "cases/patch-single/q4-distorted.json",
            "--junit",
            target.to_str().unwrap(),
        ]);
        assert_eq!(code(&o), 2, "{}", say(&o));
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("--junit") && err.contains("hint"), "{err}");
        assert!(String::from_utf8_lossy(&o.stdout).is_empty(), "{}", say(&o));
    }
    assert_eq!(std::fs::read_dir(scratch.path()).unwrap().count(), 0);
}

/// `table` on one patch case into `out`, with extra arguments.
fn table(out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["table", PATCH_CASE, "--out", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    run(&args)
}

#[test]
fn table_writes_junit_with_one_test_case_per_cell() {
    let scratch = tempfile::tempdir().unwrap();
    let out = scratch.path().join("reports");
    let xml_path = scratch.path().join("table.xml");
    let o = table(&out, &["--junit", xml_path.to_str().unwrap()]);
    assert_eq!(code(&o), 0, "{}", say(&o));
    let cells: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(out.join("patch-table.json")).unwrap())
            .unwrap();
    let verdicts = |v: &str| cells.iter().filter(|c| c["verdict"] == v).count();
    let text = std::fs::read_to_string(&xml_path).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let suites: Vec<_> = doc
        .root_element()
        .children()
        .filter(|n| n.has_tag_name("testsuite"))
        .collect();
    assert_eq!(suites.len(), 1);
    assert_eq!(suites[0].attribute("name"), Some("patch"));
    let written = counts(suites[0]);
    assert_eq!(
        written,
        (cells.len(), verdicts("fail"), 0, verdicts("n/a")),
        "{text}"
    );
    // this case has cells of every kind
    assert!(written.1 > 0 && written.3 > 0 && written.0 > written.1 + written.3);
    let failure = doc
        .descendants()
        .find(|n| n.has_tag_name("failure"))
        .unwrap();
    let message = failure.attribute("message").unwrap();
    assert!(
        message.contains("stress error") && message.contains("tol 1.0e-"),
        "{message}"
    );
    let names: std::collections::BTreeSet<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("testcase"))
        .map(|n| n.attribute("name").unwrap().to_string())
        .collect();
    assert_eq!(names.len(), cells.len(), "test case names are not unique");
}

/// The name `--baseline` prints for a cell of a table file.
fn cell_name(c: &serde_json::Value) -> String {
    let mut s = format!(
        "{} {} nu={} {}",
        c["catalogue"].as_str().unwrap(),
        c["mesh"].as_str().unwrap(),
        c["nu"].as_f64().unwrap(),
        c["discretization"].as_str().unwrap()
    );
    if let Some(p) = c["passes"].as_u64() {
        s += &format!(" {p}-pass");
    }
    if let Some(slave) = c["slave"].as_str() {
        s += &format!(" slave={slave}");
    }
    s + " " + c["enforcement"].as_str().unwrap()
}

#[test]
fn baseline_mode_passes_against_itself_and_fails_on_a_regression() {
    let scratch = tempfile::tempdir().unwrap();
    let first = scratch.path().join("first");
    let o = table(&first, &[]);
    assert_eq!(code(&o), 0, "{}", say(&o));
    let old_path = first.join("patch-table.json");
    let old_text = std::fs::read_to_string(&old_path).unwrap();

    // against its own output: no regression
    let second = scratch.path().join("second");
    let o = table(&second, &["--baseline", old_path.to_str().unwrap()]);
    assert_eq!(code(&o), 0, "{}", say(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("0 regressions"), "{stdout}");

    let cells: Vec<serde_json::Value> = serde_json::from_str(&old_text).unwrap();
    // a cell that fails now, said to pass in the baseline: a lost verdict
    let mut flipped = cells.clone();
    let i = flipped.iter().position(|c| c["verdict"] == "fail").unwrap();
    flipped[i]["verdict"] = "pass".into();
    let edited = scratch.path().join("flipped.json");
    std::fs::write(&edited, serde_json::to_string(&flipped).unwrap()).unwrap();
    let o = table(&second, &["--baseline", edited.to_str().unwrap()]);
    assert_eq!(code(&o), 1, "{}", say(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    let row = stdout
        .lines()
        .find(|l| l.contains("REGRESSION"))
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!(
        row.contains(&cell_name(&cells[i])) && row.contains("| pass | fail |"),
        "{row}"
    );
    assert_eq!(stdout.matches("REGRESSION").count(), 1, "{stdout}");

    // an error a million times smaller in the baseline: the new one grew
    let mut shrunk = cells.clone();
    let j = shrunk
        .iter()
        .position(|c| c["stress_error"].as_f64().is_some_and(|e| e > 1e-3))
        .unwrap();
    let e = shrunk[j]["stress_error"].as_f64().unwrap();
    shrunk[j]["stress_error"] = (e / 1e6).into();
    std::fs::write(&edited, serde_json::to_string(&shrunk).unwrap()).unwrap();
    let o = table(&second, &["--baseline", edited.to_str().unwrap()]);
    assert_eq!(code(&o), 1, "{}", say(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    let row = stdout
        .lines()
        .find(|l| l.contains("REGRESSION"))
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!(
        row.contains(&cell_name(&cells[j])) && row.contains("stress_error grew"),
        "{row}"
    );
    // with a factor above the change it is no regression
    let o = table(
        &second,
        &[
            "--baseline",
            edited.to_str().unwrap(),
            "--baseline-factor",
            "1e7",
        ],
    );
    assert_eq!(code(&o), 0, "{}", say(&o));

    // an improvement (the baseline's error a million times larger) is reported, not failed
    let mut grown = cells.clone();
    grown[j]["stress_error"] = (e * 1e6).into();
    std::fs::write(&edited, serde_json::to_string(&grown).unwrap()).unwrap();
    let o = table(&second, &["--baseline", edited.to_str().unwrap()]);
    assert_eq!(code(&o), 0, "{}", say(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("improvement: stress_error fell"));

    // a baseline cell of a case the run covers that the new table lacks (as if its method had
    // been dropped from the sweep)
    let mut extra = cells.clone();
    let mut ghost = cells[0].clone();
    ghost["enforcement"] = "retired_method".into();
    extra.push(ghost.clone());
    std::fs::write(&edited, serde_json::to_string(&extra).unwrap()).unwrap();
    let o = table(&second, &["--baseline", edited.to_str().unwrap()]);
    assert_eq!(code(&o), 1, "{}", say(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains(&format!(
        "| {} | REGRESSION: cell missing from the new table |",
        cell_name(&ghost)
    )));
}

#[test]
fn a_malformed_or_missing_baseline_is_bad_input() {
    let scratch = tempfile::tempdir().unwrap();
    let out = scratch.path().join("reports");
    let bad = scratch.path().join("bad.json");
    let missing = scratch.path().join("missing.json");
    std::fs::write(&bad, "[{\"catalogue\": \"patch\", \"case\": 3}]").unwrap();
    let not_cells = scratch.path().join("summary.json");
    std::fs::write(&not_cells, "{\"name\": \"x\"}").unwrap();
    for path in [&bad, &missing, &not_cells] {
        let o = table(&out, &["--baseline", path.to_str().unwrap()]);
        assert_eq!(code(&o), 2, "{}", say(&o));
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.contains(path.file_name().unwrap().to_str().unwrap()),
            "{err}"
        );
        assert!(err.contains("baseline"), "{err}");
        // refused before any work: no table written
        assert!(!out.exists());
    }
    let o = table(
        &out,
        &[
            "--baseline-factor",
            "0.5",
            "--baseline",
            bad.to_str().unwrap(),
        ],
    );
    assert_eq!(code(&o), 2, "{}", say(&o));
}
