//! Shards: a catalogue or a study split into `N` parts that run anywhere (CI jobs, a batch
//! scheduler's array) and are merged into the tables one run writes.
//!
//! Assignment: shard `K` of `N` (1-based) runs the units whose index `i` (from 0) has
//! `i mod N = K - 1`. A study's unit is a grid cell (its index depends only on the study file,
//! [`crate::harness::study`]); a table's unit is a case's sweep, numbered in the sorted order
//! of the case files the command is given (the same paths must be given to every shard). The
//! assignment is stable: it does not depend on timing, on the machine or on other shards.
//!
//! A shard writes one partial JSON file (`<name>.shard-K-of-N.json`) holding what it ran and
//! what it must be merged with (the study itself, or the list of case files). `merge` refuses
//! parts of different studies or catalogues, different `N`, a shard given twice (overlap) and
//! a shard missing, naming them; otherwise it orders the units by index, which is the order of
//! one unsharded run, and writes the same Markdown and JSON. The shard numbers read from a
//! file get the check `--shard K/N` gets ([`Shard::new`]), a study part's study gets the checks of
//! a study file that need no base case, its `total` must be the grid of that study (within its
//! cell limit) and each of its cells must carry the labels of its grid coordinates, before
//! anything is sized or looked up from them: a hostile or edited file is refused naming the file
//! and the field.

use crate::error::{Error, Result};
use crate::harness::study::{StudyCell, StudySpec};
use crate::harness::Cell;
use crate::io::paths::ReportFolder;
use crate::io::scene::Catalogue;
use serde::{Deserialize, Serialize};

/// Shard `index` (1-based) of `count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

/// The most shards a run may be split into.
pub const MAX_SHARDS: usize = 10_000;

impl Shard {
    /// Shard `index` of `count`, when `1 <= index <= count <= MAX_SHARDS`: the one check of a
    /// shard, whether it comes from `--shard K/N` or from a partial file.
    pub fn new(index: usize, count: usize) -> std::result::Result<Shard, String> {
        if index == 0 || count == 0 || index > count || count > MAX_SHARDS {
            return Err(format!("K must be from 1 to N and N at most {MAX_SHARDS}"));
        }
        Ok(Shard { index, count })
    }

    /// Whether unit `i` (from 0) belongs to this shard.
    pub fn owns(&self, i: usize) -> bool {
        i % self.count == self.index - 1
    }

    /// The partial file's name for `name`.
    pub fn file_name(&self, name: &str) -> String {
        format!("{name}.shard-{}-of-{}.json", self.index, self.count)
    }
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Shard, String> {
        let hint = "give K/N with 1 <= K <= N, e.g. --shard 2/3 (the second of three shards)";
        let (k, n) = s
            .split_once('/')
            .ok_or_else(|| format!("'{s}' is not K/N; {hint}"))?;
        let (k, n): (usize, usize) = match (k.trim().parse(), n.trim().parse()) {
            (Ok(k), Ok(n)) => (k, n),
            _ => return Err(format!("'{s}' is not two whole numbers K/N; {hint}")),
        };
        Shard::new(k, n).map_err(|why| format!("'{s}': {why}; {hint}"))
    }
}

/// A partial result.
#[derive(Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Part {
    /// Cells of a study.
    Study {
        shard: Shard,
        /// The study file as given to the shard (shown in the merged report).
        source: String,
        study: StudySpec,
        /// All cells of the grid.
        total: usize,
        cells: Vec<StudyCell>,
    },
    /// Cells of the patch-test tables.
    Table {
        shard: Shard,
        /// Every case file of the run, in unit order.
        cases: Vec<String>,
        /// The cases this shard ran (their unit indices) and their cells.
        ran: Vec<(usize, Vec<Cell>)>,
        /// Cases that could not run: unit index and message.
        errors: Vec<(usize, String)>,
        seconds: f64,
    },
}

fn refuse(what: &str, problem: String, hint: &str) -> Error {
    Error::invalid("merge", what, problem, hint)
}

