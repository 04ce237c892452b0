//! `contact-patch report`: one self-contained HTML page, `reports/index.html`, that shows every
//! table, plot and study of the reports folder, readable from the file system (no server, no
//! script or style from elsewhere, no external fetch).
//!
//! The page is built from the files that exist: for each report of [`KNOWN_REPORTS`] (a small
//! registry: file stem, title, the command that regenerates it) its Markdown file is rendered
//! to HTML (CommonMark with GitHub tables, by the `pulldown-cmark` crate) inside a section of
//! its own, with links to its `.md` and `.json` files and every SVG whose name starts with its
//! stem shown as an image (unless the Markdown already shows it). A registered report without
//! its Markdown file is listed as "not generated yet" with its command. Markdown and SVG files
//! not in the registry get sections of their own ("Other reports", "Other figures").
//!
//! Links: every `href` and `src` of the page is relative to the folder and names a file that
//! exists in it (or an anchor of the page). A link of a report's Markdown that is absolute (a
//! URL, a rooted path), or whose target does not exist, is written as its text alone (with the
//! target in `<code>`), and counted in [`Page::unlinked`]. Headings of the reports are moved
//! one level down, under the page's `<h2>` per report.
//!
//! An inline script (the page's only one) marks, once the page has loaded, every image that
//! failed to load (`naturalWidth == 0`) with `data-broken="true"` and writes the counts into
//! `<body data-images=".." data-broken-images="..">`, so that a headless browser's dumped DOM
//! tells whether every image rendered (`tests/browser/check.sh`).

use crate::error::{Error, Result};
use crate::io::paths::ReportFolder;
use pulldown_cmark::{CowStr, Event, HeadingLevel, Options, Parser, Tag, TagEnd};
use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::Path;

/// A report the page knows: the stem of its files, its title and the command that writes it.
pub struct KnownReport {
    pub stem: &'static str,
    pub title: &'static str,
    pub command: &'static str,
}

/// The reports of this repository, in the page's order.
pub const KNOWN_REPORTS: &[KnownReport] = &[
    KnownReport {
        stem: "patch-table",
        title: "Contact patch test (meshes A-E)",
        command: "contact-patch table",
    },
    KnownReport {
        stem: "tied-table",
        title: "Tied patch test",
        command: "contact-patch table",
    },
    KnownReport {
        stem: "friction-table",
        title: "Frictional patch test",
        command: "contact-patch table",
    },
    KnownReport {
        stem: "finite-patch-table",
        title: "Contact patch test at finite strain (meshes A-E compressed 20 %)",
        command: "contact-patch finite-patch",
    },
    KnownReport {
        stem: "patch-table-3d",
        title: "Contact patch test in 3D (Hex8, Tet4, Hex27, Tet10)",
        command: "contact-patch table cases/3d",
    },
    KnownReport {
        stem: "tied-table-3d",
        title: "Tied patch tests in 3D",
        command: "contact-patch table cases/3d",
    },
    KnownReport {
        stem: "hard-cases",
        title: "Stability suite (hard cases)",
        command: "contact-patch hard",
    },
    KnownReport {
        stem: "impact",
        title: "Impact treatments against the 1D wave solutions",
        command: "contact-patch impact-report",
    },
    KnownReport {
        stem: "tied-layer",
        title: "Tied layer under refinement",
        command: "contact-patch tied-layer",
    },
    KnownReport {
        stem: "hertz-profile.cylinder.pressure",
        title: "Hertz pressure profile (rigid cylinder)",
        command: "contact-patch profile cases/contact/hertz-profile.json --pair cylinder",
    },
    KnownReport {
        stem: "hertz-finite",
        title: "Hertz at finite strain: small against finite kinematics",
        command: "contact-patch hertz-finite",
    },
    KnownReport {
        stem: "hertz-3d",
        title: "Hertz in 3D: a rigid sphere on an elastic block",
        command: "contact-patch hertz-3d",
    },
    KnownReport {
        stem: "finite-sliding",
        title: "Large sliding at finite strain",
        command: "contact-patch finite-sliding",
    },
    KnownReport {
        stem: "ironing",
        title: "The ironing problem at finite strain (frictionless)",
        command: "contact-patch ironing",
    },
    KnownReport {
        stem: "crosscheck",
        title: "Cross-check against DOLFINx and scikit-fem",
        command: "bash crosscheck/run.sh",
    },
    KnownReport {
        stem: "peer-codes",
        title: "Peer codes: Kratos Multiphysics on the contact catalogue",
        command: "bash crosscheck/run.sh",
    },
];

/// The page's file name in the reports folder.
pub const INDEX_FILE: &str = "index.html";

