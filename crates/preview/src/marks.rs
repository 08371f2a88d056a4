//! The failures of a refused plan, marked in red over the view and listed in the page's
//! "Problems" panel: where the head hits, which beads hang in the air, which points the machine
//! cannot reach.

use crate::encode::{base64_f32, base64_u32};

/// Marks drawn and listed at most; the page says how many more there were.
pub const MAX_MARKS: usize = 20_000;

/// Points of one mark drawn at most; a longer polyline is thinned for the view (every k-th
/// point, both ends kept).
pub const MAX_MARK_POINTS: usize = 2_000;

/// What failed at a [`Mark`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MarkKind {
    /// The head meets the part, the deposit or the table on a move.
    Collision,
    /// A bead or a region with nothing under it (its outline is drawn closed).
    Unsupported,
    /// A point out of the machine's reach or joint limits.
    Unreachable,
    /// The self-check (the deposited volume against the feature's) failed.
    SelfCheck,
    /// A machine limit: the work envelope, an axis limit, the bed.
    Machine,
}

impl MarkKind {
    /// The kind's name in the Problems panel: `collision`, `unsupported`, `unreachable`,
    /// `self-check` or `machine`.
    pub fn name(self) -> &'static str {
        match self {
            MarkKind::Collision => "collision",
            MarkKind::Unsupported => "unsupported",
            MarkKind::Unreachable => "unreachable",
            MarkKind::SelfCheck => "self-check",
            MarkKind::Machine => "machine",
        }
    }

    /// Whether a polyline of this kind is drawn closed (an outline of a region).
    fn closed(self) -> bool {
        self == MarkKind::Unsupported
    }
}

/// One failure, drawn in red on top of everything and listed by its text.
#[derive(Debug, Clone, PartialEq)]
pub struct Mark {
    /// What failed.
    pub kind: MarkKind,
    /// The feature (file-wide id, as [`crate::FeatureMesh::id`]) it belongs to, if one.
    pub feature: Option<usize>,
    /// What the Problems panel says (one line: `move 812 of feature 3: the body meets the
    /// table 4.2 mm deep`).
    pub text: String,
    /// Where, in the tool path's frame (part coordinates, mm): one point is drawn as a dot (a
    /// square of fixed screen size), two as a thick segment (a move), more as a thick polyline,
    /// closed for [`MarkKind::Unsupported`] (a region's outline). None: listed, not drawn.
    pub points: Vec<[f64; 3]>,
}

/// The points of a mark the view draws: all of them up to [`MAX_MARK_POINTS`], else every
/// k-th and the last.
fn drawn_points(points: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let n = points.len();
    if n <= MAX_MARK_POINTS {
        return points.to_vec();
    }
    let k = n.div_ceil(MAX_MARK_POINTS - 1);
    let mut out: Vec<[f64; 3]> = points.iter().step_by(k).copied().collect();
    if (n - 1) % k != 0 {
        out.push(points[n - 1]);
    }
    out
}

/// The marks as the viewer reads them: `list` (kind, feature or -1, text, closed, the first of
/// its points and their count, the centre to look at) over one base64 f32 array of points,
/// the first [`MAX_MARKS`] of them, and how many were left out.
pub(crate) fn marks_json(marks: &[Mark]) -> serde_json::Value {
    let shown = &marks[..marks.len().min(MAX_MARKS)];
    let mut xyz: Vec<f32> = vec![];
    let mut at: Vec<u32> = vec![];
    let mut list = Vec::with_capacity(shown.len());
    for m in shown {
        let pts = drawn_points(&m.points);
        let finite: Vec<&[f64; 3]> = pts
            .iter()
            .filter(|p| p.iter().all(|x| x.is_finite()))
            .collect();
        let centre = (!finite.is_empty()).then(|| {
            let mut c = [0.0; 3];
            for p in &finite {
                for k in 0..3 {
                    c[k] += p[k] / finite.len() as f64;
                }
            }
            c
        });
        at.push((xyz.len() / 3) as u32);
        at.push(pts.len() as u32);
        xyz.extend(pts.iter().flatten().map(|&x| x as f32));
        list.push(serde_json::json!({
            "kind": m.kind.name(),
            "feature": m.feature.map_or(-1, |f| f as i64),
            "text": m.text,
            "closed": m.kind.closed() && pts.len() > 2,
            "centre": centre,
        }));
    }
    serde_json::json!({
        "list": list,
        "at": base64_u32(&at),
        "xyz": base64_f32(&xyz),
        "left_out": marks.len() - shown.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_polylines_are_thinned_keeping_both_ends() {
        let n = 3 * MAX_MARK_POINTS + 5;
        let pts: Vec<[f64; 3]> = (0..n).map(|i| [i as f64, 0.0, 0.0]).collect();
        let d = drawn_points(&pts);
        assert!(d.len() <= MAX_MARK_POINTS);
        assert_eq!(d.first(), pts.first());
        assert_eq!(d.last(), pts.last());
        // Short ones are drawn whole.
        assert_eq!(drawn_points(&pts[..7]), pts[..7].to_vec());
    }

    #[test]
    fn marks_beyond_the_limit_are_counted_not_drawn() {
        let marks: Vec<Mark> = (0..MAX_MARKS + 3)
            .map(|i| Mark {
                kind: MarkKind::Collision,
                feature: Some(i % 4),
                text: format!("move {i}"),
                points: vec![[i as f64, 0.0, 0.0]],
            })
            .collect();
        let j = marks_json(&marks);
        assert_eq!(j["left_out"], 3);
        assert_eq!(j["list"].as_array().map(Vec::len), Some(MAX_MARKS));
    }

    #[test]
    fn a_region_is_closed_and_its_centre_is_the_mean_of_finite_points() {
        let m = Mark {
            kind: MarkKind::Unsupported,
            feature: None,
            text: "layer 3: 12.5 mm² unsupported".into(),
            points: vec![
                [0.0, 0.0, 1.0],
                [2.0, 0.0, 1.0],
                [2.0, 2.0, 1.0],
                [f64::NAN, 0.0, 0.0],
                [0.0, 2.0, 1.0],
            ],
        };
        let j = marks_json(&[m]);
        let e = &j["list"][0];
        assert_eq!(e["closed"], true);
        assert_eq!(e["feature"], -1);
        let c: Vec<f64> = (0..3).filter_map(|k| e["centre"][k].as_f64()).collect();
        assert_eq!(c, vec![1.0, 1.0, 1.0]);
    }
}