/// Read partial files. The shard each file states gets the check `--shard K/N` gets
/// ([`Shard::new`]) and a study part's `total` must be its study's grid (within the study's
/// cell limit), before anything is sized from them.
pub fn read_parts(paths: &[std::path::PathBuf]) -> Result<Vec<(String, Part)>> {
    if paths.is_empty() {
        return Err(refuse(
            "PARTS",
            "no partial files given".into(),
            "give the files the shards wrote, e.g. reports/*.shard-*-of-3.json",
        ));
    }
    paths
        .iter()
        .map(|p| {
            let shown = p.display().to_string();
            let text = std::fs::read_to_string(p)
                .map_err(|e| Error::io(&shown, "reading the partial file", e))?;
            let part: Part = serde_json::from_str(&text).map_err(|e| {
                Error::invalid(
                    &shown,
                    format!("line {} column {}", e.line(), e.column()),
                    format!("not a partial file of `table --shard` or `study --shard`: {e}"),
                    "give the *.shard-K-of-N.json files the shards wrote",
                )
            })?;
            let (Part::Study { shard, .. } | Part::Table { shard, .. }) = &part;
            Shard::new(shard.index, shard.count).map_err(|why| {
                Error::invalid(
                    &shown,
                    "shard",
                    format!("index {} of count {}: {why}", shard.index, shard.count),
                    "give the files the shards wrote (`--shard K/N`), unedited",
                )
            })?;
            if let Part::Study {
                study,
                total,
                cells,
                source,
                ..
            } = &part
            {
                let checked =
                    crate::harness::study::from_parts(study.clone(), source.clone(), &shown)?;
                checked.check_recorded_cells(cells, &shown)?;
                let grid = study.checked_cells(&shown)?;
                if *total != grid {
                    return Err(Error::invalid(
                        &shown,
                        "total",
                        format!("{total} cells, but the study's axes make a grid of {grid}"),
                        "give the files the shards wrote (`study --shard K/N`), unedited",
                    ));
                }
            }
            Ok((shown, part))
        })
        .collect()
}

/// Check that `shards` (file, shard) are exactly 1..=N once each.
fn complete(shards: &[(&str, Shard)]) -> Result<usize> {
    let n = shards[0].1.count;
    if let Some((f, s)) = shards.iter().find(|(_, s)| s.count != n) {
        return Err(refuse(
            "PARTS",
            format!(
                "{f} is shard {} of {}, {} is of {n}",
                s.index, s.count, shards[0].0
            ),
            "merge the parts of one split only",
        ));
    }
    let mut seen: Vec<Option<&str>> = vec![None; n];
    for (f, s) in shards {
        if let Some(other) = seen[s.index - 1] {
            return Err(refuse(
                "PARTS",
                format!(
                    "shard {}/{n} is given twice: {other} and {f} (overlapping shards)",
                    s.index
                ),
                "give each shard's file once",
            ));
        }
        seen[s.index - 1] = Some(f);
    }
    let missing: Vec<String> = (1..=n)
        .filter(|k| seen[k - 1].is_none())
        .map(|k| format!("{k}/{n}"))
        .collect();
    if !missing.is_empty() {
        return Err(refuse(
            "PARTS",
            format!("shards missing: {}", missing.join(", ")),
            "run the missing shards (--shard K/N) and give every part",
        ));
    }
    Ok(n)
}

/// What a merge produced.
pub enum Merged {
    /// A study's cells in grid order, with its spec and source.
    Study {
        source: String,
        study: Box<StudySpec>,
        cells: Vec<StudyCell>,
    },
    /// A table's cells in the order of one run, the seconds summed over the shards, and the
    /// cases that could not run.
    Table {
        cells: Vec<Cell>,
        seconds: f64,
        errors: Vec<(String, String)>,
    },
}

