//! The patch-test table: the seed's row is reproduced with Lagrange multipliers at every nu,
//! every passing cell balances its forces, and the whole grid (errors rounded so that round-off
//! does not churn it, times left out) is a reviewed insta snapshot in `snapshots/`.

use contact_patch::harness::report::seed_summary;
use contact_patch::harness::{grid_markdown, run_sweep, Cell};
use std::path::Path;

/// The cells of every case in `cases/<folder>` (expecting `count` cases).
fn sweep_folder(folder: &str, count: usize) -> Vec<Cell> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("cases")
        .join(folder);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    assert_eq!(files.len(), count, "cases in {folder}");
    files
        .iter()
        .flat_map(|f| run_sweep(f, &mut |_| {}).unwrap())
        .collect()
}

fn catalogue() -> Vec<Cell> {
    sweep_folder("patch", 15) // meshes A-E at three values of nu
}

#[test]
fn patch_table() {
    let cells = catalogue();
    let summary = seed_summary(&cells);
    for line in summary.lines().filter(|l| l.starts_with("| Lagrange")) {
        assert!(
            line.ends_with("| yes |"),
            "the seed's row is not reproduced:\n{summary}"
        );
    }
    // global equilibrium holds in every converged cell, consistent or not: the contact forces
    // carry the punch's load
    for c in cells
        .iter()
        .filter(|c| c.termination.as_deref() == Some("converged"))
    {
        assert!(c.load_error.unwrap() <= 1e-9, "{c:?}");
    }
    // every enforcement method passes somewhere; n/a only with a reason
    let mut methods: Vec<&str> = cells.iter().map(|c| c.enforcement.as_str()).collect();
    methods.sort();
    methods.dedup();
    assert_eq!(methods.len(), 7);
    for m in methods {
        assert!(
            cells
                .iter()
                .any(|c| c.enforcement == m && c.verdict == "pass"),
            "{m} never passes"
        );
    }
    for c in cells.iter().filter(|c| c.verdict == "n/a") {
        assert!(!c.note.is_empty(), "n/a without a reason: {c:?}");
    }
    // stability: two-pass Lagrange multipliers are singular, one-pass ones are not
    for c in cells
        .iter()
        .filter(|c| c.enforcement == "lagrange" && c.discretization == "node_to_surface")
    {
        let expected = if c.passes == Some(2) {
            "unstable"
        } else {
            "stable"
        };
        assert_eq!(c.stability, expected, "{c:?}");
    }
    // Lagrange multipliers: LDL^T when the rows are independent, the Schur pseudo-inverse when not
    for c in cells
        .iter()
        .filter(|c| c.enforcement == "lagrange" && c.verdict != "n/a")
    {
        let expected = if c.rank_deficiency == Some(0) {
            "ldlt"
        } else {
            "schur-pseudo-inverse"
        };
        assert_eq!(c.linear_solver.as_deref(), Some(expected), "{c:?}");
    }
    // the penalty-type methods were also run at 1000 kappa
    for c in cells
        .iter()
        .filter(|c| c.enforcement == "penalty" && c.verdict != "n/a")
    {
        assert!(
            c.stress_error_stiff.is_some() && c.penalty_trend.is_some(),
            "{c:?}"
        );
    }
    let mut settings = insta::Settings::clone_current();
    settings.set_snapshot_path("../snapshots");
    settings.set_prepend_module_to_snapshot(false);
    settings.bind(|| {
        insta::assert_snapshot!(
            "patch_table",
            format!("{summary}\n{}", grid_markdown(&cells))
        );
    });
}

/// Tied patch tests: mortar and dual mortar ties reproduce every constant stress (normal,
/// parallel, shear) across the non-matching meshes B, C and E with every exact method; the
/// grid is a snapshot too (it records which node-to-surface ties fail and by how much).
#[test]
fn tied_table() {
    let cells = sweep_folder("tied", 9); // meshes B, C, E x three stress states
    for c in cells
        .iter()
        .filter(|c| c.discretization.contains("mortar") && c.verdict != "n/a")
    {
        assert_eq!(c.verdict, "pass", "{c:?}");
        assert!(c.force_balance.unwrap() <= 1e-12, "momentum: {c:?}");
    }
    assert!(
        cells
            .iter()
            .any(|c| c.discretization == "node_to_surface" && c.verdict == "fail"),
        "node-to-surface ties are expected to fail somewhere"
    );
    let mut settings = insta::Settings::clone_current();
    settings.set_snapshot_path("../snapshots");
    settings.set_prepend_module_to_snapshot(false);
    settings.bind(|| insta::assert_snapshot!("tied_table", grid_markdown(&cells)));
}
