//! Filling one planar layer with extrusion paths.
//!
//! A layer's cross-section arrives as closed loops ([`regions_from_loops`] groups them into
//! [`Region`]s); [`fill_layer`] turns the regions into bead centre lines by the feature's
//! [`PathMode`], and [`order_paths`] puts them in a print order with short travels.
//!
//! Geometry: every bead centre line lies half a bead width or more inside the region, but
//! for the free ends of raster and zig-zag lines. The first perimeter is the region offset
//! inward by `width / 2`, each further one by another `spacing`; infill lines are `spacing`
//! apart and end on the boundary of the infill area (the region offset inward by
//! `width / 2`, plus `perimeters · spacing` for contour-zig-zag), where connectors join them.
//! A line end that nothing joins and no ring surrounds (every raster end, the first and last
//! end of a zig-zag chain) runs on to the region's boundary ([`bead_end_reach`]). Offsets are
//! Euclidean: around a reflex corner (a hole's polygon, an inner corner) the offset is an
//! arc, chorded within 1 % of the width, so there a centre line may come that much closer
//! than `width / 2`; convex corners and straight edges are exact.
//! Offsets and booleans are i_overlay's (`OutlineOffset`, `overlay`); offsets use its float
//! arithmetic and are made from contours rid of vertices too flat for its integer grid (the
//! collinear points a mesh's cross-section has on every chord of a curved face), on which its
//! construction leaves a spike from the offset out to the boundary. The infill lines are cut
//! against the (clean, non-self-intersecting) polygons i_overlay returns with an even-odd
//! scan, which also tells on which boundary ring, and where along it, each line ends — what
//! zig-zag needs to join neighbouring lines along the boundary.
//!
//! Where successive rings leave a strip narrower than a bead uncovered (the middle of a
//! rectangle whose width is not a multiple of the spacing, the neck between a hole and the
//! outside), that strip gets a gap-fill line along its length (kind [`PathKind::Infill`]).
//! Where a part of the region is too narrow for a ring's beads from both sides, or for the
//! first ring at all, that part is handed back ([`FilledLayer::gaps`]) to be filled with beads
//! as wide as it is. So contour fills cover the region without laying any of it twice.
//!
//! What is printed is no denser than a tenth of the tolerance needs (`ring_print_tolerance`,
//! Douglas–Peucker): a two5d layer's section (`planar::fill_two5d`), every ring as it is laid
//! (the next is offset from the exact one) and every zig-zag connector along the infill
//! area's edge. A mesh's section has runs of points micrometres apart where long thin
//! triangles meet the plane, and i_overlay's offsets add an arc of points at every vertex a
//! ring turns at; kept, they were most of a planar plan's points and of what the stages after
//! the fill carry. Measured on NIST CTC-05 (the 1000 mm Marlin bed, 2026-11-28, b89bb6f):
//! 8.19 → 4.61 million points, peak RSS 917 → 572 MB, 19.3 → 15.0 s, the extruded volume
//! 12,692,396 → 12,692,386 mm³ (1 ppm); `sphere_boss` on delta5 (its base and the dome's
//! planar layers) 199,659 → 80,720 points, 1.45 → 0.97 s.

mod boolean;
mod offset;
mod order;
mod pattern;
mod region;
pub mod sparse;

use crate::geom2d::{area2, dist};
use crate::params::{LayerParams, PathMode};
use crate::toolpath::Role;
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::single::SingleFloatOverlay;
use i_overlay::mesh::float::style::LineJoin;
use offset::{erode, offset, round_join};
use pattern::{drop_short_segments, rings, scan_fill, Reach, OPEN_SHARE};
use region::{bounds, region_shapes, shape_region};

pub use crate::geom2d::{Point2, Region};
pub(crate) use boolean::{difference, grow, intersection, outside_grown, union};
pub(crate) use offset::simplified;
pub use offset::thinner_than;
pub use order::{order_greedy, order_paths};
pub use region::{regions_by_winding, regions_from_loops};
pub use sparse::SparseLayer;

/// One continuous extrusion path (an open polyline; a closed perimeter repeats its first point
/// at the end).
#[derive(Debug, Clone, PartialEq)]
pub struct Path2 {
    /// Bead centre line, mm.
    pub points: Vec<Point2>,
    /// What the path is.
    pub kind: PathKind,
    /// What it is for, as slicers name it: the first ring (about the outside and about each
    /// hole) [`Role::ExternalPerimeter`], the others [`Role::Perimeter`], infill lines
    /// [`Role::SolidInfill`] or [`Role::InternalInfill`] by their spacing
    /// ([`infill_role`]), the lines in strips rings leave
    /// [`Role::GapFill`].
    pub role: Role,
}

