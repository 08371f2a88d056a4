//! `features inspect` of a mesh file (STL, 3MF, OBJ): each object's triangles, its edges by
//! use (open and non-manifold ones: what keeps it from being planned), whether welding within
//! the process tolerance closes it, its bodies, volume, area and box.

use crate::{emit, Failure, InspectArgs};
use meshfile::edges::{count, EdgeCounts};
use meshfile::measure::{measure, Measures};
use meshfile::weld::weld;
use plan::report::round;
use serde_json::{json, Value};
use std::fmt::Write;

/// One object, measured.
struct Report {
    name: String,
    triangles: usize,
    vertices: usize,
    /// Edges with exactly equal corners joined.
    edges: EdgeCounts,
    /// Edges with corners within the tolerance joined, when exact joining leaves some open or
    /// non-manifold.
    welded: Option<EdgeCounts>,
    /// Bodies, when closed (exactly or welded).
    bodies: Option<usize>,
    measures: Measures,
}

/// Runs the command.
pub fn run(args: &InspectArgs) -> Result<(), Failure> {
    let path = &args.part;
    let file = meshfile::read(path).map_err(|e| Failure::new(path, e))?;
    let tolerance = plan::Process::default().base().tolerance;
    let reports: Vec<Report> = file
        .objects
        .iter()
        .map(|o| {
            let exact = weld(o, 0.0);
            let edges = count(&exact.object.triangles);
            let welded =
                (!edges.closed_manifold()).then(|| count(&weld(o, tolerance).object.triangles));
            let bodies = meshfile::close(o, tolerance).ok().map(|c| c.bodies.len());
            Report {
                name: o.name.clone(),
                triangles: exact.object.triangles.len(),
                vertices: exact.object.positions.len(),
                edges,
                welded,
                bodies,
                measures: measure(&exact.object.positions, &exact.object.triangles),
            }
        })
        .collect();
    let source = path.display().to_string();
    let text = if args.json {
        let mut s = serde_json::to_string_pretty(&to_json(&source, &file, &reports, tolerance))
            .map_err(|e| Failure::new(path, format!("internal error: {e}")))?;
        s.push('\n');
        s
    } else {
        to_text(&source, &file, &reports, tolerance)
    };
    emit(&text)
}

/// What keeps an object from being planned, if anything.
fn warning(r: &Report, tolerance: f64) -> Option<String> {
    let e = r.edges;
    match r.welded {
        None => None,
        Some(w) if w.closed_manifold() => Some(format!(
            "{} open edge(s) and {} non-manifold edge(s), closed by welding vertices within {tolerance} mm (plan and extract do so with a warning)",
            e.open, e.non_manifold
        )),
        Some(w) => Some(format!(
            "not closed and manifold: {} open edge(s) and {} non-manifold edge(s) after welding vertices within {tolerance} mm: plan and extract refuse it",
            w.open, w.non_manifold
        )),
    }
}

fn object_json(r: &Report, tolerance: f64) -> Value {
    let m = &r.measures;
    let p = |q: &[f64; 3]| q.map(|x| round(x, 1e4));
    json!({
        "name": r.name,
        "triangles": r.triangles,
        "vertices": r.vertices,
        "edges": r.edges.edges,
        "open_edges": r.edges.open,
        "non_manifold_edges": r.edges.non_manifold,
        "welded": r.welded.map(|w| json!({"tolerance_mm": tolerance, "open_edges": w.open, "non_manifold_edges": w.non_manifold})),
        "closed": r.bodies.is_some(),
        "bodies": r.bodies,
        "volume_mm3": round(m.volume.abs(), 1e3),
        "area_mm2": round(m.area, 1e3),
        "bbox": [p(&m.min), p(&m.max)],
    })
}

fn to_json(source: &str, file: &meshfile::MeshFile, reports: &[Report], tolerance: f64) -> Value {
    json!({
        "source": source,
        "format": file.format.name(),
        "units": "mm",
        "file_units": file.unit.0,
        "objects": reports.iter().map(|r| object_json(r, tolerance)).collect::<Vec<_>>(),
        "warnings": reports.iter().filter_map(|r| warning(r, tolerance)).collect::<Vec<_>>(),
    })
}

fn to_text(source: &str, file: &meshfile::MeshFile, reports: &[Report], tolerance: f64) -> String {
    let mut s = String::new();
    let n = reports.len();
    let units = if file.unit.1 == 1.0 {
        "mm".to_string()
    } else {
        format!(
            "{} ({} mm per unit; all figures below are in mm)",
            file.unit.0, file.unit.1
        )
    };
    let _ = writeln!(s, "file:        {source}");
    let _ = writeln!(s, "format:      {}", file.format.name());
    let _ = writeln!(s, "file units:  {units}");
    let _ = writeln!(s, "objects:     {n}");
    let mut warnings = vec![];
    for (i, r) in reports.iter().enumerate() {
        let m = &r.measures;
        let _ = writeln!(s);
        let name = if r.name.is_empty() {
            String::new()
        } else {
            format!(" (`{}`)", r.name)
        };
        let _ = writeln!(s, "object {} of {n}{name}", i + 1);
        let _ = writeln!(s, "  volume:      {:.3} mm^3", m.volume.abs());
        let _ = writeln!(s, "  area:        {:.3} mm^2", m.area);
        let _ = writeln!(
            s,
            "  mesh:        {} triangles, {} edges, {} vertices",
            r.triangles, r.edges.edges, r.vertices
        );
        let _ = writeln!(
            s,
            "  edges:       {} open, {} non-manifold",
            r.edges.open, r.edges.non_manifold
        );
        let closed = match (r.bodies, r.welded) {
            (Some(b), None) => format!("yes, {b} body(ies)"),
            (Some(b), Some(_)) => format!("yes once welded within {tolerance} mm, {b} body(ies)"),
            (None, _) => "no".into(),
        };
        let _ = writeln!(s, "  closed:      {closed}");
        let f = |x: f64| round(x, 1e4);
        let (a, b) = (m.min, m.max);
        let _ = writeln!(
            s,
            "  bbox:        ({:.4}, {:.4}, {:.4}) .. ({:.4}, {:.4}, {:.4}) mm",
            f(a[0]),
            f(a[1]),
            f(a[2]),
            f(b[0]),
            f(b[1]),
            f(b[2])
        );
        let _ = writeln!(
            s,
            "  size:        {:.4} x {:.4} x {:.4} mm",
            b[0] - a[0],
            b[1] - a[1],
            b[2] - a[2]
        );
        if let Some(w) = warning(r, tolerance) {
            warnings.push(format!("object {}: {w}", i + 1));
        }
    }
    crate::inspect::warnings_text(&mut s, &warnings);
    s
}
