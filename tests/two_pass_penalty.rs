//! Two-pass penalty scaling (issue 16, item 5): `two_pass_penalty: "full"` (default, `kappa`
//! on each pass) or `"halved"` (`kappa / 2` on each pass). On the matching meshes of the contact
//! patch test (mesh A) both passes act at every interface node, so the nodal spring is
//! `2 kappa A` (full) or `kappa A` (halved) and the uniform pressure `p` closes the gap to
//! `g = -p / (2 kappa)` or `g = -p / kappa`: the closed forms judged here, from the gaps of
//! `<pair>.contact.csv`.

mod common;
use common::run_case;

use std::path::Path;

/// Patch A, two-pass penalty at `kappa`, with `scaling` (None: the field left out); returns
/// the gaps of every point of both surfaces and the summary.
fn run(dir: &Path, kappa: f64, scaling: Option<&str>) -> (Vec<f64>, serde_json::Value) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/patch/patch-A-nu0.3.json");
    let mut c: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    c["contact"][0]["discretization"] = serde_json::json!({"kind": "node_to_surface", "passes": 2});
    c["contact"][0]["enforcement"] = serde_json::json!({"kind": "penalty", "kappa": kappa});
    if let Some(s) = scaling {
        c["contact"][0]["two_pass_penalty"] = serde_json::json!(s);
    }
    c["checks"] = serde_json::json!([]);
    let name = format!("{kappa}-{}", scaling.unwrap_or("default"));
    let case = dir.join(format!("{name}.json"));
    std::fs::write(&case, c.to_string()).unwrap();
    let out = dir.join(&name);
    let o = run_case(&case, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("interface.contact.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let g = header.iter().position(|h| *h == "gap").unwrap();
    let gaps = lines
        .map(|l| l.split(',').nth(g).unwrap().parse().unwrap())
        .collect();
    let summary =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    (gaps, summary)
}

#[test]
fn full_and_halved_two_pass_penalty_close_the_gap_to_their_closed_forms() {
    let dir = tempfile::tempdir().unwrap();
    let (kappa, p) = (1e4, 10.0);
    let (default, _) = run(dir.path(), kappa, None);
    let (full, _) = run(dir.path(), kappa, Some("full"));
    let (halved, summary) = run(dir.path(), kappa, Some("halved"));
    assert_eq!(default, full, "full is the default");
    assert!(!full.is_empty());
    for (what, gaps, expected) in [
        ("full", &full, -p / (2.0 * kappa)),
        ("halved", &halved, -p / kappa),
    ] {
        let worst = gaps
            .iter()
            .fold(0.0f64, |m, g| m.max((g - expected).abs() / expected.abs()));
        println!("{what}: every gap {expected:e}, largest relative difference {worst:e}");
        assert!(worst <= 1e-9, "{what}: {gaps:?}");
    }
    // halved at kappa is full at kappa / 2, bit for bit
    let (half_kappa, _) = run(dir.path(), kappa / 2.0, Some("full"));
    assert_eq!(halved, half_kappa);
    // the summary says what was simulated
    let effect = summary["effects"][1]["detail"].as_str().unwrap();
    assert!(effect.contains("two-pass penalty halved"), "{effect}");
}

#[test]
fn halved_without_a_two_pass_discretization_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("cases/contact/signorini-block-on-rigid-line.json");
    let mut c: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    c["contact"][0]["two_pass_penalty"] = serde_json::json!("halved");
    let case = dir.path().join("case.json");
    std::fs::write(&case, c.to_string()).unwrap();
    let out = dir.path().join("out");
    let o = run_case(&case, &out);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("contact[0]")
            && err.contains(".two_pass_penalty")
            && err.contains("passes\": 2"),
        "{err}"
    );
    assert!(!out.exists());
}
