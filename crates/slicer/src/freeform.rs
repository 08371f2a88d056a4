//! Freeform features: offset reference-surface layers, spatial slicing, paths on curved layers
//! (feature-based AM paper, "Feature-based five-axis path planning methodology": offset the
//! reference surface, spatially slice the freeform layers, generate the toolpaths of each
//! layer).
//!
//! - **Chart.** Every computation runs in a 2-D chart `q = (s, t)` of the reference surface S
//!   and the signed distance `d` from it along its unit normal N (pointing into the feature):
//!   the point `(q, d)` is `S(q) + d·N(q)`. The chart is the surface's own `(u, v)` scaled to
//!   millimetres at the feature's centre ([`ChartKind::Native`]), or, where `(u, v)` collapses
//!   under the feature (a boss on a sphere's pole), the orthogonal projection onto the tangent
//!   plane at the feature's centre ([`ChartKind::Ortho`]).
//! - **Offset surfaces.** Layer k lies on `S_k(q) = S(q) + z_k·N(q)`, `z_k` the sum of the
//!   first k layer thicknesses (`k·h` for uniform layers): exact for every surface, since it is
//!   evaluated from the exact S and N point by point. Deterioration (paper, Fig. 9: where the
//!   reference is concave with a radius of curvature under `z_k` the offset folds over itself)
//!   is detected from the principal curvatures of S under the feature: the plan stops with
//!   [`FeatureError::OffsetFolds`], naming the feature and the first layer that would fold.
//! - **Spatial slicing.** The feature's exact-surface mesh is mapped into `(s, t, d)`; its
//!   section by the plane `d = z_k − h_k/2` (the middle of layer k) gives the layer's region
//!   in the chart, boundaries sampled within the mesh tolerance.
//! - **Paths.** [`crate::geodesic`] triangulates each region with a lattice equilateral on
//!   `S_k` (the chart's metric there), lifts it onto `S_k`, and fills it by the feature's
//!   `path_mode` with iso-lines of geodesic distances (spacing measured on the surface):
//!   rings are iso-lines of the distance to the boundary (exact three spacings deep), lines
//!   iso-lines of the signed distance to a seed curve. Strips too narrow for a bead (between
//!   the rings, or a whole sliver of a layer) get a variable-width gap fill, and sharp convex
//!   corners a spur into the tip (`corner_spurs`). Each path is lifted onto `S_k` with points
//!   inserted until every chord is within the feature's `tolerance` of the surface; the tool
//!   axis is N (or `fixed_tool_axis`); extrusion follows Isa & Lazoglu 2019, Eq. 1 with the
//!   layer's thickness and each point's bead width.

use crate::chart::{choose_chart, mapped_mesh, refined, translate_chart, MAX_MAPPED_EDGE};
use crate::error::FeatureError;
use crate::feature_mesh::{grown_mesh, slicing_tolerance, Allowance};
use crate::feature_plan::{FeaturePlan, Layer, LayerPath, LayerSurface};
pub use crate::figures::FreeformFigures;
use crate::figures::{FeatureFigures, LayerChart, Layering};
use crate::fold::{check_folds, fold_check};
use crate::geom2d::{dist2, segment_foot, Point2, Region};
use crate::lift::{lift, Lifted};
use crate::params::{LayerParams, LayerStrategy, PathMode, WallOrientation};
use crate::region_fill::order_fill_paths;
use crate::sst::{Sides, WALL_REACH};
use crate::support::{reach, sliver_area};
use crate::tolerance::{FLAT_CURVATURE, MICROMETRE, SHORT_VECTOR};
use crate::toolpath::{Bead, MoveKind, PathPoint, Role};
use crate::transition::{band, build_top_field, levels, top_faces, Levels, TopField};

/// The length of bead point `i` of `pts` lays: half of each segment it ends.
fn bead_share(pts: &[Lifted], i: usize) -> f64 {
    let seg = |a: usize, b: usize| match (pts.get(a), pts.get(b)) {
        (Some(p), Some(q)) => (q.p - p.p).norm(),
        _ => 0.0,
    };
    0.5 * (if i > 0 { seg(i - 1, i) } else { 0.0 } + seg(i, i + 1))
}

