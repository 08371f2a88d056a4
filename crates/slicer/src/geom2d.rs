//! Plane geometry shared by the planar fill ([`crate::fill`]), the region filler of curved and
//! thin layers and the lattice of [`crate::geodesic`]: points, regions, lengths, areas,
//! distances to segments and even-odd point-in-polygon tests.

/// A point of the layer plane, mm.
pub type Point2 = [f64; 2];

/// A region: an outer boundary (counter-clockwise) and holes (clockwise), closed implicitly.
#[derive(Debug, Clone, PartialEq)]
pub struct Region {
    /// Outer boundary, counter-clockwise, first point not repeated.
    pub outer: Vec<Point2>,
    /// Holes, each clockwise, first point not repeated.
    pub holes: Vec<Vec<Point2>>,
}

/// Distance between two points.
pub(crate) fn dist(a: Point2, b: Point2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

pub(crate) fn dist2(a: Point2, b: Point2) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// Twice the signed area of a closed polygon (positive when counter-clockwise).
pub(crate) fn area2(pts: &[Point2]) -> f64 {
    let n = pts.len();
    if n < 3 {
        return 0.0;
    }
    // Relative to the first point, for accuracy far from the origin.
    let o = pts[0];
    let mut s = 0.0;
    for i in 1..n - 1 {
        let a = [pts[i][0] - o[0], pts[i][1] - o[1]];
        let b = [pts[i + 1][0] - o[0], pts[i + 1][1] - o[1]];
        s += a[0] * b[1] - a[1] * b[0];
    }
    s
}

/// Area of a region (its outer boundary's less its holes'), mm².
pub fn region_area(r: &Region) -> f64 {
    0.5 * (area2(&r.outer).abs() - r.holes.iter().map(|h| area2(h).abs()).sum::<f64>())
}

pub(crate) fn perimeter(pts: &[Point2]) -> f64 {
    let n = pts.len();
    (0..n).map(|i| dist(pts[i], pts[(i + 1) % n])).sum()
}

/// Even-odd point in polygon (points on the boundary may go either way).
pub(crate) fn inside(p: Point2, poly: &[Point2]) -> bool {
    let n = poly.len();
    let mut c = false;
    let mut j = n.wrapping_sub(1);
    for i in 0..n {
        let (a, b) = (poly[i], poly[j]);
        if (a[1] > p[1]) != (b[1] > p[1])
            && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0]
        {
            c = !c;
        }
        j = i;
    }
    c
}

/// Even-odd inside test against every ring of a region.
pub fn region_contains(region: &Region, q: Point2) -> bool {
    let mut inside = false;
    for ring in std::iter::once(&region.outer).chain(region.holes.iter()) {
        let n = ring.len();
        for i in 0..n {
            inside ^= crosses_right(ring[i], ring[(i + 1) % n], q);
        }
    }
    inside
}

/// Whether the edge `a`–`b` crosses the ray from `q` in +x (the even-odd step of
/// [`region_contains`]).
fn crosses_right(a: Point2, b: Point2, q: Point2) -> bool {
    (a[1] > q[1]) != (b[1] > q[1]) && a[0] + (q[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]) > q[0]
}

/// [`region_contains`] for many points: the region's edges in horizontal bands, so a point is
/// tested against the edges whose height range meets its band only. The same test on the
/// same edges, so the same answers.
#[derive(Debug, Clone)]
pub(crate) struct RegionIndex {
    lo: f64,
    per_band: f64,
    bands: Vec<Vec<(Point2, Point2)>>,
}

impl RegionIndex {
    /// Indexes `region`'s rings.
    pub(crate) fn new(region: &Region) -> RegionIndex {
        let rings = || std::iter::once(&region.outer).chain(region.holes.iter());
        let edges = rings().map(Vec::len).sum::<usize>();
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for q in rings().flatten() {
            lo = lo.min(q[1]);
            hi = hi.max(q[1]);
        }
        let n = (edges / 4).clamp(1, 4096);
        let span = hi - lo;
        let per_band = if span.is_finite() && span > 0.0 {
            n as f64 / span
        } else {
            0.0
        };
        let mut index = RegionIndex {
            lo,
            per_band,
            bands: vec![vec![]; n],
        };
        for ring in rings() {
            let m = ring.len();
            for i in 0..m {
                let (a, b) = (ring[i], ring[(i + 1) % m]);
                let (b0, b1) = (index.band(a[1].min(b[1])), index.band(a[1].max(b[1])));
                for band in &mut index.bands[b0..=b1] {
                    band.push((a, b));
                }
            }
        }
        index
    }

