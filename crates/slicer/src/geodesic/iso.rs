//! Iso-lines of a field on a layer mesh, chained into paths, and their pieces clipped where a
//! second field reaches a level.

use super::mesh::{IsoLine, LayerMesh};
use crate::fast_hash::{FastMap, FastSet};
use crate::fill::{bead_end_reach, MAX_END_REACH};
use crate::geom2d::Point2;

impl LayerMesh {
    /// The iso-lines `f = level` over the mesh, chained into polylines, with `other`
    /// interpolated along them. Triangles where `f` is not finite at a vertex are skipped.
    pub fn iso_lines(&self, f: &[f64], level: f64, other: &[f64]) -> Vec<IsoLine> {
        type Key = (u32, u32);
        let key = |a: u32, b: u32| (a.min(b), a.max(b));
        let mut point: FastMap<Key, (Point2, f64, u32)> = FastMap::default();
        let mut links: FastMap<Key, Vec<Key>> = FastMap::default();
        let at = |a: u32, b: u32| -> (Point2, f64, u32) {
            let (fa, fb) = (f[a as usize], f[b as usize]);
            let t = if (fb - fa).abs() > 0.0 {
                ((level - fa) / (fb - fa)).clamp(0.0, 1.0)
            } else {
                0.5
            };
            let (qa, qb) = (self.q[a as usize], self.q[b as usize]);
            (
                [qa[0] + (qb[0] - qa[0]) * t, qa[1] + (qb[1] - qa[1]) * t],
                other[a as usize] + (other[b as usize] - other[a as usize]) * t,
                if fa < fb { a } else { b },
            )
        };
        for tri in &self.tris {
            if tri.iter().any(|&v| !f[v as usize].is_finite()) {
                continue;
            }
            let up = [0, 1, 2].map(|k| f[tri[k] as usize] >= level);
            let Some(lone) = brep::section::lone_vertex(up) else {
                continue;
            };
            let (a, b, c) = (tri[lone], tri[(lone + 1) % 3], tri[(lone + 2) % 3]);
            let (e1, e2) = (key(a, b), key(a, c));
            point.entry(e1).or_insert_with(|| at(a, b));
            point.entry(e2).or_insert_with(|| at(a, c));
            links.entry(e1).or_default().push(e2);
            links.entry(e2).or_default().push(e1);
        }
        let mut used: FastSet<Key> = FastSet::default();
        let mut keys: Vec<Key> = links.keys().copied().collect();
        keys.sort_unstable();
        // Chain from the open ends first, then the rings.
        keys.sort_by_key(|k| links[k].len() != 1);
        let mut out = vec![];
        for s in keys {
            if used.contains(&s) {
                continue;
            }
            let mut chain = vec![s];
            used.insert(s);
            let mut cur = s;
            loop {
                let next = links[&cur].iter().copied().find(|k| !used.contains(k));
                match next {
                    Some(k) => {
                        used.insert(k);
                        chain.push(k);
                        cur = k;
                    }
                    None => break,
                }
            }
            let closed = chain.len() > 2 && links[&cur].contains(&s) && links[&s].len() == 2;
            let mut line = IsoLine {
                closed,
                ..IsoLine::default()
            };
            for k in &chain {
                let (q, o, low) = point[k];
                line.q.push(q);
                line.other.push(o);
                line.low.push(low);
            }
            if closed {
                line.q.push(line.q[0]);
                line.other.push(line.other[0]);
                line.low.push(line.low[0]);
            }
            if line.q.len() >= 2 {
                out.push(line);
            }
        }
        out
    }
}

/// A piece of an iso-line where the distance to the region's boundary is at least the
/// infill area's, and the ways on from its cut ends towards the boundary.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Piece {
    /// The line from cut to cut (or to the line's end), cut exactly at the crossings.
    pub body: Vec<Point2>,
    /// The way on before the body's first point, in the line's order (empty at a line end).
    pub head: Vec<Point2>,
    /// The way on after the body's last point.
    pub tail: Vec<Point2>,
}

impl Piece {
    /// The same piece run the other way.
    pub fn reversed(self) -> Piece {
        let rev = |mut v: Vec<Point2>| {
            v.reverse();
            v
        };
        Piece {
            body: rev(self.body),
            head: rev(self.tail),
            tail: rev(self.head),
        }
    }

    /// The body with both ways on: a raster line run on to the boundary.
    pub fn reaching(self) -> Vec<Point2> {
        let mut pts = self.head;
        pts.extend(self.body);
        pts.extend(self.tail);
        pts
    }
}