/// Splits chart paths where `keep` turns false, ending each piece on the boundary (found by
/// bisection along the segment that crosses it).
fn clip_paths(paths: Vec<FillPath>, keep: impl Fn(Point2) -> bool) -> Vec<FillPath> {
    let cross = |a: Point2, b: Point2| {
        // a kept, b not: the last kept point of a→b.
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..30 {
            let m = 0.5 * (lo + hi);
            if keep([a[0] + (b[0] - a[0]) * m, a[1] + (b[1] - a[1]) * m]) {
                lo = m;
            } else {
                hi = m;
            }
        }
        [a[0] + (b[0] - a[0]) * lo, a[1] + (b[1] - a[1]) * lo]
    };
    let mut out = vec![];
    for p in paths {
        let inside: Vec<bool> = p.points.iter().map(|q| keep(*q)).collect();
        if inside.iter().all(|x| *x) {
            out.push(p);
            continue;
        }
        let mut cur = FillPath {
            points: vec![],
            widths: vec![],
            role: p.role,
        };
        for (i, &kept) in inside.iter().enumerate() {
            if kept {
                if cur.points.is_empty() && i > 0 {
                    cur.points.push(cross(p.points[i], p.points[i - 1]));
                    cur.widths.push(p.widths[i]);
                }
                cur.points.push(p.points[i]);
                cur.widths.push(p.widths[i]);
            } else if !cur.points.is_empty() {
                cur.points.push(cross(p.points[i - 1], p.points[i]));
                cur.widths.push(p.widths[i - 1]);
                out.push(std::mem::replace(
                    &mut cur,
                    FillPath {
                        points: vec![],
                        widths: vec![],
                        role: p.role,
                    },
                ));
            }
        }
        if cur.points.len() >= 2 {
            out.push(cur);
        }
    }
    out.retain(|p| p.points.len() >= 2);
    out
}
use brep::math::{P3, V3};
use brep::mesh::Mesh;
use brep::section::Plane;
use brep::surface::Surface;
use features::{Feature, FeatureKind, FeatureTree};
use rayon::prelude::*;

mod layers;
use layers::{fill_stack, LayerFill};

pub use crate::chart::{Chart, ChartKind};
pub use crate::region_fill::{fill_flat_region, Boundary, FillPath};

/// How far (chart units) chart point `q` lies outside `regions`: 0 inside one, the distance
/// to the nearest boundary otherwise (infinite with no region).
fn outside_regions(regions: &[Region], q: Point2) -> f64 {
    if regions.iter().any(|r| crate::geom2d::region_contains(r, q)) {
        return 0.0;
    }
    let mut d2 = f64::INFINITY;
    for r in regions {
        for ring in std::iter::once(&r.outer).chain(r.holes.iter()) {
            let n = ring.len();
            for i in 0..n {
                let x = segment_foot(q, ring[i], ring[(i + 1) % n]).1;
                d2 = d2.min(dist2(x, q));
            }
        }
    }
    d2.sqrt()
}

/// Plans one freeform feature on offsets of its reference surface; its first travel starts at
/// `entry` (where the nozzle is, if anywhere): [`fill_freeform`], then [`FreeformFill::lay`].
pub fn plan_freeform(
    tree: &FeatureTree,
    f: &Feature,
    params: &LayerParams,
    bead: Bead,
    entry: Option<P3>,
) -> Result<FeaturePlan, FeatureError> {
    Ok(fill_freeform(tree, f, params, bead)?.lay(entry))
}

/// A freeform feature's layers filled in its chart, before they are ordered from where the
/// nozzle is, lifted onto their offset surfaces and joined by travel: all of a feature's
/// planning that does not depend on where the feature before it ended, so features can be
/// filled in parallel and laid one after the other.
pub struct FreeformFill<'a> {
    id: usize,
    chart: Chart<'a>,
    params: LayerParams,
    bead: Bead,
    fixed: Option<V3>,
    heights: Vec<f64>,
    /// Each layer's middle and top level: offsets, or morph levels with transition layers.
    tops: Vec<(f64, f64)>,
    /// Transition layers: the top's distance field, the number N of transition layers and
    /// the number of offset layers under them.
    blend: Option<(TopField, usize, usize)>,
    /// Layers `..offset_layers` are offsets of the reference; the rest transition layers.
    offset_layers: usize,
    /// `wall_orientation = "sst"`: the side faces, for Eq. 3's axes on wall beads.
    sides: Option<Sides>,
    /// Each layer's regions and fill paths in the chart.
    filled: Vec<LayerFill>,
    fig: FeatureFigures,
    ff: FreeformFigures,
}

