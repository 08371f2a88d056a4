//! One way to run every post: a machine profile gives its [`Post`]
//! ([`MachineProfile::post`]), which writes a [`Program`] (the files to save, figures per
//! feature, warnings) for a tool path, so a caller never matches on machine kinds.

use std::collections::BTreeMap;

pub use crate::sink::{InMemory, ProgramFile, ProgramSink};

use crate::delta5::{delta5_to, KinematicFigures};
use crate::kind::MachineKind;
use crate::kuka::{kuka_to, KukaFigures};
use crate::machine::MachineProfile;
use crate::marlin::marlin_job_to;
use crate::PostError;
use toolpath::ToolPath;

/// What the programs name: the part they are for, and what the plan asks of the program's
/// text.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Job<'a> {
    /// The source (the STEP file's name), written in every program's header.
    pub source: &'a str,
    /// The part's stem, for posts whose programs carry a name (KRL modules).
    pub stem: &'a str,
    /// Comment lines every program's header carries after the line naming the source (the
    /// planner's version and the settings used), without the comment sign.
    pub notes: &'a [String],
    /// Settings of the plan a G-code viewer reads, `(key, value)` in PrusaSlicer's names
    /// (`skirts`, `brim_width`): the Marlin post writes them in its config block with the
    /// machine's ([`crate::marlin::config`]).
    pub config: &'a [(String, String)],
    /// Arc fitting (the process key `arc_fitting`): the tolerance (mm) within which the Marlin
    /// post writes runs of print moves along a circle as `G2`/`G3`
    /// ([`crate::marlin::arcs`]); `None`: straight moves only.
    pub arcs: Option<f64>,
    /// The plan is refused when a point is out of the arm's reach (no `--allow-unreachable`),
    /// its files dropped: the KUKA post then leaves out `joints.csv` when it finds one.
    pub refused_unreachable: bool,
}

/// A post: writes a machine's program for a tool path.
pub trait Post {
    /// The program for `path`, its files written into `sink` (the returned program holds none
    /// of them, only the figures and warnings), or why it cannot be written. A file is opened
    /// only once the path passed the post's checks; the built-in posts write their programs
    /// as they make them, a [`ProgramSink::chunk`] of text at a time (a megabyte).
    fn post_to(
        &self,
        path: &ToolPath,
        job: &Job,
        sink: &mut dyn ProgramSink,
    ) -> Result<Program, PostError>;

    /// The program for `path`, its files held in memory ([`Post::post_to`] into an
    /// [`InMemory`] sink), or why it cannot be written.
    fn post(&self, path: &ToolPath, job: &Job) -> Result<Program, PostError> {
        let mut files = InMemory::default();
        let program = self.post_to(path, job, &mut files)?;
        Ok(Program {
            files: files.files,
            ..program
        })
    }
}

/// A written program: its files in the order they are saved, what the post measured per
/// feature, and warnings (one line each).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Program {
    /// The files, in order.
    pub files: Vec<ProgramFile>,
    /// Figures per feature id (the features the post measured).
    pub figures: BTreeMap<usize, PostFigures>,
    /// Things to know, one line each.
    pub warnings: Vec<String>,
    /// Print moves slowed to the machine's `max_feed_mm_min` (the delta5 post's; `None` for
    /// posts that scale no feed).
    pub feed_clamped_moves: Option<usize>,
}

/// What a post measured of one feature.
#[derive(Debug, Clone, PartialEq)]
pub enum PostFigures {
    /// The delta5 post's kinematic figures.
    Delta5(KinematicFigures),
    /// The KUKA post's reach figures.
    Kuka(KukaFigures),
}

/// The Marlin post ([`marlin`](crate::marlin())): `program.gcode`.
#[derive(Debug, Clone, Copy)]
pub struct MarlinPost<'a>(pub &'a MachineProfile);

/// A program holding no file: what a post measured, `figures` per feature (each made a
/// [`PostFigures`] by `kind`), and its `warnings`.
fn measured<K>(
    figures: BTreeMap<usize, K>,
    kind: fn(K) -> PostFigures,
    warnings: Vec<String>,
) -> Program {
    Program {
        files: vec![],
        figures: figures.into_iter().map(|(id, k)| (id, kind(k))).collect(),
        warnings,
        feed_clamped_moves: None,
    }
}

