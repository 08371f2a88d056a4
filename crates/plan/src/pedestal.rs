//! The pedestal (issue 31): where the head meets the table (a feature growing sideways low over
//! it puts the head's body under the table's surface, and no tilt inside the orientation cone
//! clears it), the part stands on a printed prism of its build-plate face's outline, printed
//! first, of the least whole number of layers that leaves no move hitting the table.
//!
//! The part keeps its coordinates: the pedestal is laid *under* the build plate, from
//! `plate − n·h` up to the plate. The posts put the lowest bead on the table, so the table
//! lies `n·h` lower under the part: the same as lifting the part by `n·h` along the plate's
//! normal, with `plan.json`'s positions, the preview's meshes and `toolpath.csv` all still in
//! the part's frame.
//!
//! Pure steps, and [`stand`], which runs them around the head check:
//! - [`outline`]: the build-plate face's outline, shrunk by `pedestal_inset`;
//! - [`layers`]: the pedestal's layers for `n` layers, filled like a two5d feature's;
//! - [`on_pedestal`]: the part's path (and its planned axes) after the pedestal's;
//! - [`lift_needed`]: how far the colliding moves' heads reach under the table;
//! - [`least`]: the least `n` that clears the table, searched (table hits only fall as the
//!   pedestal grows).

use crate::collisions::{self, Avoided};
use crate::report::{round, FeatureEntry, FeatureReport, ReferenceEntry};
use crate::tolerance::HEIGHT_SLACK;
use brep::section::Plane;
use collide::{Obstacle, Stop};
use features::FeatureTree;
use robot_post::machine::MachineProfile;
use slicer::geom2d::{region_area, Region};
use slicer::params::{LayerParams, Pedestal};
use slicer::planar::Bead;
use slicer::planar::{fill_prism, plate_regions};
use slicer::toolpath::ToolPath;
use slicer::vec3::V3;
use slicer::verify::PlannedFeature;
use slicer::FeaturePlan;

/// The `kind` of the pedestal's entry in `plan.json`.
pub const KIND: &str = "pedestal";

/// How close to +Z (cosine) a build plate's normal must be for the part to stand on a
/// pedestal: the table lies across +Z.
const FACES_UP: f64 = 1.0 - 1e-6;

/// Pedestals taller than the machine's tallest checked for the height a refusal names.
const NAMED_TRIES: usize = 4;

/// Why a plan on a pedestal was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PedestalError {
    /// Even the machine's tallest pedestal leaves moves hitting the table.
    #[error("the head meets the table on {moves} move(s) even on a pedestal of the machine's max_pedestal_height {max} mm; a pedestal of {needed} mm clears it (raise machine.max_pedestal_height to it: --set machine.max_pedestal_height={needed})")]
    TooLow {
        /// The machine's `max_pedestal_height`, mm.
        max: f64,
        /// Moves still hitting the table on it.
        moves: usize,
        /// A height (mm, whole layers) checked to lift them clear.
        needed: f64,
    },
    /// Even the machine's tallest pedestal leaves moves hitting the table, and so do the
    /// taller ones tried.
    #[error("the head meets the table on {moves} move(s) even on a pedestal of the machine's max_pedestal_height {max} mm, and still on pedestals up to {tried} mm (the tilts that clear the head give out): plan with --set pedestal=off --allow-collisions to see the moves in collisions.csv")]
    NoneClears {
        /// The machine's `max_pedestal_height`, mm.
        max: f64,
        /// Moves still hitting the table on it.
        moves: usize,
        /// The tallest pedestal tried, mm.
        tried: f64,
    },
    /// `pedestal = <mm>` taller than the machine allows.
    #[error("pedestal = {given} mm is taller than the machine's max_pedestal_height {max} mm")]
    TooTall {
        /// The height asked for, mm.
        given: f64,
        /// The machine's `max_pedestal_height`, mm.
        max: f64,
    },
    /// `pedestal = <mm>` for a part that cannot stand on one.
    #[error("pedestal = {given} mm: {why}")]
    Impossible {
        /// The height asked for, mm.
        given: f64,
        /// Why not.
        why: NoPedestal,
    },
    /// The search for the pedestal was given up at [`Context::stop_at`].
    #[error("given up at the placement time limit")]
    TimeLimit,
}

