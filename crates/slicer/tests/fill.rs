//! Layer filling: coverage, containment, closure, holes, degenerate input, ordering.

use slicer::fill::{
    fill_layer, order_paths, regions_by_winding, regions_from_loops, Path2, PathKind, Point2,
    Region, END_MARGIN,
};
use slicer::freeform::FillPath;
use slicer::params::{LayerParams, PathMode};
use slicer::planar::fill_regions;
use slicer::toolpath::Role;
use std::f64::consts::PI;

/// Chord sag of offset arcs at reflex corners: 1 % of the 0.4 mm width.
const SAG: f64 = 0.004;

/// True for the free ends of `path` (its first and last point) in a mode whose free line
/// ends run on to the boundary (raster and zig-zag), where the half-width clearance does not
/// hold.
fn free_end(mode: PathMode, path: &Path2, i: usize) -> bool {
    matches!(mode, PathMode::Raster | PathMode::Zigzag)
        && path.kind == PathKind::Infill
        && (i == 0 || i + 1 == path.points.len())
}

const MODES: [PathMode; 4] = [
    PathMode::Raster,
    PathMode::Zigzag,
    PathMode::Contour,
    PathMode::ContourZigzag,
];

fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<Point2> {
    vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
}

fn circle(c: Point2, r: f64, n: usize, ccw: bool) -> Vec<Point2> {
    let mut v: Vec<Point2> = (0..n)
        .map(|i| {
            let t = 2.0 * PI * i as f64 / n as f64;
            [c[0] + r * t.cos(), c[1] + r * t.sin()]
        })
        .collect();
    if !ccw {
        v.reverse();
    }
    v
}

fn area2(p: &[Point2]) -> f64 {
    let n = p.len();
    (0..n)
        .map(|i| p[i][0] * p[(i + 1) % n][1] - p[(i + 1) % n][0] * p[i][1])
        .sum()
}

fn region_area(r: &Region) -> f64 {
    0.5 * area2(&r.outer) + r.holes.iter().map(|h| 0.5 * area2(h)).sum::<f64>()
}

fn seg_dist(p: Point2, a: Point2, b: Point2) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let l2 = d[0] * d[0] + d[1] * d[1];
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p[0] - a[0] - t * d[0]).hypot(p[1] - a[1] - t * d[1])
}

fn boundary_dist(p: Point2, poly: &[Point2]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| seg_dist(p, poly[i], poly[(i + 1) % n]))
        .fold(f64::INFINITY, f64::min)
}