/// Merge parts into one run's results, refusing overlaps, gaps and mixed parts.
pub fn merge(parts: Vec<(String, Part)>) -> Result<Merged> {
    let shards: Vec<(&str, Shard)> = parts
        .iter()
        .map(|(f, p)| {
            (
                f.as_str(),
                match p {
                    Part::Study { shard, .. } | Part::Table { shard, .. } => *shard,
                },
            )
        })
        .collect();
    let kinds: Vec<bool> = parts
        .iter()
        .map(|(_, p)| matches!(p, Part::Study { .. }))
        .collect();
    if kinds.iter().any(|&k| k != kinds[0]) {
        return Err(refuse(
            "PARTS",
            "the parts mix study and table shards".into(),
            "merge the parts of one command",
        ));
    }
    complete(&shards)?;
    let first = parts[0].0.clone();
    if kinds[0] {
        let (mut source, mut spec, mut total, mut cells) =
            (String::new(), None::<StudySpec>, 0, Vec::new());
        for (f, p) in parts {
            let Part::Study {
                study,
                total: t,
                cells: c,
                source: s,
                ..
            } = p
            else {
                unreachable!("checked")
            };
            let text = serde_json::to_string(&study).expect("serializes");
            if let Some(first_spec) = &spec {
                if serde_json::to_string(first_spec).expect("serializes") != text || t != total {
                    return Err(refuse(
                        "PARTS",
                        format!(
                            "{f} is a shard of another study than {first} (the study files differ)"
                        ),
                        "merge the shards of one study file",
                    ));
                }
            } else {
                (spec, total, source) = (Some(study), t, s);
            }
            cells.extend(c);
        }
        cells.sort_by_key(|c| c.index);
        let indices: Vec<usize> = cells.iter().map(|c| c.index).collect();
        if indices != (0..total).collect::<Vec<_>>() {
            return Err(refuse(
                "PARTS",
                format!(
                    "the parts hold {} cells of a {total}-cell grid, not each once",
                    cells.len()
                ),
                "rerun the shards of this study file",
            ));
        }
        Ok(Merged::Study {
            source,
            study: Box::new(spec.expect("one part at least")),
            cells,
        })
    } else {
        let (mut cases, mut units, mut errors, mut seconds) =
            (None::<Vec<String>>, Vec::new(), Vec::new(), 0.0);
        for (f, p) in parts {
            let Part::Table {
                cases: c,
                ran,
                errors: e,
                seconds: s,
                ..
            } = p
            else {
                unreachable!("checked")
            };
            match &cases {
                Some(known) if *known != c => {
                    return Err(refuse(
                        "PARTS",
                        format!("{f} was run over other case files than {first}"),
                        "give every shard the same case files",
                    ));
                }
                Some(_) => {}
                None => cases = Some(c),
            }
            units.extend(ran);
            errors.extend(e);
            seconds += s;
        }
        let cases = cases.expect("one part at least");
        let mut done: Vec<usize> = units
            .iter()
            .map(|u| u.0)
            .chain(errors.iter().map(|e| e.0))
            .collect();
        done.sort();
        if done != (0..cases.len()).collect::<Vec<_>>() {
            return Err(refuse(
                "PARTS",
                format!(
                    "the parts cover {} case runs of {} cases, not each once",
                    done.len(),
                    cases.len()
                ),
                "rerun the shards over the same case files",
            ));
        }
        units.sort_by_key(|u| u.0);
        errors.sort_by_key(|e| e.0);
        Ok(Merged::Table {
            cells: units.into_iter().flat_map(|u| u.1).collect(),
            seconds,
            errors: errors
                .into_iter()
                .map(|(i, e)| (cases[i].clone(), e))
                .collect(),
        })
    }
}

/// One catalogue's files as written.
pub struct Written {
    pub catalogue: Catalogue,
    /// The cases' dimension: 2, or 3 for `<catalogue>-table-3d.*`.
    pub dimension: u8,
    pub md: String,
    pub json: String,
    pub cells: Vec<Cell>,
}

impl Written {
    /// The table's name as printed: `patch`, `tied-3d`, ...
    pub fn title(&self) -> String {
        crate::harness::report::table_stem(self.catalogue, self.dimension).replace("-table", "")
    }
}

