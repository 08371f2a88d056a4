//! Running `features plan` in the end-to-end tests of the binary (`plan_cli`, `programs`): the
//! fixtures, a scratch folder per test, the run and its stderr.

// Each test binary uses some of these.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub const BIN: &str = env!("CARGO_BIN_EXE_features");

pub fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name)
}

/// A scratch folder of one test, removed when dropped.
pub struct Scratch(PathBuf);
impl Scratch {
    pub fn new(test: &str) -> Scratch {
        let d = std::env::temp_dir().join(format!(
            "features-{}-{}-{test}",
            env!("CARGO_CRATE_NAME"),
            std::process::id()
        ));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("scratch");
        Scratch(d)
    }
    pub fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
    pub fn write(&self, name: &str, text: &str) -> String {
        let p = self.path(name);
        std::fs::write(&p, text).expect("write");
        p.display().to_string()
    }
    /// File names in `sub` (the scratch folder itself for ""), sorted.
    pub fn names(&self, sub: &str) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(self.0.join(sub))
            .map(|r| {
                r.flatten()
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default();
        v.sort();
        v
    }
}
impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

pub fn plan(part: &str, args: &[&str]) -> Output {
    // The tests are about what is planned, not how long the placement search may take on a
    // loaded test machine (the limit is wall-clock time).
    let unlimited: &[&str] = if args.contains(&"--placement-time-limit") {
        &[]
    } else {
        &["--placement-time-limit", "inf"]
    };
    Command::new(BIN)
        .arg("plan")
        .arg(fixture(part))
        .args(args)
        .args(unlimited)
        .output()
        .expect("runs")
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}
