//! `features plan` of a fixture with given arguments, run once for the whole test binary: the
//! fixture × machine matrix (issue 31) and the tests that read the same plans share them (a
//! second caller waits for the first's run). What the run printed and the files it wrote are
//! kept in memory; its directory is removed.

// Each test binary uses some of these.
#![allow(dead_code)]

use serde_json::Value;
use std::collections::{BTreeMap, HashMap};
use std::path::PathBuf;
use std::process::Command;
use std::sync::{Arc, Mutex, OnceLock};

/// One run of `features plan`.
pub struct Planned {
    /// The exit code.
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
    /// Every file written, by name: its text (empty for `preview.html`, which is large and
    /// read by no test of the matrix).
    pub files: BTreeMap<String, String>,
}

impl Planned {
    /// `plan.json`, when one was written.
    pub fn report(&self) -> Option<Value> {
        serde_json::from_str(self.files.get("plan.json")?).ok()
    }

    /// The text of the file `name` (empty when none was written).
    pub fn file(&self, name: &str) -> &str {
        self.files.get(name).map_or("", String::as_str)
    }
}

/// `features plan fixtures/<name>.step <args> -o <a directory of its own>`, run once per
/// (name, args) for the whole binary.
pub fn planned(name: &str, args: &[&str]) -> Arc<Planned> {
    type Cell = Arc<OnceLock<Arc<Planned>>>;
    type Plans = HashMap<(String, Vec<String>), Cell>;
    static PLANS: OnceLock<Mutex<Plans>> = OnceLock::new();
    let key = (
        name.to_string(),
        args.iter().map(|a| a.to_string()).collect::<Vec<_>>(),
    );
    let cell = PLANS
        .get_or_init(Default::default)
        .lock()
        .expect("the cache's lock")
        .entry(key)
        .or_default()
        .clone();
    cell.get_or_init(|| Arc::new(run(name, args))).clone()
}

fn run(name: &str, args: &[&str]) -> Planned {
    static RUNS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let k = RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!(
        "features-planned-{}-{}-{k}-{name}",
        env!("CARGO_CRATE_NAME"),
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    let part = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(format!("{name}.step"));
    let out = Command::new(env!("CARGO_BIN_EXE_features"))
        .arg("plan")
        .arg(&part)
        .args(args)
        // The tests are about what is planned, not how long the placement search may take
        // on a loaded test machine (the limit is wall-clock time).
        .args(["--placement-time-limit", "inf"])
        .arg("-o")
        .arg(&dir)
        .output()
        .expect("runs");
    let mut files = BTreeMap::new();
    for e in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
        let n = e.file_name().to_string_lossy().into_owned();
        let text = match n.as_str() {
            "preview.html" => String::new(),
            _ => std::fs::read_to_string(e.path()).unwrap_or_default(),
        };
        files.insert(n, text);
    }
    let _ = std::fs::remove_dir_all(&dir);
    Planned {
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
        files,
    }
}

/// Each of `runs` (a fixture's name, then `--machine M` and any other arguments) planned
/// ([`planned_all`]), as its name, its machine and its plan.
pub fn each_planned(runs: &[(String, Vec<String>)]) -> Vec<(&str, &str, Arc<Planned>)> {
    planned_all(runs);
    runs.iter()
        .map(|(name, args)| {
            let a: Vec<&str> = args.iter().map(String::as_str).collect();
            (name.as_str(), args[1].as_str(), planned(name, &a))
        })
        .collect()
}

/// [`planned`] of every (name, args) of `runs`, as many at a time as the machine has cores
/// (the longest first, by the STEP file's size, so that the last to finish are short).
pub fn planned_all(runs: &[(String, Vec<String>)]) {
    let size = |n: &str| {
        std::fs::metadata(
            PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("../../fixtures")
                .join(format!("{n}.step")),
        )
        .map_or(0, |m| m.len())
    };
    let mut order: Vec<&(String, Vec<String>)> = runs.iter().collect();
    order.sort_by_key(|(n, _)| std::cmp::Reverse(size(n)));
    let next = std::sync::atomic::AtomicUsize::new(0);
    let workers = std::thread::available_parallelism().map_or(2, |n| n.get());
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| loop {
                let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some((name, args)) = order.get(k) else {
                    break;
                };
                let args: Vec<&str> = args.iter().map(String::as_str).collect();
                planned(name, &args);
            });
        }
    });
}