/// Where the free ends of [`clip_reaching`]'s pieces run on to, for beads `width` wide: the
/// level `edge` of the line's `other` value (the distance to the region's boundary): 0 for
/// the boundary itself, the inner edge of the last ring's bead inside rings.
#[derive(Debug, Clone, Copy)]
pub struct RunOn {
    /// Bead width, mm.
    pub width: f64,
    /// The `other` value the ends run on to.
    pub edge: f64,
}

/// The pieces of `line` where its `other` value (the distance to the region's boundary) is
/// at least `min`, cut exactly at the crossings, each with the ways on from its cut ends
/// along the line by [`bead_end_reach`]: the edge lies where `other` falls to `run_on.edge`
/// (or the line ends), the room is half the way to where `other` climbs back to `min` (the
/// next piece). `len` is the length on the surface between two chart points.
pub fn clip_reaching(
    line: &IsoLine,
    min: f64,
    run_on: RunOn,
    len: impl Fn(Point2, Point2) -> f64,
) -> Vec<Piece> {
    let n = line.q.len();
    let lerp = |a: Point2, b: Point2, t: f64| [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t];
    // The way on from a cut in segment `i` (between points i and i+1) at the cut point `x`,
    // forwards or backwards: the line's points beyond it up to the reach, not `x` itself.
    let run_on = |i: usize, x: Point2, forward: bool| -> Vec<Point2> {
        let RunOn { width, edge } = run_on;
        let mut pts = vec![];
        let (mut at, mut walked, mut prev_d) = (x, 0.0, min);
        let mut k = if forward { i + 1 } else { i };
        let (mut boundary, mut room) = (f64::INFINITY, f64::INFINITY);
        let mut steps: Vec<(Point2, f64)> = vec![];
        while k < n && walked < 2.0 * MAX_END_REACH * width {
            let (q, d) = (line.q[k], line.other[k]);
            let l = len(at, q);
            if !l.is_finite() {
                break;
            }
            if d <= edge {
                let t = if prev_d > d {
                    (prev_d - edge) / (prev_d - d)
                } else {
                    1.0
                };
                boundary = walked + t * l;
                break;
            }
            if d >= min {
                let t = if d > prev_d {
                    (min - prev_d) / (d - prev_d)
                } else {
                    0.0
                };
                room = 0.5 * (walked + t.clamp(0.0, 1.0) * l);
                break;
            }
            walked += l;
            steps.push((q, walked));
            at = q;
            prev_d = d;
            if forward {
                k += 1;
            } else if k == 0 {
                break;
            } else {
                k -= 1;
            }
        }
        if boundary.is_infinite() && room.is_infinite() && walked < 2.0 * MAX_END_REACH * width {
            // The line ends (on the mesh's edge) before either.
            boundary = walked;
        }
        let r = bead_end_reach(width, boundary, room);
        let (mut from, mut done) = (x, 0.0);
        for &(q, w) in &steps {
            if w >= r {
                let seg = w - done;
                let t = if seg > 0.0 { (r - done) / seg } else { 1.0 };
                pts.push(lerp(from, q, t.clamp(0.0, 1.0)));
                return pts;
            }
            pts.push(q);
            from = q;
            done = w;
        }
        if r > done {
            // The reach ends inside the step the walk stopped in (towards point `k`).
            if let Some(&q) = line.q.get(k) {
                let l = len(from, q);
                if l > 0.0 && l.is_finite() {
                    pts.push(lerp(from, q, ((r - done) / l).clamp(0.0, 1.0)));
                }
            }
        }
        pts
    };
    let mut out = vec![];
    let mut cur = Piece::default();
    for i in 0..n {
        let inside = line.other[i] >= min;
        if i > 0 {
            let (a, b) = (line.other[i - 1], line.other[i]);
            if (a >= min) != inside {
                let t = ((min - a) / (b - a)).clamp(0.0, 1.0);
                let x = lerp(line.q[i - 1], line.q[i], t);
                cur.body.push(x);
                if inside {
                    // Entering: the way back out, reversed, leads up to the cut.
                    let mut back = run_on(i - 1, x, false);
                    back.reverse();
                    cur.head = back;
                } else {
                    cur.tail = run_on(i - 1, x, true);
                    out.push(std::mem::take(&mut cur));
                }
            }
        }
        if inside {
            cur.body.push(line.q[i]);
        }
    }
    out.push(cur);
    out.retain(|p| p.body.len() >= 2);
    out
}
