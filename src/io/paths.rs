//! Every path the tool writes goes through this module.
//!
//! Two rules keep a user's files safe:
//!
//! 1. **Names are not paths.** A case, body, pair, catalogue or study name becomes part of a file
//!    name only through [`file_name`], which accepts the alphabet [`NAME_RULE`] states (ASCII
//!    letters, digits, `-`, `_` and `.`, not starting with `.`, at most [`NAME_MAX`] characters)
//!    and refuses anything else with the name and the rule. No name can contain a separator,
//!    be `.`/`..`, be absolute or be hidden.
//! 2. **An output folder is the only place written or removed.** [`OutputFolder`] is a folder
//!    the tool owns as a whole (`run`'s output): it is never the working folder, one of its
//!    parents, the file-system root or the home folder, nor a symbolic link; an existing folder
//!    is replaced only when it is empty or holds exactly the files a previous run listed in its
//!    manifest ([`MANIFEST`]). The new content is built in a temporary folder beside the target
//!    and renamed into place; on any failure the temporary folder (which this process created)
//!    is removed. [`ReportFolder`] is a folder the tool writes named files into (`table`,
//!    `tied-layer`): the same refusals, each file written under a temporary name and renamed
//!    over the file of the same name; nothing else in the folder is touched.
//! 3. **A file the user names is written exactly there, and nothing else.** [`NamedFile`] is a
//!    single file given on the command line (`--junit FILE`): its folder must exist (nothing is
//!    created), the path must not be a folder, a symbolic link or anything but a regular file,
//!    and the text goes to a new temporary file beside it (created exclusively, so no other
//!    file is opened) that is renamed over it; on failure only that temporary file is removed.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::fs;
use std::path::{Component, Path, PathBuf};

/// The longest name accepted.
pub const NAME_MAX: usize = 100;

/// The rule names follow, quoted in every refusal.
pub const NAME_RULE: &str = "names become file names: use ASCII letters, digits, '-', '_' and \
'.', not starting with '.', at most 100 characters";

/// The manifest a run output folder carries: the files the tool wrote there.
pub const MANIFEST: &str = ".contact-patch-output.json";

/// Why `name` is not a safe file-name component, or `None` when it is.
pub fn name_problem(name: &str) -> Option<String> {
    if name.is_empty() {
        return Some("the name is empty".into());
    }
    if name.chars().count() > NAME_MAX {
        return Some(format!(
            "the name has {} characters (at most {NAME_MAX})",
            name.chars().count()
        ));
    }
    if name.starts_with('.') {
        return Some(format!(
            "the name '{}' starts with '.'",
            name.escape_debug()
        ));
    }
    if let Some(c) = name
        .chars()
        .find(|c| !(c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.')))
    {
        return Some(format!(
            "the name '{}' contains '{}'",
            name.escape_debug(),
            c.escape_debug()
        ));
    }
    None
}

/// `name` + `suffix` as a file name, when `name` follows [`NAME_RULE`]; `what` says what the name
/// names (e.g. "body name") in the refusal.
pub fn file_name(what: &str, name: &str, suffix: &str) -> Result<String> {
    match name_problem(name) {
        None => Ok(format!("{name}{suffix}")),
        Some(problem) => Err(Error::invalid(
            what,
            name.escape_debug(),
            problem,
            NAME_RULE,
        )),
    }
}

/// `path` made absolute against the working folder, `.` and `..` resolved, and the part of it
/// that exists resolved through symbolic links.
fn resolve(path: &Path) -> Result<PathBuf> {
    let io = |e| Error::io(path.display(), "resolving the output folder", e);
    let cwd = std::env::current_dir().map_err(io)?;
    let mut lexical = PathBuf::new();
    for c in cwd.join(path).components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                lexical.pop();
            }
            other => lexical.push(other),
        }
    }
    let mut existing = lexical.clone();
    let mut missing = Vec::new();
    while fs::symlink_metadata(&existing).is_err() {
        match existing.file_name() {
            Some(n) => missing.push(n.to_os_string()),
            None => break,
        }
        existing.pop();
    }
    let mut resolved = existing.canonicalize().map_err(io)?;
    // A symbolic link at the target itself is refused later; keep its own name.
    if missing.is_empty() && fs::symlink_metadata(&lexical).is_ok_and(|m| m.is_symlink()) {
        resolved = existing
            .parent()
            .map(|p| p.canonicalize().map_err(io))
            .transpose()?
            .unwrap_or_default()
            .join(lexical.file_name().unwrap_or_default());
    }
    for n in missing.into_iter().rev() {
        resolved.push(n);
    }
    Ok(resolved)
}

