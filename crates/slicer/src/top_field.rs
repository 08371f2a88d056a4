//! The top's distance field of a freeform feature for its transition layers
//! ([`crate::transition`]): `h_T(q)` on a grid of the reference surface's chart, continued
//! past the top's footprint, and with offset layers first the top of their stack `D(q)`.

use crate::geom2d::Point2;
use crate::tolerance::COUNT_SLACK;
use std::collections::VecDeque;

/// The top's distance from the base along the reference's normal, `h_T(q)`, sampled on a grid
/// of the chart and interpolated bilinearly; continued past the top's footprint.
#[derive(Debug, Clone)]
pub struct TopField {
    origin: Point2,
    cell: f64,
    nx: usize,
    ny: usize,
    pub(crate) h: Vec<f64>,
    /// Least, mean and greatest base-to-top distance over the top, mm.
    pub range: (f64, f64, f64),
    /// Offset layers first (see [`crate::transition::band`]): the transition band's least thickness
    /// `c` and the offset layers' thickness `h0`; `None` for transition layers from the base.
    band: Option<(f64, f64)>,
    /// With a band: the offset layers' smooth top on the grid.
    pub(crate) env: Vec<f64>,
}

impl TopField {
    /// The field from a grid of `nx × ny` cells `cell` wide from `origin`, `h` the top's
    /// distance where `covered` (the top's footprint): continued past it by the nearest
    /// covered value (breadth first), then relaxed towards the mean of the neighbours, covered
    /// cells held. `None` when no cell is covered.
    pub(crate) fn from_grid(
        origin: Point2,
        cell: f64,
        (nx, ny): (usize, usize),
        mut h: Vec<f64>,
        covered: &[bool],
    ) -> Option<TopField> {
        let vals: Vec<f64> = h.iter().copied().filter(|v| v.is_finite()).collect();
        if vals.is_empty() {
            return None;
        }
        let hmin = vals.iter().copied().fold(f64::INFINITY, f64::min);
        let hmax = vals.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let hmean = vals.iter().sum::<f64>() / vals.len() as f64;
        let mut queue: VecDeque<usize> = (0..h.len()).filter(|&i| covered[i]).collect();
        while let Some(i) = queue.pop_front() {
            let (x, y) = (i % nx, i / nx);
            let v = h[i];
            for (dx, dy) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
                let (a, b) = (x as i64 + dx, y as i64 + dy);
                if a < 0 || b < 0 || a >= nx as i64 || b >= ny as i64 {
                    continue;
                }
                let j = b as usize * nx + a as usize;
                if !h[j].is_finite() {
                    h[j] = v;
                    queue.push_back(j);
                }
            }
        }
        for _ in 0..40 {
            let prev = h.clone();
            for y in 0..ny {
                for x in 0..nx {
                    let i = y * nx + x;
                    if covered[i] {
                        continue;
                    }
                    let (mut s, mut k) = (0.0, 0.0);
                    for (a, b) in [
                        (x.wrapping_sub(1), y),
                        (x + 1, y),
                        (x, y.wrapping_sub(1)),
                        (x, y + 1),
                    ] {
                        if a < nx && b < ny {
                            s += prev[b * nx + a];
                            k += 1.0;
                        }
                    }
                    h[i] = s / k;
                }
            }
        }
        Some(TopField {
            origin,
            cell,
            nx,
            ny,
            h,
            range: (hmin, hmean, hmax),
            band: None,
            env: vec![],
        })
    }

    /// The field with offset layers `h0` thick under a transition band (see [`band`]): the
    /// offset layers' smooth top `max(0, h_T − c)` lowered until its slope is at most `slope`
    /// (the greatest function under it that is `slope`-Lipschitz, by chamfer passes over the
    /// grid).
    pub(crate) fn with_band(mut self, c: f64, h0: f64, slope: f64) -> TopField {
        let (nx, ny) = (self.nx, self.ny);
        let mut env: Vec<f64> = self.h.iter().map(|h| (h - c).max(0.0)).collect();
        // Chamfer steps are longer than the true distance by up to 8 %: keep the slope under.
        let (s1, s2) = (
            0.92 * slope * self.cell,
            0.92 * slope * self.cell * 2f64.sqrt(),
        );
        let forward = [(-1i64, 0i64, s1), (0, -1, s1), (-1, -1, s2), (1, -1, s2)];
        let backward = [(1i64, 0i64, s1), (0, 1, s1), (1, 1, s2), (-1, 1, s2)];
        for _ in 0..2 {
            for y in 0..ny {
                for x in 0..nx {
                    relax(&mut env, nx, ny, x, y, &forward);
                }
            }
            for y in (0..ny).rev() {
                for x in (0..nx).rev() {
                    relax(&mut env, nx, ny, x, y, &backward);
                }
            }
        }
        self.env = env;
        self.band = Some((c, h0));
        self
    }

    /// The thickest the transition layers stack over a point, mm: the top's greatest distance
    /// from the base, or from the offset layers' stack under a band.
    pub(crate) fn band_max(&self) -> f64 {
        match self.band {
            Some((_, h0)) => self
                .h
                .iter()
                .zip(&self.env)
                .map(|(h, e)| h - h0 * (e / h0 + COUNT_SLACK).floor())
                .fold(0.0, f64::max),
            None => self.range.2,
        }
    }

    /// The band `(c, h0)` of [`TopField::with_band`].
    pub(crate) fn band_of(&self) -> Option<(f64, f64)> {
        self.band
    }

    /// Where the transition layers start over `q`, mm from the reference: 0, or with offset
    /// layers first the top of their stack there, `D(q)` (a staircase of whole layers).
    pub fn lower(&self, q: Point2) -> f64 {
        match self.band {
            Some((_, h0)) => h0 * (self.lower_smooth(q) / h0 + COUNT_SLACK).floor(),
            None => 0.0,
        }
    }

    /// [`TopField::lower`] before it is cut to whole layers: the transition layers' normals
    /// follow it (their positions follow the steps, so that every point's thickness stays in
    /// bounds).
    pub(crate) fn lower_smooth(&self, q: Point2) -> f64 {
        match self.band {
            Some(_) => self.bilinear(&self.env, q).max(0.0),
            None => 0.0,
        }
    }

    /// `h_T(q)`, mm: bilinear between cell centres, held at the grid's edge beyond it.
    pub fn height(&self, q: Point2) -> f64 {
        self.bilinear(&self.h, q)
    }

    /// The thickness over `q` of each of `n` transition layers, mm: `(h_T(q) − D(q)) / n`.
    pub(crate) fn layer_thickness(&self, q: Point2, n: f64) -> f64 {
        (self.height(q) - self.lower(q)) / n
    }

    /// Grid values `v` interpolated bilinearly at `q`.
    fn bilinear(&self, v: &[f64], q: Point2) -> f64 {
        let fx = ((q[0] - self.origin[0]) / self.cell - 0.5).clamp(0.0, (self.nx - 1) as f64);
        let fy = ((q[1] - self.origin[1]) / self.cell - 0.5).clamp(0.0, (self.ny - 1) as f64);
        if !(fx.is_finite() && fy.is_finite()) {
            return self.range.1;
        }
        let (x0, y0) = (fx.floor() as usize, fy.floor() as usize);
        let (x1, y1) = ((x0 + 1).min(self.nx - 1), (y0 + 1).min(self.ny - 1));
        let (tx, ty) = (fx - x0 as f64, fy - y0 as f64);
        let at = |x: usize, y: usize| v[y * self.nx + x];
        let a = at(x0, y0) * (1.0 - tx) + at(x1, y0) * tx;
        let b = at(x0, y1) * (1.0 - tx) + at(x1, y1) * tx;
        a * (1.0 - ty) + b * ty
    }
}

/// One chamfer step at cell `(x, y)`: its value lowered to a neighbour's plus the step's cost.
fn relax(v: &mut [f64], nx: usize, ny: usize, x: usize, y: usize, steps: &[(i64, i64, f64)]) {
    let i = y * nx + x;
    for &(dx, dy, cost) in steps {
        let (a, b) = (x as i64 + dx, y as i64 + dy);
        if a < 0 || b < 0 || a >= nx as i64 || b >= ny as i64 {
            continue;
        }
        let j = b as usize * nx + a as usize;
        if v[j] + cost < v[i] {
            v[i] = v[j] + cost;
        }
    }
}