fn pip(p: Point2, poly: &[Point2]) -> bool {
    let n = poly.len();
    let mut c = false;
    let mut j = n - 1;
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

/// Inside the region (outer, not in a hole), or within `eps` of its boundary.
fn in_region(p: Point2, r: &Region, eps: f64) -> bool {
    let near =
        boundary_dist(p, &r.outer) <= eps || r.holes.iter().any(|h| boundary_dist(p, h) <= eps);
    near || (pip(p, &r.outer) && !r.holes.iter().any(|h| pip(p, h)))
}

fn segments_cross(a: Point2, b: Point2, c: Point2, d: Point2) -> bool {
    let o = |p: Point2, q: Point2, r: Point2| {
        (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    };
    let (d1, d2, d3, d4) = (o(a, b, c), o(a, b, d), o(c, d, a), o(c, d, b));
    (d1 > 0.0) != (d2 > 0.0) && (d3 > 0.0) != (d4 > 0.0)
}

fn shapes() -> Vec<(&'static str, Region)> {
    vec![
        (
            "rectangle 20x10",
            Region {
                outer: rect(0.0, 0.0, 20.0, 10.0),
                holes: vec![],
            },
        ),
        (
            "disk d20 (256 vertices)",
            Region {
                outer: circle([0.0, 0.0], 10.0, 256, true),
                holes: vec![],
            },
        ),
        (
            "rectangle 30x20 with a d10 hole",
            Region {
                outer: rect(0.0, 0.0, 30.0, 20.0),
                holes: vec![circle([15.0, 10.0], 5.0, 128, false)],
            },
        ),
    ]
}

fn params(mode: PathMode) -> LayerParams {
    LayerParams {
        path_mode: mode,
        ..LayerParams::default()
    }
}

fn loop_length(p: &[Point2]) -> f64 {
    let n = p.len();
    (0..n)
        .map(|i| (p[i][0] - p[(i + 1) % n][0]).hypot(p[i][1] - p[(i + 1) % n][1]))
        .sum()
}

fn total_length(paths: &[Path2]) -> f64 {
    paths.iter().map(|p| p.length()).sum()
}

/// Distance from `p` to the nearest boundary loop of the region.
fn region_boundary_dist(p: Point2, r: &Region) -> f64 {
    r.holes
        .iter()
        .map(|h| boundary_dist(p, h))
        .fold(boundary_dist(p, &r.outer), f64::min)
}

/// The whole fill of a planar layer of region `r` (`planar::fill_regions`: `fill_layer`'s
/// paths of one bead width, and beads as wide as the strips its rings leave), 0.4 mm beads.
fn fill_all(r: &Region, p: &LayerParams, layer: usize) -> Vec<FillPath> {
    fill_regions(vec![r.clone()], p, layer, 0.4, 0.4)
}

/// Σ length × width over the segments of `paths` (Eq. 1's bead area), mm².
fn bead_area(paths: &[FillPath]) -> f64 {
    paths
        .iter()
        .flat_map(|p| {
            p.points
                .windows(2)
                .zip(p.widths.windows(2))
                .map(|(q, w)| (q[1][0] - q[0][0]).hypot(q[1][1] - q[0][1]) * 0.5 * (w[0] + w[1]))
        })
        .sum()
}

/// Area of the region that no bead covers, beads being the paths stroked as wide as they are
/// (i_overlay's stroke and boolean difference), mm²: a path of one width whole, one of
/// varying width segment by segment.
fn uncovered_area(r: &Region, paths: &[FillPath]) -> f64 {
    use i_overlay::core::fill_rule::FillRule;
    use i_overlay::core::overlay_rule::OverlayRule;
    use i_overlay::float::single::SingleFloatOverlay;
    use i_overlay::mesh::float::stroke::offset::StrokeOffset;
    use i_overlay::mesh::float::style::{LineJoin, StrokeStyle};
    let mut beads: Vec<Vec<Vec<Point2>>> = Vec::new();
    for p in paths {
        let w0 = p.widths.first().copied().unwrap_or(0.0);
        if p.widths.iter().all(|&w| (w - w0).abs() < 1e-9) {
            let style = StrokeStyle::new(w0).line_join(LineJoin::Miter(0.1));
            let closed = p.points.len() > 3 && p.points.first() == p.points.last();
            if closed {
                beads.extend(p.points[..p.points.len() - 1].to_vec().stroke(style, true));
            } else {
                beads.extend(p.points.stroke(style, false));
            }
        } else {
            for (q, w) in p.points.windows(2).zip(p.widths.windows(2)) {
                let style = StrokeStyle::new(0.5 * (w[0] + w[1])).line_join(LineJoin::Miter(0.1));
                beads.extend(q.to_vec().stroke(style, false));
            }
        }
    }
    let mut region = vec![r.outer.clone()];
    region.extend(r.holes.iter().cloned());
    let uncovered = region.overlay(&beads, OverlayRule::Difference, FillRule::NonZero);
    uncovered.iter().flatten().map(|c| 0.5 * area2(c)).sum()
}

/// The coverage property: with filling ratio 1, total path length × width is within
/// 2 % of the region's area for zig-zag, contour and contour-zig-zag, on both layer parities.
#[test]
fn length_times_width_matches_area() {
    for (name, r) in shapes() {
        for mode in MODES {
            for layer in 0..2 {
                let ratio = bead_area(&fill_all(&r, &params(mode), layer)) / region_area(&r);
                assert!(
                    (ratio - 1.0).abs() < 0.02,
                    "{name}, {mode:?}, layer {layer}: length x width / area = {ratio:.4}"
                );
            }
        }
    }
}

/// Stroking every path `width` wide leaves under 1 % of the region uncovered (raster: the
/// corners its slanting line ends leave at the boundary, under 2 %).
#[test]
fn beads_cover_the_region() {
    for (name, r) in shapes() {
        for mode in MODES {
            let gap = uncovered_area(&r, &fill_all(&r, &params(mode), 0)) / region_area(&r);
            let limit = if mode == PathMode::Raster { 0.02 } else { 0.01 };
            assert!(
                gap < limit,
                "{name}, {mode:?}: {:.2} % uncovered",
                100.0 * gap
            );
        }
    }
}

/// Every path point is inside the region (point in polygon, 1e-6 slack) and half a width
/// from its boundary or more (less the 1 %-of-width chord sag of offset arcs round a hole),
/// but for the free ends of raster and zig-zag lines, which are inside and run on to within
/// a hundredth of a bead of the boundary.
#[test]
fn paths_stay_inside_half_a_width_from_the_boundary() {
    for (name, r) in shapes() {
        for mode in MODES {
            for layer in 0..2 {
                let paths =
                    fill_layer(std::slice::from_ref(&r), &params(mode), layer, 0.4, 0.4).paths;
                assert!(!paths.is_empty(), "{name}, {mode:?}");
                for p in &paths {
                    for (i, &q) in p.points.iter().enumerate() {
                        assert!(in_region(q, &r, 1e-6), "{name}, {mode:?}: {q:?} outside");
                        let d = region_boundary_dist(q, &r);
                        if free_end(mode, p, i) {
                            assert!(
                                d > 0.0 && d <= END_MARGIN * 0.4 + 1e-9,
                                "{name}, {mode:?}: free end {q:?} {d} from the boundary"
                            );
                            continue;
                        }
                        assert!(
                            d >= 0.2 - SAG - 1e-6,
                            "{name}, {mode:?}: {q:?} only {d} from the boundary"
                        );
                    }
                }
            }
        }
    }
}

/// Perimeters are closed rings; contour-zig-zag makes `perimeters` of them per boundary loop,
/// the first half a width and the second one spacing further in.
#[test]
fn perimeters_are_closed_rings() {
    for (name, r) in shapes() {
        for mode in MODES {
            let paths = fill_layer(std::slice::from_ref(&r), &params(mode), 0, 0.4, 0.4).paths;
            for p in paths.iter().filter(|p| p.kind == PathKind::Perimeter) {
                assert!(p.points.len() >= 4, "{name}, {mode:?}");
                assert_eq!(p.points.first(), p.points.last(), "{name}, {mode:?}");
                assert!(p.is_closed());
            }
            let rings = paths
                .iter()
                .filter(|p| p.kind == PathKind::Perimeter)
                .count();
            match mode {
                PathMode::Raster | PathMode::Zigzag => assert_eq!(rings, 0, "{name}"),
                PathMode::ContourZigzag => {
                    assert_eq!(rings, 2 * (1 + r.holes.len()), "{name}")
                }
                PathMode::Contour => assert!(rings >= 12, "{name}: {rings} rings"),
            }
        }
    }
    // The rectangle's perimeters: 19.6 x 9.6 and 18.8 x 8.8 rectangles.
    let (_, r) = shapes().remove(0);
    let paths = fill_layer(&[r], &params(PathMode::ContourZigzag), 0, 0.4, 0.4).paths;
    let lens: Vec<f64> = paths
        .iter()
        .filter(|p| p.kind == PathKind::Perimeter)
        .map(|p| p.length())
        .collect();
    assert!((lens[0] - 2.0 * (19.6 + 9.6)).abs() < 1e-5, "{lens:?}");
    assert!((lens[1] - 2.0 * (18.8 + 8.8)).abs() < 1e-5, "{lens:?}");
}

/// No path segment crosses a hole or comes within half a width of it.
#[test]
fn no_infill_segment_crosses_a_hole() {
    let (_, r) = shapes().remove(2);
    let hole = &r.holes[0];
    for mode in MODES {
        for layer in 0..2 {
            let paths = fill_layer(std::slice::from_ref(&r), &params(mode), layer, 0.4, 0.4).paths;
            for p in &paths {
                for w in p.points.windows(2) {
                    let n = hole.len();
                    for i in 0..n {
                        assert!(
                            !segments_cross(w[0], w[1], hole[i], hole[(i + 1) % n]),
                            "{mode:?}: {:?}-{:?} crosses the hole",
                            w[0],
                            w[1]
                        );
                    }
                    let mid = [(w[0][0] + w[1][0]) / 2.0, (w[0][1] + w[1][1]) / 2.0];
                    assert!(!pip(mid, hole), "{mode:?}: segment inside the hole");
                    // Centre lines keep half a width (less the chord sag of offset arcs, and
                    // of inner rings simplified within 5 % of a width) off the hole.
                    assert!(
                        boundary_dist(mid, hole) > 0.2 - SAG - 0.02,
                        "{mode:?}: segment {:?}-{:?} runs over the hole's edge",
                        w[0],
                        w[1]
                    );
                }
            }
        }
    }
}

/// Raster: one straight line per path, all at raster_angle_deg and pointing the same way, on
/// every layer; the ends lie exactly on the region offset inward by half a width (exactly half
/// a width from straight edges; round a hole, up to the chord sag nearer).
/// Raster lines run at the raster angle, each its own path, from boundary to boundary: both
/// ends inside, a hundredth of a bead short of the boundary along the line.
#[test]
fn raster_lines_are_parallel_and_run_on_to_the_boundary() {
    for (name, r) in shapes() {
        for layer in 0..2 {
            let paths = fill_layer(
                std::slice::from_ref(&r),
                &params(PathMode::Raster),
                layer,
                0.4,
                0.4,
            )
            .paths;
            let d = [45f64.to_radians().cos(), 45f64.to_radians().sin()];
            for p in &paths {
                assert_eq!(p.kind, PathKind::Infill);
                assert_eq!(p.points.len(), 2, "{name}");
                let (a, b) = (p.points[0], p.points[1]);
                let v = [b[0] - a[0], b[1] - a[1]];
                let l = v[0].hypot(v[1]);
                assert!(
                    (v[0] * d[0] + v[1] * d[1]) / l > 1.0 - 1e-9,
                    "{name}: {v:?}"
                );
                for (q, out) in [(a, -1.0), (b, 1.0)] {
                    assert!(in_region(q, &r, 0.0), "{name}: end {q:?} outside");
                    let on = |t: f64| [q[0] + out * t * d[0], q[1] + out * t * d[1]];
                    let m = END_MARGIN * 0.4;
                    assert!(
                        in_region(on(0.99 * m), &r, 0.0) && !in_region(on(1.01 * m), &r, 0.0),
                        "{name}: end {q:?} is not {m} short of the boundary"
                    );
                }
            }
        }
    }
    // Another angle: 9.6 / 0.4 + 1 = 25 lines across the rectangle's infill area, each 20
    // long less the margin at both ends.
    let (_, r) = shapes().remove(0);
    let p = LayerParams {
        raster_angle_deg: 0.0,
        ..params(PathMode::Raster)
    };
    let paths = fill_layer(&[r], &p, 1, 0.4, 0.4).paths;
    assert_eq!(paths.len(), 25);
    for p in &paths {
        assert!((p.points[0][1] - p.points[1][1]).abs() < 1e-9);
        assert!(p.points[1][0] > p.points[0][0]);
        assert!((p.length() - (20.0 - 2.0 * END_MARGIN * 0.4)).abs() < 1e-6);
    }
}

/// Zig-zag: lines at raster_angle_deg on even layers and +90° on odd ones, joined into one
/// path per connected piece (a convex region: one path) along the offset boundary; the
/// path's two free ends run on to the boundary.
#[test]
fn zigzag_alternates_and_joins_lines() {
    for (name, r) in shapes().into_iter().take(2) {
        for layer in 0..2 {
            let paths = fill_layer(
                std::slice::from_ref(&r),
                &params(PathMode::Zigzag),
                layer,
                0.4,
                0.4,
            )
            .paths;
            assert_eq!(paths.len(), 1, "{name}, layer {layer}");
            let angle = (45.0 + 90.0 * layer as f64).to_radians();
            let d = [angle.cos(), angle.sin()];
            let pts = &paths[0].points;
            let mut long = 0;
            for w in pts.windows(2) {
                let v = [w[1][0] - w[0][0], w[1][1] - w[0][1]];
                let l = v[0].hypot(v[1]);
                if l > 1.0 {
                    long += 1;
                    // Along the zig-zag direction (either way), never across it.
                    assert!(
                        ((v[0] * d[0] + v[1] * d[1]) / l).abs() > 1.0 - 1e-9,
                        "{name}"
                    );
                }
            }
            assert!(long > 30, "{name}: {long} lines");
            for (i, &q) in pts.iter().enumerate() {
                let e = region_boundary_dist(q, &r);
                if free_end(PathMode::Zigzag, &paths[0], i) {
                    assert!(
                        e > 0.0 && e <= END_MARGIN * 0.4 + 1e-9,
                        "{name}: free end {q:?} is {e} from the boundary"
                    );
                } else {
                    assert!(
                        (e - 0.2).abs() < 1e-6,
                        "{name}: {q:?} is {e} from the boundary"
                    );
                }
            }
        }
    }
    // Around a hole: a few pieces, each a single path.
    let (_, r) = shapes().remove(2);
    let paths = fill_layer(&[r], &params(PathMode::Zigzag), 0, 0.4, 0.4).paths;
    assert!((2..=6).contains(&paths.len()), "{} paths", paths.len());
}

/// Contour: rings every spacing inward until the region is used up; the 20 x 10 rectangle
/// gets 12 rings and one gap-fill line down the middle strip they leave.
#[test]
fn contour_rings_go_all_the_way_in() {
    let (_, r) = shapes().remove(0);
    let paths = fill_layer(&[r], &params(PathMode::Contour), 0, 0.4, 0.4).paths;
    let rings: Vec<&Path2> = paths
        .iter()
        .filter(|p| p.kind == PathKind::Perimeter)
        .collect();
    assert_eq!(rings.len(), 12);
    for (k, ring) in rings.iter().enumerate() {
        let d = 0.2 + 0.4 * k as f64;
        let expect = 2.0 * ((20.0 - 2.0 * d) + (10.0 - 2.0 * d));
        assert!((ring.length() - expect).abs() < 1e-5, "ring {k}");
    }
    let gap: Vec<&Path2> = paths
        .iter()
        .filter(|p| p.kind == PathKind::Infill)
        .collect();
    assert_eq!(gap.len(), 1);
    let g = &gap[0].points;
    assert_eq!(g.len(), 2);
    assert!(
        (g[0][1] - 5.0).abs() < 1e-6 && (g[1][1] - 5.0).abs() < 1e-6,
        "{g:?}"
    );
    assert!((gap[0].length() - 10.4).abs() < 1e-6, "{g:?}");

    // The disk: 25 concentric rings, 0.4 apart.
    let (_, r) = shapes().remove(1);
    let paths = fill_layer(&[r], &params(PathMode::Contour), 0, 0.4, 0.4).paths;
    assert_eq!(paths.len(), 25);
    for (k, ring) in paths.iter().enumerate() {
        let radius = 9.8 - 0.4 * k as f64;
        for q in &ring.points {
            let rq = q[0].hypot(q[1]);
            // Inner rings are simplified within 5 % of a width (0.02 mm).
            assert!((rq - radius).abs() < 0.02, "ring {k}: {rq} for {radius}");
        }
    }
}

/// A larger spacing (filling ratio 0.8: 0.5 mm for a 0.4 mm bead) lays proportionally less
/// path.
#[test]
fn filling_ratio_spreads_the_paths() {
    let p = LayerParams {
        filling_ratio: 0.8,
        ..params(PathMode::Zigzag)
    };
    let spacing = p.spacing(0.4);
    assert!((spacing - 0.5).abs() < 1e-12);
    let (_, r) = shapes().remove(1);
    let paths = fill_layer(std::slice::from_ref(&r), &p, 0, 0.4, spacing).paths;
    let ratio = total_length(&paths) * 0.4 / region_area(&r);
    assert!((ratio - 0.8).abs() < 0.03, "{ratio}");
}

/// Degenerate input gives fewer paths or none, never a panic.
#[test]
fn degenerate_input_does_not_panic() {
    let sq = Region {
        outer: rect(0.0, 0.0, 10.0, 10.0),
        holes: vec![],
    };
    for mode in MODES {
        let p = params(mode);
        // Nothing.
        assert!(fill_layer(&[], &p, 0, 0.4, 0.4).paths.is_empty());
        // Zero-area slivers.
        let sliver = Region {
            outer: vec![[0.0, 0.0], [5.0, 0.0], [10.0, 0.0]],
            holes: vec![],
        };
        assert!(fill_layer(&[sliver], &p, 0, 0.4, 0.4).paths.is_empty());
        let two = Region {
            outer: vec![[0.0, 0.0], [5.0, 5.0]],
            holes: vec![],
        };
        assert!(fill_layer(&[two], &p, 0, 0.4, 0.4).paths.is_empty());
        let empty = Region {
            outer: vec![],
            holes: vec![vec![]],
        };
        assert!(fill_layer(&[empty], &p, 0, 0.4, 0.4).paths.is_empty());
        // Narrower than a bead: nothing fits.
        let thin = Region {
            outer: rect(0.0, 0.0, 10.0, 0.3),
            holes: vec![],
        };
        assert!(
            fill_layer(&[thin], &p, 0, 0.4, 0.4).paths.is_empty(),
            "{mode:?}"
        );
        // Just over a bead: what fits, inside.
        let narrow = Region {
            outer: rect(0.0, 0.0, 10.0, 0.45),
            holes: vec![],
        };
        for path in fill_layer(std::slice::from_ref(&narrow), &p, 0, 0.4, 0.4).paths {
            for q in path.points {
                assert!(in_region(q, &narrow, 1e-6));
            }
        }
        // Bad widths and spacings.
        for (w, s) in [
            (0.0, 0.4),
            (-0.4, 0.4),
            (f64::NAN, 0.4),
            (0.4, 0.0),
            (0.4, f64::INFINITY),
            (0.4, -1.0),
        ] {
            assert!(
                fill_layer(std::slice::from_ref(&sq), &p, 0, w, s)
                    .paths
                    .is_empty(),
                "{w} {s}"
            );
        }
        // Absurdly fine spacing: refused, not hours of lines.
        assert!(fill_layer(std::slice::from_ref(&sq), &p, 0, 1e-9, 1e-9)
            .paths
            .is_empty());
        // Spacing wider than the region, bead wider than the region.
        let _ = fill_layer(std::slice::from_ref(&sq), &p, 0, 0.4, 50.0).paths;
        assert!(fill_layer(std::slice::from_ref(&sq), &p, 0, 20.0, 20.0)
            .paths
            .is_empty());
        // Non-finite and huge coordinates.
        let nan = Region {
            outer: vec![[0.0, 0.0], [f64::NAN, 0.0], [1.0, 1.0]],
            holes: vec![],
        };
        assert!(fill_layer(&[nan], &p, 0, 0.4, 0.4).paths.is_empty());
        let inf_hole = Region {
            outer: rect(0.0, 0.0, 10.0, 10.0),
            holes: vec![vec![[1.0, 1.0], [f64::INFINITY, 1.0], [2.0, 2.0]]],
        };
        assert!(!fill_layer(&[inf_hole], &p, 0, 0.4, 0.4).paths.is_empty());
        let huge = Region {
            outer: rect(0.0, 0.0, 1e300, 1e300),
            holes: vec![],
        };
        assert!(fill_layer(&[huge], &p, 0, 0.4, 0.4).paths.is_empty());
        // Clockwise outer, counter-clockwise hole, a hole poking out, a bow-tie, repeated
        // points and a closing repeat: filled, inside the non-zero area.
        let mut cw = rect(0.0, 0.0, 10.0, 10.0);
        cw.reverse();
        let odd = Region {
            outer: cw,
            holes: vec![rect(8.0, 4.0, 12.0, 6.0), rect(2.0, 2.0, 3.0, 3.0)],
        };
        assert!(!fill_layer(&[odd], &p, 0, 0.4, 0.4).paths.is_empty());
        let bowtie = Region {
            outer: vec![[0.0, 0.0], [10.0, 10.0], [10.0, 0.0], [0.0, 10.0]],
            holes: vec![],
        };
        let _ = fill_layer(&[bowtie], &p, 0, 0.4, 0.4).paths;
        let dup = Region {
            outer: vec![
                [0.0, 0.0],
                [0.0, 0.0],
                [10.0, 0.0],
                [10.0, 10.0],
                [10.0, 10.0],
                [0.0, 10.0],
                [0.0, 0.0],
            ],
            holes: vec![],
        };
        assert!(!fill_layer(&[dup], &p, 0, 0.4, 0.4).paths.is_empty());
        // Bad parameters do not panic either.
        let bad = LayerParams {
            tolerance: f64::NAN,
            raster_angle_deg: f64::INFINITY,
            perimeters: usize::MAX,
            ..p.clone()
        };
        let _ = fill_layer(std::slice::from_ref(&sq), &bad, 3, 0.4, 0.4).paths;
    }
}

/// regions_from_loops: even-odd nesting, orientation normalised, islands are regions.
#[test]
fn loops_group_into_regions_by_nesting() {
    let mut outer = rect(0.0, 0.0, 100.0, 100.0);
    outer.reverse(); // clockwise, as a slicer may find it
    let hole = rect(10.0, 10.0, 90.0, 90.0); // counter-clockwise
    let island = rect(20.0, 20.0, 80.0, 80.0);
    let island_hole = rect(40.0, 40.0, 60.0, 60.0);
    let other = rect(200.0, 0.0, 210.0, 10.0);
    let mut closed = other.clone();
    closed.push(closed[0]);
    let sliver = vec![[0.0, 200.0], [5.0, 200.0], [10.0, 200.0]];
    let regions = regions_from_loops(&[
        island_hole.clone(),
        hole.clone(),
        closed,
        outer.clone(),
        island.clone(),
        sliver,
        vec![[1.0, f64::NAN], [2.0, 2.0], [3.0, 1.0]],
    ]);
    assert_eq!(regions.len(), 3);
    for r in &regions {
        assert!(area2(&r.outer) > 0.0, "outer counter-clockwise");
        for h in &r.holes {
            assert!(area2(h) < 0.0, "hole clockwise");
        }
    }
    let big = &regions[0];
    assert_eq!(big.holes.len(), 1);
    assert!((region_area(big) - (10000.0 - 6400.0)).abs() < 1e-9);
    let mid = &regions[1];
    assert!((region_area(mid) - (3600.0 - 400.0)).abs() < 1e-9);
    let small = &regions[2];
    assert!(small.holes.is_empty());
    assert_eq!(small.outer.len(), 4, "closing repeat dropped");
    assert!((region_area(small) - 100.0).abs() < 1e-9);
    // Points are the input's.
    for p in &hole {
        assert!(big.holes[0].contains(p));
    }
    assert!(regions_from_loops(&[]).is_empty());
}

/// order_paths: greedy nearest end, open paths reversed when their far end is nearer, closed
/// paths kept; nothing lost.
#[test]
fn order_paths_takes_the_nearest_end() {
    let line = |a: Point2, b: Point2| Path2 {
        points: vec![a, b],
        kind: PathKind::Infill,
        role: Role::SolidInfill,
    };
    let ring = Path2 {
        points: vec![[5.0, 5.0], [6.0, 5.0], [6.0, 6.0], [5.0, 5.0]],
        kind: PathKind::Perimeter,
        role: Role::ExternalPerimeter,
    };
    let paths = vec![
        line([10.0, 0.0], [20.0, 0.0]),
        ring.clone(),
        line([3.0, 0.0], [1.0, 0.0]),
        Path2 {
            points: vec![],
            kind: PathKind::Infill,
            role: Role::SolidInfill,
        },
    ];
    let out = order_paths(paths, [0.0, 0.0]);
    assert_eq!(out.len(), 4);
    assert_eq!(out[0].points, vec![[1.0, 0.0], [3.0, 0.0]], "reversed");
    assert_eq!(out[1], ring, "closed path kept as is");
    assert_eq!(out[2].points, vec![[10.0, 0.0], [20.0, 0.0]]);
    assert!(out[3].points.is_empty());
    assert!(order_paths(vec![], [0.0, 0.0]).is_empty());

    // On a real fill, ordering never lengthens travel over the fill order and loses nothing.
    let (_, r) = shapes().remove(2);
    let paths = fill_layer(&[r], &params(PathMode::Raster), 0, 0.4, 0.4).paths;
    let travel = |ps: &[Path2]| {
        let mut cur = [0.0, 0.0];
        let mut t = 0.0;
        for p in ps {
            t += (p.points[0][0] - cur[0]).hypot(p.points[0][1] - cur[1]);
            cur = *p.points.last().unwrap();
        }
        t
    };
    let ordered = order_paths(paths.clone(), [0.0, 0.0]);
    assert_eq!(ordered.len(), paths.len());
    assert!((total_length(&ordered) - total_length(&paths)).abs() < 1e-9);
    assert!(travel(&ordered) <= travel(&paths) + 1e-9);
}

/// The infill lines are cut against the offset polygons by our own scan; cross-check every
/// raster line against i_overlay's polyline clipping of the same line by the same area.
#[test]
fn raster_lines_agree_with_i_overlay_clipping() {
    use i_overlay::core::fill_rule::FillRule;
    use i_overlay::float::clip::FloatClip;
    use i_overlay::mesh::float::outline::offset::OutlineOffset;
    use i_overlay::mesh::float::style::{LineJoin, OutlineStyle};
    use i_overlay::string::clip::ClipRule;
    let (_, r) = shapes().remove(2);
    let shape = vec![r.outer.clone(), r.holes[0].clone()];
    let area = shape.outline(&OutlineStyle::new(-0.2).line_join(LineJoin::Round(0.1)));
    let paths = fill_layer(
        std::slice::from_ref(&r),
        &params(PathMode::Raster),
        0,
        0.4,
        0.4,
    )
    .paths;
    let d = [45f64.to_radians().cos(), 45f64.to_radians().sin()];
    let mut checked = 0;
    for p in &paths {
        let (a, b) = (p.points[0], p.points[1]);
        let long = vec![
            [a[0] - 100.0 * d[0], a[1] - 100.0 * d[1]],
            [a[0] + 100.0 * d[0], a[1] + 100.0 * d[1]],
        ];
        let clipped = long.clip_by(
            &area,
            FillRule::NonZero,
            ClipRule {
                invert: false,
                boundary_included: false,
            },
        );
        // The line is i_overlay's piece run on at both ends (towards the boundary): the piece
        // lies on it, and the line is longer by no more than the run-on allows.
        let along = |u: Point2| (u[0] - a[0]) * d[0] + (u[1] - a[1]) * d[1];
        let l = along(b);
        let found = clipped.iter().any(|piece| {
            let (s, e) = (along(piece[0]), along(*piece.last().unwrap()));
            let (s, e) = (s.min(e), s.max(e));
            s > 0.0 && e < l && s < 4.0 * 0.4 && l - e < 4.0 * 0.4
        });
        assert!(found, "{a:?}-{b:?} not in {clipped:?}");
        checked += 1;
    }
    assert!(checked > 100);
}

/// Fill times for the performance figure (run with
/// `cargo test --release -p slicer --test fill -- --ignored --nocapture`).
#[test]
#[ignore]
fn fill_timing() {
    let sq = Region {
        outer: rect(0.0, 0.0, 100.0, 100.0),
        holes: vec![],
    };
    let mut cases: Vec<(&str, Region)> = vec![("100 x 100 mm square", sq)];
    cases.extend(shapes());
    for (name, r) in cases {
        for mode in MODES {
            let runs = 20;
            let t = std::time::Instant::now();
            let mut n = 0;
            for layer in 0..runs {
                n = fill_layer(std::slice::from_ref(&r), &params(mode), layer, 0.4, 0.4)
                    .paths
                    .len();
            }
            let per = t.elapsed() / runs as u32;
            println!("{name:35} {mode:?}: {n} paths, {per:?} per layer");
        }
    }
}

/// Random star-shaped regions (spiky, concave, some with a hole) in every mode: no panic,
/// every point inside, perimeters closed, and zig-zag and contour fills cover them but for
/// part of the half-width band along the boundary.
#[test]
fn random_regions_fill_inside() {
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut rnd = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for case in 0..12 {
        let n = 5 + (rnd() * 40.0) as usize;
        let r0 = 3.0 + 10.0 * rnd();
        let outer: Vec<Point2> = (0..n)
            .map(|i| {
                let t = 2.0 * PI * (i as f64 + 0.8 * rnd()) / n as f64;
                let r = r0 * (0.45 + 0.55 * rnd());
                [r * t.cos(), r * t.sin()]
            })
            .collect();
        let holes = if case % 2 == 0 {
            vec![circle([0.0, 0.0], 0.3 * r0 * rnd(), 24, false)]
        } else {
            vec![]
        };
        let region = Region { outer, holes };
        let angle = 180.0 * rnd();
        for mode in MODES {
            let p = LayerParams {
                raster_angle_deg: angle,
                ..params(mode)
            };
            for layer in 0..2 {
                let paths = fill_layer(std::slice::from_ref(&region), &p, layer, 0.4, 0.4).paths;
                for path in &paths {
                    if path.kind == PathKind::Perimeter {
                        assert!(path.is_closed(), "case {case}, {mode:?}");
                    }
                    for &q in &path.points {
                        assert!(
                            in_region(q, &region, 1e-6),
                            "case {case}, {mode:?}: {q:?} outside"
                        );
                    }
                }
                if mode != PathMode::Raster && layer == 0 {
                    // What no bead reaches is at most part of the half-width band along the
                    // boundary (spikes narrower than a bead, zig-zag's ends).
                    let gap = uncovered_area(&region, &fill_all(&region, &p, layer))
                        / region_area(&region);
                    let band = 0.2 * loop_length(&region.outer) / region_area(&region);
                    assert!(
                        gap < 0.6 * band + 0.02,
                        "case {case}, {mode:?}: {:.1} % uncovered, band {:.1} %",
                        100.0 * gap,
                        100.0 * band
                    );
                }
            }
        }
    }
}

/// A disk of radius `r` as an `n`-gon as a mesh's cross-section gives it: the vertices' radii
/// jittered by up to ±`jitter` (deterministically) and, with `split`, a point put on every
/// chord (where the cutting plane crosses the diagonal of a side quad: collinear but for
/// rounding).
fn section_disk(c: Point2, r: f64, n: usize, jitter: f64, split: bool, ccw: bool) -> Vec<Point2> {
    let mut seed = 0x9e37_79b9_7f4a_7c15_u64 ^ n as u64;
    let mut rnd = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let corners: Vec<Point2> = (0..n)
        .map(|i| {
            let t = 2.0 * PI * i as f64 / n as f64;
            let rr = r + jitter * (2.0 * rnd() - 1.0);
            [c[0] + rr * t.cos(), c[1] + rr * t.sin()]
        })
        .collect();
    let mut v = Vec::with_capacity(2 * n);
    for i in 0..n {
        let (a, b) = (corners[i], corners[(i + 1) % n]);
        v.push(a);
        if split {
            let t = 0.02 + 0.96 * rnd();
            v.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
        }
    }
    if !ccw {
        v.reverse();
    }
    v
}

/// A region's boundary edges in buckets, to test many points against a many-sided boundary.
struct Buckets {
    lo: Point2,
    cell: f64,
    n: [usize; 2],
    reach: f64,
    /// Per square cell: the edges that come within `reach` of it.
    near: Vec<Vec<(Point2, Point2)>>,
    /// Per row of cells: the edges spanning some of its height (what a ray along it crosses).
    rows: Vec<Vec<(Point2, Point2)>>,
}

impl Buckets {
    fn new(r: &Region, cell: f64, reach: f64) -> Buckets {
        let edges: Vec<(Point2, Point2)> = std::iter::once(&r.outer)
            .chain(&r.holes)
            .flat_map(|l| (0..l.len()).map(move |i| (l[i], l[(i + 1) % l.len()])))
            .collect();
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [-f64::INFINITY; 2];
        for (a, _) in &edges {
            for k in 0..2 {
                lo[k] = lo[k].min(a[k]);
                hi[k] = hi[k].max(a[k]);
            }
        }
        let n = [0, 1].map(|k| ((hi[k] - lo[k]) / cell) as usize + 1);
        let mut b = Buckets {
            lo,
            cell,
            n,
            reach,
            near: vec![Vec::new(); n[0] * n[1]],
            rows: vec![Vec::new(); n[1]],
        };
        for &(p, q) in &edges {
            let (x0, x1) = (p[0].min(q[0]), p[0].max(q[0]));
            let (y0, y1) = (p[1].min(q[1]), p[1].max(q[1]));
            for iy in b.index(y0, 1)..=b.index(y1, 1) {
                b.rows[iy].push((p, q));
            }
            for iy in b.index(y0 - reach, 1)..=b.index(y1 + reach, 1) {
                for ix in b.index(x0 - reach, 0)..=b.index(x1 + reach, 0) {
                    b.near[iy * n[0] + ix].push((p, q));
                }
            }
        }
        b
    }

    /// Cell index along axis `k`, clamped to the grid.
    fn index(&self, v: f64, k: usize) -> usize {
        (((v - self.lo[k]) / self.cell).floor().max(0.0) as usize).min(self.n[k] - 1)
    }

    /// Even-odd inside the boundary (outside when beyond its bounding box).
    fn inside(&self, p: Point2) -> bool {
        let hi = [0, 1].map(|k| self.lo[k] + self.n[k] as f64 * self.cell);
        if (0..2).any(|k| !(self.lo[k]..hi[k]).contains(&p[k])) {
            return false;
        }
        let mut c = false;
        for &(a, b) in &self.rows[self.index(p[1], 1)] {
            if (a[1] > p[1]) != (b[1] > p[1])
                && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0]
            {
                c = !c;
            }
        }
        c
    }

    /// Distance to the boundary, or `reach` when farther.
    fn clearance(&self, p: Point2) -> f64 {
        let cell = self.index(p[1], 1) * self.n[0] + self.index(p[0], 0);
        self.near[cell]
            .iter()
            .map(|&(a, b)| seg_dist(p, a, b))
            .fold(self.reach, f64::min)
    }
}

/// Every point of every path is inside `r` and at least `width / 2 - 0.01` from its boundary;
/// no path has a segment shorter than a micrometre (none of zero length), and no ring a spike
/// (a turn back by more than 170°: on these round shapes no ring turns that sharply).
fn check_clearance(name: &str, r: &Region, width: f64) {
    let edges = Buckets::new(r, 0.5, 0.5 * width);
    for mode in MODES {
        for spacing in [0.45, 0.5] {
            // Layers of the same parity fill alike (contour fills every layer alike): check
            // each different fill once.
            let mut seen: Vec<Vec<Path2>> = Vec::new();
            for layer in 0..=3 {
                let paths = fill_layer(
                    std::slice::from_ref(r),
                    &params(mode),
                    layer,
                    width,
                    spacing,
                )
                .paths;
                assert!(!paths.is_empty(), "{name}, {mode:?}");
                if seen.contains(&paths) {
                    continue;
                }
                seen.push(paths.clone());
                for (k, p) in paths.iter().enumerate() {
                    let at =
                        format!("{name}, {mode:?}, spacing {spacing}, layer {layer}, path {k}");
                    for (i, &q) in p.points.iter().enumerate() {
                        assert!(edges.inside(q), "{at}: {q:?} outside");
                        if free_end(mode, p, i) {
                            continue;
                        }
                        let d = edges.clearance(q);
                        assert!(
                            d >= 0.5 * width - 0.01,
                            "{at}: {q:?} only {d} from the boundary"
                        );
                    }
                    for w in p.points.windows(2) {
                        let l = (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]);
                        assert!(l >= 1e-6, "{at}: segment {:?}-{:?} {l} long", w[0], w[1]);
                    }
                    if p.kind == PathKind::Infill {
                        // Zig-zag turns back sharply where a line meets a hole near its
                        // tangent; the clearance above is what matters there.
                        continue;
                    }
                    for w in p.points.windows(3) {
                        let u = [w[1][0] - w[0][0], w[1][1] - w[0][1]];
                        let v = [w[2][0] - w[1][0], w[2][1] - w[1][1]];
                        let c = (u[0] * v[0] + u[1] * v[1]) / (u[0].hypot(u[1]) * v[0].hypot(v[1]));
                        assert!(c > (170f64).to_radians().cos(), "{at}: spike at {:?}", w[1]);
                    }
                }
            }
        }
    }
}

