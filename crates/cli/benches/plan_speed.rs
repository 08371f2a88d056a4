//! Speed of `features plan` against PrusaSlicer's planar slicing of the same part (issue #16:
//! "features plan faster than the planar slicer it replaces").
//!
//! For each part, in one session:
//!
//! - the part is meshed once, `features mesh PART.step -o PART.stl --tolerance 0.01` (not timed);
//! - then, `--runs N` times (default 3, or `$PLAN_SPEED_RUNS`), alternating within the part:
//!   - ours: the `features` binary of this build as a child process,
//!     `features plan PART.step --machine M -o DIR` with the built-in process defaults (0.2 mm
//!     layers, contour_zigzag with 2 perimeters, solid fill) and the built-in machine profile,
//!     whose bead width is 0.45 mm already (`profiles/{delta5,marlin}.toml`; nothing else is set).
//!     Timed: the wall time from spawning the child to reaping it, i.e. reading the STEP file,
//!     extracting features, planning, posting and writing `toolpath.csv`, `plan.json`, the
//!     machine program (and `kinematic_error.svg` for delta5). Its peak RSS is the child's own
//!     `ru_maxrss` from `wait4` (per run, not summed over children). A run that does not exit 0
//!     is reported with its error output.
//!   - PrusaSlicer: `prusa-slicer --export-gcode` of that STL with the same settings: 0.2 mm
//!     layers (first layer too), every extrusion width 0.45 mm, 2 classic perimeters, 100 %
//!     rectilinear fill (so every layer is solid), automatic supports on (`--support-material`),
//!     0.4 mm nozzle, 1.75 mm filament, 210 / 60 °C as in our profiles, no skirt or brim, the
//!     part centred on the bed (`--center 100,100`); the argument list is the one `stairstep`
//!     uses (`common/prusa.rs`). Timed: the wall time of the process (reading the STL, slicing,
//!     writing the G-code). A run counts only if it exits 0 and its G-code has G1 moves.
//! - Printed: per part the medians of both times, their ratio (ours / PrusaSlicer: below 1 is
//!   faster) and our largest peak RSS over the runs; then every run's figures, with our CPU
//!   utilisation (the child's user and system time over its wall time × the cores).
//! - Then the stage split: each part planned once more in this process as `features plan
//!   --allow-collisions` plans it (the placement search included), its stages timed by the
//!   plan's progress reports: reading, extraction, the features' layers, smoothing, the print
//!   head, the post; the time the refused placements took; the share of the plan after the
//!   features; and the CPU utilisation of the whole and of the features' layers (issue 35:
//!   "a part of N features uses both cores from the first feature to the last").
//!
//! Differences in what each side does are left as they are: ours starts from the STEP file and
//! writes three or four files, PrusaSlicer starts from the STL mesh and writes one G-code file;
//! both processes use the threads they want.
//!
//! `cargo bench -p features-cli --bench plan_speed [-- [--runs N] PART[:MACHINE] ...]`: a PART is
//! a fixture name or a `.step` path (relative to the workspace if not found where cargo runs it,
//! e.g. `fixtures/big/block_5l.step`); the machine is `delta5`, `marlin` or `kuka` (default: the
//! table below, else `delta5`). Default parts: impeller, fan, sphere_boss (delta5) and
//! plate_boss_boss (marlin). Without `prusa-slicer` on the PATH (or `$PRUSA_SLICER`) ours alone
//! is measured, and the output says so. Files are left in `target/tmp/plan_speed/`.
//!
//! Timings are wall times on whatever else the machine is doing: on a shared machine they are
//! noisy, which the medians and the alternation only soften.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

#[path = "common/prusa.rs"]
mod prusa;

/// The default parts and the machine each is planned for.
const PARTS: [(&str, &str); 4] = [
    ("impeller", "delta5"),
    ("fan", "delta5"),
    ("sphere_boss", "delta5"),
    ("plate_boss_boss", "marlin"),
];

/// Layer height and bead width of both, mm (our built-in defaults).
const H: f64 = 0.2;
const W: f64 = 0.45;

/// One run of ours.
struct OursRun {
    seconds: f64,
    /// Peak resident set size of the child, MB (MiB).
    rss_mb: f64,
    /// CPU seconds of the child, every thread's, user and system.
    cpu: f64,
    /// `None` when it exited 0, else why not.
    error: Option<String>,
}

/// One part's figures.
struct PartResult {
    name: String,
    machine: String,
    ours: Vec<OursRun>,
    /// PrusaSlicer's wall times, or why a run gave none.
    prusa: Vec<Result<f64, String>>,
}

