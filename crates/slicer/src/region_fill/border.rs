//! The infill boundary's rings, along which zig-zag connectors run.

use crate::geom2d::{dist2, segment_foot, Point2};

/// The infill boundary's rings, to run zig-zag connectors along.
pub(super) struct Border<'a> {
    rings: &'a [crate::geodesic::IsoLine],
    /// Arc length at each point of each ring.
    arc: Vec<Vec<f64>>,
}

impl<'a> Border<'a> {
    pub(super) fn new(rings: &'a [crate::geodesic::IsoLine]) -> Self {
        let arc = rings
            .iter()
            .map(|r| {
                let mut a = vec![0.0];
                for w in r.q.windows(2) {
                    let l = dist2(w[1], w[0]).sqrt();
                    a.push(a[a.len() - 1] + l);
                }
                a
            })
            .collect();
        Border { rings, arc }
    }

    /// Ring, segment and arc length of the ring point nearest `q`, with its distance.
    fn locate(&self, q: Point2) -> Option<(usize, usize, f64, f64)> {
        let mut best: Option<(usize, usize, f64, f64)> = None;
        for (r, ring) in self.rings.iter().enumerate() {
            for (i, w) in ring.q.windows(2).enumerate() {
                let (t, x, l2) = segment_foot(q, w[0], w[1]);
                let d = dist2(q, x).sqrt();
                if best.is_none_or(|b| d < b.3) {
                    best = Some((r, i, self.arc[r][i] + t * l2.sqrt(), d));
                }
            }
        }
        best
    }

    /// The way from `a` to `b` along one ring (interior ring points only), if both lie on the
    /// same ring (within a few micrometres... of a spacing) and the shorter way is at most `max`.
    pub(super) fn connect(&self, a: Point2, b: Point2, max: f64) -> Option<(f64, Vec<Point2>)> {
        let (ra, ia, sa, da) = self.locate(a)?;
        let (rb, ib, sb, db) = self.locate(b)?;
        if ra != rb || da > 0.05 * max || db > 0.05 * max {
            return None;
        }
        let ring = &self.rings[ra];
        let total = self.arc[ra][self.arc[ra].len() - 1];
        let fwd = sb - sa;
        let (len, forward) = if ring.closed {
            let f = fwd.rem_euclid(total);
            if f <= total - f {
                (f, true)
            } else {
                (total - f, false)
            }
        } else {
            (fwd.abs(), fwd >= 0.0)
        };
        if len > max {
            return None;
        }
        let n = ring.q.len() - usize::from(ring.closed);
        let mut way = vec![];
        if n > 0 {
            // Ring points strictly between the two segments, walking the chosen way.
            let mut i = ia;
            let mut guard = 0;
            while i != ib && guard <= n {
                if forward {
                    i = (i + 1) % n.max(1);
                    way.push(ring.q[i]);
                } else {
                    way.push(ring.q[i]);
                    i = (i + n - 1) % n.max(1);
                }
                guard += 1;
            }
        }
        Some((len, way))
    }
}