/// What a path is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathKind {
    /// A closed ring following the boundary (perimeters, and every ring of contour fill).
    Perimeter,
    /// Raster or zig-zag lines, and gap fill between rings.
    Infill,
}

impl Path2 {
    /// True when the path ends where it starts (a ring).
    pub fn is_closed(&self) -> bool {
        self.points.len() > 2 && self.points.first() == self.points.last()
    }

    /// Length of the polyline, mm.
    pub fn length(&self) -> f64 {
        self.points.windows(2).map(|w| dist(w[0], w[1])).sum()
    }
}

// i_overlay's nested-vector polygon types.
type Contour = Vec<Point2>;
type Shape = Vec<Contour>;
type Shapes = Vec<Shape>;

/// Coordinates beyond this (mm) are treated as garbage: the loop is dropped.
const MAX_COORD: f64 = 1e9;
/// Most scan lines one fill may use (a spacing far too small for the part gives nothing).
const MAX_LINES: f64 = 1e6;
/// Most rings contour fill makes.
const MAX_RINGS: usize = 100_000;
/// Path segments shorter than this (mm) are dropped: nothing to print.
const MIN_SEGMENT: f64 = 1e-6;

fn shapes_area(s: &Shapes) -> f64 {
    s.iter().flatten().map(|c| 0.5 * area2(c)).sum()
}

/// `regions` shrunk by `d` mm (≥ 0) inward, corners rounded within `tol` mm: what is left of
/// each, as regions (a region thinner than `2·d` is gone). `d = 0` gives the regions as they are.
pub fn shrink_regions(regions: &[Region], d: f64, tol: f64) -> Vec<Region> {
    if d <= 0.0 {
        return regions.to_vec();
    }
    let shapes: Shapes = regions.iter().flat_map(region_shapes).collect();
    erode(&shapes, d, &round_join(tol, d))
        .into_iter()
        .filter_map(shape_region)
        .collect()
}

/// `region` parted where it is thinner than `2·d` mm (an opening: eroded by `d`, grown back
/// by `d` with sharp corners, clipped to the region): the pieces a seam joined, as regions;
/// the region itself where nothing is that thin.
///
/// Why: where two offsets of one contour run micrometres apart, a boolean between them keeps
/// the seam between as a strip that thin. In NIST CTC-05's contour fill, strips 20 mm long
/// were joined so by a sliver 5e-7 mm wide and 120 mm long: the region's mean width (twice
/// its area over its perimeter, which sets the lattice step of a region under a spacing wide,
/// `region_fill::lattice_step`) came out a fifth of the strips', and each took 5–6 s to fill
/// on a lattice 25 times as fine as theirs.
pub fn parted_at_seams(region: &Region, d: f64) -> Vec<Region> {
    let base = region_shapes(region);
    if base.is_empty() || !(d.is_finite() && d > 0.0) {
        return base.into_iter().filter_map(shape_region).collect();
    }
    let core = erode(&base, d, &round_join(d, d));
    if core.is_empty() {
        return vec![];
    }
    let grown = offset::dilate_sharp(&core, d);
    grown
        .overlay(&base, OverlayRule::Intersect, FillRule::NonZero)
        .into_iter()
        .filter_map(shape_region)
        .collect()
}

/// What one fill call needs to know.
#[derive(Debug, Clone)]
struct Ctx {
    width: f64,
    spacing: f64,
    /// Join of inward offsets (arcs at reflex corners).
    join: LineJoin<f64>,
    /// Join of the erosion a ring's opening grows straight back (`pattern::opening`), whose
    /// arcs never grow deeper than that erosion: in contour mode chorded for its depth, not
    /// for the deepest ring's (an arc chorded that finely, some hundred points micrometres
    /// apart, is grown back into its centre, and i_overlay meets every pair of its segments
    /// there). The same as `join` in the other modes.
    open_join: LineJoin<f64>,
    /// How far contour fill's inner rings may be simplified, mm: the feature's tolerance, at
    /// most 0.25 % of the width (small, because each ring is offset from the simplified one
    /// before it and the error adds up).
    tol: f64,
    /// How far a contour-fill ring may be simplified where it is laid, mm: a tenth of the
    /// feature's tolerance, at most 1 % of the width (the chord error of the offsets' arcs).
    /// Each ring is simplified on its own for printing (the next one is offset from it
    /// before), so this error does not add up from ring to ring.
    print_tol: f64,
}