fn home_folder() -> Option<PathBuf> {
    std::env::var_os("HOME")
        .filter(|h| !h.is_empty())
        .map(PathBuf::from)
        .and_then(|h| h.canonicalize().ok())
}

/// Refuse output folders whose removal or replacement would touch what is not the tool's:
/// the root, the home folder or one of its parents, the working folder or one of its parents,
/// a symbolic link, an existing non-folder.
fn refuse_protected(given: &Path, resolved: &Path) -> Result<()> {
    let refuse = |problem: String| {
        Err(Error::invalid(
            given.display(),
            "the output folder",
            problem,
            "give a new or previously written output folder below the working folder, e.g. --out out/NAME",
        ))
    };
    if resolved.parent().is_none() {
        return refuse("is the root of the file system".into());
    }
    if let Ok(cwd) = std::env::current_dir().and_then(|c| c.canonicalize()) {
        if cwd.starts_with(resolved) {
            return refuse(format!(
                "is the working folder or one of its parents ({})",
                resolved.display()
            ));
        }
    }
    if let Some(home) = home_folder() {
        if home.starts_with(resolved) {
            return refuse(format!(
                "is the home folder or one of its parents ({})",
                resolved.display()
            ));
        }
    }
    if let Ok(meta) = fs::symlink_metadata(resolved) {
        if meta.is_symlink() {
            return refuse("is a symbolic link; give the folder itself".into());
        }
        if !meta.is_dir() {
            return refuse("exists and is not a folder".into());
        }
    }
    Ok(())
}

/// What a previous run wrote into its output folder.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    tool: String,
    files: Vec<String>,
}

/// Create the file `path` in a folder this process is filling (an [`OutputFolder`]'s staging
/// folder), refusing to open a file that is already there: two outputs of one case that would
/// carry the same name (a body called `a.contact` beside a pair `a`, a body called like another
/// body's frame) are an error naming the file, never one output silently written over another.
pub fn create_new_file(path: &Path) -> Result<fs::File> {
    fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)
        .map_err(|e| {
            if e.kind() == std::io::ErrorKind::AlreadyExists {
                let name = path
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default();
                Error::invalid(
                    path.display(),
                    "the output files",
                    format!("two outputs of this case would both be named '{name}'"),
                    "rename a body or a contact pair so that its files (<body>.vtu, \
                     <body>.frame-NNNN.vtu, <body>.pvd, <pair>.contact.vtu/.csv/.json) differ \
                     from the others and from summary.json and history.*",
                )
            } else {
                Error::io(path.display(), "creating", e)
            }
        })
}

/// [`create_new_file`], then write `text` into it.
pub fn write_new_file(path: &Path, text: &str) -> Result<()> {
    use std::io::Write;
    create_new_file(path)?
        .write_all(text.as_bytes())
        .map_err(|e| Error::io(path.display(), "writing", e))
}

/// A folder the tool owns as a whole: built aside, then moved into place.
#[derive(Debug)]
pub struct OutputFolder {
    given: PathBuf,
    target: PathBuf,
}

/// A folder this process created and removes again unless it was moved into place.
struct Staging {
    path: PathBuf,
    keep: bool,
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.keep {
            let _ = fs::remove_dir_all(&self.path);
        }
    }
}

/// Create a new folder `stem-N` (the first `N` free) in `parent`.
fn create_unique_folder(parent: &Path, stem: &str) -> Result<Staging> {
    for n in 0..1000 {
        let path = parent.join(format!("{stem}-{n}"));
        match fs::create_dir(&path) {
            Ok(()) => return Ok(Staging { path, keep: false }),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => {
                return Err(Error::io(
                    path.display(),
                    "creating the temporary output folder",
                    e,
                ))
            }
        }
    }
    Err(Error::invalid(
        parent.display(),
        "the output folder's parent",
        format!("holds 1000 folders named {stem}-N"),
        "remove the leftover temporary folders",
    ))
}

impl OutputFolder {
    /// Check that `path` may be written as a whole (see the module notes); nothing is created.
    pub fn new(path: &Path) -> Result<OutputFolder> {
        let target = resolve(path)?;
        refuse_protected(path, &target)?;
        let folder = OutputFolder {
            given: path.to_path_buf(),
            target,
        };
        folder.previous_files()?;
        Ok(folder)
    }

