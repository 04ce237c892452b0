//! `contact-patch report` (issue 16 item 7): the page links only to files that exist, shows
//! every table of the reports, and lists a report that is not generated yet with its command.

use contact_patch::harness::index_page::{attribute_values, build, KNOWN_REPORTS};
use std::path::Path;
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Every `href`/`src` of `html` is an anchor of the page or a relative path to a file of
/// `folder`.
fn assert_links_resolve(folder: &Path, html: &str) -> usize {
    let targets = attribute_values(html);
    for t in &targets {
        if let Some(id) = t.strip_prefix('#') {
            assert!(html.contains(&format!(" id=\"{id}\"")), "no id for {t}");
            continue;
        }
        assert!(
            !t.contains(':') && !t.starts_with('/') && !t.split('/').any(|p| p == ".."),
            "not a relative link into the folder: {t}"
        );
        let path = t.split('#').next().unwrap();
        assert!(
            folder.join(path).is_file(),
            "{t}: no file {}",
            folder.join(path).display()
        );
    }
    targets.len()
}

#[test]
fn the_page_of_the_committed_reports_links_only_to_existing_files() {
    let folder = root().join("reports");
    let page = build(&folder).unwrap();
    let links = assert_links_resolve(&folder, &page.html);
    assert_eq!(links, page.targets.len());
    // every Markdown table of every report is on the page: the tables of the Markdown files
    // (a header row followed by a |---| delimiter row) are counted independently
    let mut md_tables = 0;
    for entry in std::fs::read_dir(&folder).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "md") {
            let text = std::fs::read_to_string(&path).unwrap();
            let lines: Vec<&str> = text.lines().collect();
            md_tables += lines
                .windows(2)
                .filter(|w| {
                    let delimiter = w[1].trim();
                    w[0].trim_start().starts_with('|')
                        && delimiter.starts_with('|')
                        && delimiter.contains('-')
                        && delimiter.chars().all(|c| "|-: ".contains(c))
                })
                .count();
        }
    }
    assert!(md_tables > 0);
    assert_eq!(page.tables, md_tables);
    // every SVG of the folder is shown once
    let svgs = std::fs::read_dir(&folder)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "svg")
        })
        .count();
    assert_eq!(page.images, svgs);
    for r in KNOWN_REPORTS {
        if folder.join(format!("{}.md", r.stem)).is_file() {
            assert!(
                page.html
                    .contains(&format!("<section id=\"{}\">", r.stem.replace('.', "-"))),
                "{}",
                r.stem
            );
            assert!(page.html.contains(r.title), "{}", r.stem);
        }
    }
    assert!(!page.html.contains("http://") && !page.html.contains("https://"));
}

#[test]
fn report_writes_only_index_html_and_names_what_is_missing() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(
        dir.join("tied-layer.md"),
        "# Tied layer\n\n| a | b |\n|---|---|\n| 1 | 2 |\n\n![plot](tied-layer-q4.svg)\n[gone](gone.json)\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("tied-layer-q4.svg"),
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10\" height=\"10\"/>",
    )
    .unwrap();
    std::fs::write(dir.join("notes.md"), "# My notes\n\nText.\n").unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .args(["report", "--reports", dir.to_str().unwrap()])
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{out}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(out.contains("1 tables, 1 images"), "{out}");
    assert!(out.contains("a report links to gone.json"), "{out}");
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "index.html",
            "notes.md",
            "tied-layer-q4.svg",
            "tied-layer.md"
        ]
    );
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    assert_links_resolve(dir, &html);
    assert!(html.contains("Other report: My notes"), "{html}");
    assert!(
        html.contains("not generated yet, run <code>contact-patch table</code>"),
        "{html}"
    );
    assert_eq!(
        html.matches("class=\"missing\"").count(),
        KNOWN_REPORTS.len() - 1
    );
    // a folder that does not exist is bad input
    let o = Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .args(["report", "--reports", dir.join("no-such").to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no such folder"));
}
