//! `table --baseline OLD.json`: the new cells against a previous `patch-table.json` or
//! `tied-table.json`, so that CI can gate on "no regression" rather than on "all pass".
//!
//! Cells are matched by their identity (catalogue, case, mesh, nu, discretization, passes,
//! slave, enforcement). Only the cells of the cases the new run covers are compared: a baseline
//! cell whose case the new run has no cells of is counted as not compared, not as missing.
//! A **regression** (exit 1) is
//! * a verdict change pass -> fail, pass -> n/a or fail -> n/a;
//! * a baseline cell missing from the new cells of its case;
//! * one of `stress_error`, `pressure_error`, `load_error`, `force_balance` growing by more than
//!   the factor (default 10) *and* above round-off ([`ROUND_OFF`], the tables' own `0`), or
//!   becoming non-finite.
//!
//! Improvements (fail -> pass, an error falling by more than the factor from above round-off)
//! and other changes (n/a -> pass or fail, new cells) are reported and do not fail.

use crate::error::{Error, Result};
use crate::harness::Cell;
use crate::io::scene::Catalogue;
use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Errors below this are round-off (as in [`crate::harness::rounded`]).
pub const ROUND_OFF: f64 = 1e-10;

/// The default factor an error may grow by before it is a regression.
pub const DEFAULT_FACTOR: f64 = 10.0;

/// What a baseline cell must hold (other fields of the table files are ignored).
#[derive(Clone, Debug, Deserialize)]
pub struct BaselineCell {
    pub catalogue: Catalogue,
    pub case: String,
    pub mesh: String,
    pub nu: f64,
    pub discretization: String,
    pub passes: Option<u8>,
    pub slave: Option<String>,
    pub enforcement: String,
    pub verdict: String,
    pub stress_error: Option<f64>,
    pub pressure_error: Option<f64>,
    pub load_error: Option<f64>,
    pub force_balance: Option<f64>,
}

/// A cell's identity; `nu` by its bits (the table files round-trip floats exactly).
type Key = (
    Catalogue,
    String,
    String,
    u64,
    String,
    Option<u8>,
    Option<String>,
    String,
);

impl BaselineCell {
    fn key(&self) -> Key {
        (
            self.catalogue,
            self.case.clone(),
            self.mesh.clone(),
            self.nu.to_bits(),
            self.discretization.clone(),
            self.passes,
            self.slave.clone(),
            self.enforcement.clone(),
        )
    }

    /// The cell in words: catalogue, mesh, nu, discretization, passes, slave, enforcement.
    pub fn name(&self) -> String {
        format!(
            "{} {} nu={} {}{}{} {}",
            self.catalogue.name(),
            self.mesh,
            self.nu,
            self.discretization,
            self.passes
                .map(|p| format!(" {p}-pass"))
                .unwrap_or_default(),
            self.slave
                .as_deref()
                .map(|s| format!(" slave={s}"))
                .unwrap_or_default(),
            self.enforcement
        )
    }

    /// What the table file holds of a new cell.
    fn of(c: &Cell) -> BaselineCell {
        BaselineCell {
            catalogue: c.catalogue,
            case: c.case.clone(),
            mesh: c.mesh.clone(),
            nu: c.nu,
            discretization: c.discretization.clone(),
            passes: c.passes,
            slave: c.slave.clone(),
            enforcement: c.enforcement.clone(),
            verdict: c.verdict.clone(),
            stress_error: c.stress_error,
            pressure_error: c.pressure_error,
            load_error: c.load_error,
            force_balance: c.force_balance,
        }
    }
}

fn cell_key(c: &Cell) -> Key {
    BaselineCell::of(c).key()
}

const VERDICTS: [&str; 3] = ["pass", "fail", "n/a"];

