//! Running PrusaSlicer from the benches (`stairstep`, `plan_speed`): the executable
//! (`$PRUSA_SLICER` or `prusa-slicer` on the PATH), the settings matching our plans, one timed
//! `--export-gcode` run. Included by each bench with `#[path = "common/prusa.rs"] mod prusa;`.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

/// The planar slicing settings: the same layers and beads as our plans.
pub struct Settings {
    /// Layer height, first layer included, mm.
    pub layer: f64,
    /// Every extrusion width, mm.
    pub width: f64,
    /// Filament diameter, mm.
    pub filament: f64,
    /// Where the part's XY box centre goes on the bed, mm.
    pub center: (f64, f64),
    /// `--support-material` (automatic supports).
    pub supports: bool,
}

/// How one run went.
pub enum Run {
    /// No executable to run.
    Missing(String),
    /// It ran and failed, or wrote no G-code.
    Failed(String),
    /// It wrote the G-code, taking this many seconds of wall time.
    Done(f64),
}

/// The PrusaSlicer executable: `$PRUSA_SLICER`, or `prusa-slicer` on the PATH.
/// Meshes `step` into the binary STL `stl` with our `features mesh` (`exe`) at 0.01 mm, the
/// part PrusaSlicer is given.
pub fn mesh_stl(exe: &Path, step: &Path, stl: &Path) -> Result<(), String> {
    let m = Command::new(exe)
        .arg("mesh")
        .arg(step)
        .arg("-o")
        .arg(stl)
        .args(["--tolerance", "0.01"])
        .output()
        .map_err(|e| format!("running {}: {e}", exe.display()))?;
    if !m.status.success() {
        return Err(format!(
            "features mesh failed: {}",
            String::from_utf8_lossy(&m.stderr).trim()
        ));
    }
    Ok(())
}

pub fn exe() -> String {
    std::env::var("PRUSA_SLICER").unwrap_or_else(|_| "prusa-slicer".into())
}

/// Slices `stl` into `gcode` with `settings` (PrusaSlicer's defaults otherwise: a 0.4 mm nozzle,
/// 100 % rectilinear fill, 2 classic perimeters, no skirt or brim), then `extra` arguments; the
/// wall time of the whole process.
pub fn slice(stl: &Path, gcode: &Path, settings: &Settings, extra: &[String]) -> Run {
    let exe = exe();
    let w = format!("{}", settings.width);
    let h = format!("{}", settings.layer);
    let mut cmd = Command::new(&exe);
    cmd.args(["--export-gcode", "--loglevel", "1"])
        .args(["--layer-height", &h, "--first-layer-height", &h])
        .args(["--fill-density", "100%", "--fill-pattern", "rectilinear"])
        .args(["--perimeters", "2", "--perimeter-generator", "classic"])
        .args(["--extrusion-width", &w, "--first-layer-extrusion-width", &w])
        .args(["--perimeter-extrusion-width", &w])
        .args(["--external-perimeter-extrusion-width", &w])
        .args(["--infill-extrusion-width", &w])
        .args(["--solid-infill-extrusion-width", &w])
        .args(["--top-infill-extrusion-width", &w])
        .args(["--nozzle-diameter", "0.4", "--filament-diameter"])
        .arg(format!("{}", settings.filament))
        .args(["--skirts", "0", "--brim-width", "0"])
        .arg("--center")
        .arg(format!("{},{}", settings.center.0, settings.center.1));
    if settings.supports {
        cmd.arg("--support-material");
    }
    cmd.args(extra).arg("-o").arg(gcode).arg(stl);
    // A G-code file left from an earlier run must not pass for this one's.
    let _ = std::fs::remove_file(gcode);
    let t = Instant::now();
    let out = match cmd.output() {
        Ok(o) => o,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Run::Missing(format!("{exe} not found"))
        }
        Err(e) => return Run::Failed(format!("running {exe}: {e}")),
    };
    let seconds = t.elapsed().as_secs_f64();
    if !out.status.success() || !gcode.exists() {
        let err = String::from_utf8_lossy(&out.stderr);
        let tail: Vec<&str> = err.lines().rev().take(3).collect();
        return Run::Failed(format!(
            "{exe} exited with {}: {}",
            out.status,
            tail.into_iter().rev().collect::<Vec<_>>().join(" / ")
        ));
    }
    Run::Done(seconds)
}
