//! The shape of `src/` as a test over its imports (issue 40, item 6; the design review's
//! "N + M in the import direction").
//!
//! The graph has a node per source file (a module; `mod.rs` stands for its folder) and an edge
//! `a -> b` when file `a` names a path into module `b`: `crate::x::y`, `super::x`, `self::x`,
//! `super::super::x`, and every leaf of a use tree such as `crate::{a, b::{c, d}}`. A path is
//! resolved to the longest prefix that is a file; a reference between a module and its own
//! ancestor or descendant is the module tree itself and is not an edge. Comments and the
//! `#[cfg(test)]` part of a file are not read.
//!
//! What holds:
//! * **No import cycle** between files: a strongly connected component of more than one file
//!   (Tarjan 1972) is a cycle, printed with the edges inside it and the lines that make them.
//! * **The discretization axis stands alone**: nothing under `src/contact/discretization/`
//!   imports the enforcement methods (`contact::enforcement`) or the solver (`solver`), so each
//!   discretization ends in a [`contact_patch::contact::Constraint`] that every method treats
//!   (Taylor 2004, "1985: Solution Methods": one constraint form for all enforcements).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// A module's path from the crate root, e.g. `["contact", "discretization", "mortar"]`.
type ModulePath = Vec<String>;

/// One reference of a file to another: the target file and the line it is named on.
#[derive(Clone, Debug)]
struct Reference {
    target: ModulePath,
    line: usize,
}