/// Write `<catalogue>-table.md`, `.json` and `.times.csv` for every catalogue among `cells`
/// (`<catalogue>-table-3d.*` for the cells of 3D cases; what `table` writes; `seconds` is the
/// run's time, written with the cells' times).
pub fn write_tables(folder: &ReportFolder, cells: &[Cell], seconds: f64) -> Result<Vec<Written>> {
    let mut tables: Vec<(Catalogue, u8)> =
        cells.iter().map(|c| (c.catalogue, c.dimension)).collect();
    tables.sort();
    tables.dedup();
    let mut out = Vec::new();
    for (catalogue, dimension) in tables {
        let part: Vec<Cell> = cells
            .iter()
            .filter(|c| c.catalogue == catalogue && c.dimension == dimension)
            .cloned()
            .collect();
        let stem = crate::harness::report::table_stem(catalogue, dimension);
        let report = match (catalogue, dimension) {
            (_, 3) => crate::harness::report::report_3d(catalogue, &part),
            (Catalogue::Tied, _) => crate::harness::report::tied_report(&part),
            (Catalogue::Patch, _) => crate::harness::report::patch_report(&part),
            (Catalogue::Friction, _) => crate::harness::report::friction_report(&part),
        };
        folder.write_file(
            &format!("{stem}.times.csv"),
            &crate::harness::report::times_csv(&part, seconds),
        )?;
        let json = serde_json::to_string_pretty(&part).expect("cells serialize") + "\n";
        let (md, js) = (format!("{stem}.md"), format!("{stem}.json"));
        folder.write_file(&js, &json)?;
        folder.write_file(&md, &report)?;
        out.push(Written {
            catalogue,
            dimension,
            md,
            json: js,
            cells: part,
        });
    }
    Ok(out)
}

/// Write a partial file into `folder`.
pub fn write_part(folder: &ReportFolder, name: &str, shard: Shard, part: &Part) -> Result<String> {
    let file = shard.file_name(name);
    folder.write_file(
        &file,
        &(serde_json::to_string_pretty(part).expect("a part serializes") + "\n"),
    )?;
    Ok(file)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_own_every_nth_unit() {
        let s: Shard = "2/3".parse().unwrap();
        assert_eq!(s, Shard { index: 2, count: 3 });
        assert_eq!(
            (0..9).filter(|&i| s.owns(i)).collect::<Vec<_>>(),
            vec![1, 4, 7]
        );
        for bad in ["0/3", "4/3", "3", "a/b", "1/0", "1/20000"] {
            let e = bad.parse::<Shard>().unwrap_err();
            assert!(e.contains("K/N") || e.contains("K must be"), "{bad}: {e}");
        }
    }

    fn part(k: usize, n: usize, ran: Vec<usize>) -> (String, Part) {
        (
            format!("p{k}"),
            Part::Table {
                shard: Shard { index: k, count: n },
                cases: vec!["a".into(), "b".into(), "c".into()],
                ran: ran.into_iter().map(|i| (i, Vec::new())).collect(),
                errors: Vec::new(),
                seconds: 1.0,
            },
        )
    }

    #[test]
    fn merge_refuses_overlap_gaps_and_mixed_splits() {
        let e = merge(vec![part(1, 2, vec![0, 2]), part(1, 2, vec![0, 2])])
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("given twice"), "{e}");
        let e = merge(vec![part(1, 2, vec![0, 2])])
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("shards missing: 2/2"), "{e}");
        let e = merge(vec![part(1, 2, vec![0, 2]), part(2, 3, vec![1])])
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("of 3"), "{e}");
        let e = merge(vec![part(1, 2, vec![0]), part(2, 2, vec![1])])
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("not each once"), "{e}");
        match merge(vec![part(2, 2, vec![1]), part(1, 2, vec![0, 2])])
            .ok()
            .unwrap()
        {
            Merged::Table { seconds, .. } => assert_eq!(seconds, 2.0),
            Merged::Study { .. } => panic!("a table"),
        }
    }
}
