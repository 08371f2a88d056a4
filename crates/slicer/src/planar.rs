//! Planar layers for `two5d` features (feature-based AM paper: "the slicing plane is parallel
//! to the reference plane, ... the tool direction is vertical to them").
//!
//! Each feature is cut at the middle of every layer by a plane parallel to its reference plane;
//! the cross-section's loops are grouped into regions and filled by the feature's path mode; the
//! paths are lifted to the layer's top (where the nozzle runs) with the reference normal as the
//! tool axis, and each segment gets its filament length from Eq. 1.

use crate::feature_mesh::layer_tops;
pub use crate::feature_mesh::{reference_plane, PlanarMesh};
use crate::fill::{
    fill_layer_with, order_greedy, regions_from_loops, thinner_than, Region, SparseLayer,
};
use crate::geom2d::{dist, region_area, Point2};
use crate::params::{InfillPattern, LayerParams, PathMode};
use crate::region_fill::{fill_flat_region, solid_on_skins, Boundary, FillPath};
use crate::toolpath::{MoveKind, PathPoint, Role};
use brep::math::P3;
use brep::section::{section, Plane};
use features::{Feature, FeatureKind, FeatureTree};
use rayon::prelude::*;

pub use crate::error::FeatureError;
use crate::feature_plan::{FeaturePlan, Layer, LayerPath, LayerSurface};
pub use crate::figures::FeatureFigures;
use crate::support_material::SupportRegions;
use crate::tolerance::{COLLINEAR, KEY_GRID};
pub use toolpath::Bead;

/// How far (mm) `points` (a feature's mesh) reach below the build plate of `tree` (its base
/// feature's reference plane): 0 when they do not, or when the tree has no plate.
pub(crate) fn below_plate(tree: &FeatureTree, points: &[P3]) -> f64 {
    let Some(plate) = tree.features.first().and_then(|b| reference_plane(tree, b)) else {
        return 0.0;
    };
    points
        .iter()
        .map(|p| -plate.height(p))
        .fold(0.0f64, f64::max)
}

/// How deep (mm) a planar region must reach inside its boundary to be filled by offsets of
/// one bead width (`fill::fill_layer`): room for the first ring's half bead, the perimeters
/// (at least one) and one more spacing for the infill or the next ring. Thinner regions get
/// `freeform::fill_flat_region`.
fn thin_depth(params: &LayerParams, width: f64, spacing: f64) -> f64 {
    0.5 * width + (params.perimeters.max(1) as f64) * spacing
}

/// The paths of a planar layer's regions, for layer number `layer`, beads `width` wide and
/// `spacing` apart: `fill::fill_layer` where offsets of one bead width fit, and beads as wide
/// as the region there (`freeform::fill_flat_region`) for regions too thin for those rings
/// and infill, where they would overlap or drop beads, and for the strips the rings of the
/// others leave (thin parts, the middle between rings). Raster and zig-zag lines run
/// boundary to boundary whatever the width: only the modes with rings need this.
pub fn fill_regions(
    regions: Vec<Region>,
    params: &LayerParams,
    layer: usize,
    width: f64,
    spacing: f64,
) -> Vec<FillPath> {
    fill_regions_with(regions, params, layer, width, spacing, None).0
}

/// [`fill_regions`] with sparse infill away from the layer's skin (`sparse`,
/// [`crate::fill::fill_layer_with`]), and the area laid sparse (mm²) with the share of it its
/// lines cover (mm², area × the layer's density). Regions too thin for rings, and the strips
/// rings leave, stay solid.
pub fn fill_regions_with(
    regions: Vec<Region>,
    params: &LayerParams,
    layer: usize,
    width: f64,
    spacing: f64,
    sparse: Option<SparseLayer>,
) -> (Vec<FillPath>, (f64, f64)) {
    let rings = matches!(
        params.path_mode,
        PathMode::Contour | PathMode::ContourZigzag
    );
    let (thin, thick): (Vec<Region>, Vec<Region>) = regions
        .into_iter()
        .partition(|r| rings && thinner_than(r, thin_depth(params, width, spacing)));
    let mut paths: Vec<FillPath> = vec![];
    // What the rings of the thick regions leave, and their sparse area and its density.
    let (mut gaps, mut sparse_area, mut density) = (vec![], 0.0, 0.0);
    for r in &thick {
        let one = fill_layer_with(
            std::slice::from_ref(r),
            params,
            layer,
            width,
            spacing,
            sparse,
        );
        let mut laid: Vec<FillPath> = one
            .paths
            .into_iter()
            .map(|p| FillPath::uniform(p.points, width, p.role))
            .collect();
        if one.sparse_area <= 0.0 {
            let gaps: f64 = one.gaps.iter().map(region_area).sum();
            conserve_solid_infill(&mut laid, region_area(r) - gaps);
        }
        paths.extend(laid);
        gaps.extend(one.gaps);
        sparse_area += one.sparse_area;
        density = one.sparse_density;
    }
    for r in &thin {
        paths.extend(fill_flat_region(
            r,
            params,
            layer,
            width,
            spacing,
            Boundary::Part,
        ));
    }
    for r in &gaps {
        paths.extend(fill_flat_region(
            r,
            params,
            layer,
            width,
            spacing,
            Boundary::Beads,
        ));
    }
    (paths, (sparse_area, sparse_area * density))
}