/// The source files of the crate rooted at `root` (`lib.rs` and `main.rs` excluded: roots of
/// the tree, not modules), by module path.
fn source_files(root: &Path) -> BTreeMap<ModulePath, String> {
    fn walk(dir: &Path, root: &Path, out: &mut BTreeMap<ModulePath, String>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir)
            .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
            .map(|e| e.expect("a directory entry").path())
            .collect();
        entries.sort();
        for path in entries {
            if path.is_dir() {
                walk(&path, root, out);
            } else if path.extension().is_some_and(|x| x == "rs") {
                let relative = path.strip_prefix(root).expect("under the root");
                let mut parts: ModulePath = relative
                    .with_extension("")
                    .iter()
                    .map(|p| p.to_string_lossy().into_owned())
                    .collect();
                if parts.last().is_some_and(|p| p == "mod") {
                    parts.pop();
                }
                if parts == ["lib"] || parts == ["main"] {
                    continue;
                }
                let text = std::fs::read_to_string(&path)
                    .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
                out.insert(parts, text);
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(root, root, &mut out);
    out
}

/// The code of a file that the graph reads: up to its first `#[cfg(test)]`, with `//`
/// comments blanked (lines kept, so line numbers stay right).
fn code_of(text: &str) -> Vec<String> {
    let mut lines = Vec::new();
    for line in text.lines() {
        if line.trim_start().starts_with("#[cfg(test)]") {
            break;
        }
        lines.push(match line.find("//") {
            Some(at) => line[..at].to_string(),
            None => line.to_string(),
        });
    }
    lines
}

fn is_ident_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// The leaf paths of the use tree that starts at `chars[at]` (just after a `kw::`), each as
/// its segments, and where the tree ends.
fn use_tree(chars: &[char], mut at: usize) -> (Vec<Vec<String>>, usize) {
    let skip_space = |at: &mut usize| {
        while *at < chars.len() && chars[*at].is_whitespace() {
            *at += 1;
        }
    };
    let mut prefix: Vec<String> = Vec::new();
    loop {
        skip_space(&mut at);
        if at < chars.len() && chars[at] == '{' {
            // a group: each member is a tree of its own below `prefix`
            at += 1;
            let mut leaves = Vec::new();
            loop {
                skip_space(&mut at);
                if at >= chars.len() {
                    return (leaves, at);
                }
                if chars[at] == '}' {
                    return (leaves, at + 1);
                }
                if chars[at] == ',' {
                    at += 1;
                    continue;
                }
                let (inner, end) = use_tree(chars, at);
                if end == at {
                    // not a path (e.g. `*`): skip the character
                    at += 1;
                    continue;
                }
                for leaf in inner {
                    leaves.push(prefix.iter().cloned().chain(leaf).collect());
                }
                at = end;
            }
        }
        let start = at;
        while at < chars.len() && is_ident_char(chars[at]) {
            at += 1;
        }
        if at == start {
            let leaves = if prefix.is_empty() {
                vec![]
            } else {
                vec![prefix]
            };
            return (leaves, at);
        }
        prefix.push(chars[start..at].iter().collect());
        if chars.get(at) == Some(&':') && chars.get(at + 1) == Some(&':') {
            at += 2;
        } else {
            return (vec![prefix], at);
        }
    }
}

/// The module paths file `module` names, with the line of each (1-based).
fn named_paths(module: &ModulePath, text: &str) -> Vec<(ModulePath, usize)> {
    let lines = code_of(text);
    let code = lines.join("\n");
    let chars: Vec<char> = code.chars().collect();
    let line_of = |at: usize| chars[..at].iter().filter(|&&c| c == '\n').count() + 1;
    let mut out = Vec::new();
    let mut at = 0;
    while at < chars.len() {
        let boundary = at == 0 || !is_ident_char(chars[at - 1]);
        let keyword = ["crate", "super", "self"].into_iter().find(|kw| {
            let end = at + kw.len();
            boundary
                && chars.len() > end + 1
                && chars[at..end].iter().copied().eq(kw.chars())
                && chars[end] == ':'
                && chars[end + 1] == ':'
        });
        let Some(kw) = keyword else {
            at += 1;
            continue;
        };
        let base: ModulePath = match kw {
            "crate" => vec![],
            "super" => module[..module.len().saturating_sub(1)].to_vec(),
            _ => module.clone(),
        };
        let (leaves, end) = use_tree(&chars, at + kw.len() + 2);
        for mut leaf in leaves {
            // `super::super::x`: each further `super` climbs one module
            let mut climbed = base.clone();
            while leaf.first().is_some_and(|s| s == "super") {
                leaf.remove(0);
                climbed.pop();
            }
            if leaf.first().is_some_and(|s| s == "self") {
                leaf.remove(0);
            }
            out.push((climbed.into_iter().chain(leaf).collect(), line_of(at)));
        }
        at = end.max(at + 1);
    }
    out
}

/// The import graph of the crate rooted at `root`: for each file, the files it references.
fn import_graph(root: &Path) -> BTreeMap<ModulePath, BTreeMap<ModulePath, Vec<Reference>>> {
    let files = source_files(root);
    let resolve = |path: &ModulePath| -> Option<ModulePath> {
        (1..=path.len())
            .rev()
            .map(|n| path[..n].to_vec())
            .find(|p| files.contains_key(p))
    };
    let mut graph = BTreeMap::new();
    for (module, text) in &files {
        let mut edges: BTreeMap<ModulePath, Vec<Reference>> = BTreeMap::new();
        for (path, line) in named_paths(module, text) {
            let Some(target) = resolve(&path) else {
                continue;
            };
            let related = target.starts_with(module) || module.starts_with(&target);
            if !related {
                edges
                    .entry(target.clone())
                    .or_default()
                    .push(Reference { target, line });
            }
        }
        graph.insert(module.clone(), edges);
    }
    graph
}

/// The strongly connected components of more than one file (Tarjan's algorithm).
fn cycles(
    graph: &BTreeMap<ModulePath, BTreeMap<ModulePath, Vec<Reference>>>,
) -> Vec<Vec<ModulePath>> {
    struct Tarjan<'a> {
        graph: &'a BTreeMap<ModulePath, BTreeMap<ModulePath, Vec<Reference>>>,
        index: BTreeMap<&'a ModulePath, usize>,
        low: BTreeMap<&'a ModulePath, usize>,
        stack: Vec<&'a ModulePath>,
        on_stack: BTreeSet<&'a ModulePath>,
        found: Vec<Vec<ModulePath>>,
    }
    impl<'a> Tarjan<'a> {
        fn visit(&mut self, v: &'a ModulePath) {
            let n = self.index.len();
            self.index.insert(v, n);
            self.low.insert(v, n);
            self.stack.push(v);
            self.on_stack.insert(v);
            for w in self.graph[v].keys() {
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let low = self.low[v].min(self.low[w]);
                    self.low.insert(v, low);
                } else if self.on_stack.contains(w) {
                    let low = self.low[v].min(self.index[w]);
                    self.low.insert(v, low);
                }
            }
            if self.low[v] == self.index[v] {
                let mut component = Vec::new();
                loop {
                    let w = self.stack.pop().expect("v is on the stack");
                    self.on_stack.remove(w);
                    component.push(w.clone());
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    component.sort();
                    self.found.push(component);
                }
            }
        }
    }
    let mut tarjan = Tarjan {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        found: Vec::new(),
    };
    for v in graph.keys() {
        if !tarjan.index.contains_key(v) {
            tarjan.visit(v);
        }
    }
    tarjan.found
}

