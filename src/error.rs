//! Errors: every failure a user can cause says what is wrong, where, and how to fix it.
//!
//! The library returns these typed errors; the command-line tool prints one of them and exits
//! with a non-zero code. Panics are reserved for programmer errors.
//!
//! Every message passes through [`readable_numbers`] when it is displayed: a number that Rust
//! printed as a long decimal (`1e308` as 309 digits, `1e-300` as 300 zeros) is shown in
//! exponent form, with the same value, wherever the message was formatted.

use std::fmt;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read or written.
    Io {
        path: String,
        action: &'static str,
        #[source]
        source: std::io::Error,
    },
    /// The case file is not valid JSON or does not match the case schema.
    Parse {
        path: String,
        line: usize,
        column: usize,
        message: String,
        hint: String,
    },
    /// The case parses but describes something impossible (missing set, bad value, bad mesh...).
    Invalid {
        path: String,
        location: String,
        problem: String,
        hint: String,
    },
    /// The linear or nonlinear solver could not produce a solution.
    Solver {
        path: String,
        problem: String,
        hint: String,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let text = match self {
            Error::Io {
                path,
                action,
                source,
            } => format!("{path}: {action} failed: {source}"),
            Error::Parse {
                path,
                line,
                column,
                message,
                hint,
            } => format!("{path}:{line}:{column}: {message}\n  hint: {hint}"),
            Error::Invalid {
                path,
                location,
                problem,
                hint,
            } => format!("{path}: {location}: {problem}\n  hint: {hint}"),
            Error::Solver {
                path,
                problem,
                hint,
            } => format!("{path}: solver: {problem}\n  hint: {hint}"),
        };
        f.write_str(&readable_numbers(&text))
    }
}

/// `text` with every number that Rust's `Display` for `f64` wrote as a long decimal (more than
/// 21 digits: `1e21` and above, or a tiny value's leading zeros) in exponent form (`1e308`,
/// `2.5e-300`). A run of digits is rewritten only when it is exactly what `f64` prints for the
/// value it reads as, so integers (`u64` has at most 20 digits), names and hashes stay as
/// they are and no value changes.
pub fn readable_numbers(text: &str) -> String {
    let bytes = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let (mut i, mut copied) = (0, 0);
    let word = |b: u8| b.is_ascii_alphanumeric() || b == b'_' || b == b'.';
    while i < bytes.len() {
        if !bytes[i].is_ascii_digit() || (i > 0 && word(bytes[i - 1])) {
            i += 1;
            continue;
        }
        let start = i;
        while i < bytes.len() && bytes[i].is_ascii_digit() {
            i += 1;
        }
        if i + 1 < bytes.len() && bytes[i] == b'.' && bytes[i + 1].is_ascii_digit() {
            i += 1;
            while i < bytes.len() && bytes[i].is_ascii_digit() {
                i += 1;
            }
        }
        let run = &text[start..i];
        let digits = run.bytes().filter(u8::is_ascii_digit).count();
        let at_end = i == bytes.len() || !(bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_');
        if digits > 21 && at_end {
            if let Ok(v) = run.parse::<f64>() {
                if v.to_string() == run {
                    out.push_str(&text[copied..start]);
                    out.push_str(&format!("{v:e}"));
                    copied = i;
                }
            }
        }
    }
    out.push_str(&text[copied..]);
    out
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_decimals_are_shown_in_exponent_form_and_nothing_else_changes() {
        let text = format!(
            "got {}, {} and -{}; {} (u64), node 12, 1.5e-3, id a{}",
            1e308,
            2.5e-300,
            f64::MAX,
            u64::MAX,
            "1".repeat(30)
        );
        assert_eq!(
            readable_numbers(&text),
            format!(
                "got 1e308, 2.5e-300 and -1.7976931348623157e308; {} (u64), node 12, 1.5e-3, id a{}",
                u64::MAX,
                "1".repeat(30)
            )
        );
        // a digit run that is not what f64 prints (here 31 ones) stays
        let ones = "1".repeat(31);
        assert_eq!(readable_numbers(&ones), ones);
        let e = Error::invalid(
            "c.json",
            "materials.m.nu",
            format!("got {}", 1e308),
            "fix it",
        );
        assert_eq!(
            e.to_string(),
            "c.json: materials.m.nu: got 1e308\n  hint: fix it"
        );
    }
}
