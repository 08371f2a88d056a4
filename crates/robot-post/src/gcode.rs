//! What the G-code posts (Marlin, delta5) share in writing their programs, and the comment
//! text of every post (KUKA's KRL too).

use toolpath::PathPoint;

/// `s` with line breaks and other control characters replaced by spaces, for comments (G-code
/// and KRL alike: a comment never spills onto a new line).
pub(crate) fn comment_text(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// Appends the line `s` and its line break to `out`.
pub(crate) fn push_line(out: &mut String, s: &str) {
    out.push_str(s);
    out.push('\n');
}

/// The `;LAYER:` and `;FEATURE:` comments of a G-code program: written where the point's
/// layer or feature changes (shared by the Marlin and delta5 posts).
#[derive(Debug, Default)]
pub(crate) struct LayerMarks {
    layer: Option<usize>,
    feature: Option<usize>,
}

impl LayerMarks {
    /// Appends the comment lines `q` starts to `out`.
    pub(crate) fn write(&mut self, q: &PathPoint, out: &mut String) {
        if self.layer != Some(q.layer) {
            self.layer = Some(q.layer);
            out.push_str(&format!(";LAYER:{}\n", q.layer));
        }
        if self.feature != Some(q.feature) {
            self.feature = Some(q.feature);
            out.push_str(&format!(";FEATURE:{}\n", q.feature));
        }
    }
}
