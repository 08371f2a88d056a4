//! What the G-code posts (Marlin, delta5) share in writing their programs, and the comment
//! text of every post (KUKA's KRL too).

use toolpath::{push_fixed, MoveKind, PathPoint, Role};

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

/// The layer comments of a G-code program, as slicer viewers (PrusaSlicer's G-code viewer,
/// Cura) read them, written where the point's feature or layer changes (shared by the Marlin
/// and delta5 posts):
///
/// ```text
/// ;LAYER_CHANGE
/// ;Z:<machine Z of the layer's first point>
/// ;HEIGHT:<the layer's thickness>
/// ;LAYER:<layer number over the whole build order, from 0>
/// ;FEATURE:<feature id>            (where the feature changes)
/// ;FEATURE_LAYER:<layer index within the feature, as toolpath.csv's `layer`>
/// ```
///
/// `;TYPE:<role>` before a print move whose path's role ([`Role::prusa_name`]: `External
/// perimeter`, `Perimeter`, `Solid infill`, `Internal infill`, `Gap fill`) differs from the
/// last one written in the layer (so every layer's first print move has one), and
/// `;WIDTH:<bead width>` before a print move whose bead width differs from the last one
/// written by more than half a micrometre.
#[derive(Debug, Default)]
pub(crate) struct LayerMarks {
    layer: Option<usize>,
    feature: Option<usize>,
    /// Layers begun so far over the build order.
    count: usize,
    /// The role of the last `;TYPE:` written in this layer.
    role: Option<Role>,
    width: Option<f64>,
}

impl LayerMarks {
    /// Appends the comment lines `q` starts to `out`; `z` is the point's machine Z.
    pub(crate) fn write(&mut self, q: &PathPoint, z: f64, out: &mut String) {
        let new_feature = self.feature != Some(q.feature);
        if new_feature || self.layer != Some(q.layer) {
            self.layer = Some(q.layer);
            out.push_str(";LAYER_CHANGE\n;Z:");
            push_fixed(out, z, 3);
            out.push_str("\n;HEIGHT:");
            push_fixed(out, q.thickness, 3);
            out.push_str(&format!("\n;LAYER:{}\n", self.count));
            self.count += 1;
            self.role = None;
            if new_feature {
                self.feature = Some(q.feature);
                out.push_str(&format!(";FEATURE:{}\n", q.feature));
            }
            out.push_str(&format!(";FEATURE_LAYER:{}\n", q.layer));
        }
        if q.kind == MoveKind::Print && self.role != Some(q.role) {
            self.role = Some(q.role);
            out.push_str(";TYPE:");
            out.push_str(q.role.prusa_name());
            out.push('\n');
        }
        if q.kind == MoveKind::Print && self.width.is_none_or(|w| (w - q.width).abs() > 5e-4) {
            self.width = Some(q.width);
            out.push_str(";WIDTH:");
            push_fixed(out, q.width, 3);
            out.push('\n');
        }
    }
}
