//! Filling one region of a layer, curved (in the chart of its reference surface) or planar
//! (thin regions and the strips rings leave): rings and lines as iso-lines of geodesic
//! distances on the layer surface ([`crate::geodesic`]), gap fill of strips too narrow for a
//! bead ([`gap`], its points thinned by [`thin_out`]; on a planar strip without rings, from
//! its chordal axis, [`strip`]), spurs into sharp corners ([`spurs`]),
//! zig-zag connectors along the infill boundary ([`border`]).

mod border;
mod conserve;
mod gap;
pub(crate) mod sparse;
mod spurs;
mod strip;
#[cfg(test)]
mod tests;
mod thin_out;

use crate::chart::Chart;
use crate::geodesic::{clip_reaching, LayerMesh, Piece, RunOn};
use crate::geom2d::{Point2, Region};
use crate::params::{LayerParams, PathMode};
use crate::tolerance::{ROUND_OFF, SHORT_VECTOR};
use crate::toolpath::Role;
use border::Border;
use brep::math::{P3, V3};
use brep::surface::Surface;
use gap::{gap_fill, ridge, Beside, Gap};

pub(crate) use spurs::corner_spurs_beside;

/// One path of a curved layer in chart coordinates (or of a planar layer in its plane's),
/// with the bead width at each point and what it is for.
#[derive(Debug, Clone, PartialEq)]
pub struct FillPath {
    /// Bead centre line.
    pub points: Vec<Point2>,
    /// Bead width at each point, mm.
    pub widths: Vec<f64>,
    /// What the path is for.
    pub role: Role,
}

impl FillPath {
    /// A path of one bead width throughout.
    pub fn uniform(points: Vec<Point2>, width: f64, role: Role) -> Self {
        let widths = vec![width; points.len()];
        FillPath {
            points,
            widths,
            role,
        }
    }

    /// A path with no points yet.
    pub fn empty(role: Role) -> Self {
        FillPath {
            points: vec![],
            widths: vec![],
            role,
        }
    }

    /// The area its beads cover, mm²: each segment's length by `len` (the chord on the layer
    /// surface, or in the plane) times its mean width; segments of no finite length count none.
    pub fn strip_area(&self, len: impl Fn(Point2, Point2) -> f64) -> f64 {
        self.strip_weighted(len, |_| 1.0)
    }

    /// [`FillPath::strip_area`] with each segment's strip times `weight` at its middle (the
    /// layer's thickness there: the volume its beads lay, mm³).
    pub fn strip_weighted(
        &self,
        len: impl Fn(Point2, Point2) -> f64,
        weight: impl Fn(Point2) -> f64,
    ) -> f64 {
        (1..self.points.len())
            .map(|i| {
                let (a, b) = (self.points[i - 1], self.points[i]);
                let l = len(a, b);
                if l.is_finite() {
                    let mid = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
                    0.5 * (self.widths[i - 1] + self.widths[i]) * l * weight(mid)
                } else {
                    0.0
                }
            })
            .sum()
    }

    /// The same path run the other way.
    pub fn reverse(&mut self) {
        self.points.reverse();
        self.widths.reverse();
    }
}

/// Paths of a region of a planar layer (in its plane's 2-D coordinates) filled as the regions
/// of curved layers are: rings and raster lines as iso-lines of the exact distance to the
/// boundary, where rings leave a strip narrower than a bead a gap fill as wide as the strip
/// at each point, and spurs into sharp corners. The planar planner fills its thin regions so
/// (a blade's or a rib's section), where offsetting rings of one width would overlap their
/// own beads or drop what is narrower than a bead.
///
/// `boundary` says what the region's boundary is: the part's surface, which a bead's middle
/// stays a tenth of a bead inside in a region too thin for a ring, or the edge of beads laid
/// around it (a strip rings leave), which the beads may reach within a fiftieth.
pub fn fill_flat_region(
    region: &Region,
    params: &LayerParams,
    layer: usize,
    width: f64,
    spacing: f64,
    boundary: Boundary,
) -> Vec<FillPath> {
    let plane = Surface::Plane {
        frame: brep::math::Frame::world(P3::origin()),
    };
    // The plane's own (u, v) at scale 1 is the identity on the layer's 2-D coordinates.
    let chart = Chart::unit(&plane);
    let sliver_inset = match boundary {
        Boundary::Part => SLIVER_INSET,
        Boundary::Beads => GAP_INSET,
    } * width;
    let mut paths = vec![];
    // Rings where a strip is wide enough for one, and the narrowest bead of a strip without.
    let rings = ring_count(params) > 0;
    let min_width = SLIVER_MIN_WIDTH_SHARE * width;
    // Each piece a seam joined on its own (its width sets its lattice's step); a plain strip
    // too narrow for a ring gets its gap fill from its chordal axis.
    for piece in crate::fill::parted_at_seams(region, SEAM_SHARE * width) {
        let mut laid = match strip::strip_fill(&piece, width, min_width, rings) {
            Some(laid) => laid,
            None => fill_region(
                &chart,
                &piece,
                0.0,
                params,
                layer,
                width,
                spacing,
                sliver_inset,
            ),
        };
        let spurs = corner_spurs_beside(&chart, &piece, 0.0, width, &laid);
        laid.extend(spurs);
        paths.extend(laid);
    }
    paths.retain(|p| p.points.len() >= 2);
    if boundary == Boundary::Beads {
        // A strip the rings leave: its beads, as wide as the strip, are gap fill.
        for p in &mut paths {
            p.role = Role::GapFill;
        }
    }
    paths
}