/// Why a part cannot stand on a pedestal.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NoPedestal {
    /// No base feature with a reference plane.
    #[error("the part has no build plate to stand a pedestal under")]
    NoPlate,
    /// The build plate does not face the table.
    #[error("the build plate's normal ({:.3}, {:.3}, {:.3}) does not point up from the table (+Z)", .0[0], .0[1], .0[2])]
    NotUp([f64; 3]),
    /// The plate face's section could not be made.
    #[error("the build-plate face's outline cannot be made: {0}")]
    Section(String),
    /// Nothing is left of the outline.
    #[error("the build-plate face's outline is empty (pedestal_inset {0} mm)")]
    Empty(f64),
}

/// The build-plate face's outline the pedestal is a prism of.
#[derive(Debug, Clone)]
pub struct Outline {
    /// The build plate: the base feature's reference plane (its normal +Z).
    pub plane: Plane,
    /// The outline's regions in `plane`'s 2-D frame.
    pub regions: Vec<Region>,
    /// Their area, mm².
    pub area: f64,
}

/// (a) The outline of the part's build-plate face: the section of the first tree's base
/// feature in the middle of its first layer (`params`: that feature's parameters), shrunk by
/// `inset` mm. The plate must face +Z.
pub fn outline(
    trees: &[FeatureTree],
    params: &LayerParams,
    inset: f64,
) -> Result<Outline, NoPedestal> {
    let tree = trees.first().ok_or(NoPedestal::NoPlate)?;
    let base = tree.features.first().ok_or(NoPedestal::NoPlate)?;
    let (plane, regions) =
        plate_regions(tree, base, params).map_err(|e| NoPedestal::Section(e.to_string()))?;
    let n = [plane.normal.x, plane.normal.y, plane.normal.z];
    if n[2] < FACES_UP {
        return Err(NoPedestal::NotUp(n));
    }
    let regions = slicer::fill::shrink_regions(&regions, inset, params.tolerance);
    let area: f64 = regions.iter().map(region_area).sum();
    if regions.is_empty() || area.is_nan() || area <= 0.0 {
        return Err(NoPedestal::Empty(inset));
    }
    Ok(Outline {
        plane,
        regions,
        area,
    })
}

/// Whole layers `layer` mm thick in a pedestal `height` mm tall: rounded up.
pub fn layer_count(height: f64, layer: f64) -> usize {
    if !(height > 0.0 && layer > 0.0) {
        return 0;
    }
    (height / layer - HEIGHT_SLACK).ceil().max(0.0) as usize
}

/// (b) The pedestal's `n` layers, each `layer` mm thick, under `outline`'s plate (the top of the
/// last on the plate), filled with `params` as feature `id`'s, laid from nowhere (it is
/// printed first).
pub fn layers(
    outline: &Outline,
    n: usize,
    layer: f64,
    id: usize,
    params: &LayerParams,
    bead: Bead,
) -> FeaturePlan {
    let floor = outline.plane.offset(-(n as f64) * layer);
    let mut plan = fill_prism(id, floor, &outline.regions, n, layer, params, bead).lay(None);
    for q in &mut plan.points {
        q.feature = id as u32;
    }
    plan
}

/// (c) The part's `path` after the pedestal's points (`pedestal`), and the planned axes of both
/// (`planned`: the part's, one a point, or none where the head does not tilt).
pub fn on_pedestal(pedestal: &FeaturePlan, path: &ToolPath, planned: &[V3]) -> (ToolPath, Vec<V3>) {
    let mut points = Vec::with_capacity(pedestal.points.len() + path.points.len());
    points.extend_from_slice(&pedestal.points);
    points.extend_from_slice(&path.points);
    let axes = if planned.is_empty() {
        vec![]
    } else {
        pedestal
            .points
            .iter()
            .map(|q| q.axis)
            .chain(planned.iter().copied())
            .collect()
    };
    (ToolPath { points }, axes)
}

/// The moves of `avoided` that hit the table.
pub fn table_hits(avoided: &Avoided) -> usize {
    avoided
        .left
        .iter()
        .filter(|c| c.hits == Obstacle::Table)
        .count()
}

