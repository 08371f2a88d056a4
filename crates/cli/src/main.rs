//! `features`: the command-line front end of the STEP-native, feature-based path planner.
//!
//! Every failure is reported as exactly one line on stderr, `features: <path>: <cause>`, with
//! exit code 2. A panic (a bug) is caught and reported the same way with exit code 3.

mod extract;
mod inspect;
mod inspect_mesh;
mod memory;
mod mesh;
mod outputs;
mod plan;
mod preview;
mod profiles;
mod simulation;
mod staged;

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
    after_help = "Examples:\n  features plan part.step --machine delta5 -o out/\n  \
                  features plan part.step --process my_process.toml -o part.gcode\n  \
                  features extract part.step\n  \
                  features extract part.step --json --export features/\n  \
                  features inspect part.step --json\n  \
                  features mesh part.step -o part.stl --tolerance 0.02\n  \
                  features profiles show delta5 > my.toml\n  \
                  features preview part.step -o part.html\n\n\
                  Errors are one line on stderr, `features: <file>: <cause>`, exit code 2; \
                  warnings are lines `features: <file>: warning: ...`."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Read a STEP file and report each solid: volume, area, topology, surface kinds, checks (or a
    /// mesh file: each object's volume, area, box, open and non-manifold edges).
    #[command(
        after_help = "Examples:\n  features inspect part.step\n  features inspect part.step --json"
    )]
    Inspect(InspectArgs),
    /// Triangulate every solid of a STEP file into one STL or OBJ file.
    #[command(
        after_help = "Examples:\n  features mesh part.step -o part.stl\n  features mesh part.step -o part.obj --tolerance 0.01"
    )]
    Mesh(MeshArgs),
    /// Recognise the AM features a part is built from: concave loops, splitting, dependency order.
    #[command(
        after_help = "Examples:\n  features extract part.step                 the feature tree\n  \
                            features extract part.step --json          features.extract/1 JSON\n  \
                            features extract part.step --export out/   each feature as its own STEP and STL"
    )]
    Extract(ExtractArgs),
    /// Plan layers and paths for every feature and write the machine program.
    #[command(
        after_help = "Examples:\n  features plan part.step                              Marlin G-code, toolpath.csv, plan.json in part_plan/\n  \
                            features plan part.step -o out/                      the same in out/ (an earlier plan there is replaced)\n  \
                            features plan part.step --machine delta5 -o part.gcode   5-axis program part.gcode, beside it part.toolpath.csv, part.plan.json\n  \
                            features plan part.step --machine kuka -o cell/          KRL modules for a KUKA cell\n  \
                            features plan part.step --process profiles/process.toml --strict -o out/"
    )]
    Plan(PlanArgs),
    /// Write a web page that shows the features a part is built from (WebGL, works offline).
    #[command(after_help = "Examples:\n  features preview part.step -o part.html")]
    Preview(PreviewArgs),
    /// List the built-in machine and process profiles, or print one as TOML to copy and edit.
    #[command(
        after_help = "Examples:\n  features profiles\n  features profiles show delta5 > my.toml\n  \
                            features plan part.step --machine-profile my.toml -o out/"
    )]
    Profiles(ProfilesArgs),
}

/// Arguments of `features preview`.
#[derive(Debug, Args)]
pub struct PreviewArgs {
    /// STEP file to read, or a mesh (.stl, .3mf, .obj).
    #[arg(value_name = "PART.step")]
    pub part: PathBuf,
    /// The page to write, a self-contained .html file (no network: opens offline)
    #[arg(short, long, value_name = "FILE.html")]
    pub output: PathBuf,
}

/// Arguments of `features profiles`.
#[derive(Debug, Args)]
pub struct ProfilesArgs {
    #[command(subcommand)]
    pub action: Option<ProfilesAction>,
}

/// What `features profiles` does beyond listing.
#[derive(Debug, Subcommand)]
pub enum ProfilesAction {
    /// Print a built-in profile (marlin, delta5, kuka or process) as TOML, with its comments.
    Show {
        /// The profile's name.
        name: String,
    },
}

