//! preview: one self-contained HTML file (`preview.html`) that draws a part's features and its
//! planned tool path with WebGL in any current browser, offline: the viewer's script, its
//! styles and the data are all inline; the file names no other file and no address.
//!
//! - the features' meshes, translucent, one colour each, toggled one by one; with a machining
//!   allowance ([`MeshAllowance`]), the nominal surface coloured by the allowance the beads
//!   leave over it (warm where least, cool where most, grey where nothing was measured);
//! - the tool path as lines, print and travel told apart (travel hidden at first), a range of
//!   layers over the whole build order, coloured by feature, layer or local layer thickness,
//!   support material's beads in a colour of their own (green);
//! - tool axes as short ticks at a chosen density; orbit (drag), pan (shift-drag or right-drag)
//!   and zoom (wheel); a legend and the plan's figures beside the view.
//!
//! A refused plan's page also shows why: its failures ([`Mark`]s) in red over everything and
//! listed in a "Problems" panel (a click centres the view on one), the machine's bed or table
//! ([`MachineShape`]) and the head at the first failure ([`HeadShape`]), and a "refused" line
//! over the figures. Red is kept for them: no feature colour or colour ramp is red.
//!
//! With a [`Simulation`] the page has a simulation view (issue 36 item 2): a scrubber over the
//! program's moves that draws, at each, the head at the tool tip and the machine around it (a
//! KUKA arm by its OPW forward kinematics, delta5's table tilted by B and turned by C), the
//! joints and the move's number in a panel, and the moves near a joint limit, near the wrist
//! singularity or in collision marked on the path and listed ("Machine"). The machine is orange,
//! a colour nothing else is drawn in. `preview.html#sim=F` opens it at the fraction F (0 to 1)
//! of the moves.
//!
//! What is drawn is decimated, never what is printed: at most [`MAX_DRAWN_POINTS`] path points
//! (every k-th point of a long run, the ends of every path kept) and the meshes as the caller
//! gives them (coarse).

#![warn(missing_docs)]

mod encode;
mod machine;
mod marks;
mod simulation;
mod tolerance;

use encode::{base64_f32, base64_u32};
pub use machine::{HeadShape, HeadSize, MachineShape};
pub use marks::{Mark, MarkKind, MAX_MARKS, MAX_MARK_POINTS};
pub use simulation::{
    SimArm, SimFlags, SimMachine, SimMargins, SimMove, SimTable, Simulation, MAX_SIM_FLAGGED,
    MAX_SIM_MOVES, NEAR_LIMIT_DEG, NEAR_SINGULARITY_DEG,
};
use std::fmt::Write as _;
use toolpath::{MoveKind, ToolPath};

/// Path points drawn at most; longer paths are thinned for the view only.
pub const MAX_DRAWN_POINTS: usize = 400_000;

/// The viewer (styles and script), inlined into every preview.
const VIEWER_HTML: &str = include_str!("viewer.html");

/// The simulation view's script, inlined into the viewer's at its `/*__SIMULATION__*/`.
const SIMULATION_JS: &str = include_str!("simulation.js");

/// One feature's surface, triangulated for the view.
#[derive(Debug, Clone, Default)]
pub struct FeatureMesh {
    /// The feature's file-wide id.
    pub id: usize,
    /// Its label in the legend (`two5d`, `freeform on cone face #54`, ...).
    pub label: String,
    /// Vertex positions, mm.
    pub positions: Vec<[f32; 3]>,
    /// Triangles over `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// The machining allowance left over each vertex, if the feature has one.
    pub allowance: Option<MeshAllowance>,
}

/// A feature's nominal surface coloured by the machining allowance its beads leave (issue 37,
/// item 2).
#[derive(Debug, Clone, Default)]
pub struct MeshAllowance {
    /// `machining_allowance` asked for, mm.
    pub requested: f32,
    /// The allowance left over each vertex of the mesh (one per position), mm; NaN where
    /// nothing was measured (the build plate, a face shared with another feature, a face a
    /// child feature covers).
    pub left: Vec<f32>,
}