/// Read the cells of one or more table files; any problem is bad input with what, where and a
/// hint.
pub fn load(paths: &[impl AsRef<Path>]) -> Result<Vec<BaselineCell>> {
    let hint = "give a patch-table.json or tied-table.json written by `contact-patch table` \
                (e.g. a copy of reports/patch-table.json from the commit you compare with)";
    let mut all = Vec::new();
    let mut seen: BTreeMap<Key, String> = BTreeMap::new();
    for path in paths {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| {
            Error::invalid(
                path.display(),
                "the baseline (--baseline)",
                format!("cannot be read: {e}"),
                hint,
            )
        })?;
        let cells: Vec<BaselineCell> = serde_json::from_str(&text).map_err(|e| Error::Parse {
            path: path.display().to_string(),
            line: e.line(),
            column: e.column(),
            message: format!("the baseline is not a table of cells: {e}"),
            hint: hint.into(),
        })?;
        if cells.is_empty() {
            return Err(Error::invalid(
                path.display(),
                "the baseline (--baseline)",
                "holds no cells",
                hint,
            ));
        }
        for (i, c) in cells.iter().enumerate() {
            if !VERDICTS.contains(&c.verdict.as_str()) {
                return Err(Error::invalid(
                    path.display(),
                    format!("cell {i} ({})", c.name()),
                    format!(
                        "verdict '{}' is not pass, fail or n/a",
                        c.verdict.escape_debug()
                    ),
                    hint,
                ));
            }
            let here = format!("{} cell {i}", path.display());
            if let Some(first) = seen.insert(c.key(), here) {
                return Err(Error::invalid(
                    path.display(),
                    format!("cell {i} ({})", c.name()),
                    format!("the same cell is also {first}"),
                    "give each table file once (--baseline patch-table.json --baseline tied-table.json)",
                ));
            }
        }
        all.extend(cells);
    }
    Ok(all)
}

/// What kind of change a row reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kind {
    Regression,
    Improvement,
    Other,
}

/// One row of the changes table.
#[derive(Clone, Debug)]
pub struct Change {
    pub kind: Kind,
    pub cell: String,
    pub what: String,
    pub old: String,
    pub new: String,
}

/// The comparison.
#[derive(Debug, Default)]
pub struct Comparison {
    pub compared: usize,
    /// Baseline cells of cases the new run has no cells of.
    pub not_compared: usize,
    /// New cells of cases the baseline has no cells of.
    pub new_not_compared: usize,
    pub changes: Vec<Change>,
}

impl Comparison {
    pub fn regressions(&self) -> usize {
        self.changes
            .iter()
            .filter(|c| c.kind == Kind::Regression)
            .count()
    }

    pub fn improvements(&self) -> usize {
        self.changes
            .iter()
            .filter(|c| c.kind == Kind::Improvement)
            .count()
    }

    /// The changes as a Markdown table, regressions first, at most `rows` rows.
    pub fn markdown(&self, rows: usize) -> String {
        let mut changes = self.changes.clone();
        changes.sort_by_key(|c| c.kind);
        let mut s = String::from("| cell | what changed | old | new |\n|---|---|---|---|\n");
        for c in changes.iter().take(rows) {
            let tag = match c.kind {
                Kind::Regression => "REGRESSION: ",
                Kind::Improvement => "improvement: ",
                Kind::Other => "",
            };
            s += &format!(
                "| {} | {tag}{} | {} | {} |\n",
                c.cell.replace('|', "/"),
                c.what.replace('|', "/"),
                c.old,
                c.new
            );
        }
        if changes.len() > rows {
            s += &format!("\n... and {} more changes\n", changes.len() - rows);
        }
        s
    }
}

fn show(v: Option<f64>) -> String {
    match v {
        None => "-".into(),
        Some(v) => format!("{v:.1e}"),
    }
}