    /// The band of height `y` (monotone in `y`, clamped to the bands).
    fn band(&self, y: f64) -> usize {
        let k = ((y - self.lo) * self.per_band).floor();
        if k.is_nan() || k < 0.0 {
            0
        } else {
            (k as usize).min(self.bands.len() - 1)
        }
    }

    /// Whether `q` lies inside the region (even-odd, as [`region_contains`]).
    pub(crate) fn contains(&self, q: Point2) -> bool {
        let mut inside = false;
        for &(a, b) in &self.bands[self.band(q[1])] {
            inside ^= crosses_right(a, b, q);
        }
        inside
    }

    /// The region's crossings of the line at height `y`, for [`RegionIndex::contains`] of many
    /// points on it: where [`crosses_right`] puts each edge's crossing (the same arithmetic,
    /// so the same answers), in increasing order.
    pub(crate) fn row(&self, y: f64) -> Row {
        let mut xs: Vec<f64> = self.bands[self.band(y)]
            .iter()
            .filter(|(a, b)| (a[1] > y) != (b[1] > y))
            .map(|(a, b)| a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]))
            .collect();
        xs.sort_by(f64::total_cmp);
        Row { xs }
    }
}

/// The crossings of one horizontal line with a region's edges ([`RegionIndex::row`]).
#[derive(Debug, Clone)]
pub(crate) struct Row {
    xs: Vec<f64>,
}

impl Row {
    /// [`RegionIndex::contains`] of the point at `x` on the line: an odd number of crossings
    /// beyond `x`.
    pub(crate) fn contains(&self, x: f64) -> bool {
        let beyond = self.xs.len()
            - self
                .xs
                .partition_point(|c| c.partial_cmp(&x) != Some(std::cmp::Ordering::Greater));
        beyond % 2 == 1
    }
}

/// Douglas–Peucker's recursion over the chains `spans` (`(i, j)`: point indices, both ends
/// kept already): `split(i, j)` names the point between that must be kept (`None`: the chord
/// from `i` to `j` replaces the points between), and the two chains it splits into are done
/// alike, the later one first. The simplifications of rings, lines, lifted paths and gap
/// fills differ only in what `split` asks of a chord.
pub(crate) fn peucker_by(
    mut spans: Vec<(usize, usize)>,
    keep: &mut [bool],
    mut split: impl FnMut(usize, usize) -> Option<usize>,
) {
    while let Some((i, j)) = spans.pop() {
        if j <= i + 1 {
            continue;
        }
        if let Some(k) = split(i, j) {
            keep[k] = true;
            spans.push((i, k));
            spans.push((k, j));
        }
    }
}

/// Distance from `p` to the segment `a`–`b`.
pub(crate) fn seg_dist(p: Point2, a: Point2, b: Point2) -> f64 {
    dist(p, segment_foot(p, a, b).1)
}

/// The point of the segment `a`–`b` nearest `p`: its parameter `t` along the segment (0 at
/// `a`, 1 at `b`; 0 when the segment is a point), the point, and the segment's squared length.
pub(crate) fn segment_foot(p: Point2, a: Point2, b: Point2) -> (f64, Point2, f64) {
    let d = [b[0] - a[0], b[1] - a[1]];
    let l2 = d[0] * d[0] + d[1] * d[1];
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (t, [a[0] + t * d[0], a[1] + t * d[1]], l2)
}

pub(crate) fn on_boundary(p: Point2, poly: &[Point2], eps: f64) -> bool {
    let n = poly.len();
    (0..n).any(|i| seg_dist(p, poly[i], poly[(i + 1) % n]) <= eps)
}

/// Shapes the unit tests of the region operations build from.
#[cfg(test)]
pub(crate) mod shapes {
    use super::{region_area, Region};

    /// The rectangle `[x0, x1] × [y0, y1]`, counter-clockwise, without holes.
    pub(crate) fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Region {
        Region {
            outer: vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]],
            holes: vec![],
        }
    }

    /// The area of `r`, summed.
    pub(crate) fn area(r: &[Region]) -> f64 {
        r.iter().map(region_area).sum()
    }
}