/// What a preview shows.
#[derive(Debug, Clone, Default)]
pub struct Preview<'a> {
    /// The title (the part's file).
    pub title: String,
    /// The features, in build order.
    pub features: Vec<FeatureMesh>,
    /// The planned path, if there is a plan.
    pub path: Option<&'a ToolPath>,
    /// Figures shown beside the view: (name, value) in order.
    pub figures: Vec<(String, String)>,
    /// Why the plan was refused, shown first among the figures as `refused: <reason>` (when
    /// this is `None` but there are marks: `refused: see Problems`).
    pub refusal: Option<String>,
    /// The failures, in the tool path's frame: drawn in red over everything (no depth test)
    /// and listed in the Problems panel, the first [`MAX_MARKS`] of them (the panel says how
    /// many more there were).
    pub marks: Vec<Mark>,
    /// The machine's bed or turning table, in the tool path's frame, drawn grey and
    /// translucent.
    pub machine: Option<MachineShape>,
    /// The print head (at the first failure), in the tool path's frame, drawn red and
    /// translucent with a wire frame.
    pub head: Option<HeadShape>,
    /// The machine's moves for the simulation view (a scrubber over them), if the caller
    /// computed its joints.
    pub simulation: Option<Simulation>,
}

/// The preview as one HTML document.
pub fn html(p: &Preview) -> String {
    let mut page = Vec::new();
    // Writing to memory cannot fail, and the page is UTF-8 (its pieces are `str`s, and the
    // JSON serialiser writes UTF-8).
    let _ = write_html(p, &mut page);
    String::from_utf8(page).unwrap_or_default()
}

/// [`html`] written into `w` as it is made: the page's data (its JSON, most of a large plan's
/// page) is serialised straight into `w`, never held as text beside the page (NIST CTC-05's
/// 24 MB page took 90 MB more than the plan while it was made, as a string, its copy with
/// `</` escaped and the page around it).
pub fn write_html(p: &Preview, w: &mut dyn std::io::Write) -> std::io::Result<()> {
    let title = escape(&p.title);
    let page = VIEWER_HTML
        .replace("/*__SIMULATION__*/", SIMULATION_JS)
        .replace("__TITLE__", &title);
    let (head, tail) = page.split_once("__DATA__").unwrap_or((&page, ""));
    w.write_all(head.as_bytes())?;
    let mut data = ScriptSafe { w, after_lt: false };
    serde_json::to_writer(&mut data, &data_json(p)).map_err(std::io::Error::other)?;
    w.write_all(tail.as_bytes())
}

/// A writer for text inside a `<script>` element: `</` (which would close it early) is
/// written `<\/`, which JSON reads as the same string, across the pieces it is handed too.
struct ScriptSafe<'w> {
    w: &'w mut dyn std::io::Write,
    /// Whether the last byte written was `<`.
    after_lt: bool,
}

impl std::io::Write for ScriptSafe<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let mut from = 0;
        for (i, &b) in buf.iter().enumerate() {
            let lt_before = if i == 0 {
                self.after_lt
            } else {
                buf[i - 1] == b'<'
            };
            if b == b'/' && lt_before {
                self.w.write_all(&buf[from..i])?;
                self.w.write_all(b"\\")?;
                from = i;
            }
        }
        self.w.write_all(&buf[from..])?;
        if let Some(&last) = buf.last() {
            self.after_lt = last == b'<';
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.w.flush()
    }
}

/// The points of `path` the view draws: every point where the feature, layer or move kind
/// changes and the points on either side, and every k-th point of the runs between.
fn drawn(path: &ToolPath) -> Vec<usize> {
    let n = path.points.len();
    let k = n.div_ceil(MAX_DRAWN_POINTS).max(1);
    let same = |a: usize, b: usize| {
        let (p, q) = (&path.points[a], &path.points[b]);
        p.feature == q.feature && p.layer == q.layer && p.kind == q.kind
    };
    (0..n)
        .filter(|&i| {
            k == 1 || i % k == 0 || i == 0 || i + 1 == n || !same(i - 1, i) || !same(i, i + 1)
        })
        .collect()
}

