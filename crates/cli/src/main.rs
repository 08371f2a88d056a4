//! `features`: the command-line front end of the STEP-native, feature-based path planner.
//!
//! Every failure is reported as exactly one line on stderr, `features: <path>: <cause>`, with
//! exit code 2. A panic (a bug) is caught and reported the same way with exit code 3.

mod extract;
mod inspect;
mod mesh;
mod plan;
mod settings;

use clap::{Args, Parser, Subcommand};
use std::io::Write;
use std::panic::{self, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// STEP-native, feature-based path planning for multi-axis additive manufacturing.
#[derive(Debug, Parser)]
#[command(
    name = "features",
    version,
    after_help = "Examples:\n  features inspect part.step\n  features inspect part.step --json\n  \
                  features mesh part.step -o part.stl --tolerance 0.02\n  \
                  features extract part.step --json --export features/\n\n\
                  Errors are one line on stderr, `features: <file>: <cause>`, exit code 2."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Read a STEP file and report each solid: volume, area, topology, surface kinds, checks.
    Inspect(InspectArgs),
    /// Triangulate every solid of a STEP file into one STL or OBJ file.
    Mesh(MeshArgs),
    /// Recognise the AM features a part is built from: concave loops, splitting, dependency order.
    Extract(ExtractArgs),
    /// Plan layers and paths for every feature and write the machine program.
    Plan(PlanArgs),
}

/// Arguments of `features plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// STEP file to read.
    #[arg(value_name = "PART.step")]
    pub part: PathBuf,
    /// Process file (TOML): `[defaults]` layer parameters and `[features.<id>]` overrides
    /// [default: 0.2 mm layers, contour_zigzag, 2 perimeters, solid fill; see profiles/process.toml]
    #[arg(long, value_name = "FILE")]
    pub process: Option<PathBuf>,
    /// Built-in machine: marlin, delta5 or kuka [default: marlin]
    #[arg(long, value_name = "NAME", conflicts_with = "machine_profile")]
    pub machine: Option<String>,
    /// Machine profile (TOML) instead of a built-in one (see profiles/*.toml)
    #[arg(long, value_name = "FILE")]
    pub machine_profile: Option<PathBuf>,
    /// Output directory for toolpath.csv, plan.json and the machine program [required]
    #[arg(short, long, value_name = "DIR")]
    pub output: PathBuf,
    /// Write the plan even when its self-check fails (a feature with no layer, or extruded
    /// volume more than 3 % from volume x fill): the failures become warnings and plan.json
    /// says `"complete": false`
    #[arg(long)]
    pub keep_going: bool,
    /// Write the plan even when the print head meets material built before a move, or the
    /// table (plan.json counts the colliding moves per feature): the lines become warnings
    #[arg(long)]
    pub allow_collisions: bool,
}

/// Arguments of `features extract`.
#[derive(Debug, Args)]
pub struct ExtractArgs {
    /// STEP file to read.
    #[arg(value_name = "PART.step")]
    pub part: PathBuf,
    /// Print the feature tree as one JSON object (schema `features.extract/1`) [default: text].
    #[arg(long)]
    pub json: bool,
    /// Write each feature as its own closed solid, `feature_<id>.step` and `.stl`, into DIR
    ///
    /// The directory is created if missing. Each file is written under a temporary name and
    /// renamed on success.
    #[arg(long, value_name = "DIR")]
    pub export: Option<PathBuf>,
}

