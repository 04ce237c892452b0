//! The `contact-patch` command-line tool.
//!
//! Everything it prints goes through [`write_to`]: a reader that has gone away (`contact-patch
//! table | head`, a closed terminal) stops the printing, not the work. The command still writes
//! its files and ends with its own exit code, where the standard `println!` would panic on the
//! broken pipe and leave the run half done.

/// `println!` for a standard output that may have been closed (see [`write_to`]).
macro_rules! println {
    () => { write_to(Stream::Out, format_args!("\n")) };
    ($($arg:tt)*) => { write_to(Stream::Out, format_args!("{}\n", format_args!($($arg)*))) };
}
/// `print!` for a standard output that may have been closed.
macro_rules! print {
    ($($arg:tt)*) => { write_to(Stream::Out, format_args!($($arg)*)) };
}
/// `eprintln!` for a standard error that may have been closed.
macro_rules! eprintln {
    ($($arg:tt)*) => { write_to(Stream::Err, format_args!("{}\n", format_args!($($arg)*))) };
}

/// Which standard stream [`write_to`] writes.
#[derive(Clone, Copy)]
enum Stream {
    Out,
    Err,
}

/// Write `text` to a standard stream; a write that fails (a closed pipe, a full disk under a
/// redirection) is dropped: what is printed is a copy of what the command writes to its files
/// and of its exit code, so nothing is lost that the user cannot read from those.
fn write_to(stream: Stream, text: std::fmt::Arguments) {
    use std::io::Write;
    let _ignored = match stream {
        Stream::Out => std::io::stdout().lock().write_fmt(text),
        Stream::Err => std::io::stderr().lock().write_fmt(text),
    };
}

