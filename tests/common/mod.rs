//! Helpers shared by the integration tests.

use std::path::{Path, PathBuf};

/// The reproducer `tests/defects/NAME-*` or `tests/defects/s4/NAME-*` (NAME as `D12`, `D24a`
/// or `W01a`; the second report's reproducers keep their own folder).
#[allow(dead_code)] // not every test binary that includes this module replays defects
pub fn defect(name: &str) -> PathBuf {
    let top = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/defects");
    [top.clone(), top.join("s4")]
        .iter()
        .flat_map(|dir| std::fs::read_dir(dir).unwrap())
        .map(|e| e.unwrap().path())
        .find(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with(&format!("{name}-"))
        })
        .unwrap_or_else(|| panic!("no reproducer {name} in {}", top.display()))
}

/// `contact-patch run CASE --out OUT`, its output captured.
#[allow(dead_code)] // not every test binary that includes this module runs cases
pub fn run_case(case: &Path, out: &Path) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .args([
            "run",
            case.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap()
}
