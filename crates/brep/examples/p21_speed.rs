//! Times `brep::p21::parse` on every `*.step` file of the shared corpus.
//!
//! ```text
//! cargo run --release -p brep --example p21_speed [DIR]
//! ```
//!
//! DIR defaults to `../../../shared/corpus` relative to the crate. Each file is
//! read into memory first, parsed once cold (the time a one-shot CLI run
//! sees, page faults included), then `RUNS` more times; the cold, minimum and
//! median wall times are printed.

use std::time::Instant;

const RUNS: usize = 20;

fn main() {
    let dir = std::env::args()
        .nth(1)
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| {
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus")
        });
    let Ok(read) = std::fs::read_dir(&dir) else {
        eprintln!("note: {} not found, nothing to time", dir.display());
        return;
    };
    let mut paths: Vec<_> = read
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension()
                .is_some_and(|x| x.eq_ignore_ascii_case("step"))
        })
        .collect();
    paths.sort();
    println!(
        "{:<40} {:>9} {:>9} {:>9} {:>9} {:>9} {:>8}",
        "file", "kB", "entities", "first ms", "min ms", "med ms", "MB/s"
    );
    for path in &paths {
        let name = path
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let bytes = match std::fs::read(path) {
            Ok(b) => b,
            Err(e) => {
                println!("{name:<40} read error: {e}");
                continue;
            }
        };
        let t = Instant::now();
        let first = brep::p21::parse(&bytes);
        let first_ms = t.elapsed().as_secs_f64() * 1e3;
        let entities = match first {
            Ok(f) => f.entities.len(),
            Err(e) => {
                println!("{name:<40} parse error: {e}");
                continue;
            }
        };
        let mut times: Vec<f64> = (0..RUNS)
            .map(|_| {
                let t = Instant::now();
                let r = brep::p21::parse(&bytes);
                let ms = t.elapsed().as_secs_f64() * 1e3;
                std::hint::black_box(r.is_ok());
                drop(r);
                ms
            })
            .collect();
        times.sort_by(f64::total_cmp);
        let (min, med) = (times[0], times[RUNS / 2]);
        println!(
            "{name:<40} {:>9.1} {entities:>9} {first_ms:>9.2} {min:>9.2} {med:>9.2} {:>8.0}",
            bytes.len() as f64 / 1e3,
            bytes.len() as f64 / 1e3 / min
        );
    }
}
