//! Sparse infill with solid skins (issue 33): the interior a planar layer's perimeters leave
//! is split into its solid skin (given by the planner, [`SparseLayer::skin`]) and the rest,
//! which gets lines of the feature's [`InfillPattern`] `bead width / infill_density` apart
//! (as PrusaSlicer's sparse infill: the share of the area a pattern's beads cover is the
//! density).
//!
//! Every pattern lies on a grid fixed in the layer's plane (not centred on each region), so the
//! lines of one layer stand on the lines of the layer below: rectilinear lines turn 90° every
//! other layer, grid and triangle lines repeat on every layer, and gyroid lines are the section
//! of one gyroid surface at each layer's height.

use super::offset::simplify_line;
use super::{Path2, PathKind, Shapes};
use crate::geom2d::{Point2, Region};
use crate::params::{InfillPattern, LayerParams};
use crate::toolpath::Role;
use i_overlay::core::fill_rule::FillRule;
use i_overlay::float::clip::FloatClip;
use i_overlay::string::clip::ClipRule;
use std::f64::consts::PI;

/// What a planar layer's sparse infill needs from its planner: the solid skin of the layer and
/// its height.
#[derive(Debug, Clone, Copy)]
pub struct SparseLayer<'a> {
    /// The part of the layer within `top_solid_layers` of a top surface or
    /// `bottom_solid_layers` of a bottom one: filled solid. The rest of the interior is sparse.
    pub skin: &'a [Region],
    /// Height of the layer's middle over the feature's reference plane, mm (the gyroid's z).
    pub z: f64,
}

/// Gyroid samples per period along a wave line.
const GYROID_SAMPLES: usize = 32;
/// Heights (per period) over which the gyroid's mean line length is taken.
const GYROID_HEIGHTS: usize = 256;

/// The lines of the `infill_pattern` of `params` at its `infill_density` for beads `width`
/// wide, over `area` (the sparse part of a layer's interior, i_overlay shapes), for layer
/// number `layer` at height `z`, the pattern turned by `raster_angle_deg`. Each line is
/// clipped to the area and is its own path, role [`Role::InternalInfill`], simplified within
/// the feature's `tolerance` (the chord error its curved boundaries get).
pub(super) fn pattern_lines(
    area: &Shapes,
    params: &LayerParams,
    layer: usize,
    z: f64,
    width: f64,
) -> Vec<Path2> {
    let tol = params.tolerance;
    let (pattern, density) = (params.infill_pattern, params.infill_density);
    let angle = params.raster_angle_deg.to_radians();
    if area.is_empty() || !(density > 0.0 && width > 0.0) {
        return vec![];
    }
    let spacing = width / density;
    let Some((lo, hi)) = extent(area) else {
        return vec![];
    };
    let families: Vec<Vec<Vec<Point2>>> = match pattern {
        InfillPattern::Rectilinear => {
            let turn = if layer % 2 == 1 { 0.5 * PI } else { 0.0 };
            vec![straight(lo, hi, angle + turn, spacing)]
        }
        InfillPattern::Grid => (0..2)
            .map(|k| straight(lo, hi, angle + k as f64 * 0.5 * PI, 2.0 * spacing))
            .collect(),
        InfillPattern::Triangles => (0..3)
            .map(|k| straight(lo, hi, angle + k as f64 * PI / 3.0, 3.0 * spacing))
            .collect(),
        InfillPattern::Gyroid => vec![gyroid(lo, hi, z, width, density)],
    };
    let rule = ClipRule {
        invert: false,
        boundary_included: false,
    };
    let mut out = vec![];
    for line in families.into_iter().flatten() {
        for piece in line.clip_by(area, FillRule::NonZero, rule) {
            if piece.len() >= 2 {
                out.push(Path2 {
                    points: simplify_line(&piece, tol),
                    kind: PathKind::Infill,
                    role: Role::InternalInfill,
                });
            }
        }
    }
    out
}

/// The bounding box of `area`'s points, if it has any.
fn extent(area: &Shapes) -> Option<(Point2, Point2)> {
    let mut pts = area.iter().flatten().flatten();
    let first = *pts.next()?;
    let (lo, hi) = pts.fold((first, first), |(lo, hi), p| {
        (
            [lo[0].min(p[0]), lo[1].min(p[1])],
            [hi[0].max(p[0]), hi[1].max(p[1])],
        )
    });
    Some((lo, hi))
}