/// Widens the solid infill lines of one region's fill (`laid`: its rings and lines, beads of
/// one width) so that the beads cover `area` (mm², the region less its gaps, which are filled
/// to their own area), where they fall short by more than [`INFILL_SHORT`] of it: by at most
/// [`MAX_INFILL_WIDENING`]. A small region's core, a disc a few beads across inside the rings
/// of a pin, is crossed by two or three lines whose square ends leave the round core's rim
/// bare: a 3 mm pin was filled 2.6 % short, its core 15 %. The lines put down the core's
/// volume by Eq. 1 for the wider bead.
fn conserve_solid_infill(laid: &mut [FillPath], area: f64) {
    let strip = |p: &FillPath| p.strip_area(dist);
    let total: f64 = laid.iter().map(strip).sum();
    let infill: f64 = laid
        .iter()
        .filter(|p| p.role == Role::SolidInfill)
        .map(strip)
        .sum();
    let short = area - total;
    if infill <= 0.0 || short.is_nan() || short <= INFILL_SHORT * area {
        return;
    }
    let k = (1.0 + short / infill).min(MAX_INFILL_WIDENING);
    for p in laid.iter_mut().filter(|p| p.role == Role::SolidInfill) {
        for w in &mut p.widths {
            *w *= k;
        }
    }
}

/// The share of a region's area its beads may fall short of before its solid infill is
/// widened ([`conserve_solid_infill`]): a large region's fill is within a few tenths of a
/// per cent, and is left as it is.
const INFILL_SHORT: f64 = 0.005;

/// The most a region's solid infill lines are widened to cover it.
const MAX_INFILL_WIDENING: f64 = 1.3;

/// Plans one two5d feature in planar layers parallel to its reference plane; its first travel
/// starts at `entry` (where the nozzle is, if anywhere): [`fill_two5d`], then
/// [`Two5dFill::lay`].
pub fn plan_two5d(
    tree: &FeatureTree,
    f: &Feature,
    params: &LayerParams,
    bead: Bead,
    entry: Option<P3>,
) -> Result<FeaturePlan, FeatureError> {
    Ok(fill_two5d(tree, f, params, bead)?.lay(entry))
}

/// A two5d feature's layers sectioned and filled in their planes, before they are ordered
/// from where the nozzle is and joined by travel (see [`crate::freeform::FreeformFill`]).
pub struct Two5dFill {
    id: usize,
    plane: Plane,
    bead: Bead,
    /// Each layer's middle and top height and thickness.
    tops: Vec<(f64, f64, f64)>,
    /// Each layer's fill paths in its plane.
    filled: Vec<Vec<FillPath>>,
    /// Each layer's area laid sparse and the share of it its lines cover, mm² (all 0 without
    /// sparse infill).
    sparse: Vec<(f64, f64)>,
    fig: FeatureFigures,
}

/// Sections and fills every layer of a two5d feature (in parallel).
pub fn fill_two5d(
    tree: &FeatureTree,
    f: &Feature,
    params: &LayerParams,
    bead: Bead,
) -> Result<Two5dFill, FeatureError> {
    fill_two5d_on(tree, f, params, bead, None)
}

