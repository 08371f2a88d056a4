//! Tool-axis smoothing inside a tolerance cone (Chalvin et al. 2022, "Orientation smoothing in
//! multi-axis additive manufacturing", Eq. 3–7), run between planning and posting.
//!
//! Each continuous path ([`continuous_paths`]) is smoothed on its own, in two steps, as in the
//! paper's hybrid approach (§3.2):
//!
//! 1. a zero-phase moving-average or median filter over a window measured in millimetres of
//!    path (Eq. 3, [`filter_axes`]);
//! 2. every smoothed axis further than γ/2 from its planned axis is rotated back onto the
//!    boundary of the tolerance cone around the planned axis (Eq. 4–7, [`cone_correct`]).
//!
//! [`orientation_step_rate`] gives the figures `plan.json` reports before and after
//! ([`OrientationFigures`]).

use crate::toolpath::{MoveKind, PathPoint, ToolPath};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::ops::Range;

use crate::tolerance::{PARALLEL_HEADING, RATE_SLACK, SHORT_VECTOR, TILT_MARGIN_DEG};
use crate::vec3::{cross, dot, norm, scale, sub, unit, V3};

/// Which filter smooths the axes (the paper's two variants, §3.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Filter {
    /// Zero-phase moving average (Eq. 3 forward then backward). The default: the paper found
    /// it the one that works (§5.2, "the median filter had too little effect").
    #[default]
    MovingAverage,
    /// Zero-phase (centred) median, component by component, then renormalised.
    Median,
}

/// Process options, the `[orientation]` table of the process TOML file.
///
/// Missing keys take their defaults (`[orientation]` alone is [`SmoothParams::default`]);
/// unknown keys are an error.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct SmoothParams {
    /// Smooth at all. Default true.
    pub enabled: bool,
    /// `moving_average` or `median`. Default `moving_average`.
    pub filter: Filter,
    /// Window W of the filter, mm of path (the `n` values of Eq. 3 measured along the path, so
    /// uneven point spacing does not change the smoothing). The zero-phase filter reaches W
    /// on each side of a point. Default 5 mm: the paper's window, 20 mm for a 1 mm nozzle
    /// (§5.2), scaled to our 0.4 mm nozzle is 8 mm; 5 mm (about a dozen bead widths) still
    /// spans the turn of a corner while keeping the 10 mm reach shorter than the perimeter of
    /// small features (a 5 mm hole is 16 mm round), which would otherwise be blended whole.
    pub window_mm: f64,
    /// Opening angle γ of the tolerance cone, degrees, in (0, 180]: a smoothed axis may lean
    /// at most γ/2 from its planned axis. Default 60 (the paper's FFF tolerance, §5.1).
    pub cone_angle_deg: f64,
}

impl Default for SmoothParams {
    fn default() -> Self {
        SmoothParams {
            enabled: true,
            filter: Filter::MovingAverage,
            window_mm: 5.0,
            cone_angle_deg: 60.0,
        }
    }
}

impl SmoothParams {
    /// Checks the options; the error is one line naming the offending key.
    pub fn validate(&self) -> Result<(), String> {
        let w = self.window_mm;
        if !(w.is_finite() && w > 0.0) {
            return Err(format!(
                "window_mm must be a positive number of mm, got {w}"
            ));
        }
        let g = self.cone_angle_deg;
        if !(g.is_finite() && g > 0.0 && g <= 180.0) {
            return Err(format!(
                "cone_angle_deg must be in (0, 180] degrees, got {g} (set enabled = false to keep the planned axes)"
            ));
        }
        Ok(())
    }
}

