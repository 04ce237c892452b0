//! The seed's tied layer (cases/tied-layer/): mortar and dual mortar ties approach the one-body
//! solution under refinement (both distances shrink at every level, Q4 and Q9), and the
//! `tied-layer` command writes its report, SVG plots and readable `.vtu` files.

use contact_patch::harness::layer::study;
use std::path::Path;
use std::process::Command;

#[test]
fn mortar_ties_converge_to_the_one_body_solution() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/tied-layer");
    for element in ["q4", "q9"] {
        let s = study(&dir, element, &[1, 2, 4], 2).unwrap();
        for variant in ["mortar", "dual mortar"] {
            let runs: Vec<_> = s.runs.iter().filter(|r| r.variant == variant).collect();
            assert_eq!(runs.len(), 3);
            for w in runs.windows(2) {
                assert!(
                    w[1].du < w[0].du && w[1].ds < w[0].ds,
                    "{element} {variant}: {runs:?}"
                );
            }
            // at the finest level the mortar tie is within 1% in displacement and 5% of p in stress
            let last = runs.last().unwrap();
            assert!(
                last.du < 0.01 && last.ds < 0.05,
                "{element} {variant}: {last:?}"
            );
        }
        // 4 curves (one body and three ties) at the plotted level
        assert_eq!(s.curves.len(), 4);
    }
}

#[test]
fn the_command_writes_report_plots_and_vtu() {
    let out = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "tied-layer",
            "--levels",
            "1,2",
            "--out",
            out.path().to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let md = std::fs::read_to_string(out.path().join("tied-layer.md")).unwrap();
    assert!(md.contains("| 2 | dual mortar |"), "{md}");
    for element in ["q4", "q9"] {
        for plot in ["uy-interface", "syy-interface", "syy-through"] {
            let svg = std::fs::read_to_string(
                out.path().join(format!("tied-layer-{element}-{plot}.svg")),
            )
            .unwrap();
            assert!(
                svg.starts_with("<svg") && svg.matches("<polyline").count() == 4,
                "{element} {plot}"
            );
        }
        for variant in ["one-body", "node-to-surface", "mortar", "dual-mortar"] {
            let folder = out
                .path()
                .join("tied-layer")
                .join(format!("{element}-{variant}"));
            let summary: serde_json::Value = serde_json::from_str(
                &std::fs::read_to_string(folder.join("summary.json")).unwrap(),
            )
            .unwrap();
            assert_eq!(summary["passed"], true, "{element} {variant}");
            let names: Vec<String> = std::fs::read_dir(&folder)
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect();
            // one .vtu per body; a tied pair also writes its contact-surface file
            let bodies = names
                .iter()
                .filter(|n| n.ends_with(".vtu") && !n.ends_with(".contact.vtu"))
                .count();
            let surfaces = names.iter().filter(|n| n.ends_with(".contact.vtu")).count();
            assert_eq!(bodies, if variant == "one-body" { 1 } else { 2 });
            assert_eq!(surfaces, if variant == "one-body" { 0 } else { 1 });
        }
    }
}