/// (d) How far (mm) the head reaches under the table on the moves of `avoided` that hit it,
/// along `path` (the path they index) on `machine`: the most, over those moves, of the depth of
/// the head's lowest point below the table's surface where it first meets it and at the move's
/// end, with the axis it ends with. A pedestal that much taller lifts them clear (with the
/// same axes).
pub fn lift_needed(avoided: &Avoided, path: &ToolPath, machine: &MachineProfile) -> f64 {
    let table = collisions::table(path, machine);
    let shape = machine.head.shape();
    avoided
        .left
        .iter()
        .filter(|c| c.hits == Obstacle::Table)
        .filter_map(|c| {
            let q = path.points.get(c.index)?;
            let axis = slicer::vec3::unit(q.axis)?;
            let d = table
                .depth_below(&shape, c.at, axis)
                .max(table.depth_below(&shape, q.p, axis));
            Some(d + collide::TOLERANCE)
        })
        .fold(0.0, f64::max)
}

/// (d) The least `n` in `1..=max` for which `fits(n)` (false at 0, and true from some `n` on:
/// a taller pedestal never brings the table nearer), `None` when not even `max` fits. Probes
/// the layer under `guess` (clamped into range) first: the guess is most often the answer or
/// tall ([`lift_needed`] takes the axes the part's own check tilted, and a taller pedestal
/// lets a smaller tilt do), and a check that fits costs a whole walk of the path where one
/// that does not stops at its first table hit (the fan: 0.26 s against 0.10 s). Where it
/// fits, steps down by doubling; where not, up from it (the guess next); then halves the
/// range left.
pub fn least<E>(
    max: usize,
    guess: usize,
    mut fits: impl FnMut(usize) -> Result<bool, E>,
) -> Result<Option<usize>, E> {
    if max == 0 {
        return Ok(None);
    }
    let under = guess.clamp(1, max).saturating_sub(1).max(1);
    // The most layers known to leave a hit, and the fewest known to clear.
    let (mut lo, mut hi);
    if fits(under)? {
        // Tall: step down by doubling to a height that leaves a hit (the fan's guess of 81
        // layers for the 78 it needs: 80, 78, 74, 76, 77).
        (lo, hi) = (0, under);
        let mut step = 2;
        while hi > 1 {
            let n = hi.saturating_sub(step).max(1);
            if fits(n)? {
                hi = n;
                step *= 2;
            } else {
                lo = n;
                break;
            }
        }
    } else {
        lo = under;
        let mut step = 1;
        loop {
            if lo == max {
                return Ok(None);
            }
            let n = (lo + step).min(max);
            if fits(n)? {
                hi = n;
                break;
            }
            lo = n;
            step *= 2;
        }
    }
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if fits(mid)? {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(Some(hi))
}

/// A pedestal the part stands on.
#[derive(Debug, Clone)]
pub struct Stood {
    /// Its layers and figures (points moved into the tool path).
    pub plan: FeaturePlan,
    /// Its feature id: the next after the part's features.
    pub id: usize,
    /// Layers.
    pub layers: usize,
    /// Height, mm.
    pub height: f64,
    /// The prism's volume (outline area × height), mm³.
    pub volume: f64,
    /// The plate's normal (+Z).
    pub normal: [f64; 3],
    /// The `filling_ratio` and `infill_density` it is laid with (the base feature's).
    pub fill: f64,
    /// See `fill`.
    pub density: f64,
}

impl Stood {
    /// Its entry in `plan.json`'s features (the collision and post figures are the caller's).
    pub fn report(&self, filament_area: f64) -> FeatureReport {
        let fig = &self.plan.figures;
        FeatureReport {
            feature: FeatureEntry {
                id: self.id,
                kind: KIND.to_string(),
                subtype: KIND.to_string(),
                reference: ReferenceEntry {
                    surface: "build_plate".into(),
                    step_face: None,
                    normal: Some(self.normal.map(|x| round(x, 1e6))),
                },
                parents: vec![],
                volume_mm3: round(self.volume, 1e3),
                faces: vec![],
                root_loops: 0,
            },
            layers: fig.layers,
            points: fig.points,
            print_length_mm: round(fig.print_length, 1e3),
            travel_length_mm: round(fig.travel_length, 1e3),
            extruded_volume_mm3: round(fig.filament * filament_area, 1e3),
            expected_volume_mm3: round(self.planned(filament_area).expected(), 1e3),
            sparse_volume_mm3: round(fig.sparse_volume, 1e3),
            widened_volume_mm3: 0.0,
            support_volume_mm3: 0.0,
            below_resolution: None,
            unsupported_area_mm2: 0.0,
            thickness_min_mm: round(fig.thickness.0, 1e6),
            thickness_mean_mm: round(fig.thickness.1, 1e6),
            thickness_max_mm: round(fig.thickness.2, 1e6),
            freeform: None,
            warnings: vec![],
            // Every axis the plate's normal: nothing turns, before or after smoothing.
            orientation: Some(slicer::orient::OrientationFigures {
                step_max_deg_before: 0.0,
                step_max_deg_after: 0.0,
                rate_max_deg_per_mm_before: 0.0,
                rate_max_deg_per_mm_after: 0.0,
            }),
            post: None,
            collision: Default::default(),
            pedestal_height_mm: Some(round(self.height, 1e6)),
            machining_allowance: None,
        }
    }

    /// What the self-check is asked of it: extruded within its tolerance of the prism's volume
    /// × `fill` (the base feature's `filling_ratio`), its sparse layers' volume at `density`
    /// (the base feature's `infill_density`).
    pub fn planned(&self, filament_area: f64) -> PlannedFeature {
        PlannedFeature {
            id: self.id,
            kind: KIND.to_string(),
            volume: self.volume,
            fill: self.fill,
            sparse: self.plan.figures.sparse_volume,
            density: self.plan.figures.sparse_density(self.density),
            layers: self.plan.figures.layers,
            extruded: self.plan.figures.filament * filament_area,
            tolerance: slicer::verify::VOLUME_TOLERANCE,
            smallest_bead: 0.0,
        }
    }

    /// One line for the program's header and the summary.
    pub fn line(&self) -> String {
        format!(
            "pedestal: {} mm ({} layers, {:.1} mm^3), feature {}",
            round(self.height, 1e3),
            self.layers,
            self.volume,
            self.id
        )
    }
}

/// What the part's pedestal is made of: the inputs of [`stand`].
pub struct Context<'a> {
    /// The part's feature trees.
    pub trees: &'a [FeatureTree],
    /// The base feature's parameters (layer height, perimeters, fill), and the pedestal keys.
    pub params: &'a LayerParams,
    /// The pedestal's setting (`[defaults]`).
    pub setting: Pedestal,
    /// The machine's bead.
    pub bead: Bead,
    /// The machine.
    pub machine: &'a MachineProfile,
    /// The pedestal's feature id.
    pub id: usize,
    /// Plan on where even the tallest pedestal leaves moves hitting the table (with a warning).
    pub allow_collisions: bool,
    /// Past this instant the search for the pedestal is given up ([`PedestalError::TimeLimit`],
    /// [`crate::Options::stop_at`]).
    pub stop_at: Option<std::time::Instant>,
}