/// Files of the folder the page never shows: itself and its screenshot.
const NOT_SHOWN: [&str; 2] = [INDEX_FILE, "index.png"];

/// The built page.
pub struct Page {
    pub html: String,
    /// `<table>` elements on the page.
    pub tables: usize,
    /// `<img>` elements on the page.
    pub images: usize,
    /// Every `href` and `src` target on the page (relative file paths and `#anchors`).
    pub targets: Vec<String>,
    /// Reports of the registry that are not generated yet.
    pub missing: Vec<&'static str>,
    /// Links of the reports written as text (absolute, or to a missing file).
    pub unlinked: Vec<String>,
}

/// `text` with `& < > " '` escaped for HTML text and attribute values.
pub fn escape(text: &str) -> String {
    let mut s = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&#39;"),
            c => s.push(c),
        }
    }
    s
}

/// The anchor id of a report stem (letters, digits and `-`).
fn anchor(stem: &str) -> String {
    stem.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect()
}

/// Whether `dest` is a relative path (no scheme, not rooted, no `..`) to a file of `folder`.
fn resolves(folder: &Path, dest: &str) -> bool {
    let path = dest.split('#').next().unwrap_or_default();
    !path.is_empty()
        && !dest.contains(':')
        && !path.starts_with('/')
        && !path.starts_with('\\')
        && !path.split(['/', '\\']).any(|part| part == "..")
        && folder.join(path).is_file()
}

fn deeper(level: HeadingLevel) -> HeadingLevel {
    match level {
        HeadingLevel::H1 => HeadingLevel::H3,
        HeadingLevel::H2 => HeadingLevel::H4,
        HeadingLevel::H3 => HeadingLevel::H5,
        _ => HeadingLevel::H6,
    }
}

/// A report's Markdown as HTML (see the module notes for links and headings); also the images
/// it shows.
fn render(folder: &Path, markdown: &str, unlinked: &mut Vec<String>) -> (String, BTreeSet<String>) {
    let mut shown = BTreeSet::new();
    // per open link or image: its target, when it is written as text
    let mut dropped: Vec<Option<String>> = Vec::new();
    let mut events = Vec::new();
    for event in Parser::new_ext(markdown, Options::ENABLE_TABLES) {
        match event {
            Event::Start(Tag::Heading {
                level,
                id,
                classes,
                attrs,
            }) => events.push(Event::Start(Tag::Heading {
                level: deeper(level),
                id,
                classes,
                attrs,
            })),
            Event::End(TagEnd::Heading(level)) => {
                events.push(Event::End(TagEnd::Heading(deeper(level))))
            }
            Event::Start(Tag::Link { ref dest_url, .. })
            | Event::Start(Tag::Image { ref dest_url, .. }) => {
                if resolves(folder, dest_url) {
                    if matches!(event, Event::Start(Tag::Image { .. })) {
                        shown.insert(dest_url.to_string());
                    }
                    dropped.push(None);
                    events.push(event);
                } else {
                    unlinked.push(dest_url.to_string());
                    dropped.push(Some(dest_url.to_string()));
                }
            }
            Event::End(TagEnd::Link) | Event::End(TagEnd::Image) => match dropped.pop() {
                Some(Some(target)) => {
                    events.push(Event::Text(CowStr::from(" (")));
                    events.push(Event::Code(CowStr::from(target)));
                    events.push(Event::Text(CowStr::from(")")));
                }
                _ => events.push(event),
            },
            // raw HTML in a report is shown as text, never run
            Event::Html(h) | Event::InlineHtml(h) => events.push(Event::Text(h)),
            e => events.push(e),
        }
    }
    let mut html = String::new();
    pulldown_cmark::html::push_html(&mut html, events.into_iter());
    (html, shown)
}

/// The files of `folder` with extension `ext`, sorted (the page itself excluded).
fn files_with(folder: &Path, ext: &str) -> Result<Vec<String>> {
    let entries = std::fs::read_dir(folder)
        .map_err(|e| Error::io(folder.display(), "reading the reports folder", e))?;
    let mut names = Vec::new();
    for entry in entries {
        let entry =
            entry.map_err(|e| Error::io(folder.display(), "reading the reports folder", e))?;
        let Ok(name) = entry.file_name().into_string() else {
            continue;
        };
        if name.ends_with(&format!(".{ext}"))
            && !NOT_SHOWN.contains(&name.as_str())
            && entry.path().is_file()
        {
            names.push(name);
        }
    }
    names.sort();
    Ok(names)
}

