//! Where `features plan` writes: a directory (`-o out/`: `toolpath.csv`, `plan.json` and the
//! machine program under their own names; `<part stem>_plan/` in the current folder when `-o`
//! is left out), or a program file (`-o box.gcode`, `-o cell.src`: that program, and the other
//! outputs beside it under the same stem, `box.toolpath.csv`, `box.plan.json`, ...).
//!
//! What is there already ([`Outputs::claim`]): an earlier plan (the files its `plan.json` lists
//! under `outputs`, and that `plan.json`) is replaced by the new one, and its files the new plan
//! does not write are removed once it is written ([`Outputs::remove_stale`]). A file no plan
//! wrote (beside an earlier plan in its folder, or of a name the new plan would write) is left
//! alone: the plan is refused unless `--force`, which writes it anyway, leaving such files
//! where they are (those of the new plan's names are replaced).

use crate::Failure;
use robot_post::machine::MachineKind;
use std::path::{Path, PathBuf};

/// The fixed names of a plan's outputs (before a `-o` stem); KRL modules are named by the stem.
const OUTPUT_NAMES: [&str; 7] = [
    "toolpath.csv",
    "program.gcode",
    "joints.csv",
    "kinematic_error.svg",
    "preview.html",
    "collisions.csv",
    "plan.json",
];

/// The outputs of one plan.
#[derive(Debug, Clone)]
pub struct Outputs {
    /// The folder every file goes into.
    pub dir: PathBuf,
    /// `-o` as given, or the folder chosen when it was left out: what the summary line names.
    given: PathBuf,
    /// `Some(stem)` when `-o` named the program file: the other outputs take its stem.
    file_stem: Option<String>,
    /// The program file's name when `-o` named it.
    program: Option<String>,
    /// The machine's kind: KUKA plans write KRL modules named by the stem.
    kind: MachineKind,
    /// The part file's stem (the KRL modules' names without a `-o` program file).
    part_stem: String,
}

/// The extension of the program file a machine writes first (its main program).
fn program_extension(kind: MachineKind) -> &'static str {
    match kind {
        MachineKind::Marlin | MachineKind::Delta5 => "gcode",
        MachineKind::Kuka => "src",
    }
}

/// The stem of a part file's name (`part` when it has none).
fn part_stem(part: &Path) -> String {
    part.file_stem()
        .map_or("part".into(), |s| s.to_string_lossy().into_owned())
}

impl Outputs {
    /// Reads `-o` for the plan of `part`: a path ending in the machine's program extension
    /// (`.gcode`, or `.src` for KUKA) names the program file; any other path is a directory;
    /// without `-o`, the directory `<part stem>_plan` in the current folder. `-o -` is refused:
    /// a plan is several files, not one stream.
    pub fn from_arg(
        output: Option<&Path>,
        part: &Path,
        kind: MachineKind,
    ) -> Result<Outputs, Failure> {
        let stem = part_stem(part);
        let given = match output {
            Some(o) if o == Path::new("-") => {
                return Err(Failure::new(
                    o,
                    "a plan is several files and cannot go to standard output: give -o a folder or a program file, or leave -o out for ./<part>_plan/",
                ))
            }
            Some(o) => o.to_path_buf(),
            None => PathBuf::from(format!("{stem}_plan")),
        };
        let ext = given
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let wanted = program_extension(kind);
        let mut outputs = Outputs {
            dir: given.clone(),
            given: given.clone(),
            file_stem: None,
            program: None,
            kind,
            part_stem: stem,
        };
        match ext.as_deref() {
            Some(e) if e == wanted => {
                let stem = given
                    .file_stem()
                    .and_then(|s| s.to_str())
                    .filter(|s| !s.is_empty())
                    .ok_or_else(|| Failure::new(&given, "the program file needs a name"))?;
                let dir = match given.parent() {
                    Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
                    _ => PathBuf::from("."),
                };
                if !dir.is_dir() {
                    return Err(Failure::new(
                        &dir,
                        "the program's folder does not exist (create it, or give -o a folder)",
                    ));
                }
                let name = given
                    .file_name()
                    .and_then(|s| s.to_str())
                    .unwrap_or_default()
                    .to_string();
                outputs.dir = dir;
                outputs.file_stem = Some(stem.to_string());
                outputs.program = Some(name);
                Ok(outputs)
            }
            Some(e @ ("gcode" | "src" | "krl" | "nc")) => Err(Failure::new(
                &given,
                format!(
                    "a {kind} plan writes a .{wanted} program, not .{e}: give -o a folder or a .{wanted} file"
                ),
            )),
            _ if given.is_file() => Err(Failure::new(
                &given,
                format!("is a file: give -o a folder or a .{wanted} program file"),
            )),
            _ => Ok(outputs),
        }
    }