use clap::{Parser, Subcommand};
use contact_patch::harness::checks::CheckVerdict;
use contact_patch::harness::{baseline, junit};
use contact_patch::io::output::write_run;
use contact_patch::io::paths::{file_name, NamedFile, OutputFolder, ReportFolder};
use contact_patch::io::scene::Catalogue;
use contact_patch::run::{run_case, run_checked, Outcome};
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
    /// Run the patch-test catalogues (contact, tied, friction; 2D and 3D) and write reports/patch-table.md, tied-table.md, friction-table.md, patch-table-3d.md, tied-table-3d.md and their .json.
    #[command(
        after_help = "Example:\n  contact-patch table\n  contact-patch table cases/patch/patch-C-nu0.3.json --out /tmp/reports\n  contact-patch table cases/3d --out /tmp/reports\n  contact-patch table --out new --junit table.xml --baseline old/patch-table.json --baseline old/tied-table.json\n  contact-patch table cases/patch --results their-results --code mycode --out their-tables\n\nWith --baseline the exit code is 1 only on a regression against the baseline (a verdict lost,\na cell gone, an error grown by more than --baseline-factor above 1e-10), not on failing cells."
    )]
    Table {
        /// Case files or folders with a sweep (default: cases/patch, cases/tied, cases/friction and
        /// cases/3d).
        paths: Vec<PathBuf>,
        /// Folder for patch-table.md and patch-table.json.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        /// Also write JUnit XML to this file (one test case per cell; its folder must exist).
        #[arg(long, value_name = "FILE")]
        junit: Option<PathBuf>,
        /// A previous patch-table.json or tied-table.json to compare with (repeatable).
        #[arg(long, value_name = "OLD.json")]
        baseline: Vec<PathBuf>,
        /// How much an error may grow against the baseline before it is a regression.
        #[arg(long, value_name = "FACTOR", default_value_t = baseline::DEFAULT_FACTOR)]
        baseline_factor: f64,
        /// Judge another code's results instead of solving: DIR/<case>.vtu or DIR/<case>/
        /// (one <body>.vtu per body) for each case; one cell per case.
        #[arg(long, value_name = "DIR")]
        results: Option<PathBuf>,
        /// The other code's name, shown in the enforcement column (with --results).
        #[arg(
            long,
            value_name = "NAME",
            default_value = "outside",
            requires = "results"
        )]
        code: String,
        /// With --results: the area the results' contact_pressure is per: `case` (the case's
        /// contact geometry, the default) or `deformed` (X + u, whatever the case says).
        #[arg(long, value_name = "AREA", default_value = "case", value_parser = contact_patch::harness::judge::PressureArea::parse, requires = "results")]
        pressure_area: contact_patch::harness::judge::PressureArea,
        /// Run only shard K of N (every N-th case, from the K-th) and write
        /// table.shard-K-of-N.json into --out; `contact-patch merge` combines the parts.
        #[arg(long, value_name = "K/N", conflicts_with_all = ["baseline", "junit"])]
        shard: Option<contact_patch::harness::shard::Shard>,
    },
    /// Run a study: a base case over the cartesian grid of the study's axes; writes
    /// <study>.md, <study>.json and one error-versus-time SVG per metric.
    #[command(
        after_help = "Example:\n  contact-patch study cases/studies/hertz-cylinder.study.json\n  contact-patch study cases/studies/penalty-window.study.json --shard 1/4 --out parts\n  contact-patch merge parts/penalty-window.shard-*-of-4.json --out reports\n\nThe study format's JSON Schema: contact-patch schema --study. Exit 2 on a bad study file, or when no cell could run."
    )]
    Study {
        /// The study file (JSON).
        study: PathBuf,
        /// Folder for the reports.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        /// Run only shard K of N (every N-th cell, from the K-th) and write
        /// <study>.shard-K-of-N.json; `contact-patch merge` combines the parts.
        #[arg(long, value_name = "K/N")]
        shard: Option<contact_patch::harness::shard::Shard>,
    },
    /// Merge the partial files of `table --shard` or `study --shard` into the tables and
    /// reports one unsharded run writes.
    #[command(
        after_help = "Example:\n  contact-patch merge parts/table.shard-1-of-3.json parts/table.shard-2-of-3.json parts/table.shard-3-of-3.json --out reports\n\nA shard given twice, a missing shard or parts of different runs are refused (exit 2)."
    )]
    Merge {
        /// The partial files (*.shard-K-of-N.json), every shard of one run once.
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        /// Folder for the merged reports.
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
    /// The stability suite: run every hard case and write reports/hard-cases.md and .json (each
    /// case with method, expected and actual outcome, iterations, condition estimate, accuracy).
    #[command(
        after_help = "Example:\n  contact-patch hard\n  contact-patch hard cases/hard --out /tmp/reports\n\nExit 1 when a case does not meet the outcome it states, 2 on bad input."
    )]
    Hard {
        /// Case files or folders (default: cases/hard).
        paths: Vec<PathBuf>,
        /// Folder for hard-cases.md and hard-cases.json.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
    },
    /// Newton's residual histories with the consistent, symmetrized and Laursen-Simo friction
    /// tangents on the slip patch and the incline; writes reports/friction-convergence.md and
    /// reports/friction-convergence.json (run from the repository's root).
    #[command(
        name = "friction-convergence",
        after_help = "Example:\n  contact-patch friction-convergence\n  contact-patch friction-convergence --out /tmp/reports"
    )]
    FrictionConvergence {
        /// Output folder.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        /// Another build of the tool (a contact-patch executable) to run the same cases of the
        /// iterations-per-step table with, listed as "before" beside this build's (its case
        /// files and outputs go to a scratch folder in OUT, removed after the run).
        #[arg(long, value_name = "BINARY")]
        baseline: Option<PathBuf>,
    },
    /// The contact patch test at finite strain: meshes A-E of cases/patch with neo-Hookean
    /// bodies compressed by 20 %, every discretization built at finite strain, each cell
    /// against its small-strain verdict;
    /// writes reports/finite-patch-table.md and .json (run from the repository's root).
    #[command(
        name = "finite-patch",
        after_help = "Example:\n  contact-patch finite-patch\n  contact-patch finite-patch --out /tmp/reports"
    )]
    FinitePatch {
        /// Output folder.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
    },
    /// Hertz at loads where geometric nonlinearity matters: a block pressed onto a rigid
    /// cylinder with small-strain and finite-strain (neo-Hookean) kinematics over approaches
    /// 0.005 to 0.32 of its top, and the finite-strain result at the largest on four meshes;
    /// writes reports/hertz-finite.md, .json and two SVG plots.
    #[command(
        name = "hertz-finite",
        after_help = "Example:\n  contact-patch hertz-finite\n  contact-patch hertz-finite --out /tmp/reports\n\nThe problem and the measures: src/harness/hertz_finite.rs."
    )]
    HertzFinite {
        /// Output folder.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
    },
    /// Hertz in 3D: a rigid sphere pressed into an elastic quarter block on four graded
    /// Hex8 meshes, the contact radius and peak pressure against the closed form; writes
    /// reports/hertz-3d.md, .json and an SVG of the pressure profile.
    #[command(
        name = "hertz-3d",
        after_help = "Example:\n  contact-patch hertz-3d\n  contact-patch hertz-3d --out /tmp/reports\n\nThe problem and the measures: src/harness/hertz3d.rs."
    )]
    Hertz3d {
        /// Output folder.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
    },
    /// Large sliding at finite strain: a neo-Hookean block pressed and slid by six facet
    /// lengths over a non-matching neo-Hookean foundation, per contact discretization (those
    /// finite strain refuses are listed with the reason); the oscillation of the contact forces
    /// along the path and Newton's residual histories; writes reports/finite-sliding.md, .json
    /// and two SVG plots.
    #[command(
        name = "finite-sliding",
        after_help = "Example:\n  contact-patch finite-sliding\n  contact-patch finite-sliding --out /tmp/reports\n\nThe problem and the measures: src/harness/finite_sliding.rs."
    )]
    FiniteSliding {
        /// Output folder.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
    },
    /// The ironing problem at finite strain, frictionless: a stiff neo-Hookean die with a
    /// circular bottom pressed into a soft neo-Hookean slab and slid by 2.5 die widths, on three
    /// meshes, per contact discretization; the forces on the die along the path, their
    /// differences between successive refinements and their oscillation; writes
    /// reports/ironing.md, .json and .svg.
    #[command(
        name = "ironing",
        after_help = "Example:\n  contact-patch ironing\n  contact-patch ironing --out /tmp/reports\n\nThe problem and the measures: src/harness/ironing.rs."
    )]
    Ironing {
        /// Output folder.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
    },
    /// The impact studies: `impact` (default), the dynamic cases with every impact treatment
    /// and mass against the 1D wave solutions (reports/impact.md, .json); `block-drop`, a block
    /// dropped on a foundation under time-step refinement (reports/block-drop.md, .json, .svg);
    /// `cost`, errors against the wave solution versus wall time over four refinement levels
    /// (reports/impact-cost.md, .json, .svg).
    #[command(
        name = "impact-report",
        after_help = "Example:\n  contact-patch impact-report\n  contact-patch impact-report cases/dynamics/bar-on-rigid-wall.json --out /tmp/reports\n  contact-patch impact-report --study block-drop\n  contact-patch impact-report --study cost"
    )]
    ImpactReport {
        /// Dynamic case files (default: the three bar cases of cases/dynamics for `impact`,
        /// the three block-drop cases for `block-drop`, the bar on a rigid wall for `cost`).
        paths: Vec<PathBuf>,
        /// Output folder.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        /// Which study to run.
        #[arg(long, value_enum, default_value = "impact")]
        study: ImpactStudy,
    },
    /// Solve one case and plot a contact pair's pressure profile (against Hertz's closed form
    /// when the master is a rigid circle); writes <case>.<pair>.pressure.svg and .md.
    #[command(
        after_help = "Example:\n  contact-patch profile cases/contact/hertz-profile.json --pair cylinder\n\nThe pressures are those of <pair>.contact.csv in the folder `run` writes."
    )]
    Profile {
        /// The case file (JSON).
        case: PathBuf,
        /// The contact pair.
        #[arg(long)]
        pair: String,
        /// Folder for the plot and its table.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
    },
    /// Write reports/index.html: one self-contained page with every table, plot and study of
    /// the reports folder (a report not generated yet is listed with its command).
    #[command(
        after_help = "Example:\n  contact-patch report\n  contact-patch report --reports /tmp/reports"
    )]
    Report {
        /// The reports folder (read, and where index.html is written).
        #[arg(long, default_value = "reports")]
        reports: PathBuf,
    },
    /// Solve Cattaneo-Mindlin cases (a cylinder pressed, then sheared, with Coulomb friction)
    /// and measure the stick zone and the shear traction against the closed forms; writes
    /// cattaneo-mindlin.md, .json and .svg (the plot of the last case).
    #[command(
        after_help = "Example:\n  contact-patch cattaneo\n  contact-patch cattaneo cases/friction-bench/cattaneo-mindlin-L1.json --out /tmp/reports\n\nGive the cases from coarse to fine."
    )]
    Cattaneo {
        /// Case files (default: cases/friction-bench/cattaneo-mindlin-L1 .. L4).
        paths: Vec<PathBuf>,
        /// The frictional contact pair.
        #[arg(long, default_value = "interface")]
        pair: String,
        /// Output folder.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
    },
    /// Print the JSON Schema of the case format (committed as cases/case.schema.json; a case
    /// file may name it in "$schema" so that editors validate and complete it).
    #[command(
        after_help = "Example:\n  contact-patch schema > cases/case.schema.json\n  contact-patch schema --study > cases/studies/study.schema.json"
    )]
    Schema {
        /// Print the JSON Schema of the study format instead.
        #[arg(long)]
        study: bool,
    },
    /// Run the checks declared in cases; exit 0 only when every check of every case passes.
    #[command(
        after_help = "Example:\n  contact-patch check cases/patch-single cases/convergence/cantilever-q4.json\n\nFolders are searched recursively for *.json case files."
    )]
    Check {
        /// Case files or folders of case files.
        #[arg(required = true)]
        paths: Vec<PathBuf>,
        /// Also write JUnit XML to this file (one test case per check; its folder must exist).
        #[arg(long, value_name = "FILE")]
        junit: Option<PathBuf>,
    },
    /// Write cases as files other contact codes read: a Gmsh .msh (physical groups for every
    /// body, node set and facet set), one .vtu per body, and a JSON sidecar with the problem.
    #[command(
        after_help = "Example:\n  contact-patch export cases/patch cases/patch-single --out export\n\nEach case goes to <out>/<case name>/ (replaced as a whole): <case name>.msh, <case name>.json,\n<body>.vtu. Judge the other code's results with `contact-patch judge`."
    )]
    Export {
        /// Case files or folders of case files.
        #[arg(required = true)]
        paths: Vec<PathBuf>,
        /// Folder that receives one sub-folder per case.
        #[arg(long)]
        out: PathBuf,
    },
    /// Judge another code's results for a case with the case's checks (see `export`).
    #[command(
        after_help = "Example:\n  contact-patch judge cases/patch-single/q4-distorted.json results/q4-distorted.vtu\n  contact-patch judge cases/patch/patch-A-nu0.3.json results/patch-A-nu0.3/ --junit judge.xml\n  contact-patch judge export/patch-A-nu0.3 results/patch-A-nu0.3/\n\nCASE is a case file, or the folder `export` wrote for it (or the <case>.json in it), which\ncarries the case. RESULTS is a .vtu file (ASCII, base64 binary, appended raw or base64,\nzlib-compressed) with the point field 'displacement' (optional: 'stress'; names read without\nregard to case), or a folder with one <body name>.vtu per body. Each node is matched to the result point within\n--match-tol times the model size. Checks that need the solve's contact forces are listed as\nnot judged. Exit codes: 0 every judged check passes, 1 one fails, 2 bad input."
    )]
    Judge {
        /// The case file (JSON), or a folder `export` wrote (or the <case>.json sidecar in it).
        case: PathBuf,
        /// The results: a .vtu file, or a folder with <body name>.vtu per body.
        results: PathBuf,
        /// Node-matching distance, as a share of the model size.
        #[arg(long, value_name = "SHARE", default_value_t = contact_patch::harness::judge::DEFAULT_MATCH_SHARE)]
        match_tol: f64,
        /// The area the results' contact_pressure is per: `case` (the case's contact
        /// geometry, the default) or `deformed` (X + u, whatever the case says).
        #[arg(long, value_name = "AREA", default_value = "case", value_parser = contact_patch::harness::judge::PressureArea::parse)]
        pressure_area: contact_patch::harness::judge::PressureArea,
        /// Also write JUnit XML to this file (one test case per check; its folder must exist).
        #[arg(long, value_name = "FILE")]
        junit: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Run { case, out } => run(&case, out),
        Command::Check { paths, junit } => check(&paths, junit.as_deref()),
        Command::Export { paths, out } => export(&paths, &out),
        Command::Judge {
            case,
            results,
            match_tol,
            pressure_area,
            junit,
        } => judge(&case, &results, match_tol, pressure_area, junit.as_deref()),
        Command::Table {
            paths,
            out,
            junit,
            baseline,
            baseline_factor,
            results,
            code,
            pressure_area,
            shard,
        } => table(
            &paths,
            &out,
            junit.as_deref(),
            &baseline,
            baseline_factor,
            results
                .as_deref()
                .map(|dir| (dir, code.as_str(), pressure_area)),
            shard,
        ),
        Command::Study { study, out, shard } => run_study(&study, &out, shard),
        Command::Merge { parts, out } => merge(&parts, &out),
        Command::TiedLayer { cases, levels, out } => tied_layer(&cases, &levels, &out),
        Command::Hard { paths, out } => hard(&paths, &out),
        Command::ImpactReport { paths, out, study } => impact_report(&paths, &out, study),
        Command::FrictionConvergence { out, baseline } => {
            friction_convergence(&out, baseline.as_deref())
        }
        Command::FinitePatch { out } => finite_patch(&out),
        Command::HertzFinite { out } => hertz_finite(&out),
        Command::Hertz3d { out } => hertz_3d(&out),
        Command::FiniteSliding { out } => finite_sliding(&out),
        Command::Ironing { out } => ironing(&out),
        Command::Profile { case, pair, out } => profile(&case, &pair, &out),
        Command::Report { reports } => report_page(&reports),
        Command::Cattaneo { paths, pair, out } => cattaneo(&paths, &pair, &out),
        Command::Schema { study } => {
            if study {
                print!("{}", contact_patch::harness::study::study_schema());
            } else {
                print!("{}", contact_patch::io::scene::case_schema());
            }
            ExitCode::SUCCESS
        }
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
    // A given output folder is checked before the solve, so that a refusal costs nothing.
    let given = match out.as_deref().map(OutputFolder::new).transpose() {
        Ok(folder) => folder,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    if let Some(case3) = contact_patch::run3d::read_3d_case(case) {
        return run3(case, &case3, given);
    }
    let bar = spinner();
    let mut progress = |stage: &str| {
        if let Some(b) = &bar {
            b.set_message(format!("{}: {stage}", case.display()));
        }
    };
    let result = run_case(case, &mut progress).and_then(|outcome| {
        let folder = match given {
            Some(folder) => folder,
            None => OutputFolder::new(&Path::new("out").join(file_name(
                "case name",
                &outcome.model.name,
                "",
            )?))?,
        };
        progress("writing output");
        write_run(&folder, &outcome)?;
        Ok((outcome, folder))
    });
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    match result {
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
        Ok((outcome, folder)) => {
            print_outcome(&outcome);
            println!("output: {}", folder.path().display());
            if let Some(why) = outcome.failed_solve() {
                eprintln!("error: {why}");
                return ExitCode::from(2);
            }
            if outcome.passed() {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }
    }
}

/// `run` for a 3D case (see `contact_patch::run3d`).
fn run3(
    path: &Path,
    case: &contact_patch::io::scene::Case,
    given: Option<OutputFolder>,
) -> ExitCode {
    let source = path.display().to_string();
    let result = contact_patch::run::run_case3(case, &source).and_then(|outcome| {
        let folder = match given {
            Some(folder) => folder,
            None => OutputFolder::new(&Path::new("out").join(file_name(
                "case name",
                &outcome.model.name,
                "",
            )?))?,
        };
        contact_patch::run3d::write_run3(&folder, &outcome)?;
        Ok((outcome, folder))
    });
    match result {
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
        Ok((o, folder)) => {
            for w in &o.warnings {
                eprintln!("warning: {w}");
            }
            let cells: Vec<String> = o
                .model
                .bodies
                .iter()
                .map(|b| format!("{} {:?} cells", b.mesh.cell_count(), b.mesh.kind))
                .collect();
            println!(
                "{}: 3D, {} dofs ({})",
                o.model.name,
                o.model.dof_count,
                cells.join(", ")
            );
            if let Some(r) = &o.solution.iterative {
                println!("  linear solver: {}", r.describe());
            }
            if let Some(c) = &o.solution.contact {
                let active = c.active.iter().filter(|&&a| a).count();
                println!(
                    "  contact: {:?} after {} iteration(s), {active} of {} rows active",
                    c.termination,
                    c.iterations,
                    c.rows.len()
                );
            }
            for c in &o.checks {
                println!("  {}", c.report_line());
            }
            println!("output: {}", folder.path().display());
            if o.passed() {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }
    }
}

fn print_outcome(o: &Outcome) {
    for w in &o.warnings {
        eprintln!("warning: {w}");
    }
    let t = &o.solution.timings;
    println!(
        "{}: {} dofs, {} equations; mesh {:.3}s, assembly {:.3}s, factorization {:.3}s, solve {:.3}s, total {:.3}s",
        o.model.name, o.model.dof_count, o.solution.equations, t.mesh, t.assembly, t.factorization, t.solve, t.total
    );
    if let Some(r) = &o.solution.iterative {
        println!("  linear solver: {}", r.describe());
    }
    for c in &o.checks {
        println!("  {}", c.report_line());
    }
}

/// Case files named by `paths` (folders searched recursively), sorted. In folders, a
/// `*.schema.json` file (a format's schema) and a `*.study.json` file (a study) are not cases.
fn collect_cases(paths: &[PathBuf]) -> Result<Vec<PathBuf>, String> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) -> Result<(), String> {
        let entries = std::fs::read_dir(dir)
            .map_err(|e| format!("{}: cannot read the folder: {e}", dir.display()))?;
        let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
        paths.sort();
        for p in paths {
            if p.is_dir() {
                walk(&p, out)?;
            } else if p.extension().is_some_and(|x| x == "json")
                && !p.to_string_lossy().ends_with(".schema.json")
                && !p.to_string_lossy().ends_with(".study.json")
            {
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

/// The `--junit` file, checked before any work (a refusal is bad input).
fn junit_file(path: Option<&Path>) -> Result<Option<NamedFile>, ExitCode> {
    path.map(|p| NamedFile::new(p, "the --junit file"))
        .transpose()
        .map_err(|e| {
            eprintln!("error: {e}");
            ExitCode::from(2)
        })
}

/// Write the JUnit document; a failure is reported and turns the exit code into 2.
fn write_junit(file: Option<&NamedFile>, name: &str, suites: &[junit::TestSuite]) -> bool {
    let Some(file) = file else { return true };
    match file.write(&junit::render(name, suites)) {
        Ok(()) => {
            println!("wrote {}", file.path().display());
            true
        }
        Err(e) => {
            eprintln!("error: {e}");
            false
        }
    }
}

fn check(paths: &[PathBuf], junit_path: Option<&Path>) -> ExitCode {
    let junit_out = match junit_file(junit_path) {
        Ok(f) => f,
        Err(code) => return code,
    };
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
    let (mut expected_failures, mut cases_with_expected_failures) = (0, 0);
    let mut suites = Vec::new();
    for case in &cases {
        if let Some(b) = &bar {
            b.set_message(case.display().to_string());
        }
        let start = std::time::Instant::now();
        let result = guarded(case, || run_checked(case, &mut |_| {}));
        let shown = case.display().to_string();
        suites.push(junit::TestSuite {
            name: shown.clone(),
            seconds: start.elapsed().as_secs_f64(),
            cases: match &result {
                Ok(outcome) => junit::check_cases(&outcome.name, &outcome.checks),
                Err(e) => vec![junit::error_case(&shown, "run", e)],
            },
        });
        let say = |text: String| match &bar {
            Some(b) => b.println(text),
            None => println!("{text}"),
        };
        match result {
            Ok(outcome) => {
                let fail: Vec<_> = outcome
                    .checks
                    .iter()
                    .filter(|c| c.fails_the_case())
                    .collect();
                let expected: Vec<_> = outcome
                    .checks
                    .iter()
                    .filter(|c| c.verdict() == CheckVerdict::ExpectedFailure)
                    .collect();
                let counted = match expected.len() {
                    0 => String::new(),
                    1 => ", 1 expected failure".to_string(),
                    n => format!(", {n} expected failures"),
                };
                say(format!(
                    "{} {} ({} checks{counted}, {:.3}s)",
                    if fail.is_empty() { "pass" } else { "FAIL" },
                    case.display(),
                    outcome.checks.len(),
                    outcome.seconds
                ));
                for c in &expected {
                    say(format!("  {}", c.report_line()));
                }
                expected_failures += expected.len();
                cases_with_expected_failures += usize::from(!expected.is_empty());
                for w in &outcome.warnings {
                    eprintln!("warning: {}: {w}", case.display());
                }
                for c in fail {
                    let why = c.expectation();
                    let why = if why.is_empty() {
                        String::new()
                    } else {
                        format!(": {why}")
                    };
                    failures.push((
                        case.display().to_string(),
                        format!("{} ({}){why}", c.check, c.measured()),
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
    let written = write_junit(junit_out.as_ref(), "contact-patch check", &suites);
    let expected =
        if expected_failures > 0 {
            format!(
            "; {expected_failures} expected failure{} in {cases_with_expected_failures} case{} \
             (listed above with the reasons their cases give in expected_failures)",
            if expected_failures == 1 { "" } else { "s" },
            if cases_with_expected_failures == 1 { "" } else { "s" },
        )
        } else {
            String::new()
        };
    if failures.is_empty() {
        println!("all {} cases pass{expected}", cases.len());
        return if written {
            ExitCode::SUCCESS
        } else {
            ExitCode::from(2)
        };
    }
    println!("\n| case | failure |\n|---|---|");
    for (case, what) in &failures {
        println!("| {case} | {} |", what.replace('\n', " "));
    }
    println!(
        "\n{} of {} cases failed{expected}",
        failures
            .iter()
            .map(|f| &f.0)
            .collect::<std::collections::BTreeSet<_>>()
            .len(),
        cases.len()
    );
    ExitCode::from(if errors > 0 || !written { 2 } else { 1 })
}

fn export(paths: &[PathBuf], out: &Path) -> ExitCode {
    let folder = match ReportFolder::new(out) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let cases = match collect_cases(paths) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let mut errors = 0;
    for case in &cases {
        let result = guarded(case, || {
            contact_patch::io::export::export_case(case, &folder)
        });
        match result {
            Ok((target, files)) => println!(
                "{}: wrote {} ({})",
                case.display(),
                target.path().display(),
                files.join(", ")
            ),
            Err(e) => {
                eprintln!("error: {e}");
                errors += 1;
            }
        }
    }
    if errors > 0 {
        eprintln!(
            "error: {errors} of {} cases could not be exported",
            cases.len()
        );
        return ExitCode::from(2);
    }
    ExitCode::SUCCESS
}

fn judge(
    case: &Path,
    results: &Path,
    match_tol: f64,
    pressure_area: contact_patch::harness::judge::PressureArea,
    junit_path: Option<&Path>,
) -> ExitCode {
    use contact_patch::harness::judge;
    let junit_out = match junit_file(junit_path) {
        Ok(f) => f,
        Err(code) => return code,
    };
    // an export folder or its sidecar carries the case (contact_patch::io::export)
    let model = match contact_patch::io::export::exported_case(case) {
        Ok(Some((sidecar, exported))) => {
            let source = sidecar.display().to_string();
            contact_patch::model::Model::build(&exported, &source)
                .and_then(contact_patch::model::admit::admit)
        }
        Ok(None) => {
            if let Some(case3) = contact_patch::run3d::read_3d_case(case) {
                if pressure_area != judge::PressureArea::Case {
                    eprintln!(
                        "error: --pressure-area {pressure_area:?}: a 3D case's judge reads no \
                         contact fields (only 'displacement' and 'stress')\n  hint: leave out \
                         --pressure-area for 3D cases"
                    );
                    return ExitCode::from(2);
                }
                return judge3(case, &case3, results, match_tol, junit_out);
            }
            contact_patch::model::admit::load(case)
        }
        Err(e) => Err(e),
    };
    let judged = model.and_then(|model| {
        let found = judge::load_results(&model, results)?;
        let j = judge::judge_with(
            &model,
            &found,
            judge::ReadOptions {
                match_share: match_tol,
                pressure_area,
            },
        )?;
        Ok((model, j))
    });
    let (model, j) = match judged {
        Ok(x) => x,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    println!(
        "{}: {} nodes matched to {} (largest distance {:.3e}, allowed {:.3e})",
        model.name,
        j.nodes,
        results.display(),
        j.largest_distance,
        j.match_distance
    );
    for f in &j.fields {
        println!(
            "  field '{}': {} ({})",
            f.field,
            if f.found { "found" } else { "missing" },
            f.use_
        );
    }
    judge_verdicts(
        case,
        results,
        &model.name,
        &j.checks,
        &j.not_judged,
        &model.expected_failures,
        junit_out,
    )
}

/// `judge` for a 3D case (`contact_patch::harness::judge3`).
fn judge3(
    path: &Path,
    case: &contact_patch::io::scene::Case,
    results: &Path,
    match_tol: f64,
    junit_out: Option<NamedFile>,
) -> ExitCode {
    use contact_patch::harness::judge3;
    let source = path.display().to_string();
    let judged = contact_patch::run3d::build3(case, &source).and_then(|model| {
        let found = judge3::load_results3(&model, results)?;
        let j = judge3::judge3(&model, &found, match_tol)?;
        Ok((model, j))
    });
    let (model, j) = match judged {
        Ok(x) => x,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    println!(
        "{}: {} nodes matched to {} (largest distance {:.3e}, allowed {:.3e}; 3D)",
        model.name,
        j.nodes,
        results.display(),
        j.largest_distance,
        j.match_distance
    );
    println!(
        "  field 'stress': {}",
        if j.stress_field {
            "found (a uniform-stress check of the results' own nodal stress)"
        } else {
            "missing (stresses are judged from the displacement only)"
        }
    );
    judge_verdicts(
        path,
        results,
        &model.name,
        &j.checks,
        &j.not_judged,
        &model.expected_failures,
        junit_out,
    )
}

/// The judged checks and the ones not judged, printed and written as JUnit; the exit code.
fn judge_verdicts(
    case: &Path,
    results: &Path,
    name: &str,
    checks: &[contact_patch::harness::checks::CheckResult],
    not_judged: &[contact_patch::harness::judge::NotJudged],
    expected_failures: &[contact_patch::io::scene::ExpectedFailure],
    junit_out: Option<NamedFile>,
) -> ExitCode {
    for c in checks {
        println!("  {}", c.report_line());
    }
    for n in not_judged {
        println!("  not judged {}: {}", n.check, n.why);
    }
    for e in expected_failures {
        println!(
            "  note: the case expects its {} check to fail with the pair it states ({}); judged \
             here as a plain check, since the results come from another code and method",
            e.check, e.reason
        );
    }
    let mut cases = junit::check_cases(name, checks);
    cases.extend(not_judged.iter().map(|n| junit::TestCase {
        classname: name.to_string(),
        name: n.check.clone(),
        seconds: 0.0,
        verdict: junit::Verdict::Skipped {
            message: format!("not judged: {}", n.why),
        },
    }));
    let suite = junit::TestSuite {
        name: format!("{} judged on {}", case.display(), results.display()),
        seconds: 0.0,
        cases,
    };
    if !write_junit(junit_out.as_ref(), "contact-patch judge", &[suite]) {
        return ExitCode::from(2);
    }
    let failed = checks.iter().filter(|c| c.fails_the_case()).count();
    println!(
        "{} judged checks: {} pass, {failed} fail; {} not judged",
        checks.len(),
        checks.len() - failed,
        not_judged.len()
    );
    if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

/// Run `job` on one case, turning a panic (a bug, never expected) into an error so that a
/// command over many cases reports every case.
fn guarded<T>(case: &Path, job: impl FnOnce() -> contact_patch::Result<T>) -> Result<T, String> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(job)) {
        Ok(result) => result.map_err(|e| e.to_string()),
        Err(_) => Err(format!(
            "{}: internal error (a bug in contact-patch; please report it with this case)",
            case.display()
        )),
    }
}

fn table(
    paths: &[PathBuf],
    out: &Path,
    junit_path: Option<&Path>,
    baseline_paths: &[PathBuf],
    baseline_factor: f64,
    outside: Option<(&Path, &str, contact_patch::harness::judge::PressureArea)>,
    shard: Option<contact_patch::harness::shard::Shard>,
) -> ExitCode {
    let paths = if paths.is_empty() {
        vec![
            PathBuf::from("cases/patch"),
            PathBuf::from("cases/tied"),
            PathBuf::from("cases/friction"),
            PathBuf::from("cases/3d"),
        ]
    } else {
        paths.to_vec()
    };
    let folder = match ReportFolder::new(out) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let junit_out = match junit_file(junit_path) {
        Ok(f) => f,
        Err(code) => return code,
    };
    if !(baseline_factor.is_finite() && baseline_factor > 1.0) {
        eprintln!("error: --baseline-factor {baseline_factor}: must be a number above 1\n  hint: it is how many times an error may grow before it is a regression, e.g. --baseline-factor 10");
        return ExitCode::from(2);
    }
    if let Some((dir, _, _)) = outside {
        if !dir.is_dir() {
            eprintln!("error: --results {}: no such folder\n  hint: give the folder that holds <case name>.vtu (or <case name>/<body>.vtu) for each case", dir.display());
            return ExitCode::from(2);
        }
    }
    let old_cells = match baseline::load(baseline_paths) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
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
    let mut errors = Vec::new();
    let mut units = Vec::new();
    let mut unit_errors = Vec::new();
    for (unit, case) in cases.iter().enumerate() {
        if shard.is_some_and(|s| !s.owns(unit)) {
            continue;
        }
        let mut progress = |m: &str| {
            if let Some(b) = &bar {
                b.set_message(m.to_string());
            }
        };
        match guarded(case, || match outside {
            Some((dir, code, pressure_area)) => contact_patch::harness::judge::outside_cells(
                case,
                dir,
                code,
                contact_patch::harness::judge::ReadOptions {
                    pressure_area,
                    ..Default::default()
                },
            ),
            None => contact_patch::harness::run_sweep(case, &mut progress),
        }) {
            Ok(c) => {
                units.push((unit, c.clone()));
                cells.extend(c)
            }
            Err(e) => {
                match &bar {
                    Some(b) => b.println(format!("error: {e}")),
                    None => eprintln!("error: {e}"),
                }
                unit_errors.push((unit, e.clone()));
                errors.push((case.display().to_string(), e));
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
    if let Some(shard) = shard {
        use contact_patch::harness::shard::{write_part, Part};
        let part = Part::Table {
            shard,
            cases: cases.iter().map(|c| c.display().to_string()).collect(),
            ran: units,
            errors: unit_errors,
            seconds,
        };
        return match write_part(&folder, "table", shard, &part) {
            Ok(file) => {
                println!(
                    "shard {}/{}: {} cells of {} cases in {seconds:.2}s; wrote {}",
                    shard.index,
                    shard.count,
                    cells.len(),
                    cases
                        .iter()
                        .enumerate()
                        .filter(|(i, _)| shard.owns(*i))
                        .count(),
                    folder.shown(&file).display()
                );
                if errors.is_empty() {
                    ExitCode::SUCCESS
                } else {
                    eprintln!(
                        "error: {} cases of this shard could not be run",
                        errors.len()
                    );
                    ExitCode::from(2)
                }
            }
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::from(2)
            }
        };
    }
    let written = match contact_patch::harness::shard::write_tables(&folder, &cells, seconds) {
        Ok(w) => w,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let mut suites = Vec::new();
    for w in &written {
        let part = &w.cells;
        if w.catalogue == Catalogue::Patch
            && w.dimension == 2
            && contact_patch::harness::report::has_seed_cells(part)
        {
            println!("{}", contact_patch::harness::report::seed_summary(part));
        }
        suites.push(junit::TestSuite {
            name: w.title(),
            seconds: part.iter().filter_map(|c| c.time_ms).sum::<f64>() / 1e3,
            cases: part.iter().map(junit::cell_case).collect(),
        });
        print_catalogue(&folder, w);
    }
    println!(
        "{} cells {} {seconds:.2}s",
        cells.len(),
        if outside.is_some() { "judged in" } else { "in" }
    );
    if !errors.is_empty() {
        suites.push(junit::TestSuite {
            name: "cases that could not run".into(),
            seconds: 0.0,
            cases: errors
                .iter()
                .map(|(case, e)| junit::error_case(case, "sweep", e))
                .collect(),
        });
    }
    let mut code = ExitCode::SUCCESS;
    if !write_junit(junit_out.as_ref(), "contact-patch table", &suites) {
        code = ExitCode::from(2);
    }
    if !baseline_paths.is_empty() {
        let cmp = baseline::compare(&old_cells, &cells, baseline_factor);
        let shown: Vec<String> = baseline_paths
            .iter()
            .map(|p| p.display().to_string())
            .collect();
        println!(
            "\nbaseline {}: {} cells compared, {} regressions, {} improvements, {} other changes",
            shown.join(", "),
            cmp.compared,
            cmp.regressions(),
            cmp.improvements(),
            cmp.changes.len() - cmp.regressions() - cmp.improvements()
        );
        if cmp.not_compared > 0 {
            println!(
                "({} baseline cells belong to cases this run did not cover; not compared)",
                cmp.not_compared
            );
        }
        if cmp.new_not_compared > 0 {
            println!(
                "({} new cells belong to cases the baseline does not hold; not compared)",
                cmp.new_not_compared
            );
        }
        if !cmp.changes.is_empty() {
            println!("\n{}", cmp.markdown(40));
        }
        if cmp.regressions() > 0 {
            eprintln!(
                "error: {} regressions against the baseline (see the table above)",
                cmp.regressions()
            );
            if code == ExitCode::SUCCESS {
                code = ExitCode::from(1);
            }
        }
    }
    if !errors.is_empty() {
        eprintln!(
            "error: {} of {} cases could not be run (their cells are missing from the tables): {}",
            errors.len(),
            cases.len(),
            errors
                .iter()
                .map(|(c, _)| c.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        );
        code = ExitCode::from(2);
    }
    code
}

/// The most refinement levels `tied-layer` accepts, and the largest level.
/// Run the hard cases and write their report.
fn hard(paths: &[PathBuf], out: &Path) -> ExitCode {
    let folder = match ReportFolder::new(out) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let default = [PathBuf::from("cases/hard")];
    let paths = if paths.is_empty() {
        &default[..]
    } else {
        paths
    };
    let cases = match collect_cases(paths) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let bar = progress_bar(cases.len());
    let mut rows = Vec::new();
    for case in &cases {
        if let Some(b) = &bar {
            b.set_message(case.display().to_string());
        }
        let row = match guarded(case, || run_case(case, &mut |_| {})) {
            Ok(outcome) => contact_patch::harness::hard::row(&outcome),
            Err(e) => {
                contact_patch::harness::hard::error_row(&case.display().to_string(), &e.to_string())
            }
        };
        rows.push(row);
        if let Some(b) = &bar {
            b.inc(1);
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let markdown = contact_patch::harness::hard::markdown(&rows);
    let json = serde_json::to_string_pretty(&rows).expect("rows serialize") + "\n";
    let written = folder
        .write_file("hard-cases.md", &markdown)
        .and_then(|_| folder.write_file("hard-cases.json", &json));
    if let Err(e) = written {
        eprintln!("error: {e}");
        return ExitCode::from(2);
    }
    let met = rows.iter().filter(|r| r.met).count();
    for r in rows.iter().filter(|r| !r.met) {
        eprintln!(
            "FAIL {}: expected {}, got {}{}",
            r.case,
            r.expected,
            r.outcome,
            r.error
                .as_deref()
                .map(|e| format!(" ({e})"))
                .unwrap_or_default()
        );
    }
    println!(
        "{met} of {} hard cases meet their expected outcome; wrote {}",
        rows.len(),
        folder.shown("hard-cases.md").display()
    );
    if met == rows.len() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

const MAX_LEVELS: usize = 16;
const MAX_LEVEL: usize = 64;

fn profile(case: &Path, pair: &str, out: &Path) -> ExitCode {
    let result = (|| -> contact_patch::Result<()> {
        let folder = ReportFolder::new(out)?;
        let outcome = run_case(case, &mut |_| {})?;
        let profile = contact_patch::harness::profile::pressure_profile(&outcome, pair)?;
        let files = contact_patch::harness::profile::write_profile(&folder, &profile)?;
        if let Some(h) = profile.hertz {
            println!(
                "{} '{}': Hertz a = {:.6}, p0 = {:.6}; largest |p - p_Hertz| / p0 {:.3e} over |s| <= {} a, {:.3e} over all points; outermost closed point |s| = {:.6}",
                profile.case,
                profile.pair,
                h.half_width(),
                h.peak(),
                profile.deviation(contact_patch::harness::profile::INTERIOR_SHARE).unwrap_or(f64::NAN),
                contact_patch::harness::profile::INTERIOR_SHARE,
                profile.deviation(f64::INFINITY).unwrap_or(f64::NAN),
                profile.contact_extent()
            );
        }
        for f in files {
            println!("wrote {}", folder.shown(&f).display());
        }
        Ok(())
    })();
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn tied_layer(cases: &Path, levels: &[usize], out: &Path) -> ExitCode {
    if levels.is_empty()
        || levels.len() > MAX_LEVELS
        || levels.iter().any(|&k| k == 0 || k > MAX_LEVEL)
    {
        eprintln!(
            "error: --levels: give 1 to {MAX_LEVELS} refinement levels, each from 1 to {MAX_LEVEL}, e.g. 1,2,4,8\n  hint: a level multiplies every division of the layer's meshes"
        );
        return ExitCode::from(2);
    }
    let folder = match ReportFolder::new(out) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let plot_level = levels[levels.len() / 2];
    let mut studies = Vec::new();
    for element in ["q4", "q9"] {
        match contact_patch::harness::layer::study(cases, element, levels, plot_level) {
            Ok(s) => studies.push((element.to_string(), s)),
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
        }
    }
    let result = (|| -> contact_patch::Result<Vec<String>> {
        let runs_folder = folder.sub_folder("tied-layer")?;
        let mut files = Vec::new();
        for (element, study) in &studies {
            for (stem, svg) in
                contact_patch::harness::layer::plots(element, plot_level, &study.curves)
            {
                let name = format!("{stem}.svg");
                folder.write_file(&name, &svg)?;
                files.push(name);
            }
            for (name, model, solution) in &study.solved {
                let outcome = contact_patch::run::Outcome {
                    warnings: contact_patch::harness::checks::warnings(model, solution),
                    checks: contact_patch::harness::checks::evaluate(model, solution),
                    model: model.clone(),
                    solution: solution.clone(),
                };
                write_run(
                    &runs_folder.run_folder(&format!("{element}-{name}"))?,
                    &outcome,
                )?;
            }
        }
        let report = contact_patch::harness::layer::report(&studies, levels, plot_level, &files);
        folder.write_file("tied-layer.md", &report)?;
        let runs: Vec<_> = studies.iter().flat_map(|(_, s)| s.runs.clone()).collect();
        let json = serde_json::to_string_pretty(&runs).expect("runs serialize") + "\n";
        folder.write_file("tied-layer.json", &json)?;
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
            println!("wrote {}", folder.shown("tied-layer.md").display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// The studies of `contact-patch impact-report`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
enum ImpactStudy {
    /// The bar cases with every treatment and mass (reports/impact.md, .json).
    Impact,
    /// A block dropped on a foundation under dt refinement (reports/block-drop.*).
    BlockDrop,
    /// Errors against the wave solution versus wall time (reports/impact-cost.*).
    Cost,
}

/// The cases of `contact-patch cattaneo` when none are given, coarse to fine.
const CATTANEO_CASES: [&str; 4] = [
    "cases/friction-bench/cattaneo-mindlin-L1.json",
    "cases/friction-bench/cattaneo-mindlin-L2.json",
    "cases/friction-bench/cattaneo-mindlin-L3.json",
    "cases/friction-bench/cattaneo-mindlin-L4.json",
];

fn cattaneo(paths: &[PathBuf], pair: &str, out: &Path) -> ExitCode {
    use contact_patch::harness::cattaneo::{measure, write_report, REPORT_FILES};
    let paths: Vec<&Path> = if paths.is_empty() {
        CATTANEO_CASES.iter().map(Path::new).collect()
    } else {
        paths.iter().map(PathBuf::as_path).collect()
    };
    let result = (|| -> contact_patch::Result<()> {
        let folder = ReportFolder::new(out)?;
        let mut levels = Vec::new();
        for path in paths {
            let outcome = run_case(path, &mut |_| {})?;
            let level = measure(&outcome, pair)?;
            println!(
                "{}: h = {:.4}, P = {:.6}, Q = {:.6}, a = {:.5} (a_h {:.5}), c = {:.5} (c_h {:.5}), q error {:.3e}, p error {:.3e}",
                level.case,
                level.spacing,
                level.closed_form.load,
                level.closed_form.shear,
                level.half_width,
                level.measured_half_width,
                level.stick_half_width,
                level.measured_stick_half_width,
                level.traction_error,
                level.pressure_error
            );
            levels.push(level);
        }
        write_report(&folder, &levels)?;
        for f in REPORT_FILES {
            println!("wrote {}", folder.shown(f).display());
        }
        Ok(())
    })();
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// A report command whose `count` cells run under a progress bar: `run` (told each cell's name)
/// gives the report's Markdown and JSON, written as `<stem>.md` and `<stem>.json` into `out`.
fn cell_report(
    out: &Path,
    count: usize,
    stem: &str,
    run: impl FnOnce(&mut dyn FnMut(&str)) -> contact_patch::Result<(String, String)>,
) -> ExitCode {
    let folder = match ReportFolder::new(out) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let (md, json) = (format!("{stem}.md"), format!("{stem}.json"));
    let bar = progress_bar(count);
    let result = run(&mut |name| {
        if let Some(b) = &bar {
            b.set_message(name.to_string());
            b.inc(1);
        }
    })
    .and_then(|(report, data)| {
        folder.write_file(&md, &report)?;
        folder.write_file(&json, &data)
    });
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    match result {
        Ok(()) => {
            println!(
                "wrote {} and {}",
                folder.shown(&md).display(),
                folder.shown(&json).display()
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// `contact-patch finite-patch`: the contact patch test at finite strain.
fn finite_patch(out: &Path) -> ExitCode {
    use contact_patch::harness::finite_patch;
    cell_report(
        out,
        finite_patch::cell_count(),
        "finite-patch-table",
        |progress| {
            let cells = finite_patch::run(Path::new("."), progress)?;
            let json = serde_json::to_string_pretty(&cells).expect("cells serialize") + "\n";
            Ok((finite_patch::report(&cells), json))
        },
    )
}

/// `contact-patch friction-convergence`: the residual histories of the friction tangents.
fn friction_convergence(out: &Path, baseline: Option<&Path>) -> ExitCode {
    let folder = match ReportFolder::new(out) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let result = (|| -> contact_patch::Result<()> {
        use contact_patch::harness::friction_convergence as study;
        let runs = study::study(Path::new("."))?;
        // the baseline's case files and outputs: a scratch folder of this run, removed after
        let work = folder.path().join(format!(
            ".friction-convergence-baseline-{}",
            std::process::id()
        ));
        // only a folder this run creates is removed: it is created here, at once, and one
        // that is there already is refused
        let created = baseline.is_some();
        if created {
            std::fs::create_dir(&work).map_err(|e| {
                if e.kind() == std::io::ErrorKind::AlreadyExists {
                    contact_patch::error::Error::invalid(
                        work.display(),
                        "--baseline",
                        "the scratch folder for the baseline's runs exists already",
                        "remove it, or choose another --out folder",
                    )
                } else {
                    contact_patch::error::Error::io(
                        work.display(),
                        "creating the scratch folder",
                        e,
                    )
                }
            })?;
        }
        let steps = study::step_iterations(Path::new("."), baseline, &work);
        if created {
            let _ = std::fs::remove_dir_all(&work);
        }
        let steps = steps?;
        let shown = baseline.map(|b| b.display().to_string());
        folder.write_file(
            "friction-convergence.md",
            &(study::report(&runs) + &study::step_iterations_report(&steps, shown.as_deref())),
        )?;
        let json = serde_json::to_string_pretty(
            &serde_json::json!({"tangents": runs, "iterations_per_step": steps}),
        )
        .expect("runs serialize")
            + "\n";
        folder.write_file("friction-convergence.json", &json)
    })();
    match result {
        Ok(()) => {
            println!(
                "wrote {} and {}",
                folder.shown("friction-convergence.md").display(),
                folder.shown("friction-convergence.json").display()
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// Write `files` (name, text) into the report folder `out`, printing what was written; exit 2
/// with the message on a bad folder or a failed study.
fn write_study(
    out: &Path,
    files: impl FnOnce() -> contact_patch::Result<Vec<(String, String)>>,
) -> ExitCode {
    let folder = match ReportFolder::new(out) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let result = files().and_then(|files| {
        for (name, text) in &files {
            folder.write_file(name, text)?;
        }
        Ok(files)
    });
    match result {
        Ok(files) => {
            for (name, _) in &files {
                println!("wrote {}", folder.shown(name).display());
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn hertz_finite(out: &Path) -> ExitCode {
    use contact_patch::harness::hertz_finite;
    write_study(out, || {
        let study = hertz_finite::study()?;
        let mut files = vec![
            ("hertz-finite.md".to_string(), hertz_finite::report(&study)),
            (
                "hertz-finite.json".to_string(),
                serde_json::to_string_pretty(&study).expect("the study serializes") + "\n",
            ),
        ];
        files.extend(hertz_finite::plots(&study));
        Ok(files)
    })
}

fn hertz_3d(out: &Path) -> ExitCode {
    use contact_patch::harness::hertz3d;
    write_study(out, || {
        let study = hertz3d::study(&hertz3d::REPORT_SIZES)?;
        let mut files = vec![
            ("hertz-3d.md".to_string(), hertz3d::report(&study)),
            (
                "hertz-3d.json".to_string(),
                serde_json::to_string_pretty(&study).expect("the study serializes") + "\n",
            ),
        ];
        files.extend(hertz3d::plots(&study));
        Ok(files)
    })
}

fn finite_sliding(out: &Path) -> ExitCode {
    use contact_patch::harness::finite_sliding;
    write_study(out, || {
        let runs = finite_sliding::study();
        let mut files = vec![
            (
                "finite-sliding.md".to_string(),
                finite_sliding::report(&runs),
            ),
            (
                "finite-sliding.json".to_string(),
                serde_json::to_string_pretty(&runs).expect("the runs serialize") + "\n",
            ),
        ];
        files.extend(finite_sliding::plots(&runs));
        Ok(files)
    })
}

fn ironing(out: &Path) -> ExitCode {
    use contact_patch::harness::ironing;
    write_study(out, || {
        let studies = ironing::study();
        let mut files = vec![
            ("ironing.md".to_string(), ironing::report(&studies)),
            (
                "ironing.json".to_string(),
                serde_json::to_string_pretty(&studies).expect("the study serializes") + "\n",
            ),
        ];
        files.extend(ironing::plots(&studies));
        Ok(files)
    })
}

/// The cases of `contact-patch impact-report` when none are given.
const IMPACT_CASES: [&str; 3] = [
    "cases/dynamics/bar-on-rigid-wall.json",
    "cases/dynamics/two-identical-bars.json",
    "cases/dynamics/two-bars-different-impedance.json",
];
/// The cases of `impact-report --study block-drop` when none are given.
const BLOCK_DROP_CASES: [&str; 3] = [
    "cases/dynamics/block-drop-node-to-surface.json",
    "cases/dynamics/block-drop-mortar.json",
    "cases/dynamics/block-drop-rigid.json",
];
/// The case of `impact-report --study cost` when none is given.
const COST_CASES: [&str; 1] = ["cases/dynamics/bar-on-rigid-wall.json"];

fn impact_report(paths: &[PathBuf], out: &Path, study: ImpactStudy) -> ExitCode {
    use contact_patch::harness::{block_drop, impact, impact_cost};
    let folder = match ReportFolder::new(out) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let defaults: &[&str] = match study {
        ImpactStudy::Impact => &IMPACT_CASES,
        ImpactStudy::BlockDrop => &BLOCK_DROP_CASES,
        ImpactStudy::Cost => &COST_CASES,
    };
    let paths: Vec<&Path> = if paths.is_empty() {
        defaults.iter().map(Path::new).collect()
    } else {
        paths.iter().map(PathBuf::as_path).collect()
    };
    let result = (|| -> contact_patch::Result<Vec<String>> {
        let (stem, md, json, plots) = match study {
            ImpactStudy::Impact => {
                let m = impact::study(&paths)?;
                (
                    "impact",
                    impact::report(&m),
                    serde_json::to_string_pretty(&m),
                    Vec::new(),
                )
            }
            ImpactStudy::BlockDrop => {
                let m = block_drop::study(&paths)?;
                let plots = block_drop::plots(&m);
                (
                    "block-drop",
                    block_drop::report(&m),
                    serde_json::to_string_pretty(&m),
                    plots,
                )
            }
            ImpactStudy::Cost => {
                let m = impact_cost::study(&paths)?;
                let plots = impact_cost::plots(&m);
                (
                    "impact-cost",
                    impact_cost::report(&m),
                    serde_json::to_string_pretty(&m),
                    plots,
                )
            }
        };
        let mut written = vec![format!("{stem}.md"), format!("{stem}.json")];
        folder.write_file(&written[0], &md)?;
        folder.write_file(&written[1], &(json.expect("measures serialize") + "\n"))?;
        for (name, svg) in plots {
            let file = format!("{name}.svg");
            folder.write_file(&file, &svg)?;
            written.push(file);
        }
        Ok(written)
    })();
    match result {
        Ok(written) => {
            let shown: Vec<String> = written
                .iter()
                .map(|f| folder.shown(f).display().to_string())
                .collect();
            println!("wrote {}", shown.join(", "));
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn report_page(reports: &Path) -> ExitCode {
    let result = ReportFolder::new(reports).and_then(|f| {
        let page = contact_patch::harness::index_page::write(&f)?;
        Ok((f, page))
    });
    match result {
        Ok((folder, page)) => {
            println!(
                "wrote {}: {} tables, {} images, {} links; {} reports not generated yet{}",
                folder
                    .shown(contact_patch::harness::index_page::INDEX_FILE)
                    .display(),
                page.tables,
                page.images,
                page.targets.len(),
                page.missing.len(),
                if page.missing.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", page.missing.join(", "))
                }
            );
            for link in &page.unlinked {
                println!(
                    "  a report links to {link}, which is not a file of the folder: shown as text"
                );
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn print_catalogue(folder: &ReportFolder, w: &contact_patch::harness::shard::Written) {
    let part = &w.cells;
    println!(
        "{}: {} cells ({} pass, {} fail, {} n/a); wrote {} and {}",
        w.title(),
        part.len(),
        part.iter().filter(|c| c.verdict == "pass").count(),
        part.iter().filter(|c| c.verdict == "fail").count(),
        part.iter().filter(|c| c.verdict == "n/a").count(),
        folder.shown(&w.md).display(),
        folder.shown(&w.json).display()
    );
}

fn run_study(
    path: &Path,
    out: &Path,
    shard: Option<contact_patch::harness::shard::Shard>,
) -> ExitCode {
    use contact_patch::harness::{shard as shards, study};
    let result = (|| -> contact_patch::Result<()> {
        let folder = ReportFolder::new(out)?;
        let s = study::load_study(path)?;
        let total = s.cell_count();
        let todo: Vec<usize> = (0..total)
            .filter(|&i| shard.is_none_or(|k| k.owns(i)))
            .collect();
        let bar = progress_bar(todo.len());
        let mut cells = Vec::new();
        for &i in &todo {
            if let Some(b) = &bar {
                b.set_message(s.cell_labels(i).join(" "));
            }
            let cell = s.run_cell(i);
            if let Some(e) = &cell.error {
                let line = format!("cell {i} ({}): {e}", cell.labels.join(", "));
                match &bar {
                    Some(b) => b.println(line),
                    None => eprintln!("{line}"),
                }
            }
            cells.push(cell);
            if let Some(b) = &bar {
                b.inc(1);
            }
        }
        if let Some(b) = bar {
            b.finish_and_clear();
        }
        let failed = cells.iter().filter(|c| c.error.is_some()).count();
        // the reports are written either way; a run in which no cell could run failed
        let none_ran = || {
            contact_patch::error::Error::invalid(
                path.display(),
                "cells",
                format!(
                    "none of the {} cells could run (each says why above)",
                    todo.len()
                ),
                "fix the base case or the axis values named above",
            )
        };
        match shard {
            Some(k) => {
                let part = shards::Part::Study {
                    shard: k,
                    source: s.source.clone(),
                    study: s.spec.clone(),
                    total,
                    cells,
                };
                let file = shards::write_part(&folder, &s.spec.name, k, &part)?;
                println!(
                    "shard {}/{}: {} of {total} cells ({failed} could not run); wrote {}",
                    k.index,
                    k.count,
                    todo.len(),
                    folder.shown(&file).display()
                );
                if failed > 0 && failed == todo.len() {
                    return Err(none_ran());
                }
            }
            None => {
                let command = format!("contact-patch study {}", path.display());
                let files = study::write_reports(&folder, &s, &cells, &command)?;
                println!("{total} cells ({failed} could not run)");
                for f in files {
                    println!("wrote {}", folder.shown(&f).display());
                }
                if failed > 0 && failed == todo.len() {
                    return Err(none_ran());
                }
            }
        }
        Ok(())
    })();
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn merge(parts: &[PathBuf], out: &Path) -> ExitCode {
    use contact_patch::harness::{shard as shards, study};
    let result = (|| -> contact_patch::Result<()> {
        let folder = ReportFolder::new(out)?;
        match shards::merge(shards::read_parts(parts)?)? {
            shards::Merged::Study {
                source,
                study: spec,
                cells,
            } => {
                let s = study::from_parts(*spec, source, "merge")?;
                let command = format!("contact-patch merge ({} shards)", parts.len());
                for f in study::write_reports(&folder, &s, &cells, &command)? {
                    println!("wrote {}", folder.shown(&f).display());
                }
            }
            shards::Merged::Table {
                cells,
                seconds,
                errors,
            } => {
                for w in shards::write_tables(&folder, &cells, seconds)? {
                    print_catalogue(&folder, &w);
                }
                for (case, e) in &errors {
                    eprintln!("error: {case}: {e}");
                }
                if !errors.is_empty() {
                    return Err(contact_patch::error::Error::invalid(
                        "merge",
                        "PARTS",
                        format!("{} cases could not be run in their shards (their cells are missing from the tables)", errors.len()),
                        "fix the cases named above and rerun their shards",
                    ));
                }
            }
        }
        Ok(())
    })();
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