/// Orientation figures of one feature, before and after smoothing. Serialised under the
/// `plan.json` key names (`orientation_step_max_deg_before`, ...).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct OrientationFigures {
    /// Largest angle between consecutive axes along print segments, degrees, as planned.
    #[serde(rename = "orientation_step_max_deg_before")]
    pub step_max_deg_before: f64,
    /// The same after smoothing.
    #[serde(rename = "orientation_step_max_deg_after")]
    pub step_max_deg_after: f64,
    /// Largest angle change per mm of print segment, degrees per mm, as planned.
    #[serde(rename = "orientation_rate_max_deg_per_mm_before")]
    pub rate_max_deg_per_mm_before: f64,
    /// The same after smoothing.
    #[serde(rename = "orientation_rate_max_deg_per_mm_after")]
    pub rate_max_deg_per_mm_after: f64,
}

/// Segments shorter than this (mm) are left out of the rate (an angle over no length).
pub const MIN_RATE_SEGMENT_MM: f64 = 1e-6;

/// Angle between two directions, radians in [0, π]. This is Eq. 4's
/// `arccos(a·b / (|a||b|))`, computed as `atan2(|a×b|, a·b)`, which is the same angle but stays
/// accurate near 0 and π where arccos loses half its digits.
pub fn angle_between(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm(cross(a, b)).atan2(dot(a, b))
}

/// Whether `q` continues the deposit of `prev`: a print segment of the same feature and layer.
fn joins(prev: &PathPoint, q: &PathPoint) -> bool {
    q.kind == MoveKind::Print && q.feature == prev.feature && q.layer == prev.layer
}

/// The continuous paths of `points`, as index ranges covering every point once, in order: each
/// is a maximal run of consecutive points of one feature and layer joined by print segments,
/// i.e. the point where the bead starts (usually a travel point) and the print points that
/// follow it. A travel point that starts no bead is a range of its own.
pub fn continuous_paths(points: &[PathPoint]) -> Vec<Range<usize>> {
    let mut out = Vec::new();
    let mut start = 0;
    while start < points.len() {
        let mut end = start + 1;
        while end < points.len() && joins(&points[end - 1], &points[end]) {
            end += 1;
        }
        out.push(start..end);
        start = end;
    }
    out
}

/// (largest angle between consecutive axes along print segments, degrees; largest such angle
/// over the segment's length, degrees per mm) of one feature's points.
///
/// A segment counts when its end point is a print point of the same feature and layer as the
/// point before it; segments shorter than [`MIN_RATE_SEGMENT_MM`] count for the step but not
/// for the rate. `(0, 0)` when there is no such segment.
pub fn orientation_step_rate(points: &[PathPoint]) -> (f64, f64) {
    let mut step: f64 = 0.0;
    let mut rate: f64 = 0.0;
    for w in points.windows(2) {
        if !joins(&w[0], &w[1]) {
            continue;
        }
        let a = angle_between(w[0].axis, w[1].axis).to_degrees();
        step = step.max(a);
        let len = norm(sub(w[1].p, w[0].p));
        if len >= MIN_RATE_SEGMENT_MM {
            rate = rate.max(a / len);
        }
    }
    (step, rate)
}

