//! Sparse infill on curved layers (issue 33 item 1): the rule of planar layers
//! ([`crate::skins`]) along a freeform feature's stack of layers. The part of a layer's
//! interior within `top_solid_layers` of a top or `bottom_solid_layers` of a bottom (its skin,
//! found on the layers' sections in the chart) keeps the solid lines; the rest gets the
//! pattern's lines `bead width / infill_density` apart **on the layer surface**.
//!
//! The pattern is laid in geodesic coordinates: `a`, the signed distance on the surface across
//! the chart line along the raster direction through the region's deepest point, and `b`,
//! across the chart line square to it (both marched over the region's lattice, as the solid
//! lines' field is). A family of straight lines at angle θ from the raster direction is the
//! iso-lines of `a cos θ + b sin θ` a pitch apart (rectilinear: θ = 0, turned 90° every other
//! layer, pitch `w/d`; grid: 0° and 90°, `2w/d`; triangles: 0°, 60° and 120°, `3w/d`), and the
//! gyroid is the zero set of `sin x cos y + sin y cos z + sin z cos x` at `x = b`, `y = a` and
//! the layer's height `z` along the stack, scaled to its period. Each coordinate is offset by
//! the deepest point's chart coordinates, so the lines of one layer stand near those of the
//! next.
//!
//! The self-check's figures come from the same lattice: the sparse area is the surface area
//! of the lattice triangles past the inner edge of the last ring's bead and outside the
//! skin, each times the layer's thickness there; its lines cover `infill_density` of it (the
//! gyroid's share at the layer's height, [`crate::fill::sparse::layer_density`]).

use super::{seed_field, surface_length, FillPath};
use crate::chart::Chart;
use crate::geodesic::{clip_reaching, LayerMesh, RunOn};
use crate::geom2d::{Point2, RegionIndex};
use crate::params::{InfillPattern, LayerParams};
use crate::toolpath::Role;
use std::f64::consts::PI;

/// What a curved layer's sparse infill needs from the freeform planner.
pub(crate) struct CurvedSparse<'a> {
    /// The layer's solid skin (chart coordinates), indexed for inside tests; `None` when the
    /// whole layer is skin (within the solid layers of the feature's first or last layer).
    pub skin: Option<&'a [RegionIndex]>,
    /// The layer's thickness (mm) at a chart point, 0 where nothing is laid there.
    pub thickness: &'a (dyn Fn(Point2) -> f64 + Sync),
    /// The layer's middle along the stack from the reference, mm (the gyroid's height).
    pub height: f64,
}

impl CurvedSparse<'_> {
    /// Whether chart point `q` lies in the layer's skin.
    pub(crate) fn in_skin(&self, q: Point2) -> bool {
        match self.skin {
            None => true,
            Some(skin) => skin.iter().any(|r| r.contains(q)),
        }
    }
}

/// A region's sparse volume (mm³) and the part of it its lines cover.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct SparseVolume {
    /// Surface area laid sparse × the layer's thickness there, mm³.
    pub volume: f64,
    /// `volume` × the pattern's density on this layer, mm³.
    pub laid: f64,
}

impl std::ops::AddAssign for SparseVolume {
    fn add_assign(&mut self, o: SparseVolume) {
        self.volume += o.volume;
        self.laid += o.laid;
    }
}

/// The sparse part of a region's lattice: the surface area (mm², and times the thickness,
/// mm³) of its triangles whose middle lies at least `edge` from the region's boundary (`db`)
/// and outside the skin.
fn sparse_measure(lm: &LayerMesh, db: &[f64], edge: f64, sparse: &CurvedSparse) -> (f64, f64) {
    let (mut area, mut volume) = (0.0, 0.0);
    for t in &lm.tris {
        let [a, b, c] = t.map(|v| v as usize);
        let d = (db[a] + db[b] + db[c]) / 3.0;
        if !(d.is_finite() && d >= edge) {
            continue;
        }
        let q = [
            (lm.q[a][0] + lm.q[b][0] + lm.q[c][0]) / 3.0,
            (lm.q[a][1] + lm.q[b][1] + lm.q[c][1]) / 3.0,
        ];
        if sparse.in_skin(q) {
            continue;
        }
        let s = 0.5 * (lm.p[b] - lm.p[a]).cross(&(lm.p[c] - lm.p[a])).norm();
        if s.is_finite() {
            area += s;
            volume += s * (sparse.thickness)(q);
        }
    }
    (area, volume)
}