/// Paths filling `regions` for layer number `layer` (for zig-zag angle alternation), bead width
/// `width`, spacing `spacing` between neighbouring path centre lines.
///
/// - raster: lines at `raster_angle_deg`, each a separate path, all printed in the same
///   direction, cut by the region offset inward by `width / 2` and then run on to the
///   region's boundary ([`bead_end_reach`]);
/// - zigzag: the same lines (at `raster_angle_deg + 90°` on odd layers), neighbours within a
///   connected piece joined by a connector along the infill boundary when no other line ends
///   on the boundary between them (and the connector is shorter than ten spacings); the
///   first and last end of each chain run on to the boundary as raster ends do;
/// - contour: rings offset inward by `width / 2`, `width / 2 + spacing`, ... until nothing is
///   left, plus gap-fill lines in strips the rings leave uncovered (parts too narrow for a
///   ring go to [`FilledLayer::gaps`]);
/// - contour_zigzag: `perimeters` rings, then zig-zag inside the region offset inward by
///   `width / 2 + perimeters · spacing`.
///
/// Rings are [`PathKind::Perimeter`] and closed (first point repeated); lines are
/// [`PathKind::Infill`]. Paths come region by region, rings outermost first (a gap-fill line
/// right after the ring it lies inside), infill last; use [`order_paths`] for a print order. No
/// path has a segment shorter than a micrometre (none of zero length). Degenerate input (no
/// regions, slivers, a region narrower than a bead, width or spacing not positive) gives fewer
/// paths or none, never a panic.
pub fn fill_layer(
    regions: &[Region],
    params: &LayerParams,
    layer: usize,
    width: f64,
    spacing: f64,
) -> FilledLayer {
    fill_layer_with(regions, params, layer, width, spacing, None)
}

/// [`fill_layer`], and with `sparse` (and [`LayerParams::sparse_infill`]) the infill lines of
/// each region laid solid only on the layer's skin ([`SparseLayer::skin`]) and sparse
/// ([`sparse`]) on the rest of its interior, whose area [`FilledLayer::sparse_area`] gives.
/// Rings and gaps are as [`fill_layer`] makes them.
pub fn fill_layer_with(
    regions: &[Region],
    params: &LayerParams,
    layer: usize,
    width: f64,
    spacing: f64,
    sparse: Option<SparseLayer>,
) -> FilledLayer {
    let sparse = sparse.filter(|_| params.sparse_infill());
    let mut sparse_area = 0.0;
    let mut out = Vec::new();
    let mut gaps: Shapes = Vec::new();
    if !(width.is_finite() && width > 0.0 && spacing.is_finite() && spacing > 0.0) {
        return FilledLayer::default();
    }
    let tol = if params.tolerance.is_finite() && params.tolerance > 0.0 {
        params.tolerance
    } else {
        0.05
    };
    let base_angle = if params.raster_angle_deg.is_finite() {
        params.raster_angle_deg
    } else {
        0.0
    };
    let infill = infill_role(width, spacing);
    let zigzag_angle = if layer % 2 == 1 {
        base_angle + 90.0
    } else {
        base_angle
    }
    .to_radians();
    for region in regions {
        let base = region_shapes(region);
        if base.is_empty() {
            continue;
        }
        // Too many lines or rings for this spacing: the parameters are wrong, fill nothing.
        let (lo, hi) = bounds(&base);
        let size = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
        if size / spacing > MAX_LINES {
            continue;
        }
        // Arcs grow as rings move inward: chord them for the deepest offset this fill makes.
        let deepest = 0.5 * width
            + spacing
                * match params.path_mode {
                    PathMode::Raster | PathMode::Zigzag => 0.0,
                    PathMode::Contour => f64::INFINITY,
                    PathMode::ContourZigzag => params.perimeters as f64,
                };
        let join = round_join(tol.min(0.01 * width), deepest.min(0.5 * size));
        let open_join = match params.path_mode {
            PathMode::Contour => round_join(tol.min(0.01 * width), OPEN_SHARE * spacing),
            _ => join.clone(),
        };
        let ctx = Ctx {
            width,
            spacing,
            join,
            open_join,
            tol: tol.min(0.0025 * width),
            print_tol: ring_print_tolerance(tol, width),
        };
        let lines = Lines {
            role: infill,
            sparse: sparse.as_ref(),
            params,
            layer,
            inset: match params.path_mode {
                PathMode::ContourZigzag => 0.5 * spacing,
                _ => 0.5 * width,
            },
        };
        match params.path_mode {
            PathMode::Raster => {
                let area = erode(&base, 0.5 * width, &ctx.join);
                let angle = base_angle.to_radians();
                sparse_area += lines.lay(&area, &base, angle, false, &ctx, &mut out);
            }
            PathMode::Zigzag => {
                let area = erode(&base, 0.5 * width, &ctx.join);
                sparse_area += lines.lay(&area, &base, zigzag_angle, true, &ctx, &mut out);
            }
            PathMode::Contour => {
                rings(&base, &ctx, MAX_RINGS, true, &mut out, &mut gaps);
            }
            PathMode::ContourZigzag => {
                let area = rings(
                    &base,
                    &ctx,
                    params.perimeters.min(MAX_RINGS),
                    false,
                    &mut out,
                    &mut gaps,
                );
                // Free chain ends run on to the inner edge of the last ring's bead: the
                // infill area grown back by half a spacing (not the ring itself eroded, which
                // would take in the strips left to the gaps).
                let edge = offset(&area, 0.5 * spacing, &ctx.join, 1.0);
                sparse_area += lines.lay(&area, &edge, zigzag_angle, true, &ctx, &mut out);
            }
        }
    }
    for p in &mut out {
        drop_short_segments(&mut p.points);
    }
    out.retain(|p| {
        let n = p.points.len();
        n >= 2 && (p.kind != PathKind::Perimeter || (n >= 4 && p.is_closed()))
    });
    FilledLayer {
        paths: out,
        gaps: gaps.into_iter().filter_map(shape_region).collect(),
        sparse_area,
        sparse_density: sparse.map_or(params.infill_density, |s| {
            sparse::layer_density(params, s.z, width)
        }),
    }
}