/// Compare `new` cells with the baseline; `factor` (> 1) is how much an error may grow.
pub fn compare(old: &[BaselineCell], new: &[Cell], factor: f64) -> Comparison {
    let mut result = Comparison::default();
    let new_by_key: BTreeMap<Key, &Cell> = new.iter().map(|c| (cell_key(c), c)).collect();
    let old_keys: BTreeSet<Key> = old.iter().map(|c| c.key()).collect();
    let cases: BTreeSet<(Catalogue, &str)> =
        new.iter().map(|c| (c.catalogue, c.case.as_str())).collect();
    for o in old {
        if !cases.contains(&(o.catalogue, o.case.as_str())) {
            result.not_compared += 1;
            continue;
        }
        result.compared += 1;
        let cell = o.name();
        let Some(n) = new_by_key.get(&o.key()) else {
            result.changes.push(Change {
                kind: Kind::Regression,
                cell,
                what: "cell missing from the new table".into(),
                old: o.verdict.clone(),
                new: "-".into(),
            });
            continue;
        };
        if o.verdict != n.verdict {
            let kind = match (o.verdict.as_str(), n.verdict.as_str()) {
                ("pass", _) | ("fail", "n/a") => Kind::Regression,
                ("fail", "pass") => Kind::Improvement,
                _ => Kind::Other,
            };
            result.changes.push(Change {
                kind,
                cell: cell.clone(),
                what: "verdict".into(),
                old: o.verdict.clone(),
                new: n.verdict.clone(),
            });
        }
        for (what, a, b) in [
            ("stress_error", o.stress_error, n.stress_error),
            ("pressure_error", o.pressure_error, n.pressure_error),
            ("load_error", o.load_error, n.load_error),
            ("force_balance", o.force_balance, n.force_balance),
        ] {
            // the table files write a non-finite error as null
            let b = b.filter(|v| v.is_finite()).or(b.map(|_| f64::NAN));
            let kind = match (a, b) {
                (Some(a), Some(b)) if b.is_nan() && a.is_finite() => Some(Kind::Regression),
                (Some(a), Some(b)) if b > factor * a && b > ROUND_OFF => Some(Kind::Regression),
                (Some(a), Some(b)) if a > factor * b && a > ROUND_OFF => Some(Kind::Improvement),
                _ => None,
            };
            if let Some(kind) = kind {
                result.changes.push(Change {
                    kind,
                    cell: cell.clone(),
                    what: format!(
                        "{what} {} by more than {factor}x",
                        if kind == Kind::Regression {
                            "grew"
                        } else {
                            "fell"
                        }
                    ),
                    old: show(a),
                    new: show(b),
                });
            }
        }
    }
    let old_cases: BTreeSet<(Catalogue, &str)> =
        old.iter().map(|c| (c.catalogue, c.case.as_str())).collect();
    for n in new {
        if !old_cases.contains(&(n.catalogue, n.case.as_str())) {
            result.new_not_compared += 1;
        } else if !old_keys.contains(&cell_key(n)) {
            result.changes.push(Change {
                kind: Kind::Other,
                cell: BaselineCell::of(n).name(),
                what: "new cell (not in the baseline)".into(),
                old: "-".into(),
                new: n.verdict.clone(),
            });
        }
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cell(verdict: &str, stress_error: Option<f64>) -> Cell {
        Cell {
            nu: 0.3,
            discretization: "mortar".into(),
            slave: Some("punch".into()),
            enforcement: "lagrange".into(),
            pressure: 1.0,
            verdict: verdict.into(),
            stress_error,
            ..Cell::unmeasured(Catalogue::Patch, "patch-X".into(), "X".into(), 1e-10)
        }
    }

    /// The cell as the table file holds it (non-finite numbers as null).
    fn old(c: &Cell) -> BaselineCell {
        let text = serde_json::to_string(c).unwrap();
        serde_json::from_str(&text).unwrap()
    }

    fn kinds(old_cell: &Cell, new_cell: &Cell) -> Vec<Kind> {
        compare(&[old(old_cell)], std::slice::from_ref(new_cell), 10.0)
            .changes
            .iter()
            .map(|c| c.kind)
            .collect()
    }

    #[test]
    fn verdict_changes() {
        use Kind::*;
        let k = |a, b| kinds(&cell(a, Some(0.0)), &cell(b, Some(0.0)));
        assert_eq!(k("pass", "pass"), []);
        assert_eq!(k("pass", "fail"), [Regression]);
        assert_eq!(k("pass", "n/a"), [Regression]);
        assert_eq!(k("fail", "n/a"), [Regression]);
        assert_eq!(k("fail", "pass"), [Improvement]);
        assert_eq!(k("n/a", "fail"), [Other]);
    }

    #[test]
    fn errors_grow_only_beyond_the_factor_and_above_round_off() {
        use Kind::*;
        let k = |a, b| kinds(&cell("pass", a), &cell("pass", b));
        assert_eq!(k(Some(1e-15), Some(1e-11)), []); // 1e4 x, but round-off
        assert_eq!(k(Some(1e-9), Some(9e-9)), []); // within the factor
        assert_eq!(k(Some(1e-9), Some(2e-8)), [Regression]);
        assert_eq!(k(Some(2e-8), Some(1e-9)), [Improvement]);
        assert_eq!(k(Some(1e-3), Some(f64::NAN)), [Regression]);
        // NaN in both (null in the file) is no change
        assert_eq!(k(Some(f64::NAN), Some(f64::NAN)), []);
    }

    #[test]
    fn cells_of_cases_not_run_are_not_compared_but_missing_ones_are_regressions() {
        let mut other = cell("pass", Some(0.0));
        other.case = "patch-Y".into();
        let mut dropped = cell("pass", Some(0.0));
        dropped.enforcement = "penalty".into();
        let now = cell("pass", Some(0.0));
        let cmp = compare(
            &[old(&other), old(&dropped), old(&now)],
            std::slice::from_ref(&now),
            10.0,
        );
        assert_eq!((cmp.compared, cmp.not_compared), (2, 1));
        assert_eq!(cmp.regressions(), 1);
        assert!(cmp.markdown(10).contains("cell missing"));
    }
}