/// Disks of radius 10 as polygons of 64 to 1000 vertices, exact, with the radius jittered by
/// ±0.01 and with a collinear point on every chord (a cylinder's cross-section): with the
/// default parameters, width 0.45 and spacing 0.45 or 0.5, every mode on layers 0 to 3 keeps
/// every bead centre line half a width inside.
#[test]
fn many_sided_disks_keep_half_a_width_inside() {
    for n in [64, 200, 256, 360, 1000] {
        for jitter in [0.0, 0.01] {
            for split in [false, true] {
                let r = Region {
                    outer: section_disk([0.0, 0.0], 10.0, n, jitter, split, true),
                    holes: vec![],
                };
                let name = format!("disk, {n} vertices, jitter {jitter}, split {split}");
                check_clearance(&name, &r, 0.45);
            }
        }
    }
}

/// A 30 x 20 rectangle with a round hole of radius 5 (64 and 300 vertices, exact, jittered,
/// split): half a width clear of the outside and of the hole.
#[test]
fn many_sided_holes_keep_half_a_width_clear() {
    for n in [64, 300] {
        for jitter in [0.0, 0.01] {
            for split in [false, true] {
                let r = Region {
                    outer: rect(0.0, 0.0, 30.0, 20.0),
                    holes: vec![section_disk([15.0, 10.0], 5.0, n, jitter, split, false)],
                };
                let name = format!("plate, hole of {n} vertices, jitter {jitter}, split {split}");
                check_clearance(&name, &r, 0.45);
            }
        }
    }
}