    /// Where the plan went, as the summary line names it: `-o` as given, or the folder chosen.
    pub fn shown(&self) -> String {
        self.given.display().to_string()
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

    /// Whether the file `name` of this folder is one this plan's outputs could be called: a
    /// fixed output name (under the stem), or a KRL module named by the stem.
    fn could_write(&self, name: &str) -> bool {
        let krl = self.kind == MachineKind::Kuka
            && name.starts_with(&self.stem(&self.part_stem))
            && (name.ends_with(".src") || name.ends_with(".dat"));
        krl || OUTPUT_NAMES.iter().any(|n| self.name(n) == name)
    }

    /// Whether `name` belongs to this output: in a folder of its own every entry does; under a
    /// program file's stem, the names a plan there may write (not `box.step`, the part itself
    /// perhaps, beside `box.gcode`).
    fn holds(&self, name: &str) -> bool {
        self.file_stem.is_none() || self.could_write(name)
    }

    /// The names of the files an earlier plan here wrote, `plan.json` last: those its
    /// `plan.json` lists under `outputs` (a report written before that list: the fixed names
    /// that exist); empty when there is no `plan.json` this program wrote.
    fn earlier(&self) -> Vec<String> {
        let report = self.name("plan.json");
        let old: Option<serde_json::Value> = std::fs::read_to_string(self.dir.join(&report))
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok());
        let Some(old) = old else {
            return vec![];
        };
        let listed: Option<Vec<String>> = old.get("outputs").and_then(|o| {
            o.as_array().map(|a| {
                a.iter()
                    .filter_map(|x| x.as_str().map(str::to_string))
                    .collect()
            })
        });
        let mut names = match listed {
            Some(names) => names,
            // A report of ours from before the list: it names its part and its features.
            None if old.get("source").is_some() && old.get("features").is_some() => {
                let stem = old
                    .get("source")
                    .and_then(|s| s.as_str())
                    .map(|s| part_stem(Path::new(s)));
                self.entries()
                    .into_iter()
                    .filter(|n| {
                        OUTPUT_NAMES.iter().any(|o| self.name(o) == *n)
                            || stem.as_ref().is_some_and(|s| {
                                n.starts_with(s.as_str())
                                    && (n.ends_with(".src") || n.ends_with(".dat"))
                            })
                    })
                    .collect()
            }
            None => return vec![],
        };
        // Only plain names inside the folder: a report cannot send the removal elsewhere.
        names
            .retain(|n| n != &report && Path::new(n).file_name().map(|f| f.len()) == Some(n.len()));
        names.push(report);
        names
    }

    /// The names of the entries of the output folder (none when it does not exist yet).
    fn entries(&self) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(&self.dir)
            .map(|r| {
                r.flatten()
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default();
        names.sort();
        names
    }

    /// Checks what the output holds before any work, and returns the earlier plan's files the
    /// new plan replaces (empty for a new output). Where the output holds files no plan wrote
    /// (beside an earlier plan: any; without one: those of the new plan's names) the plan is
    /// refused, naming one, unless `force`.
    pub fn claim(&self, force: bool) -> Result<Vec<PathBuf>, Failure> {
        let earlier = self.earlier();
        let foreign: Vec<String> = self
            .entries()
            .into_iter()
            .filter(|n| self.holds(n) && !earlier.contains(n))
            .filter(|n| !earlier.is_empty() || self.could_write(n))
            .collect();
        if let (false, Some(first)) = (force, foreign.first()) {
            let beside = if earlier.is_empty() {
                ""
            } else {
                " beside an earlier plan"
            };
            return Err(Failure::new(
                &self.given,
                format!(
                    "holds {} file(s) no plan wrote{beside} (e.g. {}): --force writes the plan anyway, or choose another output",
                    foreign.len(),
                    self.dir.join(first).display()
                ),
            ));
        }
        Ok(earlier
            .iter()
            .map(|n| self.dir.join(n))
            .filter(|p| p.is_file())
            .collect())
    }

    /// Removes the files of the earlier plan `earlier` ([`Outputs::claim`]) that the new plan,
    /// now written, did not write again (`written`: the new plan's file names, `plan.json` among
    /// them or not).
    pub fn remove_stale(&self, earlier: &[PathBuf], written: &[String]) -> Result<(), Failure> {
        let report = self.path("plan.json");
        for p in earlier {
            let again = p == &report
                || p.file_name()
                    .is_some_and(|f| written.iter().any(|w| f == w.as_str()));
            if !again {
                std::fs::remove_file(p).map_err(|e| {
                    Failure::new(p, format!("cannot remove the earlier plan's file: {e}"))
                })?;
            }
        }
        Ok(())
    }
}
