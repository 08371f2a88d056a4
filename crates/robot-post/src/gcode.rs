//! What the G-code posts (Marlin, delta5) share in writing their programs, and the comment
//! text of every post (KUKA's KRL too).

use crate::machine::MachineProfile;
use toolpath::{push_fixed, push_scaled, MoveKind, PathPoint, Role};

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
        let new_feature = self.feature != Some(q.feature as usize);
        if new_feature || self.layer != Some(q.layer as usize) {
            self.layer = Some(q.layer as usize);
            out.push_str(";LAYER_CHANGE\n;Z:");
            push_fixed(out, z, 3);
            out.push_str("\n;HEIGHT:");
            push_fixed(out, f64::from(q.thickness), 3);
            out.push_str(&format!("\n;LAYER:{}\n", self.count));
            self.count += 1;
            self.role = None;
            if new_feature {
                self.feature = Some(q.feature as usize);
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
        if q.kind == MoveKind::Print
            && self
                .width
                .is_none_or(|w| (w - f64::from(q.width)).abs() > 5e-4)
        {
            self.width = Some(f64::from(q.width));
            out.push_str(";WIDTH:");
            push_fixed(out, f64::from(q.width), 3);
            out.push('\n');
        }
    }
}

/// The part-cooling fan of a G-code program (Marlin and delta5): `M106 S<0..255>` or `M107`
/// where the wanted speed changes, written before the print move that needs it. Beads resting
/// on the build plate get `fan_first_layer`, the others `fan_speed`.
#[derive(Debug)]
pub(crate) struct Fan {
    /// The `S` on the first layer and above it.
    first_layer: u8,
    above: u8,
    /// The `S` written last.
    at: Option<u8>,
}

impl Fan {
    /// The fan of profile `m`, not yet set.
    pub(crate) fn new(m: &MachineProfile) -> Fan {
        Fan {
            first_layer: m.fan_pwm(true),
            above: m.fan_pwm(false),
            at: None,
        }
    }

    /// Writes the fan command for a print move (`first_layer`: its bead rests on the plate)
    /// when the speed changes.
    pub(crate) fn set(&mut self, first_layer: bool, out: &mut String) {
        let s = if first_layer {
            self.first_layer
        } else {
            self.above
        };
        if self.at == Some(s) {
            return;
        }
        self.at = Some(s);
        if s == 0 {
            push_line(out, "M107 ; fan off");
        } else {
            push_line(out, &format!("M106 S{s} ; fan"));
        }
    }
}

/// The E of print moves with cumulative rounding (shared by the Marlin and delta5 posts): the
/// E written adds up to the planned filament, to the 0.00001 mm of the text, however many
/// moves it is split over or merged into.
#[derive(Debug, Default)]
pub(crate) struct Extrusion {
    /// Filament written so far, in 0.00001 mm.
    written: i64,
    /// Filament planned so far (mm).
    planned: f64,
}

impl Extrusion {
    /// Adds `e` mm planned; returns what a move written now would carry (0.00001 mm), not yet
    /// taken as written.
    pub(crate) fn add(&mut self, e: f64) -> i64 {
        self.planned += e;
        (self.planned * 1e5).round() as i64 - self.written
    }

    /// The move carrying `units` is written.
    pub(crate) fn written(&mut self, units: i64) {
        self.written += units;
    }
}

/// Whether a move of `xyz` mm over the part's axes and `rotary` degrees of the rotary axes is
/// too short to stand alone as a print move that extrudes nothing (its E rounds to 0): it is
/// merged into the next move (no G1 is written for it), at most 0.01 mm and 0.01 degrees off
/// the path.
pub(crate) fn mergeable(xyz: f64, rotary: f64) -> bool {
    xyz < 0.01 && rotary < 0.01
}

/// `units` hundred-thousandths of a millimetre as fixed-point text with 5 decimals.
pub(crate) fn e_text(units: i64) -> String {
    let mut s = String::new();
    push_e_text(&mut s, units);
    s
}

/// Appends [`e_text`]`(units)` to `out` without a new allocation.
pub(crate) fn push_e_text(out: &mut String, units: i64) {
    push_scaled(out, units < 0, units.unsigned_abs(), 5);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn e_text_is_fixed_point() {
        assert_eq!(e_text(0), "0.00000");
        assert_eq!(e_text(123_456), "1.23456");
        assert_eq!(e_text(-80_000), "-0.80000");
        assert_eq!(e_text(7), "0.00007");
    }

    /// The digits made by hand read back as the number of units, whatever its size and sign.
    #[test]
    fn e_text_reads_back_as_its_units() {
        let mut x: i64 = 1;
        let mut values = vec![0, 1, -1, 99_999, 100_000, -100_001, i64::MAX, i64::MIN + 1];
        for _ in 0..2000 {
            // A spread of magnitudes from a simple generator.
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            values.push(x >> (x.unsigned_abs() % 60));
        }
        for units in values {
            let text = e_text(units);
            let (int, frac) = text.split_once('.').expect("a decimal point");
            assert_eq!(frac.len(), 5, "{text}");
            let back = int.trim_start_matches('-').parse::<i128>().expect("digits") * 100_000
                + frac.parse::<i128>().expect("digits");
            let back = if text.starts_with('-') { -back } else { back };
            assert_eq!(back, i128::from(units), "{text}");
        }
    }

    #[test]
    fn extrusion_adds_up_over_merged_moves() {
        let mut e = Extrusion::default();
        // Three moves of 0.000004 mm: the first two round to nothing and are merged.
        assert_eq!(e.add(0.000004), 0);
        assert_eq!(e.add(0.000004), 1);
        e.written(1);
        assert_eq!(e.add(0.000004), 0);
        assert_eq!(e.add(1.0), 100_000);
    }
}