/// Fills every layer of a freeform feature in its chart (the offsets of its reference
/// surface, sectioned and filled in parallel): see the module documentation.
pub fn fill_freeform<'a>(
    tree: &'a FeatureTree,
    f: &Feature,
    params: &LayerParams,
    bead: Bead,
) -> Result<FreeformFill<'a>, FeatureError> {
    let id = f.id;
    let err = |msg: String| FeatureError::Freeform { id, msg };
    if f.kind != FeatureKind::Freeform {
        return Err(err("it is not freeform".into()));
    }
    params
        .validate()
        .map_err(|msg| FeatureError::Params { id, msg })?;
    let b = &tree.brep;
    let rf = f
        .reference
        .face
        .ok_or_else(|| err("it has no reference face".into()))?;
    let surf = b.face_surface(rf);
    // N into the feature: the host face's outward normal (the parent's outside).
    let sign = if b.face(rf).same_sense { 1.0 } else { -1.0 };
    let tol = slicing_tolerance(params);
    let (mesh, grown) = grown_mesh(tree, f, tol, Allowance::of(params))?;
    if mesh.positions.is_empty() {
        return Err(err("its mesh is empty".into()));
    }
    let below = crate::planar::below_plate(tree, &mesh.positions);
    let raw = mesh;
    let mesh = refined(&raw, MAX_MAPPED_EDGE);
    // Offset deterioration first: a concave reference under the feature folds its offsets
    // before they reach the feature's top, and the feature may not even have a chart then
    // (a rib standing across a trough maps onto both of its flanks).
    // Unless offset layers are asked for, a feature whose offsets fold is carried over the
    // valley by levels that are translates of its reference along one direction, which cannot
    // fold (issue 17, item 5: crate::chart::translate_chart); transition layers then morph
    // them into its top.
    let (chart, mapped, translated) = feature_chart(surf, sign, &mesh, tol, params, id)?;
    let top = mapped.positions.iter().map(|p| p.z).fold(0.0f64, f64::max);
    let mut heights = params.layer_heights(top);
    // Offset deterioration (paper, Fig. 9): the smallest concave radius under the feature
    // (none for translates).
    let concave_radius = concave_radius(&chart, &mapped, params, !translated);
    let spacing = params.spacing(bead.width);
    let mut fig = FeatureFigures {
        below_plate: below,
        grown,
        ..FeatureFigures::default()
    };
    let mut ff = FreeformFigures {
        chart: match chart.kind {
            _ if chart.along.is_some() => LayerChart::Translate,
            ChartKind::Native { .. } => LayerChart::Native,
            ChartKind::Ortho { .. } => LayerChart::Projection,
        },
        concave_radius,
        overhang_points: 0,
        overhang_layers: None,
        support: Default::default(),
        layers: Layering::Offset,
    };
    // The top faces, for transition layers and side-surface-tangent walls.
    let sst = params.wall_orientation == WallOrientation::Sst && params.fixed_tool_axis.is_none();
    let tops = if params.layer_strategy != LayerStrategy::Offset || sst {
        top_faces(&chart, &raw, &f.heal_faces, id)
    } else {
        vec![]
    };
    // Offset or transition layers (issue 17): see crate::transition.
    let blend = choose_blend(
        (&chart, b, &raw),
        (&tops, &mapped),
        params,
        bead.width,
        id,
        &mut fig.warnings,
    )?;
    // Offset layers first (all of them without transition layers), then the transition layers.
    let offset_layers = match &blend {
        Some((field, n, k)) => {
            // Nominal thicknesses for the fold check and the layers' figures (the thickest a
            // point gets); each point's is its own.
            let t = field.band_max() / *n as f64;
            let h0 = field.band_of().map_or(0.0, |b| b.1);
            heights = vec![h0; *k];
            heights.extend(std::iter::repeat_n(t, *n));
            ff.layers = Layering::Transition;
            *k
        }
        None => heights.len(),
    };
    let ff = ff;
    let sides = sst.then(|| Sides::new(&raw, &f.heal_faces, &tops, 1.0));
    let up = Plane::new(P3::origin(), V3::z());
    // Checked before any layer is planned: nothing is laid down for a feature that folds.
    check_folds(id, &heights, concave_radius)?;
    let fixed = params
        .fixed_tool_axis
        .map(|a| V3::new(a[0], a[1], a[2]).normalize());
    // Each layer's regions and fill depend on that layer alone: computed in parallel, then
    // ordered, lifted and joined by travel one layer after the other.
    let tops = layer_tops(&heights[..offset_layers], blend.as_ref().map(|b| b.1));
    // Transition layers are sliced at morph levels: each vertex's place between where they
    // start and the top over it.
    let blended = blend.as_ref().map(|(field, _, _)| {
        let mut m = mapped.clone();
        for p in &mut m.positions {
            let q = [p.x, p.y];
            let lower = field.lower(q);
            p.z = (p.z - lower) / (field.height(q) - lower).max(MICROMETRE);
        }
        (chart.blended(field), m, field)
    });
    let (filled, sparse) = fill_stack(
        (&chart, &mapped),
        blended.as_ref(),
        blend.as_ref(),
        (&tops, &heights, offset_layers),
        &up,
        params,
        (bead.width, spacing),
    );
    fig.sparse_volume = sparse.volume;
    fig.sparse_laid = sparse.laid;
    drop(blended);
    Ok(FreeformFill {
        id,
        chart,
        blend,
        offset_layers,
        sides,
        params: params.clone(),
        bead,
        fixed,
        heights,
        tops,
        filled,
        fig,
        ff,
    })
}

