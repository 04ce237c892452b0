//! Every example of `docs/` and the README runs: a fenced `sh` block preceded by a comment
//! `<!-- example: exit N; creates FILE... -->` is run by `bash -e` with the built
//! `contact-patch` first on the `PATH` (the README's `cargo run --release --` stands for it),
//! in a scratch folder that links the repository's `cases/`; its exit code must be `N` and
//! every file it names must exist and be non-empty.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

struct Example {
    at: String,
    exit: i32,
    creates: Vec<String>,
    script: String,
}

fn examples(file: &Path) -> Vec<Example> {
    let text = std::fs::read_to_string(file).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    for (k, line) in lines.iter().enumerate() {
        let Some(spec) = line
            .trim()
            .strip_prefix("<!-- example:")
            .and_then(|s| s.strip_suffix("-->"))
        else {
            continue;
        };
        let at = format!("{}:{}", file.strip_prefix(root()).unwrap().display(), k + 1);
        let mut exit = None;
        let mut creates = Vec::new();
        for part in spec.split(';') {
            let words: Vec<&str> = part.split_whitespace().collect();
            match words.split_first() {
                Some((&"exit", [n])) => exit = Some(n.parse().unwrap()),
                Some((&"creates", files)) => creates.extend(files.iter().map(|f| f.to_string())),
                None => {}
                _ => panic!("{at}: unknown example field in `{part}`"),
            }
        }
        assert_eq!(
            lines.get(k + 1).map(|l| l.trim()),
            Some("```sh"),
            "{at}: the example comment must precede a ```sh block"
        );
        let body: Vec<&str> = lines[k + 2..]
            .iter()
            .take_while(|l| l.trim() != "```")
            .copied()
            .collect();
        out.push(Example {
            at,
            exit: exit.unwrap_or_else(|| panic!("example without an exit code")),
            creates,
            script: body
                .join("\n")
                .replace("cargo run --release -- ", "contact-patch "),
        });
    }
    out
}

fn markdown_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            markdown_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "md") {
            out.push(p);
        }
    }
}

#[test]
fn every_marked_example_of_the_docs_runs() {
    let mut files = vec![root().join("README.md")];
    markdown_files(&root().join("docs"), &mut files);
    files.sort();
    let all: Vec<Example> = files.iter().flat_map(|f| examples(f)).collect();
    assert!(all.len() >= 12, "{} examples", all.len());
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_contact-patch"));
    let path = format!(
        "{}:{}",
        bin.parent().unwrap().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut failures = Vec::new();
    for ex in &all {
        let dir = tempfile::tempdir().unwrap();
        std::os::unix::fs::symlink(root().join("cases"), dir.path().join("cases")).unwrap();
        let out = Command::new("bash")
            .args(["-e", "-o", "pipefail", "-c", &ex.script])
            .current_dir(dir.path())
            .env("PATH", &path)
            .output()
            .unwrap();
        let code = out.status.code().unwrap_or(-1);
        let missing: Vec<&String> = ex
            .creates
            .iter()
            .filter(|f| std::fs::metadata(dir.path().join(f)).map_or(true, |m| m.len() == 0))
            .collect();
        if code != ex.exit || !missing.is_empty() {
            failures.push(format!(
                "{}: exit {code} (expected {}), missing {missing:?}\n{}\nstdout:\n{}\nstderr:\n{}",
                ex.at,
                ex.exit,
                ex.script,
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn every_command_page_has_an_example() {
    let mut files = Vec::new();
    markdown_files(&root().join("docs/guide"), &mut files);
    for f in files {
        let name = f.file_name().unwrap().to_string_lossy().to_string();
        if name == "README.md" {
            continue;
        }
        assert!(
            !examples(&f).is_empty(),
            "{name} has no example the tests run"
        );
    }
}