/// Half the width (in bead widths) of the thinnest part of a planar region that
/// [`fill_flat_region`] fills: thinner parts are seams, where the region is parted
/// ([`crate::fill::parted_at_seams`]). 0.0045 mm for 0.45 mm beads: parts under 0.009 mm
/// across, a tenth of the narrowest gap fill's bead ([`SLIVER_MIN_WIDTH_SHARE`]).
const SEAM_SHARE: f64 = 0.01;

/// What bounds a region filled by [`fill_flat_region`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Boundary {
    /// The part's surface (a layer's section).
    Part,
    /// The edges of beads laid around it (a strip the rings of `fill::fill_layer` leave).
    Beads,
}

/// How far inside a region too thin for a ring its gap fill's bead middles stay, in bead
/// widths, where the boundary is the part's: clear of the region's sampling error.
pub(crate) const SLIVER_INSET: f64 = 0.1;
/// The same where the boundary is a bead's edge (or the strip the last ring leaves).
const GAP_INSET: f64 = 0.02;

/// Paths of one region of a curved layer at offset `z`, in chart coordinates. Where the region
/// is too thin for a ring, the gap fill's bead middles stay `sliver_inset` inside it.
#[allow(clippy::too_many_arguments)]
pub(crate) fn fill_region(
    chart: &Chart,
    region: &Region,
    z: f64,
    params: &LayerParams,
    layer: usize,
    width: f64,
    spacing: f64,
    sliver_inset: f64,
) -> Vec<FillPath> {
    fill_region_with(
        chart,
        region,
        z,
        params,
        (layer, width, spacing, sliver_inset),
        None,
    )
    .0
}