/// Straight lines at `angle` (radians from +x), `spacing` apart on the grid through the
/// plane's origin, long enough to cross the box `lo`–`hi`.
fn straight(lo: Point2, hi: Point2, angle: f64, spacing: f64) -> Vec<Vec<Point2>> {
    let (d, n) = ([angle.cos(), angle.sin()], [-angle.sin(), angle.cos()]);
    let corners = [lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]];
    let along = |p: Point2, v: Point2| p[0] * v[0] + p[1] * v[1];
    let span = |v: Point2| {
        corners
            .iter()
            .map(|&c| along(c, v))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            })
    };
    let (t0, t1) = span(d);
    let (s0, s1) = span(n);
    let (j0, j1) = ((s0 / spacing).floor() as i64, (s1 / spacing).ceil() as i64);
    (j0..=j1)
        .map(|j| {
            let s = j as f64 * spacing;
            let at = |t: f64| [d[0] * t + n[0] * s, d[1] * t + n[1] * s];
            vec![at(t0 - spacing), at(t1 + spacing)]
        })
        .collect()
}

/// The section at height `z` of the gyroid `sin x cos y + sin y cos z + sin z cos x = 0`
/// scaled to the period [`gyroid_period`], as wave lines across the box `lo`–`hi`.
///
/// Where `|cos z| ≥ |sin z|` the section is solved for y along x: `A cos y + B sin y =
/// −sin z cos x` with `A = sin x`, `B = cos z`, so `y = atan2(B, A) ± acos(−sin z cos x / R)`,
/// `R = √(A² + B²) ≥ |cos z| ≥ |sin z cos x|`; elsewhere for x along y the same way
/// (`cos y sin x + sin z cos x = −sin y cos z`). Either way each line is a continuous function
/// across the box, two lines a period.
fn gyroid(lo: Point2, hi: Point2, z: f64, width: f64, density: f64) -> Vec<Vec<Point2>> {
    let period = gyroid_period(width, density);
    let k = 2.0 * PI / period;
    let w = z * k;
    let (sz, cz) = w.sin_cos();
    // Along x (y solved) or along y (x solved): the free axis and the solved one.
    let along_x = cz.abs() >= sz.abs();
    let (a, b) = if along_x { (0, 1) } else { (1, 0) };
    let step = period / GYROID_SAMPLES as f64;
    let samples = ((hi[a] - lo[a]) / step).ceil() as usize + 2;
    let (m0, m1) = (
        (lo[b] * k / (2.0 * PI)).floor() as i64 - 1,
        (hi[b] * k / (2.0 * PI)).ceil() as i64 + 1,
    );
    let mut lines = vec![];
    for branch in [0, 1] {
        for m in m0..=m1 {
            let line: Vec<Point2> = (0..samples)
                .map(|i| {
                    let t = lo[a] - step + i as f64 * step;
                    let u = gyroid_solve(t * k, sz, cz, along_x, branch) + 2.0 * PI * m as f64;
                    let mut p = [0.0; 2];
                    p[a] = t;
                    p[b] = u / k;
                    p
                })
                .collect();
            lines.push(line);
        }
    }
    lines
}

/// The solved coordinate (scaled to radians) of branch `branch` of the gyroid's section at
/// `sin z = sz`, `cos z = cz` over the free coordinate `t` ([`gyroid`]).
fn gyroid_solve(t: f64, sz: f64, cz: f64, along_x: bool, branch: usize) -> f64 {
    let sign = if branch == 0 { 1.0 } else { -1.0 };
    if along_x {
        // sin x cos y + cos z sin y = −sin z cos x, for y.
        let (a, b) = (t.sin(), cz);
        let r = a.hypot(b);
        let c = (-sz * t.cos() / r).clamp(-1.0, 1.0);
        b.atan2(a) + sign * c.acos()
    } else {
        // cos y sin x + sin z cos x = −sin y cos z, for x.
        let (a, b) = (t.cos(), sz);
        let r = a.hypot(b);
        let c = (-t.sin() * cz / r).clamp(-1.0, 1.0);
        let s = c.asin();
        -b.atan2(a) + if branch == 0 { s } else { PI - s }
    }
}

/// The gyroid's period (mm) for beads `width` wide covering `density` of the area: each period
/// square holds two lines, each `stretch` periods long ([`gyroid_stretch`]), so the beads
/// cover `2·stretch·width / period` of it.
pub(crate) fn gyroid_period(width: f64, density: f64) -> f64 {
    2.0 * gyroid_stretch() * width / density
}