/// An I-section whose web (1.4 mm) takes the first ring's beads from both sides but leaves
/// the second ring's offset only 0.2 mm wide: that ring's beads would overlap by half a bead
/// down the whole web. The second ring keeps to the flanges; the web's middle is handed back
/// as a gap and filled with beads as wide as it, so the beads put the region's area down
/// without laying the web twice.
#[test]
fn a_web_narrower_than_two_rings_is_not_laid_twice() {
    use i_overlay::core::fill_rule::FillRule;
    use i_overlay::float::simplify::SimplifyShape;
    use i_overlay::mesh::float::stroke::offset::StrokeOffset;
    use i_overlay::mesh::float::style::{LineJoin, StrokeStyle};
    let outer = vec![
        [0.0, 0.0],
        [6.0, 0.0],
        [6.0, 3.0],
        [3.7, 3.0],
        [3.7, 13.0],
        [6.0, 13.0],
        [6.0, 16.0],
        [0.0, 16.0],
        [0.0, 13.0],
        [2.3, 13.0],
        [2.3, 3.0],
        [0.0, 3.0],
    ];
    let r = Region {
        outer,
        holes: vec![],
    };
    let area = region_area(&r);
    for mode in [PathMode::Contour, PathMode::ContourZigzag] {
        let filled = fill_layer(std::slice::from_ref(&r), &params(mode), 0, 0.4, 0.4);
        assert!(
            !filled.gaps.is_empty(),
            "{mode:?}: the web's middle is a gap"
        );
        // Ring beads laid twice: their stroked areas less the area of their union.
        let style = StrokeStyle::new(0.4).line_join(LineJoin::Miter(0.1));
        let mut sum = 0.0;
        let mut all: Vec<Vec<Vec<Point2>>> = vec![];
        for p in filled
            .paths
            .iter()
            .filter(|p| p.kind == PathKind::Perimeter)
        {
            let s = p.points[..p.points.len() - 1]
                .to_vec()
                .stroke(style.clone(), true);
            sum += s.iter().flatten().map(|c| 0.5 * area2(c)).sum::<f64>();
            all.extend(s);
        }
        let union = all.simplify_shape(FillRule::NonZero);
        let twice = sum - union.iter().flatten().map(|c| 0.5 * area2(c)).sum::<f64>();
        assert!(
            twice < 0.005 * area,
            "{mode:?}: {twice:.3} mm^2 of ring bead laid twice"
        );
        let ratio = bead_area(&fill_all(&r, &params(mode), 0)) / area;
        assert!(
            (ratio - 1.0).abs() < 0.02,
            "{mode:?}: bead area / area {ratio:.4}"
        );
    }
}