/// [`fill_two5d`] on the feature's planar mesh made already (`None`: made here).
pub fn fill_two5d_on(
    tree: &FeatureTree,
    f: &Feature,
    params: &LayerParams,
    bead: Bead,
    meshed: Option<&PlanarMesh>,
) -> Result<Two5dFill, FeatureError> {
    if f.kind != FeatureKind::Two5d {
        return Err(FeatureError::NotTwo5d(f.id));
    }
    params
        .validate()
        .map_err(|msg| FeatureError::Params { id: f.id, msg })?;
    let pm = PlanarMesh::given_or_of(meshed, tree, f, params)?;
    let (plane, mesh, grown) = (pm.plane, &pm.mesh, pm.grown.clone());
    let spacing = params.spacing(bead.width);
    let fig = FeatureFigures {
        below_plate: below_plate(tree, &mesh.positions),
        grown,
        ..FeatureFigures::default()
    };
    // Each layer's section and fill depend on that layer alone: computed in parallel, then
    // ordered and joined by travel one layer after the other.
    let tops = pm.layers.clone();
    let covering = fig.grown.is_some();
    // Each section simplified within a tenth of the tolerance: a mesh's section has runs of
    // points micrometres apart where long thin triangles meet the plane (NIST CTC-05's arcs),
    // which every offset of the fill and every point of the plan would carry.
    let near = crate::fill::ring_print_tolerance(params.tolerance, bead.width);
    let found = pm
        .mid_sections
        .as_ref()
        .filter(|s| !covering && s.len() == tops.len());
    let sections: Vec<Vec<Region>> = match found {
        Some(s) => s.clone(),
        None => sections_at(mesh, &plane, &tops, covering, near),
    };
    let mut fig = fig;
    if let Some(g) = fig.grown.as_mut() {
        g.layered_volume = Some(
            sections
                .iter()
                .zip(&tops)
                .map(|(rs, t)| rs.iter().map(region_area).sum::<f64>() * t.2)
                .sum(),
        );
    }
    let mids: Vec<f64> = tops.iter().map(|t| t.0).collect();
    let (filled, sparse) = fill_sections(sections, &mids, params, bead.width, spacing);
    Ok(Two5dFill {
        id: f.id,
        plane,
        bead,
        tops,
        filled,
        sparse,
        fig,
    })
}

/// The outline of a tree's build-plate face: the section of its base feature `f` (a two5d
/// feature) in the middle of its first layer, what that layer fills, as regions in the 2-D
/// frame of `f`'s reference plane, with that plane. Empty regions when the section is empty.
pub fn plate_regions(
    tree: &FeatureTree,
    f: &Feature,
    params: &LayerParams,
) -> Result<(Plane, Vec<Region>), FeatureError> {
    let PlanarMesh {
        plane,
        mesh,
        layers,
        ..
    } = PlanarMesh::of(tree, f, params)?;
    let Some(&(mid, _, _)) = layers.first() else {
        return Ok((plane, vec![]));
    };
    let regions = section_regions(&mesh, &plane.offset(mid), &plane);
    Ok((plane, regions))
}

/// The regions of `mesh`'s section by the plane `cut`, in the 2-D frame of `frame` (a plane
/// parallel to it). Loops that may cross (the sections of solids pushed into each other,
/// sliced whole: [`loops_may_cross`]) are united by their winding
/// ([`crate::fill::regions_by_winding`]), so the material they share is laid once; the others
/// nest even-odd.
pub(crate) fn section_regions(mesh: &brep::mesh::Mesh, cut: &Plane, frame: &Plane) -> Vec<Region> {
    let loops: Vec<Vec<[f64; 2]>> = section(mesh, cut)
        .iter()
        .map(|l| l.iter().map(|p| frame.to_2d(p)).collect())
        .collect();
    match loops_may_cross(&loops) {
        true => crate::fill::regions_by_winding(&loops),
        false => regions_from_loops(&loops),
    }
}

/// Whether two of `loops` may cross or one lies in the other running the same way round:
/// their boxes overlap and neither box holds the other (a hole's box lies inside its
/// outline's, a separate island's apart from it), or one box holds the other and the loops
/// turn the same way (a hole runs against its outline; a body inside another does not).
fn loops_may_cross(loops: &[Vec<[f64; 2]>]) -> bool {
    let turns: Vec<bool> = loops
        .iter()
        .map(|l| brep::section::signed_area(l) > 0.0)
        .collect();
    let boxes: Vec<[f64; 4]> = loops
        .iter()
        .map(|l| {
            l.iter().fold(
                [f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY],
                |b, p| {
                    [
                        b[0].min(p[0]),
                        b[1].min(p[1]),
                        b[2].max(p[0]),
                        b[3].max(p[1]),
                    ]
                },
            )
        })
        .collect();
    let holds =
        |a: &[f64; 4], b: &[f64; 4]| a[0] <= b[0] && a[1] <= b[1] && a[2] >= b[2] && a[3] >= b[3];
    let apart =
        |a: &[f64; 4], b: &[f64; 4]| a[2] < b[0] || b[2] < a[0] || a[3] < b[1] || b[3] < a[1];
    boxes.iter().enumerate().any(|(i, a)| {
        boxes[i + 1..].iter().enumerate().any(|(k, b)| {
            let j = i + 1 + k;
            match (apart(a, b), holds(a, b) || holds(b, a)) {
                (true, _) => false,
                (false, false) => true,
                (false, true) => turns[i] == turns[j],
            }
        })
    })
}