/// [`fill_region`], and with `sparse` (a curved layer of a feature with sparse infill,
/// [`sparse::CurvedSparse`]) its infill lines solid on the layer's skin only and the sparse
/// pattern's elsewhere, with the sparse volume that lays.
pub(crate) fn fill_region_with(
    chart: &Chart,
    region: &Region,
    z: f64,
    params: &LayerParams,
    (layer, width, spacing, sliver_inset): (usize, f64, f64, f64),
    sparse: Option<&sparse::CurvedSparse>,
) -> (Vec<FillPath>, sparse::SparseVolume) {
    let none = sparse::SparseVolume::default();
    let mut out = vec![];
    let Some(lm) = lifted_mesh(chart, region, z, spacing) else {
        return (out, none);
    };
    // Exact distances (to the lifted boundary) three spacings deep: the rings of the default
    // contour-zig-zag, the infill's edge and a thin blade's ridge all lie there, so they do
    // not depend on how well the front is marched over the lattice.
    let db = lm.march(&lm.boundary_seeds(SEED_DEPTH * spacing));
    let (deep, dmax) = db.iter().enumerate().filter(|(_, d)| d.is_finite()).fold(
        (0usize, 0.0f64),
        |a, (i, &d)| if d > a.1 { (i, d) } else { a },
    );
    // Rings: iso-lines of the distance to the boundary, half a bead in, then a spacing apart.
    // Where the region is too narrow for a ring's bead and its mirror image from the other
    // side (the ridge of the distance, the region's half width R there, is less than the
    // ring's inner bead edge), the ring narrows to what is left between its outer bead edge
    // and the ridge, `R − (c − w/2)`, extruded for that width by Eq. 1: the two sides then
    // put down the strip's volume instead of overlapping (a blade section 0.8 mm wide took
    // two full 0.45 mm beads). Where what is left is wider than a bead by less than the gap
    // fill's narrowest bead, the ring widens to take it. A ring less than a tenth of a bead
    // below the deepest point is left out.
    let (rings, levels) = ring_levels(params, width, spacing, dmax);
    let insets = Insets::new(sliver_inset, width);
    // The ridge is needed only where the rings' iso-lines run: at both ends of each lattice
    // edge those levels cross.
    let ridge = ring_ridge(&lm, &db, &levels, width, spacing);
    let (last_ring, last_ring_from) = lay_rings(&lm, &db, &ridge, &levels, width, insets, &mut out);
    // Infill where the rings stop: lines end a spacing past the last ring, joined along that
    // boundary (as on planar layers), or half a bead inside the boundary without rings. Where
    // the rings leave only a strip narrower than that (a thin blade), the lines cross the strip
    // from the edge of the last ring's bead instead, filling the gap.
    // The gap fill of all that is left farther in than `gap.edge` (no ring or line beyond
    // it), within what that core holds.
    let Some(inner) = infill_start(
        (&lm, &db, chart, z),
        (last_ring, last_ring_from, rings, dmax),
        (width, spacing, sliver_inset),
        &mut out,
    ) else {
        return (out, none);
    };
    let zig = params.path_mode != PathMode::Raster;
    let infill = crate::fill::infill_role(width, spacing);
    let dir = raster_dir(params, zig && layer % 2 == 1);
    let nrm = [-dir[1], dir[0]];
    // The seed curve: the chart line along `dir` through the deepest point; the field is the
    // signed geodesic distance to it, so its iso-lines are geodesic parallels.
    let phi = seed_field(&lm, chart, z, lm.q[deep], (dir, nrm), spacing);
    // The infill's area: inside the inner edge of the last ring's bead (half a spacing short
    // of the infill boundary), or the whole region without rings.
    let edge = if last_ring.is_some() {
        inner - 0.5 * spacing
    } else {
        0.0
    };
    let Some((lo, hi)) = level_span(&lm, &phi, &db, edge) else {
        return (out, none);
    };
    if (hi - lo) / spacing > 1e5 {
        return (out, none);
    }
    // Lines a whole number of spacings across the infill area, centred on it: the spacing
    // and the bead width with it (Eq. 1 extrudes for that width) stretch or shrink so that
    // the beads' strips fill the area's extent across the lines exactly, as a planar
    // slicer's solid infill does. At the nominal spacing a region a few beads across kept a
    // strip up to a spacing wide unfilled beside its outer lines (7–10 % of a small boss's
    // layer).
    let (width0, spacing0) = (width, spacing);
    let n = ((hi - lo) / spacing).round().max(1.0);
    let step = (hi - lo) / n;
    let width = width * step / spacing;
    if width < 0.2 * spacing {
        return (out, none);
    }
    let spacing = step;
    let (j0, j1) = (0i64, n as i64 - 1);
    // A line end with no connector to meet runs on to the boundary, or inside rings to the
    // inner edge of the last ring's bead, so the line's strip of the region is filled up to
    // it (`fill::bead_end_reach`, as on planar layers): every raster end, and the two free
    // ends of each zig-zag chain.
    let reach = RunOn { width, edge };
    let pieces = infill_pieces(
        &lm,
        chart,
        z,
        (&phi, &db),
        (lo, spacing, j0..=j1),
        (inner, reach),
        dir,
    );
    let from = out.len();
    lay_lines(
        &lm,
        &db,
        pieces,
        zig,
        inner,
        (spacing, width),
        infill,
        &mut out,
    );
    // A small core's few lines put down what it holds ([`SMALL_CORE_LINES`]).
    if n <= SMALL_CORE_LINES {
        let lines = out.split_off(from);
        out.extend(conserved(lines, &lm, &db, edge, |a, b| {
            surface_length(chart, z, a, b)
        }));
    }
    // Sparse infill (issue 33): the solid lines kept on the skin, the pattern's elsewhere.
    match sparse.filter(|s| s.skin.is_some()) {
        None => (out, none),
        Some(sparse) => {
            let frame = (lm.q[deep], raster_dir(params, false), spacing0);
            let at = (&lm, chart, z, db.as_slice(), edge);
            sparse::lay(out, from, at, frame, (params, layer, width0), sparse)
        }
    }
}

