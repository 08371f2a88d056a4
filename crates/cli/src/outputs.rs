//! Where `features plan` writes: a directory (`-o out/`: `toolpath.csv`, `plan.json` and the
//! machine program under their own names), or a program file (`-o box.gcode`, `-o cell.src`:
//! that program, and the other outputs beside it under the same stem, `box.toolpath.csv`,
//! `box.plan.json`, ...). An earlier plan's files there are refused unless `--force`, which
//! first removes what that plan wrote (the list `plan.json` keeps under `outputs`).

use crate::Failure;
use robot_post::machine::MachineKind;
use std::path::{Path, PathBuf};

/// The outputs of one plan.
#[derive(Debug, Clone)]
pub struct Outputs {
    /// The folder every file goes into.
    pub dir: PathBuf,
    /// `Some(stem)` when `-o` named the program file: the other outputs take its stem.
    file_stem: Option<String>,
    /// The program file's name when `-o` named it.
    program: Option<String>,
}

/// The extension of the program file a machine writes first (its main program).
fn program_extension(kind: MachineKind) -> &'static str {
    match kind {
        MachineKind::Marlin | MachineKind::Delta5 => "gcode",
        MachineKind::Kuka => "src",
    }
}

impl Outputs {
    /// Reads `-o`: a path ending in the machine's program extension (`.gcode`, or `.src` for
    /// KUKA) names the program file; any other path is a directory.
    pub fn from_arg(output: &Path, kind: MachineKind) -> Result<Outputs, Failure> {
        let ext = output
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let wanted = program_extension(kind);
        match ext.as_deref() {
            Some(e) if e == wanted => {
                let stem = output
                    .file_stem()
                    .and_then(|s| s.to_str())
                    .filter(|s| !s.is_empty())
                    .ok_or_else(|| Failure::new(output, "the program file needs a name"))?;
                let dir = match output.parent() {
                    Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
                    _ => PathBuf::from("."),
                };
                if !dir.is_dir() {
                    return Err(Failure::new(
                        &dir,
                        "the program's folder does not exist (create it, or give -o a folder)",
                    ));
                }
                let name = output
                    .file_name()
                    .and_then(|s| s.to_str())
                    .unwrap_or_default()
                    .to_string();
                Ok(Outputs {
                    dir,
                    file_stem: Some(stem.to_string()),
                    program: Some(name),
                })
            }
            Some(e @ ("gcode" | "src" | "krl" | "nc")) => Err(Failure::new(
                output,
                format!(
                    "a {kind} plan writes a .{wanted} program, not .{e}: give -o a folder or a .{wanted} file"
                ),
            )),
            _ => {
                if output.is_file() {
                    return Err(Failure::new(
                        output,
                        format!("is a file: give -o a folder or a .{wanted} program file"),
                    ));
                }
                Ok(Outputs {
                    dir: output.to_path_buf(),
                    file_stem: None,
                    program: None,
                })
            }
        }
    }

    /// The stem KRL module names take: the program file's, else the part's.
    pub fn stem(&self, part_stem: &str) -> String {
        self.file_stem
            .clone()
            .unwrap_or_else(|| part_stem.to_string())
    }

    /// The name of output `name` (`toolpath.csv`, `plan.json`, `program.gcode`, or a KRL module
    /// already named by the stem) in this plan's folder.
    pub fn name(&self, name: &str) -> String {
        let krl = name.ends_with(".src") || name.ends_with(".dat");
        match (&self.file_stem, &self.program) {
            (Some(_), Some(program)) if name == "program.gcode" => program.clone(),
            // KRL modules are named by the stem already.
            (Some(stem), _) if !krl => format!("{stem}.{name}"),
            _ => name.to_string(),
        }
    }

    /// The path of output `name`.
    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.join(self.name(name))
    }

    /// The files of an earlier plan here: those its `plan.json` lists under `outputs` (and the
    /// `plan.json` itself), or, for a plan written before that list, the outputs' fixed names
    /// that exist.
    pub fn earlier(&self) -> Vec<PathBuf> {
        let report = self.path("plan.json");
        if !report.is_file() {
            // The program alone (a plan whose report was removed) still counts.
            return ["program.gcode", "toolpath.csv"]
                .iter()
                .map(|n| self.path(n))
                .filter(|p| p.is_file())
                .collect();
        }
        let old: Option<serde_json::Value> = std::fs::read_to_string(&report)
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok());
        let listed: Option<Vec<String>> = old.as_ref().and_then(|v| {
            v.get("outputs")?.as_array().map(|a| {
                a.iter()
                    .filter_map(|x| x.as_str().map(str::to_string))
                    .collect()
            })
        });
        let names = listed.unwrap_or_else(|| {
            let mut names: Vec<String> = ["toolpath.csv", "program.gcode", "kinematic_error.svg"]
                .iter()
                .map(|n| self.name(n))
                .collect();
            // KRL modules of that plan: named by its part's stem.
            let stem = old
                .as_ref()
                .and_then(|v| v.get("source")?.as_str().map(str::to_string))
                .and_then(|s| Some(Path::new(&s).file_stem()?.to_str()?.to_string()));
            if let (Some(stem), Ok(entries)) = (stem, std::fs::read_dir(&self.dir)) {
                for e in entries.flatten() {
                    let n = e.file_name().to_string_lossy().into_owned();
                    if n.starts_with(&stem) && (n.ends_with(".src") || n.ends_with(".dat")) {
                        names.push(n);
                    }
                }
            }
            names
        });
        let mut out: Vec<PathBuf> = names
            .iter()
            // Only plain names inside the folder: a report cannot send the removal elsewhere.
            .filter(|n| Path::new(n).file_name().map(|f| f.len()) == Some(n.len()))
            .map(|n| self.dir.join(n))
            .filter(|p| p.is_file())
            .collect();
        out.push(report);
        out
    }

    /// Removes the files of an earlier plan (`--force`).
    pub fn clear_earlier(&self) -> Result<(), Failure> {
        for p in self.earlier() {
            std::fs::remove_file(&p).map_err(|e| {
                Failure::new(&p, format!("cannot remove the earlier plan's file: {e}"))
            })?;
        }
        Ok(())
    }
}