/// A prism's layers filled like a two5d feature's (feature `id`): `layers` layers `height` mm
/// thick on `plane`, each the section `regions` (in `plane`'s 2-D frame), filled by `params`
/// with solid skins at the bottom and the top; [`Two5dFill::lay`] lays them.
pub fn fill_prism(
    id: usize,
    plane: Plane,
    regions: &[Region],
    layers: usize,
    height: f64,
    params: &LayerParams,
    bead: Bead,
) -> Two5dFill {
    let spacing = params.spacing(bead.width);
    let tops: Vec<(f64, f64, f64)> = (0..layers)
        .map(|k| {
            let z = k as f64 * height;
            (z + 0.5 * height, z + height, height)
        })
        .collect();
    let mids: Vec<f64> = tops.iter().map(|t| t.0).collect();
    let sections = vec![regions.to_vec(); layers];
    let (filled, sparse) = fill_sections(sections, &mids, params, bead.width, spacing);
    Two5dFill {
        id,
        plane,
        bead,
        tops,
        filled,
        sparse,
        fig: FeatureFigures::default(),
    }
}

/// Each layer's section of `mesh` (`tops`: each layer's middle, top and thickness over
/// `plane`): at its middle, or where `covering` (a feature grown by an allowance) the union of
/// its sections over its thickness; simplified within `near`. In parallel.
fn sections_at(
    mesh: &brep::mesh::Mesh,
    plane: &Plane,
    tops: &[(f64, f64, f64)],
    covering: bool,
    near: f64,
) -> Vec<Vec<Region>> {
    tops.par_iter()
        .with_max_len(1)
        .map(|&(mid, top, dl)| {
            let at = |z: f64| {
                let cut = plane.offset(z);
                section_regions(mesh, &cut, &cut)
            };
            let regions = match covering {
                false => at(mid),
                true => crate::feature_mesh::covering_section(at, (mid, top, dl)),
            };
            crate::fill::simplified(regions, near)
        })
        .collect()
}

/// Each layer's paths from its section's regions, filled in parallel, and each layer's area
/// laid sparse (mm²). A layer whose section is the same polygon as an earlier layer's
/// ([`SectionKey`]) of the same parity where the fill alternates ([`alternates`]: the
/// zig-zag's angle turns every other layer, and nothing else of a fill depends on the layer)
/// takes a copy of that layer's fill instead of making it again: the layers of a prism are all
/// one section.
///
/// Without sparse infill (`infill_density` 1, [`LayerParams::sparse_infill`]) the bottom and
/// top layers then get their solid skins. With it, each layer's skin is found from its
/// neighbours' sections ([`crate::skins`], at `mids`, each layer's middle height) and laid
/// solid, the rest of its interior sparse; only layers without skin share a fill, on layers
/// of the same parity (rectilinear turns every other layer) and never for the gyroid (its
/// lines change with the height).
fn fill_sections(
    sections: Vec<Vec<Region>>,
    mids: &[f64],
    params: &LayerParams,
    width: f64,
    spacing: f64,
) -> (Vec<Vec<FillPath>>, Vec<(f64, f64)>) {
    let n = sections.len();
    let mut sections = sections;
    if params.path_mode == PathMode::Contour {
        sections.par_iter_mut().for_each(canonical_order);
    }
    let keys: Vec<SectionKey> = sections.par_iter().map(|r| SectionKey::new(r)).collect();
    let sparse = params.sparse_infill();
    let skins: Vec<Vec<Region>> = if sparse {
        let same: Vec<bool> = keys.windows(2).map(|k| k[0] == k[1]).collect();
        let (top, bottom) = (params.top_solid_layers, params.bottom_solid_layers);
        crate::skins::skins(&sections, &same, top, bottom, width, params.tolerance)
    } else {
        vec![vec![]; n]
    };
    let first = first_of_each_fill(&keys, &skins, params);
    let mut fills: Vec<Option<LayerFill>> = sections
        .into_par_iter()
        .enumerate()
        .with_max_len(1)
        .map(|(layer, regions)| {
            let at = sparse.then(|| SparseLayer {
                skin: &skins[layer],
                z: mids.get(layer).copied().unwrap_or(0.0),
            });
            (first[layer] == layer)
                .then(|| fill_regions_with(regions, params, layer, width, spacing, at))
        })
        .collect();
    // The last layer to take each fill, which moves it instead of copying it.
    let mut last: Vec<usize> = (0..n).collect();
    for (layer, &j) in first.iter().enumerate() {
        last[j] = layer;
    }
    (0..n)
        .map(|layer| {
            let j = first[layer];
            let (paths, area) = if last[j] == layer {
                fills[j].take()
            } else {
                fills[j].clone()
            }
            .unwrap_or_default();
            match sparse {
                true => (paths, area),
                false => (solid_on_skins(paths, layer, n), area),
            }
        })
        .unzip()
}

