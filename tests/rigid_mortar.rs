//! Mortar (standard and dual multipliers) against rigid masters, and two-pass node-to-surface
//! against them refused (issue 16, item 4), judged against closed forms:
//!
//! * the flat punch on a rigid line (`cases/contact/signorini-block-on-rigid-line*.json`, a Q9
//!   block under a uniform pressure 5): the exact solution is the uniform stress
//!   `sigma_yy = -5` with contact pressure 5 at every slave node, for every enforcement method;
//! * Hertz's rigid cylinder on a half-space (Johnson, Contact Mechanics, eqs. 4.43 and 4.45),
//!   `cases/contact/hertz-profile-{standard,dual}-mortar.json`: the nodal pressures against
//!   `p(x) = p0 sqrt(1 - x^2/a^2)`, with the tolerances of the node-to-surface profile in
//!   `tests/contact_results.rs`.

mod common;

use contact_patch::run::run_case;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn case(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// A copy of case `rel` with `edit` applied, written into `dir`.
fn edited(rel: &str, dir: &Path, edit: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let mut c: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(case(rel)).unwrap()).unwrap();
    edit(&mut c);
    let path = dir.join("case.json");
    std::fs::write(&path, serde_json::to_string(&c).unwrap()).unwrap();
    path
}

/// The flat punch on a rigid line with standard and dual mortar rows and every enforcement
/// method: the uniform stress and the contact pressure 5 at every slave node to the case's
/// 1e-10 (penalty-type methods included: the block sinks uniformly by `5 / kappa`, which leaves
/// the stress uniform), the forces in balance to 1e-12.
#[test]
fn flat_punch_on_a_rigid_line_is_exact_for_every_enforcement_with_mortar() {
    let enforcements = [
        serde_json::json!({"kind": "lagrange"}),
        serde_json::json!({"kind": "perturbed_lagrange", "kappa": 1e4}),
        serde_json::json!({"kind": "penalty", "kappa": 1e4}),
        serde_json::json!({"kind": "perturbed_tangent", "kappa": 1e4}),
        serde_json::json!({"kind": "augmented_lagrange", "kappa": 1e4}),
        serde_json::json!({"kind": "augmented_lagrange", "kappa": 1e4, "update": "outer_loop"}),
        serde_json::json!({"kind": "elimination"}),
    ];
    let mut ran = 0;
    for multiplier in ["standard", "dual"] {
        for enforcement in &enforcements {
            let dir = tempfile::tempdir().unwrap();
            let path = edited(
                &format!("cases/contact/signorini-block-on-rigid-line-{multiplier}-mortar.json"),
                dir.path(),
                |c| c["contact"][0]["enforcement"] = enforcement.clone(),
            );
            let label = format!("{multiplier} mortar, {enforcement}");
            let outcome = match run_case(&path, &mut |_| {}) {
                Ok(o) => o,
                Err(e) => {
                    // constraint elimination needs rows that touch their own slave node only
                    let text = e.to_string();
                    assert!(
                        multiplier == "standard"
                            && enforcement["kind"] == "elimination"
                            && text.contains("elimination"),
                        "{label}: {text}"
                    );
                    println!("{label}: refused: {text}");
                    continue;
                }
            };
            assert_eq!(outcome.checks.len(), 3, "{label}");
            for c in &outcome.checks {
                println!(
                    "{label}: {} error {:.3e} (tol {:.0e})",
                    c.check, c.error, c.tol
                );
                assert!(c.passed, "{label}: {} error {:e}", c.check, c.error);
            }
            ran += 1;
        }
    }
    assert!(ran >= 13, "{ran} cells ran");
}

fn csv_rows(path: &Path) -> Vec<BTreeMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            header
                .iter()
                .cloned()
                .zip(l.split(',').map(String::from))
                .collect()
        })
        .collect()
}

fn num(row: &BTreeMap<String, String>, column: &str) -> f64 {
    row[column].parse().unwrap()
}

