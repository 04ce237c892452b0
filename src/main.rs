//! The `contact-patch` command-line tool.

use clap::{Parser, Subcommand};
use contact_patch::output::write_run;
use contact_patch::run::{run_case, Outcome};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

#[derive(Parser)]
#[command(
    name = "contact-patch",
    version,
    about = "Finite-element contact solver with a verification harness",
    after_help = "Examples:\n  contact-patch run cases/patch-single/q4-distorted.json --out out/q4\n  contact-patch check cases/patch-single cases/convergence\n\nExit codes: 0 success, 1 a check failed, 2 bad input or a failed solve."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solve one case and write summary.json and one .vtu file per body.
    #[command(
        after_help = "Example:\n  contact-patch run cases/patch-single/q9-distorted.json --out out/q9\n\nThe output folder is replaced only when the run succeeds (default: out/<case name>)."
    )]
    Run {
        /// The case file (JSON).
        case: PathBuf,
        /// Output folder.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Run the contact patch-test catalogue and write reports/patch-table.md and .json.
    #[command(
        after_help = "Example:\n  contact-patch table\n  contact-patch table cases/patch/patch-C-nu0.3.json --out /tmp/reports"
    )]
    Table {
        /// Case files or folders with a sweep (default: cases/patch).
        paths: Vec<PathBuf>,
        /// Folder for patch-table.md and patch-table.json.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
    },
    /// The seed's tied layer: node-to-surface and mortar ties against one body, under refinement;
    /// writes reports/tied-layer.md, SVG plots and .vtu files.
    #[command(
        name = "tied-layer",
        after_help = "Example:\n  contact-patch tied-layer --levels 1,2,4,8"
    )]
    TiedLayer {
        /// Folder with the tied-layer cases.
        #[arg(long, default_value = "cases/tied-layer")]
        cases: PathBuf,
        /// Refinement levels (each multiplies every division).
        #[arg(long, value_delimiter = ',', default_value = "1,2,4,8")]
        levels: Vec<usize>,
        /// Output folder.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
    },
    /// Run the checks declared in cases; exit 0 only when every check of every case passes.
    #[command(
        after_help = "Example:\n  contact-patch check cases/patch-single cases/convergence/cantilever-q4.json\n\nFolders are searched recursively for *.json case files."
    )]
    Check {
        /// Case files or folders of case files.
        #[arg(required = true)]
        paths: Vec<PathBuf>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Run { case, out } => run(&case, out),
        Command::Check { paths } => check(&paths),
        Command::Table { paths, out } => table(&paths, &out),
        Command::TiedLayer { cases, levels, out } => tied_layer(&cases, &levels, &out),
    }
}

/// A progress bar over `len` cases on a terminal, nothing when piped.
fn progress_bar(len: usize) -> Option<ProgressBar> {
    std::io::stderr().is_terminal().then(|| {
        let b = ProgressBar::new(len as u64);
        b.set_style(
            ProgressStyle::with_template("{bar:30} {pos}/{len} {elapsed} {msg}")
                .expect("valid template"),
        );
        b
    })
}

fn spinner() -> Option<ProgressBar> {
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{spinner} {elapsed} {msg}").expect("valid template"),
    );
    bar.enable_steady_tick(Duration::from_millis(120));
    Some(bar)
}