impl Post for MarlinPost<'_> {
    fn post_to(
        &self,
        path: &ToolPath,
        job: &Job,
        sink: &mut dyn ProgramSink,
    ) -> Result<Program, PostError> {
        marlin_job_to(path, self.0, job, sink)?;
        Ok(Program::default())
    }
}

/// The 5-axis post ([`delta5`](crate::delta5())): `program.gcode` and `kinematic_error.svg`, kinematic figures
/// per feature.
#[derive(Debug, Clone, Copy)]
pub struct Delta5Post<'a>(pub &'a MachineProfile);

impl Post for Delta5Post<'_> {
    fn post_to(
        &self,
        path: &ToolPath,
        job: &Job,
        sink: &mut dyn ProgramSink,
    ) -> Result<Program, PostError> {
        let program = delta5_to(path, self.0, job.source, job.notes, sink)?;
        Ok(Program {
            feed_clamped_moves: Some(program.feed_clamped_moves),
            ..measured(program.figures, PostFigures::Delta5, program.warnings)
        })
    }
}

/// The KUKA post ([`kuka`](crate::kuka())): the KRL files named after the job's stem, reach figures per
/// feature, and its warnings.
#[derive(Debug, Clone, Copy)]
pub struct KukaPost<'a>(pub &'a MachineProfile);

impl Post for KukaPost<'_> {
    fn post_to(
        &self,
        path: &ToolPath,
        job: &Job,
        sink: &mut dyn ProgramSink,
    ) -> Result<Program, PostError> {
        let joints = match job.refused_unreachable {
            true => crate::kuka::JointsCsv::UnlessUnreachable,
            false => crate::kuka::JointsCsv::Always,
        };
        let program = kuka_to(path, self.0, job.stem, job.source, job.notes, sink, joints)?;
        Ok(measured(
            program.figures,
            PostFigures::Kuka,
            program.warnings,
        ))
    }
}

impl MachineProfile {
    /// The post of this profile's kind, writing with this profile.
    pub fn post(&self) -> Box<dyn Post + '_> {
        match self.kind {
            MachineKind::Marlin => Box::new(MarlinPost(self)),
            MachineKind::Delta5 => Box::new(Delta5Post(self)),
            MachineKind::Kuka => Box::new(KukaPost(self)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use toolpath::{MoveKind, PathPoint};

    #[test]
    fn every_kind_posts_its_files() {
        let q = |x: f64, kind| PathPoint {
            feature: 0,
            layer: 1,
            kind,
            p: [x, 0.0, 0.2],
            axis: [0.0, 0.0, 1.0],
            e: 0.1,
            thickness: 0.2,
            width: 0.45,
            role: toolpath::Role::Perimeter,
        };
        let path = ToolPath {
            points: vec![q(0.0, MoveKind::Travel), q(5.0, MoveKind::Print)],
        };
        let notes = vec!["features 1.0".to_string(), "setting a = 1".to_string()];
        let job = Job {
            source: "part.step",
            stem: "part",
            notes: &notes,
            ..Job::default()
        };
        for (kind, names) in [
            (MachineKind::Marlin, vec!["program.gcode"]),
            (
                MachineKind::Delta5,
                vec!["program.gcode", "kinematic_error.svg", "joints.csv"],
            ),
            (
                MachineKind::Kuka,
                vec!["part.src", "part.dat", "joints.csv"],
            ),
        ] {
            let m = MachineProfile::builtin(kind);
            let program = m.post().post(&path, &job).unwrap();
            let got: Vec<&str> = program.files.iter().map(|f| f.name.as_str()).collect();
            assert_eq!(got, names, "{kind}");
            // The notes follow the line naming the source in the first program file.
            let text = String::from_utf8_lossy(&program.files[0].bytes).into_owned();
            let lines: Vec<&str> = text.lines().collect();
            let at = lines
                .iter()
                .position(|l| l.starts_with("; generated by features from part.step"))
                .expect("source line");
            assert_eq!(
                lines[at + 1..at + 3],
                ["; features 1.0", "; setting a = 1"],
                "{kind}"
            );
            assert_eq!(program.figures.is_empty(), kind == MachineKind::Marlin);
        }
    }
}
