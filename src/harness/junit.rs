//! JUnit XML, the report format CI systems display natively (`--junit FILE` on `check` and
//! `table`).
//!
//! The subset every consumer reads: `<testsuites>` holding one `<testsuite name tests failures
//! errors skipped time>` per group, each holding `<testcase classname name time>`; a test case
//! is passed (empty), `<failure message="...">` (a check or cell that ran and failed, the
//! message carrying the measured errors and tolerances), `<error message="...">` (it could not
//! run) or `<skipped message="..."/>` (a table cell that does not apply, or a check that failed
//! as its case expects, with the case's reason). Times are seconds.
//! Text is escaped with `quick_xml::escape`; characters XML 1.0 cannot carry at all (control
//! characters other than tab, newline and carriage return) become U+FFFD.

use crate::harness::checks::{CheckResult, CheckVerdict};
use crate::harness::Cell;

/// How one test case ended.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    Passed,
    /// Ran and failed: a one-line message and a longer text.
    Failure {
        message: String,
        text: String,
    },
    /// Could not run.
    Error {
        message: String,
        text: String,
    },
    /// Does not apply.
    Skipped {
        message: String,
    },
}

/// One `<testcase>`.
#[derive(Clone, Debug)]
pub struct TestCase {
    pub classname: String,
    pub name: String,
    pub seconds: f64,
    pub verdict: Verdict,
}

/// One `<testsuite>`.
#[derive(Clone, Debug)]
pub struct TestSuite {
    pub name: String,
    pub seconds: f64,
    pub cases: Vec<TestCase>,
}

/// `s` with the characters XML 1.0 cannot carry replaced by U+FFFD.
fn xml_chars(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            '\t' | '\n' | '\r' => c,
            c if (c as u32) < 0x20 || c == '\u{FFFE}' || c == '\u{FFFF}' => '\u{FFFD}',
            c => c,
        })
        .collect()
}

/// Escaped for element text.
pub fn text(s: &str) -> String {
    quick_xml::escape::escape(xml_chars(s)).into_owned()
}

/// Escaped for a double-quoted attribute value: also tab, newline and carriage return as
/// character references (a parser would turn them into spaces otherwise).
pub fn attribute(s: &str) -> String {
    text(s)
        .replace('\t', "&#9;")
        .replace('\n', "&#10;")
        .replace('\r', "&#13;")
}

fn seconds(s: f64) -> String {
    if s.is_finite() && s >= 0.0 {
        format!("{s:.6}")
    } else {
        "0".into()
    }
}

/// The whole document.
pub fn render(name: &str, suites: &[TestSuite]) -> String {
    let count =
        |s: &TestSuite, f: fn(&Verdict) -> bool| s.cases.iter().filter(|c| f(&c.verdict)).count();
    let failure = |v: &Verdict| matches!(v, Verdict::Failure { .. });
    let error = |v: &Verdict| matches!(v, Verdict::Error { .. });
    let skipped = |v: &Verdict| matches!(v, Verdict::Skipped { .. });
    let sum = |f: fn(&Verdict) -> bool| suites.iter().map(|s| count(s, f)).sum::<usize>();
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    x += &format!(
        "<testsuites name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"{}\" skipped=\"{}\" time=\"{}\">\n",
        attribute(name),
        suites.iter().map(|s| s.cases.len()).sum::<usize>(),
        sum(failure),
        sum(error),
        sum(skipped),
        seconds(suites.iter().map(|s| s.seconds).sum())
    );
    for s in suites {
        x += &format!(
            "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"{}\" skipped=\"{}\" time=\"{}\">\n",
            attribute(&s.name),
            s.cases.len(),
            count(s, failure),
            count(s, error),
            count(s, skipped),
            seconds(s.seconds)
        );
        for c in &s.cases {
            let open = format!(
                "    <testcase classname=\"{}\" name=\"{}\" time=\"{}\"",
                attribute(&c.classname),
                attribute(&c.name),
                seconds(c.seconds)
            );
            match &c.verdict {
                Verdict::Passed => x += &format!("{open}/>\n"),
                Verdict::Failure { message, text: t } | Verdict::Error { message, text: t } => {
                    let tag = if failure(&c.verdict) {
                        "failure"
                    } else {
                        "error"
                    };
                    x += &format!(
                        "{open}>\n      <{tag} message=\"{}\">{}</{tag}>\n    </testcase>\n",
                        attribute(message),
                        text(t)
                    );
                }
                Verdict::Skipped { message } => {
                    x += &format!(
                        "{open}>\n      <skipped message=\"{}\"/>\n    </testcase>\n",
                        attribute(message)
                    );
                }
            }
        }
        x += "  </testsuite>\n";
    }
    x += "</testsuites>\n";
    x
}