/// The stem of the registered report whose files an SVG named `svg` belongs to (the longest
/// stem it starts with).
fn owner_of(svg: &str) -> Option<&'static str> {
    KNOWN_REPORTS
        .iter()
        .map(|r| r.stem)
        .filter(|stem| svg.starts_with(&format!("{stem}-")) || svg.starts_with(&format!("{stem}.")))
        .max_by_key(|stem| stem.len())
}

fn figure(html: &mut String, svg: &str) {
    let _ = writeln!(
        html,
        "<figure><img src=\"{0}\" alt=\"{0}\"><figcaption><a href=\"{0}\">{0}</a></figcaption></figure>",
        escape(svg)
    );
}

const STYLE: &str =
    "body{font-family:sans-serif;margin:1.5em auto;max-width:1200px;padding:0 1em;line-height:1.4}\
table{border-collapse:collapse;margin:0.8em 0;font-size:0.85em;display:block;overflow-x:auto}\
th,td{border:1px solid #bbb;padding:2px 6px;text-align:left}th{background:#eee}\
section{border-top:2px solid #444;margin-top:2em}figure{display:inline-block;margin:0.5em}\
img{max-width:560px;border:1px solid #ddd}code{background:#f4f4f4;padding:0 3px}\
.missing{color:#a00}nav li{margin:0.1em 0}";

const SCRIPT: &str = "window.addEventListener('load', function () {\n\
  var broken = 0;\n\
  for (var i = 0; i < document.images.length; i++) {\n\
    var img = document.images[i];\n\
    if (!img.complete || img.naturalWidth === 0) { img.setAttribute('data-broken', 'true'); broken++; }\n\
  }\n\
  document.body.setAttribute('data-images', String(document.images.length));\n\
  document.body.setAttribute('data-broken-images', String(broken));\n\
});";

/// Build the page for the reports in `folder`.
pub fn build(folder: &Path) -> Result<Page> {
    if !folder.is_dir() {
        return Err(Error::invalid(
            folder.display(),
            "--reports",
            "no such folder",
            "give the folder the reports were written to (default: reports)",
        ));
    }
    let markdown = files_with(folder, "md")?;
    let svgs = files_with(folder, "svg")?;
    let mut unlinked = Vec::new();
    let mut missing = Vec::new();
    let mut shown_svgs: BTreeSet<String> = BTreeSet::new();
    let mut nav = String::new();
    let mut body = String::new();
    let section = |body: &mut String,
                   nav: &mut String,
                   stem: &str,
                   title: &str,
                   command: Option<&str>,
                   unlinked: &mut Vec<String>,
                   shown_svgs: &mut BTreeSet<String>|
     -> Result<()> {
        let md = format!("{stem}.md");
        let path = folder.join(&md);
        let text =
            std::fs::read_to_string(&path).map_err(|e| Error::io(path.display(), "reading", e))?;
        let id = anchor(stem);
        let _ = writeln!(nav, "<li><a href=\"#{id}\">{}</a></li>", escape(title));
        let _ = writeln!(body, "<section id=\"{id}\">\n<h2>{}</h2>", escape(title));
        let mut files = format!("<a href=\"{0}\">{0}</a>", escape(&md));
        let json = format!("{stem}.json");
        if folder.join(&json).is_file() {
            let _ = write!(files, ", <a href=\"{0}\">{0}</a>", escape(&json));
        }
        let regenerate = command
            .map(|c| format!("; regenerate with <code>{}</code>", escape(c)))
            .unwrap_or_default();
        let _ = writeln!(body, "<p class=\"files\">Files: {files}{regenerate}.</p>");
        let (html, shown) = render(folder, &text, unlinked);
        shown_svgs.extend(shown.iter().cloned());
        for svg in svgs
            .iter()
            .filter(|s| owner_of(s) == Some(stem) && !shown.contains(*s))
        {
            figure(body, svg);
            shown_svgs.insert(svg.clone());
        }
        body.push_str(&html);
        body.push_str("</section>\n");
        Ok(())
    };
    for r in KNOWN_REPORTS {
        if markdown.contains(&format!("{}.md", r.stem)) {
            section(
                &mut body,
                &mut nav,
                r.stem,
                r.title,
                Some(r.command),
                &mut unlinked,
                &mut shown_svgs,
            )?;
        } else {
            missing.push(r.stem);
        }
    }
    let others: Vec<&String> = markdown
        .iter()
        .filter(|m| {
            !KNOWN_REPORTS
                .iter()
                .any(|r| format!("{}.md", r.stem) == **m)
        })
        .collect();
    for md in others {
        let stem = md.trim_end_matches(".md");
        let path = folder.join(md);
        let text =
            std::fs::read_to_string(&path).map_err(|e| Error::io(path.display(), "reading", e))?;
        let title = text
            .lines()
            .find_map(|l| l.strip_prefix("# "))
            .unwrap_or(stem)
            .to_string();
        section(
            &mut body,
            &mut nav,
            stem,
            &format!("Other report: {title}"),
            None,
            &mut unlinked,
            &mut shown_svgs,
        )?;
    }
    let loose: Vec<&String> = svgs.iter().filter(|s| !shown_svgs.contains(*s)).collect();
    if !loose.is_empty() {
        let _ = writeln!(nav, "<li><a href=\"#other-figures\">Other figures</a></li>");
        let _ = writeln!(
            body,
            "<section id=\"other-figures\">\n<h2>Other figures</h2>"
        );
        for svg in loose {
            figure(&mut body, svg);
        }
        body.push_str("</section>\n");
    }
    if !missing.is_empty() {
        let _ = writeln!(
            nav,
            "<li><a href=\"#not-generated\">Not generated yet</a></li>"
        );
        let _ = writeln!(
            body,
            "<section id=\"not-generated\">\n<h2>Not generated yet</h2>\n<ul>"
        );
        for stem in &missing {
            let r = KNOWN_REPORTS
                .iter()
                .find(|r| r.stem == *stem)
                .expect("registered");
            let _ = writeln!(
                body,
                "<li class=\"missing\">{} (<code>{}.md</code>): not generated yet, run <code>{}</code></li>",
                escape(r.title),
                escape(stem),
                escape(r.command)
            );
        }
        body.push_str("</ul>\n</section>\n");
    }
    let html = format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>contact-patch reports</title>\n<style>{STYLE}</style>\n</head>\n<body>\n\
         <h1>contact-patch reports</h1>\n\
         <p>Every table, plot and study in this folder, generated by <code>contact-patch report</code> \
         from the reports' Markdown, JSON and SVG files. Each section names the command that \
         regenerates it.</p>\n<nav>\n<ul>\n{nav}</ul>\n</nav>\n{body}<script>\n{SCRIPT}\n</script>\n\
         </body>\n</html>\n"
    );
    let targets = attribute_values(&html);
    Ok(Page {
        tables: html.matches("<table").count(),
        images: html.matches("<img ").count(),
        targets,
        html,
        missing,
        unlinked,
    })
}