fn name(module: &ModulePath) -> String {
    module.join("/")
}

/// The cycles of `graph`, each with the edges inside it and their lines, as a report.
fn cycle_report(graph: &BTreeMap<ModulePath, BTreeMap<ModulePath, Vec<Reference>>>) -> String {
    let mut report = String::new();
    for component in cycles(graph) {
        let members: Vec<String> = component.iter().map(name).collect();
        report += &format!("cycle: {}\n", members.join(", "));
        for from in &component {
            for (to, references) in &graph[from] {
                if component.contains(to) {
                    let lines: BTreeSet<usize> = references.iter().map(|r| r.line).collect();
                    let lines: Vec<String> = lines.iter().map(usize::to_string).collect();
                    report += &format!(
                        "  src/{}.rs -> {} (lines {})\n",
                        name(from),
                        name(&references[0].target),
                        lines.join(", ")
                    );
                }
            }
        }
    }
    report
}

fn crate_source() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

#[test]
fn the_source_files_import_one_another_without_a_cycle() {
    let graph = import_graph(&crate_source());
    assert!(
        graph.len() > 50,
        "the source tree was not read: {} files",
        graph.len()
    );
    let report = cycle_report(&graph);
    assert!(
        report.is_empty(),
        "import cycles between source files (move what both sides need below both):\n{report}"
    );
}

#[test]
fn discretization_code_imports_no_enforcement_and_no_solver() {
    let graph = import_graph(&crate_source());
    let discretization: ModulePath = vec!["contact".into(), "discretization".into()];
    let forbidden: [ModulePath; 2] = [
        vec!["contact".into(), "enforcement".into()],
        vec!["solver".into()],
    ];
    let mut files = 0;
    let mut offences = Vec::new();
    for (module, edges) in &graph {
        if !module.starts_with(&discretization) {
            continue;
        }
        files += 1;
        for (target, references) in edges {
            if forbidden.iter().any(|f| target.starts_with(f)) {
                offences.push(format!(
                    "src/{}.rs imports {} (line {})",
                    name(module),
                    name(target),
                    references[0].line
                ));
            }
        }
    }
    assert!(files >= 10, "only {files} discretization files were read");
    assert!(
        offences.is_empty(),
        "a discretization must end in Constraint rows and know no enforcement or solver:\n{}",
        offences.join("\n")
    );
}

/// A small crate written to a temporary folder, to show the graph sees what the tests above
/// rely on: `super::`, `self::`, groups, nested groups, `super::super::`, comments and test
/// code ignored, and the module tree not counted.
#[test]
fn the_import_graph_finds_cycles_through_every_kind_of_path() {
    let dir = std::env::temp_dir().join(format!("contact-patch-imports-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let write = |path: &str, text: &str| {
        let file = dir.join(path);
        std::fs::create_dir_all(file.parent().expect("a parent")).expect("a folder");
        std::fs::write(file, text).expect("written");
    };
    write("lib.rs", "pub mod a;\npub mod b;\npub mod c;\n");
    write(
        "a/mod.rs",
        "pub mod inner;\nuse self::inner::X;\n// use crate::c::Y;\n",
    );
    write("a/inner.rs", "use super::super::b::{self, Z};\n");
    write("b.rs", "use crate::{c::{Q, R}, a::inner as i};\n");
    write(
        "c.rs",
        "pub struct Q;\n#[cfg(test)]\nmod tests { use crate::a::inner::X; }\n",
    );
    let graph = import_graph(&dir);
    let module = |p: &str| -> ModulePath { p.split('/').map(String::from).collect() };
    let targets = |p: &str| -> Vec<String> { graph[&module(p)].keys().map(name).collect() };
    assert_eq!(
        targets("a"),
        Vec::<String>::new(),
        "a's own child and a comment are no edge"
    );
    assert_eq!(targets("a/inner"), vec!["b"]);
    assert_eq!(targets("b"), vec!["a/inner", "c"]);
    assert_eq!(targets("c"), Vec::<String>::new(), "test code is no edge");
    let found = cycles(&graph);
    assert_eq!(found, vec![vec![module("a/inner"), module("b")]]);
    let report = cycle_report(&graph);
    assert!(report.contains("src/a/inner.rs -> b (lines 1)"), "{report}");
    assert!(report.contains("src/b.rs -> a/inner (lines 1)"), "{report}");
    // breaking the cycle: b no longer names a
    write("b.rs", "use crate::c::Q;\n");
    assert!(cycles(&import_graph(&dir)).is_empty());
    std::fs::remove_dir_all(&dir).expect("removed");
}