/// Runs `cmd` as a child with its output into `log`, waits for that one child with `wait4` and
/// returns its wall time, its peak RSS in KiB, its CPU seconds (user and system, every thread)
/// and its exit code (or the signal that ended it).
#[allow(clippy::type_complexity)]
fn run_measured(
    cmd: &mut Command,
    log: &Path,
) -> Result<(f64, i64, f64, Result<i32, String>), String> {
    let out = std::fs::File::create(log).map_err(|e| format!("{}: {e}", log.display()))?;
    let err = out
        .try_clone()
        .map_err(|e| format!("{}: {e}", log.display()))?;
    cmd.stdin(Stdio::null())
        .stdout(Stdio::from(out))
        .stderr(Stdio::from(err));
    let t = Instant::now();
    let child = cmd.spawn().map_err(|e| format!("spawning: {e}"))?;
    let pid = child.id() as libc::pid_t;
    let mut status: libc::c_int = 0;
    // SAFETY: `rusage` is plain old data, zeroes are a valid value, and `wait4` only writes to it.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    loop {
        // SAFETY: `pid` is our own child, not yet reaped (`child` is never waited on through
        // std); `status` and `usage` are valid for writes.
        let r = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
        if r == pid {
            break;
        }
        let e = std::io::Error::last_os_error();
        if e.kind() != std::io::ErrorKind::Interrupted {
            return Err(format!("wait4: {e}"));
        }
    }
    let seconds = t.elapsed().as_secs_f64();
    drop(child);
    let code = if libc::WIFEXITED(status) {
        Ok(libc::WEXITSTATUS(status))
    } else if libc::WIFSIGNALED(status) {
        Err(format!("killed by signal {}", libc::WTERMSIG(status)))
    } else {
        Err(format!("wait status {status:#x}"))
    };
    let cpu = timeval_s(usage.ru_utime) + timeval_s(usage.ru_stime);
    // Linux reports ru_maxrss in KiB.
    Ok((seconds, usage.ru_maxrss, cpu, code))
}

/// The last lines of a log, joined.
fn tail(log: &Path, n: usize) -> String {
    let text = std::fs::read_to_string(log).unwrap_or_default();
    let lines: Vec<&str> = text.lines().rev().take(n).collect();
    lines.into_iter().rev().collect::<Vec<_>>().join(" / ")
}

fn run_ours(exe: &Path, step: &Path, machine: &str, dir: &Path) -> OursRun {
    let out = dir.join("ours");
    let _ = std::fs::remove_dir_all(&out);
    let log = dir.join("ours.log");
    let mut cmd = Command::new(exe);
    cmd.arg("plan")
        .arg(step)
        .args(["--machine", machine, "--allow-collisions"])
        .arg("-o")
        .arg(&out);
    match run_measured(&mut cmd, &log) {
        Ok((seconds, rss_kib, cpu, code)) => OursRun {
            seconds,
            rss_mb: rss_kib as f64 / 1024.0,
            cpu,
            error: match code {
                Ok(0) => None,
                Ok(c) => Some(format!("exited with {c}: {}", tail(&log, 3))),
                Err(e) => Some(format!("{e}: {}", tail(&log, 3))),
            },
        },
        Err(e) => OursRun {
            seconds: f64::NAN,
            rss_mb: f64::NAN,
            cpu: f64::NAN,
            error: Some(e),
        },
    }
}

/// One PrusaSlicer run of `stl` into `gcode`, which must have G1 moves to count.
fn run_prusa(stl: &Path, gcode: &Path) -> prusa::Run {
    let settings = prusa::Settings {
        layer: H,
        width: W,
        filament: 1.75,
        center: (100.0, 100.0),
        supports: true,
    };
    let extra: Vec<String> = ["--temperature", "210", "--bed-temperature", "60"]
        .map(String::from)
        .to_vec();
    match prusa::slice(stl, gcode, &settings, &extra) {
        prusa::Run::Done(s) => match std::fs::read_to_string(gcode) {
            Ok(text) if text.lines().any(|l| l.starts_with("G1 ")) => prusa::Run::Done(s),
            Ok(_) => prusa::Run::Failed(format!("{}: no G1 moves", gcode.display())),
            Err(e) => prusa::Run::Failed(format!("{}: {e}", gcode.display())),
        },
        other => other,
    }
}

/// Seconds of a plan's stages, as `features plan` runs them: the part read, then each
/// placement tried (the part as modelled first), each a whole plan of its own.
#[derive(Default)]
struct Stages {
    /// Reading the STEP file.
    read: Span,
    /// Extracting the features (each placement's).
    extract: Span,
    /// Every feature's layers and fills (each placement's).
    features: Span,
    /// Smoothing the tool axes.
    smoothing: Span,
    /// The print-head check (with its pedestal search).
    head: Span,
    /// The post and the report.
    program: Span,
    /// Of all of the above, what the placements refused before the chosen one took.
    refused: Span,
    /// Placements tried after the part as modelled.
    tried: usize,
}

