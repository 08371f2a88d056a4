//! Read + mesh + analysis time per STEP file: every `fixtures/*.step` and `fixtures/reader/*.step`
//! of the repository and every `*.step` of both shared corpora (`../../../shared/corpus` and
//! `corpus-more` from this crate, each skipped if absent).
//!
//! ```text
//! cargo bench -p brep --bench read_mesh            # every file
//! cargo bench -p brep --bench read_mesh -- impeller # only files whose name contains "impeller"
//! ```
//!
//! A small hand-written harness (no criterion). For each file, the bytes are read into memory
//! first; one warm-up pass runs read, mesh and report, then `N` timed passes, `N` chosen so that
//! the file takes about 0.75 s in all (at least 3, at most 50). Each pass times separately:
//!
//! - read: `brep::read_step_bytes` (Part 21 parse and B-rep translation);
//! - mesh: `brep::solid::mesh_solid` of every solid at display tolerance
//!   (`MeshOptions::default()`, 0.05 mm chord);
//! - report: `brep::solid::report_solid` of every solid (volume, area, checks; it meshes again
//!   at analysis precision).
//!
//! Medians are printed. Without `--bench` on the command line (as when `cargo test --benches`
//! runs it) only the smallest file is read and meshed once, as a smoke test.

use brep::mesh::MeshOptions;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Wall time each file should take over its timed passes.
const TARGET: Duration = Duration::from_millis(750);
const MIN_RUNS: usize = 3;
const MAX_RUNS: usize = 50;

fn step_files(dir: &Path) -> Option<Vec<PathBuf>> {
    let read = std::fs::read_dir(dir).ok()?;
    let mut paths: Vec<_> = read
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension()
                .is_some_and(|x| x.eq_ignore_ascii_case("step") || x.eq_ignore_ascii_case("stp"))
        })
        .collect();
    paths.sort();
    Some(paths)
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

/// What one pass over a file found and how long each phase took, in ms.
struct Pass {
    read_ms: f64,
    mesh_ms: f64,
    report_ms: f64,
    solids: usize,
    faces: usize,
    triangles: usize,
    /// First mesh or report error, if any.
    problem: Option<String>,
}

fn one_pass(bytes: &[u8], with_report: bool) -> Result<Pass, String> {
    let t = Instant::now();
    let part = brep::read_step_bytes(std::hint::black_box(bytes)).map_err(|e| e.to_string())?;
    let read_ms = t.elapsed().as_secs_f64() * 1e3;
    let b = &part.brep;
    let solids: Vec<_> = b.solid_ids().collect();
    let faces = solids.iter().map(|&s| b.solid_faces(s).len()).sum();
    let mut problem = None;

    let t = Instant::now();
    let meshes: Vec<_> = solids
        .iter()
        .map(|&s| brep::solid::mesh_solid(b, s, Some(MeshOptions::default())))
        .collect();
    let mesh_ms = t.elapsed().as_secs_f64() * 1e3;
    let mut triangles = 0;
    for m in meshes {
        match m {
            Ok(m) => triangles += m.triangles().len(),
            Err(e) => {
                problem.get_or_insert_with(|| format!("mesh: {e}"));
            }
        }
    }

    let t = Instant::now();
    let reports: Vec<_> = solids
        .iter()
        .filter(|_| with_report)
        .map(|&s| brep::solid::report_solid(b, s))
        .collect();
    let report_ms = t.elapsed().as_secs_f64() * 1e3;
    for r in reports {
        if let Err(e) = r {
            problem.get_or_insert_with(|| format!("report: {e}"));
        }
    }
    Ok(Pass {
        read_ms,
        mesh_ms,
        report_ms,
        solids: solids.len(),
        faces,
        triangles,
        problem,
    })
}

