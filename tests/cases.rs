//! Every case under `cases/` runs and passes the checks it declares (a check the case lists in
//! `expected_failures` must fail, and does), except the size benchmarks in `cases/large/` and
//! the refinement study `cases/friction-bench/` (its finer levels take minutes), judged against
//! the closed forms by `tests/cattaneo.rs`. The patch-test catalogues `cases/patch/` and
//! `cases/friction/` run their pairs as written here (meshes C and E state their expected
//! failures); their sweeps are judged cell by cell in the snapshot-tested tables
//! (`tests/patch_table.rs`, `tests/friction_table.rs`). A case without checks is itself a
//! failure: it could not fail.

use contact_patch::run::{run_case, run_checked};
use std::path::{Path, PathBuf};

fn case_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            if p.file_name()
                .is_some_and(|n| n == "large" || n == "friction-bench")
            {
                continue;
            }
            case_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "json")
            && !p.to_string_lossy().ends_with(".schema.json")
            && !p.to_string_lossy().ends_with(".study.json")
        {
            out.push(p);
        }
    }
}

#[test]
fn every_case_passes_its_checks() {
    let mut files = Vec::new();
    case_files(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("cases"),
        &mut files,
    );
    assert!(
        files.len() >= 10,
        "expected the catalogue under cases/, found {files:?}"
    );
    let mut failures = Vec::new();
    for f in &files {
        // 2D and 3D cases alike (`contact-patch check` runs them the same way)
        match run_checked(f, &mut |_| {}) {
            Ok(o) => {
                if o.checks.is_empty() {
                    failures.push(format!("{}: declares no checks", f.display()));
                }
                for c in o.checks.iter().filter(|c| c.fails_the_case()) {
                    failures.push(format!("{}: {}", f.display(), c.report_line()));
                }
            }
            Err(e) => failures.push(format!("{}: {e}", f.display())),
        }
    }
    assert!(
        failures.is_empty(),
        "failing cases:\n{}",
        failures.join("\n")
    );
}

/// The single-body patch tests reproduce the exact uniform stress to 1e-10 relative on
/// distorted Q4, Q9, T3 and T6 meshes; this pins that each of them is in the catalogue and
/// that its stress check is that strict.
#[test]
fn patch_tests_cover_every_element_at_round_off() {
    for element in ["q4", "q9", "t3", "t6"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join(format!("cases/patch-single/{element}-distorted.json"));
        let o = run_case(&path, &mut |_| {}).unwrap();
        let stress = o
            .checks
            .iter()
            .find(|c| c.check.starts_with("uniform stress"))
            .expect("a uniform stress check");
        assert!(
            stress.tol <= 1e-10 && stress.passed,
            "{element}: {stress:?}"
        );
        assert!(
            stress.error < 1e-12,
            "{element}: stress error {} is not round-off",
            stress.error
        );
    }
}
