//! The case format's JSON Schema (`contact-patch schema`, committed as
//! `cases/case.schema.json`): the committed file is the one the code generates, and every case
//! file the project ships validates against it (so an editor that follows the schema accepts
//! them), while a file with a misspelt field does not.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn json_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            json_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "json")
            && !path.to_string_lossy().ends_with(".schema.json")
            && !path.to_string_lossy().ends_with(".study.json")
        {
            out.push(path);
        }
    }
}

#[test]
fn the_committed_schema_is_the_generated_one() {
    let committed = std::fs::read_to_string(root().join("cases/case.schema.json")).unwrap();
    assert!(
        committed == contact_patch::io::scene::case_schema(),
        "cases/case.schema.json is out of date: run `cargo run --release -- schema > cases/case.schema.json`"
    );
}

#[test]
fn every_shipped_case_validates_and_a_misspelt_field_does_not() {
    let schema: serde_json::Value =
        serde_json::from_str(&contact_patch::io::scene::case_schema()).unwrap();
    let validator = jsonschema::validator_for(&schema).unwrap();
    let mut files = Vec::new();
    json_files(&root().join("cases"), &mut files);
    assert!(files.len() >= 40, "{} case files", files.len());
    for f in &files {
        let case: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(f).unwrap()).unwrap();
        let errors: Vec<String> = validator
            .iter_errors(&case)
            .map(|e| format!("{} at {}", e, e.instance_path()))
            .collect();
        assert!(errors.is_empty(), "{}: {errors:?}", f.display());
        // and the tool itself reads it
        contact_patch::model::parse(&case.to_string(), &f.display().to_string()).unwrap();
    }
    // a misspelt field (the tool refuses it too) and a wrong type are caught by the schema
    let mut case: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("cases/contact/signorini-block-on-rigid-line.json"))
            .unwrap(),
    )
    .unwrap();
    case["solver"] = serde_json::json!({"load_step": 2});
    assert!(!validator.is_valid(&case));
    assert!(contact_patch::model::parse(&case.to_string(), "case").is_err());
    case["solver"] = serde_json::json!({"load_steps": "two"});
    assert!(!validator.is_valid(&case));
    // a case naming the schema is accepted by both
    case["solver"] = serde_json::json!({});
    case["$schema"] = serde_json::json!("../case.schema.json");
    assert!(validator.is_valid(&case));
    contact_patch::model::parse(&case.to_string(), "case").unwrap();
}