    pub fn path(&self) -> &Path {
        &self.given
    }

    /// The files of a previous output at the target (empty when there is none), or a refusal
    /// when the target holds anything this tool did not write.
    fn previous_files(&self) -> Result<Vec<String>> {
        let refuse = |problem: String| {
            Err(Error::invalid(
                self.given.display(),
                "the output folder",
                problem,
                "it is replaced only when it holds a previous output of contact-patch; \
                 choose another --out folder, or empty or remove this one yourself",
            ))
        };
        let entries = match fs::read_dir(&self.target) {
            Ok(entries) => entries,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
            Err(e) => {
                return Err(Error::io(
                    self.given.display(),
                    "reading the output folder",
                    e,
                ))
            }
        };
        let mut names = Vec::new();
        for entry in entries {
            let entry = entry
                .map_err(|e| Error::io(self.given.display(), "reading the output folder", e))?;
            names.push(entry.file_name().to_string_lossy().into_owned());
        }
        if names.is_empty() {
            return Ok(names);
        }
        let manifest_path = self.target.join(MANIFEST);
        let manifest: Option<Manifest> = fs::read_to_string(&manifest_path)
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok());
        let Some(manifest) = manifest.filter(|m| m.tool == env!("CARGO_PKG_NAME")) else {
            return refuse(format!(
                "exists and holds files that are not a contact-patch output (no valid {MANIFEST})"
            ));
        };
        for name in &names {
            if name == MANIFEST {
                continue;
            }
            let meta = fs::symlink_metadata(self.target.join(name));
            let listed = manifest.files.contains(name) && name_problem_in_folder(name).is_none();
            if !listed || !meta.is_ok_and(|m| m.is_file()) {
                return refuse(format!(
                    "holds '{}', which the previous run of contact-patch did not write",
                    name.escape_debug()
                ));
            }
        }
        names.retain(|n| n != MANIFEST);
        names.push(MANIFEST.to_string());
        Ok(names)
    }

    /// Build the folder's content with `fill` (given the temporary folder to write into), write
    /// the manifest, then move the result into place, replacing a previous output.
    pub fn write(&self, fill: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
        let parent = self.target.parent().unwrap_or(Path::new("/"));
        let name = self
            .target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "out".into());
        fs::create_dir_all(parent)
            .map_err(|e| Error::io(parent.display(), "creating the output folder", e))?;
        let mut staging =
            create_unique_folder(parent, &format!(".{name}.partial-{}", std::process::id()))?;
        fill(&staging.path)?;
        let mut files = Vec::new();
        for entry in fs::read_dir(&staging.path)
            .map_err(|e| Error::io(staging.path.display(), "listing the output", e))?
        {
            let entry =
                entry.map_err(|e| Error::io(staging.path.display(), "listing the output", e))?;
            files.push(entry.file_name().to_string_lossy().into_owned());
        }
        files.sort();
        let manifest = Manifest {
            tool: env!("CARGO_PKG_NAME").into(),
            files,
        };
        let manifest_path = staging.path.join(MANIFEST);
        let text = serde_json::to_string_pretty(&manifest).expect("the manifest serializes");
        fs::write(&manifest_path, text + "\n")
            .map_err(|e| Error::io(manifest_path.display(), "writing", e))?;

        // Checked again just before replacing: the folder may have changed during the solve.
        let previous = self.previous_files()?;
        let moved_in = |staging: &mut Staging| {
            fs::rename(&staging.path, &self.target)
                .map_err(|e| Error::io(self.given.display(), "moving the output into place", e))?;
            staging.keep = true;
            Ok::<(), Error>(())
        };
        if fs::symlink_metadata(&self.target).is_err() {
            return moved_in(&mut staging);
        }
        // Set the previous output aside, move the new one in, then delete the old files by name.
        let old = (0..1000)
            .map(|n| parent.join(format!(".{name}.previous-{}-{n}", std::process::id())))
            .find(|p| fs::symlink_metadata(p).is_err())
            .ok_or_else(|| {
                Error::invalid(
                    parent.display(),
                    "the output folder's parent",
                    "holds 1000 leftover folders of earlier replacements",
                    "remove the folders named .NAME.previous-*",
                )
            })?;
        fs::rename(&self.target, &old)
            .map_err(|e| Error::io(self.given.display(), "replacing the previous output", e))?;
        if let Err(e) = moved_in(&mut staging) {
            let _ = fs::rename(&old, &self.target);
            return Err(e);
        }
        for file in &previous {
            let _ = fs::remove_file(old.join(file));
        }
        // Non-recursive: if anything unexpected appeared meanwhile, it stays (and so does the
        // folder holding it).
        let _ = fs::remove_dir(&old);
        Ok(())
    }
}

