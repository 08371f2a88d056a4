//! The last ring of a region a few beads across, with the gap fill beside it and the core
//! inside it, puts down what the region holds there (issue 31, item 4).
//!
//! Where a region is too narrow for a ring's bead and its mirror image (a wall 0.8 mm thick,
//! a pin 2 mm across), the ring narrows to the room between its outer bead edge and the
//! ridge of the distance to the boundary. That ridge is read at the lattice's vertices
//! ([`super::gap::ridge`]), which lie up to a third of a spacing beside it: the half width
//! is underestimated there, by as much as 0.07 mm where the ridge shrinks to a point (a pin's
//! axis). And a ring of small radius runs on its iso-line's chords, shorter than the circle.
//! A 1.76 mm pin's inner ring was laid 0.361 mm wide, not 0.431 mm, on 1.221 mm, not 1.293
//! mm: its layers 6.6 % short; a 0.85 mm wall's 1.7 %. Everything deeper than the last ring's
//! outer bead edge is covered by that ring, the gap fill beside it and the core's: the
//! narrowed beads among them are scaled to put down that area (the lattice's, exact at its
//! vertices and linear between), the full beads kept.

use super::FillPath;
use crate::geom2d::Point2;

/// A bead at least this share of the bead width is a full bead, which [`conserve_core`]
/// leaves as it is (the ring's width where it is not narrowed).
const FULL_BEAD_SHARE: f64 = 0.999;

/// The most [`conserve_core`] scales narrowed beads by: the last ring of a pin 1.66 mm
/// across runs on a polygon of a few lattice chords round a circle 0.3 mm across and needs
/// 1.6 (its layers were 8 % short where it stopped at the core's 1.5).
pub(super) const MAX_LAST_RING_SCALE: f64 = 2.0;

/// The widest a scaled bead gets, in bead widths: what a ring narrowed to its room may be
/// (`GAP_MIN_WIDTH_SHARE` over a bead).
const MAX_SCALED_WIDTH: f64 = 1.1;

/// Scales the beads of `paths` narrowed or widened to their room (other than the bead `width`)
/// so that all of them cover `held` (mm² on the layer surface), segment by segment length
/// (`len`) × mean width, by a factor above 0 and at most `max_scale`, no bead wider than
/// [`MAX_SCALED_WIDTH`] beads; the beads of the nominal width are kept. A ring widened to its
/// room keeps its middle where it was and so stands past a round region's rim more than it
/// leaves bare inside (a pin 1.1 mm across: +6.1 %): it is scaled too. Where every bead is
/// nominal (the core inside a ring too small for any gap fill: a pin 1.05 mm across, −3.0 %),
/// all of them are scaled, by at most [`MAX_NOMINAL_SCALE`] either way, when they miss by
/// more than [`NOMINAL_SLACK`]. Nothing changes where the factor is not positive.
pub(super) fn conserve_core(
    paths: &mut [FillPath],
    held: f64,
    width: f64,
    max_scale: f64,
    len: impl Fn(Point2, Point2) -> f64,
) {
    let (full, wide) = (FULL_BEAD_SHARE * width, width / FULL_BEAD_SHARE);
    let nominal = |w: f64| (full..=wide).contains(&w);
    let (mut covered_nominal, mut covered_other) = (0.0, 0.0);
    for p in paths.iter() {
        for i in 1..p.points.len() {
            let l = len(p.points[i - 1], p.points[i]);
            if !l.is_finite() {
                continue;
            }
            for w in [p.widths[i - 1], p.widths[i]] {
                if nominal(w) {
                    covered_nominal += 0.5 * w * l;
                } else {
                    covered_other += 0.5 * w * l;
                }
            }
        }
    }
    if !held.is_finite() {
        return;
    }
    // The factor, and whether the nominal beads take it too.
    let (k, all) = if covered_other > 0.0 {
        ((held - covered_nominal) / covered_other, false)
    } else if covered_nominal > 0.0 {
        let k = held / covered_nominal;
        if (k - 1.0).abs() <= NOMINAL_SLACK {
            return;
        }
        (k.clamp(1.0 / MAX_NOMINAL_SCALE, MAX_NOMINAL_SCALE), true)
    } else {
        return;
    };
    if k.is_nan() || k <= 0.0 {
        return;
    }
    let k = k.min(max_scale);
    let widest = MAX_SCALED_WIDTH * width;
    for p in paths.iter_mut() {
        for w in p.widths.iter_mut().filter(|w| all || !nominal(**w)) {
            *w = (*w * k).min(widest);
        }
    }
}