/// The feature's chart and its mesh mapped into it, and whether the chart is a translate:
/// offsets of the reference where they do not fold (or offset layers are asked for), else
/// translates of it; N turned round where the feature lies on the other side.
fn feature_chart<'a>(
    surf: &'a Surface,
    mut sign: f64,
    mesh: &Mesh,
    tol: f64,
    params: &LayerParams,
    id: usize,
) -> Result<(Chart<'a>, Mesh, bool), FeatureError> {
    let translate = match fold_check(surf, sign, mesh, tol, params, id) {
        Ok(()) => None,
        Err(e) if params.layer_strategy == LayerStrategy::Offset => return Err(e),
        Err(e) => Some(translate_chart(surf, sign, mesh, tol).ok_or(e)?),
    };
    let mut chart = match translate {
        Some(c) => c,
        None => choose_chart(surf, sign, id, mesh)?,
    };
    let mut mapped = mapped_mesh(&chart, mesh, id)?;
    // The feature lies on the side N points to: check, and turn N round if the face said
    // otherwise (a translate chart has checked it).
    let mean_d = mapped.positions.iter().map(|p| p.z).sum::<f64>() / mapped.positions.len() as f64;
    if mean_d < 0.0 && translate.is_none() {
        sign = -sign;
        chart = choose_chart(surf, sign, id, mesh)?;
        mapped = mapped_mesh(&chart, mesh, id)?;
    }
    Ok((chart, mapped, translate.is_some()))
}

/// Each layer's middle and top level: the offset layers' (thicknesses `offsets`) from 0, then
/// the `transition` layers' morph levels in (0, 1].
fn layer_tops(offsets: &[f64], transition: Option<usize>) -> Vec<(f64, f64)> {
    let mut tops = Vec::with_capacity(offsets.len() + transition.unwrap_or(0));
    let mut z = 0.0;
    for &dl in offsets {
        tops.push((z + 0.5 * dl, z + dl));
        z += dl;
    }
    if let Some(n) = transition {
        for k in 0..n {
            tops.push(((k as f64 + 0.5) / n as f64, (k + 1) as f64 / n as f64));
        }
    }
    tops
}

/// Offset deterioration (paper, Fig. 9): the smallest concave radius of the reference under
/// the feature, sampled at its mapped mesh's points; infinite for translates (`offsets` false)
/// or a reference that is nowhere concave.
fn concave_radius(chart: &Chart, mapped: &Mesh, params: &LayerParams, offsets: bool) -> f64 {
    let stride = (mapped.positions.len() / 300).max(1);
    let step = (0.5 * params.uniform_layer_height).max(MICROMETRE);
    let mut lambda = 0.0f64;
    if offsets {
        for p in mapped.positions.iter().step_by(stride) {
            if let Some(l) = chart.min_curvature([p.x, p.y], step) {
                lambda = lambda.min(l);
            }
        }
    }
    if lambda < -FLAT_CURVATURE {
        -1.0 / lambda
    } else {
        f64::INFINITY
    }
}