/// Files in a run folder are plain names (the manifest is checked against this too).
fn name_problem_in_folder(name: &str) -> Option<String> {
    if name == MANIFEST {
        None
    } else {
        name_problem(name)
    }
}

/// A folder the tool writes named report files into; other files in it are left alone.
#[derive(Debug)]
pub struct ReportFolder {
    given: PathBuf,
    target: PathBuf,
}

impl ReportFolder {
    /// Check that `path` is not a protected folder (see the module notes); nothing is created.
    pub fn new(path: &Path) -> Result<ReportFolder> {
        let target = resolve(path)?;
        refuse_protected(path, &target)?;
        Ok(ReportFolder {
            given: path.to_path_buf(),
            target,
        })
    }

    pub fn path(&self) -> &Path {
        &self.given
    }

    /// The path of the file `name` + `suffix` in this folder (what the user reads in messages).
    pub fn shown(&self, name: &str) -> PathBuf {
        self.given.join(name)
    }

    fn create(&self) -> Result<()> {
        fs::create_dir_all(&self.target)
            .map_err(|e| Error::io(self.given.display(), "creating the output folder", e))
    }

    /// Write `text` to the file `name` (checked against [`NAME_RULE`]), under a temporary name
    /// first, then renamed over any file of that name.
    pub fn write_file(&self, name: &str, text: &str) -> Result<()> {
        if let Some(problem) = name_problem(name) {
            return Err(Error::invalid(
                name,
                "the report file name",
                problem,
                NAME_RULE,
            ));
        }
        self.create()?;
        let target = self.target.join(name);
        if fs::symlink_metadata(&target).is_ok_and(|m| !m.is_file()) {
            return Err(Error::invalid(
                self.shown(name).display(),
                "the report file",
                "exists and is not a regular file",
                "remove it or choose another --out folder",
            ));
        }
        let tmp = self
            .target
            .join(format!(".{name}.partial-{}", std::process::id()));
        let result = fs::write(&tmp, text).and_then(|_| fs::rename(&tmp, &target));
        if let Err(e) = result {
            let _ = fs::remove_file(&tmp);
            return Err(Error::io(self.shown(name).display(), "writing", e));
        }
        Ok(())
    }

    /// A run output folder `name` inside this report folder.
    pub fn run_folder(&self, name: &str) -> Result<OutputFolder> {
        let name = file_name("output folder name", name, "")?;
        self.create()?;
        OutputFolder::new(&self.given.join(name))
    }

    /// A report sub-folder `name`.
    pub fn sub_folder(&self, name: &str) -> Result<ReportFolder> {
        let name = file_name("report folder name", name, "")?;
        ReportFolder::new(&self.given.join(name))
    }
}

/// One file the user names explicitly (e.g. `--junit FILE`), written as a whole.
#[derive(Debug)]
pub struct NamedFile {
    given: PathBuf,
    what: &'static str,
    target: PathBuf,
}

impl NamedFile {
    /// Check that `path` may be written (see the module notes); nothing is created. `what`
    /// names the file in refusals (e.g. "the --junit file").
    pub fn new(path: &Path, what: &'static str) -> Result<NamedFile> {
        let refuse =
            |problem: &str, hint: &str| Err(Error::invalid(path.display(), what, problem, hint));
        let hint = "give the path of a file (new or to be replaced) in an existing folder, e.g. out/junit.xml";
        if path.as_os_str().is_empty() {
            return refuse("is empty", hint);
        }
        let Some(name) = path.file_name() else {
            return refuse("does not end in a file name", hint);
        };
        let raw = path.as_os_str().to_string_lossy();
        if raw.ends_with('/') || raw.ends_with("/.") || raw == "." {
            return refuse("ends with a separator or '.' (a folder)", hint);
        }
        let parent = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let parent = match parent.canonicalize() {
            Ok(p) if p.is_dir() => p,
            Ok(_) => return refuse("has a parent that is not a folder", hint),
            Err(_) => {
                return refuse(
                    "is in a folder that does not exist",
                    "create the folder first (the tool does not create it), or give a file in an existing folder",
                )
            }
        };
        let target = parent.join(name);
        let file = NamedFile {
            given: path.to_path_buf(),
            what,
            target,
        };
        file.refuse_existing()?;
        Ok(file)
    }