/// Where a region's infill lines start (the level of the distance `db` a spacing past the
/// last ring, at `last_ring`, or half a bead in without rings); `None` where the region is too
/// narrow for lines: then the gap fill of what is left is pushed onto `out` instead (the strip
/// along the ridge that the last ring's bead leaves, conserved with the last ring from
/// `last_ring_from`, or a region too thin for a ring filled from its boundary).
fn infill_start(
    (lm, db, chart, z): (&LayerMesh, &[f64], &Chart, f64),
    (last_ring, last_ring_from, rings, dmax): (Option<f64>, usize, usize, f64),
    (width, spacing, sliver_inset): (f64, f64, f64),
    out: &mut Vec<FillPath>,
) -> Option<f64> {
    let core_fill = |gap: Gap| core_fill(lm, db, chart, z, gap, width);
    match last_ring {
        Some(c) if dmax > c + 1.5 * spacing => Some(c + spacing),
        Some(c) => {
            // The strip along the ridge that the last ring's bead leaves.
            let edge = c + 0.5 * width;
            let gap = Gap {
                edge,
                inset: GAP_INSET * width,
                min_width: GAP_MIN_WIDTH_SHARE * width,
                below: f64::INFINITY,
            };
            out.extend(core_fill(gap));
            conserve::conserve_core(
                &mut out[last_ring_from..],
                lm.area_above(db, c - 0.5 * width),
                width,
                conserve::MAX_LAST_RING_SCALE,
                |a, b| surface_length(chart, z, a, b),
            );
            None
        }
        // A region too thin for a ring (the sliver a curved layer cuts off a blade's tip or
        // edge): the same gap fill from its boundary, the beads' middles a tenth of a bead
        // inside it, down to a fifth of a bead wide.
        None if rings > 0 || dmax <= 0.5 * width => {
            let gap = Gap {
                edge: 0.0,
                inset: sliver_inset,
                min_width: SLIVER_MIN_WIDTH_SHARE * width,
                below: f64::INFINITY,
            };
            out.extend(core_fill(gap));
            None
        }
        None => Some(0.5 * width),
    }
}

/// The infill's pieces as paths onto `out`: zig-zag, each line's end joined to the nearest end
/// of a line on the next level along the infill boundary (the iso-line of `db` at `inner`,
/// where the lines were cut) when that way is short; or raster lines, each run on.
#[allow(clippy::too_many_arguments)]
fn lay_lines(
    lm: &LayerMesh,
    db: &[f64],
    pieces: Vec<(i64, Piece)>,
    zig: bool,
    inner: f64,
    (spacing, width): (f64, f64),
    infill: Role,
    out: &mut Vec<FillPath>,
) {
    if zig {
        let border = lm.iso_lines(db, inner, db);
        join_zigzag(pieces, &Border::new(&border), spacing, width, infill, out);
    } else {
        out.extend(
            pieces
                .into_iter()
                .map(|(_, p)| FillPath::uniform(p.reaching(), width, infill)),
        );
    }
}

/// The most infill lines a core has for its lines to be made to put down what it holds
/// ([`fill_region`]). Their strips' square ends stand past a round core's rim or fall short of
/// it, by a share that grows as the lines get fewer (a pin 3.8 mm across on a dome, its core
/// crossed by three lines, was laid 9 % over its core, 2.1 % over the pin); past a few, their
/// ends' error is a small share of the core.
const SMALL_CORE_LINES: f64 = 4.0;

/// The rings asked for by the path mode, and their levels: half a bead in, then a spacing
/// apart, down to a tenth of a bead below the deepest point `dmax`.
fn ring_levels(params: &LayerParams, width: f64, spacing: f64, dmax: f64) -> (usize, Vec<f64>) {
    let rings = ring_count(params);
    let levels: Vec<f64> = (0..rings)
        .map(|j| 0.5 * width + j as f64 * spacing)
        .take_while(|c| *c <= dmax - 0.1 * width)
        .collect();
    (rings, levels)
}

/// The rings the path mode asks for: none with raster or zig-zag lines, as many as fit in
/// contour mode, the perimeters in contour-zig-zag.
fn ring_count(params: &LayerParams) -> usize {
    match params.path_mode {
        PathMode::Raster | PathMode::Zigzag => 0,
        PathMode::Contour => usize::MAX,
        PathMode::ContourZigzag => params.perimeters,
    }
}