/// Offset or transition layers (issue 17, see crate::transition): the top's distance field,
/// the number of transition layers and the number of offset layers under them; `None` for
/// offset layers only (asked for, no top, or transition layers that would break the layer
/// height bounds, with a warning).
fn choose_blend(
    (chart, b, raw): (&Chart, &brep::Brep, &Mesh),
    (tops, mapped): (&[brep::topology::FaceId], &Mesh),
    params: &LayerParams,
    bead_width: f64,
    id: usize,
    warnings: &mut Vec<String>,
) -> Result<Option<(TopField, usize, usize)>, FeatureError> {
    let err = |msg: String| FeatureError::Freeform { id, msg };
    Ok(match params.layer_strategy {
        LayerStrategy::Offset => None,
        strategy => {
            let forced = strategy == LayerStrategy::Transition;
            match build_top_field(chart, b, raw, tops, mapped, id)? {
                None if forced => {
                    return Err(err(
                        "layer_strategy = \"transition\" needs a top, and no face of it faces the way it grows".into(),
                    ))
                }
                None => None,
                Some(field) => match levels(field.range, params) {
                    Levels::Offset => None,
                    Levels::Transition(n) => Some((field, n, 0)),
                    Levels::Infeasible(lo, hi) => {
                        let (a, _, b) = field.range;
                        // Offset layers first, a band of transition layers for the rest.
                        match band(field, params, bead_width) {
                            Some(banded) => Some(banded),
                            None => {
                                let why = format!(
                                    "its top lies {a:.3} to {b:.3} mm from its base, so transition layers would need at least {lo} layers for max_layer_height = {} and at most {hi} for min_layer_height = {}, and no band of transition layers over offset layers keeps those bounds either",
                                    params.max_layer_height, params.min_layer_height
                                );
                                if forced {
                                    return Err(err(why));
                                }
                                warnings.push(format!(
                                    "feature {id}: offset layers, not transition layers: {why}"
                                ));
                                None
                            }
                        }
                    }
                },
            }
        }
    })
}

impl FreeformFill<'_> {
    /// Orders each layer's paths from where the nozzle is (starting at `entry`), lifts them
    /// onto the layer's offset surface (the paths of a layer in parallel) and joins them by
    /// travel over the layer above.
    pub fn lay(self, entry: Option<P3>) -> FeaturePlan {
        let FreeformFill {
            id,
            chart,
            blend,
            offset_layers,
            sides,
            params,
            bead,
            fixed,
            heights,
            tops,
            filled,
            mut fig,
            mut ff,
        } = self;
        let params = &params;
        // Transition layers: the chart's level is the morph level, a layer 1/N of it, and a
        // point's thickness (h_T(q) − D(q))/N (crate::transition).
        let base_chart = chart;
        let blended_chart = blend.as_ref().map(|(field, _, _)| chart.blended(field));
        let levels_of = |layer: usize| {
            blend
                .as_ref()
                .filter(|_| layer >= offset_layers)
                .map(|(field, n, _)| (field, *n as f64))
        };
        // Thinnest, summed and thickest thickness over the print points.
        let mut spread = (f64::INFINITY, 0.0f64, 0.0f64, 0usize);
        let mut cursor = entry;
        let cursor = &mut cursor;
        let mut prev_regions: Vec<Region> = vec![];
        // A layer below had material (a feature on a parent grown by `base_allowance` has none
        // under that height: its first layer with some rests on the grown face, as layer 0).
        let mut laid_any = false;
        // A band of transition layers over offset layers: each point of its first layer rests
        // on the last offset layer laid there (the offset layers stop where the band takes
        // over, point by point), so it is held by any of them, not by the last one alone.
        let banded = blend.is_some() && offset_layers > 0;
        let mut offset_regions: Vec<Region> = vec![];
        let mut layers = vec![];
        let mut points: Vec<PathPoint> = vec![];
        // Print points whose fixed axis points against the layer normal, and the worst angle.
        let mut against = (0usize, 0.0f64);
        for (layer, ((&dl, &(_, z)), (regions, paths))) in
            heights.iter().zip(&tops).zip(filled).enumerate()
        {
            let levels = levels_of(layer);
            let chart = match (&blended_chart, levels) {
                (Some(c), Some(_)) => *c,
                _ => base_chart,
            };
            let thick = |q: Point2, dl: f64| match levels {
                Some((field, n)) => field.layer_thickness(q, n),
                None => dl,
            };
            if banded && layer < offset_layers {
                offset_regions.extend(regions.iter().cloned());
            }
            let held_by = (banded && layer == offset_layers).then_some(&offset_regions);
            let on_reference = layer == 0 || (params.base_allowance > 0.0 && !laid_any);
            laid_any |= !regions.is_empty();
            let below = std::mem::replace(&mut prev_regions, regions);
            let start = cursor
                .and_then(|c| chart.inverse(&c).map(|(q, _)| q))
                .unwrap_or([0.0, 0.0]);
            let paths = if params.path_mode == PathMode::Raster {
                paths
            } else {
                order_fill_paths(paths, start)
            };
            // Each path lifted onto the layer and its unsupported points counted, in parallel.
            let support = Support {
                on_reference,
                below: below.as_slice(),
                held_by: held_by.map(|r| r.as_slice()),
                reach: reach(dl, params.overhang_angle_deg),
            };
            let lifted = lift_paths(
                &chart,
                &paths,
                z,
                params,
                (&sides, bead.width),
                |q| thick(q, dl),
                support,
            );
            note_support(&mut ff, layer, &lifted, bead.width);
            let mut layer_paths: Vec<LayerPath> = vec![];
            for (pts, unheld, _) in lifted {
                if pts.len() < 2 {
                    continue;
                }
                // A fixed axis pointing against the layer's growth lays beads from below.
                count_against(fixed, &pts, &mut against);
                note_overhang(&mut ff, unheld, layer);
                let start = points.len();
                let axis = |n: V3| {
                    let a = fixed.unwrap_or(n);
                    [a.x, a.y, a.z]
                };
                // Travel: up one layer over the start of the path, along the layer above
                // (clear of this layer's beads on a curved surface), then down.
                let first = pts[0];
                // One layer up, in the chart's level.
                let step = levels.map_or(dl, |(_, n)| 1.0 / n);
                let lift_to = z + step;
                let mut travel = travel_over(&chart, *cursor, first.q, lift_to, step);
                travel.push((first.p, first.n));
                let head = (thick(first.q, dl), bead.width, pts[0].role);
                push_travel(
                    &mut points,
                    travel,
                    (id, layer, head),
                    &axis,
                    cursor,
                    &mut fig,
                );
                let print_start = points.len();
                let leans = levels.is_some() || base_chart.along.is_some();
                let seg_thick = |w: &[Lifted]| 0.5 * (thick(w[0].q, dl) + thick(w[1].q, dl));
                let chart = leans.then_some(&base_chart);
                let at = (id, layer, bead);
                push_prints(
                    &mut points,
                    &pts,
                    at,
                    (seg_thick, chart, &axis),
                    &mut fig,
                    &mut spread,
                );
                *cursor = pts.last().map(|x| x.p);
                layer_paths.push(LayerPath {
                    travel: start..print_start,
                    print: print_start..points.len(),
                });
            }
            layers.extend(layer_of(layer, (dl, z), levels.is_some(), layer_paths));
        }
        finished(
            id,
            (points, layers),
            (fig, ff),
            blend.is_some(),
            spread,
            against,
        )
    }
}