    /// The path as the user gave it.
    pub fn path(&self) -> &Path {
        &self.given
    }

    /// Refuse a target that exists and is not a regular file (a folder, a symbolic link...).
    fn refuse_existing(&self) -> Result<()> {
        match fs::symlink_metadata(&self.target) {
            Err(_) => Ok(()),
            Ok(m) if m.is_symlink() => Err(Error::invalid(
                self.given.display(),
                self.what,
                "is a symbolic link",
                "give the file itself, not a link to it",
            )),
            Ok(m) if m.is_dir() => Err(Error::invalid(
                self.given.display(),
                self.what,
                "is a folder",
                "give a file name inside the folder, e.g. DIR/junit.xml",
            )),
            Ok(m) if !m.is_file() => Err(Error::invalid(
                self.given.display(),
                self.what,
                "exists and is not a regular file",
                "give the path of a regular file or of a new one",
            )),
            Ok(_) => Ok(()),
        }
    }

    /// Write `text`: to a new temporary file beside the target, then renamed over it.
    pub fn write(&self, text: &str) -> Result<()> {
        use std::io::Write;
        // Checked again: the path may have changed since `new`.
        self.refuse_existing()?;
        let parent = self.target.parent().unwrap_or(Path::new("/"));
        let name = self
            .target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let io = |e| Error::io(self.given.display(), "writing", e);
        let (tmp, mut handle) = (0..1000)
            .find_map(|n| {
                let tmp = parent.join(format!(".{name}.partial-{}-{n}", std::process::id()));
                match fs::OpenOptions::new()
                    .write(true)
                    .create_new(true)
                    .open(&tmp)
                {
                    Ok(h) => Some(Ok((tmp, h))),
                    Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => None,
                    Err(e) => Some(Err(e)),
                }
            })
            .unwrap_or_else(|| {
                Err(std::io::Error::other(
                    "1000 leftover temporary files named .NAME.partial-*",
                ))
            })
            .map_err(io)?;
        let result = handle
            .write_all(text.as_bytes())
            .and_then(|_| handle.sync_all())
            .map_err(io)
            .and_then(|_| self.refuse_existing())
            .and_then(|_| fs::rename(&tmp, &self.target).map_err(io));
        if result.is_err() {
            let _ = fs::remove_file(&tmp);
        }
        result
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_that_are_paths_are_refused() {
        for bad in [
            "", ".", "..", "../x", "/tmp/x", "a/b", "a\\b", ".hidden", "a b", "é", "a\0b", "~",
        ] {
            assert!(name_problem(bad).is_some(), "{bad:?} accepted");
            assert!(file_name("case name", bad, ".vtu").is_err());
        }
        assert!(name_problem(&"x".repeat(NAME_MAX + 1)).is_some());
        for good in [
            "patch-A-nu0.3",
            "block",
            "q4_layer.v2",
            &"x".repeat(NAME_MAX),
        ] {
            assert_eq!(name_problem(good), None, "{good:?} refused");
        }
        assert_eq!(
            file_name("body name", "block", ".vtu").unwrap(),
            "block.vtu"
        );
    }

    #[test]
    fn refusal_states_the_rule() {
        let e = file_name("case name", "..", "").unwrap_err().to_string();
        assert!(
            e.contains("case name") && e.contains("starts with '.'"),
            "{e}"
        );
        assert!(e.contains("ASCII letters, digits"), "{e}");
    }

    #[test]
    fn protected_folders_are_refused() {
        for p in [".", "..", "/", "../.."] {
            let e = OutputFolder::new(Path::new(p)).unwrap_err().to_string();
            assert!(
                e.contains("working folder") || e.contains("root") || e.contains("home"),
                "{p}: {e}"
            );
            assert!(ReportFolder::new(Path::new(p)).is_err());
        }
        if let Some(home) = home_folder() {
            assert!(OutputFolder::new(&home).is_err());
        }
    }

    #[test]
    fn a_folder_with_foreign_files_is_not_replaced() {
        let scratch = tempfile::tempdir().unwrap();
        let target = scratch.path().join("results");
        fs::create_dir(&target).unwrap();
        fs::write(target.join("thesis.tex"), "keep me").unwrap();
        let e = OutputFolder::new(&target).unwrap_err().to_string();
        assert!(e.contains("not a contact-patch output"), "{e}");
        assert_eq!(
            fs::read_to_string(target.join("thesis.tex")).unwrap(),
            "keep me"
        );
    }

    #[test]
    fn a_previous_output_is_replaced_and_nothing_is_left_beside_it() {
        let scratch = tempfile::tempdir().unwrap();
        let target = scratch.path().join("run");
        let folder = OutputFolder::new(&target).unwrap();
        folder
            .write(|tmp| {
                fs::write(tmp.join("a.txt"), "1").unwrap();
                Ok(())
            })
            .unwrap();
        let again = OutputFolder::new(&target).unwrap();
        again
            .write(|tmp| {
                fs::write(tmp.join("b.txt"), "2").unwrap();
                Ok(())
            })
            .unwrap();
        let mut names: Vec<_> = fs::read_dir(&target)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        assert_eq!(names, [MANIFEST, "b.txt"]);
        let beside: Vec<_> = fs::read_dir(scratch.path()).unwrap().collect();
        assert_eq!(beside.len(), 1, "temporary folders left behind");

        // A file added by the user blocks the next replacement.
        fs::write(target.join("notes.txt"), "mine").unwrap();
        assert!(OutputFolder::new(&target).is_err());
    }

    #[test]
    fn a_failed_fill_leaves_nothing() {
        let scratch = tempfile::tempdir().unwrap();
        let folder = OutputFolder::new(&scratch.path().join("run")).unwrap();
        let r = folder.write(|tmp| {
            fs::write(tmp.join("half.txt"), "x").unwrap();
            Err(Error::invalid("t", "t", "fails on purpose", "none"))
        });
        assert!(r.is_err());
        assert_eq!(fs::read_dir(scratch.path()).unwrap().count(), 0);
    }
    #[test]
    fn a_named_file_is_written_exactly_there() {
        let scratch = tempfile::tempdir().unwrap();
        fs::write(scratch.path().join("other.txt"), "keep").unwrap();
        let path = scratch.path().join("junit.xml");
        let f = NamedFile::new(&path, "the --junit file").unwrap();
        f.write("one").unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "one");
        // replaced as a whole
        NamedFile::new(&path, "the --junit file")
            .unwrap()
            .write("two")
            .unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "two");
        let mut names: Vec<_> = fs::read_dir(scratch.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        assert_eq!(names, ["junit.xml", "other.txt"], "temporary files left");
        assert_eq!(
            fs::read_to_string(scratch.path().join("other.txt")).unwrap(),
            "keep"
        );
    }