/// Zero-phase moving average (Eq. 3) of `axes` sampled at arc lengths `s`, window `w` mm.
///
/// Eq. 3 averages the last `n` axes; in millimetres of path that is the mean of the axis over
/// `[s − W, s]`, the axis taken as varying linearly between points, so the weights follow arc
/// length and uneven spacing does not skew the mean. Run forward then backward (the paper's
/// zero-phase filter, Matlab's `filtfilt`), the two boxes make one symmetric triangle kernel
/// `k(u) = W − |u − s_m|` on `[s_m − W, s_m + W]` (a box convolved with its mirror image). We apply
/// that kernel directly, integrating `k · axis` exactly (Simpson's rule is exact for the product
/// of two linear functions), which makes the output exactly symmetric under reversing the path:
/// no lag. At the path's ends the kernel is cut off and divided by the weight left inside the
/// path (where `filtfilt` pads), so an end axis is the mean of the axes next to it. The sums are
/// not normalised; `None` where the kernel has no weight.
fn moving_average(s: &[f64], axes: &[V3], w: f64) -> Vec<Option<V3>> {
    let n = axes.len();
    (0..n)
        .map(|m| {
            let c = s[m];
            let (lo_k, hi_k) = (c - w, c + w);
            let k = |u: f64| (w - (u - c).abs()).max(0.0);
            let mut sum = [0.0; 3];
            let mut weight = 0.0;
            // First segment [s_i, s_i+1] that ends after the kernel starts.
            let first = s[1..].partition_point(|&x| x <= lo_k);
            for i in first..n.saturating_sub(1) {
                let (s0, s1) = (s[i], s[i + 1]);
                if s0 >= hi_k {
                    break;
                }
                let len = s1 - s0;
                if len <= 0.0 {
                    continue;
                }
                let at = |u: f64| -> V3 {
                    let t = (u - s0) / len;
                    let (a, b) = (axes[i], axes[i + 1]);
                    [
                        a[0] + t * (b[0] - a[0]),
                        a[1] + t * (b[1] - a[1]),
                        a[2] + t * (b[2] - a[2]),
                    ]
                };
                let (a, b) = (s0.max(lo_k), s1.min(hi_k));
                // The kernel has its peak at c: split there so each piece is linear.
                let pieces: [(f64, f64); 2] = if a < c && c < b {
                    [(a, c), (c, b)]
                } else {
                    [(a, b), (b, b)]
                };
                for (a, b) in pieces {
                    if b <= a {
                        continue;
                    }
                    let mid = 0.5 * (a + b);
                    let (ka, km, kb) = (k(a), k(mid), k(b));
                    let (va, vm, vb) = (at(a), at(mid), at(b));
                    let h = (b - a) / 6.0;
                    for j in 0..3 {
                        sum[j] += h * (ka * va[j] + 4.0 * km * vm[j] + kb * vb[j]);
                    }
                    weight += 0.5 * (b - a) * (ka + kb);
                }
            }
            (weight > 0.0).then(|| scale(sum, 1.0 / weight))
        })
        .collect()
}

/// Weighted median of `(value, weight)` pairs: the midpoint of the lowest value whose
/// cumulative weight (from below) reaches half the total and the highest value whose cumulative
/// weight from above does. With equal weights this is the ordinary median (the mean of the two
/// middle values for an even count).
fn weighted_median(items: &mut [(f64, f64)]) -> f64 {
    items.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = items.iter().map(|x| x.1).sum();
    let half = 0.5 * total;
    let mut acc = 0.0;
    let mut lo = items[0].0;
    for &(v, wt) in items.iter() {
        acc += wt;
        if acc >= half {
            lo = v;
            break;
        }
    }
    let mut acc = 0.0;
    let mut hi = items[items.len() - 1].0;
    for &(v, wt) in items.iter().rev() {
        acc += wt;
        if acc >= half {
            hi = v;
            break;
        }
    }
    0.5 * (lo + hi)
}

/// Zero-phase median of `axes` sampled at arc lengths `s`, window `w` mm (§3.2: "sorting the
/// entries by size and selecting the median value", applied to each component of the vectors).
///
/// A median run forward over `[s − W, s]` lags like Eq. 3 does; the zero-phase version is the
/// median over the centred window `[s_m − W, s_m + W]`, the same reach as the zero-phase moving
/// average. Each axis is weighted by the length of path it stands for (half of each adjacent
/// segment) inside the window, so uneven spacing does not skew the median. Not normalised;
/// `None` where the window holds no weight.
fn median(s: &[f64], axes: &[V3], w: f64) -> Vec<Option<V3>> {
    let n = axes.len();
    let cell = |j: usize| -> (f64, f64) {
        let lo = if j == 0 {
            s[0]
        } else {
            0.5 * (s[j - 1] + s[j])
        };
        let hi = if j + 1 == n {
            s[n - 1]
        } else {
            0.5 * (s[j] + s[j + 1])
        };
        (lo, hi)
    };
    let mut items: Vec<(f64, f64)> = Vec::new();
    (0..n)
        .map(|m| {
            let (lo_k, hi_k) = (s[m] - w, s[m] + w);
            let first = s.partition_point(|&x| x < lo_k).saturating_sub(1);
            let mut members: Vec<(usize, f64)> = Vec::new();
            for j in first..n {
                let (a, b) = cell(j);
                if a > hi_k {
                    break;
                }
                let wt = b.min(hi_k) - a.max(lo_k);
                if wt > 0.0 {
                    members.push((j, wt));
                }
            }
            if members.is_empty() {
                return None;
            }
            let mut out = [0.0; 3];
            for (c, o) in out.iter_mut().enumerate() {
                items.clear();
                items.extend(members.iter().map(|&(j, wt)| (axes[j][c], wt)));
                *o = weighted_median(&mut items);
            }
            Some(out)
        })
        .collect()
}