/// Roles: in a square plate with a round hole, the first ring about the outside and the one
/// about the hole are `ExternalPerimeter` (the beads on the part's surface, each within half
/// a bead of its boundary), the second ring `Perimeter`, the zig-zag between them
/// `SolidInfill` where beads touch and `InternalInfill` where they are laid apart; in a strip
/// 4.6 beads wide filled by contours, the 0.6 bead the two rings from each side leave in the
/// middle is `GapFill`.
#[test]
fn paths_carry_the_roles_slicers_name() {
    let regions = regions_from_loops(&[
        rect(0.0, 0.0, 20.0, 20.0),
        circle([10.0, 10.0], 3.0, 64, false),
    ]);
    let w = 0.4;
    let filled = fill_layer(&regions, &params(PathMode::ContourZigzag), 0, w, w);
    let rings: Vec<&Path2> = filled
        .paths
        .iter()
        .filter(|p| p.kind == PathKind::Perimeter)
        .collect();
    assert_eq!(
        rings.len(),
        4,
        "two rings about the outside, two about the hole"
    );
    for r in &rings {
        // Distance of the ring to the region's boundary: the square's edge or the hole's.
        let d = r
            .points
            .iter()
            .map(|p| {
                let edge = p[0].min(p[1]).min(20.0 - p[0]).min(20.0 - p[1]);
                let hole = (p[0] - 10.0).hypot(p[1] - 10.0) - 3.0;
                edge.min(hole)
            })
            .fold(f64::INFINITY, f64::min);
        let want = if (d - 0.5 * w).abs() < 0.02 {
            Role::ExternalPerimeter
        } else {
            assert!((d - 1.5 * w).abs() < 0.02, "ring {d} mm in");
            Role::Perimeter
        };
        assert_eq!(r.role, want, "ring {d} mm in");
    }
    let infill: Vec<&Path2> = filled
        .paths
        .iter()
        .filter(|p| p.kind == PathKind::Infill)
        .collect();
    assert!(!infill.is_empty());
    assert!(infill.iter().all(|p| p.role == Role::SolidInfill));
    let sparse = LayerParams {
        filling_ratio: 0.3,
        ..params(PathMode::ContourZigzag)
    };
    let filled = fill_layer(&regions, &sparse, 0, w, w / 0.3);
    assert!(filled
        .paths
        .iter()
        .filter(|p| p.kind == PathKind::Infill)
        .all(|p| p.role == Role::InternalInfill));
    let strip = regions_from_loops(&[rect(0.0, 0.0, 30.0, 4.0 * w + 0.6 * w)]);
    let paths = fill_regions(strip, &params(PathMode::Contour), 0, w, w);
    assert!(
        paths.iter().any(|p| p.role == Role::GapFill),
        "{:?}",
        paths.iter().map(|p| p.role).collect::<Vec<_>>()
    );
    assert!(paths.iter().any(|p| p.role == Role::ExternalPerimeter));
}