/// How one layer's infill lines are laid: solid (the lines of the path mode, role `role`),
/// or, with `sparse`, solid on the skin and in the infill pattern elsewhere.
struct Lines<'a> {
    role: Role,
    sparse: Option<&'a SparseLayer<'a>>,
    params: &'a LayerParams,
    layer: usize,
    /// How far inside the beads' edge the lines' centres keep: half a bead for raster and
    /// zig-zag, half a spacing inside the rings of contour-zig-zag.
    inset: f64,
}

impl Lines<'_> {
    /// The infill lines of a region whose lines' centres lie in `area` and whose beads fill
    /// `edge` (`area` grown by half a spacing): lines at `angle` (chained with `join`),
    /// appended to `out`. Returns the area (mm²) laid sparse.
    fn lay(
        &self,
        area: &Shapes,
        edge: &Shapes,
        angle: f64,
        join: bool,
        ctx: &Ctx,
        out: &mut Vec<Path2>,
    ) -> f64 {
        let (width, spacing) = (ctx.width, ctx.spacing);
        let Some(sparse) = self.sparse else {
            let from = out.len();
            scan_fill(
                area,
                angle,
                spacing,
                join.then_some(ctx.print_tol),
                Some(Reach { base: edge, width }),
                out,
            );
            set_role(&mut out[from..], self.role);
            return 0.0;
        };
        use i_overlay::core::fill_rule::FillRule;
        use i_overlay::core::overlay_rule::OverlayRule;
        use i_overlay::float::single::SingleFloatOverlay;
        let skin: Shapes = sparse.skin.iter().flat_map(region_shapes).collect();
        let (mut solid, rest) = if skin.is_empty() {
            (vec![], edge.clone())
        } else {
            (
                edge.overlay(&skin, OverlayRule::Intersect, FillRule::NonZero),
                edge.overlay(&skin, OverlayRule::Difference, FillRule::NonZero),
            )
        };
        // Pieces too small for the pattern's density are laid solid.
        let (small, rest): (Shapes, Shapes) = rest.into_iter().partition(|piece| {
            shapes_area(&vec![piece.clone()]).abs() < self.params.solid_infill_below_area
        });
        if !small.is_empty() {
            solid = if solid.is_empty() {
                small
            } else {
                solid.overlay(&small, OverlayRule::Union, FillRule::NonZero)
            };
        }
        // The skin solid: lines whose centres keep half a line off its edge, run on to it.
        let solid_area = erode(&solid, self.inset, &ctx.join);
        let from = out.len();
        let reach = Some(Reach {
            base: &solid,
            width,
        });
        scan_fill(
            &solid_area,
            angle,
            spacing,
            join.then_some(ctx.print_tol),
            reach,
            out,
        );
        set_role(&mut out[from..], Role::SolidInfill);
        out.extend(sparse::pattern_lines(
            &rest,
            self.params,
            self.layer,
            sparse.z,
            width,
        ));
        shapes_area(&rest).abs()
    }
}

/// How far (mm) a contour-fill ring may move where it is simplified for printing, for a
/// feature tolerance `tol` and beads `width` wide: a tenth of the tolerance, at most 1 % of
/// the width (what the offsets' arcs are chorded within already).
pub(crate) fn ring_print_tolerance(tol: f64, width: f64) -> f64 {
    (0.1 * tol).min(0.01 * width)
}