    #[test]
    fn a_named_file_refuses_folders_links_and_missing_parents() {
        let scratch = tempfile::tempdir().unwrap();
        let what = "the --junit file";
        // a folder
        let e = NamedFile::new(scratch.path(), what)
            .unwrap_err()
            .to_string();
        assert!(e.contains("is a folder") && e.contains(what), "{e}");
        let mut slash = scratch.path().join("x").into_os_string();
        slash.push("/");
        assert!(NamedFile::new(Path::new(&slash), what).is_err());
        assert!(NamedFile::new(Path::new(""), what).is_err());
        assert!(NamedFile::new(Path::new(".."), what).is_err());
        assert!(NamedFile::new(&scratch.path().join("new").join("."), what).is_err());
        // a missing parent: refused, and nothing is created
        let deep = scratch.path().join("no").join("such").join("junit.xml");
        let e = NamedFile::new(&deep, what).unwrap_err().to_string();
        assert!(e.contains("does not exist"), "{e}");
        assert!(!scratch.path().join("no").exists());
        // a symbolic link (to a file the user keeps): refused, the file untouched
        let kept = scratch.path().join("kept.txt");
        fs::write(&kept, "mine").unwrap();
        let link = scratch.path().join("link.xml");
        std::os::unix::fs::symlink(&kept, &link).unwrap();
        let e = NamedFile::new(&link, what).unwrap_err().to_string();
        assert!(e.contains("symbolic link"), "{e}");
        // a path that became a folder after the check is refused at writing
        let later = scratch.path().join("later.xml");
        let f = NamedFile::new(&later, what).unwrap();
        fs::create_dir(&later).unwrap();
        assert!(f.write("x").is_err());
        assert!(later.is_dir());
        assert_eq!(fs::read_to_string(&kept).unwrap(), "mine");
        assert_eq!(fs::read_dir(scratch.path()).unwrap().count(), 3);
    }
}