/// What [`stand`] leaves: the tool path as checked, its collisions left, and the pedestal it
/// stands on, if any.
pub struct Checked {
    /// The tool path, the pedestal's points first.
    pub path: ToolPath,
    /// The head check's result on it.
    pub avoided: Avoided,
    /// The pedestal.
    pub pedestal: Option<Stood>,
    /// Things to know (no pedestal where one was wanted, the tallest not enough).
    pub warnings: Vec<String>,
}

impl Stood {
    /// The pedestal of `n` layers `layer` mm thick under the outline `o`.
    fn build(ctx: &Context, o: &Outline, n: usize, layer: f64) -> Stood {
        let plan = layers(o, n, layer, ctx.id, ctx.params, ctx.bead);
        let height = n as f64 * layer;
        Stood {
            id: ctx.id,
            layers: n,
            height,
            volume: o.area * height,
            normal: [o.plane.normal.x, o.plane.normal.y, o.plane.normal.z],
            fill: ctx.params.filling_ratio,
            density: ctx.params.infill_density,
            plan,
        }
    }
}

/// The head check (`avoid`: [`collisions::avoid`] with the machine and the features) of `path`
/// (`planned` its planned axes) with the pedestal `ctx` asks for: `auto` checks the part as
/// it is and, where moves hit the table, the part on pedestals of whole layers, keeping the
/// least that hits it nowhere ([`least`], from the guess [`lift_needed`] makes); a height is
/// checked on that pedestal; `off` checks the part alone.
pub fn stand(
    ctx: &Context,
    path: ToolPath,
    planned: Vec<V3>,
    avoid: impl Fn(&mut ToolPath, &[V3], Stop) -> Avoided,
) -> Result<Checked, PedestalError> {
    let layer = ctx.params.uniform_layer_height;
    let max_height = ctx.machine.max_pedestal_height();
    // The most whole layers under the machine's tallest pedestal.
    let max = if layer > 0.0 && max_height >= 0.0 {
        (max_height / layer + HEIGHT_SLACK).floor() as usize
    } else {
        0
    };
    let build = |o: &Outline, n: usize| Stood::build(ctx, o, n, layer);
    let check = |stood: &Stood, stop: Stop| {
        crate::in_time(ctx.stop_at).map_err(|_| PedestalError::TimeLimit)?;
        let (mut p, axes) = on_pedestal(&stood.plan, &path, &planned);
        let a = avoid(&mut p, &axes, stop);
        Ok::<_, PedestalError>((p, a))
    };
    match ctx.setting {
        Pedestal::Height(given) if layer_count(given, layer) > 0 => {
            if layer_count(given, layer) > max {
                return Err(PedestalError::TooTall {
                    given,
                    max: max_height,
                });
            }
            let o = outline(ctx.trees, ctx.params, ctx.params.pedestal_inset)
                .map_err(|why| PedestalError::Impossible { given, why })?;
            let stood = build(&o, layer_count(given, layer));
            let (p, avoided) = check(&stood, Stop::AtEnd)?;
            return Ok(Checked {
                path: p,
                avoided,
                pedestal: Some(stood),
                warnings: vec![],
            });
        }
        Pedestal::Auto => {}
        _ => {
            let mut p = path;
            let avoided = avoid(&mut p, &planned, Stop::AtEnd);
            return Ok(Checked {
                path: p,
                avoided,
                pedestal: None,
                warnings: vec![],
            });
        }
    }
    // Auto: the part as it is first.
    let mut first = path.clone();
    let avoided = avoid(&mut first, &planned, Stop::AtEnd);
    if table_hits(&avoided) == 0 || max == 0 {
        return Ok(Checked {
            path: first,
            avoided,
            pedestal: None,
            warnings: vec![],
        });
    }
    let o = match outline(ctx.trees, ctx.params, ctx.params.pedestal_inset) {
        Ok(o) => o,
        Err(why) => {
            return Ok(Checked {
                path: first,
                avoided,
                pedestal: None,
                warnings: vec![format!(
                    "the head meets the table and no pedestal lifts the part: {why}"
                )],
            })
        }
    };
    let guess = layer_count(lift_needed(&avoided, &first, ctx.machine), layer);
    drop(first);
    // The least pedestal that clears the table, with its check's result.
    let mut best: Option<(Stood, ToolPath, Avoided)> = None;
    // The tallest's check when it leaves a hit (`least` asks for it last before giving up).
    let mut tallest: Option<(Stood, ToolPath, Avoided)> = None;
    let fits = |n: usize| -> Result<bool, PedestalError> {
        let stood = build(&o, n);
        // Below the tallest only whether the table is hit matters: the walk stops at the
        // first hit (most heights tried fail, most often halfway along the path). The
        // tallest's check is walked whole: a refusal's figures are its.
        let stop = if n < max {
            Stop::AtTableHit
        } else {
            Stop::AtEnd
        };
        let (p, a) = check(&stood, stop)?;
        let clear = !a.stopped && table_hits(&a) == 0;
        if clear && best.as_ref().is_none_or(|(s, _, _)| n < s.layers) {
            best = Some((stood, p, a));
        } else if !clear && n == max {
            tallest = Some((stood, p, a));
        }
        Ok(clear)
    };
    let found = least(max, guess, fits)?;
    if let (Some(_), Some((stood, p, a))) = (found, best) {
        return Ok(Checked {
            path: p,
            avoided: a,
            pedestal: Some(stood),
            warnings: vec![],
        });
    }
    // Not even the tallest: the height that would do, from how deep the head still reaches,
    // checked (the tilts found change with the height: a move cleared at one height may hit
    // at the next), and raised again from where it still hits, a few times.
    let (stood, p, a) = match tallest {
        Some(checked) => checked,
        None => {
            let stood = build(&o, max);
            let (p, a) = check(&stood, Stop::AtEnd)?;
            (stood, p, a)
        }
    };
    let e = refusal(ctx, (&stood, &p, &a), max, layer, |n| {
        let s = build(&o, n);
        let (q, b) = check(&s, Stop::AtEnd)?;
        let lift = lift_needed(&b, &q, ctx.machine);
        Ok((table_hits(&b) == 0, s.height + lift))
    })?;
    if !ctx.allow_collisions {
        return Err(e);
    }
    Ok(Checked {
        path: p,
        avoided: a,
        pedestal: Some(stood),
        warnings: vec![e.to_string()],
    })
}