/// The geodesic frame of a region's pattern: the fields `a` and `b` (see the module) offset to
/// the chart's origin.
struct Frame {
    a: Vec<f64>,
    b: Vec<f64>,
}

impl Frame {
    fn new(
        lm: &LayerMesh,
        chart: &Chart,
        z: f64,
        q0: Point2,
        dir: [f64; 2],
        spacing: f64,
    ) -> Frame {
        let nrm = [-dir[1], dir[0]];
        let off = |v: [f64; 2]| q0[0] * v[0] + q0[1] * v[1];
        let a = seed_field(lm, chart, z, q0, (dir, nrm), spacing);
        // Across the line along `nrm`: its own normal is −dir, so b grows along dir.
        let b = seed_field(lm, chart, z, q0, (nrm, [-dir[0], -dir[1]]), spacing);
        let (oa, ob) = (off(nrm), off(dir));
        Frame {
            a: a.into_iter().map(|x| x + oa).collect(),
            b: b.into_iter().map(|x| ob - x).collect(),
        }
    }

    /// `a cos θ + b sin θ` at each vertex: its iso-lines run at θ from the raster direction.
    fn across(&self, theta: f64) -> Vec<f64> {
        let (s, c) = theta.sin_cos();
        self.a
            .iter()
            .zip(&self.b)
            .map(|(a, b)| a * c + b * s)
            .collect()
    }
}

/// The sparse lines of a region's infill area and its sparse volume; `None` where the region's
/// sparse part is smaller than `solid_infill_below_area` (laid solid, as on planar layers).
/// `edge`: the inner edge of the last ring's bead (the boundary without rings), as
/// [`super::fill_region`] has it; `q0` the deepest point, `dir` the raster direction.
#[allow(clippy::too_many_arguments)]
pub(super) fn sparse_lines(
    lm: &LayerMesh,
    chart: &Chart,
    z: f64,
    db: &[f64],
    edge: f64,
    (q0, dir, spacing): (Point2, [f64; 2], f64),
    (params, layer, width): (&LayerParams, usize, f64),
    sparse: &CurvedSparse,
) -> Option<(Vec<FillPath>, SparseVolume)> {
    let density = params.infill_density;
    let (area, volume) = sparse_measure(lm, db, edge, sparse);
    if area <= 0.0 || area < params.solid_infill_below_area || density.is_nan() || density <= 0.0 {
        return None;
    }
    let frame = Frame::new(lm, chart, z, q0, dir, spacing);
    let pitch = width / density;
    let lines = |field: &[f64], levels: Vec<f64>| -> Vec<crate::geodesic::IsoLine> {
        levels
            .into_iter()
            .flat_map(|l| lm.iso_lines(field, l, db))
            .collect()
    };
    let straight = |theta: f64, pitch: f64| {
        let f = frame.across(theta);
        let (lo, hi) = f
            .iter()
            .filter(|x| x.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                (lo.min(x), hi.max(x))
            });
        if lo >= hi || !lo.is_finite() || (hi - lo) / pitch > 1e5 {
            return vec![];
        }
        let levels = ((lo / pitch).ceil() as i64..=(hi / pitch).floor() as i64)
            .map(|j| j as f64 * pitch)
            .collect();
        lines(&f, levels)
    };
    let iso = match params.infill_pattern {
        InfillPattern::Rectilinear => {
            let turn = if layer % 2 == 1 { 0.5 * PI } else { 0.0 };
            straight(turn, pitch)
        }
        InfillPattern::Grid => [0.0, 0.5 * PI]
            .into_iter()
            .flat_map(|t| straight(t, 2.0 * pitch))
            .collect(),
        InfillPattern::Triangles => [0.0, PI / 3.0, 2.0 * PI / 3.0]
            .into_iter()
            .flat_map(|t| straight(t, 3.0 * pitch))
            .collect(),
        InfillPattern::Gyroid => {
            let k = 2.0 * PI / crate::fill::sparse::gyroid_period(width, density);
            let (sz, cz) = (k * sparse.height).sin_cos();
            let g: Vec<f64> = frame
                .b
                .iter()
                .zip(&frame.a)
                .map(|(&x, &y)| {
                    let ((sx, cx), (sy, cy)) = ((k * x).sin_cos(), (k * y).sin_cos());
                    sx * cy + sy * cz + sz * cx
                })
                .collect();
            lines(&g, vec![0.0])
        }
    };
    // Each line cut where it meets the inner edge of the last ring's bead (`edge`), where the
    // sparse area is measured from: its strip (length × width) covers what the area counts,
    // and its end's round half overlaps the ring it is anchored on.
    let reach = RunOn { width, edge };
    let len = |a, b| surface_length(chart, z, a, b);
    let pieces: Vec<FillPath> = iso
        .iter()
        .flat_map(|line| clip_reaching(line, edge, reach, len))
        .map(|piece| FillPath::uniform(piece.body, width, Role::InternalInfill))
        .collect();
    let mut out = split_by(pieces, |q| sparse.in_skin(q)).1;
    let d = crate::fill::sparse::layer_density(params, sparse.height, width);
    let want = volume * d;
    // A region crossed by a few lines: where they fall on the pattern's fixed grid decides
    // what they lay (a boss 10 mm across, three grid lines a family, laid 9 % over its share
    // on every layer), so their beads are scaled to lay the share, within
    // [`MAX_SPARSE_SCALE`]; past a few lines the grid's phase evens out.
    let lines = want / (width * sparse_thickness(volume, area) * area.sqrt());
    if lines <= FEW_SPARSE_LINES {
        let laid: f64 = out
            .iter()
            .map(|p| p.strip_weighted(|a, b| surface_length(chart, z, a, b), sparse.thickness))
            .sum();
        if laid > 0.0 {
            let k = (want / laid).clamp(1.0 / MAX_SPARSE_SCALE, MAX_SPARSE_SCALE);
            for p in &mut out {
                p.widths.iter_mut().for_each(|w| *w *= k);
            }
        }
    }
    Some((out, SparseVolume { volume, laid: want }))
}

