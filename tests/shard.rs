//! Shards (`table --shard K/N`, `study --shard K/N`, `merge`): the patch table run as three
//! shards and merged equals the single run, timings aside; a study's shards merged equal its
//! single run, timings and memory aside; overlapping and missing shards are refused.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn binary(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .current_dir(root())
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// `v` with the named fields removed at every depth (the measured times).
fn without(mut v: Value, fields: &[&str]) -> Value {
    fn strip(v: &mut Value, fields: &[&str]) {
        match v {
            Value::Object(m) => {
                for f in fields {
                    m.remove(*f);
                }
                m.values_mut().for_each(|x| strip(x, fields));
            }
            Value::Array(a) => a.iter_mut().for_each(|x| strip(x, fields)),
            _ => {}
        }
    }
    strip(&mut v, fields);
    v
}

fn read(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn the_patch_table_in_three_shards_merged_equals_the_single_run() {
    let dir = tempfile::tempdir().unwrap();
    let (single, parts, merged) = (
        dir.path().join("single"),
        dir.path().join("parts"),
        dir.path().join("merged"),
    );
    let (code, _, err) = binary(&["table", "cases/patch", "--out", s(&single)]);
    assert_eq!(code, 0, "{err}");
    let mut files = Vec::new();
    for k in 1..=3 {
        let shard = format!("{k}/3");
        let (code, out, err) = binary(&[
            "table",
            "cases/patch",
            "--out",
            s(&parts),
            "--shard",
            &shard,
        ]);
        assert_eq!(code, 0, "{err}");
        assert!(out.contains(&format!("shard {k}/3")), "{out}");
        files.push(parts.join(format!("table.shard-{k}-of-3.json")));
    }
    // each shard ran 5 of the 15 cases: every third, from its own
    for (k, f) in files.iter().enumerate() {
        let ran: Vec<u64> = read(f)["ran"]
            .as_array()
            .unwrap()
            .iter()
            .map(|u| u[0].as_u64().unwrap())
            .collect();
        assert_eq!(
            ran,
            (0..15).filter(|i| i % 3 == k as u64).collect::<Vec<_>>()
        );
    }
    // merged in any order
    let mut args = vec![
        "merge",
        s(&files[2]),
        s(&files[0]),
        s(&files[1]),
        "--out",
        s(&merged),
    ];
    let (code, _, err) = binary(&args);
    assert_eq!(code, 0, "{err}");
    let a = without(read(&single.join("patch-table.json")), &["time_ms"]);
    let b = without(read(&merged.join("patch-table.json")), &["time_ms"]);
    assert_eq!(a.as_array().unwrap().len(), 630);
    assert!(a == b, "the merged table differs from the single run");
    // the Markdown tables too, byte for byte: the wall times are in their own file
    let md_a = std::fs::read_to_string(single.join("patch-table.md")).unwrap();
    let md_b = std::fs::read_to_string(merged.join("patch-table.md")).unwrap();
    assert!(
        md_a == md_b,
        "the merged Markdown differs from the single run"
    );
    // which lists the same cells in the same order (the times aside)
    let keys = |dir: &std::path::Path| -> Vec<String> {
        std::fs::read_to_string(dir.join("patch-table.times.csv"))
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| l.rsplit_once(',').unwrap().0.to_string())
            .collect()
    };
    assert_eq!(keys(&single).len(), 631, "a header and 630 cells");
    assert_eq!(keys(&single), keys(&merged));

    // a shard twice, a shard missing
    args = vec![
        "merge",
        s(&files[0]),
        s(&files[0]),
        s(&files[1]),
        s(&files[2]),
        "--out",
        s(&merged),
    ];
    let (code, _, err) = binary(&args);
    assert_eq!(code, 2);
    assert!(err.contains("shard 1/3 is given twice"), "{err}");
    let (code, _, err) = binary(&["merge", s(&files[0]), s(&files[2]), "--out", s(&merged)]);
    assert_eq!(code, 2);
    assert!(err.contains("shards missing: 2/3"), "{err}");
}

#[test]
fn a_study_in_two_shards_merged_equals_the_single_run() {
    let dir = tempfile::tempdir().unwrap();
    let study = dir.path().join("window.study.json");
    let mut v = read(&root().join("cases/studies/penalty-window.study.json"));
    v["base"] = Value::String(s(&root().join("cases/studies/penalty-window-patch-A.json")).into());
    v["axes"][2]["values"] = serde_json::json!([1e2, 1e4, 1e6]);
    v["axes"][2]["labels"] = serde_json::json!(["1e2 E/h", "1e4 E/h", "1e6 E/h"]);
    std::fs::write(&study, v.to_string()).unwrap();
    let (single, parts, merged) = (
        dir.path().join("single"),
        dir.path().join("parts"),
        dir.path().join("merged"),
    );
    let (code, _, err) = binary(&["study", s(&study), "--out", s(&single)]);
    assert_eq!(code, 0, "{err}");
    for k in ["1/2", "2/2"] {
        let (code, _, err) = binary(&["study", s(&study), "--out", s(&parts), "--shard", k]);
        assert_eq!(code, 0, "{err}");
    }
    let p1 = parts.join("penalty-window.shard-1-of-2.json");
    let p2 = parts.join("penalty-window.shard-2-of-2.json");
    let (code, _, err) = binary(&["merge", s(&p2), s(&p1), "--out", s(&merged)]);
    assert_eq!(code, 0, "{err}");
    let times = ["times", "peak_memory_mb", "pareto"];
    let a = without(read(&single.join("penalty-window.json")), &times);
    let b = without(read(&merged.join("penalty-window.json")), &times);
    assert_eq!(a["cells"].as_array().unwrap().len(), 4 * 6 * 3);
    assert!(a == b, "the merged study differs from the single run");
    // a table part with a study part
    let (code, _, err) = binary(&[
        "merge",
        s(&p1),
        s(&root().join("cases/studies/penalty-window.study.json")),
        "--out",
        s(&merged),
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("not a partial file"), "{err}");
}
