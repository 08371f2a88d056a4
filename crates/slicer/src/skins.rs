//! Solid skins of planar layers (issue 33), as slicers find them: the part of a layer's
//! section that is not covered by every one of the `top_solid_layers` layers above it and the
//! `bottom_solid_layers` layers below it. A layer near the feature's first or last layer is
//! all skin (nothing lies beyond them), and so is the part of a layer under a step or over a
//! shoulder inside the feature, not only its first and last layers.

use crate::fill::{difference, grow, intersection, shrink_regions, Region};
use rayon::prelude::*;

/// Each layer's solid skin, for layers whose sections are `sections` (bottom up): the part of
/// layer i's section outside the intersection of the sections of layers `i − bottom ..= i +
/// top` other than i (a layer outside the feature is empty: a layer within `bottom` of the
/// first or `top` of the last is all skin). `same[i]` says layer i's section is the same
/// polygon as layer i + 1's: a window of such layers has no skin, and no boolean is made
/// for it (a prism's layers). The skin is opened by half a bead (`width`, chords within `tol`):
/// slivers thinner than a bead, where a wall's section moves by a hair from layer to layer,
/// stay sparse; what is left reaches [`SKIN_ANCHOR`] on into the layer's section.
pub(crate) fn skins(
    sections: &[Vec<Region>],
    same: &[bool],
    top: usize,
    bottom: usize,
    width: f64,
    tol: f64,
) -> Vec<Vec<Region>> {
    let n = sections.len();
    (0..n)
        .into_par_iter()
        .with_max_len(1)
        .map(|i| {
            let own = &sections[i];
            if own.is_empty() || (top == 0 && bottom == 0) {
                return vec![];
            }
            if i < bottom || i + top >= n {
                return own.clone();
            }
            let (lo, hi) = (i - bottom, i + top);
            if same[lo..hi].iter().all(|&s| s) {
                return vec![];
            }
            let mut cover: Option<Vec<Region>> = None;
            for (j, s) in sections.iter().enumerate().take(hi + 1).skip(lo) {
                if j == i {
                    continue;
                }
                let next = match cover {
                    None => s.clone(),
                    Some(c) => intersection(&c, s),
                };
                let empty = next.is_empty();
                cover = Some(next);
                if empty {
                    break;
                }
            }
            let skin = difference(own, &cover.unwrap_or_default());
            let half = 0.5 * width;
            let opened = grow(&shrink_regions(&skin, half, tol), half, tol);
            if opened.is_empty() {
                return opened;
            }
            intersection(&grow(&opened, SKIN_ANCHOR, tol), own)
        })
        .collect()
}

/// How far (mm) a skin reaches on into the sparse part of its layer, where it lies over or
/// under sparse lines: its edge then rests on them, not on one line's span (PrusaSlicer's
/// external infill margin, 3 mm).
pub(crate) const SKIN_ANCHOR: f64 = 3.0;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom2d::shapes::{area, rect};

    /// A plate 10 layers high with a boss on layers 6..10: the plate's bottom three layers are
    /// skin, its top three under the boss's step only where the boss does not cover it, and
    /// the boss's last four layers whole.
    #[test]
    fn a_step_inside_a_feature_gets_its_skin() {
        let plate = vec![rect(0.0, 0.0, 20.0, 20.0)];
        let boss = vec![rect(5.0, 5.0, 15.0, 15.0)];
        let sections: Vec<Vec<Region>> = (0..14)
            .map(|k| if k < 6 { plate.clone() } else { boss.clone() })
            .collect();
        let same: Vec<bool> = (0..13).map(|k| k != 5).collect();
        let s = skins(&sections, &same, 4, 3, 0.45, 0.01);
        let a: Vec<f64> = s.iter().map(|r| area(r)).collect();
        for (k, &x) in a.iter().enumerate() {
            let want = match k {
                0..=2 => 400.0,
                // The step's skin reaches 3 mm under the boss: all but its middle 4 x 4 mm.
                3..=5 => 384.0,
                6..=9 => 0.0,
                _ => 100.0,
            };
            assert!((x - want).abs() < 1.0, "layer {k}: {x} mm^2, not {want}");
        }
    }
}