/// The smoothed unit axes T_S of one continuous path (Eq. 3 and its median variant, zero
/// phase): `axes[m]` sits at arc length `s[m]` (non-decreasing, mm). See [`Filter`] and
/// [`SmoothParams::window_mm`]; the filters work on the axes as given and renormalise their
/// result. Where the result has no direction (the window's axes cancel out, or the path has no
/// length) the planned axis is kept. `axes` should be unit and `s` as long as `axes`.
pub fn filter_axes(s: &[f64], axes: &[[f64; 3]], filter: Filter, window_mm: f64) -> Vec<[f64; 3]> {
    if axes.is_empty() || s.len() != axes.len() {
        return axes.to_vec();
    }
    let raw = match filter {
        Filter::MovingAverage => moving_average(s, axes, window_mm),
        Filter::Median => median(s, axes, window_mm),
    };
    raw.into_iter()
        .zip(axes)
        .map(|(r, &b)| r.and_then(unit).unwrap_or(b))
        .collect()
}

/// Tilts every axis that leans more than `max_tilt_deg` from +Z (a B/C bed's B limit), by at
/// most `slack_deg`, up to that limit in the plane of the axis and +Z (a hair inside it, so the
/// post's check holds): the tool-axis counterpart of a machine limit, for axes that a curved
/// layer's normal tips just past it (a feature on a vertical wall whose layers lean down by a
/// degree). Axes farther out are left for the post to refuse. Returns, per feature, how many
/// axes were tilted and the largest tilt, degrees.
pub fn limit_tilt(
    path: &mut ToolPath,
    max_tilt_deg: f64,
    slack_deg: f64,
) -> BTreeMap<usize, (usize, f64)> {
    let mut out: BTreeMap<usize, (usize, f64)> = BTreeMap::new();
    let target = (max_tilt_deg - TILT_MARGIN_DEG).to_radians();
    for p in &mut path.points {
        let Some(a) = unit(p.axis) else { continue };
        let tilt = a[2].clamp(-1.0, 1.0).acos();
        let over = tilt.to_degrees() - max_tilt_deg;
        let r = a[0].hypot(a[1]);
        if over <= 0.0 || over > slack_deg || r < SHORT_VECTOR {
            continue;
        }
        let (s, c) = target.sin_cos();
        p.axis = [s * a[0] / r, s * a[1] / r, c];
        let e = out.entry(p.feature as usize).or_default();
        e.0 += 1;
        e.1 = e.1.max(tilt.to_degrees() - target.to_degrees());
    }
    out
}