/// The chart direction of the infill's lines: the raster angle, turned a quarter on the odd
/// layers of a zig-zag (`turned`).
fn raster_dir(params: &LayerParams, turned: bool) -> [f64; 2] {
    let angle = if turned {
        params.raster_angle_deg + 90.0
    } else {
        params.raster_angle_deg
    }
    .to_radians();
    [angle.cos(), angle.sin()]
}

/// The lattice step of a region filled with lines `spacing` apart: a third of a spacing, or
/// for a region narrower than that allows (its mean width, twice its area over its
/// perimeter, under [`LATTICE_PER_WIDTH`] steps) finer, down to [`FINEST_LATTICE_SHARE`] of
/// a spacing. A strip 0.2 mm wide (a contact, an LED's lead) fell between the vertices of a
/// 0.15 mm lattice and got no bead at all. Regions at least a spacing wide keep the coarse
/// lattice: finer, the rims of a pin's curved layers on a dome (family `pin_1`) were filled
/// 3.02 % over their volume.
fn lattice_step(region: &Region, spacing: f64) -> f64 {
    let coarse = spacing / 3.0;
    let perimeter: f64 = std::iter::once(&region.outer)
        .chain(region.holes.iter())
        .map(|r| {
            (0..r.len())
                .map(|i| {
                    let (a, b) = (r[i], r[(i + 1) % r.len()]);
                    (b[0] - a[0]).hypot(b[1] - a[1])
                })
                .sum::<f64>()
        })
        .sum();
    let area = 0.5 * crate::geom2d::area2(&region.outer).abs()
        - region
            .holes
            .iter()
            .map(|h| 0.5 * crate::geom2d::area2(h).abs())
            .sum::<f64>();
    if !(perimeter > 0.0 && area > 0.0) {
        return coarse;
    }
    let width = 2.0 * area / perimeter;
    if width >= spacing {
        // Wide enough for the coarse lattice to find: finer steps only move its iso-lines.
        return coarse;
    }
    (width / LATTICE_PER_WIDTH).clamp(FINEST_LATTICE_SHARE * spacing, coarse)
}

/// Lattice steps across a region's mean width, at least ([`lattice_step`]). Four, not the six
/// it was: a thin strip's lattice holds (steps across)² times its length over its width in
/// vertices, and NIST CTC-05's contour fill spent most of its time on the lattices of the
/// strips its rings leave (0.1–0.4 mm wide, up to 300 mm long). At four: 193.8 → 171.2 s,
/// user 328 → 282 s, 12,711,963.5 → 12,711,957.0 mm³; every fixture's volume on delta5 the
/// same to 0.01 % (the cone's and the impeller's points alone change), 2026-11-29.
const LATTICE_PER_WIDTH: f64 = 4.0;
/// The finest lattice step, in spacings ([`lattice_step`]).
const FINEST_LATTICE_SHARE: f64 = 0.02;

/// The lattice of a region at offset `z`, lifted onto the layer surface; `None` where it has no
/// triangle or a point does not lift.
fn lifted_mesh(chart: &Chart, region: &Region, z: f64, spacing: f64) -> Option<LayerMesh> {
    let step = lattice_step(region, spacing);
    let mut lm = LayerMesh::build_with_metric(region, step, chart.metric(region, z));
    if lm.tris.is_empty() {
        return None;
    }
    let mut pts = Vec::with_capacity(lm.q.len());
    for q in &lm.q {
        match chart.point(*q, z) {
            Some(p) => pts.push(p),
            None => return None,
        }
    }
    lm.p = pts;
    Some(lm)
}

/// The gap fill of all that is left farther in than `gap.edge` (no ring or line beyond it),
/// within what that core holds.
fn core_fill(
    lm: &LayerMesh,
    db: &[f64],
    chart: &Chart,
    z: f64,
    gap: Gap,
    width: f64,
) -> Vec<FillPath> {
    conserved(
        gap_fill(lm, db, gap, width, None),
        lm,
        db,
        gap.edge,
        |a, b| surface_length(chart, z, a, b),
    )
}