fn run(case: &Path, out: Option<PathBuf>) -> ExitCode {
    let bar = spinner();
    let mut progress = |stage: &str| {
        if let Some(b) = &bar {
            b.set_message(format!("{}: {stage}", case.display()));
        }
    };
    let result = run_case(case, &mut progress).and_then(|outcome| {
        let dir = out.unwrap_or_else(|| Path::new("out").join(&outcome.model.name));
        progress("writing output");
        write_run(&dir, &outcome)?;
        Ok((outcome, dir))
    });
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    match result {
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
        Ok((outcome, dir)) => {
            print_outcome(&outcome);
            println!("output: {}", dir.display());
            if outcome.passed() {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }
    }
}

fn print_outcome(o: &Outcome) {
    let t = &o.solution.timings;
    println!(
        "{}: {} dofs, {} equations; mesh {:.3}s, assembly {:.3}s, factorization {:.3}s, solve {:.3}s, total {:.3}s",
        o.model.name, o.model.dof_count, o.solution.equations, t.mesh, t.assembly, t.factorization, t.solve, t.total
    );
    for c in &o.checks {
        println!(
            "  {} {} (error {:.3e}, tol {:.1e})",
            if c.passed { "pass" } else { "FAIL" },
            c.check,
            c.error,
            c.tol
        );
    }
}

/// Case files named by `paths` (folders searched recursively), sorted.
fn collect_cases(paths: &[PathBuf]) -> Result<Vec<PathBuf>, String> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) -> Result<(), String> {
        let entries = std::fs::read_dir(dir)
            .map_err(|e| format!("{}: cannot read the folder: {e}", dir.display()))?;
        let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
        paths.sort();
        for p in paths {
            if p.is_dir() {
                walk(&p, out)?;
            } else if p.extension().is_some_and(|x| x == "json") {
                out.push(p);
            }
        }
        Ok(())
    }
    let mut out = Vec::new();
    for p in paths {
        if p.is_dir() {
            walk(p, &mut out)?;
        } else if p.exists() {
            out.push(p.clone());
        } else {
            return Err(format!("{}: no such file or folder\n  hint: give case files (*.json) or folders that contain them", p.display()));
        }
    }
    if out.is_empty() {
        return Err("no case files (*.json) found in the given folders".into());
    }
    Ok(out)
}