/// Brings a smoothed axis back into the tolerance cone of opening angle γ =
/// `cone_angle_deg` around its planned axis (Eq. 4–7). Returns a unit vector.
///
/// - Eq. 4: α, the angle between the smoothed axis T_S and the planned axis b
///   ([`angle_between`]).
/// - Eq. 7, first case: α ≤ γ/2, T_S is kept.
/// - Eq. 5: the rotation axis h, normal to the plane of b and T_S. The paper writes
///   h = T_S ∧ b, but with that h the right-handed rotation of Eq. 6 turns b *away* from T_S;
///   we take h = b ∧ T_S (the paper's h with the angle's sign flipped), normalised (Eq. 6 needs
///   a unit axis) and made exactly normal to b. When T_S is opposite to b the plane is
///   undefined and any h normal to b is taken.
/// - Eq. 6: R, the rotation by γ/2 about h (c = cos γ/2, s = sin γ/2).
/// - Eq. 7, second case: T = R b, on the cone's boundary in the plane of b and T_S, on T_S's
///   side: the nearest axis to T_S that the tolerance allows.
///
/// A zero or non-finite `smoothed` gives the planned axis (normalised).
pub fn cone_correct(smoothed: [f64; 3], original: [f64; 3], cone_angle_deg: f64) -> [f64; 3] {
    let Some(b) = unit(original) else {
        return original;
    };
    let Some(t) = unit(smoothed) else {
        return b;
    };
    let half = 0.5 * cone_angle_deg.to_radians();
    // Eq. 4.
    let alpha = angle_between(t, b);
    // Eq. 7, first case.
    if alpha <= half {
        return t;
    }
    // Eq. 5 (sign and normalisation as documented above).
    let h0 = cross(b, t);
    let h0 = if norm(h0) > PARALLEL_HEADING {
        h0
    } else {
        // T_S opposite to b: any normal to b; cross b with the world axis it is least along.
        let i = (0..3)
            .min_by(|&i, &j| b[i].abs().total_cmp(&b[j].abs()))
            .unwrap_or(0);
        let mut e = [0.0; 3];
        e[i] = 1.0;
        cross(b, e)
    };
    let h = match unit(sub(h0, scale(b, dot(h0, b)))) {
        Some(h) => h,
        None => return b,
    };
    // Eq. 6.
    let (c, s) = (half.cos(), half.sin());
    let (hx, hy, hz) = (h[0], h[1], h[2]);
    let r = [
        [
            c + hx * hx * (1.0 - c),
            hx * hy * (1.0 - c) - hz * s,
            hx * hz * (1.0 - c) + hy * s,
        ],
        [
            hy * hx * (1.0 - c) + hz * s,
            c + hy * hy * (1.0 - c),
            hy * hz * (1.0 - c) - hx * s,
        ],
        [
            hz * hx * (1.0 - c) - hy * s,
            hz * hy * (1.0 - c) + hx * s,
            c + hz * hz * (1.0 - c),
        ],
    ];
    // Eq. 7, second case: T = R b.
    let rb = [dot(r[0], b), dot(r[1], b), dot(r[2], b)];
    unit(rb).unwrap_or(b)
}

/// Smooths one continuous path in place: filter (Eq. 3), then cone correction (Eq. 4–7). Left
/// unchanged when it has fewer than 3 points, no length, or an axis that is zero or not finite.
fn smooth_run(points: &mut [PathPoint], params: &SmoothParams) {
    if points.len() < 3 {
        return;
    }
    // A path along one coordinate axis throughout (every planar layer) smooths to itself
    // exactly: each weighted sum is that axis times a positive weight, which `unit` divides
    // back to ±1 exactly, and the zero components stay +0. Skipped, it costs nothing.
    let first = points[0].axis;
    let aligned = first.iter().filter(|x| x.abs() == 1.0).count() == 1
        && first.iter().all(|x| x.abs() == 1.0 || x.to_bits() == 0);
    if aligned
        && points
            .iter()
            .all(|q| q.axis.map(f64::to_bits) == first.map(f64::to_bits))
    {
        return;
    }
    let mut axes = Vec::with_capacity(points.len());
    for q in points.iter() {
        match unit(q.axis) {
            Some(a) => axes.push(a),
            None => return,
        }
    }
    let mut s = Vec::with_capacity(points.len());
    let mut acc = 0.0;
    s.push(acc);
    for w in points.windows(2) {
        acc += norm(sub(w[1].p, w[0].p));
        s.push(acc);
    }
    if !(acc.is_finite() && acc > 0.0) {
        return;
    }
    let smoothed = filter_axes(&s, &axes, params.filter, params.window_mm);
    for ((q, t), b) in points.iter_mut().zip(smoothed).zip(axes) {
        q.axis = cone_correct(t, b, params.cone_angle_deg);
    }
}

