//! Local-support B-spline evaluation.
//!
//! truck-geometry 0.5 evaluates a B-spline surface by summing over *every* control point
//! (O(n_u·n_v) per point); on real files with hundreds of control points that made one face
//! take 200 ms to mesh. Here only the `(p+1)(q+1)` control points whose basis functions are
//! non-zero are touched (span search and basis derivatives after Piegl & Tiller, *The NURBS
//! Book*, A2.1 and A2.3). truck's types still build and validate the splines; the test
//! `local_evaluation_agrees_with_truck` pins the agreement.

/// Largest degree we evaluate (the reader rejects higher ones).
pub const MAX_DEGREE: usize = 25;
const M: usize = MAX_DEGREE + 1;
/// Scratch width for degrees below it (nearly every real spline): the basis arrays stay small.
const SMALL: usize = 8;

/// The knot span `i` with `knots[i] <= t < knots[i+1]`, clamped to `[p, n-1]`.
pub fn find_span(knots: &[f64], p: usize, n: usize, t: f64) -> usize {
    if t >= knots[n] {
        // Last non-empty span.
        let mut i = n - 1;
        while i > p && knots[i] >= knots[i + 1] {
            i -= 1;
        }
        return i;
    }
    if t <= knots[p] {
        let mut i = p;
        while i < n - 1 && knots[i + 1] <= knots[i] {
            i += 1;
        }
        return i;
    }
    let (mut lo, mut hi) = (p, n);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if t < knots[mid] {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo
}

/// Values and derivatives up to order `nd` (≤ 2) of the `p+1` basis functions non-zero on
/// `span`: `ders[k][j]` is the k-th derivative of `N_{span-p+j}`.
pub fn basis_ders(knots: &[f64], span: usize, t: f64, p: usize, nd: usize) -> [[f64; M]; 3] {
    // Scratch sized for the usual degrees keeps the zero-filling cheap.
    if p < SMALL {
        let d = basis_ders_n::<SMALL>(knots, span, t, p, nd);
        let mut out = [[0.0f64; M]; 3];
        for k in 0..3 {
            out[k][..SMALL].copy_from_slice(&d[k]);
        }
        return out;
    }
    basis_ders_n::<M>(knots, span, t, p, nd)
}

fn basis_ders_n<const N: usize>(
    knots: &[f64],
    span: usize,
    t: f64,
    p: usize,
    nd: usize,
) -> [[f64; N]; 3] {
    let mut ndu = [[0.0f64; N]; N];
    let mut left = [0.0f64; N];
    let mut right = [0.0f64; N];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = t - knots[span + 1 - j];
        right[j] = knots[span + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = if ndu[j][r] != 0.0 {
                ndu[r][j - 1] / ndu[j][r]
            } else {
                0.0
            };
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    let mut ders = [[0.0f64; N]; 3];
    for j in 0..=p {
        ders[0][j] = ndu[j][p];
    }
    let nd = nd.min(2).min(p);
    let mut a = [[0.0f64; N]; 2];
    for r in 0..=p {
        let (mut s1, mut s2) = (0usize, 1usize);
        a[0][0] = 1.0;
        for k in 1..=nd {
            let mut d = 0.0;
            let rk = r as isize - k as isize;
            let pk = p - k;
            if r >= k {
                let den = ndu[pk + 1][rk as usize];
                a[s2][0] = if den != 0.0 { a[s1][0] / den } else { 0.0 };
                d = a[s2][0] * ndu[rk as usize][pk];
            }
            let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
            let j2 = if r as isize - 1 <= pk as isize {
                k - 1
            } else {
                p - r
            };
            for j in j1..=j2 {
                let den = ndu[pk + 1][(rk + j as isize) as usize];
                a[s2][j] = if den != 0.0 {
                    (a[s1][j] - a[s1][j - 1]) / den
                } else {
                    0.0
                };
                d += a[s2][j] * ndu[(rk + j as isize) as usize][pk];
            }
            if r <= pk {
                let den = ndu[pk + 1][r];
                a[s2][k] = if den != 0.0 { -a[s1][k - 1] / den } else { 0.0 };
                d += a[s2][k] * ndu[r][pk];
            }
            ders[k][r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut f = p as f64;
    for k in 1..=nd {
        for j in 0..=p {
            ders[k][j] *= f;
        }
        f *= (p - k) as f64;
    }
    ders
}

/// A rational B-spline curve in homogeneous form, evaluated locally.
#[derive(Debug, Clone)]
pub struct LocalCurve {
    /// Full knot vector.
    pub knots: Vec<f64>,
    /// Degree.
    pub degree: usize,
    /// Homogeneous control points `(w·x, w·y, w·z, w)`.
    pub cps: Vec<[f64; 4]>,
}

impl LocalCurve {
    /// Point and first two derivatives at `t`.
    pub fn ders(&self, t: f64) -> [[f64; 3]; 3] {
        self.ders_upto(t, 2)
    }

    /// Point and derivatives up to order `nd` (≤ 2) at `t`; higher orders come back zero.
    pub fn ders_upto(&self, t: f64, nd: usize) -> [[f64; 3]; 3] {
        let p = self.degree;
        let span = find_span(&self.knots, p, self.cps.len(), t);
        // The usual degrees on a small scratch: the basis is not copied into the widest one.
        if p < SMALL {
            self.combine(
                &basis_ders_n::<SMALL>(&self.knots, span, t, p, nd),
                span,
                nd,
            )
        } else {
            self.combine(&basis_ders_n::<M>(&self.knots, span, t, p, nd), span, nd)
        }
    }

    /// The curve's homogeneous derivatives from the basis on `span`, made rational.
    fn combine<const N: usize>(&self, b: &[[f64; N]; 3], span: usize, nd: usize) -> [[f64; 3]; 3] {
        let p = self.degree;
        let mut h = [[0.0f64; 4]; 3];
        for j in 0..=p {
            let c = &self.cps[span - p + j];
            for k in 0..=nd.min(2) {
                for (d, hk) in h[k].iter_mut().enumerate() {
                    *hk += b[k][j] * c[d];
                }
            }
        }
        rational_curve(h)
    }
}

fn rational_curve(h: [[f64; 4]; 3]) -> [[f64; 3]; 3] {
    let w = h[0][3];
    let (w1, w2) = (h[1][3], h[2][3]);
    let mut out = [[0.0; 3]; 3];
    for d in 0..3 {
        let c0 = h[0][d] / w;
        let c1 = (h[1][d] - w1 * c0) / w;
        let c2 = (h[2][d] - 2.0 * w1 * c1 - w2 * c0) / w;
        out[0][d] = c0;
        out[1][d] = c1;
        out[2][d] = c2;
    }
    out
}

/// A rational B-spline surface in homogeneous form, evaluated locally.
#[derive(Debug, Clone)]
pub struct LocalSurface {
    /// Knots in `u`.
    pub ku: Vec<f64>,
    /// Knots in `v`.
    pub kv: Vec<f64>,
    /// Degrees.
    pub degree: (usize, usize),
    /// Control points in `u`, `v`.
    pub n: (usize, usize),
    /// Homogeneous control points, row-major: index `i * n.1 + j`.
    pub cps: Vec<[f64; 4]>,
}

impl LocalSurface {
    /// Point, `S_u` and `S_v` at `(u, v)`.
    pub fn eval_d1(&self, u: f64, v: f64) -> [[f64; 3]; 3] {
        let (p, q) = self.degree;
        let su = find_span(&self.ku, p, self.n.0, u);
        let sv = find_span(&self.kv, q, self.n.1, v);
        // The usual degrees on a small scratch, as for curves.
        if p < SMALL && q < SMALL {
            let bu = basis_ders_n::<SMALL>(&self.ku, su, u, p, 1);
            let bv = basis_ders_n::<SMALL>(&self.kv, sv, v, q, 1);
            self.combine(&bu, &bv, su, sv)
        } else {
            let bu = basis_ders_n::<M>(&self.ku, su, u, p, 1);
            let bv = basis_ders_n::<M>(&self.kv, sv, v, q, 1);
            self.combine(&bu, &bv, su, sv)
        }
    }

    /// Point, `S_u` and `S_v` from the bases in `u` and `v` on spans `su`, `sv`.
    fn combine<const N: usize>(
        &self,
        bu: &[[f64; N]; 3],
        bv: &[[f64; N]; 3],
        su: usize,
        sv: usize,
    ) -> [[f64; 3]; 3] {
        let (p, q) = self.degree;
        // h[0] = S_w, h[1] = ∂u S_w, h[2] = ∂v S_w.
        let mut h = [[0.0f64; 4]; 3];
        for a in 0..=p {
            let row = (su - p + a) * self.n.1;
            let mut t0 = [0.0f64; 4];
            let mut t1 = [0.0f64; 4];
            for b in 0..=q {
                let c = &self.cps[row + sv - q + b];
                for d in 0..4 {
                    t0[d] += bv[0][b] * c[d];
                    t1[d] += bv[1][b] * c[d];
                }
            }
            for d in 0..4 {
                h[0][d] += bu[0][a] * t0[d];
                h[1][d] += bu[1][a] * t0[d];
                h[2][d] += bu[0][a] * t1[d];
            }
        }
        let w = h[0][3];
        let mut out = [[0.0; 3]; 3];
        for d in 0..3 {
            let s = h[0][d] / w;
            out[0][d] = s;
            out[1][d] = (h[1][d] - h[1][3] * s) / w;
            out[2][d] = (h[2][d] - h[2][3] * s) / w;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_a_partition_of_unity_and_derivatives_sum_to_zero() {
        let knots = [0.0, 0.0, 0.0, 0.0, 0.3, 0.5, 0.5, 0.9, 1.0, 1.0, 1.0, 1.0];
        let p = 3;
        let n = knots.len() - p - 1;
        for i in 0..=50 {
            let t = i as f64 / 50.0;
            let s = find_span(&knots, p, n, t);
            let d = basis_ders(&knots, s, t, p, 2);
            let (s0, s1, s2): (f64, f64, f64) = (
                d[0][..=p].iter().sum(),
                d[1][..=p].iter().sum(),
                d[2][..=p].iter().sum(),
            );
            assert!(
                (s0 - 1.0).abs() < 1e-12 && s1.abs() < 1e-9 && s2.abs() < 1e-7,
                "t={t}: {s0} {s1} {s2}"
            );
        }
    }
}
