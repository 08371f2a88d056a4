//! Cuts the mesher draws across a face (the seam side of a band or of a loop closed through a
//! pole), sampled like edges, and the joining of wrapping loops through them.

use super::edges::chord_deviation;
use super::options::MeshOptions;
use super::uv::{singular_kind, Pt};
use crate::math::P3;
use crate::surface::Surface;
use crate::tolerance::NONZERO;

/// Points strictly inside a cut the mesher adds across a face (not a B-rep edge: the seam side
/// of a band or of a loop closed through a pole), from `p` to `q` in `(u, v)`, spaced like an
/// edge by the chord and angle tolerances of the surface curve between them. A cut is drawn
/// twice, a period apart, so both sides must take these same vertices: a cut left as one
/// segment becomes a chord through the solid (a meridian from the rim to a sphere's pole).
pub(super) fn cut_points(
    s: &Surface,
    p: [f64; 2],
    q: [f64; 2],
    positions: &mut Vec<P3>,
    opts: &MeshOptions,
) -> Vec<Pt> {
    let at = |t: f64| [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])];
    let eval = |t: f64| {
        let uv = at(t);
        s.eval(uv[0], uv[1])
    };
    // Uniform steps first (a chord test between the ends alone can miss a curve that comes
    // back), unless the curve is straight (a cylinder's generator); then bisection by chord
    // deviation and the turn of the chord direction.
    const START: usize = 8;
    let (pp, pq) = (eval(0.0), eval(1.0));
    let chord = pq - pp;
    let straight = (1..START).all(|i| {
        let x = eval(i as f64 / START as f64) - pp;
        let dev = if chord.norm() > NONZERO {
            x.cross(&chord).norm() / chord.norm()
        } else {
            x.norm()
        };
        dev <= 0.1 * opts.chord_tol
    });
    if straight {
        return vec![];
    }
    let mut ts = vec![0.0];
    for i in 0..START {
        let (a, b) = (i as f64 / START as f64, (i + 1) as f64 / START as f64);
        cut_refine(&eval, a, b, opts, 0, &mut ts);
    }
    let mut out = vec![];
    for &t in &ts[1..ts.len() - 1] {
        let uv = at(t);
        let sing = singular_kind(s, uv);
        if sing != 0 {
            continue;
        }
        positions.push(s.eval(uv[0], uv[1]));
        out.push(Pt {
            uv,
            idx: (positions.len() - 1) as u32,
            sing,
        });
    }
    out
}

/// Bisects `[a, b]` of a cut until its chords are within tolerance, pushing the right ends.
fn cut_refine(
    eval: &dyn Fn(f64) -> P3,
    a: f64,
    b: f64,
    opts: &MeshOptions,
    depth: u32,
    out: &mut Vec<f64>,
) {
    let m = 0.5 * (a + b);
    if depth < 12 {
        let (pa, pm, pb) = (eval(a), eval(m), eval(b));
        let dev = chord_deviation(&pa, &pm, &pb);
        let (d0, d1) = (pm - pa, pb - pm);
        let turn = if d0.norm() > NONZERO && d1.norm() > NONZERO {
            2.0 * d0.angle(&d1)
        } else {
            0.0
        };
        if dev > opts.chord_tol || turn > opts.angle_tol {
            cut_refine(eval, a, m, opts, depth + 1, out);
            cut_refine(eval, m, b, opts, depth + 1, out);
            return;
        }
    }
    out.push(b);
}

/// Joins a loop winding `+1` with one winding `-1` (a band around a cylinder) into one polygon
/// through a cut at the first loop's start; the cut's two sides share their vertices.
pub(super) fn join_wrapping(
    a: Vec<Pt>,
    b: Vec<Pt>,
    axis: usize,
    per: f64,
    s: &Surface,
    positions: &mut Vec<P3>,
    opts: &MeshOptions,
) -> Vec<Pt> {
    let wa = a.clone();
    let first = wa[0];
    let mut end = first;
    // The loop that winds forward ends one period on.
    let forward = {
        let n = wa.len();
        let last = wa[n - 1].uv[axis];
        crate::math::nearest_periodic(first.uv[axis], last, per) > first.uv[axis]
    };
    end.uv[axis] += if forward { per } else { -per };
    // Start `b` at its point nearest the cut, shifted next to `end`.
    let target = end.uv[axis];
    let (j, _) = b
        .iter()
        .enumerate()
        .map(|(i, p)| {
            (
                i,
                (crate::math::nearest_periodic(p.uv[axis], target, per) - target).abs(),
            )
        })
        .min_by(|x, y| x.1.total_cmp(&y.1))
        .unwrap_or((0, 0.0));
    let m = b.len();
    let mut out = a;
    out.push(end);
    let mut prev = target;
    let mut run = Vec::with_capacity(m + 1);
    for k in 0..=m {
        let mut p = b[(j + k) % m];
        p.uv[axis] = crate::math::nearest_periodic(p.uv[axis], prev, per);
        prev = p.uv[axis];
        run.push(p);
    }
    // The cut from `end` to `b`'s first point, and its twin a period away from `b`'s last
    // point back to the start of `a`.
    let (b0, bn) = (run[0].uv, run[m].uv);
    let shift = [b0[0] - bn[0], b0[1] - bn[1]];
    let cut = cut_points(s, end.uv, b0, positions, opts);
    out.extend(cut.iter().copied());
    out.extend(run);
    out.extend(cut.iter().rev().map(|p| Pt {
        uv: [p.uv[0] - shift[0], p.uv[1] - shift[1]],
        ..*p
    }));
    out
}