/// Every `href="..."` and `src="..."` value of `html` (unescaped `&amp;`).
pub fn attribute_values(html: &str) -> Vec<String> {
    let mut out = Vec::new();
    for key in ["href=\"", "src=\""] {
        let mut rest = html;
        while let Some(k) = rest.find(key) {
            let after = &rest[k + key.len()..];
            let end = after.find('"').unwrap_or(after.len());
            // only attributes (preceded by a space), not text that mentions them
            if rest[..k].ends_with(' ') {
                out.push(after[..end].replace("&amp;", "&"));
            }
            rest = &after[end..];
        }
    }
    out
}

/// Write `index.html` into the reports folder `folder`; returns the page.
pub fn write(folder: &ReportFolder) -> Result<Page> {
    let page = build(folder.path())?;
    folder.write_file(INDEX_FILE, &page.html)?;
    Ok(page)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn links_of_a_report_resolve_or_become_text() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("a.svg"),
            "<svg xmlns=\"http://www.w3.org/2000/svg\"/>",
        )
        .unwrap();
        let mut unlinked = Vec::new();
        let md = "# T\n\n![a](a.svg) [gone](gone.svg) [web](https://example.org) [up](../x.md)\n\n| x | y |\n|---|---|\n| 1 | 2 |\n\n<script>alert(1)</script>\n";
        let (html, shown) = render(dir.path(), md, &mut unlinked);
        assert!(html.contains("<h3>T</h3>"), "{html}");
        assert!(html.contains("<img src=\"a.svg\""), "{html}");
        assert!(html.contains("gone (<code>gone.svg</code>)"), "{html}");
        assert!(!html.contains("https://example.org\""), "{html}");
        assert!(!html.contains("<script>"), "{html}");
        assert!(html.contains("<table>"), "{html}");
        assert_eq!(unlinked, ["gone.svg", "https://example.org", "../x.md"]);
        assert_eq!(shown.into_iter().collect::<Vec<_>>(), ["a.svg"]);
        assert_eq!(
            escape("<a href=\"x\">&'"),
            "&lt;a href=&quot;x&quot;&gt;&amp;&#39;"
        );
        assert_eq!(owner_of("tied-layer-q4-uy.svg"), Some("tied-layer"));
        assert_eq!(
            owner_of("hertz-profile.cylinder.pressure.svg"),
            Some("hertz-profile.cylinder.pressure")
        );
        assert_eq!(owner_of("patchwork.svg"), None);
    }
}