/// Contour rings are laid simplified within a tenth of the feature's tolerance (0.005 mm, at
/// most 1 % of the 0.4 mm width): about a 1024-sided hole of radius 3 mm, each ring that
/// runs round it alone stays, between its points too, within that of the circle its offset
/// is, its rings stay a spacing apart, and it has no more points than twice what a chord
/// sag of that tolerance needs (an offset keeps every vertex of the ring before it, and
/// i_overlay puts two at each: the hole's 1024 and more).
#[test]
fn contour_rings_are_simplified_within_the_tolerance() {
    let c = [15.0, 15.0];
    let r = Region {
        outer: rect(0.0, 0.0, 30.0, 30.0),
        holes: vec![circle(c, 3.0, 1024, false)],
    };
    let p = params(PathMode::Contour);
    let tol = (0.1 * p.tolerance).min(0.01 * 0.4);
    let paths = fill_layer(&[r], &p, 0, 0.4, 0.4).paths;
    let radius = |q: &Point2| (q[0] - c[0]).hypot(q[1] - c[1]);
    let mut hole_rings: Vec<(f64, &Path2)> = paths
        .iter()
        .filter(|path| path.kind == PathKind::Perimeter)
        .filter_map(|path| {
            let (lo, hi) = path
                .points
                .iter()
                .map(radius)
                .fold((f64::INFINITY, 0.0f64), |(lo, hi), d| {
                    (lo.min(d), hi.max(d))
                });
            (hi < 8.0 && hi - lo < 0.05).then_some((hi, path))
        })
        .collect();
    hole_rings.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!(
        hole_rings.len() >= 8,
        "{} rings about the hole",
        hole_rings.len()
    );
    for (k, (_, ring)) in hole_rings.iter().enumerate() {
        let rho = 3.0 + 0.2 + 0.4 * k as f64;
        // The ring's points and the middles of its chords (where a chord strays farthest).
        for w in ring.points.windows(2) {
            let mid = [0.5 * (w[0][0] + w[1][0]), 0.5 * (w[0][1] + w[1][1])];
            for q in [w[0], mid] {
                let e = radius(&q) - rho;
                assert!(e.abs() <= tol + 1e-4, "ring {k}: {e} off radius {rho}");
            }
        }
        let need = PI / (1.0 - tol / rho).acos();
        let n = ring.points.len() - 1;
        assert!(
            (n as f64) <= 2.0 * need + 8.0,
            "ring {k}: {n} points, {need:.0} needed"
        );
    }
}