/// Wall and CPU seconds of a stretch of the plan (CPU: every thread's, user and system).
#[derive(Default, Clone, Copy)]
struct Span {
    wall: f64,
    cpu: f64,
}

impl Span {
    fn add(&mut self, o: Span) {
        self.wall += o.wall;
        self.cpu += o.cpu;
    }

    /// The share of the machine's cores this stretch kept busy, % (100: every core, all along).
    fn utilisation(&self, cores: usize) -> f64 {
        100.0 * self.cpu / (self.wall * cores as f64).max(1e-9)
    }
}

/// CPU seconds this process has used so far, every thread's, user and system.
fn cpu_now() -> f64 {
    // SAFETY: `rusage` is plain old data, zeroes are a valid value, and `getrusage` only
    // writes to it.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `u` is valid for writes.
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    timeval_s(u.ru_utime) + timeval_s(u.ru_stime)
}

/// A `timeval` in seconds.
fn timeval_s(t: libc::timeval) -> f64 {
    t.tv_sec as f64 + t.tv_usec as f64 * 1e-6
}

/// Plans `step` for `machine` in this process as `features plan --allow-collisions` does (the
/// placement search included) and times its stages by the plan's progress reports
/// ([`plan::Progress`]): a placement's extraction from its start (or `Trying`) to `Start`, its
/// features to `Planned`, then each of [`plan::Stage::AFTER_FEATURES`] to the next (the last to
/// the next `Trying` or the plan's return). What ran before the last `Trying` is also summed
/// as `refused`.
fn stage_times(step: &Path, machine: &str) -> Result<Stages, String> {
    use plan::Progress;
    use std::sync::Mutex;
    let kind = match machine {
        "marlin" => robot_post::MachineKind::Marlin,
        "kuka" => robot_post::MachineKind::Kuka,
        _ => robot_post::MachineKind::Delta5,
    };
    let machine = robot_post::MachineProfile::builtin(kind);
    let (w0, c0) = (Instant::now(), cpu_now());
    let file = brep::StepFile::read(step).map_err(|e| format!("{}: {e}", step.display()))?;
    let mut st = Stages {
        read: Span {
            wall: w0.elapsed().as_secs_f64(),
            cpu: cpu_now() - c0,
        },
        ..Default::default()
    };
    let marks: Mutex<Vec<(&'static str, Instant, f64)>> = Mutex::new(vec![]);
    let mark = |p: Progress| {
        let label = match p {
            Progress::Trying { .. } => Some("trying"),
            Progress::Start { .. } => Some("start"),
            Progress::Planned => Some("planned"),
            Progress::Stage(s) => Some(s.name()),
            _ => None,
        };
        if let (Some(l), Ok(mut m)) = (label, marks.lock()) {
            m.push((l, Instant::now(), cpu_now()));
        }
    };
    let options = plan::Options {
        source: step.display().to_string(),
        stem: "part".into(),
        allow_collisions: true,
        progress: Some(&mark),
        placement: plan::Placement::Find,
        placement_time_limit: std::time::Duration::try_from_secs_f64(
            plan::retry::DEFAULT_TIME_LIMIT_S,
        )
        .ok(),
        ..Default::default()
    };
    let mut out = robot_post::InMemory::default();
    let begin = ("trying", Instant::now(), cpu_now());
    plan::plan_file_to(
        &file,
        &plan::Process::default(),
        &machine,
        &options,
        &mut out,
    )
    .map_err(|e| format!("plan failed: {e}"))?;
    let end = ("end", Instant::now(), cpu_now());
    let marks = marks.into_inner().map_err(|e| e.to_string())?;
    let all: Vec<_> = std::iter::once(begin)
        .chain(marks)
        .chain(std::iter::once(end))
        .collect();
    let last_try = all.iter().rposition(|m| m.0 == "trying").unwrap_or(0);
    let [smooth, head, program] = plan::Stage::AFTER_FEATURES.map(plan::Stage::name);
    for (i, w) in all.windows(2).enumerate() {
        let span = Span {
            wall: w[1].1.duration_since(w[0].1).as_secs_f64(),
            cpu: w[1].2 - w[0].2,
        };
        let stage = match w[0].0 {
            "trying" => &mut st.extract,
            "start" => &mut st.features,
            l if l == smooth => &mut st.smoothing,
            l if l == head => &mut st.head,
            l if l == program => &mut st.program,
            // `planned` is followed by smoothing at once.
            _ => &mut st.smoothing,
        };
        stage.add(span);
        if i < last_try {
            st.refused.add(span);
        }
    }
    st.tried = all.iter().filter(|m| m.0 == "trying").count() - 1;
    Ok(st)
}

fn median(v: &[f64]) -> Option<f64> {
    let mut v: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

fn fmt(v: Option<f64>, prec: usize) -> String {
    v.map_or("-".into(), |v| format!("{v:.prec$}"))
}

/// Plans and slices one part `runs` times; `prusa_on` is cleared when PrusaSlicer turns out to be
/// missing.
fn bench_part(
    step: &Path,
    machine: &str,
    runs: usize,
    tmp: &Path,
    prusa_on: &mut bool,
) -> Result<PartResult, String> {
    let name = step
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "part".into());
    let exe = PathBuf::from(env!("CARGO_BIN_EXE_features"));
    let dir = tmp.join(&name);
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let stl = dir.join(format!("{name}.stl"));
    let gcode = dir.join(format!("{name}.gcode"));
    if *prusa_on {
        prusa::mesh_stl(&exe, step, &stl)?;
    }
    let mut res = PartResult {
        name: name.clone(),
        machine: machine.into(),
        ours: vec![],
        prusa: vec![],
    };
    for i in 0..runs {
        let o = run_ours(&exe, step, machine, &dir);
        if let Some(e) = &o.error {
            println!("{name} run {}: features plan failed: {e}", i + 1);
        }
        res.ours.push(o);
        if *prusa_on {
            match run_prusa(&stl, &gcode) {
                prusa::Run::Done(s) => res.prusa.push(Ok(s)),
                prusa::Run::Missing(why) => {
                    println!(
                        "{why}: measuring ours alone (install PrusaSlicer, \
                         `apt-get install prusa-slicer`, or set $PRUSA_SLICER, to compare)"
                    );
                    *prusa_on = false;
                }
                prusa::Run::Failed(why) => {
                    println!("{name} run {}: PrusaSlicer failed: {why}", i + 1);
                    res.prusa.push(Err(why));
                }
            }
        }
    }
    Ok(res)
}

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut runs: usize = std::env::var("PLAN_SPEED_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3);
    let mut parts: Vec<(PathBuf, String)> = vec![];
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if let Some(n) = a.strip_prefix("--runs") {
            let v = match n.strip_prefix('=') {
                Some(v) => Some(v.to_string()),
                None if n.is_empty() => args.next(),
                None => None,
            };
            match v.and_then(|v| v.parse().ok()) {
                Some(n) => runs = n,
                None => {
                    eprintln!("--runs needs a number");
                    std::process::exit(2);
                }
            }
            continue;
        }
        // `cargo bench` passes `--bench`; other flags are not ours either.
        if a.starts_with('-') {
            continue;
        }
        let (part, machine) = match a.rsplit_once(':') {
            Some((p, m)) if ["delta5", "marlin", "kuka"].contains(&m) => (p, Some(m)),
            _ => (a.as_str(), None),
        };
        let path = if part.ends_with(".step") || part.ends_with(".stp") {
            // Relative to where cargo was run, or else to the workspace (cargo runs benches
            // in the crate's directory).
            let given = PathBuf::from(part);
            if given.is_relative() && !given.exists() {
                root.join(given)
            } else {
                given
            }
        } else {
            root.join("fixtures").join(format!("{part}.step"))
        };
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let machine = machine
            .or_else(|| PARTS.iter().find(|(n, _)| *n == stem).map(|(_, m)| *m))
            .unwrap_or("delta5");
        parts.push((path, machine.into()));
    }
    if parts.is_empty() {
        parts = PARTS
            .iter()
            .map(|(n, m)| {
                (
                    root.join("fixtures").join(format!("{n}.step")),
                    m.to_string(),
                )
            })
            .collect();
    }
    let runs = runs.max(1);
    let tmp = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("plan_speed");
    println!(
        "features plan vs PrusaSlicer {} on the same part: {H} mm layers, {W} mm beads, 2 \
         perimeters, solid fill (PrusaSlicer: our STL at 0.01 mm, supports on); {runs} runs each, \
         alternating; wall times",
        prusa::exe()
    );
    let mut prusa_on = true;
    let mut results = vec![];
    let mut failed = false;
    for (step, machine) in &parts {
        match bench_part(step, machine, runs, &tmp, &mut prusa_on) {
            Ok(r) => results.push(r),
            Err(e) => {
                println!("{}: {e}", step.display());
                failed = true;
            }
        }
    }

    println!();
    println!(
        "{:<16} {:<7} | {:>8} {:>8} | {:>6} | {:>8}",
        "part", "machine", "ours s", "prusa s", "ratio", "RSS MB"
    );
    println!("{}", "-".repeat(64));
    for r in &results {
        let ok: Vec<f64> = r
            .ours
            .iter()
            .filter(|o| o.error.is_none())
            .map(|o| o.seconds)
            .collect();
        let ours = median(&ok);
        let ps: Vec<f64> = r
            .prusa
            .iter()
            .filter_map(|p| p.as_ref().ok())
            .copied()
            .collect();
        let prusa = median(&ps);
        let rss = r
            .ours
            .iter()
            .map(|o| o.rss_mb)
            .filter(|x| x.is_finite())
            .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))));
        println!(
            "{:<16} {:<7} | {:>8} {:>8} | {:>6} | {:>8}",
            r.name,
            r.machine,
            fmt(ours, 2),
            fmt(prusa, 2),
            fmt(ours.zip(prusa).map(|(o, p)| o / p), 2),
            fmt(rss, 0),
        );
        if ok.len() < r.ours.len() || ps.len() < r.prusa.len() {
            failed = true;
        }
    }
    println!(
        "medians over the runs that succeeded; ratio = ours / PrusaSlicer (< 1: ours is faster); \
         RSS = our peak resident set size, the largest over the runs"
    );
    if !prusa_on {
        println!(
            "PrusaSlicer not run ({} not found): ours alone",
            prusa::exe()
        );
    }

    println!();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!("per run (s; ours: peak RSS MB, CPU % = CPU time over wall time x {cores} cores):");
    for r in &results {
        let mut line = format!("{:<16}", r.name);
        for (i, o) in r.ours.iter().enumerate() {
            let p = match r.prusa.get(i) {
                Some(Ok(s)) => format!("{s:.2}"),
                Some(Err(_)) => "failed".into(),
                None => "-".into(),
            };
            let ours = if o.error.is_none() {
                format!("{:.2}", o.seconds)
            } else {
                "failed".into()
            };
            line.push_str(&format!(
                "  #{}: ours {ours} ({:.0} MB, CPU {:.0} %), prusa {p}",
                i + 1,
                o.rss_mb,
                100.0 * o.cpu / (o.seconds * cores as f64).max(1e-9)
            ));
        }
        println!("{line}");
    }

    // Where the time goes: each part planned once more in this process, its stages timed by the
    // plan's progress reports, with the share of the cores each kept busy.
    println!();
    println!(
        "{:<16} | {:>6} {:>7} {:>8} {:>7} {:>7} {:>7} | {:>7} {:>7} | {:>7} {:>7}",
        "stages (1 run)",
        "read",
        "extract",
        "features",
        "smooth",
        "head",
        "program",
        "refused",
        "after %",
        "CPU %",
        "feat. %"
    );
    println!("{}", "-".repeat(106));
    for (step, machine) in &parts {
        let name = step
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        match stage_times(step, machine) {
            Ok(t) => {
                let mut all = Span::default();
                for s in [
                    t.read,
                    t.extract,
                    t.features,
                    t.smoothing,
                    t.head,
                    t.program,
                ] {
                    all.add(s);
                }
                let after = t.smoothing.wall + t.head.wall + t.program.wall;
                println!(
                    "{name:<16} | {:>6.2} {:>7.2} {:>8.2} {:>7.2} {:>7.2} {:>7.2} | {:>4.2} ({}) {:>6.1}% | {:>6.0}% {:>6.0}%",
                    t.read.wall,
                    t.extract.wall,
                    t.features.wall,
                    t.smoothing.wall,
                    t.head.wall,
                    t.program.wall,
                    t.refused.wall,
                    t.tried,
                    100.0 * after / all.wall.max(1e-9),
                    all.utilisation(cores),
                    t.features.utilisation(cores),
                );
            }
            Err(e) => println!("{name:<16} | {e}"),
        }
    }
    println!(
        "wall seconds of `features plan --allow-collisions` run in this process, the placement \
         search included (each stage summed over the placements tried): read = the STEP file; \
         extract = the features; features = every feature's layers; head = the print-head \
         check (issue 18) with its pedestal search; program = the post and the report; refused \
         = the placements refused before the chosen one took (how many after the part as \
         modelled); after % = smoothing, head and program over the whole; CPU % = CPU time of \
         every thread over wall time x {cores} cores (100 %: every core busy all along), for the \
         whole and for the features' layers"
    );
    println!("(files in {})", tmp.display());
    if failed {
        std::process::exit(1);
    }
}