/// A layer's paths, and its area laid sparse with the share of it its lines cover (mm²).
type LayerFill = (Vec<FillPath>, (f64, f64));

/// For each layer, the first layer whose fill it takes (itself when none before it has the
/// same section, [`SectionKey`], and parity where the fill alternates). With sparse infill,
/// a layer with skin, and every gyroid layer, fills itself.
fn first_of_each_fill(
    keys: &[SectionKey],
    skins: &[Vec<Region>],
    params: &LayerParams,
) -> Vec<usize> {
    let sparse = params.sparse_infill();
    let mut first: Vec<usize> = Vec::with_capacity(keys.len());
    let mut seen: crate::fast_hash::FastMap<(u64, usize), Vec<usize>> = Default::default();
    for (layer, key) in keys.iter().enumerate() {
        let own =
            sparse && (!skins[layer].is_empty() || params.infill_pattern == InfillPattern::Gyroid);
        if own {
            first.push(layer);
            continue;
        }
        let parity = if alternates(params.path_mode) || sparse {
            layer % 2
        } else {
            0
        };
        let same = seen.entry((key.hash, parity)).or_default();
        match same.iter().find(|&&j| keys[j].rings == key.rings) {
            Some(&j) => first.push(j),
            None => {
                same.push(layer);
                first.push(layer);
            }
        }
    }
    first
}

/// Puts a section's regions, and each region's holes, in an order of their own (by their
/// least vertex, x then y: a corner, never a point where the plane crosses a face's diagonal),
/// not the order the section found its loops in, which changes from layer to layer: a prism's
/// layers then have one [`SectionKey`] and share their fill. Only for contour fills, whose
/// paths come in this order (the other modes keep the order they have always had).
fn canonical_order(regions: &mut Vec<Region>) {
    for r in regions.iter_mut() {
        sort_by_least_vertex(&mut r.holes, |h| h);
    }
    sort_by_least_vertex(regions, |r| &r.outer);
}

/// `items` sorted (stably) by the least vertex, x then y, of each one's `ring`, found once
/// per item.
fn sort_by_least_vertex<T>(items: &mut Vec<T>, ring: impl Fn(&T) -> &[Point2]) {
    let by = |a: &Point2, b: &Point2| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal);
    let mut keyed: Vec<(Point2, T)> = items
        .drain(..)
        .map(|t| {
            let least = ring(&t).iter().copied().min_by(by).unwrap_or([0.0; 2]);
            (least, t)
        })
        .collect();
    keyed.sort_by(|a, b| by(&a.0, &b.0));
    items.extend(keyed.into_iter().map(|(_, t)| t));
}

/// True when the fill of `mode` turns from layer to layer (every other layer's zig-zag runs
/// at 90° to the one before), so that only layers of the same parity may share a fill. Raster
/// lines keep one angle, and contour rings and their gap fill depend on the section alone.
fn alternates(mode: PathMode) -> bool {
    matches!(mode, PathMode::Zigzag | PathMode::ContourZigzag)
}