/// `check`: one test case per declared check of a case that ran. A check the case expects to
/// fail (`expected_failures`) that failed is `<skipped>` with the reason, as pytest reports an
/// expected failure; one that passed is a `<failure>` saying so.
pub fn check_cases(case: &str, checks: &[CheckResult]) -> Vec<TestCase> {
    checks
        .iter()
        .map(|c| {
            let text = |also: String| {
                format!(
                    "{}\nmeasured error: {:e}\ntolerance: {:e}{also}",
                    c.check, c.error, c.tol
                )
            };
            let verdict = match c.verdict() {
                CheckVerdict::Passed => Verdict::Passed,
                CheckVerdict::ExpectedFailure => Verdict::Skipped {
                    message: format!("expected failure ({}): {}", c.measured(), c.expectation()),
                },
                CheckVerdict::Failed if c.expected_failure.is_none() => Verdict::Failure {
                    message: c.measured(),
                    text: text(String::new()),
                },
                CheckVerdict::Failed | CheckVerdict::UnexpectedPass => Verdict::Failure {
                    message: format!("{}: {}", c.measured(), c.expectation()),
                    text: text(format!("\n{}", c.expectation())),
                },
            };
            TestCase {
                classname: case.to_string(),
                name: c.check.clone(),
                seconds: 0.0,
                verdict,
            }
        })
        .collect()
}

/// A case (or case file) that could not run: one test case with `<error>`.
pub fn error_case(classname: &str, name: &str, error: &str) -> TestCase {
    TestCase {
        classname: classname.to_string(),
        name: name.to_string(),
        seconds: 0.0,
        verdict: Verdict::Error {
            message: error.lines().next().unwrap_or("error").to_string(),
            text: error.to_string(),
        },
    }
}

/// The identity of a table cell in words: mesh, nu, discretization, passes, slave, enforcement.
pub fn cell_name(c: &Cell) -> String {
    format!(
        "mesh {} nu {} {}{}{} {}",
        c.mesh,
        c.nu,
        c.discretization,
        c.passes.map(|p| format!(" {p}-pass")).unwrap_or_default(),
        c.slave
            .as_deref()
            .map(|s| format!(" slave {s}"))
            .unwrap_or_default(),
        c.enforcement
    )
}

fn error_words(c: &Cell) -> String {
    let show = |v: Option<f64>| match v {
        None => "-".to_string(),
        Some(v) => format!("{v:.3e}"),
    };
    let mut s = format!(
        "stress error {}, pressure error {}, load error {} (tol {:.1e}, relative to the load scale {}); force balance {}",
        show(c.stress_error),
        show(c.pressure_error),
        show(c.load_error),
        c.tol,
        c.pressure,
        show(c.force_balance),
    );
    if let Some(e2) = c.stress_error_stiff {
        s += &format!(
            "; stress error at the stiffer penalty {}, trend {}",
            show(Some(e2)),
            c.penalty_trend.as_deref().unwrap_or("-")
        );
    }
    s
}

/// `table`: one test case per cell; `fail` is a failure, `n/a` skipped.
pub fn cell_case(c: &Cell) -> TestCase {
    let words = error_words(c);
    let verdict = match c.verdict.as_str() {
        "pass" => Verdict::Passed,
        "n/a" => Verdict::Skipped {
            message: if c.note.is_empty() {
                "does not apply".into()
            } else {
                c.note.clone()
            },
        },
        _ => Verdict::Failure {
            message: format!("{}: {words}", c.verdict),
            text: if c.note.is_empty() {
                words
            } else {
                format!("{words}\n{}", c.note)
            },
        },
    };
    TestCase {
        classname: format!("{}.{}", c.catalogue.name(), c.case),
        name: cell_name(c),
        seconds: c.time_ms.unwrap_or(0.0) / 1e3,
        verdict,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaping_covers_markup_quotes_newlines_and_control_characters() {
        assert_eq!(text("a<b & c>d"), "a&lt;b &amp; c&gt;d");
        assert_eq!(
            attribute("say \"hi\"\n'x'\t"),
            "say &quot;hi&quot;&#10;&apos;x&apos;&#9;"
        );
        assert_eq!(text("nul\0bell\u{7}"), "nul\u{FFFD}bell\u{FFFD}");
        assert_eq!(text("é ü 1e-10"), "é ü 1e-10");
    }

    #[test]
    fn counts_are_per_suite_and_total() {
        let case = |v: Verdict| TestCase {
            classname: "c".into(),
            name: "n <1>".into(),
            seconds: 0.5,
            verdict: v,
        };
        let suites = [TestSuite {
            name: "s&t".into(),
            seconds: 1.0,
            cases: vec![
                case(Verdict::Passed),
                case(Verdict::Failure {
                    message: "m".into(),
                    text: "t".into(),
                }),
                case(Verdict::Error {
                    message: "e".into(),
                    text: "".into(),
                }),
                case(Verdict::Skipped {
                    message: "n/a".into(),
                }),
            ],
        }];
        let x = render("all", &suites);
        assert!(
            x.contains("<testsuite name=\"s&amp;t\" tests=\"4\" failures=\"1\" errors=\"1\" skipped=\"1\" time=\"1.000000\">"),
            "{x}"
        );
        assert!(x.contains("name=\"n &lt;1&gt;\""), "{x}");
        assert!(x.contains("<skipped message=\"n/a\"/>"), "{x}");
    }
}