fn total_area(rs: &[Region]) -> f64 {
    rs.iter().map(region_area).sum()
}

fn reversed(mut p: Vec<Point2>) -> Vec<Point2> {
    p.reverse();
    p
}

#[test]
fn crossing_sections_of_overlapping_solids_are_united_by_their_winding() {
    // Two 10 x 10 squares overlapping by 5 x 5, both counter-clockwise (two solids' sections):
    // their union, 175 mm², whichever way round the loops are given.
    let a = rect(0.0, 0.0, 10.0, 10.0);
    let b = rect(5.0, 5.0, 15.0, 15.0);
    for loops in [
        vec![a.clone(), b.clone()],
        vec![reversed(a.clone()), reversed(b.clone())],
    ] {
        let rs = regions_by_winding(&loops);
        assert!(
            (total_area(&rs) - 175.0).abs() < 1e-6,
            "{}",
            total_area(&rs)
        );
        for p in [[2.0, 2.0], [7.5, 7.5], [12.0, 12.0]] {
            assert!(rs.iter().any(|r| in_region(p, r, 0.0)), "{p:?} not covered");
        }
    }
    // A body inside another, both counter-clockwise (a cylinder pushed into a box): the box.
    let inner = circle([5.0, 5.0], 2.0, 64, true);
    let rs = regions_by_winding(&[a.clone(), inner.clone()]);
    assert!(
        (total_area(&rs) - 100.0).abs() < 1e-6,
        "{}",
        total_area(&rs)
    );
    // A hole runs the other way round: the even-odd regions, outline less the hole.
    let hole = circle([5.0, 5.0], 2.0, 64, false);
    let expect = regions_from_loops(&[a.clone(), hole.clone()]);
    assert_eq!(regions_by_winding(&[a, hole]), expect);
    assert!(
        (total_area(&expect) - (100.0 - total_area(&regions_from_loops(&[inner])))).abs() < 1e-9
    );
}