/// The role of infill lines `spacing` apart for beads `width` wide: [`Role::SolidInfill`]
/// where the beads touch (spacing at most the width, the default `filling_ratio` 1),
/// [`Role::InternalInfill`] where they are laid apart (the planners make a feature's bottom
/// and top layers solid: `region_fill::solid_on_skins`).
pub fn infill_role(width: f64, spacing: f64) -> Role {
    if spacing <= width * (1.0 + 1e-6) {
        Role::SolidInfill
    } else {
        Role::InternalInfill
    }
}

/// Gives `paths` the role `role`.
fn set_role(paths: &mut [Path2], role: Role) {
    for p in paths {
        p.role = role;
    }
}

/// The paths of a layer's regions, and the strips they leave for beads as wide as each strip.
#[derive(Debug, Clone, Default)]
pub struct FilledLayer {
    /// Paths of one bead width.
    pub paths: Vec<Path2>,
    /// Parts of the regions too narrow for a ring (where its beads would meet from both
    /// sides, or the first ring cannot reach): each is to be filled with beads as wide as it
    /// is there (`freeform::fill_flat_region`; `planar::fill_regions` does so).
    pub gaps: Vec<Region>,
    /// Area of the regions laid sparse, mm² ([`fill_layer_with`]; 0 without sparse infill).
    pub sparse_area: f64,
    /// The share of `sparse_area` the sparse lines cover on this layer
    /// ([`sparse::layer_density`]: `infill_density`, or the gyroid's at the layer's height).
    pub sparse_density: f64,
}

/// The part of a bead width by which a free line end stops short of the boundary it runs
/// towards: a hundredth, so that no print point lies on the boundary
/// itself.
pub const END_MARGIN: f64 = 0.01;

/// The most, in bead widths, a free line end runs on past the edge of the infill area: a line
/// nearly parallel to the boundary meets it only far on.
pub const MAX_END_REACH: f64 = 4.0;

/// How far (mm) a free line end (one that no connector joins and no ring surrounds: every
/// raster end, the first and last of a zig-zag chain) runs on past the edge of the infill
/// area where it was cut, half a bead inside the region, for beads `width` wide: to [`END_MARGIN`] of a bead
/// before the boundary, which lies `boundary` mm on along the line; no more than `room`
/// (half the way to the next piece of the same line) nor [`MAX_END_REACH`] beads.
///
/// Eq. 1 lays a bead `w` wide and `h` high along its centre line: the line's share of the
/// region is the strip `w` wide about it, and where a straight boundary cuts that strip, at
/// any angle, the strip holds `w` times the centre line's length up to the boundary. An end
/// that stops on the infill area instead leaves `w/2 · w` unfilled at a square end and more
/// at a slanting one (where a connector joins two ends, it puts that volume down along the
/// boundary): raster fills lost 2–9 % of a small feature's volume so, and zig-zag fills of
/// thin blades, whose slanting lines few connectors join, up to 7 %.
pub fn bead_end_reach(width: f64, boundary: f64, room: f64) -> f64 {
    let r = (boundary - END_MARGIN * width)
        .min(MAX_END_REACH * width)
        .min(room);
    if r.is_finite() && r > 0.0 {
        r
    } else {
        0.0
    }
}

/// The area (mm²) of each piece of `layer` lying outside `below` grown by `reach` (mm; round
/// joins chorded within `tol`): what a layer holds that the one under it does not carry
/// ([`crate::support`]). Pieces come as i_overlay's shapes, outer contour and holes; a piece's
/// area is the outer's minus its holes'.
pub(crate) fn pieces_outside(layer: &[Region], below: &[Region], reach: f64, tol: f64) -> Vec<f64> {
    use i_overlay::core::fill_rule::FillRule;
    use i_overlay::core::overlay_rule::OverlayRule;
    use i_overlay::float::single::SingleFloatOverlay;
    let top: Shapes = layer.iter().flat_map(region_shapes).collect();
    if top.is_empty() {
        return vec![];
    }
    let base: Shapes = below.iter().flat_map(region_shapes).collect();
    let pieces = if base.is_empty() {
        top
    } else {
        let grown = if reach > 0.0 {
            offset(&base, reach, &round_join(tol, reach), 1.1)
        } else {
            base
        };
        top.overlay(&grown, OverlayRule::Difference, FillRule::NonZero)
    };
    pieces
        .iter()
        .map(|shape| shape.iter().map(|c| 0.5 * area2(c)).sum::<f64>().abs())
        .collect()
}