/// Feature `id`'s plan from its laid `points` and `layers`: its figures finished (the thickness
/// `spread` of its points where the layers are `blended`), with the warnings of `against` (fixed
/// axes pointing against the layers' growth).
fn finished(
    id: usize,
    (points, layers): (Vec<PathPoint>, Vec<Layer>),
    (mut fig, ff): (FeatureFigures, FreeformFigures),
    blended: bool,
    spread: (f64, f64, f64, usize),
    against: (usize, f64),
) -> FeaturePlan {
    let printed: Vec<f64> = layers.iter().map(|l: &Layer| l.thickness).collect();
    fig.finish(id, points.len(), &printed);
    if blended && spread.3 > 0 {
        fig.thickness = (spread.0, spread.1 / spread.3 as f64, spread.2);
    }
    lay_warnings(&mut fig, id, against, &ff);
    FeaturePlan {
        feature: id,
        points,
        layers,
        figures: fig,
        freeform: Some(ff),
    }
}

/// The layer `index` of thickness `dl` at chart level `z` (a morph level where `blended`, else
/// an offset) with its paths; none when it has no path.
fn layer_of(
    index: usize,
    (dl, z): (f64, f64),
    blended: bool,
    paths: Vec<LayerPath>,
) -> Option<Layer> {
    (!paths.is_empty()).then_some(Layer {
        index,
        thickness: dl,
        surface: if blended {
            LayerSurface::Blend { level: z }
        } else {
            LayerSurface::Offset { offset: z }
        },
        paths,
    })
}

/// A layer's unsupported area, the sum over its lifted paths, added to `ff`'s support where it
/// is more than a sliver ([`sliver_area`]).
fn note_support(
    ff: &mut FreeformFigures,
    layer: usize,
    lifted: &[(Vec<Lifted>, usize, f64)],
    bead_width: f64,
) {
    let area: f64 = lifted.iter().map(|l| l.2).sum();
    if area >= sliver_area(bead_width) {
        ff.support.add(layer + 1, area);
    }
}

