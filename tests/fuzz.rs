//! Fuzz test of the `contact-patch` binary on mutated case files, and replays of the known
//! defect reproducers in `tests/defects/`.
//!
//! `mutated_cases_keep_the_invariants` takes every case under `cases/` (except `cases/large/`
//! and the refinement study `cases/friction-bench/`, too slow), two reproducers with explicit
//! meshes and four 3D cases with contact, friction and finite strain (which `cases/` lacks,
//! [`EXTRA_BASES`]) and mutates them
//! with a fixed seed: keys deleted, values replaced by a wrong type, huge, tiny and shifted
//! numbers, NaN and infinity tokens, names replaced by path-like, empty or odd strings (renamed
//! everywhere they are referenced), keys inserted or duplicated, the text truncated or damaged,
//! a byte-order mark put in front, the object wrapped in an array; a Gmsh mesh file the case
//! reads is put beside the mutant, one time in ten cut short and one in ten with bytes
//! overwritten. Each mutant is run through
//! the release binary, mostly as `run CASE [--out DIR]`, sometimes as `check FOLDER` over a
//! folder of several mutants, and as `table CASE --out DIR` on mutants of the sweep cases
//! (`cases/patch`, `cases/tied`).
//!
//! It also mutates the result files the tool reads (about one run in five), made valid by the
//! binary itself before the fuzzing (not counted in the time budget): family `vtu`, the body
//! files `run` writes for a few cases ([`VTU_BASES`]: 2D and 3D, one and two bodies, contact,
//! tie and friction), given to `judge CASE RESULTS` (a file or a folder of `<body>.vtu`,
//! sometimes with `--junit FILE` or a hostile `--match-tol`) and to `table CASE --results DIR
//! --code NAME --out DIR` (swept cases, sometimes a hostile `--code`), with attribute values
//! (`NumberOfPoints`, `NumberOfCells`, `NumberOfComponents`, `offset`, `format`, `type`,
//! `Name`, ...) huge, negative, zero, non-numeric or removed, a DataArray's values changed,
//! removed, repeated or emptied, elements removed, repeated, renamed or nested, an array made
//! binary or appended, bytes that are not UTF-8 (or the whole file in UTF-16), the text truncated
//! or damaged; family `shard`, the partial files of two `table --shard K/N` splits and two
//! `study --shard K/N` splits (timings set to 0), given to `merge PARTS --out DIR` with shard
//! numbers and totals replaced (huge, zero, negative, fractional, strings), units removed,
//! repeated, emptied or given other indices, a part of another split in place of one, a part left
//! out, given twice or joined by a file that is no part, or any mutation of the case files above
//! applied to a part's JSON.
//!
//! Every run happens in a fresh scratch folder three levels below a temporary root
//! (`ROOT/run-N/a/b/scratch`), holding sentinel files, the case file(s) and a working folder
//! `scratch/work/` (with its own sentinel) that is the process's current folder. The output goes
//! to the default `work/out/<case name>`, to `--out out-N` or an absolute `--out`, or to the
//! hostile `--out .`, `--out ..` and `--out` an existing regular file. Every file under
//! `ROOT/run-N/a` is listed (path, size, content hash) before and after the run. A run passes
//! when:
//!
//! - it exits with 0, 1 or 2 within the per-run limit (`CONTACT_PATCH_FUZZ_RUN_SECONDS`, default
//!   60 s; a timeout, a signal, a panic or any other code fails it) and says something (stdout
//!   or stderr); an exit 2 of any command but `check` has a message on stderr; `check` names every case
//!   it was given (its errors go to its table on stdout);
//! - every file that existed before is still there with the same content, and every new file
//!   lies inside the output the tool may write (the `--out` target, `work/out/` without `--out`,
//!   the `--junit` file of `judge`, nothing for `check` and `judge` without it). Pre-existing files are protected even inside the `--out` target:
//!   with `--out .` the working folder's sentinel must survive.
//!
//! Children run with `RUST_BACKTRACE=1`, 4 GiB of address space, 1 GiB file size and no core
//! dumps, so an unchecked size aborts quickly instead of filling the machine.
//!
//! The runs are spread over two worker threads; each run's mutation is derived from the seed and
//! the run's index alone, so the same seed gives the same sequence of runs whatever the timing.
//! The fuzzing stops at a time budget (`CONTACT_PATCH_FUZZ_SECONDS`, default 60 s; a run started
//! before the end may add up to the per-run limit) or a run count (`CONTACT_PATCH_FUZZ_RUNS`); the
//! seed can be changed with `CONTACT_PATCH_FUZZ_SEED`, and `CONTACT_PATCH_FUZZ_FAMILY` (a family
//! named in the per-family count, e.g. `3d`, `finite strain`, `gmsh`) mutates the cases of that
//! family only (`vtu` or `shard`: those result files only). At the end the test prints (straight to
//! stderr, so it shows in CI even when the test passes) the number of runs, the runs per family
//! of the mutated cases (2D or 3D, contact, friction, finite strain, dynamics, Gmsh, explicit
//! mesh, sweep) and result files (`vtu`, `shard`), the count of each exit code, of each command and of each mutation kind. All failures are collected, grouped into
//! classes and reported at once; the inputs of the first few failures of each class are saved
//! under `target/fuzz-failures/` with the command, stdout and stderr, to be replayed by hand, and
//! `report.txt` there lists every failure.
//!
//! `defect_reproducers_keep_the_invariants` replays each `tests/defects/*.json` (see
//! `tests/defects/README.md`) with the command its README gives, plus `check` over a folder with
//! D01 between two good cases and a good case with `--out .`, `--out ..` and `--out FILE`, under
//! the same invariants. An absolute case name in a reproducer (D05) is rewritten at run time to
//! a folder inside the scratch folder, so a replay never touches anything outside it.

use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::fs;
use std::io::Write as _;
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Component, Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_contact-patch");
const SEED: u64 = 0x00C0_47AC_7FA7_C401;
/// Wall-clock limit of one run of the binary (default); a run still going is killed and fails.
/// It tells a hang from work: a mutant within the size limits may be a real computation, and
/// run 2441 of the default seed (`check` over four mutants, one of them
/// `cases/dynamics/block-drop-rigid.json` with 8000 divisions along y: 72 009 nodes, 50
/// implicit steps, 35 factorizations of the effective stiffness) took 20.1 s on the two-core
/// machine alone (2026-11-28, `contact-patch run`, which also writes 51 frames of 72 009 nodes),
/// over the 20 s this limit was; 60 s leaves room for a slower CI machine. Measured again the
/// next session: `contact-patch check` of that mutant alone takes 6.8 s (factorization 3.2 s,
/// solve 2.0 s; 35 factorizations, each an active-set change of the semi-smooth Newton step,
/// not a refactorization of an unchanged tangent), and the first 2450 runs of the default
/// seed pass with an 8 s limit (`CONTACT_PATCH_FUZZ_RUNS=2450 CONTACT_PATCH_FUZZ_SECONDS=600
/// CONTACT_PATCH_FUZZ_RUN_SECONDS=8`, 27 s); CI's machine took about twice this one's time
/// for the whole suite.
const RUN_LIMIT_SECONDS: f64 = 60.0;
const DEFAULT_BUDGET_SECONDS: f64 = 60.0;
const DEFAULT_MAX_RUNS: usize = 100_000;
const WORKERS: usize = 2;
const MEMORY_LIMIT: libc::rlim_t = 4 << 30;
const FILE_SIZE_LIMIT: libc::rlim_t = 1 << 30;
/// Failures of one class whose inputs are saved under `target/fuzz-failures/`.
const SAVED_PER_CLASS: usize = 10;
/// Failures of one class shown in the test's failure message (`report.txt` has them all).
const PRINTED_PER_CLASS: usize = 3;

// ---------------------------------------------------------------------------------------------
// A small deterministic generator (splitmix64).

struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Self {
        Rng(seed)
    }

    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`).
    fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }

    fn chance(&mut self, p: f64) -> bool {
        ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64) < p
    }

    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

// ---------------------------------------------------------------------------------------------
// Paths into a JSON value.

#[derive(Clone)]
enum Seg {
    Key(String),
    Index(usize),
}

type JPath = Vec<Seg>;

fn show(path: &[Seg]) -> String {
    let mut s = String::new();
    for seg in path {
        match seg {
            Seg::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(k);
            }
            Seg::Index(i) => {
                let _ = write!(s, "[{i}]");
            }
        }
    }
    if s.is_empty() {
        "(root)".into()
    } else {
        s
    }
}

/// Every node below the root, depth first.
fn all_paths(v: &Value) -> Vec<JPath> {
    fn walk(v: &Value, prefix: &mut JPath, out: &mut Vec<JPath>) {
        match v {
            Value::Object(m) => {
                for (k, child) in m {
                    prefix.push(Seg::Key(k.clone()));
                    out.push(prefix.clone());
                    walk(child, prefix, out);
                    prefix.pop();
                }
            }
            Value::Array(a) => {
                for (i, child) in a.iter().enumerate() {
                    prefix.push(Seg::Index(i));
                    out.push(prefix.clone());
                    walk(child, prefix, out);
                    prefix.pop();
                }
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk(v, &mut Vec::new(), &mut out);
    out
}

fn node<'a>(v: &'a Value, path: &[Seg]) -> &'a Value {
    path.iter().fold(v, |v, seg| match seg {
        Seg::Key(k) => &v[k.as_str()],
        Seg::Index(i) => &v[*i],
    })
}

fn node_mut<'a>(v: &'a mut Value, path: &[Seg]) -> &'a mut Value {
    path.iter().fold(v, |v, seg| match seg {
        Seg::Key(k) => &mut v[k.as_str()],
        Seg::Index(i) => &mut v[*i],
    })
}

fn remove(v: &mut Value, path: &[Seg]) {
    let (last, parent) = path.split_last().expect("not the root");
    match (node_mut(v, parent), last) {
        (Value::Object(m), Seg::Key(k)) => {
            m.remove(k);
        }
        (Value::Array(a), Seg::Index(i)) => {
            a.remove(*i);
        }
        _ => unreachable!("a path of this value"),
    }
}

fn paths_where(v: &Value, keep: impl Fn(&Value) -> bool) -> Vec<JPath> {
    all_paths(v)
        .into_iter()
        .filter(|p| keep(node(v, p)))
        .collect()
}

fn short(v: &Value) -> String {
    let s = serde_json::to_string(v).expect("serializes");
    if s.chars().count() > 60 {
        format!("{}...", s.chars().take(57).collect::<String>())
    } else {
        s
    }
}

fn pretty(v: &Value) -> String {
    serde_json::to_string_pretty(v).expect("serializes")
}

// ---------------------------------------------------------------------------------------------
// Mutations.

/// What a mutation may need to know about the scratch folder it will run in.
struct Ctx {
    /// An existing folder inside the scratch folder, as an absolute path (for absolute names).
    victim: String,
}

impl Ctx {
    /// Names that are path-like, empty, reserved or odd.
    fn names(&self) -> Vec<String> {
        let mut names: Vec<String> = [
            "..",
            "../..",
            "../escape",
            "a/../..",
            "a/b",
            "./x/",
            "",
            ".",
            "~",
            "con",
            "NUL",
            "-rf",
            "with space",
            "ünïcødé-名前",
            "nul\u{0}byte",
            "tab\tnew\nline",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        names.push("x".repeat(300));
        names.push(self.victim.clone());
        names.push(format!("{}/inner", self.victim));
        names
    }

    /// Replacement values of every kind.
    fn values(&self, rng: &mut Rng) -> Value {
        match rng.below(4) {
            0 => rng.pick(&huge_numbers()).clone(),
            1 => rng.pick(&tiny_numbers()).clone(),
            2 => rng.pick(&wrong_types()).clone(),
            _ => Value::String(rng.pick(&self.names()).clone()),
        }
    }
}

fn huge_numbers() -> Vec<Value> {
    vec![
        json!(1e308),
        json!(-1e308),
        json!(1e300),
        json!(1e15),
        json!(1_000_000_000_000u64),
        json!(4_294_967_296u64),
        json!(u64::MAX),
        json!(i64::MIN),
    ]
}

fn tiny_numbers() -> Vec<Value> {
    vec![
        json!(1e-300),
        json!(5e-324),
        json!(-1e-300),
        json!(1e-12),
        json!(0),
        json!(0.0),
        json!(-0.0),
        json!(-1),
        json!(0.5),
    ]
}

fn wrong_types() -> Vec<Value> {
    vec![
        Value::Null,
        json!(true),
        json!("text"),
        json!(""),
        json!(42),
        json!(-1.5),
        json!([]),
        json!({}),
        json!([1, 2, 3]),
        json!({"a": 1}),
    ]
}

fn type_of(v: &Value) -> u8 {
    match v {
        Value::Null => 0,
        Value::Bool(_) => 1,
        Value::Number(_) => 2,
        Value::String(_) => 3,
        Value::Array(_) => 4,
        Value::Object(_) => 5,
    }
}

/// Keys the case format knows, to insert where they may or may not belong.
const KNOWN_KEYS: &[&str] = &[
    "search_distance",
    "name",
    "divisions",
    "kappa",
    "passes",
    "tol",
    "penalty_factor",
    "catalogue",
    "physics",
    "contact_geometry",
    "update",
    "multiplier",
    "normal",
    "radius",
    "from",
    "to",
    "moves",
    "nodes",
    "cells",
    "sweep",
    "exact",
    "thickness",
];

/// Mutations of the parsed value (the text is the value written back, pretty).
const VALUE_KINDS: &[&str] = &[
    "delete",
    "wrong_type",
    "huge_number",
    "tiny_number",
    "shift_number",
    "path_name",
    "insert_key",
];

/// Every mutation kind and its weight.
const KINDS: &[(&str, usize)] = &[
    ("delete", 12),
    ("wrong_type", 12),
    ("huge_number", 12),
    ("tiny_number", 10),
    ("shift_number", 8),
    ("path_name", 14),
    ("insert_key", 6),
    ("nonfinite", 8),
    ("duplicate_key", 6),
    ("truncate", 6),
    ("byte_damage", 6),
    ("bom", 2),
    ("wrap_array", 2),
    ("stacked", 8),
];

fn pick_kind(rng: &mut Rng) -> &'static str {
    pick_weighted(rng, KINDS)
}

/// An entry of `table` drawn with its weight.
fn pick_weighted<T: Copy>(rng: &mut Rng, table: &[(T, usize)]) -> T {
    let total: usize = table.iter().map(|k| k.1).sum();
    let mut r = rng.below(total);
    for &(kind, w) in table {
        if r < w {
            return kind;
        }
        r -= w;
    }
    unreachable!()
}

/// Replace the string `old` by `new` wherever the case refers to it (string values and the
/// keys of `materials`); returns how many places changed.
fn rename(v: &mut Value, old: &str, new: &str) -> usize {
    fn walk(v: &mut Value, old: &str, new: &str) -> usize {
        match v {
            Value::String(s) if s == old => {
                *s = new.to_string();
                1
            }
            Value::Array(a) => a.iter_mut().map(|c| walk(c, old, new)).sum(),
            Value::Object(m) => m.values_mut().map(|c| walk(c, old, new)).sum(),
            _ => 0,
        }
    }
    let mut n = walk(v, old, new);
    if let Some(m) = v.get_mut("materials").and_then(Value::as_object_mut) {
        if let Some(x) = m.remove(old) {
            m.insert(new.to_string(), x);
            n += 1;
        }
    }
    n
}

/// Apply one mutation of the parsed value; `None` when it has nothing to act on.
fn value_mutation(kind: &str, rng: &mut Rng, v: &mut Value, ctx: &Ctx) -> Option<String> {
    let paths = all_paths(v);
    if paths.is_empty() {
        return None;
    }
    match kind {
        "delete" => {
            let p = rng.pick(&paths).clone();
            remove(v, &p);
            Some(format!("deleted {}", show(&p)))
        }
        "wrong_type" => {
            let p = rng.pick(&paths).clone();
            let old = type_of(node(v, &p));
            let pool: Vec<Value> = wrong_types()
                .into_iter()
                .filter(|x| type_of(x) != old)
                .collect();
            let new = rng.pick(&pool).clone();
            let d = format!("{} = {} (wrong type)", show(&p), short(&new));
            *node_mut(v, &p) = new;
            Some(d)
        }
        "huge_number" | "tiny_number" => {
            let numbers = paths_where(v, Value::is_number);
            let p = if !numbers.is_empty() && rng.chance(0.85) {
                rng.pick(&numbers).clone()
            } else {
                rng.pick(&paths).clone()
            };
            let pool = if kind == "huge_number" {
                huge_numbers()
            } else {
                tiny_numbers()
            };
            let new = rng.pick(&pool).clone();
            let d = format!("{} = {}", show(&p), short(&new));
            *node_mut(v, &p) = new;
            Some(d)
        }
        "shift_number" => {
            let numbers = paths_where(v, Value::is_number);
            if numbers.is_empty() {
                return None;
            }
            let p = rng.pick(&numbers).clone();
            let old = node(v, &p).clone();
            let new = match old.as_i64() {
                Some(i) => json!(match rng.below(6) {
                    0 => i.saturating_add(1),
                    1 => i.saturating_sub(1),
                    2 => i.saturating_mul(2),
                    3 => i.saturating_mul(1000),
                    4 => i.saturating_neg(),
                    _ => i.saturating_add(1 + rng.below(100) as i64),
                }),
                None => {
                    let x = old.as_f64().unwrap_or(0.0);
                    json!(match rng.below(5) {
                        0 => x * 2.0,
                        1 => x * 1000.0,
                        2 => -x,
                        3 => x + 1e-9 * x.abs().max(1.0),
                        _ => 1.0 / x,
                    })
                }
            };
            let d = format!("{} = {} (was {})", show(&p), short(&new), short(&old));
            *node_mut(v, &p) = new;
            Some(d)
        }
        "path_name" => {
            let new = rng.pick(&ctx.names()).clone();
            let strings = paths_where(v, Value::is_string);
            let named: Vec<JPath> = strings
                .iter()
                .filter(|p| matches!(p.last(), Some(Seg::Key(k)) if k == "name"))
                .cloned()
                .collect();
            let catalogue = vec![Seg::Key("sweep".into()), Seg::Key("catalogue".into())];
            let target = if rng.chance(0.35) || strings.is_empty() {
                vec![Seg::Key("name".into())]
            } else if !named.is_empty() && rng.chance(0.5) {
                rng.pick(&named).clone()
            } else if v.get("sweep").is_some_and(Value::is_object) && rng.chance(0.3) {
                catalogue
            } else {
                rng.pick(&strings).clone()
            };
            let old = node(v, &target).as_str().map(str::to_string);
            match old {
                Some(old) => {
                    let n = rename(v, &old, &new);
                    Some(format!(
                        "{} {old:?} renamed {new:?} ({n} places)",
                        show(&target)
                    ))
                }
                None => {
                    let d = format!("{} = {new:?}", show(&target));
                    *node_mut(v, &target) = Value::String(new);
                    Some(d)
                }
            }
        }
        "insert_key" => {
            let pairs: Vec<usize> = v["contact"].as_array().map_or(Vec::new(), |a| {
                (0..a.len()).filter(|&i| a[i].is_object()).collect()
            });
            let (path, key, new) = if !pairs.is_empty() && rng.chance(0.3) {
                let distances = [1e4, 1e308, 1e-300, 0.0, -1.0, 2.0, 100.0, 1e-3];
                (
                    vec![Seg::Key("contact".into()), Seg::Index(*rng.pick(&pairs))],
                    "search_distance".to_string(),
                    json!(*rng.pick(&distances)),
                )
            } else {
                let mut objects = paths_where(v, Value::is_object);
                objects.push(Vec::new());
                let p = rng.pick(&objects).clone();
                let key = rng.pick(KNOWN_KEYS).to_string();
                (p, key, ctx.values(rng))
            };
            let d = format!("inserted {}.{key} = {}", show(&path), short(&new));
            node_mut(v, &path)
                .as_object_mut()
                .expect("an object")
                .insert(key, new);
            Some(d)
        }
        _ => unreachable!("not a value mutation: {kind}"),
    }
}

struct Mutant {
    kind: &'static str,
    /// The kind, and for a renamed name which field it was (`path_name on bodies[].name`).
    cause: String,
    description: String,
    bytes: Vec<u8>,
}

/// The first word of a description with the array indices dropped: `bodies[1].name` ->
/// `bodies[].name`.
fn field_pattern(description: &str) -> String {
    let word = description.split(' ').next().unwrap_or("");
    let mut out = String::new();
    let mut in_index = false;
    for c in word.chars() {
        match c {
            '[' => {
                in_index = true;
                out.push_str("[]");
            }
            ']' => in_index = false,
            _ if !in_index => out.push(c),
            _ => {}
        }
    }
    out
}

/// `bytes` cut at a random byte, with what was done.
fn truncated(rng: &mut Rng, bytes: &[u8]) -> (String, Vec<u8>) {
    let n = rng.below(bytes.len().max(1));
    (
        format!("truncated to {n} of {} bytes", bytes.len()),
        bytes[..n.min(bytes.len())].to_vec(),
    )
}

/// `bytes` with one to eight bytes overwritten, inserted or removed (characters of JSON
/// syntax, NUL, invalid UTF-8, or any byte), with what was done.
fn byte_damaged(rng: &mut Rng, bytes: &[u8]) -> (String, Vec<u8>) {
    const BYTES: &[u8] = b"\"{}[],:\\0-e.\x00\xff\xc3/ ";
    let mut b = bytes.to_vec();
    let mut edits = Vec::new();
    for _ in 0..1 + rng.below(8) {
        let at = rng.below(b.len().max(1));
        let byte = if rng.chance(0.5) {
            *rng.pick(BYTES)
        } else {
            rng.next_u64() as u8
        };
        match rng.below(3) {
            0 if !b.is_empty() => {
                edits.push(format!("@{at}={byte:#04x}"));
                b[at] = byte;
            }
            1 => {
                edits.push(format!("@{at}+{byte:#04x}"));
                b.insert(at.min(b.len()), byte);
            }
            _ if !b.is_empty() => {
                edits.push(format!("@{at}-"));
                b.remove(at);
            }
            _ => {}
        }
    }
    (format!("byte damage {}", edits.join(" ")), b)
}

/// One mutant of `base`.
fn mutate(rng: &mut Rng, base: &Base, ctx: &Ctx) -> Mutant {
    let kind = pick_kind(rng);
    let text = base.text.as_bytes();
    let mut v = base.value.clone();
    let done = |description: String, bytes: Vec<u8>| Mutant {
        kind,
        cause: match kind {
            "path_name" => format!("path_name on {}", field_pattern(&description)),
            _ => kind.to_string(),
        },
        description,
        bytes,
    };
    match kind {
        "truncate" => {
            let (d, b) = truncated(rng, text);
            done(d, b)
        }
        "byte_damage" => {
            let (d, b) = byte_damaged(rng, text);
            done(d, b)
        }
        "bom" => {
            let mut b = b"\xef\xbb\xbf".to_vec();
            b.extend_from_slice(text);
            done("UTF-8 byte-order mark in front".into(), b)
        }
        "wrap_array" => {
            let twice = rng.chance(0.3);
            let inner = if twice {
                format!("{},{}", base.text, base.text)
            } else {
                base.text.clone()
            };
            done(
                format!("wrapped in an array ({} copies)", 1 + twice as usize),
                format!("[{inner}]").into_bytes(),
            )
        }
        "nonfinite" => {
            const TOKENS: &[&str] = &[
                "NaN",
                "Infinity",
                "-Infinity",
                "nan",
                "inf",
                "1e999",
                "-1e999",
                "1e400",
            ];
            let numbers = paths_where(&v, Value::is_number);
            if numbers.is_empty() {
                return done("no numbers: unchanged".into(), text.to_vec());
            }
            let mut subs = Vec::new();
            for j in 0..1 + rng.below(2) {
                let p = rng.pick(&numbers).clone();
                let token = *rng.pick(TOKENS);
                *node_mut(&mut v, &p) = Value::String(format!("@@NONFINITE{j}@@"));
                subs.push((j, token, show(&p)));
            }
            let mut out = pretty(&v);
            for (j, token, _) in &subs {
                out = out.replace(&format!("\"@@NONFINITE{j}@@\""), token);
            }
            let d: Vec<String> = subs.iter().map(|(_, t, p)| format!("{p} = {t}")).collect();
            done(d.join(", "), out.into_bytes())
        }
        "duplicate_key" => {
            let members: Vec<JPath> = all_paths(&v)
                .into_iter()
                .filter(|p| matches!(p.last(), Some(Seg::Key(_))))
                .collect();
            let p = rng.pick(&members).clone();
            let Some((Seg::Key(key), parent)) = p.split_last() else {
                unreachable!()
            };
            let same = rng.chance(0.3);
            let dup = if same {
                node(&v, &p).clone()
            } else {
                ctx.values(rng)
            };
            let marker = *rng.pick(&["@@DUP@@", "~~DUP~~"]);
            let d = format!("{} duplicated with {}", show(&p), short(&dup));
            node_mut(&mut v, parent)
                .as_object_mut()
                .expect("an object")
                .insert(marker.into(), dup);
            let key_json = serde_json::to_string(key).expect("serializes");
            let out = pretty(&v).replacen(&format!("\"{marker}\""), &key_json, 1);
            done(d, out.into_bytes())
        }
        "stacked" => {
            let mut d = Vec::new();
            for _ in 0..2 + rng.below(2) {
                let k = *rng.pick(VALUE_KINDS);
                if let Some(x) = value_mutation(k, rng, &mut v, ctx) {
                    d.push(format!("{k}: {x}"));
                }
            }
            done(d.join("; "), pretty(&v).into_bytes())
        }
        k => match value_mutation(k, rng, &mut v, ctx) {
            Some(d) => done(d, pretty(&v).into_bytes()),
            None => done("nothing to mutate: unchanged".into(), text.to_vec()),
        },
    }
}

/// Whether running a case with these bytes can only touch the scratch folder: every string
/// that is an absolute path is one of `allowed_absolute`, and none climbs three or more levels.
/// (Text that does not parse as JSON is rejected by the tool before it writes anything.)
fn stays_in_scratch(bytes: &[u8], allowed_absolute: &[String]) -> bool {
    fn ok(s: &str, allowed: &[String]) -> bool {
        let ups = Path::new(s)
            .components()
            .filter(|c| matches!(c, Component::ParentDir))
            .count();
        (!s.starts_with('/') || allowed.iter().any(|a| a == s)) && ups < 3
    }
    fn walk(v: &Value, allowed: &[String]) -> bool {
        match v {
            Value::String(s) => ok(s, allowed),
            Value::Array(a) => a.iter().all(|c| walk(c, allowed)),
            Value::Object(m) => m.iter().all(|(k, c)| ok(k, allowed) && walk(c, allowed)),
            _ => true,
        }
    }
    match serde_json::from_slice::<Value>(bytes) {
        Ok(v) => walk(&v, allowed_absolute),
        Err(_) => true,
    }
}

// ---------------------------------------------------------------------------------------------
// The scratch folder, the command, the run.

/// Cases fuzzed besides `cases/`, for what `cases/` lacks: explicit meshes (node and cell
/// lists: a stray node, D09, and a block on a cylinder, D11a), and 3D contact, friction and
/// finite strain (`cases/3d/` holds the small-strain patch tests only): a block dragged on a
/// rigid plane with Coulomb friction, a punch on a foundation (mortar, Lagrange), a sphere
/// pressed into a neo-Hookean block and two neo-Hookean blocks pressed together
/// (`tests/data/fuzz/`).
const EXTRA_BASES: &[&str] = &[
    "tests/defects/D09-singular-message-names-wrong-node.json",
    "tests/defects/D11a-arbitrary-rigid-rotation-numbering-1.json",
    "tests/data/fuzz/3d-friction-block-dragged.json",
    "tests/data/fuzz/3d-punch-mortar.json",
    "tests/data/fuzz/3d-finite-sphere-on-block.json",
    "tests/data/fuzz/3d-finite-two-blocks.json",
];

/// One case of the catalogue.
struct Base {
    /// Path in the repository.
    rel: String,
    text: String,
    value: Value,
    /// The families the case belongs to ([`families`]), for the count of runs per family.
    families: Vec<&'static str>,
    /// The files the case reads besides itself (Gmsh meshes): the name it gives and the bytes,
    /// put beside the mutant.
    attachments: Vec<(String, Vec<u8>)>,
}

/// The families of the case `v`: its dimension (`2d` or `3d`), and each of `contact`,
/// `friction`, `finite strain`, `dynamics`, `gmsh`, `explicit mesh` and `sweep` it uses.
fn families(v: &Value) -> Vec<&'static str> {
    let bodies = v["bodies"].as_array().cloned().unwrap_or_default();
    let mesh = |key: &str| bodies.iter().any(|b| b["mesh"].get(key).is_some());
    let contact = v["contact"].as_array().cloned().unwrap_or_default();
    let mut out = vec![if mesh("block3d") { "3d" } else { "2d" }];
    let flags = [
        ("contact", !contact.is_empty()),
        (
            "friction",
            contact
                .iter()
                .any(|c| c["interaction"].get("coulomb").is_some()),
        ),
        ("finite strain", v["physics"]["kinematics"] == "finite"),
        ("dynamics", v["physics"].get("dynamics").is_some()),
        ("gmsh", mesh("gmsh")),
        ("explicit mesh", mesh("explicit")),
        ("sweep", v.get("sweep").is_some()),
    ];
    out.extend(flags.iter().filter(|(_, on)| *on).map(|(name, _)| *name));
    out
}

/// The Gmsh files the case `v` at `path` names, read from beside it.
fn attachments(v: &Value, path: &Path) -> Vec<(String, Vec<u8>)> {
    let bodies = v["bodies"].as_array().cloned().unwrap_or_default();
    bodies
        .iter()
        .filter_map(|b| b["mesh"]["gmsh"]["file"].as_str())
        .map(|file| {
            let bytes = fs::read(path.parent().unwrap().join(file)).unwrap();
            (file.to_string(), bytes)
        })
        .collect()
}

/// An attachment as a mutant sees it: mostly unchanged, sometimes cut short at a random byte
/// or with a stretch of bytes overwritten (the mesh file's own damage), with what was done.
fn damaged(rng: &mut Rng, bytes: &[u8]) -> (Vec<u8>, Option<String>) {
    let mut out = bytes.to_vec();
    match rng.below(10) {
        0 if !out.is_empty() => {
            let at = rng.below(out.len());
            out.truncate(at);
            (out, Some(format!("cut at byte {at} of {}", bytes.len())))
        }
        1 if !out.is_empty() => {
            let at = rng.below(out.len());
            let n = 1 + rng.below(8);
            for b in out.iter_mut().skip(at).take(n) {
                *b = rng.below(256) as u8;
            }
            (out, Some(format!("{n} bytes overwritten at byte {at}")))
        }
        _ => (out, None),
    }
}

fn bases() -> Vec<Base> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let mut entries: Vec<PathBuf> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                if p.file_name()
                    .is_some_and(|n| n != "large" && n != "friction-bench")
                {
                    walk(&p, out);
                }
            } else if p.extension().is_some_and(|x| x == "json") {
                out.push(p);
            }
        }
    }
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    walk(&manifest.join("cases"), &mut files);
    files.extend(EXTRA_BASES.iter().map(|p| manifest.join(p)));
    files
        .into_iter()
        .map(|p| {
            let text = fs::read_to_string(&p).unwrap();
            let value: Value = serde_json::from_str(&text).unwrap();
            Base {
                rel: p.strip_prefix(manifest).unwrap().display().to_string(),
                families: families(&value),
                attachments: attachments(&value, &p),
                value,
                text,
            }
        })
        .collect()
}

/// Where `run` writes.
#[derive(Clone)]
enum Out {
    /// No `--out`: `out/<case name>` in the working folder.
    Default,
    /// `--out NAME`, a new folder in the working folder.
    Sub(String),
    /// `--out WORK/NAME` as an absolute path.
    Absolute(String),
    /// `--out .`
    Dot,
    /// `--out ..`
    DotDot,
    /// `--out out-file.txt`, an existing regular file.
    File,
}

impl Out {
    fn label(&self) -> &'static str {
        match self {
            Out::Default => "run (no --out)",
            Out::Sub(_) => "run --out DIR",
            Out::Absolute(_) => "run --out /ABS/DIR",
            Out::Dot => "run --out .",
            Out::DotDot => "run --out ..",
            Out::File => "run --out FILE",
        }
    }
}

/// What to run; case paths are relative to the scratch folder.
enum Cmd {
    Run {
        case: String,
        out: Out,
    },
    Check {
        folder: String,
        cases: Vec<String>,
    },
    Table {
        case: String,
        out: String,
    },
    /// `judge CASE RESULTS [--junit FILE] [--match-tol X]`
    Judge {
        case: String,
        results: String,
        junit: Option<String>,
        match_tol: Option<String>,
    },
    /// `table CASE --results DIR --code NAME --out OUT`
    TableResults {
        case: String,
        results: String,
        code: String,
        out: String,
    },
    /// `merge PARTS... --out OUT`
    Merge {
        parts: Vec<String>,
        out: String,
    },
}

impl Cmd {
    fn label(&self) -> &'static str {
        match self {
            Cmd::Run { out, .. } => out.label(),
            Cmd::Check { .. } => "check FOLDER",
            Cmd::Table { .. } => "table CASE --out DIR",
            Cmd::Judge { junit: None, .. } => "judge CASE RESULTS",
            Cmd::Judge { junit: Some(_), .. } => "judge CASE RESULTS --junit FILE",
            Cmd::TableResults { .. } => "table CASE --results DIR --code NAME",
            Cmd::Merge { .. } => "merge PARTS --out DIR",
        }
    }
}

/// Files to put in the scratch folder: `(path relative to the scratch folder, bytes)`.
type Inputs = Vec<(String, Vec<u8>)>;

/// A run to make: the files to put in the scratch folder and the command.
struct Trial {
    /// Mutation kind(s), for the statistics and the report.
    kinds: Vec<&'static str>,
    /// The families of the case(s) mutated (each once), for the statistics.
    families: Vec<&'static str>,
    /// What the failure classes name as the mutation.
    cause: String,
    description: String,
    inputs: Inputs,
    cmd: Cmd,
}

/// The folders of one run: `run_dir/a/b/scratch/work`.
struct Scratch {
    run_dir: PathBuf,
    scratch: PathBuf,
    work: PathBuf,
    victim: PathBuf,
}

const SCRATCH_REL: &str = "a/b/scratch";

impl Scratch {
    fn new(run_dir: PathBuf) -> Self {
        let scratch = run_dir.join(SCRATCH_REL);
        let work = scratch.join("work");
        let victim = scratch.join("victim");
        for d in [&work, &scratch.join("sub"), &victim, &run_dir.join("io")] {
            fs::create_dir_all(d).unwrap();
        }
        let files = [
            (run_dir.join("a/b/keep-outer.txt"), "outer sentinel\n"),
            (scratch.join("keep.txt"), "scratch sentinel\n"),
            (scratch.join("sub/keep2.txt"), "nested sentinel\n"),
            (victim.join("keep3.txt"), "victim sentinel\n"),
            (work.join("keep-work.txt"), "working-folder sentinel\n"),
        ];
        for (p, text) in files {
            fs::write(p, text).unwrap();
        }
        Scratch {
            run_dir,
            scratch,
            work,
            victim,
        }
    }

    fn ctx(&self) -> Ctx {
        Ctx {
            victim: self.victim.display().to_string(),
        }
    }

    /// Absolute names a case may hold here.
    fn allowed_absolute(&self) -> Vec<String> {
        let v = self.victim.display().to_string();
        vec![v.clone(), format!("{v}/inner")]
    }

    /// The arguments, and the folders (relative to `run_dir`) the tool may create files in.
    fn command(&self, cmd: &Cmd) -> (Vec<String>, Vec<PathBuf>) {
        let work = Path::new(SCRATCH_REL).join("work");
        let up = |p: &str| format!("../{p}");
        match cmd {
            Cmd::Run { case, out } => {
                let mut args = vec!["run".to_string(), up(case)];
                let (arg, allowed) = match out {
                    Out::Default => (None, work.join("out")),
                    Out::Sub(d) => (Some(d.clone()), work.join(d)),
                    Out::Absolute(d) => {
                        (Some(self.work.join(d).display().to_string()), work.join(d))
                    }
                    Out::Dot => (Some(".".into()), work.clone()),
                    Out::DotDot => (Some("..".into()), PathBuf::from(SCRATCH_REL)),
                    Out::File => (Some("out-file.txt".into()), work.join("out-file.txt")),
                };
                if let Some(a) = arg {
                    args.extend(["--out".to_string(), a]);
                }
                (args, vec![allowed])
            }
            Cmd::Check { folder, .. } => (vec!["check".into(), up(folder)], Vec::new()),
            Cmd::Table { case, out } => (
                vec!["table".into(), up(case), "--out".into(), out.clone()],
                vec![work.join(out)],
            ),
            Cmd::Judge {
                case,
                results,
                junit,
                match_tol,
            } => {
                let mut args = vec!["judge".to_string(), up(case), up(results)];
                let mut allowed = Vec::new();
                if let Some(j) = junit {
                    args.extend(["--junit".to_string(), j.clone()]);
                    allowed.push(work.join(j));
                }
                if let Some(t) = match_tol {
                    args.extend(["--match-tol".to_string(), t.clone()]);
                }
                (args, allowed)
            }
            Cmd::TableResults {
                case,
                results,
                code,
                out,
            } => (
                vec![
                    "table".into(),
                    up(case),
                    "--results".into(),
                    up(results),
                    "--code".into(),
                    code.clone(),
                    "--out".into(),
                    out.clone(),
                ],
                vec![work.join(out)],
            ),
            Cmd::Merge { parts, out } => {
                let mut args = vec!["merge".to_string()];
                args.extend(parts.iter().map(|p| up(p)));
                args.extend(["--out".to_string(), out.clone()]);
                (args, vec![work.join(out)])
            }
        }
    }
}

/// `relative path -> (size, content hash)` of every file below `run_dir/a`.
type Listing = BTreeMap<PathBuf, (u64, u64)>;

fn listing(run_dir: &Path) -> Listing {
    fn fnv(bytes: &[u8]) -> u64 {
        bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
            (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
        })
    }
    fn walk(dir: &Path, root: &Path, out: &mut Listing) {
        let Ok(entries) = fs::read_dir(dir) else {
            return;
        };
        for e in entries.flatten() {
            let p = e.path();
            let Ok(meta) = fs::symlink_metadata(&p) else {
                continue;
            };
            let rel = p.strip_prefix(root).unwrap().to_path_buf();
            if meta.is_dir() {
                walk(&p, root, out);
            } else if meta.file_type().is_symlink() {
                let target = fs::read_link(&p).unwrap_or_default();
                out.insert(rel, (0, fnv(target.as_os_str().as_encoded_bytes())));
            } else {
                let bytes = fs::read(&p).unwrap_or_default();
                out.insert(rel, (meta.len(), fnv(&bytes)));
            }
        }
    }
    let mut out = Listing::new();
    walk(&run_dir.join("a"), run_dir, &mut out);
    out
}

/// Files deleted or modified anywhere, or created outside `allowed`.
fn changes(before: &Listing, after: &Listing, allowed: &[PathBuf]) -> Vec<(&'static str, String)> {
    let mut out = Vec::new();
    for (p, v) in before {
        match after.get(p) {
            None => out.push(("deleted", p.display().to_string())),
            Some(w) if w != v => out.push(("modified", p.display().to_string())),
            _ => {}
        }
    }
    for p in after.keys() {
        if !before.contains_key(p) && !allowed.iter().any(|a| p.starts_with(a)) {
            out.push(("created", p.display().to_string()));
        }
    }
    out
}

#[derive(Clone, Copy, PartialEq)]
enum Exit {
    Code(i32),
    Signal(i32),
    Timeout,
}

impl Exit {
    fn key(self) -> String {
        match self {
            Exit::Code(c) => format!("exit {c}"),
            Exit::Signal(s) => format!("signal {s} ({})", signal_name(s)),
            Exit::Timeout => format!("timeout (> {:.0} s)", run_limit().as_secs_f64()),
        }
    }
}

fn signal_name(s: i32) -> &'static str {
    match s {
        libc::SIGABRT => "SIGABRT",
        libc::SIGSEGV => "SIGSEGV",
        libc::SIGBUS => "SIGBUS",
        libc::SIGILL => "SIGILL",
        libc::SIGFPE => "SIGFPE",
        libc::SIGKILL => "SIGKILL",
        libc::SIGXFSZ => "SIGXFSZ",
        _ => "?",
    }
}

struct Execution {
    exit: Exit,
    stdout: String,
    stderr: String,
}

/// Run the binary in `cwd` with the resource limits, killing it after the per-run limit; its output
/// goes to files in `io` (outside the listed tree).
fn execute(args: &[String], cwd: &Path, io: &Path) -> Execution {
    let (out_path, err_path) = (io.join("stdout.txt"), io.join("stderr.txt"));
    let mut cmd = Command::new(BIN);
    cmd.args(args)
        .current_dir(cwd)
        .env("RUST_BACKTRACE", "1")
        .stdin(Stdio::null())
        .stdout(fs::File::create(&out_path).unwrap())
        .stderr(fs::File::create(&err_path).unwrap());
    // SAFETY: the closure runs in the forked child before exec and only calls setrlimit, which
    // is async-signal-safe and touches no shared state.
    unsafe {
        cmd.pre_exec(|| {
            let limits = [
                (libc::RLIMIT_AS, MEMORY_LIMIT),
                (libc::RLIMIT_FSIZE, FILE_SIZE_LIMIT),
                (libc::RLIMIT_CORE, 0),
            ];
            for (resource, value) in limits {
                let limit = libc::rlimit {
                    rlim_cur: value,
                    rlim_max: value,
                };
                if libc::setrlimit(resource, &limit) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
            }
            Ok(())
        });
    }
    let mut child = cmd.spawn().expect("the binary starts");
    let start = Instant::now();
    let mut pause = Duration::from_millis(1);
    let exit = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break match (status.code(), status.signal()) {
                (Some(c), _) => Exit::Code(c),
                (None, Some(s)) => Exit::Signal(s),
                (None, None) => unreachable!("a status has a code or a signal"),
            };
        }
        if start.elapsed() > run_limit() {
            let _ = child.kill();
            let _ = child.wait();
            break Exit::Timeout;
        }
        std::thread::sleep(pause);
        pause = (pause * 2).min(Duration::from_millis(20));
    };
    let read = |p: &Path| String::from_utf8_lossy(&fs::read(p).unwrap_or_default()).into_owned();
    Execution {
        exit,
        stdout: read(&out_path),
        stderr: read(&err_path),
    }
}

/// The result of one trial.
struct Verdict {
    args: Vec<String>,
    exec: Execution,
    /// Why the run fails (empty: it passes).
    reasons: Vec<String>,
    /// The failure class (empty when it passes).
    class: String,
}

/// Replace each run of digits by `N`, so that messages differing only in numbers group.
fn without_numbers(s: &str) -> String {
    let mut out = String::new();
    let mut in_digits = false;
    for c in s.chars() {
        if c.is_ascii_digit() {
            if !in_digits {
                out.push('N');
            }
            in_digits = true;
        } else {
            out.push(c);
            in_digits = false;
        }
    }
    out
}

/// `location: message` of a Rust panic in `stderr`.
fn panic_site(stderr: &str) -> Option<String> {
    let mut lines = stderr.lines();
    while let Some(line) = lines.next() {
        if let Some(i) = line.find("panicked at ") {
            let at = line[i + "panicked at ".len()..].trim_end_matches(':');
            // `/rustc/HASH/library/...` -> `library/...`
            let at = match at.strip_prefix("/rustc/") {
                Some(rest) => rest.split_once('/').map_or(rest, |(_, p)| p),
                None => at,
            };
            let message = lines.next().unwrap_or("").trim();
            return Some(format!("{at}: {}", without_numbers(message)));
        }
    }
    None
}

/// The innermost frame of this crate in a backtrace (`contact_patch::...`), if any.
fn own_frame(stderr: &str) -> Option<&str> {
    stderr
        .lines()
        .filter_map(|l| l.trim().split_once(": ").map(|(_, f)| f))
        .find(|f| f.contains("contact_patch::"))
}

/// Write the trial's inputs into a fresh scratch folder, run it, judge it.
fn run_trial(scratch: &Scratch, trial: &Trial) -> Verdict {
    for (rel, bytes) in &trial.inputs {
        let p = scratch.scratch.join(rel);
        fs::create_dir_all(p.parent().unwrap()).unwrap();
        fs::write(p, bytes).unwrap();
    }
    if let Cmd::Run { out: Out::File, .. } = trial.cmd {
        fs::write(
            scratch.work.join("out-file.txt"),
            "an existing regular file\n",
        )
        .unwrap();
    }
    let (args, allowed) = scratch.command(&trial.cmd);
    let before = listing(&scratch.run_dir);
    let exec = execute(&args, &scratch.work, &scratch.run_dir.join("io"));
    let after = listing(&scratch.run_dir);
    let changed = changes(&before, &after, &allowed);

    let mut reasons = Vec::new();
    let mut class = String::new();
    let mut classify = |reason: String, c: String| {
        if class.is_empty() {
            class = c;
        }
        reasons.push(reason);
    };
    let first_line = exec.stderr.trim_start().lines().next().unwrap_or("");
    let frame = own_frame(&exec.stderr)
        .map(|f| format!(" (in {f})"))
        .unwrap_or_default();
    let panic = panic_site(&exec.stderr);
    match exec.exit {
        Exit::Timeout => classify(
            format!(
                "still running after {:.0} s (killed)",
                run_limit().as_secs_f64()
            ),
            "timeout".into(),
        ),
        Exit::Signal(s) => classify(
            format!("killed by signal {s} ({})", signal_name(s)),
            format!(
                "signal {}: {}{frame}",
                signal_name(s),
                without_numbers(first_line)
            ),
        ),
        Exit::Code(c) if c == 101 || panic.is_some() => classify(
            format!("panic (exit {c})"),
            format!("panic at {}{frame}", panic.unwrap_or_else(|| "?".into())),
        ),
        Exit::Code(c) if !(0..=2).contains(&c) => {
            classify(format!("exit code {c}"), format!("exit code {c}"))
        }
        Exit::Code(c) => {
            let check = matches!(trial.cmd, Cmd::Check { .. });
            if c == 2 && !check && exec.stderr.trim().is_empty() {
                classify(
                    "exit 2 with nothing on stderr".into(),
                    format!("exit 2 without a message ({})", trial.cmd.label()),
                );
            }
            if exec.stdout.trim().is_empty() && exec.stderr.trim().is_empty() {
                classify(format!("exit {c} without any message"), "no message".into());
            }
            if let Cmd::Check { cases, .. } = &trial.cmd {
                let all = format!("{}{}", exec.stdout, exec.stderr);
                let missing: Vec<&String> = cases.iter().filter(|n| !all.contains(*n)).collect();
                if !missing.is_empty() {
                    classify(
                        format!("check does not report {missing:?}"),
                        "check does not report every case".into(),
                    );
                }
            }
        }
    }
    if !changed.is_empty() {
        let mut what: Vec<&str> = changed.iter().map(|c| c.0).collect();
        what.sort_unstable();
        what.dedup();
        let mut list: Vec<String> = changed
            .iter()
            .take(6)
            .map(|(k, p)| format!("{k} {p}"))
            .collect();
        if changed.len() > 6 {
            list.push(format!("... ({} in all)", changed.len()));
        }
        // With `--out .`, `--out ..` or `--out FILE` any case that solves does it; otherwise
        // the mutation is what matters.
        let cause = match trial.cmd {
            Cmd::Run {
                out: Out::Dot | Out::DotDot | Out::File,
                ..
            } => String::new(),
            _ => format!(" ({})", trial.cause),
        };
        classify(
            format!("files outside the output changed: {}", list.join(", ")),
            format!(
                "files outside the output {} by `{}`{cause}",
                what.join("/"),
                trial.cmd.label(),
            ),
        );
    }
    Verdict {
        args,
        exec,
        reasons,
        class,
    }
}

// ---------------------------------------------------------------------------------------------
// Failures and statistics.

struct Failure {
    class: String,
    title: String,
    description: String,
    command: String,
    exit: String,
    reasons: Vec<String>,
    stderr_head: String,
    saved: Option<PathBuf>,
}

fn failures_dir(name: &str) -> PathBuf {
    let tmp = Path::new(env!("CARGO_TARGET_TMPDIR"));
    tmp.parent().unwrap_or(tmp).join("fuzz-failures").join(name)
}

fn slug(s: &str) -> String {
    let s: String = s
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    s.split('-')
        .filter(|p| !p.is_empty())
        .collect::<Vec<_>>()
        .join("-")
        .chars()
        .take(60)
        .collect()
}

/// The failure of `trial` (if it failed), its inputs saved under `dir` while its class has
/// fewer than [`SAVED_PER_CLASS`] saved.
fn record(
    title: String,
    trial: &Trial,
    verdict: Verdict,
    dir: &Path,
    saved_per_class: &Mutex<BTreeMap<String, usize>>,
) -> Option<Failure> {
    if verdict.reasons.is_empty() {
        return None;
    }
    let command = format!(
        "contact-patch {}   (in {SCRATCH_REL}/work)",
        verdict
            .args
            .iter()
            .map(|a| format!("{a:?}"))
            .collect::<Vec<_>>()
            .join(" ")
    );
    let exit = verdict.exec.exit.key();
    let save = {
        let mut m = saved_per_class.lock().unwrap();
        let n = m.entry(verdict.class.clone()).or_default();
        *n += 1;
        *n <= SAVED_PER_CLASS
    };
    let saved = save.then(|| {
        let class: String = slug(&verdict.class).chars().take(40).collect();
        let d = dir.join(format!("{}-{class}", slug(&title)));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        for (rel, bytes) in &trial.inputs {
            let p = d.join(rel);
            fs::create_dir_all(p.parent().unwrap()).unwrap();
            fs::write(p, bytes).unwrap();
        }
        let about = format!(
            "{title}\nmutation: {}\nlayout: ROOT/{SCRATCH_REL}/ holds keep.txt, sub/keep2.txt, victim/keep3.txt, \
             the inputs of this folder and work/keep-work.txt; ROOT/a/b/keep-outer.txt is above it.\n\
             command: {command}\nexit: {exit}\nclass: {}\nwhy:\n  {}\n\
             Absolute names in the inputs point into the scratch folder of the original run;\n\
             replay only inside a throwaway folder at least three levels deep.\n",
            trial.description,
            verdict.class,
            verdict.reasons.join("\n  ")
        );
        fs::write(d.join("about.txt"), about).unwrap();
        fs::write(d.join("stdout.txt"), &verdict.exec.stdout).unwrap();
        fs::write(d.join("stderr.txt"), &verdict.exec.stderr).unwrap();
        d
    });
    Some(Failure {
        class: verdict.class,
        title,
        description: trial.description.clone(),
        command,
        exit,
        reasons: verdict.reasons,
        stderr_head: verdict
            .exec
            .stderr
            .trim_start()
            .lines()
            .take(6)
            .collect::<Vec<_>>()
            .join("\n      "),
        saved,
    })
}

/// The failures grouped by class, with up to `per_class` examples each.
fn failure_report(failures: &[Failure], per_class: usize) -> String {
    let mut classes: BTreeMap<&str, Vec<&Failure>> = BTreeMap::new();
    for f in failures {
        classes.entry(&f.class).or_default().push(f);
    }
    let mut s = format!(
        "{} failing runs in {} classes:\n",
        failures.len(),
        classes.len()
    );
    for (class, list) in &classes {
        let _ = writeln!(s, "\n== {class}: {} runs", list.len());
        for f in list.iter().take(per_class) {
            let _ = writeln!(s, "  - {}: {}", f.title, f.description);
            let _ = writeln!(s, "    command: {}", f.command);
            let _ = writeln!(s, "    exit: {}; {}", f.exit, f.reasons.join("; "));
            if !f.stderr_head.is_empty() {
                let _ = writeln!(s, "    stderr: {}", f.stderr_head);
            }
            if let Some(p) = &f.saved {
                let _ = writeln!(s, "    saved: {}", p.display());
            }
        }
    }
    s
}

/// Print to the real stderr (the test harness captures `print!`, not direct writes), so the
/// summary shows in CI when the test passes.
fn say(text: &str) {
    let _ = std::io::stderr().write_all(text.as_bytes());
}

#[derive(Default)]
struct Stats {
    runs: usize,
    /// Runs per family of the mutated case(s) ([`families`]).
    families: BTreeMap<&'static str, usize>,
    exits: BTreeMap<String, usize>,
    commands: BTreeMap<&'static str, usize>,
    kinds: BTreeMap<&'static str, usize>,
    unsafe_redrawn: usize,
}

/// The per-run limit: `CONTACT_PATCH_FUZZ_RUN_SECONDS`, default [`RUN_LIMIT_SECONDS`].
fn run_limit() -> Duration {
    static LIMIT: std::sync::OnceLock<Duration> = std::sync::OnceLock::new();
    *LIMIT.get_or_init(|| {
        Duration::from_secs_f64(env_or("CONTACT_PATCH_FUZZ_RUN_SECONDS", RUN_LIMIT_SECONDS))
    })
}

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    match std::env::var(name) {
        Ok(v) => v
            .parse()
            .unwrap_or_else(|_| panic!("{name}={v:?} does not parse")),
        Err(_) => default,
    }
}

fn seed() -> u64 {
    match std::env::var("CONTACT_PATCH_FUZZ_SEED") {
        Ok(v) => match v.strip_prefix("0x") {
            Some(hex) => u64::from_str_radix(hex, 16),
            None => v.parse(),
        }
        .unwrap_or_else(|_| panic!("CONTACT_PATCH_FUZZ_SEED={v:?} does not parse")),
        Err(_) => SEED,
    }
}

// ---------------------------------------------------------------------------------------------
// Result files: the `.vtu` files `judge` and `table --results` read (family `vtu`) and the
// partial files `merge` reads (family `shard`), made valid by the binary itself before the
// fuzzing and then mutated.

/// Cases whose own results (the body files of `run`) are the valid `.vtu` files mutated: Q4 and
/// T6 single-body patches, the two-body contact patch and a tied patch (swept, so also read by
/// `table --results`), a block on a rigid line, a Coulomb patch, a Hex8 patch and a 3D mortar
/// punch.
const VTU_BASES: &[&str] = &[
    "cases/patch-single/q4-distorted.json",
    "cases/patch-single/t6-distorted.json",
    "cases/patch/patch-A-nu0.3.json",
    "cases/tied/tied-B-normal.json",
    "cases/contact/signorini-block-on-rigid-line.json",
    "cases/contact/coulomb-patch-slip.json",
    "cases/3d/patch-hex8.json",
    "tests/data/fuzz/3d-punch-mortar.json",
];

/// A case and its valid results.
struct VtuBase {
    rel: String,
    case: Vec<u8>,
    /// The case's `name`: `table --results DIR` looks for `DIR/<name>.vtu` or `DIR/<name>/`.
    name: String,
    sweep: bool,
    /// `(body name, bytes of <body>.vtu)` for every body of the case.
    files: Vec<(String, Vec<u8>)>,
}

/// The partial files of one sharded command (each a [`Base`] for [`mutate`]).
struct ShardRun {
    label: &'static str,
    parts: Vec<Base>,
}

/// The valid result files both families start from.
struct Fixtures {
    vtu: Vec<VtuBase>,
    shards: Vec<ShardRun>,
}

/// Run the binary for a fixture; it must exit 0 (or 1: a table with a failing cell).
fn make_fixture(args: &[&str], cwd: &Path) {
    let o = Command::new(BIN)
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("the binary starts");
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "fixture `contact-patch {}` failed: {}",
        args.join(" "),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Keys of a partial file whose values are timings or memory: set to 0 so that the bytes of a
/// fixture, and so every mutant, depend on the seed only.
fn without_timings(v: &mut Value) {
    match v {
        Value::Object(m) => {
            for (k, x) in m.iter_mut() {
                if k.contains("seconds") || k.contains("time") || k.contains("memory") {
                    if x.is_number() {
                        *x = json!(0.0);
                    } else if let Value::Object(inner) = x {
                        for t in inner.values_mut().filter(|t| t.is_number()) {
                            *t = json!(0.0);
                        }
                    }
                } else {
                    without_timings(x);
                }
            }
        }
        Value::Array(a) => a.iter_mut().for_each(without_timings),
        _ => {}
    }
}

/// The study of `tests/shard.rs` made smaller: the first `n` values of each axis of
/// `cases/studies/penalty-window.study.json` (`n` cells per axis), with its base beside it.
fn small_study(n: usize) -> Value {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text =
        fs::read_to_string(manifest.join("cases/studies/penalty-window.study.json")).unwrap();
    let mut v: Value = serde_json::from_str(&text).unwrap();
    for axis in v["axes"].as_array_mut().unwrap() {
        for key in ["values", "labels"] {
            if let Some(a) = axis.get_mut(key).and_then(Value::as_array_mut) {
                a.truncate(n);
            }
        }
    }
    v
}

/// Make the fixtures in `dir`: each [`VTU_BASES`] case run, and the partial files of two table
/// splits (two cases in 2 shards, three cases in 3) and of two studies (2 x 2 x 2 cells in 2
/// shards, 3 x 3 x 3 in 3), all run with relative names from `dir/shards`.
fn fixtures(dir: &Path) -> Fixtures {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut vtu = Vec::new();
    for (i, rel) in VTU_BASES.iter().enumerate() {
        let out = dir.join(format!("vtu-{i}"));
        make_fixture(&["run", rel, "--out", out.to_str().unwrap()], manifest);
        let case = fs::read(manifest.join(rel)).unwrap();
        let v: Value = serde_json::from_slice(&case).unwrap();
        let files: Vec<(String, Vec<u8>)> = v["bodies"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|b| b["name"].as_str())
            .map(|b| {
                let bytes = fs::read(out.join(format!("{b}.vtu")))
                    .unwrap_or_else(|e| panic!("{rel}: {b}.vtu: {e}"));
                (b.to_string(), bytes)
            })
            .collect();
        assert!(!files.is_empty(), "{rel}: no body file");
        vtu.push(VtuBase {
            rel: rel.to_string(),
            name: v["name"].as_str().unwrap().to_string(),
            sweep: v.get("sweep").is_some(),
            case,
            files,
        });
    }
    let work = dir.join("shards");
    fs::create_dir_all(&work).unwrap();
    for c in [
        "cases/patch/patch-A-nu0.3.json",
        "cases/patch/patch-C-nu0.3.json",
        "cases/tied/tied-B-normal.json",
        "cases/studies/penalty-window-patch-A.json",
    ] {
        let name = Path::new(c).file_name().unwrap();
        fs::copy(manifest.join(c), work.join(name)).unwrap();
    }
    for (n, file) in [(2, "window-2.study.json"), (3, "window-3.study.json")] {
        fs::write(work.join(file), pretty(&small_study(n))).unwrap();
    }
    let splits: [(&'static str, usize, Vec<&str>); 4] = [
        (
            "table, 2 cases in 2 shards",
            2,
            vec!["table", "patch-A-nu0.3.json", "patch-C-nu0.3.json"],
        ),
        (
            "table, 3 cases in 3 shards",
            3,
            vec![
                "table",
                "patch-A-nu0.3.json",
                "patch-C-nu0.3.json",
                "tied-B-normal.json",
            ],
        ),
        (
            "study, 8 cells in 2 shards",
            2,
            vec!["study", "window-2.study.json"],
        ),
        (
            "study, 27 cells in 3 shards",
            3,
            vec!["study", "window-3.study.json"],
        ),
    ];
    let mut shards = Vec::new();
    for (s, (label, count, command)) in splits.into_iter().enumerate() {
        let out = format!("parts-{s}");
        let mut parts = Vec::new();
        for k in 1..=count {
            let shard = format!("{k}/{count}");
            let mut args = command.clone();
            args.extend(["--out", &out, "--shard", &shard]);
            make_fixture(&args, &work);
            let name = if command[0] == "table" {
                "table".to_string()
            } else {
                "penalty-window".to_string()
            };
            let file = format!("{name}.shard-{k}-of-{count}.json");
            let mut value: Value =
                serde_json::from_slice(&fs::read(work.join(&out).join(&file)).unwrap())
                    .unwrap_or_else(|e| panic!("{label}: {file}: {e}"));
            without_timings(&mut value);
            let text = pretty(&value);
            parts.push(Base {
                rel: format!("{out}/{file}"),
                text,
                value,
                families: vec!["shard"],
                attachments: Vec::new(),
            });
        }
        shards.push(ShardRun { label, parts });
    }
    Fixtures { vtu, shards }
}

/// The `.vtu` mutation kinds and their weights.
const VTU_KINDS: &[(&str, usize)] = &[
    ("vtu_attribute", 26),
    ("vtu_values", 18),
    ("vtu_element", 14),
    ("vtu_encoding", 8),
    ("vtu_non_utf8", 6),
    ("truncate", 8),
    ("byte_damage", 8),
    ("bom", 2),
    ("stacked", 10),
];

/// The attributes whose values are mutated.
const VTU_ATTRIBUTES: &[&str] = &[
    "NumberOfPoints",
    "NumberOfCells",
    "NumberOfComponents",
    "offset",
    "format",
    "type",
    "Name",
    "byte_order",
    "header_type",
    "version",
    "RangeMin",
    "RangeMax",
];

/// `(attribute, start, end)` of every value of the attributes [`VTU_ATTRIBUTES`] in `text`
/// (the byte range between the quotes).
fn vtu_attribute_values(text: &str) -> Vec<(&'static str, usize, usize)> {
    let mut out = Vec::new();
    for &a in VTU_ATTRIBUTES {
        let pattern = format!("{a}=\"");
        let mut from = 0;
        while let Some(i) = text[from..].find(&pattern) {
            let start = from + i + pattern.len();
            let preceded = text[..from + i].ends_with(char::is_whitespace);
            let Some(len) = text[start..].find('"') else {
                break;
            };
            if preceded {
                out.push((a, start, start + len));
            }
            from = start + len;
        }
    }
    out.sort_by_key(|x| x.1);
    out
}

/// The `DataArray` elements of `text` that hold something ([`vtu_elements`]' tuples).
fn filled_data_arrays(text: &str) -> Vec<(usize, usize, usize, usize)> {
    vtu_elements(text, "DataArray")
        .into_iter()
        .filter(|e| e.2 > e.1)
        .collect()
}

/// The byte ranges of each `<tag ...>...</tag>` (or `<tag .../>`) element: `(start of the
/// element, start of its content, end of its content, end of the element)`.
fn vtu_elements(text: &str, tag: &str) -> Vec<(usize, usize, usize, usize)> {
    let (open, close) = (format!("<{tag}"), format!("</{tag}>"));
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(i) = text[from..].find(&open) {
        let start = from + i;
        let Some(gt) = text[start..].find('>') else {
            break;
        };
        let head_end = start + gt + 1;
        let after = text.as_bytes().get(start + open.len()).copied();
        if !matches!(after, Some(b' ' | b'>' | b'\n' | b'\t' | b'/')) {
            from = start + open.len();
            continue;
        }
        if text[..head_end].ends_with("/>") {
            out.push((start, head_end, head_end, head_end));
            from = head_end;
        } else if let Some(j) = text[head_end..].find(&close) {
            let content_end = head_end + j;
            out.push((start, head_end, content_end, content_end + close.len()));
            from = content_end + close.len();
        } else {
            break;
        }
    }
    out
}

/// A replacement for a value of attribute `a` that held `old`.
fn vtu_attribute_value(rng: &mut Rng, a: &str, old: &str) -> String {
    const SIZES: &[&str] = &[
        "1000000000000",
        "2e62",
        "18446744073709551615",
        "18446744073709551616",
        "9223372036854775807",
        "4294967296",
        "1000000000",
        "-1",
        "-3",
        "0",
        "1",
        "2",
        "3",
        "4",
        "6",
        "9",
        "abc",
        "",
        "1.5",
        "NaN",
        " 3 ",
        "0x10",
        "+2",
        "1e3",
        "3 3",
    ];
    match a {
        "format" => rng
            .pick(&["binary", "appended", "Binary", "ASCII", "", "ascii ", "raw"])
            .to_string(),
        "type" => rng
            .pick(&[
                "Float32",
                "Float64",
                "Int32",
                "Int64",
                "UInt8",
                "UInt64",
                "String",
                "Bogus",
                "",
                "PolyData",
                "ImageData",
            ])
            .to_string(),
        "Name" => rng
            .pick(&[
                "",
                "displacement",
                "stress",
                "contact_pressure",
                "contact_force",
                "contact_gap",
                "contact_status",
                "Points",
                "with space",
                "ünïcødé-名前",
                "&amp;lt;",
            ])
            .to_string(),
        _ => match old.trim().parse::<i64>() {
            Ok(n) if rng.chance(0.3) => match rng.below(4) {
                0 => n.saturating_add(1),
                1 => n.saturating_sub(1),
                2 => n.saturating_mul(2),
                _ => n.saturating_neg(),
            }
            .to_string(),
            _ => rng.pick(SIZES).to_string(),
        },
    }
}

/// One mutation of the text of a `.vtu` file (`kind` one of the structural [`VTU_KINDS`]);
/// `None` when the text has nothing it acts on.
fn vtu_text_mutation(kind: &str, rng: &mut Rng, text: &mut String) -> Option<String> {
    match kind {
        "vtu_attribute" => {
            let spans = vtu_attribute_values(text);
            if spans.is_empty() {
                return None;
            }
            let &(a, start, end) = rng.pick(&spans);
            let old = text[start..end].to_string();
            if rng.chance(0.12) {
                // the attribute removed, with its leading space
                let name_start = start - a.len() - 2;
                text.replace_range(name_start - 1..end + 1, "");
                return Some(format!("attribute {a}=\"{old}\" removed"));
            }
            let new = vtu_attribute_value(rng, a, &old);
            text.replace_range(start..end, &new);
            Some(format!("{a}=\"{old}\" -> \"{new}\""))
        }
        "vtu_values" => {
            let arrays = filled_data_arrays(text);
            if arrays.is_empty() {
                return None;
            }
            let &(_, start, end, _) = rng.pick(&arrays);
            let mut tokens: Vec<String> = text[start..end]
                .split_whitespace()
                .map(String::from)
                .collect();
            let what = match rng.below(6) {
                0 if !tokens.is_empty() => {
                    let at = rng.below(tokens.len());
                    let new = *rng.pick(&[
                        "1e308",
                        "-1e308",
                        "1e999",
                        "NaN",
                        "nan",
                        "inf",
                        "-inf",
                        "Infinity",
                        "abc",
                        "-",
                        "1,5",
                        "0x1p3",
                        "1e-320",
                        "18446744073709551616",
                        "--1",
                        ".",
                        "1e",
                        "&#0;",
                    ]);
                    let d = format!("value {at} {:?} -> {new:?}", tokens[at]);
                    tokens[at] = new.to_string();
                    d
                }
                1 if !tokens.is_empty() => {
                    let n = 1 + rng.below(tokens.len().min(4));
                    let at = rng.below(tokens.len() - n + 1);
                    tokens.drain(at..at + n);
                    format!("{n} values removed at {at}")
                }
                2 => {
                    let n = 1 + rng.below(4);
                    for _ in 0..n {
                        tokens.push(format!("{}", rng.below(10)));
                    }
                    format!("{n} values appended")
                }
                3 => {
                    tokens.clear();
                    "values emptied".into()
                }
                4 => {
                    let copies = 2 + rng.below(4);
                    let one = tokens.clone();
                    for _ in 1..copies {
                        tokens.extend(one.iter().cloned());
                    }
                    format!("values repeated {copies} times")
                }
                _ => {
                    let n = tokens.len();
                    tokens.reverse();
                    format!("{n} values reversed")
                }
            };
            let mut joined = tokens.join(" ");
            if !joined.is_empty() {
                joined = format!("\n{joined}\n");
            }
            text.replace_range(start..end, &joined);
            Some(format!("a DataArray's {what}"))
        }
        "vtu_element" => {
            let tag = *rng.pick(&[
                "DataArray",
                "DataArray",
                "DataArray",
                "Points",
                "PointData",
                "Cells",
                "Piece",
            ]);
            let elements = vtu_elements(text, tag);
            if elements.is_empty() {
                return None;
            }
            let &(start, _, _, end) = rng.pick(&elements);
            let element = text[start..end].to_string();
            Some(match rng.below(4) {
                0 => {
                    text.replace_range(start..end, "");
                    format!("a <{tag}> removed")
                }
                1 => {
                    text.insert_str(end, &element);
                    format!("a <{tag}> given twice")
                }
                2 => {
                    let new = *rng.pick(&["CellData", "FieldData", "Bogus", "Point", "dataarray"]);
                    let renamed = element
                        .replacen(&format!("<{tag}"), &format!("<{new}"), 1)
                        .replace(&format!("</{tag}>"), &format!("</{new}>"));
                    text.replace_range(start..end, &renamed);
                    format!("a <{tag}> renamed <{new}>")
                }
                _ => {
                    let nested = format!("<{tag}>{element}</{tag}>");
                    text.replace_range(start..end, &nested);
                    format!("a <{tag}> nested in another")
                }
            })
        }
        "vtu_encoding" => {
            let arrays = filled_data_arrays(text);
            if arrays.is_empty() {
                return None;
            }
            let &(start, content_start, content_end, _) = rng.pick(&arrays);
            const B64: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
            let junk: String = (0..8 + rng.below(64))
                .map(|_| *rng.pick(B64) as char)
                .collect();
            let head = &text[start..content_start];
            let head = match head.find("format=\"ascii\"") {
                Some(i) => {
                    let mut h = head.to_string();
                    let new = if rng.chance(0.5) {
                        "format=\"binary\""
                    } else {
                        "format=\"appended\" offset=\"0\""
                    };
                    h.replace_range(i..i + "format=\"ascii\"".len(), new);
                    h
                }
                None => head.to_string(),
            };
            let appended = head.contains("appended");
            let content = if appended {
                String::new()
            } else {
                junk.clone()
            };
            text.replace_range(start..content_end, &format!("{head}{content}"));
            if appended {
                if let Some(i) = text.rfind("</VTKFile>") {
                    text.insert_str(
                        i,
                        &format!("<AppendedData encoding=\"raw\">_{junk}</AppendedData>\n"),
                    );
                }
            }
            Some(format!(
                "a DataArray made {} ({} bytes of data)",
                if appended { "appended" } else { "binary" },
                junk.len()
            ))
        }
        _ => unreachable!("not a .vtu text mutation: {kind}"),
    }
}

/// Bytes that are not UTF-8 put into `text`: in an attribute value, in a DataArray's values, at
/// a random place, or the whole file recoded as UTF-16.
fn vtu_non_utf8(rng: &mut Rng, text: &str) -> (String, Vec<u8>) {
    const BAD: &[&[u8]] = &[
        b"\xff",
        b"\xfe\xff",
        b"\xc3",
        b"\x80",
        b"\xed\xa0\x80",
        b"\xf8\x88\x80\x80\x80",
    ];
    let bad = *rng.pick(BAD);
    let spans = vtu_attribute_values(text);
    let arrays = vtu_elements(text, "DataArray");
    let at = match rng.below(4) {
        0 if !spans.is_empty() => rng.pick(&spans).1,
        1 if !arrays.is_empty() => rng.pick(&arrays).1,
        2 => {
            let mut b = vec![0xff, 0xfe];
            for u in text.encode_utf16() {
                b.extend_from_slice(&u.to_le_bytes());
            }
            return ("recoded as UTF-16 with a byte-order mark".into(), b);
        }
        _ => rng.below(text.len().max(1)),
    };
    let at = (0..=at)
        .rev()
        .find(|&i| text.is_char_boundary(i))
        .unwrap_or(0);
    let mut b = text.as_bytes()[..at].to_vec();
    b.extend_from_slice(bad);
    b.extend_from_slice(&text.as_bytes()[at..]);
    (format!("bytes {bad:x?} (not UTF-8) at byte {at}"), b)
}

/// One mutant of a `.vtu` file.
fn mutate_vtu(rng: &mut Rng, bytes: &[u8]) -> Mutant {
    let kind = pick_weighted(rng, VTU_KINDS);
    let mut text = String::from_utf8(bytes.to_vec()).expect("our .vtu files are UTF-8");
    let (description, bytes) = match kind {
        "truncate" => truncated(rng, bytes),
        "byte_damage" => byte_damaged(rng, bytes),
        "bom" => {
            let mut b = b"\xef\xbb\xbf".to_vec();
            b.extend_from_slice(bytes);
            ("UTF-8 byte-order mark in front".into(), b)
        }
        "vtu_non_utf8" => vtu_non_utf8(rng, &text),
        "stacked" => {
            let mut d = Vec::new();
            for _ in 0..2 + rng.below(2) {
                let k = *rng.pick(&["vtu_attribute", "vtu_values", "vtu_element", "vtu_encoding"]);
                if let Some(x) = vtu_text_mutation(k, rng, &mut text) {
                    d.push(format!("{k}: {x}"));
                }
            }
            (d.join("; "), text.into_bytes())
        }
        k => match vtu_text_mutation(k, rng, &mut text) {
            Some(d) => (d, text.into_bytes()),
            None => ("nothing to mutate: unchanged".into(), bytes.to_vec()),
        },
    };
    Mutant {
        kind,
        cause: kind.to_string(),
        description,
        bytes,
    }
}

/// A `judge` or `table --results` run on the results of a [`VTU_BASES`] case with one body
/// file mutated (sometimes each of them), laid out as the command reads them: `judge CASE
/// FILE.vtu` for a single body (sometimes its folder), `judge CASE FOLDER` with one
/// `<body>.vtu` each, `table CASE --results DIR --code NAME` with `DIR/<case name>.vtu` or
/// `DIR/<case name>/<body>.vtu`; `--junit`, `--match-tol` and `--code` sometimes hostile.
fn vtu_trial(rng: &mut Rng, index: usize, fx: &[VtuBase]) -> Trial {
    let base = rng.pick(fx);
    let n = base.files.len();
    let target = rng.below(n);
    let each = n > 1 && rng.chance(0.2);
    let table = base.sweep && rng.chance(0.4);
    let shared = rng.chance(if n == 1 { 0.8 } else { 0.15 });
    let mut inputs: Inputs = vec![("case.json".into(), base.case.clone())];
    let (mut kinds, mut descs) = (Vec::new(), Vec::new());
    let folder = if table {
        format!("results/{}", base.name)
    } else {
        "results".to_string()
    };
    for (j, (body, bytes)) in base.files.iter().enumerate() {
        if shared && j != target {
            continue;
        }
        let bytes = if j == target || (each && rng.chance(0.5)) {
            let m = mutate_vtu(rng, bytes);
            kinds.push(m.kind);
            descs.push(format!("{body}.vtu {}: {}", m.kind, m.description));
            m.bytes
        } else {
            bytes.clone()
        };
        let rel = if shared {
            format!("{folder}.vtu")
        } else {
            format!("{folder}/{body}.vtu")
        };
        inputs.push((rel, bytes));
    }
    let results = if shared {
        format!("{folder}.vtu")
    } else {
        folder
    };
    let cmd = if table {
        let code = if rng.chance(0.85) {
            "other-code".to_string()
        } else {
            rng.pick(&[
                "",
                "../escape",
                "a/b",
                "with space",
                "ünïcødé",
                "-x",
                "--out",
            ])
            .to_string()
        };
        Cmd::TableResults {
            case: "case.json".into(),
            results: "results".into(),
            code,
            out: format!("tables-{index}"),
        }
    } else {
        let junit = rng.chance(0.2).then(|| format!("junit-{index}.xml"));
        let match_tol = rng.chance(0.1).then(|| {
            rng.pick(&["0", "-1", "1e308", "NaN", "inf", "1", "abc", "1e-300"])
                .to_string()
        });
        Cmd::Judge {
            case: "case.json".into(),
            results,
            junit,
            match_tol,
        }
    };
    let vtu_cause = kinds.join("+");
    Trial {
        kinds,
        families: vec!["vtu"],
        cause: vtu_cause,
        description: format!(
            "{} ({}): {}",
            base.rel,
            cmd_label_hint(&base.files),
            descs.join(" | ")
        ),
        inputs,
        cmd,
    }
}

/// The bodies of a results set, for a trial's description.
fn cmd_label_hint(files: &[(String, Vec<u8>)]) -> String {
    let names: Vec<&str> = files.iter().map(|f| f.0.as_str()).collect();
    format!("bodies {}", names.join(", "))
}

/// The shard mutation kinds and their weights; `json` applies a mutation of the case family
/// ([`mutate`]) to one part.
const SHARD_KINDS: &[(&str, usize)] = &[
    ("shard_numbers", 22),
    ("shard_units", 16),
    ("shard_mix", 12),
    ("shard_set", 10),
    ("json", 40),
];

/// A replacement of a shard number (`index`, `count` or `total`).
fn shard_number(rng: &mut Rng) -> Value {
    rng.pick(&[
        json!(0),
        json!(-1),
        json!(1),
        json!(2),
        json!(3),
        json!(5),
        json!(10_000),
        json!(10_001),
        json!(1_000_000_000_000_000u64),
        json!(1_000_000_000_000_000_000u64),
        json!(u64::MAX),
        json!(4_294_967_296u64),
        json!(1.5),
        json!(1e300),
        json!("1"),
        Value::Null,
    ])
    .clone()
}

/// The path of the unit list of a part (`ran` of a table, `cells` of a study) and of the
/// index in unit `i`.
fn unit_paths(v: &Value) -> (JPath, Box<dyn Fn(usize) -> JPath>) {
    if v.get("ran").is_some() {
        (
            vec![Seg::Key("ran".into())],
            Box::new(|i| vec![Seg::Key("ran".into()), Seg::Index(i), Seg::Index(0)]),
        )
    } else {
        (
            vec![Seg::Key("cells".into())],
            Box::new(|i| {
                vec![
                    Seg::Key("cells".into()),
                    Seg::Index(i),
                    Seg::Key("index".into()),
                ]
            }),
        )
    }
}

/// A `merge` of the parts of one sharded command with one or more of them mutated, mixed with
/// another command's parts, dropped, repeated or joined by a file that is no part.
fn shard_trial(
    rng: &mut Rng,
    index: usize,
    runs: &[ShardRun],
    vtu: &[VtuBase],
    scratch: &Scratch,
    unsafe_redrawn: &mut usize,
) -> Trial {
    let ctx = scratch.ctx();
    let allowed = scratch.allowed_absolute();
    let r = rng.below(runs.len());
    let run = &runs[r];
    // (file name, bytes) in the order given to merge
    let mut parts: Vec<(String, Vec<u8>)> = run
        .parts
        .iter()
        .map(|p| {
            let name = Path::new(&p.rel).file_name().unwrap();
            (
                name.to_string_lossy().into_owned(),
                p.text.clone().into_bytes(),
            )
        })
        .collect();
    let j = rng.below(parts.len());
    let kind = pick_weighted(rng, SHARD_KINDS);
    let mut value = run.parts[j].value.clone();
    let (mut kind_used, mut cause) = (kind, kind.to_string());
    let description = match kind {
        "shard_numbers" => {
            let mut fields = vec![
                vec![Seg::Key("shard".into()), Seg::Key("index".into())],
                vec![Seg::Key("shard".into()), Seg::Key("count".into())],
            ];
            if value.get("total").is_some() {
                fields.push(vec![Seg::Key("total".into())]);
            }
            let mut d = Vec::new();
            for _ in 0..1 + rng.below(2) {
                let p = rng.pick(&fields).clone();
                let new = shard_number(rng);
                d.push(format!("{} = {}", show(&p), short(&new)));
                *node_mut(&mut value, &p) = new;
            }
            parts[j].1 = pretty(&value).into_bytes();
            d.join(", ")
        }
        "shard_units" => {
            let (list, index_of) = unit_paths(&value);
            let len = node(&value, &list).as_array().map_or(0, Vec::len);
            let d = match rng.below(5) {
                0 if len > 0 => {
                    let i = rng.below(len);
                    node_mut(&mut value, &list)
                        .as_array_mut()
                        .unwrap()
                        .remove(i);
                    format!("{}[{i}] removed", show(&list))
                }
                1 if len > 0 => {
                    let i = rng.below(len);
                    let a = node_mut(&mut value, &list).as_array_mut().unwrap();
                    let unit = a[i].clone();
                    a.push(unit);
                    format!("{}[{i}] given twice", show(&list))
                }
                2 if len > 0 => {
                    let i = rng.below(len);
                    let new = rng
                        .pick(&[
                            json!(u64::MAX),
                            json!(1_000_000_000_000u64),
                            json!(-1),
                            json!(len),
                            json!(len + 1),
                            json!(100),
                            json!(0),
                            json!(1.5),
                            Value::Null,
                        ])
                        .clone();
                    let p = index_of(i);
                    let d = format!("{} = {}", show(&p), short(&new));
                    *node_mut(&mut value, &p) = new;
                    d
                }
                3 if value.get("errors").is_some() => {
                    let at = rng
                        .pick(&[json!(0), json!(u64::MAX), json!(99), json!(-1)])
                        .clone();
                    let e = json!([at, "an error"]);
                    let d = format!("errors += {}", short(&e));
                    if let Some(a) = value["errors"].as_array_mut() {
                        a.push(e);
                    }
                    d
                }
                _ => {
                    *node_mut(&mut value, &list) = json!([]);
                    format!("{} emptied", show(&list))
                }
            };
            parts[j].1 = pretty(&value).into_bytes();
            d
        }
        "shard_mix" => {
            let o = rng.below(runs.len());
            let other = &runs[o].parts[rng.below(runs[o].parts.len())];
            let name = Path::new(&other.rel)
                .file_name()
                .unwrap()
                .to_string_lossy()
                .into_owned();
            let d = format!(
                "{} replaced by {} of \"{}\"",
                parts[j].0, name, runs[o].label
            );
            parts[j] = (format!("other-{name}"), other.text.clone().into_bytes());
            d
        }
        "shard_set" => match rng.below(4) {
            0 if parts.len() > 1 => {
                let (name, _) = parts.remove(j);
                format!("{name} left out")
            }
            1 => {
                let p = parts[j].clone();
                let d = format!("{} given twice", p.0);
                parts.push(p);
                d
            }
            2 => {
                let stranger: (String, Vec<u8>) = match rng.below(5) {
                    0 => ("case.json".into(), vtu[0].case.clone()),
                    1 => ("body.vtu".into(), vtu[0].files[0].1.clone()),
                    2 => ("empty.json".into(), Vec::new()),
                    3 => ("object.json".into(), b"{}".to_vec()),
                    _ => (
                        "kind-only.json".into(),
                        br#"{"kind": "table", "shard": {"index": 1, "count": 1}}"#.to_vec(),
                    ),
                };
                let d = format!("{} among the parts", stranger.0);
                parts.insert(rng.below(parts.len() + 1), stranger);
                d
            }
            _ => {
                parts.reverse();
                "parts given in reverse order".into()
            }
        },
        _ => {
            let m = loop {
                let m = mutate(rng, &run.parts[j], &ctx);
                if stays_in_scratch(&m.bytes, &allowed) {
                    break m;
                }
                *unsafe_redrawn += 1;
            };
            kind_used = m.kind;
            cause = format!("json {}", m.cause);
            parts[j].1 = m.bytes;
            format!("{}: {}", m.kind, m.description)
        }
    };
    // a name repeated on the command line is one file given twice; others get their own file
    let mut inputs: Inputs = Vec::new();
    let mut names = Vec::new();
    for (name, bytes) in parts {
        let rel = format!("parts/{name}");
        if !inputs.iter().any(|(r, _)| *r == rel) {
            inputs.push((rel.clone(), bytes));
        }
        names.push(rel);
    }
    Trial {
        kinds: vec![kind_used],
        families: vec!["shard"],
        cause,
        description: format!("{} ({}): {description}", run.label, run.parts[j].rel),
        inputs,
        cmd: Cmd::Merge {
            parts: names,
            out: format!("merged-{index}"),
        },
    }
}

// ---------------------------------------------------------------------------------------------
// The fuzz test.

/// What a run mutates: a case, a `.vtu` results file, or shard parts.
#[derive(Clone, Copy, PartialEq)]
enum Source {
    Case,
    Vtu,
    Shard,
}

/// The sources and their weights (per cent of the runs).
const SOURCES: &[(Source, usize)] = &[(Source::Case, 80), (Source::Vtu, 12), (Source::Shard, 8)];

/// The trial of run `index` (a function of the seed and the index only, given the scratch).
fn draw_trial(
    rng: &mut Rng,
    index: usize,
    bases: &[Base],
    sweeps: &[&Base],
    scratch: &Scratch,
    unsafe_redrawn: &mut usize,
) -> Trial {
    let ctx = scratch.ctx();
    let allowed = scratch.allowed_absolute();
    // A mutant whose names could reach outside the scratch folder is drawn again.
    let mut safe_mutant = |rng: &mut Rng, base: &Base| loop {
        let m = mutate(rng, base, &ctx);
        if stays_in_scratch(&m.bytes, &allowed) {
            break m;
        }
        *unsafe_redrawn += 1;
    };
    let roll = rng.below(100);
    if roll < 10 {
        let count = 3 + rng.below(3);
        let good_at = rng.chance(0.5).then(|| rng.below(count));
        let (mut inputs, mut kinds, mut causes, mut names, mut descs) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut families: Vec<&'static str> = Vec::new();
        for j in 0..count {
            let base = rng.pick(bases);
            let name = format!("case-{j}.json");
            let Mutant {
                kind,
                cause,
                description: desc,
                bytes,
            } = if good_at == Some(j) {
                Mutant {
                    kind: "none",
                    cause: "none".into(),
                    description: "unchanged".into(),
                    bytes: base.text.clone().into_bytes(),
                }
            } else {
                safe_mutant(rng, base)
            };
            let mut desc = desc;
            for (file, original) in &base.attachments {
                let (bytes, damage) = damaged(rng, original);
                if let Some(damage) = damage {
                    desc.push_str(&format!("; {file} {damage}"));
                }
                inputs.push((format!("cases/{file}"), bytes));
            }
            families.extend(&base.families);
            descs.push(format!("{name} = {} {kind}: {desc}", base.rel));
            inputs.push((format!("cases/{name}"), bytes));
            kinds.push(kind);
            causes.push(cause);
            names.push(name);
        }
        families.sort_unstable();
        families.dedup();
        Trial {
            kinds,
            families,
            cause: causes.join("+"),
            description: descs.join(" | "),
            inputs,
            cmd: Cmd::Check {
                folder: "cases".into(),
                cases: names,
            },
        }
    } else {
        let table = roll < 20 && !sweeps.is_empty();
        let base = if table {
            *rng.pick(sweeps)
        } else {
            rng.pick(bases)
        };
        let m = safe_mutant(rng, base);
        let cmd = if table {
            Cmd::Table {
                case: "case.json".into(),
                out: format!("tables-{index}"),
            }
        } else {
            let out = match rng.below(100) {
                0..=34 => Out::Default,
                35..=69 => Out::Sub(format!("out-{index}")),
                70..=79 => Out::Absolute(format!("out-abs-{index}")),
                80..=86 => Out::Dot,
                87..=93 => Out::DotDot,
                _ => Out::File,
            };
            Cmd::Run {
                case: "case.json".into(),
                out,
            }
        };
        let mut description = format!("{} {}: {}", base.rel, m.kind, m.description);
        let mut inputs = vec![("case.json".to_string(), m.bytes)];
        for (file, original) in &base.attachments {
            let (bytes, damage) = damaged(rng, original);
            if let Some(damage) = damage {
                description.push_str(&format!("; {file} {damage}"));
            }
            inputs.push((file.clone(), bytes));
        }
        Trial {
            kinds: vec![m.kind],
            families: base.families.clone(),
            cause: m.cause,
            description,
            inputs,
            cmd,
        }
    }
}

#[test]
fn mutated_cases_keep_the_invariants() {
    let seed = seed();
    let budget =
        Duration::from_secs_f64(env_or("CONTACT_PATCH_FUZZ_SECONDS", DEFAULT_BUDGET_SECONDS));
    let max_runs: usize = env_or("CONTACT_PATCH_FUZZ_RUNS", DEFAULT_MAX_RUNS);
    let mut bases = bases();
    assert!(
        bases.len() > 20 && bases.iter().any(|b| b.value.get("sweep").is_some()),
        "the catalogue"
    );
    // one family only (`CONTACT_PATCH_FUZZ_FAMILY`, a name of the per-family count): `vtu` and
    // `shard` are the result files, any other name selects the cases of that family
    let family: String = env_or("CONTACT_PATCH_FUZZ_FAMILY", String::new());
    let mut sources: Vec<(Source, usize)> = SOURCES.to_vec();
    if !family.is_empty() {
        match family.as_str() {
            "vtu" => sources.retain(|s| s.0 == Source::Vtu),
            "shard" => sources.retain(|s| s.0 == Source::Shard),
            _ => {
                sources.retain(|s| s.0 == Source::Case);
                bases.retain(|b| b.families.contains(&family.as_str()));
                assert!(!bases.is_empty(), "no case of the family {family:?}");
            }
        }
    }
    let sweeps: Vec<&Base> = bases
        .iter()
        .filter(|b| b.value.get("sweep").is_some())
        .collect();
    let root = tempfile::Builder::new()
        .prefix("contact-patch-fuzz-")
        .tempdir()
        .unwrap();
    let made = Instant::now();
    let fx = if sources.iter().any(|s| s.0 != Source::Case) {
        fixtures(&root.path().join("fixtures"))
    } else {
        Fixtures {
            vtu: Vec::new(),
            shards: Vec::new(),
        }
    };
    let fixture_seconds = made.elapsed().as_secs_f64();
    let failures_dir = failures_dir("fuzz");
    let _ = fs::remove_dir_all(&failures_dir);

    let next = AtomicUsize::new(0);
    let stats = Mutex::new(Stats::default());
    let failures = Mutex::new(Vec::new());
    let saved = Mutex::new(BTreeMap::new());
    let start = Instant::now();
    std::thread::scope(|s| {
        for _ in 0..WORKERS {
            s.spawn(|| loop {
                if start.elapsed() >= budget {
                    break;
                }
                let index = next.fetch_add(1, Ordering::SeqCst);
                if index >= max_runs {
                    break;
                }
                let mut rng = Rng::new(seed ^ (index as u64).wrapping_mul(0xD6E8_FEB8_6659_FD93));
                let scratch = Scratch::new(root.path().join(format!("run-{index}")));
                let mut redrawn = 0;
                let trial = match pick_weighted(&mut rng, &sources) {
                    Source::Case => {
                        draw_trial(&mut rng, index, &bases, &sweeps, &scratch, &mut redrawn)
                    }
                    Source::Vtu => vtu_trial(&mut rng, index, &fx.vtu),
                    Source::Shard => {
                        shard_trial(&mut rng, index, &fx.shards, &fx.vtu, &scratch, &mut redrawn)
                    }
                };
                let verdict = run_trial(&scratch, &trial);
                {
                    let mut st = stats.lock().unwrap();
                    st.runs += 1;
                    *st.exits.entry(verdict.exec.exit.key()).or_default() += 1;
                    *st.commands.entry(trial.cmd.label()).or_default() += 1;
                    for k in &trial.kinds {
                        *st.kinds.entry(k).or_default() += 1;
                    }
                    for f in &trial.families {
                        *st.families.entry(f).or_default() += 1;
                    }
                    st.unsafe_redrawn += redrawn;
                }
                let title = format!("run {index}");
                if let Some(f) = record(title, &trial, verdict, &failures_dir, &saved) {
                    failures.lock().unwrap().push(f);
                }
                let _ = fs::remove_dir_all(&scratch.run_dir);
            });
        }
    });
    let elapsed = start.elapsed().as_secs_f64();
    let st = stats.into_inner().unwrap();
    let mut failures = failures.into_inner().unwrap();
    failures.sort_by_key(|f| {
        f.title
            .trim_start_matches("run ")
            .parse::<usize>()
            .unwrap_or(0)
    });
    let counts = |m: &BTreeMap<String, usize>| {
        m.iter()
            .map(|(k, v)| format!("{k}: {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let counts_static = |m: &BTreeMap<&'static str, usize>| {
        m.iter()
            .map(|(k, v)| format!("{k}: {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    say(&format!(
        "\nfuzz: seed {seed:#x}, {} runs in {elapsed:.1} s (budget {:.0} s, {WORKERS} workers, \
         limit {:.0} s a run; result-file fixtures made in {fixture_seconds:.1} s), {} failing\n  \
         runs per family: {}\n  exit codes: {}\n  commands: {}\n  \
         mutations: {}\n  mutants drawn again because a name could leave the scratch folder: {}\n",
        st.runs,
        budget.as_secs_f64(),
        run_limit().as_secs_f64(),
        failures.len(),
        counts_static(&st.families),
        counts(&st.exits),
        counts_static(&st.commands),
        counts_static(&st.kinds),
        st.unsafe_redrawn,
    ));
    assert!(st.runs > 0, "no run was made");
    if !failures.is_empty() {
        fs::create_dir_all(&failures_dir).unwrap();
        let all = failure_report(&failures, usize::MAX);
        fs::write(failures_dir.join("report.txt"), all).unwrap();
        let report = failure_report(&failures, PRINTED_PER_CLASS);
        panic!(
            "{report}\nfuzz: {} of {} runs failed; inputs saved under {}",
            failures.len(),
            st.runs,
            failures_dir.display()
        );
    }
}

// ---------------------------------------------------------------------------------------------
// The defect reproducers.

#[test]
fn defect_reproducers_keep_the_invariants() {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = manifest.join("tests/defects");
    let mut files: Vec<PathBuf> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    assert!(files.len() >= 20, "the reproducers in {}", dir.display());
    let good = fs::read(manifest.join("cases/contact/signorini-block-on-rigid-line.json")).unwrap();
    let d01 = fs::read(dir.join("D01-panic-divisions-u64max.json")).unwrap();

    // (title, inputs, command); inputs may still hold absolute names, rewritten per scratch.
    let mut replays: Vec<(String, Inputs, Cmd)> = Vec::new();
    for f in &files {
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        let bytes = fs::read(f).unwrap();
        let cmd = if name.starts_with("D04") || name.starts_with("D05") {
            Cmd::Run {
                case: "case.json".into(),
                out: Out::Default,
            }
        } else if name.starts_with("D07") {
            Cmd::Table {
                case: "case.json".into(),
                out: "a/b/tables".into(),
            }
        } else {
            Cmd::Run {
                case: "case.json".into(),
                out: Out::Sub("out-defect".into()),
            }
        };
        replays.push((name, vec![("case.json".into(), bytes)], cmd));
    }
    replays.push((
        "check FOLDER with D01 between two good cases".into(),
        vec![
            ("cases/a-good.json".into(), good.clone()),
            ("cases/b-D01.json".into(), d01),
            ("cases/c-good.json".into(), good.clone()),
        ],
        Cmd::Check {
            folder: "cases".into(),
            cases: ["a-good.json", "b-D01.json", "c-good.json"]
                .map(String::from)
                .to_vec(),
        },
    ));
    for out in [Out::Dot, Out::DotDot, Out::File] {
        replays.push((
            format!("good case, {}", out.label()),
            vec![("case.json".into(), good.clone())],
            Cmd::Run {
                case: "case.json".into(),
                out,
            },
        ));
    }

    let root = tempfile::Builder::new()
        .prefix("contact-patch-defects-")
        .tempdir()
        .unwrap();
    let failures_dir = failures_dir("defects");
    let _ = fs::remove_dir_all(&failures_dir);
    let saved = Mutex::new(BTreeMap::new());
    let mut failures = Vec::new();
    let mut exits: BTreeMap<String, usize> = BTreeMap::new();
    let start = Instant::now();
    let count = replays.len();
    for (i, (title, inputs, cmd)) in replays.into_iter().enumerate() {
        let scratch = Scratch::new(root.path().join(format!("run-{i}")));
        let victim = scratch.victim.display().to_string();
        let inputs: Inputs = inputs
            .into_iter()
            .map(|(rel, bytes)| (rel, absolute_names_into(&bytes, &victim)))
            .collect();
        for (rel, bytes) in &inputs {
            assert!(
                stays_in_scratch(bytes, &scratch.allowed_absolute()),
                "{title}: {rel} has a name that could leave the scratch folder"
            );
        }
        let trial = Trial {
            kinds: vec!["defect"],
            families: Vec::new(),
            cause: "defect".into(),
            description: "replay".into(),
            inputs,
            cmd,
        };
        let verdict = run_trial(&scratch, &trial);
        *exits.entry(verdict.exec.exit.key()).or_default() += 1;
        if let Some(f) = record(title, &trial, verdict, &failures_dir, &saved) {
            failures.push(f);
        }
        let _ = fs::remove_dir_all(&scratch.run_dir);
    }
    say(&format!(
        "\ndefects: {} replays in {:.1} s, {} failing; exit codes: {}\n",
        count,
        start.elapsed().as_secs_f64(),
        failures.len(),
        exits
            .iter()
            .map(|(k, v)| format!("{k}: {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    ));
    if !failures.is_empty() {
        fs::create_dir_all(&failures_dir).unwrap();
        let all = failure_report(&failures, usize::MAX);
        fs::write(failures_dir.join("report.txt"), all).unwrap();
        let report = failure_report(&failures, PRINTED_PER_CLASS);
        panic!(
            "{report}\ndefects: {} replays fail the invariants; saved under {}",
            failures.len(),
            failures_dir.display()
        );
    }
}

/// The case text with every absolute-path string value replaced by `victim` (a folder inside
/// the scratch folder); other bytes are kept as they are.
fn absolute_names_into(bytes: &[u8], victim: &str) -> Vec<u8> {
    let Ok(mut v) = serde_json::from_slice::<Value>(bytes) else {
        return bytes.to_vec();
    };
    let absolute: Vec<String> = paths_where(&v, |x| x.as_str().is_some_and(|s| s.starts_with('/')))
        .iter()
        .map(|p| node(&v, p).as_str().unwrap().to_string())
        .collect();
    if absolute.is_empty() {
        return bytes.to_vec();
    }
    for old in absolute {
        rename(&mut v, &old, victim);
    }
    pretty(&v).into_bytes()
}
