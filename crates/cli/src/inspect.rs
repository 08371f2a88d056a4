//! `features inspect`: figures and checks of every solid of a STEP file, as text or JSON.

use crate::{emit, Failure, InspectArgs};
use brep::solid::{report_solid, SolidReport};
use brep::StepPart;
use plan::report::round;
use serde_json::{json, Map, Value};
use std::collections::BTreeMap;
use std::fmt::Write;

/// The file, read and measured.
struct Inspection {
    source: String,
    part: StepPart,
    reports: Vec<SolidReport>,
}

impl Inspection {
    /// Name of the file's length unit (`mm` when the file declares none).
    fn file_units(&self) -> &str {
        self.part
            .brep
            .units
            .first()
            .map(|u| u.name.as_str())
            .unwrap_or("mm")
    }

    /// The reader's warnings, then each solid's findings (prefixed with the solid's `#id`).
    fn warnings(&self) -> Vec<String> {
        let mut w = self.part.brep.warnings.clone();
        for r in &self.reports {
            w.extend(
                r.findings
                    .iter()
                    .map(|f| format!("solid #{}: {f}", r.step_id)),
            );
        }
        w
    }
}

/// Runs the command.
pub fn run(args: &InspectArgs) -> Result<(), Failure> {
    let path = &args.part;
    if meshfile::is_mesh(path) {
        return crate::inspect_mesh::run(args);
    }
    let part = brep::read_step(path).map_err(|e| Failure::new(path, e))?;
    let mut reports = vec![];
    for s in part.brep.solid_ids() {
        let r = report_solid(&part.brep, s).map_err(|e| {
            let id = part.brep.solids[s.idx()].step_id;
            Failure::new(path, format!("solid #{id}: {e}"))
        })?;
        reports.push(r);
    }
    let ins = Inspection {
        source: path.display().to_string(),
        part,
        reports,
    };
    let text = if args.json {
        let mut s = serde_json::to_string_pretty(&to_json(&ins))
            .map_err(|e| Failure::new(path, format!("internal error: {e}")))?;
        s.push('\n');
        s
    } else {
        to_text(&ins)
    };
    emit(&text)
}

fn counts(m: &BTreeMap<String, usize>) -> Value {
    Value::Object(
        m.iter()
            .map(|(k, v)| (k.clone(), json!(v)))
            .collect::<Map<_, _>>(),
    )
}

fn solid_json(r: &SolidReport) -> Value {
    let bbox = if r.bbox.is_empty() {
        Value::Null
    } else {
        let p = |q: &brep::math::P3| json!([round(q.x, 1e4), round(q.y, 1e4), round(q.z, 1e4)]);
        json!([p(&r.bbox.min), p(&r.bbox.max)])
    };
    json!({
        "volume_mm3": round(r.volume, 1e3),
        "area_mm2": round(r.area, 1e3),
        "faces": r.faces,
        "edges": r.edges,
        "vertices": r.vertices,
        "genus": r.genus,
        "closed": r.closed,
        "surfaces": counts(&r.surfaces),
        "bbox": bbox,
        "step_id": r.step_id,
        "curves": counts(&r.curves),
        "voids": r.voids,
        "watertight": r.watertight,
    })
}

fn to_json(ins: &Inspection) -> Value {
    json!({
        "source": ins.source,
        "units": "mm",
        "file_units": ins.file_units(),
        "solids": ins.reports.iter().map(solid_json).collect::<Vec<_>>(),
        "warnings": ins.warnings(),
    })
}

fn yes_no(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}

fn list_counts(m: &BTreeMap<String, usize>) -> String {
    if m.is_empty() {
        return "none".into();
    }
    m.iter()
        .map(|(k, v)| format!("{k} {v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn to_text(ins: &Inspection) -> String {
    let mut s = String::new();
    let schema = if ins.part.schemas.is_empty() {
        "(none declared)".to_string()
    } else {
        ins.part.schemas.join(", ")
    };
    let units = match ins.part.brep.units.first() {
        Some(u) if u.name != "mm" => format!(
            "{} ({} mm per unit; all figures below are in mm)",
            u.name, u.mm_per_unit
        ),
        Some(u) => u.name.clone(),
        None => "mm (none declared)".into(),
    };
    let n = ins.reports.len();
    let _ = writeln!(s, "file:        {}", ins.source);
    let _ = writeln!(s, "schema:      {schema}");
    let _ = writeln!(s, "file units:  {units}");
    let _ = writeln!(s, "solids:      {n}");
    for (i, r) in ins.reports.iter().enumerate() {
        let _ = writeln!(s);
        let _ = writeln!(s, "solid {} of {n} (#{})", i + 1, r.step_id);
        let _ = writeln!(s, "  volume:      {:.3} mm^3", r.volume);
        let _ = writeln!(s, "  area:        {:.3} mm^2", r.area);
        let _ = writeln!(
            s,
            "  topology:    {} faces, {} edges, {} vertices{}",
            r.faces,
            r.edges,
            r.vertices,
            match r.voids {
                0 => String::new(),
                1 => ", 1 void".into(),
                v => format!(", {v} voids"),
            }
        );
        let _ = writeln!(s, "  surfaces:    {}", list_counts(&r.surfaces));
        let _ = writeln!(s, "  curves:      {}", list_counts(&r.curves));
        let genus = match r.genus {
            Some(g) => g.to_string(),
            None => "unknown (shell not closed)".into(),
        };
        let _ = writeln!(s, "  genus:       {genus}");
        let _ = writeln!(s, "  closed:      {}", yes_no(r.closed));
        let _ = writeln!(s, "  watertight:  {}", yes_no(r.watertight));
        if r.bbox.is_empty() {
            let _ = writeln!(s, "  bbox:        empty");
        } else {
            let (a, b) = (r.bbox.min, r.bbox.max);
            // Rounded first, so a coordinate a hair below zero does not print as -0.0000.
            let f = |x: f64| {
                let r = (x * 1e4).round() / 1e4;
                if r == 0.0 {
                    0.0
                } else {
                    r
                }
            };
            let _ = writeln!(
                s,
                "  bbox:        ({:.4}, {:.4}, {:.4}) .. ({:.4}, {:.4}, {:.4}) mm",
                f(a.x),
                f(a.y),
                f(a.z),
                f(b.x),
                f(b.y),
                f(b.z)
            );
            let _ = writeln!(
                s,
                "  size:        {:.4} x {:.4} x {:.4} mm",
                b.x - a.x,
                b.y - a.y,
                b.z - a.z
            );
        }
    }
    warnings_text(&mut s, &ins.warnings());
    s
}

/// The text report's closing lines: a blank line, then `warnings:    none` or the count and
/// one `  - ` line for each (a STEP file's and a mesh file's report alike).
pub(crate) fn warnings_text(s: &mut String, warnings: &[String]) {
    let _ = writeln!(s);
    if warnings.is_empty() {
        let _ = writeln!(s, "warnings:    none");
    } else {
        let _ = writeln!(s, "warnings:    {}", warnings.len());
        for w in warnings {
            let _ = writeln!(s, "  - {w}");
        }
    }
}