/// The infill's lines: iso-lines of `phi` at levels `j0..=j1` (a spacing apart from `lo`),
/// clipped to `inner` and run on to the reach's edge, each along `dir`; with their level index.
fn infill_pieces(
    lm: &LayerMesh,
    chart: &Chart,
    z: f64,
    (phi, db): (&[f64], &[f64]),
    (lo, spacing, levels): (f64, f64, std::ops::RangeInclusive<i64>),
    (inner, reach): (f64, RunOn),
    dir: [f64; 2],
) -> Vec<(i64, Piece)> {
    let RunOn { width, edge } = reach;
    let mut pieces: Vec<(i64, Piece)> = vec![];
    for j in levels {
        let level = lo + (j as f64 + 0.5) * spacing;
        for line in lm.iso_lines(phi, level, db) {
            let len = |a, b| surface_length(chart, z, a, b);
            let mut cut = clip_reaching(&line, inner, reach, len);
            if cut.is_empty() {
                // A line beside the infill boundary's reach (in a small area, or one
                // narrowing to a corner) crosses only the band between the last ring's bead
                // and the boundary where connectors run: it fills its strip of that band
                // from edge to edge, on its own.
                cut = clip_reaching(&line, edge + crate::fill::END_MARGIN * width, reach, len);
            }
            for piece in cut {
                let (a, b) = (piece.body[0], piece.body[piece.body.len() - 1]);
                let piece = if (b[0] - a[0]) * dir[0] + (b[1] - a[1]) * dir[1] < 0.0 {
                    piece.reversed()
                } else {
                    piece
                };
                pieces.push((j, piece));
            }
        }
    }
    pieces
}

/// How far inside the strip it fills a gap fill's bead middles stay: `sliver` where the
/// strip's edge is the region's boundary (beside the first ring, where the region is too
/// narrow for it), `gap` where it is the edge of a ring's bead.
#[derive(Debug, Clone, Copy)]
struct Insets {
    sliver: f64,
    gap: f64,
}

impl Insets {
    /// `sliver` beside the boundary, [`GAP_INSET`] of a bead `width` beside a bead's edge.
    fn new(sliver: f64, width: f64) -> Insets {
        Insets {
            sliver,
            gap: GAP_INSET * width,
        }
    }
}

/// The gap fill where ring `j` (at level `c`) does not reach: the strip the ring before
/// leaves along the ridge, or for the first ring the stretches of the region too narrow for
/// it (a contact 0.3 mm wide off a body 1 mm thick, which the rings left empty: 25 % of
/// such a region), its beads down to a fifth of a bead as a region too thin for any ring.
fn gap_beside_ring(j: usize, c: f64, width: f64, insets: Insets) -> Gap {
    let (inset, min_width) = if j == 0 {
        (insets.sliver, SLIVER_MIN_WIDTH_SHARE * width)
    } else {
        (insets.gap, GAP_MIN_WIDTH_SHARE * width)
    };
    Gap {
        edge: c - 0.5 * width,
        inset,
        min_width,
        below: c,
    }
}

/// The ridge of the distance to the boundary where the rings at `levels` run (at both ends
/// of each lattice edge those levels cross); empty without rings.
fn ring_ridge(lm: &LayerMesh, db: &[f64], levels: &[f64], width: f64, spacing: f64) -> Vec<f64> {
    if levels.is_empty() {
        vec![]
    } else {
        // Each level with the highest ridge its ring tells apart: a full bead above the gap
        // fill's narrowest one past its edge (the gap fill finds its own ridge).
        let wanted: Vec<(f64, f64)> = levels
            .iter()
            .map(|&c| {
                (
                    c,
                    c - 0.5 * width + GAP_MIN_WIDTH_SHARE.mul_add(width, width),
                )
            })
            .collect();
        ridge(
            lm,
            db,
            &wanted,
            crate::geodesic::Reach::Within(1.5 * spacing),
        )
    }
}

/// The rings at `levels` (the first the external perimeter), each narrowed or widened to the
/// room left before the ridge, with the gap fill of the strip the ring before leaves where a
/// ring does not reach; pushed onto `out`. The last ring's level.
fn lay_rings(
    lm: &LayerMesh,
    db: &[f64],
    ridge: &[f64],
    levels: &[f64],
    width: f64,
    insets: Insets,
    out: &mut Vec<FillPath>,
) -> (Option<f64>, usize) {
    let mut last_ring = None;
    let mut last_ring_from = out.len();
    for (j, &c) in levels.iter().enumerate() {
        last_ring_from = out.len();
        let edge = c - 0.5 * width;
        let role = if j == 0 {
            Role::ExternalPerimeter
        } else {
            Role::Perimeter
        };
        let ring: Vec<FillPath> = lm
            .iso_lines(db, c, ridge)
            .into_iter()
            .map(|line| {
                let widths = line
                    .other
                    .iter()
                    .map(|r| {
                        let room = r - edge;
                        if room <= GAP_MIN_WIDTH_SHARE.mul_add(width, width) {
                            room.max(0.2 * width)
                        } else {
                            width
                        }
                    })
                    .collect();
                FillPath {
                    points: line.q,
                    widths,
                    role,
                }
            })
            .collect();
        // Where this ring does not reach (the region's half width is under `c` there), the
        // strip the ring before leaves along the ridge, or the region itself, gets its gap
        // fill.
        let beside = Beside::new(lm, &ring, 0.5 * width);
        out.extend(gap_fill(
            lm,
            db,
            gap_beside_ring(j, c, width, insets),
            width,
            Some(&beside),
        ));
        out.extend(ring);
        last_ring = Some(c);
    }
    (last_ring, last_ring_from)
}