/// A layer's section as a polygon, to find layers cut through the same one: each ring without
/// the vertices that lie on the segment between their neighbours (where a plane cuts the
/// diagonal of a side face's two triangles, at a point that moves along the face's edge from
/// layer to layer), starting at its least point; the coordinates in steps of [`KEY_GRID`]
/// (an edge a rounding off square to the layers moves its crossing by 1e-14 mm a layer).
#[derive(Debug, PartialEq)]
struct SectionKey {
    /// Every ring of every region, outer first, in grid steps.
    rings: Vec<Vec<[u64; 2]>>,
    /// A hash of `rings`.
    hash: u64,
}

impl SectionKey {
    fn new(regions: &[Region]) -> SectionKey {
        use std::hash::{Hash, Hasher};
        let mut rings = vec![];
        for r in regions {
            for (k, ring) in std::iter::once(&r.outer).chain(&r.holes).enumerate() {
                let mut pts = without_straight_vertices(ring);
                let start = (0..pts.len())
                    .min_by(|&a, &b| {
                        pts[a]
                            .partial_cmp(&pts[b])
                            .unwrap_or(std::cmp::Ordering::Equal)
                    })
                    .unwrap_or(0);
                pts.rotate_left(start);
                // A region's first ring is its outer one: mark it, so that holes do not pair
                // with outer rings of other regions.
                let mut bits = vec![[k as u64, 0]];
                bits.extend(
                    pts.iter()
                        .map(|p| p.map(|x| (x / KEY_GRID).round() as i64 as u64)),
                );
                rings.push(bits);
            }
        }
        let mut h = crate::fast_hash::FastHasher::default();
        rings.hash(&mut h);
        SectionKey {
            hash: h.finish(),
            rings,
        }
    }
}

/// A closed ring without its vertices that lie between their neighbours on the segment joining
/// them (to within rounding: 1e-12 of the segment's length squared), each judged against the
/// neighbours left after the ones before it are dropped.
fn without_straight_vertices(ring: &[Point2]) -> Vec<Point2> {
    let mut out: Vec<Point2> = Vec::with_capacity(ring.len());
    let straight = |a: Point2, b: Point2, c: Point2| {
        let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
        let len2 = v[0] * v[0] + v[1] * v[1];
        let along = u[0] * v[0] + u[1] * v[1];
        (u[0] * v[1] - u[1] * v[0]).abs() <= COLLINEAR * len2 && along > 0.0 && along < len2
    };
    for &p in ring {
        while out.len() >= 2 && straight(out[out.len() - 2], out[out.len() - 1], p) {
            out.pop();
        }
        out.push(p);
    }
    // Round the closing corner: the last and first vertices against their neighbours.
    loop {
        let m = out.len();
        if m < 4 {
            break;
        }
        if straight(out[m - 2], out[m - 1], out[0]) {
            out.pop();
        } else if straight(out[m - 1], out[0], out[1]) {
            out.remove(0);
        } else {
            break;
        }
    }
    out
}

impl Two5dFill {
    /// These layers with support material in `columns` (the feature's
    /// [`crate::support::planar_support`], one entry a layer): sparse and interface lines
    /// ([`crate::support_material`]) added to each layer, laid before the part's paths. The
    /// layers below the reference plane ([`SupportRegions::below`], a lifted solid's) go
    /// before the first, support alone.
    pub fn with_support(mut self, columns: &SupportRegions, params: &LayerParams) -> Two5dFill {
        let mut paths =
            crate::support_material::fill_columns(columns, params, self.bead.width).into_iter();
        let under: Vec<Vec<FillPath>> = paths.by_ref().take(columns.below.len()).collect();
        for (layer, support) in self.filled.iter_mut().zip(paths) {
            layer.extend(support);
        }
        let u = under.len();
        if u > 0 {
            let below = &columns.below[..u];
            let mut tops = layer_tops(-below.iter().sum::<f64>(), below);
            tops.append(&mut self.tops);
            self.tops = tops;
            let mut filled = under;
            filled.append(&mut self.filled);
            self.filled = filled;
            let mut sparse = vec![(0.0, 0.0); u];
            sparse.append(&mut self.sparse);
            self.sparse = sparse;
        }
        self
    }