/// Arguments of `features inspect`.
#[derive(Debug, Args)]
pub struct InspectArgs {
    /// STEP file to read (AP203, AP214 or AP242; any length unit, reported in mm).
    #[arg(value_name = "PART.step")]
    pub part: PathBuf,
    /// Print the report as one JSON object instead of text [default: text].
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `features mesh`.
#[derive(Debug, Args)]
pub struct MeshArgs {
    /// STEP file to read.
    #[arg(value_name = "PART.step")]
    pub part: PathBuf,
    /// Output file: `.stl` writes binary STL, `.obj` Wavefront OBJ [required]
    ///
    /// The extension picks the format (`.stl`: binary STL; `.obj`: Wavefront OBJ, one `o` group
    /// per solid). All solids of the file go into it, in mm. It is written to a temporary file
    /// beside it and renamed only on success, so a failure leaves no partial file.
    #[arg(short, long, value_name = "OUT.stl|OUT.obj")]
    pub output: PathBuf,
    /// Chord tolerance, mm: largest gap between a triangle and the exact surface
    ///
    /// The largest distance between a triangle and the exact surface it stands for, in mm. The
    /// angle between neighbouring points' normals is also kept under 15°.
    #[arg(long, value_name = "MM", default_value_t = 0.05, value_parser = parse_tolerance)]
    pub tolerance: f64,
}

fn parse_tolerance(s: &str) -> Result<f64, String> {
    let t: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if t.is_finite() && t > 0.0 {
        Ok(t)
    } else {
        Err(format!("`{s}` must be a positive number of mm"))
    }
}

/// A failure: the file it concerns and why. Displayed as one line.
#[derive(Debug)]
pub struct Failure {
    /// The file (as given on the command line) the failure is about.
    pub path: String,
    /// The cause, one line.
    pub cause: String,
}

impl Failure {
    /// A failure about `path`.
    pub fn new(path: &Path, cause: impl std::fmt::Display) -> Self {
        Failure {
            path: path.display().to_string(),
            cause: cause.to_string(),
        }
    }
}

/// A progress bar on stderr, hidden when stderr is not a terminal.
fn progress_bar(template: &str) -> indicatif::ProgressBar {
    let bar =
        indicatif::ProgressBar::with_draw_target(None, indicatif::ProgressDrawTarget::stderr());
    if !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    bar.set_style(
        indicatif::ProgressStyle::with_template(template)
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar
}

/// Collapses line breaks so that a message is guaranteed to be one line.
fn one_line(s: &str) -> String {
    let parts: Vec<&str> = s.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    if parts.is_empty() {
        "unknown error".to_string()
    } else {
        parts.join("; ")
    }
}

/// Writes `text` to stdout. A closed pipe (`features inspect x | head`) is not an error.
pub fn emit(text: &str) -> Result<(), Failure> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err(Failure {
            path: "<stdout>".into(),
            cause: format!("cannot write: {e}"),
        }),
    }
}

fn run(cmd: &Command) -> Result<(), Failure> {
    // Lets the end-to-end tests prove that a panic is caught and reported on one line. Debug
    // builds only: a release binary carries no hidden trigger.
    #[cfg(debug_assertions)]
    if std::env::var_os("FEATURES_TEST_PANIC").is_some() {
        panic!("panic injected by FEATURES_TEST_PANIC\n(second line)");
    }
    match cmd {
        Command::Inspect(a) => inspect::run(a),
        Command::Mesh(a) => mesh::run(a),
        Command::Extract(a) => extract::run(a),
        Command::Plan(a) => plan::run(a),
    }
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "panic with a non-text payload".to_string()
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let path = match &cli.command {
        Command::Inspect(a) => a.part.display().to_string(),
        Command::Mesh(a) => a.part.display().to_string(),
        Command::Extract(a) => a.part.display().to_string(),
        Command::Plan(a) => a.part.display().to_string(),
    };
    // The panic is reported below, on one line; the default hook would add a second.
    panic::set_hook(Box::new(|_| {}));
    let (path, cause, code) = match panic::catch_unwind(AssertUnwindSafe(|| run(&cli.command))) {
        Ok(Ok(())) => return ExitCode::SUCCESS,
        Ok(Err(f)) => (f.path, f.cause, 2),
        Err(payload) => (
            path,
            format!("internal error: {}", panic_message(payload.as_ref())),
            3,
        ),
    };
    let line = format!("features: {}: {}\n", one_line(&path), one_line(&cause));
    let _ = std::io::stderr().lock().write_all(line.as_bytes());
    ExitCode::from(code)
}