#[test]
fn holes_of_no_area_do_not_break_the_lines() {
    // A boolean between nearly coincident edges leaves holes of 1e-16 to 1e-8 mm² (741 in
    // one support column under the sphere fixture): each was grown by half a bead where the
    // region was eroded for its lines, cutting a 0.45 mm gap into every line through it, and
    // made the erosion take seconds.
    let params = LayerParams {
        path_mode: PathMode::Zigzag,
        ..LayerParams::default()
    };
    let outer = rect(0.0, 0.0, 10.0, 6.0);
    let noise: Vec<Vec<Point2>> = (0..40)
        .map(|k| {
            let (x, y) = (0.37 + 0.23 * k as f64, 0.5 + 0.12 * k as f64);
            // A sliver triangle 1e-5 mm tall: 5e-6 mm² at most.
            vec![[x, y], [x + 1e-5, y], [x, y + 1e-5]]
        })
        .collect();
    let clean = Region {
        outer: outer.clone(),
        holes: vec![],
    };
    let noisy = Region {
        outer,
        holes: noise,
    };
    let lines = |r: &Region| -> Vec<Path2> {
        fill_layer(std::slice::from_ref(r), &params, 0, 0.45, 0.45).paths
    };
    let (a, b) = (lines(&clean), lines(&noisy));
    let length = |ps: &[Path2]| -> f64 {
        ps.iter()
            .flat_map(|p| p.points.windows(2))
            .map(|s| (s[1][0] - s[0][0]).hypot(s[1][1] - s[0][1]))
            .sum()
    };
    assert_eq!(
        a.len(),
        b.len(),
        "paths: {} clean, {} with noise",
        a.len(),
        b.len()
    );
    assert!(
        (length(&a) - length(&b)).abs() < 1e-6,
        "{} vs {}",
        length(&a),
        length(&b)
    );
}

/// Every mode lays its rings and its zig-zag connectors about a finely chorded hole (a
/// 1024-sided circle, the chords of a 3 mm hole 18 micrometres long, as a mesh's section
/// gives them) simplified within a tenth of the tolerance: each chord's middle within that of
/// the circle through its ends about the hole's centre, and each run of points hugging the
/// hole (a ring about it, a connector along the infill area's edge) no denser than twice what
/// a chord sag of that tolerance needs for the angle it turns through, where the hole's own
/// vertices (and i_overlay's arcs at each) came through before.
#[test]
fn every_mode_lays_its_rings_and_connectors_simplified_within_a_tenth_of_the_tolerance() {
    let c = [15.0, 15.0];
    let (hole, width) = (3.0, 0.4);
    let r = Region {
        outer: rect(0.0, 0.0, 30.0, 30.0),
        holes: vec![circle(c, hole, 1024, false)],
    };
    let radius = |q: &Point2| (q[0] - c[0]).hypot(q[1] - c[1]);
    let angle = |q: &Point2| (q[1] - c[1]).atan2(q[0] - c[0]);
    let near = hole + 2.0 * width;
    for mode in MODES {
        let p = params(mode);
        let tol = (0.1 * p.tolerance).min(0.01 * width);
        // Points a chord sag of `tol` needs a turn at the hole's radius (the least).
        let need = PI / (1.0 - tol / hole).acos();
        let paths = fill_layer(std::slice::from_ref(&r), &p, 0, width, width).paths;
        let mut runs = 0;
        for path in &paths {
            for run in path
                .points
                .chunk_by(|a, b| (radius(a) < near) == (radius(b) < near))
            {
                if radius(&run[0]) >= near {
                    continue;
                }
                runs += 1;
                let turned: f64 = run
                    .windows(2)
                    .map(|w| (angle(&w[1]) - angle(&w[0]) + PI).rem_euclid(2.0 * PI) - PI)
                    .map(f64::abs)
                    .sum();
                let most = 2.0 * need * turned / (2.0 * PI) + 8.0;
                assert!(
                    run.len() as f64 <= most,
                    "{mode:?}: {} points turning {turned:.3} rad about the hole, at most {most:.0}",
                    run.len()
                );
                for w in run.windows(2) {
                    let m = [0.5 * (w[0][0] + w[1][0]), 0.5 * (w[0][1] + w[1][1])];
                    let sag = 0.5 * (radius(&w[0]) + radius(&w[1])) - radius(&m);
                    assert!(sag <= tol + 1e-4, "{mode:?}: a chord sags {sag} mm");
                }
            }
        }
        assert!(runs > 0, "{mode:?}: nothing laid about the hole");
    }
}