/// The infill's field: the signed geodesic distance to the seed curve, the chart line along
/// `dir` through `q0` (the deepest point), so its iso-lines are geodesic parallels.
fn seed_field(
    lm: &LayerMesh,
    chart: &Chart,
    z: f64,
    q0: Point2,
    (dir, nrm): ([f64; 2], [f64; 2]),
    spacing: f64,
) -> Vec<f64> {
    let l: Vec<f64> =
        lm.q.iter()
            .map(|q| (q[0] - q0[0]) * nrm[0] + (q[1] - q0[1]) * nrm[1])
            .collect();
    // Vertices within a spacing of the seed line start at their distance across it: the
    // chart offset times the surface's stretch across the line there, i.e. the part of the
    // surface step along the chart normal that is square to the line's own surface direction
    // (a sheared chart does not map the chart normal to the surface normal of the line).
    let stretch = {
        let e = 1e-3;
        let step = |d: [f64; 2]| -> Option<V3> {
            let a = chart.point([q0[0] + e * d[0], q0[1] + e * d[1]], z)?;
            let b = chart.point([q0[0] - e * d[0], q0[1] - e * d[1]], z)?;
            Some((a - b) / (2.0 * e))
        };
        match (step(dir), step(nrm)) {
            (Some(t), Some(n)) if t.norm() > SHORT_VECTOR => {
                let t = t / t.norm();
                (n - t * n.dot(&t)).norm()
            }
            _ => 1.0,
        }
    };
    let seeds: Vec<(u32, f64)> = l
        .iter()
        .enumerate()
        .filter(|(_, x)| x.abs() * stretch <= spacing)
        .map(|(i, x)| (i as u32, x.abs() * stretch))
        .collect();
    let dist = lm.march(&seeds);
    let phi: Vec<f64> = dist
        .iter()
        .zip(&l)
        .map(|(d, l)| if *l < 0.0 { -d } else { *d })
        .collect();
    phi
}

/// Zig-zag: each line's end joined to the nearest end of a line on the next level, along the
/// infill boundary `along` (the iso-line where the lines were cut), when that way is short;
/// the chains pushed onto `out`.
fn join_zigzag(
    pieces: Vec<(i64, Piece)>,
    along: &Border,
    spacing: f64,
    width: f64,
    infill: Role,
    out: &mut Vec<FillPath>,
) {
    let mut used = vec![false; pieces.len()];
    for s in 0..pieces.len() {
        if used[s] {
            continue;
        }
        used[s] = true;
        let first = &pieces[s].1;
        let (mut level, mut pts) = (pieces[s].0, first.body.clone());
        pts.splice(0..0, first.head.iter().copied());
        let mut tail = first.tail.clone();
        loop {
            let end = pts[pts.len() - 1];
            let mut best: Option<(f64, usize, bool, Vec<Point2>)> = None;
            for (i, (lv, p)) in pieces.iter().enumerate() {
                if used[i] || *lv != level + 1 {
                    continue;
                }
                let p = &p.body;
                for (rev, q) in [(false, p[0]), (true, p[p.len() - 1])] {
                    if let Some((len, way)) = along.connect(end, q, 2.5 * spacing) {
                        if best.as_ref().is_none_or(|b| len < b.0) {
                            best = Some((len, i, rev, way));
                        }
                    }
                }
            }
            match best {
                Some((_, i, rev, way)) => {
                    used[i] = true;
                    let next = if rev {
                        pieces[i].1.clone().reversed()
                    } else {
                        pieces[i].1.clone()
                    };
                    pts.extend(way);
                    pts.extend(next.body);
                    tail = next.tail;
                    level += 1;
                }
                None => break,
            }
        }
        pts.extend(tail);
        out.push(FillPath::uniform(pts, width, infill));
    }
}