fn short(s: &str, n: usize) -> String {
    if s.chars().count() <= n {
        s.to_string()
    } else {
        let mut t: String = s.chars().take(n.saturating_sub(1)).collect();
        t.push('…');
        t
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let bench_mode = args.iter().any(|a| a == "--bench");
    let filter: Option<&str> = args
        .iter()
        .find(|a| !a.starts_with('-'))
        .map(String::as_str);

    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<(String, PathBuf)> = vec![];
    for sub in ["fixtures", "fixtures/reader"] {
        let fixtures = root.join("../..").join(sub);
        match step_files(&fixtures) {
            Some(ps) => files.extend(ps.into_iter().map(|p| {
                (
                    format!("{sub}/{}", p.file_name().unwrap().to_string_lossy()),
                    p,
                )
            })),
            None => println!("note: {} not found, fixtures skipped", fixtures.display()),
        }
    }
    for set in ["corpus", "corpus-more"] {
        let dir = root.join("../../../shared").join(set);
        match step_files(&dir) {
            Some(ps) => files.extend(ps.into_iter().map(|p| {
                (
                    format!("{set}/{}", p.file_name().unwrap().to_string_lossy()),
                    p,
                )
            })),
            None => println!(
                "note: shared {set} {} not found, its files skipped",
                dir.display()
            ),
        }
    }
    if let Some(f) = filter {
        files.retain(|(name, _)| name.contains(f));
    }

    if !bench_mode {
        // `cargo test --benches`: a quick read + mesh of the smallest file, not a benchmark
        // (report_solid is left out: at analysis precision it takes seconds on a sphere).
        let smallest = files
            .iter()
            .min_by_key(|(_, p)| std::fs::metadata(p).map_or(u64::MAX, |m| m.len()));
        if let Some((name, p)) = smallest {
            let bytes = std::fs::read(p).expect("readable fixture");
            let pass = one_pass(&bytes, false);
            println!(
                "read_mesh smoke test on {name}: {}",
                match pass {
                    Ok(p) => format!("{} solids, {} triangles", p.solids, p.triangles),
                    Err(e) => format!("read error: {e}"),
                }
            );
        }
        println!("(run `cargo bench -p brep --bench read_mesh` for timings)");
        return;
    }

    println!("goal: impeller read+mesh < 50 ms");
    println!(
        "mesh = mesh_solid at MeshOptions::default() (0.05 mm chord) for every solid; \
         report = report_solid for every solid; medians of N timed runs after one warm-up"
    );
    println!();
    let header = format!(
        "{:<44} {:>8} {:>6} {:>6} {:>3} {:>9} {:>9} {:>10} {:>9}  {}",
        "file",
        "kB",
        "solids",
        "faces",
        "N",
        "read ms",
        "mesh ms",
        "triangles",
        "report ms",
        "note"
    );
    println!("{header}");
    println!("{}", "-".repeat(header.chars().count()));

    let mut goal_lines = vec![];
    for (name, path) in &files {
        let bytes = match std::fs::read(path) {
            Ok(b) => b,
            Err(e) => {
                println!("{name:<44} file error: {e}");
                continue;
            }
        };
        let kb = bytes.len() as f64 / 1e3;
        // Warm-up, which also sizes N.
        let t = Instant::now();
        let warm = match one_pass(&bytes, true) {
            Ok(p) => p,
            Err(e) => {
                println!("{name:<44} {kb:>8.1} read error: {e}");
                continue;
            }
        };
        let once = t.elapsed().max(Duration::from_micros(1));
        let n =
            ((TARGET.as_secs_f64() / once.as_secs_f64()).ceil() as usize).clamp(MIN_RUNS, MAX_RUNS);
        let (mut read, mut mesh, mut report) = (vec![], vec![], vec![]);
        for _ in 0..n {
            match one_pass(&bytes, true) {
                Ok(p) => {
                    read.push(p.read_ms);
                    mesh.push(p.mesh_ms);
                    report.push(p.report_ms);
                }
                Err(e) => {
                    // Deterministic reader: should not happen after a good warm-up.
                    println!("{name:<44} read error on a timed run: {e}");
                    break;
                }
            }
        }
        let (read, mesh, report) = (median(&mut read), median(&mut mesh), median(&mut report));
        let note = warm
            .problem
            .as_deref()
            .map(|p| short(p, 80))
            .unwrap_or_default();
        println!(
            "{name:<44} {kb:>8.1} {:>6} {:>6} {n:>3} {read:>9.2} {mesh:>9.2} {:>10} {report:>9.2}  {note}",
            warm.solids, warm.faces, warm.triangles
        );
        if name.contains("impeller") {
            let total = read + mesh;
            goal_lines.push(format!(
                "{name}: read+mesh {total:.1} ms ({} 50 ms goal)",
                if total < 50.0 {
                    "meets the"
                } else {
                    "misses the"
                }
            ));
        }
    }
    if !goal_lines.is_empty() {
        println!();
        for l in goal_lines {
            println!("{l}");
        }
    }
}