/// The region's mean thickness over its sparse area, mm (a layer's nominal one where the
/// area is empty).
fn sparse_thickness(volume: f64, area: f64) -> f64 {
    if area > 0.0 && volume > 0.0 {
        volume / area
    } else {
        1.0
    }
}

/// The most lines (the sparse share's length over the region's size, `√area`) for which a
/// region's sparse lines are scaled to lay its share ([`sparse_lines`]).
const FEW_SPARSE_LINES: f64 = 12.0;
/// The most a sparse bead is widened or narrowed by for that ([`FEW_SPARSE_LINES`]).
const MAX_SPARSE_SCALE: f64 = 1.25;

/// The paths `out` of a region with its solid infill lines (those from `from` on) kept on
/// the layer's skin and its sparse lines laid elsewhere ([`sparse_lines`]), with the sparse
/// volume; `out` as it is where the region's sparse part is too small for the pattern.
pub(super) fn lay(
    mut out: Vec<FillPath>,
    from: usize,
    (lm, chart, z, db, edge): (&LayerMesh, &Chart, f64, &[f64], f64),
    frame: (Point2, [f64; 2], f64),
    at: (&LayerParams, usize, f64),
    sparse: &CurvedSparse,
) -> (Vec<FillPath>, SparseVolume) {
    match sparse_lines(lm, chart, z, db, edge, frame, at, sparse) {
        None => (out, SparseVolume::default()),
        Some((lines, volume)) => {
            let solid = out.split_off(from);
            out.extend(split_by(solid, |q| sparse.in_skin(q)).0);
            out.extend(lines);
            (out, volume)
        }
    }
}

/// Bisection steps that place a path's crossing of the skin's boundary (a segment is a
/// lattice step or so long: 2⁻³⁰ of it).
const CROSSING_STEPS: usize = 30;

