//! Helpers shared by the integration tests.

use std::path::{Path, PathBuf};

/// The reproducer `tests/defects/NAME-*.json` (NAME as `D12` or `D24a`).
pub fn defect(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/defects");
    std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with(&format!("{name}-"))
        })
        .unwrap_or_else(|| panic!("no reproducer {name} in {}", dir.display()))
}