/// The share of its area the sparse lines of `params` cover on a layer at height `z` (mm),
/// for beads `width` wide: `infill_density` for straight lines; for the gyroid, whose lines
/// are longer where the section's two families of lines meet, `infill_density` × the
/// section's line length at `z` over its mean (`stretch_at`, from 1.15 to 1.51 periods a
/// period): the density holds over the layers of a period, not on each.
pub fn layer_density(params: &LayerParams, z: f64, width: f64) -> f64 {
    let d = params.infill_density;
    if params.infill_pattern != InfillPattern::Gyroid || !(d > 0.0 && width > 0.0) {
        return d;
    }
    let w = 2.0 * PI * z / gyroid_period(width, d);
    d * stretch_at(w) / gyroid_stretch()
}

/// The mean length of one gyroid section line over one period, in periods, over the heights
/// of a period: more than 1, as the lines wave (found once).
fn gyroid_stretch() -> f64 {
    static MEAN: std::sync::OnceLock<f64> = std::sync::OnceLock::new();
    *MEAN.get_or_init(|| {
        let total: f64 = (0..GYROID_HEIGHTS)
            .map(|h| stretch_at(2.0 * PI * (h as f64 + 0.5) / GYROID_HEIGHTS as f64))
            .sum();
        total / GYROID_HEIGHTS as f64
    })
}

/// The length of one gyroid section line over one period at the scaled height `w`, in
/// periods.
fn stretch_at(w: f64) -> f64 {
    let n = GYROID_SAMPLES * 4;
    let (sz, cz) = w.sin_cos();
    let along_x = cz.abs() >= sz.abs();
    let point = |i: usize| {
        let t = 2.0 * PI * i as f64 / n as f64;
        [t, gyroid_solve(t, sz, cz, along_x, 0)]
    };
    let mut len = 0.0;
    for i in 0..n {
        let (p, q) = (point(i), point(i + 1));
        len += (q[0] - p[0]).hypot(q[1] - p[1]);
    }
    len / (2.0 * PI)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(s: f64) -> Shapes {
        vec![vec![vec![[0.0, 0.0], [s, 0.0], [s, s], [0.0, s]]]]
    }

    fn cover(paths: &[Path2], width: f64) -> f64 {
        paths.iter().map(|p| p.length() * width).sum()
    }

    /// Every pattern's beads cover the layer's density ([`layer_density`]) of a large square
    /// (within 3 %: the lines cut at the square's edges), on several layers.
    #[test]
    fn every_pattern_covers_its_density() {
        let area = square(60.0);
        for pattern in [
            InfillPattern::Rectilinear,
            InfillPattern::Grid,
            InfillPattern::Triangles,
            InfillPattern::Gyroid,
        ] {
            for density in [0.15, 0.4] {
                for layer in 0..4 {
                    let z = 0.2 * layer as f64 + 0.1;
                    let params = LayerParams {
                        infill_pattern: pattern,
                        infill_density: density,
                        ..LayerParams::default()
                    };
                    let paths = pattern_lines(&area, &params, layer, z, 0.45);
                    let share = cover(&paths, 0.45) / 3600.0;
                    let want = layer_density(&params, z, 0.45);
                    assert!(
                        (share / want - 1.0).abs() < 0.03,
                        "{pattern:?} {density} layer {layer}: {share}"
                    );
                }
            }
        }
    }

    /// The gyroid's layer density averages to the density over a period of heights.
    #[test]
    fn the_gyroid_holds_its_density_over_a_period() {
        let params = LayerParams {
            infill_pattern: InfillPattern::Gyroid,
            infill_density: 0.2,
            ..LayerParams::default()
        };
        let period = gyroid_period(0.45, 0.2);
        let n = 1000;
        let mean: f64 = (0..n)
            .map(|k| layer_density(&params, period * (k as f64 + 0.5) / n as f64, 0.45))
            .sum::<f64>()
            / n as f64;
        assert!((mean / 0.2 - 1.0).abs() < 0.01, "{mean}");
    }

    /// How far from 0 the gyroid's function may be at a point of its lines (rounding).
    const ON_SURFACE: f64 = 1e-9;

    /// Gyroid lines lie on the surface: every point satisfies its equation at the layer's z.
    #[test]
    fn gyroid_points_lie_on_the_gyroid() {
        let (w, d, z) = (0.45, 0.2, 1.3);
        let k = 2.0 * PI / gyroid_period(w, d);
        for line in gyroid([0.0, 0.0], [10.0, 10.0], z, w, d) {
            for p in line {
                let (x, y, zz) = (p[0] * k, p[1] * k, z * k);
                let f = x.sin() * y.cos() + y.sin() * zz.cos() + zz.sin() * x.cos();
                assert!(f.abs() < ON_SURFACE, "{p:?}: {f}");
            }
        }
    }
}
