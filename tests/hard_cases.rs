//! The stability suite: every hard case under `cases/hard/` meets the outcome it states (a
//! converged answer that passes its closed-form checks, or a named stop with its diagnosis),
//! no stiff penalty converges in silence with lost digits, and the report
//! (`contact-patch hard`, `reports/hard-cases.md`) is a reviewed insta snapshot in
//! `snapshots/`.

use contact_patch::harness::hard::{markdown, row, HardCase};
use contact_patch::run::run_case;
use std::path::Path;

fn hard_cases() -> Vec<HardCase> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/hard");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    files
        .iter()
        .map(|f| row(&run_case(f, &mut |_| {}).unwrap()))
        .collect()
}

fn find<'a>(rows: &'a [HardCase], name: &str) -> &'a HardCase {
    rows.iter().find(|r| r.case == name).unwrap()
}

#[test]
fn every_hard_case_meets_its_expected_outcome() {
    let rows = hard_cases();
    assert!(rows.len() >= 25, "{} hard cases", rows.len());
    for r in &rows {
        assert!(r.met, "{r:#?}");
    }
    // a converged answer whose equilibrium is not at round-off always says so
    for r in &rows {
        if r.outcome == "converged" && r.equilibrium_residual > 1e-12 {
            assert!(
                r.warnings
                    .iter()
                    .any(|w| w.contains("equilibrium is not at round-off")),
                "{r:#?}"
            );
        }
    }
    // the condition estimate grows with the penalty (kappa A dominates the stiffness): from
    // 1e3 E/h to 1e9 E/h it grows by 1e6 within a factor 3 (penalty stiffness over the bodies')
    let cond = |name: &str| find(&rows, name).condition_estimate.unwrap();
    let growth = cond("penalty-1e9-E-over-h") / cond("penalty-1e3-E-over-h");
    assert!((1e6 / 3.0..=3e6).contains(&growth), "growth {growth:e}");
    // the stiffest penalty stops as singular instead of converging with lost digits
    assert_eq!(find(&rows, "penalty-1e12-E-over-h").outcome, "singular");
    let mut settings = insta::Settings::clone_current();
    settings.set_snapshot_path("../snapshots");
    settings.set_prepend_module_to_snapshot(false);
    settings.bind(|| insta::assert_snapshot!("hard_cases", markdown(&rows)));
}