/// Each path lifted onto the layer at `z` (wall beads given the side-surface-tangent axis
/// where `sides` are), and its points unsupported: off the reference face under the first
/// layer, else off the regions `below`; in parallel.
fn lift_paths(
    chart: &Chart,
    paths: &[FillPath],
    z: f64,
    params: &LayerParams,
    (sides, bead_width): (&Option<Sides>, f64),
    thick: impl Fn(Point2) -> f64 + Sync,
    support: Support,
) -> Vec<(Vec<Lifted>, usize, f64)> {
    paths
        .par_iter()
        .map(|path| {
            let mut pts = lift(chart, path, z, params.tolerance);
            // Wall beads: the side-surface-tangent axis (Eq. 3).
            if let Some(s) = sides {
                crate::sst::apply(&mut pts, s, &thick, WALL_REACH * bead_width);
            }
            let (unheld, unsupported) = support.of(chart, z, &pts, bead_width);
            (pts, unheld, unsupported)
        })
        .collect()
}

/// What holds up a curved layer's beads: the layer below (or, under the first layer, the
/// reference face), and, for the first transition layer over offset layers, any offset layer
/// under it.
#[derive(Clone, Copy)]
struct Support<'a> {
    /// The layer rests on the reference face (the first layer, or the first with material over
    /// a parent's grown face).
    on_reference: bool,
    /// The regions of the layer below.
    below: &'a [Region],
    /// The offset layers' regions under the first transition layer, if this is it.
    held_by: Option<&'a [Region]>,
    /// How far a bead may reach past the layer below, mm (`h·tan(overhang_angle_deg)`).
    reach: f64,
}

impl Support<'_> {
    /// Of the lifted path `pts`: its points more than half a bead off what is below
    /// (`overhang_points`), and the bead (length × width, mm²) of those more than the reach
    /// off it, unsupported area ([`crate::support`]).
    fn of(&self, chart: &Chart, z: f64, pts: &[Lifted], bead_width: f64) -> (usize, f64) {
        let mut unheld = 0;
        let mut unsupported = 0.0;
        for (i, x) in pts.iter().enumerate() {
            let (off, limit) = if self.on_reference {
                let off = if chart.on_face(x.q) {
                    0.0
                } else {
                    f64::INFINITY
                };
                (off, 0.0)
            } else {
                let s = chart.stretch(x.q, z);
                (outside_regions(self.below, x.q) * s, self.reach)
            };
            if off > 0.5 * bead_width {
                unheld += 1;
            }
            let off = match self.held_by {
                Some(r) if off > limit => outside_regions(r, x.q) * chart.stretch(x.q, z),
                _ => off,
            };
            if off > limit {
                unsupported += bead_share(pts, i) * x.w;
            }
        }
        (unheld, unsupported)
    }
}

/// Travel from `cursor` to over `q`: up one layer (`step`, at least to `lift_to`) and along
/// the layer above, clear of this layer's beads on a curved surface.
fn travel_over(
    chart: &Chart,
    cursor: Option<P3>,
    q: Point2,
    lift_to: f64,
    step: f64,
) -> Vec<(P3, V3)> {
    let mut travel: Vec<(P3, V3)> = vec![];
    if let Some(c) = cursor {
        if let Some((qc, dc)) = chart.inverse(&c) {
            let hz = lift_to.max(dc + step);
            let span = dist2(q, qc).sqrt();
            let n = (span / 2.0).ceil().clamp(1.0, 1000.0) as usize;
            for i in 0..=n {
                let t = i as f64 / n as f64;
                let q = [qc[0] + (q[0] - qc[0]) * t, qc[1] + (q[1] - qc[1]) * t];
                if let Some(x) = chart.at(q, hz) {
                    travel.push(x);
                }
            }
        }
    }
    travel
}

/// A segment `w` of a transition layer (or of a translate of the reference), which leans on the
/// direction its levels grow along (N, or a translate chart's `a`): the bead is as thick as
/// the layers lie apart across it, t_N·(n_L·N), and as long as the segment runs along it (not
/// up its steps over the offset layers' staircase, which the layer under it climbs too). The
/// thickness `t` so scaled, and that length.
fn leaning(chart: &Chart, w: &[Lifted], mut t: f64) -> (f64, f64) {
    let nl = (w[0].ln + w[1].ln)
        .try_normalize(SHORT_VECTOR)
        .unwrap_or(w[1].ln);
    if let Some(g) = chart.growth(w[1].q) {
        t *= nl.dot(&g).abs();
    }
    let d = w[1].p - w[0].p;
    let run = (d - nl * d.dot(&nl)).norm();
    (t, run)
}