fn check(paths: &[PathBuf]) -> ExitCode {
    let cases = match collect_cases(paths) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let bar = progress_bar(cases.len());
    let mut failures: Vec<(String, String)> = Vec::new();
    let mut errors = 0;
    for case in &cases {
        if let Some(b) = &bar {
            b.set_message(case.display().to_string());
        }
        match run_case(case, &mut |_| {}) {
            Ok(outcome) => {
                let fail: Vec<_> = outcome.checks.iter().filter(|c| !c.passed).collect();
                let line = format!(
                    "{} ({} checks, {:.3}s)",
                    case.display(),
                    outcome.checks.len(),
                    outcome.solution.timings.total
                );
                match &bar {
                    Some(b) => b.println(format!(
                        "{} {line}",
                        if fail.is_empty() { "pass" } else { "FAIL" }
                    )),
                    None => println!("{} {line}", if fail.is_empty() { "pass" } else { "FAIL" }),
                }
                for c in fail {
                    failures.push((
                        case.display().to_string(),
                        format!("{} (error {:.3e} > tol {:.1e})", c.check, c.error, c.tol),
                    ));
                }
            }
            Err(e) => {
                errors += 1;
                failures.push((case.display().to_string(), format!("error: {e}")));
            }
        }
        if let Some(b) = &bar {
            b.inc(1);
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if failures.is_empty() {
        println!("all {} cases pass", cases.len());
        return ExitCode::SUCCESS;
    }
    println!("\n| case | failure |\n|---|---|");
    for (case, what) in &failures {
        println!("| {case} | {} |", what.replace('\n', " "));
    }
    println!(
        "\n{} of {} cases failed",
        failures
            .iter()
            .map(|f| &f.0)
            .collect::<std::collections::BTreeSet<_>>()
            .len(),
        cases.len()
    );
    ExitCode::from(if errors > 0 { 2 } else { 1 })
}

fn table(paths: &[PathBuf], out: &Path) -> ExitCode {
    let paths = if paths.is_empty() {
        vec![PathBuf::from("cases/patch"), PathBuf::from("cases/tied")]
    } else {
        paths.to_vec()
    };
    let cases = match collect_cases(&paths) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let bar = progress_bar(cases.len());
    let start = std::time::Instant::now();
    let mut cells = Vec::new();
    for case in &cases {
        let mut progress = |m: &str| {
            if let Some(b) = &bar {
                b.set_message(m.to_string());
            }
        };
        match contact_patch::harness::run_sweep(case, &mut progress) {
            Ok(c) => cells.extend(c),
            Err(e) => {
                if let Some(b) = &bar {
                    b.finish_and_clear();
                }
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
        }
        if let Some(b) = &bar {
            b.inc(1);
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let seconds = start.elapsed().as_secs_f64();
    if let Err(e) = std::fs::create_dir_all(out) {
        eprintln!("error: {}: creating the folder failed: {e}", out.display());
        return ExitCode::from(2);
    }
    let mut catalogues: Vec<String> = cells.iter().map(|c| c.catalogue.clone()).collect();
    catalogues.sort();
    catalogues.dedup();
    for catalogue in catalogues {
        let part: Vec<_> = cells
            .iter()
            .filter(|c| c.catalogue == catalogue)
            .cloned()
            .collect();
        let report = match catalogue.as_str() {
            "tied" => contact_patch::report::tied_report(&part),
            _ => contact_patch::report::patch_report(&part, seconds),
        };
        let json = serde_json::to_string_pretty(&part).expect("cells serialize") + "\n";
        let (md_path, json_path) = (
            out.join(format!("{catalogue}-table.md")),
            out.join(format!("{catalogue}-table.json")),
        );
        if let Err(e) =
            write_replacing(&json_path, &json).and_then(|_| write_replacing(&md_path, &report))
        {
            eprintln!("error: {}: writing the tables failed: {e}", out.display());
            return ExitCode::from(2);
        }
        if catalogue == "patch" {
            println!("{}", contact_patch::report::seed_summary(&part));
        }
        println!(
            "{catalogue}: {} cells ({} pass, {} fail, {} n/a); wrote {} and {}",
            part.len(),
            part.iter().filter(|c| c.verdict == "pass").count(),
            part.iter().filter(|c| c.verdict == "fail").count(),
            part.iter().filter(|c| c.verdict == "n/a").count(),
            md_path.display(),
            json_path.display()
        );
    }
    println!("{} cells in {seconds:.2}s", cells.len());
    ExitCode::SUCCESS
}

/// Write a file under a temporary name and rename it into place.
fn write_replacing(path: &Path, text: &str) -> std::io::Result<()> {
    let tmp = path.with_extension("partial");
    std::fs::write(&tmp, text)?;
    std::fs::rename(&tmp, path)
}

fn tied_layer(cases: &Path, levels: &[usize], out: &Path) -> ExitCode {
    if levels.is_empty() || levels.contains(&0) {
        eprintln!("error: --levels needs positive integers, e.g. 1,2,4,8");
        return ExitCode::from(2);
    }
    let plot_level = levels[levels.len() / 2];
    let mut studies = Vec::new();
    for element in ["q4", "q9"] {
        match contact_patch::layer::study(cases, element, levels, plot_level) {
            Ok(s) => studies.push((element.to_string(), s)),
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
        }
    }
    let result = (|| -> contact_patch::Result<Vec<String>> {
        let io = |p: &Path, e| contact_patch::Error::io(p.display(), "writing", e);
        std::fs::create_dir_all(out).map_err(|e| io(out, e))?;
        let mut files = Vec::new();
        for (element, study) in &studies {
            for (stem, svg) in contact_patch::layer::plots(element, plot_level, &study.curves) {
                let name = format!("{stem}.svg");
                std::fs::write(out.join(&name), svg).map_err(|e| io(&out.join(&name), e))?;
                files.push(name);
            }
            for (name, model, solution) in &study.solved {
                let outcome = contact_patch::run::Outcome {
                    checks: contact_patch::checks::evaluate(model, solution),
                    model: model.clone(),
                    solution: solution.clone(),
                };
                contact_patch::output::write_run(
                    &out.join("tied-layer").join(format!("{element}-{name}")),
                    &outcome,
                )?;
            }
        }
        let report = contact_patch::layer::report(&studies, levels, plot_level, &files);
        write_replacing(&out.join("tied-layer.md"), &report)
            .map_err(|e| io(&out.join("tied-layer.md"), e))?;
        let runs: Vec<_> = studies.iter().flat_map(|(_, s)| s.runs.clone()).collect();
        let json = serde_json::to_string_pretty(&runs).expect("runs serialize") + "\n";
        write_replacing(&out.join("tied-layer.json"), &json)
            .map_err(|e| io(&out.join("tied-layer.json"), e))?;
        Ok(files)
    })();
    match result {
        Ok(_) => {
            for (_, study) in &studies {
                for r in &study.runs {
                    println!(
                        "{} level {} {:>16}: {:>6} dofs, du {:.2e}, ds {:.2e}",
                        r.element, r.level, r.variant, r.dofs, r.du, r.ds
                    );
                }
            }
            println!("wrote {}", out.join("tied-layer.md").display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