/// Why not even the machine's tallest pedestal (`tallest`, of `max` layers `layer` mm thick,
/// with its check of its path) will do: the height that would, from how deep the head still
/// reaches, checked by `check` ([`named_height`]), or the tallest tried where none cleared.
fn refusal(
    ctx: &Context,
    (stood, p, a): (&Stood, &ToolPath, &Avoided),
    max: usize,
    layer: f64,
    check: impl FnMut(usize) -> Result<(bool, f64), PedestalError>,
) -> Result<PedestalError, PedestalError> {
    let max_height = ctx.machine.max_pedestal_height();
    let moves = table_hits(a);
    let first = layer_count(stood.height + lift_needed(a, p, ctx.machine), layer).max(max + 1);
    let (height, cleared) = named_height(first, layer, check)?;
    Ok(if cleared {
        PedestalError::TooLow {
            max: max_height,
            moves,
            needed: height,
        }
    } else {
        PedestalError::NoneClears {
            max: max_height,
            moves,
            tried: height,
        }
    })
}

/// The height (mm) a refusal names where not even the tallest pedestal clears the table, and
/// whether it was found to clear: from `first` layers, `check(n)` (whether `n` layers clear
/// it, and how tall a pedestal the moves still hitting it ask for) raised again from where it
/// still hits, [`NAMED_TRIES`] times at most.
fn named_height(
    first: usize,
    layer: f64,
    mut check: impl FnMut(usize) -> Result<(bool, f64), PedestalError>,
) -> Result<(f64, bool), PedestalError> {
    let mut n = first;
    let mut cleared = false;
    for _ in 0..NAMED_TRIES {
        let (clear, wanted) = check(n)?;
        if clear {
            cleared = true;
            break;
        }
        n = layer_count(wanted, layer).max(n + 1);
    }
    Ok((round(n as f64 * layer, 1e3), cleared))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `least` finds the threshold of every monotone predicate from every guess, and says when
    /// not even the most fits; it asks few questions.
    #[test]
    fn the_least_pedestal_is_found_from_any_guess() {
        for max in 1..40 {
            for need in 1..=max + 1 {
                for guess in 0..=max + 2 {
                    let mut asked = 0;
                    let got = least(max, guess, |n| {
                        asked += 1;
                        assert!((1..=max).contains(&n));
                        Ok::<_, ()>(n >= need)
                    })
                    .unwrap();
                    let want = (need <= max).then_some(need);
                    assert_eq!(got, want, "max {max} need {need} guess {guess}");
                    assert!(asked <= 2 + 2 * (usize::BITS - max.leading_zeros()) as usize);
                }
            }
        }
        assert_eq!(least(0, 3, |_| Ok::<_, ()>(true)), Ok(None));
    }

    /// A guess a few layers tall (the fan's: 81 for the 78 it needs) is walked down from, not
    /// halved from the plate: each check is a whole head check, and the short pedestals' many
    /// table hits make them the slowest.
    #[test]
    fn a_tall_guess_is_walked_down_in_a_few_checks() {
        let mut asked = vec![];
        let got = least(200, 81, |n| {
            asked.push(n);
            Ok::<_, ()>(n >= 78)
        });
        assert_eq!(got, Ok(Some(78)));
        assert_eq!(asked, [80, 78, 74, 76, 77]);
    }

    /// Checks that fit cost a whole walk, those that do not stop at their first table hit:
    /// where the guess is the answer, one of each; where the guess is the layer over it, the
    /// guess is not checked.
    #[test]
    fn a_good_guess_costs_one_check_that_fits() {
        let count = |need: usize, guess: usize| {
            let mut asked = vec![];
            let got = least(200, guess, |n| {
                asked.push(n);
                Ok::<_, ()>(n >= need)
            });
            assert_eq!(got, Ok(Some(need)));
            asked
        };
        assert_eq!(count(40, 40), [39, 40]);
        assert_eq!(count(39, 40), [39, 37, 38]);
    }

    #[test]
    fn heights_round_up_to_whole_layers() {
        assert_eq!(layer_count(2.4, 0.2), 12);
        assert_eq!(layer_count(2.2, 0.2), 11);
        assert_eq!(layer_count(2.21, 0.2), 12);
        assert_eq!(layer_count(0.0, 0.2), 0);
        assert_eq!(layer_count(-1.0, 0.2), 0);
        assert_eq!(layer_count(f64::NAN, 0.2), 0);
    }
}