/// The most [`conserve_core`] scales beads of the nominal width by, either way, where no other
/// bead can take what they miss.
const MAX_NOMINAL_SCALE: f64 = 1.1;

/// What beads of the nominal width may miss the area they cover by before [`conserve_core`]
/// scales them: the lattice's area is exact at its vertices, linear between.
const NOMINAL_SLACK: f64 = 0.005;

#[cfg(test)]
mod tests {
    use super::super::{fill_flat_region, Boundary};
    use super::*;
    use crate::geom2d::Region;
    use crate::params::LayerParams;

    /// Beads 0.45 mm wide, 0.45 mm apart (the delta5's and Marlin's).
    const BEAD: f64 = 0.45;
    /// What issue 31 asks of features a few beads across.
    const WITHIN: f64 = 0.015;

    fn covered(paths: &[FillPath]) -> f64 {
        paths
            .iter()
            .map(|p| {
                (1..p.points.len())
                    .map(|i| {
                        let (a, b) = (p.points[i - 1], p.points[i]);
                        (b[0] - a[0]).hypot(b[1] - a[1]) * 0.5 * (p.widths[i - 1] + p.widths[i])
                    })
                    .sum::<f64>()
            })
            .sum()
    }

    fn fill(outer: Vec<Point2>) -> Vec<FillPath> {
        let region = Region {
            outer,
            holes: vec![],
        };
        fill_flat_region(
            &region,
            &LayerParams::default(),
            0,
            BEAD,
            BEAD,
            Boundary::Part,
        )
    }

    #[test]
    fn small_pins_are_filled_to_their_area() {
        // A pin 1.76 mm across was 5 % short, 1.66 mm 8.3 % (its ring on the lattice's
        // underestimated ridge and on chords of a small circle; 1.66 mm needs a scale of
        // 1.6). A pin 1.05 mm across was 3.0 % short (a ring round a core too small for any
        // gap fill), 1.1 mm 6.1 % over (its ring widened about its old middle).
        let mut missed = vec![];
        for d in [
            0.9, 0.95, 1.0, 1.05, 1.1, 1.13, 1.15, 1.2, 1.25, 1.3, 1.39, 1.5, 1.66, 1.76, 1.92,
            2.4, 3.0, 4.0,
        ] {
            let r: f64 = 0.5 * d;
            let n = 96;
            let outer: Vec<Point2> = (0..n)
                .map(|i| {
                    let a = i as f64 / n as f64 * std::f64::consts::TAU + 0.1;
                    [3.0 + r * a.cos(), -2.0 + r * a.sin()]
                })
                .collect();
            let area = crate::geom2d::area2(&outer) * 0.5;
            let rel = covered(&fill(outer)) / area - 1.0;
            if rel.abs() > WITHIN {
                missed.push(format!("pin {d} mm across: {:+.2} %", 100.0 * rel));
            }
        }
        assert!(missed.is_empty(), "{}", missed.join("\n"));
    }

    #[test]
    fn thin_walls_are_filled_to_their_area() {
        // A wall 0.85 mm thick was 1.7 % short (its one ring narrowed to the lattice's
        // underestimated half width).
        let (c, s) = (0.4f64.cos(), 0.4f64.sin());
        let rot = |x: f64, y: f64| [x * c - y * s, x * s + y * c];
        for t in [0.6, 0.8, 0.85, 1.0, 1.2, 1.5, 2.0] {
            let l = 12.0;
            let outer = vec![rot(0.0, 0.0), rot(l, 0.0), rot(l, t), rot(0.0, t)];
            let rel = covered(&fill(outer)) / (l * t) - 1.0;
            assert!(rel.abs() <= WITHIN, "wall {t} mm: {:+.2} %", 100.0 * rel);
        }
    }
}