/// The data the viewer reads: JSON with base64 arrays of little-endian f32 and u32.
fn data_json(p: &Preview) -> serde_json::Value {
    let figures: Vec<serde_json::Value> = p
        .figures
        .iter()
        .map(|(k, v)| serde_json::json!([k, v]))
        .collect();
    let refusal = match (&p.refusal, p.marks.is_empty()) {
        (Some(r), _) => serde_json::json!(r),
        (None, false) => serde_json::json!("see Problems"),
        (None, true) => serde_json::Value::Null,
    };
    // The path's points drawn, which the simulation's moves refer to as well.
    let drawn_points = p.path.map(drawn).unwrap_or_default();
    serde_json::json!({
        "title": p.title,
        "features": meshes_json(&p.features),
        "path": p.path.map_or(serde_json::Value::Null, |tp| path_json(tp, &drawn_points)),
        "figures": figures,
        "max_drawn_points": MAX_DRAWN_POINTS,
        "refusal": refusal,
        "marks": marks::marks_json(&p.marks),
        "machine": p.machine.as_ref().map_or(serde_json::Value::Null, |m| machine::machine_overlay(m).json()),
        "head": p.head.as_ref().map_or(serde_json::Value::Null, head_json),
        "simulation": p.simulation.as_ref().map_or(serde_json::Value::Null, |s| simulation::json::simulation_json(s, p.path, &drawn_points)),
    })
}

/// The head as the viewer reads it: its overlay and its tip (which the view frames).
fn head_json(h: &HeadShape) -> serde_json::Value {
    let mut j = machine::head_overlay(h).json();
    if let Some(o) = j.as_object_mut() {
        o.insert("tip".into(), serde_json::json!(h.tip));
    }
    j
}

/// The features' meshes as the viewer reads them.
fn meshes_json(features: &[FeatureMesh]) -> Vec<serde_json::Value> {
    features
        .iter()
        .map(|f| {
            let pos: Vec<f32> = f.positions.iter().flatten().copied().collect();
            let tri: Vec<u32> = f.triangles.iter().flatten().copied().collect();
            let allowance = f
                .allowance
                .as_ref()
                .filter(|a| a.left.len() == f.positions.len());
            serde_json::json!({
                "id": f.id,
                "label": f.label,
                "positions": base64_f32(&pos),
                "triangles": base64_u32(&tri),
                "allowance": allowance.map_or(serde_json::Value::Null, |a| serde_json::json!({
                    "requested": a.requested,
                    "left": base64_f32(&a.left),
                })),
            })
        })
        .collect()
}

/// The drawn points of the path as the viewer reads them.
fn path_json(tp: &ToolPath, keep: &[usize]) -> serde_json::Value {
    // A layer number over the whole build order: it counts up where the feature or its
    // layer changes (counted over every point, kept for the drawn ones).
    let mut count = 0u32;
    let mut global = Vec::with_capacity(keep.len());
    let mut kept = keep.iter().peekable();
    for (i, b) in tp.points.iter().enumerate() {
        if i > 0 {
            let a = &tp.points[i - 1];
            if a.feature != b.feature || a.layer != b.layer {
                count += 1;
            }
        }
        while kept.next_if(|&&k| k == i).is_some() {
            global.push(count);
        }
    }
    let mut xyz = Vec::with_capacity(3 * keep.len());
    let mut axis = Vec::with_capacity(3 * keep.len());
    let mut thick = Vec::with_capacity(keep.len());
    let mut info = Vec::with_capacity(3 * keep.len());
    for (&i, &layer) in keep.iter().zip(&global) {
        let q = &tp.points[i];
        xyz.extend(q.p.map(|x| x as f32));
        axis.extend(q.axis.map(|x| x as f32));
        thick.push(q.thickness);
        info.push(q.feature);
        info.push(layer);
        // 0 travel, 1 the part's bead, 2 support material's.
        info.push(match q.kind {
            MoveKind::Print if q.role.is_support() => 2,
            MoveKind::Print => 1,
            MoveKind::Travel => 0,
        });
    }
    serde_json::json!({
        "points": keep.len(),
        "planned_points": tp.points.len(),
        "xyz": base64_f32(&xyz),
        "axis": base64_f32(&axis),
        "thickness": base64_f32(&thick),
        "info": base64_u32(&info),
        "layers": count + 1,
    })
}