/// The warnings of a laid feature: a fixed axis pointing against the layers' growth (`against`:
/// print points and the worst angle), and print points overhanging the layer below.
fn lay_warnings(fig: &mut FeatureFigures, id: usize, against: (usize, f64), ff: &FreeformFigures) {
    if against.0 > 0 {
        fig.warnings.push(format!(
            "feature {id}: its fixed_tool_axis points against the layers' growth (more than 90 degrees from their normal, up to {:.1}) at {} print point(s): the nozzle would lay those beads from below",
            against.1, against.0
        ));
    }
    if let Some((a, b)) = ff.overhang_layers {
        fig.warnings.push(format!(
            "feature {id}: {} print point(s) in layers {a}..{b} overhang the layer below (nothing under them on the offsets of its reference surface)",
            ff.overhang_points
        ));
    }
}

/// Counts the print points of `pts` whose fixed axis points against the layer's growth (lays
/// beads from below), and the worst angle, into `against`.
fn count_against(fixed: Option<V3>, pts: &[Lifted], against: &mut (usize, f64)) {
    if let Some(a) = fixed {
        for x in &pts[1..] {
            let c = a.dot(&x.n).clamp(-1.0, 1.0);
            if c < 0.0 {
                against.0 += 1;
                against.1 = against.1.max(c.acos().to_degrees());
            }
        }
    }
}

/// Counts `unheld` overhanging print points of layer `layer` into the figures.
fn note_overhang(ff: &mut FreeformFigures, unheld: usize, layer: usize) {
    if unheld > 0 {
        ff.overhang_points += unheld;
        let l = layer + 1;
        ff.overhang_layers = Some(match ff.overhang_layers {
            Some((a, b)) => (a.min(l), b.max(l)),
            None => (l, l),
        });
    }
}

/// The print points of the lifted path `pts` (feature, layer, bead: `at`), each segment's
/// filament by Eq. 1 with its thickness (`thick`; scaled by [`leaning`] on `leaning_on`'s
/// levels) and the axis `axis` makes of its normal; lengths, filament and thickness spread
/// added to the figures.
fn push_prints(
    points: &mut Vec<PathPoint>,
    pts: &[Lifted],
    (id, layer, bead): (usize, usize, Bead),
    (thick, leaning_on, axis): (
        impl Fn(&[Lifted]) -> f64,
        Option<&Chart>,
        &dyn Fn(V3) -> [f64; 3],
    ),
    fig: &mut FeatureFigures,
    spread: &mut (f64, f64, f64, usize),
) {
    for w in pts.windows(2) {
        let l = (w[1].p - w[0].p).norm();
        let width = 0.5 * (w[0].w + w[1].w);
        // Eq. 1 with the segment's thickness (its ends' mean on a transition layer).
        let t = thick(w);
        let (t, run) = match leaning_on {
            Some(chart) => leaning(chart, w, t),
            None => (t, l),
        };
        let e = bead.filament_length(width, t, run);
        *spread = (spread.0.min(t), spread.1 + t, spread.2.max(t), spread.3 + 1);
        fig.print_length += l;
        fig.filament += e;
        points.push(PathPoint {
            feature: id as u32,
            layer: layer as u32,
            kind: MoveKind::Print,
            p: [w[1].p.x, w[1].p.y, w[1].p.z],
            axis: axis(w[1].n),
            e,
            thickness: t as f32,
            width: width as f32,
            role: w[1].role,
        });
    }
}

/// The travel points `travel` (feature, layer, and the bead's thickness, width and role:
/// `at`), each from the cursor, which follows them; their length added to the figures.
fn push_travel(
    points: &mut Vec<PathPoint>,
    travel: Vec<(P3, V3)>,
    (id, layer, (thickness, width, role)): (usize, usize, (f64, f64, Role)),
    axis: &dyn Fn(V3) -> [f64; 3],
    cursor: &mut Option<P3>,
    fig: &mut FeatureFigures,
) {
    for (p, n) in travel {
        if let Some(c) = *cursor {
            fig.travel_length += (p - c).norm();
        }
        points.push(PathPoint {
            feature: id as u32,
            layer: layer as u32,
            kind: MoveKind::Travel,
            p: [p.x, p.y, p.z],
            axis: axis(n),
            e: 0.0,
            thickness: thickness as f32,
            width: width as f32,
            role,
        });
        *cursor = Some(p);
    }
}