    /// Orders each layer's paths from where the nozzle is (starting at `entry`) and joins them
    /// by travel.
    pub fn lay(self, entry: Option<P3>) -> FeaturePlan {
        let Two5dFill {
            id,
            plane,
            bead,
            tops,
            filled,
            sparse,
            mut fig,
        } = self;
        let mut cursor = entry;
        let axis = [plane.normal.x, plane.normal.y, plane.normal.z];
        let mut layers = vec![];
        let mut points: Vec<PathPoint> = vec![];
        for (layer, (paths, &(_, z, dl))) in filled.into_iter().zip(&tops).enumerate() {
            let start = cursor.map(|c| plane.to_2d(&c)).unwrap_or([0.0, 0.0]);
            // Support material first, then the part's paths from where it ended.
            let (support, part): (Vec<FillPath>, Vec<FillPath>) =
                paths.into_iter().partition(|p| p.role.is_support());
            let mut paths = order_greedy(support, start, |p| &p.points, FillPath::reverse);
            let start = paths
                .last()
                .and_then(|p| p.points.last().copied())
                .unwrap_or(start);
            paths.extend(order_greedy(part, start, |p| &p.points, FillPath::reverse));
            if paths.is_empty() {
                continue;
            }
            let mut layer_paths = Vec::with_capacity(paths.len());
            for path in paths {
                let pts: Vec<P3> = path.points.iter().map(|q| plane.to_3d(*q, z)).collect();
                let Some(first) = pts.first() else { continue };
                // Travel to the start of the path.
                if let Some(c) = cursor {
                    fig.travel_length += (first - c).norm();
                }
                let start = points.len();
                points.push(PathPoint {
                    feature: id as u32,
                    layer: layer as u32,
                    kind: MoveKind::Travel,
                    p: [first.x, first.y, first.z],
                    axis,
                    e: 0.0,
                    thickness: dl as f32,
                    width: path.widths[0] as f32,
                    role: path.role,
                });
                for (i, w) in pts.windows(2).enumerate() {
                    let l = (w[1] - w[0]).norm();
                    // Eq. 1 with the bead's width along the segment.
                    let width = 0.5 * (path.widths[i] + path.widths[i + 1]);
                    let e = bead.filament_length(width, dl, l);
                    fig.print_length += l;
                    match path.role.is_support() {
                        true => fig.support_filament += e,
                        false => fig.filament += e,
                    }
                    points.push(PathPoint {
                        feature: id as u32,
                        layer: layer as u32,
                        kind: MoveKind::Print,
                        p: [w[1].x, w[1].y, w[1].z],
                        axis,
                        e,
                        thickness: dl as f32,
                        width: path.widths[i + 1] as f32,
                        role: path.role,
                    });
                }
                cursor = pts.last().copied();
                layer_paths.push(LayerPath {
                    travel: start..start + 1,
                    print: start + 1..points.len(),
                });
            }
            let (area, laid) = sparse.get(layer).copied().unwrap_or_default();
            fig.sparse_volume += area * dl;
            fig.sparse_laid += laid * dl;
            layers.push(Layer {
                index: layer,
                thickness: dl,
                surface: LayerSurface::Plane {
                    normal: axis,
                    height: z,
                },
                paths: layer_paths,
            });
        }
        let printed: Vec<f64> = layers.iter().map(|l: &Layer| l.thickness).collect();
        fig.finish(id, points.len(), &printed);
        FeaturePlan {
            feature: id,
            points,
            layers,
            figures: fig,
            freeform: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every path mode.
    const EVERY_MODE: [PathMode; 4] = [
        PathMode::Raster,
        PathMode::Zigzag,
        PathMode::Contour,
        PathMode::ContourZigzag,
    ];

    /// A 20 × 30 mm rectangle as a section cuts it, with a point where the plane crosses each
    /// side face's diagonal at `t` of the way along.
    fn cut_box(t: f64) -> Vec<Region> {
        let ring = vec![
            [0.0, -30.0 * t],
            [0.0, -30.0],
            [20.0 * (1.0 - t), -30.0],
            [20.0, -30.0],
            [20.0, -30.0 * (1.0 - t)],
            [20.0, 0.0],
            [20.0 * t, 0.0],
            [0.0, 0.0],
        ];
        regions_from_loops(&[ring])
    }

    #[test]
    fn sections_of_one_polygon_share_a_key_and_others_do_not() {
        let (a, b) = (
            SectionKey::new(&cut_box(0.01)),
            SectionKey::new(&cut_box(0.37)),
        );
        assert_eq!(a, b);
        assert_eq!(
            a.rings[0].len(),
            1 + 4,
            "the outer ring's mark and its four corners"
        );
        // Wider by a micrometre: another section.
        let mut wider = cut_box(0.01);
        for p in &mut wider[0].outer {
            if p[0] == 20.0 {
                p[0] += 1e-3;
            }
        }
        assert_ne!(SectionKey::new(&wider), a);
        // A hole makes another section too.
        let mut holed = cut_box(0.01);
        holed[0]
            .holes
            .push(vec![[5.0, -5.0], [5.0, -10.0], [10.0, -10.0], [10.0, -5.0]]);
        assert_ne!(SectionKey::new(&holed), a);
    }

    /// The modes whose layers of either parity share a fill ([`alternates`] false) fill a
    /// section the same on even and odd layers, rings, their gap fill and beads as wide as a
    /// thin web included: a plate with a round hole and a slot that leaves a web 0.7 mm wide
    /// (under two beads), and the zig-zag modes, which turn, do not.
    #[test]
    fn only_turning_fills_depend_on_the_layer_parity() {
        let hole: Vec<Point2> = (0..96)
            .map(|i| {
                let t = -2.0 * std::f64::consts::PI * i as f64 / 96.0;
                [6.0 + 3.0 * t.cos(), 6.0 + 3.0 * t.sin()]
            })
            .collect();
        let slot = vec![[12.0, 10.0], [12.0, 2.0], [19.3, 2.0], [19.3, 10.0]];
        let outer = vec![[0.0, 0.0], [20.0, 0.0], [20.0, 12.0], [0.0, 12.0]];
        let regions = regions_from_loops(&[outer, hole, slot]);
        assert_eq!(regions.len(), 1);
        assert_eq!(regions[0].holes.len(), 2);
        for mode in EVERY_MODE {
            let params = LayerParams {
                path_mode: mode,
                ..LayerParams::default()
            };
            let fill = |layer| fill_regions(regions.clone(), &params, layer, 0.45, 0.45);
            let (even, odd) = (fill(2), fill(3));
            assert!(!even.is_empty());
            assert_eq!(even == odd, !alternates(mode), "{mode:?}");
        }
    }

    /// A section whose loops come in another order (as a mesh's section finds them, from
    /// layer to layer; holes of one area keep it when grouped into regions, largest first)
    /// is, for contour fills, put in the same order: one key, and the layers
    /// get the same paths, in the same order.
    #[test]
    fn contour_sections_in_another_loop_order_share_their_fill() {
        let square = |x: f64, y: f64, s: f64| vec![[x, y], [x, y + s], [x + s, y + s], [x + s, y]];
        let outer = vec![[0.0, 0.0], [30.0, 0.0], [30.0, 12.0], [0.0, 12.0]];
        let loops = [
            outer,
            square(3.0, 3.0, 4.0),
            square(12.0, 4.0, 4.0),
            square(20.0, 2.0, 4.0),
        ];
        let mut other = loops.clone();
        other.swap(1, 3);
        let (a, b) = (regions_from_loops(&loops), regions_from_loops(&other));
        assert_ne!(SectionKey::new(&a), SectionKey::new(&b));
        let (mut ca, mut cb) = (a.clone(), b.clone());
        canonical_order(&mut ca);
        canonical_order(&mut cb);
        assert_eq!(SectionKey::new(&ca), SectionKey::new(&cb));
        let params = LayerParams {
            path_mode: PathMode::Contour,
            ..LayerParams::default()
        };
        let (filled, _) = fill_sections(vec![a, b.clone(), b], &[0.0; 3], &params, 0.45, 0.45);
        assert!(!filled[1].is_empty());
        assert_eq!(filled[0], filled[1]);
    }

    /// Layers taking an earlier layer's fill get what filling their own section gives, for
    /// every path mode: the fill depends on the layer only through its parity.
    #[test]
    fn a_repeated_section_gets_the_fill_its_own_would_give() {
        for mode in EVERY_MODE {
            let params = LayerParams {
                path_mode: mode,
                ..LayerParams::default()
            };
            let (width, spacing) = (0.45, 0.4);
            let sections: Vec<Vec<Region>> =
                (0..6).map(|l| cut_box(0.05 + 0.1 * l as f64)).collect();
            let (shared, _) = fill_sections(sections.clone(), &[0.0; 6], &params, width, spacing);
            let n = sections.len();
            for (layer, regions) in sections.into_iter().enumerate() {
                let own = solid_on_skins(
                    fill_regions(regions, &params, layer, width, spacing),
                    layer,
                    n,
                );
                assert!(!own.is_empty());
                assert_eq!(shared[layer], own, "{mode:?}, layer {layer}");
            }
        }
    }
}
