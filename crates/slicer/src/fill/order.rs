//! Print order of a layer's paths: greedy nearest end, reversing open paths.

use super::Path2;
use crate::geom2d::{dist, Point2};

/// Orders paths to keep travel short (greedy nearest start/end from `start`, reversing open
/// paths where that is shorter) and returns them in print order.
///
/// Closed paths are entered at their first point and kept as they are; empty paths go last.
/// Reversing open paths means raster lines no longer all run the same way: keep
/// [`super::fill_layer`]'s order for raster when that matters.
pub fn order_paths(paths: Vec<Path2>, start: Point2) -> Vec<Path2> {
    let (todo, empty): (Vec<Path2>, Vec<Path2>) =
        paths.into_iter().partition(|p| !p.points.is_empty());
    let mut out = order_greedy(todo, start, |p| &p.points, |p| p.points.reverse());
    out.extend(empty);
    out
}

/// The greedy order of [`order_paths`] for any path type: `points` gives a path's (non-empty)
/// polyline, closed when it ends where it starts; `reverse` turns a path round (with anything
/// it carries per point).
pub fn order_greedy<T>(
    paths: Vec<T>,
    start: Point2,
    points: impl Fn(&T) -> &[Point2],
    reverse: impl Fn(&mut T),
) -> Vec<T> {
    let mut todo: Vec<Option<T>> = paths
        .into_iter()
        .filter(|p| !points(p).is_empty())
        .map(Some)
        .collect();
    let mut out = Vec::with_capacity(todo.len());
    let d = |a: Point2, b: Point2| {
        let v = dist(a, b);
        if v.is_nan() {
            f64::INFINITY
        } else {
            v
        }
    };
    let mut cur = start;
    for _ in 0..todo.len() {
        // (distance, index, reverse); ties go to the earlier path.
        let mut best: Option<(f64, usize, bool)> = None;
        for (i, p) in todo.iter().enumerate() {
            let Some(p) = p else { continue };
            let pts = points(p);
            let ds = d(cur, pts[0]);
            if best.is_none_or(|b| ds < b.0) {
                best = Some((ds, i, false));
            }
            let closed = pts.len() > 2 && pts.first() == pts.last();
            if !closed {
                let de = d(cur, pts[pts.len() - 1]);
                if best.is_none_or(|b| de < b.0) {
                    best = Some((de, i, true));
                }
            }
        }
        let Some((_, i, rev)) = best else { break };
        let Some(mut p) = todo[i].take() else { break };
        if rev {
            reverse(&mut p);
        }
        let pts = points(&p);
        cur = pts[pts.len() - 1];
        out.push(p);
    }
    out
}
