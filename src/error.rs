//! Errors: every failure a user can cause says what is wrong, where, and how to fix it.
//!
//! The library returns these typed errors; the command-line tool prints one of them and exits
//! with a non-zero code. Panics are reserved for programmer errors.

use std::fmt;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read or written.
    #[error("{path}: {action} failed: {source}")]
    Io {
        path: String,
        action: &'static str,
        #[source]
        source: std::io::Error,
    },
    /// The case file is not valid JSON or does not match the case schema.
    #[error("{path}:{line}:{column}: {message}\n  hint: {hint}")]
    Parse {
        path: String,
        line: usize,
        column: usize,
        message: String,
        hint: String,
    },
    /// The case parses but describes something impossible (missing set, bad value, bad mesh...).
    #[error("{path}: {location}: {problem}\n  hint: {hint}")]
    Invalid {
        path: String,
        location: String,
        problem: String,
        hint: String,
    },
    /// The linear or nonlinear solver could not produce a solution.
    #[error("{path}: solver: {problem}\n  hint: {hint}")]
    Solver {
        path: String,
        problem: String,
        hint: String,
    },
}

impl Error {
    pub fn invalid(
        path: impl fmt::Display,
        location: impl fmt::Display,
        problem: impl fmt::Display,
        hint: impl fmt::Display,
    ) -> Self {
        Error::Invalid {
            path: path.to_string(),
            location: location.to_string(),
            problem: problem.to_string(),
            hint: hint.to_string(),
        }
    }

    pub fn io(path: impl fmt::Display, action: &'static str, source: std::io::Error) -> Self {
        Error::Io {
            path: path.to_string(),
            action,
            source,
        }
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