/// Arguments of `features plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// STEP file to read, or a mesh (.stl, .3mf, .obj): each closed body one mesh_two5d feature
    /// in planar layers along +Z.
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
    /// Output folder, or the program file [default: ./<part stem>_plan/]
    ///
    /// A folder (created if missing) gets toolpath.csv, plan.json and the machine program
    /// (program.gcode, or the KRL modules named by the part). A path ending in .gcode (Marlin,
    /// delta5) or .src (KUKA) is the program file itself, and the other outputs go beside it
    /// under its stem: `-o box.gcode` writes box.gcode, box.toolpath.csv and box.plan.json. An
    /// earlier plan there is replaced (its files the new plan does not write are removed); a
    /// place that holds files no plan wrote is refused unless --force. `-o -` is refused.
    #[arg(short, long, value_name = "DIR|FILE.gcode|FILE.src")]
    pub output: Option<PathBuf>,
    /// Write the plan where files no plan wrote are (beside an earlier plan, or of the plan's
    /// names): those of the new plan's names are replaced, the others left as they are
    #[arg(long)]
    pub force: bool,
    /// Treat every warning as an error: exit 2 and write nothing when the plan has one
    #[arg(long)]
    pub strict: bool,
    /// Write a KUKA program even when points are out of the arm's reach (an error otherwise)
    #[arg(long)]
    pub allow_unreachable: bool,
    /// Override one setting, KEY=VALUE (repeatable): a process key (`uniform_layer_height=0.1`
    /// for [defaults], `features.2.perimeters=3`, `orientation.cone_angle_deg=20`) or a machine
    /// key after `machine.` (`machine.nozzle_temperature=215`)
    #[arg(long, value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Stand the part on the planar face with STEP #id ID: the part is turned so that face's
    /// outward normal points down [default: as modelled, -Z down]
    #[arg(long, value_name = "ID", conflicts_with = "orient")]
    pub base_face: Option<u64>,
    /// `auto`: stand the part on the planar face that leaves the least unsupported area, then
    /// the fewest features growing below the horizon (ties: the most planar area down);
    /// `modelled`: as the file has it
    #[arg(long, value_name = "auto|modelled", value_parser = ["auto", "modelled"])]
    pub orient: Option<String>,
    /// Without --base-face or --orient: the most seconds spent finding a placement that plans
    /// (the plan as modelled included); past it no other placement is tried, the one being
    /// planned is given up, and the refusal lists what was tried and what was not. `inf`: no
    /// limit
    #[arg(long, value_name = "SECONDS", default_value_t = ::plan::retry::DEFAULT_TIME_LIMIT_S, value_parser = seconds)]
    pub placement_time_limit: f64,
    /// Write the plan even when its self-check fails (a feature with no layer, or extruded
    /// volume more than 3 % from volume x fill) or some layers are unsupported (reaching past
    /// the layer below by more than layer height x tan(overhang_angle_deg)): the failures
    /// become warnings and plan.json says `"complete": false`
    #[arg(long)]
    pub keep_going: bool,
    /// Write the plan even when the print head meets material built before a move, or the
    /// table (plan.json counts the colliding moves per feature): the lines become warnings
    #[arg(long)]
    pub allow_collisions: bool,
}

/// A time limit in seconds: a number from 0, or `inf`.
fn seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v >= 0.0 => Ok(v),
        _ => Err(format!("{s}: seconds from 0, or inf for no limit")),
    }
}

/// Arguments of `features extract`.
#[derive(Debug, Args)]
pub struct ExtractArgs {
    /// STEP file to read, or a mesh (.stl, .3mf, .obj).
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
    /// STEP file to read (AP203, AP214 or AP242; any length unit, reported in mm), or a mesh
    /// (.stl, .3mf, .obj: volume, area, box, open and non-manifold edges).
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
    if std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        // The elapsed time keeps running through long stages.
        bar.enable_steady_tick(std::time::Duration::from_millis(250));
    } else {
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
        Command::Profiles(a) => profiles::run(a),
        Command::Preview(a) => preview::run(a),
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
        Command::Profiles(_) => "profiles".to_string(),
        Command::Preview(a) => a.part.display().to_string(),
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