/// Text for HTML.
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            '"' => out.push_str("&quot;"),
            c => {
                let _ = write!(out, "{c}");
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use toolpath::PathPoint;

    #[test]
    fn a_closing_tag_in_the_data_is_escaped_across_the_pieces_it_is_written_in() {
        let mut out = Vec::new();
        let mut w = ScriptSafe {
            w: &mut out,
            after_lt: false,
        };
        for piece in ["{\"t\":\"a<", "/script>", "</b>/<", "", "/\"}"] {
            std::io::Write::write_all(&mut w, piece.as_bytes()).unwrap();
        }
        let text = String::from_utf8(out).unwrap();
        assert_eq!(text, r#"{"t":"a<\/script><\/b>/<\/"}"#);
        let back: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(back["t"], "a</script></b>/</");
        // A title that would close the data's element is read back whole from the page.
        let page = html(&Preview {
            title: "x</script><b>".into(),
            ..Preview::default()
        });
        let data = page
            .split_once(r#"<script id="data" type="application/json">"#)
            .and_then(|(_, rest)| rest.split_once("</script>"))
            .map(|(data, _)| data)
            .unwrap();
        let json: serde_json::Value = serde_json::from_str(data).unwrap();
        assert_eq!(json["title"], "x</script><b>");
    }

    fn point(feature: usize, layer: usize, x: f64, kind: MoveKind) -> PathPoint {
        PathPoint {
            feature: feature as u32,
            layer: layer as u32,
            kind,
            p: [x, 0.0, 0.2],
            axis: [0.0, 0.0, 1.0],
            e: 0.0,
            thickness: 0.2,
            width: 0.45,
            role: toolpath::Role::Perimeter,
        }
    }

    #[test]
    fn the_page_is_self_contained() {
        let path = ToolPath {
            points: vec![
                point(0, 0, 0.0, MoveKind::Travel),
                point(0, 0, 1.0, MoveKind::Print),
            ],
        };
        let page = html(&Preview {
            title: "a <part>.step".into(),
            features: vec![FeatureMesh {
                id: 0,
                label: "two5d".into(),
                positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                triangles: vec![[0, 1, 2]],
                allowance: Some(MeshAllowance {
                    requested: 1.0,
                    left: vec![1.0, 1.5, f32::NAN],
                }),
            }],
            path: Some(&path),
            figures: vec![("features".into(), "1".into())],
            ..Preview::default()
        });
        assert!(page.starts_with("<!DOCTYPE html>"));
        assert!(page.contains("a &lt;part&gt;.step"));
        // Nothing fetched: no addresses, no protocol-relative references, no external files.
        for bad in ["http:", "https:", "//", " src=", "<link"] {
            assert!(!page.contains(bad), "the page holds `{bad}`");
        }
        assert!(!page.contains("__DATA__") && !page.contains("__TITLE__"));
    }

    #[test]
    fn long_paths_are_thinned_for_the_view_keeping_every_change() {
        let n = 3 * MAX_DRAWN_POINTS + 7;
        let points = (0..n)
            .map(|i| {
                let kind = if i % 1000 == 0 {
                    MoveKind::Travel
                } else {
                    MoveKind::Print
                };
                point(i / 500_000, (i / 10_000) % 50, i as f64, kind)
            })
            .collect();
        let path = ToolPath { points };
        let keep = drawn(&path);
        assert!(keep.len() <= MAX_DRAWN_POINTS + 4 * (n / 1000 + 2) + 2 * (n / 10_000 + 2));
        assert_eq!(keep.first(), Some(&0));
        assert_eq!(keep.last(), Some(&(n - 1)));
        // Every travel and the point before it are kept.
        for i in (1000..n).step_by(1000) {
            assert!(keep.binary_search(&i).is_ok() && keep.binary_search(&(i - 1)).is_ok());
        }
    }
}