/// The paths of layer `layer` of `layers` with their internal infill made solid where the
/// layer is a feature's first or last (its bottom or top skin).
pub fn solid_on_skins(mut paths: Vec<FillPath>, layer: usize, layers: usize) -> Vec<FillPath> {
    if layer == 0 || layer + 1 >= layers {
        for p in &mut paths {
            if p.role == Role::InternalInfill {
                p.role = Role::SolidInfill;
            }
        }
    }
    paths
}

/// The range of `phi` over the part of the lattice where `db` is at least `edge`, with the
/// crossings of that level on the lattice's edges interpolated.
fn level_span(lm: &LayerMesh, phi: &[f64], db: &[f64], edge: f64) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut take = |x: f64| {
        if x.is_finite() {
            lo = lo.min(x);
            hi = hi.max(x);
        }
    };
    for t in &lm.tris {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            let (da, db_) = (db[a], db[b]);
            if da >= edge {
                take(phi[a]);
            }
            if (da - edge) * (db_ - edge) < 0.0 {
                let s = (edge - da) / (db_ - da);
                take(phi[a] + (phi[b] - phi[a]) * s);
            }
        }
    }
    (lo < hi).then_some((lo, hi))
}

/// Gap fill of the whole core a region's rings leave (or of a region too thin for a ring),
/// its widths scaled so that it puts down what the core holds: down where it would put down
/// more, up (by at most [`MAX_CORE_WIDENING`]) where less. Up: a core a lattice step or two
/// across breaks into islands along its ridge, whose beads fall short (the loop that made
/// them was two flanks of half-width beads: 12 % short on a 2 mm rib's 0.2 mm core, −3.8 % of
/// the rib); down: a compact core (a small boss's square one) whose ridge branches into its
/// corners (the loop laid it twice over: +5 % on a 3 mm pin). The core's area on the layer
/// surface is exact (the lattice's triangles clipped at the core's edge), and so is each
/// bead's strip by Eq. 1.
fn conserved(
    mut paths: Vec<FillPath>,
    lm: &LayerMesh,
    db: &[f64],
    edge: f64,
    len: impl Fn(Point2, Point2) -> f64,
) -> Vec<FillPath> {
    let covered: f64 = paths.iter().map(|p| p.strip_area(&len)).sum();
    scale_to_area(&mut paths, covered, lm.area_above(db, edge));
    paths
}

/// Scales the widths of `paths`, whose beads cover `covered` mm², so that they cover `held`
/// (by at most [`MAX_CORE_WIDENING`]), where the two differ by more than round-off.
fn scale_to_area(paths: &mut [FillPath], covered: f64, held: f64) {
    if covered > 0.0 && (covered - held).abs() > ROUND_OFF * held {
        let k = (held / covered).min(MAX_CORE_WIDENING);
        for w in paths.iter_mut().flat_map(|p| p.widths.iter_mut()) {
            *w *= k;
        }
    }
}

/// The length on the layer surface at `d` of the chart segment `a`–`b` (its chord there).
fn surface_length(chart: &Chart, d: f64, a: Point2, b: Point2) -> f64 {
    match (chart.point(a, d), chart.point(b, d)) {
        (Some(p), Some(q)) => (q - p).norm(),
        _ => f64::NAN,
    }
}

/// Most a core's gap fill is widened to put down what the core holds ([`conserved`]).
const MAX_CORE_WIDENING: f64 = 1.5;

/// The narrowest gap fill between rings, in bead widths: a ring with less than this left
/// beyond its bead widens to take it.
const GAP_MIN_WIDTH_SHARE: f64 = 0.1;
/// The narrowest bead of the gap fill of a region (or a stretch of one) too thin for a ring,
/// in bead widths.
const SLIVER_MIN_WIDTH_SHARE: f64 = 0.2;

/// Distances to a layer region's boundary are exact (not marched) this many spacings deep.
const SEED_DEPTH: f64 = 3.0;

/// [`crate::fill::order_paths`] for paths that carry their bead widths.
pub(crate) fn order_fill_paths(paths: Vec<FillPath>, start: Point2) -> Vec<FillPath> {
    let paths = paths.into_iter().filter(|p| p.points.len() >= 2).collect();
    crate::fill::order_greedy(paths, start, |p| &p.points, FillPath::reverse)
}
