//! `cargo bench -p features --bench extract`: feature extraction time per fixture and corpus
//! file (file already read; goal: impeller under 100 ms end to end, reading included), and over
//! the generated part families (goal: median extract time under 100 ms per part).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x == "step"))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// Median read and extract times of one file: `(solids, features, read ms, extract ms)`.
fn measure(path: &Path) -> Option<(usize, usize, f64, f64)> {
    let bytes = std::fs::read(path).ok()?;
    let part = brep::read_step_bytes(&bytes).ok()?;
    let run = || {
        let mut n = 0;
        for s in part.brep.solid_ids() {
            if let Ok(t) = features::extract(&part.brep, s, &Default::default()) {
                n += t.features.len();
            }
        }
        n
    };
    let n = run();
    let (mut reads, mut extracts) = (vec![], vec![]);
    let start = Instant::now();
    while reads.len() < 3 || (start.elapsed() < Duration::from_millis(800) && reads.len() < 30) {
        let t = Instant::now();
        let _ = brep::read_step_bytes(&bytes);
        reads.push(t.elapsed());
        let t = Instant::now();
        let _ = run();
        extracts.push(t.elapsed());
    }
    Some((
        part.brep.solids.len(),
        n,
        median(reads).as_secs_f64() * 1e3,
        median(extracts).as_secs_f64() * 1e3,
    ))
}

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut all = files(&root.join("fixtures"));
    all.extend(files(&root.join("../shared/corpus")));
    all.extend(files(&root.join("../shared/corpus-more")));
    println!(
        "goal: impeller read + extract < 100 ms; generated parts: extract < 100 ms at the median"
    );
    println!(
        "{:<40} {:>7} {:>9} {:>11} {:>11}",
        "file", "solids", "features", "read ms", "extract ms"
    );
    let families = files(&root.join("fixtures/families"));
    let mut family_ms = vec![];
    let n_named = all.len();
    all.extend(families);
    for (k, path) in all.iter().enumerate() {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        match measure(path) {
            Some((solids, n, read, extract)) => {
                if k >= n_named {
                    family_ms.push(extract);
                }
                println!("{name:<40} {solids:>7} {n:>9} {read:>11.2} {extract:>11.2}");
            }
            None => println!("{name:<40} unreadable"),
        }
    }
    if !family_ms.is_empty() {
        family_ms.sort_by(f64::total_cmp);
        let at = |q: f64| family_ms[((family_ms.len() - 1) as f64 * q).round() as usize];
        println!(
            "generated parts (fixtures/families): {} parts, extract ms per part: median {:.2}, p90 {:.2}, max {:.2} (goal: median < 100)",
            family_ms.len(),
            at(0.5),
            at(0.9),
            at(1.0)
        );
    }
}
