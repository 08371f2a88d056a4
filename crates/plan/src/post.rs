//! The post stage: the printing time and filament estimated (the program's header gives them
//! first, as slicers do, then the settings), and the machine's program written into the
//! caller's sink, with `toolpath.csv` beside it on another thread.

use crate::estimate::{self, Estimate};
use crate::head::Checked;
use crate::report::SettingsEntry;
use crate::{Options, PlanError};
use robot_post::machine::MachineProfile;
use robot_post::{Job, Program, ProgramSink};
use slicer::params::LayerParams;
use slicer::toolpath::ToolPath;

/// What a program's header is made of: the settings, the estimate of `checked`'s tool path on
/// `machine`, and the notes they give ([`notes`]).
pub fn header(
    checked: &Checked,
    process: &crate::Process,
    machine: &MachineProfile,
) -> (SettingsEntry, Estimate, Vec<String>) {
    let settings = crate::settings::entry(process, machine, &process.base());
    let est = estimate::estimate(&checked.toolpath, machine);
    let notes = notes(&est, checked, &settings);
    (settings, est, notes)
}

/// The header notes of a program: the estimate, the pedestal (when the part stands on one),
/// then every setting.
pub fn notes(est: &Estimate, checked: &Checked, settings: &SettingsEntry) -> Vec<String> {
    let mut notes = vec![
        format!(
            "estimated printing time (normal mode) = {}",
            estimate::hms(est.time_s)
        ),
        format!("filament used [mm] = {:.2}", est.filament_mm),
        format!("filament used [g] = {:.2}", est.filament_g),
    ];
    notes.extend(checked.pedestal.as_ref().map(crate::pedestal::Stood::line));
    notes.extend(settings.lines());
    notes
}

/// The process's settings a G-code viewer reads, in PrusaSlicer's names, for the Marlin
/// program's config block: `perimeters`, `skirts`, `skirt_distance`, `brim_width`,
/// `arc_fitting` (`emit_center` or `disabled`).
pub fn viewer_config(base: &LayerParams) -> Vec<(String, String)> {
    let n = |v: f64| format!("{v}");
    vec![
        ("perimeters".into(), base.perimeters.to_string()),
        ("skirts".into(), base.skirt_loops.to_string()),
        ("skirt_distance".into(), n(base.skirt_distance_mm)),
        ("brim_width".into(), n(base.brim_width_mm)),
        (
            "arc_fitting".into(),
            match base.arc_fitting {
                true => "emit_center",
                false => "disabled",
            }
            .into(),
        ),
    ]
}

/// Runs `work` on this thread while, with `csv`, `toolpath.csv` ([`ToolPath::write_csv`]) is
/// written on another (its blocks of lines made by the thread pool): the estimate and the
/// program's text beside the path's, the bulk of a large plan's writing (NIST CTC-05: the
/// estimate, 0.4 s on one core, no longer waits for an idle one).
pub fn beside_csv<T>(
    toolpath: &ToolPath,
    csv: Option<&mut (dyn std::io::Write + Send)>,
    work: impl FnOnce() -> T,
) -> (T, Result<(), PlanError>) {
    match csv {
        Some(w) => std::thread::scope(|scope| {
            let lines =
                scope.spawn(move || toolpath.write_csv(&mut &mut *w).and_then(|()| w.flush()));
            let out = work();
            // A panic in the writer is a panic of the plan, as on this thread.
            let csv = lines
                .join()
                .unwrap_or_else(|p| std::panic::resume_unwind(p));
            (out, csv.map_err(PlanError::Csv))
        }),
        None => (work(), Ok(())),
    }
}

/// Writes `toolpath`'s program for `machine` into `sink`, headed by `notes` (its config block
/// and arc fitting from the process's `base` parameters, [`viewer_config`]).
pub fn post(
    toolpath: &ToolPath,
    machine: &MachineProfile,
    base: &LayerParams,
    options: &Options,
    notes: &[String],
    sink: &mut dyn ProgramSink,
) -> Result<Program, PlanError> {
    let config = viewer_config(base);
    let job = Job {
        source: &options.source,
        stem: &options.stem,
        notes,
        config: &config,
        arcs: base.arc_fitting.then_some(base.tolerance),
        refused_unreachable: !options.allow_unreachable,
    };
    Ok(machine.post().post_to(toolpath, &job, sink)?)
}

/// A sink that keeps nothing: the post run only for its checks (a refused plan asks whether
/// the machine would also refuse it).
pub struct Discard;

impl ProgramSink for Discard {
    fn file(&mut self, _name: &str) -> std::io::Result<Box<dyn std::io::Write + '_>> {
        Ok(Box::new(std::io::sink()))
    }
}
