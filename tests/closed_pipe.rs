//! A reader that goes away (`contact-patch table | head -1`) stops the printing, not the work:
//! the command finishes, writes its files and ends with its own exit code. Before, the first
//! `println!` after the pipe closed panicked (exit 101) in the middle of the run.

use std::process::{Command, Stdio};

/// Run `contact-patch ARGS` with standard output and error going into pipes whose reading ends
/// are closed at once, and return its exit code.
fn exit_code_with_closed_pipes(args: &[&str]) -> Option<i32> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the tool starts");
    drop(child.stdout.take());
    drop(child.stderr.take());
    child.wait().expect("the tool ends").code()
}

/// The same command with its output read to the end.
fn exit_code_read(args: &[&str]) -> Option<i32> {
    Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the tool runs")
        .status
        .code()
}

#[test]
fn a_table_whose_reader_has_gone_is_still_written_with_its_exit_code() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tables");
    let code = exit_code_with_closed_pipes(&["table", "--out", out.to_str().unwrap()]);
    assert_eq!(code, Some(0), "the table ends as it does with a reader");
    for name in [
        "patch-table.md",
        "patch-table.json",
        "tied-table.md",
        "friction-table.json",
        "patch-table-3d.md",
        "tied-table-3d.json",
    ] {
        let written = std::fs::read_to_string(out.join(name)).unwrap();
        assert!(!written.is_empty(), "{name} is written");
    }
}

#[test]
fn a_check_whose_reader_has_gone_keeps_the_verdict_of_a_check_that_is_read() {
    // cases/patch holds the seed's failing patch tests (meshes C and E), so its verdict is 1;
    // cases/patch-single passes (0). Both are kept when nobody reads the output.
    for (cases, verdict) in [("cases/patch", 1), ("cases/patch-single", 0)] {
        let read = exit_code_read(&["check", cases]);
        assert_eq!(read, Some(verdict), "check {cases} read to the end");
        let unread = exit_code_with_closed_pipes(&["check", cases]);
        assert_eq!(unread, read, "check {cases} with nobody reading");
    }
}