/// Hertz's cylinder (R = 10, P = 4, E = 200, nu = 0.3, plane strain) with standard and dual
/// mortar against the rigid circle on the graded 0.02 mesh: the nodal pressures within 2% of p0
/// over |x| <= 0.8 a (the finite block sits 1.25% below the half-space value, as with
/// node-to-surface), the outermost closed node within one element (0.02) of a, and the pressures
/// integrating to the load to 1e-10.
#[test]
fn hertz_profile_with_mortar_against_the_rigid_cylinder() {
    let e_star = 200.0 / (1.0 - 0.3f64 * 0.3);
    let a = (4.0 * 4.0 * 10.0 / (std::f64::consts::PI * e_star)).sqrt();
    let p0 = 2.0 * 4.0 / (std::f64::consts::PI * a);
    let hertz = |x: f64| p0 * (1.0 - (x / a).powi(2)).max(0.0).sqrt();
    for multiplier in ["standard", "dual"] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let o = common::run_case(
            &case(&format!(
                "cases/contact/hertz-profile-{multiplier}-mortar.json"
            )),
            &out,
        );
        assert_eq!(o.status.code(), Some(0), "{o:?}");
        let rows = csv_rows(&out.join("cylinder.contact.csv"));
        assert_eq!(rows.len(), 125, "the slave surface's nodes");
        let (mut interior, mut extent, mut total) = (0.0f64, 0.0f64, 0.0);
        for row in &rows {
            let (x, p) = (num(row, "x"), num(row, "pressure"));
            total += p * num(row, "area");
            if row["status"] == "closed" {
                extent = extent.max(x.abs());
            } else {
                // (a closed row also loads its open neighbours: standard rows through D, and
                // under the curved master every row through the variation of its weights)
                assert!(num(row, "gap") > 0.0, "{multiplier}: {row:?}");
            }
            if x.abs() <= 0.8 * a {
                interior = interior.max((p - hertz(x)).abs() / p0);
            }
        }
        println!(
            "{multiplier} mortar: a = {a:.6}, p0 = {p0:.6}: largest |p - p_H| / p0 over |x| <= 0.8 a = {interior:.3e}; outermost closed node {extent}; sum p A = {total}"
        );
        assert!(interior <= 0.02, "{multiplier}: {interior}");
        assert!((extent - a).abs() <= 0.02, "{multiplier}: {extent} vs {a}");
        assert!((total - 4.0).abs() <= 1e-10 * 4.0, "{multiplier}: {total}");
    }
}

/// Constraint elimination against the rigid circle is refused even with dual rows: the
/// variation of the weights under the curved master couples each row to its neighbours, so no
/// row owns its slave dof alone; the message says so (the wording the patch and tied tables
/// snapshot, kept).
#[test]
fn elimination_against_a_rigid_circle_is_refused_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let path = edited(
        "cases/contact/hertz-profile-dual-mortar.json",
        dir.path(),
        |c| c["contact"][0]["enforcement"] = serde_json::json!({"kind": "elimination"}),
    );
    let o = common::run_case(&path, &dir.path().join("out"));
    assert_ne!(o.status.code(), Some(0));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("constraint elimination does not apply"),
        "{err}"
    );
    assert!(err.contains("also appears in another constraint"), "{err}");
}

/// Two-pass node-to-surface against a rigid master is refused, non-zero exit, with the reason
/// (the second pass would take the master's nodes as slaves; a rigid surface has none) and the
/// fix (one pass).
#[test]
fn two_pass_against_a_rigid_master_is_refused_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let path = edited(
        "cases/contact/signorini-block-on-rigid-line.json",
        dir.path(),
        |c| {
            c["contact"][0]["discretization"] =
                serde_json::json!({"kind": "node_to_surface", "passes": 2})
        },
    );
    let o = common::run_case(&path, &dir.path().join("out"));
    assert_ne!(o.status.code(), Some(0));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("contact 'ground'"), "{err}");
    assert!(err.contains("a rigid surface has none"), "{err}");
    assert!(err.contains("\"passes\": 1"), "{err}");
    assert!(!dir.path().join("out").join("summary.json").exists());
}