/// Smooths every continuous path ([`continuous_paths`]) of `path` in place, each on its own,
/// when `params.enabled`, and returns, for every feature in the path (key = `PathPoint.feature`),
/// its [`orientation_step_rate`] figures before and after (after == before when disabled).
///
/// Only axes change: positions, kinds, extrusion, thickness and width stay as they are, and so
/// do travel points that start no bead, paths of fewer than 3 points and paths that smoothing
/// would make rougher (a larger step or rate than planned), so the figures after never exceed
/// those before. Every smoothed axis is
/// unit and within `cone_angle_deg / 2` of its planned axis. Parameters that fail
/// [`SmoothParams::validate`] leave the path unchanged (the caller validates and reports).
pub fn smooth(path: &mut ToolPath, params: &SmoothParams) -> BTreeMap<usize, OrientationFigures> {
    let active = params.enabled && params.validate().is_ok();
    let mut out: BTreeMap<usize, OrientationFigures> = BTreeMap::new();
    for r in continuous_paths(&path.points) {
        let feature = path.points[r.start].feature;
        let run = &mut path.points[r];
        let before = orientation_step_rate(run);
        let after = if active {
            let planned: Vec<[f64; 3]> = run.iter().map(|q| q.axis).collect();
            smooth_run(run, params);
            // A low-pass filter cut off at a path's ends can still turn its first or last
            // step a little more than planned (uneven spacing there): a path that smoothing
            // would make rougher keeps its planned axes.
            let after = orientation_step_rate(run);
            if after.0 > before.0 + RATE_SLACK || after.1 > before.1 + RATE_SLACK {
                for (q, a) in run.iter_mut().zip(planned) {
                    q.axis = a;
                }
                before
            } else {
                after
            }
        } else {
            before
        };
        // Per feature, the largest figures over its paths.
        let e = out.entry(feature as usize).or_default();
        e.step_max_deg_before = e.step_max_deg_before.max(before.0);
        e.rate_max_deg_per_mm_before = e.rate_max_deg_per_mm_before.max(before.1);
        e.step_max_deg_after = e.step_max_deg_after.max(after.0);
        e.rate_max_deg_per_mm_after = e.rate_max_deg_per_mm_after.max(after.1);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weighted_median_is_the_ordinary_median_for_equal_weights() {
        let mut odd = vec![(3.0, 1.0), (-1.0, 1.0), (7.0, 1.0)];
        assert_eq!(weighted_median(&mut odd), 3.0);
        let mut even = vec![(4.0, 1.0), (1.0, 1.0), (2.0, 1.0), (10.0, 1.0)];
        assert_eq!(weighted_median(&mut even), 3.0);
        // A heavy value wins.
        let mut heavy = vec![(0.0, 1.0), (5.0, 3.0), (9.0, 1.0)];
        assert_eq!(weighted_median(&mut heavy), 5.0);
    }

    #[test]
    fn moving_average_of_a_linear_ramp_in_the_interior_is_the_ramp() {
        // A linearly varying signal is reproduced by a symmetric kernel away from the ends,
        // whatever the spacing.
        let s = [0.0, 0.3, 1.0, 1.2, 2.5, 3.0, 3.1, 4.5, 6.0, 7.0];
        let axes: Vec<V3> = s.iter().map(|&x| [x, 1.0, 2.0 - 0.5 * x]).collect();
        let out = moving_average(&s, &axes, 1.0);
        for (m, o) in out.iter().enumerate() {
            if s[m] - 1.0 >= 0.0 && s[m] + 1.0 <= 7.0 {
                let o = o.expect("weight");
                for j in 0..3 {
                    assert!(
                        (o[j] - axes[m][j]).abs() < 1e-12,
                        "m {m}: {o:?} vs {:?}",
                        axes[m]
                    );
                }
            }
        }
    }
}
