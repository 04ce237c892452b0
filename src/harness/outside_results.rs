//! Another code's results files for `judge` and `table --results`: a `.vtu` with every body, or
//! a folder with one `<body>.vtu` per body (read by [`crate::io::vtu_read`]), and the point
//! fields looked up in them by name, with their component counts checked and every value
//! finite. The names read are the constants below, matched without regard to case
//! (`DISPLACEMENT` and `Contact_Pressure` are `displacement` and `contact_pressure`; two fields
//! whose names differ only in case are refused as ambiguous); what each is used for is stated
//! in [`crate::harness::judge`] and [`crate::harness::outside_contact`].

use crate::error::{Error, Result};
use crate::io::paths::file_name;
use crate::io::vtu_read::{read_vtu, PointField, PointGrid};
use crate::model::Model;
use std::path::Path;

/// The point field names read.
pub const DISPLACEMENT_FIELD: &str = "displacement";
pub const STRESS_FIELD: &str = "stress";
pub const CONTACT_PRESSURE_FIELD: &str = "contact_pressure";
pub const CONTACT_FORCE_FIELD: &str = "contact_force";
pub const CONTACT_GAP_FIELD: &str = "contact_gap";
pub const CONTACT_STATUS_FIELD: &str = "contact_status";

/// One results file.
#[derive(Clone, Debug)]
pub struct ResultsFile {
    pub shown: String,
    pub grid: PointGrid,
}

impl ResultsFile {
    /// The point field named `name` without regard to case, with the name the file gives it;
    /// `None` when absent, an error when two fields match.
    pub(crate) fn lookup(&self, name: &str) -> Result<Option<(&str, &PointField)>> {
        if let Some((k, f)) = self.grid.fields.get_key_value(name) {
            return Ok(Some((k, f)));
        }
        let mut found = self
            .grid
            .fields
            .iter()
            .filter(|(k, _)| k.eq_ignore_ascii_case(name));
        let first = found.next();
        if let Some((other, _)) = found.next() {
            return Err(Error::invalid(
                &self.shown,
                format!("point field '{name}'"),
                format!(
                    "the fields '{}' and '{other}' both match (names are read without regard \
                     to case)",
                    first.expect("a first match").0
                ),
                "give the field one name only",
            ));
        }
        Ok(first.map(|(k, f)| (k.as_str(), f)))
    }

    /// Whether the file has a point field named `name` (without regard to case).
    pub(crate) fn has(&self, name: &str) -> bool {
        self.grid
            .fields
            .keys()
            .any(|k| k.eq_ignore_ascii_case(name))
    }
}

/// Another code's results: one file for every body, or one file per body.
#[derive(Clone, Debug)]
pub enum Results {
    Shared(ResultsFile),
    /// In the order of the model's bodies.
    PerBody(Vec<ResultsFile>),
}

impl Results {
    pub(crate) fn of_body(&self, b: usize) -> &ResultsFile {
        match self {
            Results::Shared(f) => f,
            Results::PerBody(files) => &files[b],
        }
    }

    pub(crate) fn files(&self) -> Vec<&ResultsFile> {
        match self {
            Results::Shared(f) => vec![f],
            Results::PerBody(files) => files.iter().collect(),
        }
    }
}

/// Read the results at `path`: a `.vtu` file (for every body), or a folder with `<body>.vtu`
/// for each body of `model` (the layout `contact-patch run` writes).
pub fn load_results(model: &Model, path: &Path) -> Result<Results> {
    load_results_of(model.bodies.iter().map(|b| b.name.as_str()), path)
}

/// [`load_results`] for the bodies named `bodies` (in order; a 2D or a 3D model's).
pub fn load_results_of<'a>(bodies: impl Iterator<Item = &'a str>, path: &Path) -> Result<Results> {
    if path.is_dir() {
        let mut files = Vec::new();
        for body in bodies {
            let file = path.join(file_name("body name", body, ".vtu")?);
            if !file.is_file() {
                return Err(Error::invalid(
                    path.display(),
                    format!("body '{body}'"),
                    format!("the folder holds no {}", file.display()),
                    "a results folder holds one <body name>.vtu per body of the case; or give \
                     one .vtu file that holds every body",
                ));
            }
            files.push(ResultsFile {
                shown: file.display().to_string(),
                grid: read_vtu(&file)?,
            });
        }
        Ok(Results::PerBody(files))
    } else if path.is_file() {
        Ok(Results::Shared(ResultsFile {
            shown: path.display().to_string(),
            grid: read_vtu(path)?,
        }))
    } else {
        Err(Error::invalid(
            path.display(),
            "results",
            "no such file or folder",
            "give a .vtu file, or a folder with one <body name>.vtu per body",
        ))
    }
}

/// A named point field (matched without regard to case, [`ResultsFile::lookup`]) with at
/// least `min_components` components, or `None` when absent.
pub(crate) fn field<'a>(
    file: &'a ResultsFile,
    name: &str,
    min_components: usize,
) -> Result<Option<&'a PointField>> {
    let Some((name, f)) = file.lookup(name)? else {
        return Ok(None);
    };
    if f.components < min_components {
        return Err(Error::invalid(
            &file.shown,
            format!("point field '{name}'"),
            format!(
                "{} components per point (at least {min_components} expected)",
                f.components
            ),
            "write displacement and contact_force as 2- or 3-component vectors (x, y[, 0]), \
             contact_pressure, contact_gap and contact_status as scalars",
        ));
    }
    if let Some(k) = f.values.iter().position(|v| !v.is_finite()) {
        return Err(Error::invalid(
            &file.shown,
            format!("point field '{name}'"),
            format!(
                "value {} of point {} is {}",
                k % f.components + 1,
                k / f.components,
                f.values[k]
            ),
            "the results hold a non-finite number; the other code's solve failed",
        ));
    }
    Ok(Some(f))
}