/// `paths` cut where they cross into or out of the set `inside`: the pieces inside, and those
/// outside. Each segment is tested at its ends and cut once, at the crossing found by
/// bisection (segments run a lattice step long, far shorter than the skin's features); the
/// widths are interpolated at the cut.
pub(crate) fn split_by(
    paths: Vec<FillPath>,
    inside: impl Fn(Point2) -> bool,
) -> (Vec<FillPath>, Vec<FillPath>) {
    let (mut ins, mut outs) = (vec![], vec![]);
    for p in paths {
        if p.points.is_empty() {
            continue;
        }
        let flags: Vec<bool> = p.points.iter().map(|&q| inside(q)).collect();
        if flags.iter().all(|&f| f) {
            ins.push(p);
            continue;
        }
        if flags.iter().all(|&f| !f) {
            outs.push(p);
            continue;
        }
        let mut cur = FillPath::empty(p.role);
        let mut state = flags[0];
        cur.points.push(p.points[0]);
        cur.widths.push(p.widths[0]);
        for (i, &flag) in flags.iter().enumerate().skip(1) {
            let (a, b) = (p.points[i - 1], p.points[i]);
            if flag != state {
                // The crossing: bisect between a (state) and b (not).
                let (mut lo, mut hi) = (0.0f64, 1.0f64);
                for _ in 0..CROSSING_STEPS {
                    let m = 0.5 * (lo + hi);
                    let q = [a[0] + (b[0] - a[0]) * m, a[1] + (b[1] - a[1]) * m];
                    if inside(q) == state {
                        lo = m;
                    } else {
                        hi = m;
                    }
                }
                let t = 0.5 * (lo + hi);
                let x = [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t];
                let w = p.widths[i - 1] + (p.widths[i] - p.widths[i - 1]) * t;
                cur.points.push(x);
                cur.widths.push(w);
                let done = std::mem::replace(&mut cur, FillPath::empty(p.role));
                if state { &mut ins } else { &mut outs }.push(done);
                cur.points.push(x);
                cur.widths.push(w);
                state = flag;
            }
            cur.points.push(b);
            cur.widths.push(p.widths[i]);
        }
        if state { &mut ins } else { &mut outs }.push(cur);
    }
    let keep = |v: Vec<FillPath>| -> Vec<FillPath> {
        v.into_iter().filter(|p| p.points.len() >= 2).collect()
    };
    (keep(ins), keep(outs))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_across_a_square_is_cut_at_its_edges() {
        let line = FillPath::uniform(
            (0..=40).map(|i| [i as f64 * 0.25, 0.3]).collect(),
            0.45,
            Role::InternalInfill,
        );
        let square = crate::geom2d::shapes::rect(2.0, -1.0, 6.0, 1.0);
        let index = RegionIndex::new(&square);
        let (ins, outs) = split_by(vec![line], |q| index.contains(q));
        assert_eq!(ins.len(), 1);
        assert_eq!(outs.len(), 2);
        let x = |p: &FillPath, k: usize| p.points[k][0];
        assert!((x(&ins[0], 0) - 2.0).abs() < 1e-6, "{:?}", ins[0].points[0]);
        assert!((x(&ins[0], ins[0].points.len() - 1) - 6.0).abs() < 1e-6);
        let total: f64 = ins
            .iter()
            .chain(&outs)
            .map(|p| p.strip_area(crate::geom2d::dist))
            .sum();
        assert!((total - 10.0 * 0.45).abs() < 1e-9, "{total}");
    }

    /// A flat square 40 mm across filled sparse with no skin (17 lines across at 20 %, too
    /// many for their beads to be scaled): each pattern's lines cover the density's share of
    /// the sparse area the planner reports, and the sparse area is the square inside the inner
    /// edge of the second ring's bead.
    #[test]
    fn sparse_lines_cover_the_density_of_the_sparse_area() {
        let plane = brep::surface::Surface::Plane {
            frame: brep::math::Frame::world(brep::math::P3::origin()),
        };
        let chart = Chart::unit(&plane);
        let region = crate::geom2d::shapes::rect(0.0, 0.0, 40.0, 40.0);
        let thickness = |_: Point2| 0.2;
        let (w, d) = (0.45, 0.2);
        for pattern in [
            InfillPattern::Rectilinear,
            InfillPattern::Grid,
            InfillPattern::Triangles,
            InfillPattern::Gyroid,
        ] {
            let params = LayerParams {
                infill_density: d,
                infill_pattern: pattern,
                ..LayerParams::default()
            };
            let sparse = CurvedSparse {
                skin: Some(&[]),
                thickness: &thickness,
                height: 3.1,
            };
            let (paths, v) = super::super::fill_region_with(
                &chart,
                &region,
                0.0,
                &params,
                (1, w, w, 0.1 * w),
                Some(&sparse),
            );
            let side = 40.0 - 2.0 * (2.0 * w);
            assert!(
                (v.volume / 0.2 - side * side).abs() < 0.01 * side * side,
                "{pattern:?}: sparse area {} for {}",
                v.volume / 0.2,
                side * side
            );
            let laid: f64 = paths
                .iter()
                .filter(|p| p.role == Role::InternalInfill)
                .map(|p| p.strip_area(crate::geom2d::dist))
                .sum();
            let want = v.laid / 0.2;
            assert!(
                (laid / want - 1.0).abs() < 0.02,
                "{pattern:?}: laid {laid:.2} mm^2 for {want:.2}"
            );
        }
    }
}
