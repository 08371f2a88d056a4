//! The lay stage: every feature's layers filled (the bulk of the work: a few features at a time
//! in parallel) and laid in build order, each from where the one before ended, then joined into
//! one tool path (the sequence stage).

use crate::extract::{Extracted, Slot};
use crate::report::FeatureEntry;
use crate::support::{CurvedKey, KnownUnsupported};
use crate::warning::{Warning, WarningKind};
use crate::{PlanError, Process, Progress};
use brep::math::P3;
use rayon::prelude::*;
use robot_post::machine::MachineProfile;
use slicer::feature_fill::fill_feature_on;
use slicer::figures::{FreeformFigures, Layering};
use slicer::params::{LayerParams, LayerStrategy};
use slicer::toolpath::{MoveKind, PathPoint, ToolPath};
use slicer::verify::{PlannedFeature, VOLUME_TOLERANCE};
use slicer::{fill_feature, FeaturePlan};

/// What was laid for one feature, as the report gives it.
#[derive(Debug, Clone)]
pub struct LaidFeature {
    /// What the feature is.
    pub entry: FeatureEntry,
    /// What the self-check compares.
    pub planned: PlannedFeature,
    /// Layers that print.
    pub layers: usize,
    /// Points laid.
    pub points: usize,
    /// Printed length, mm.
    pub print_length: f64,
    /// Travel length, mm.
    pub travel_length: f64,
    /// Bead volume planned (Eq. 1 filament × filament area), mm³.
    pub extruded: f64,
    /// Bead volume added by widening narrow beads, mm³.
    pub widened: f64,
    /// Bead volume of support material laid with its planar layers (issue 33), mm³: not the
    /// part's, so not in `extruded` nor in the self-check.
    pub support_volume: f64,
    /// Thinnest, mean and thickest layer, mm.
    pub thickness: (f64, f64, f64),
    /// The freeform planner's figures (curved features).
    pub freeform: Option<FreeformFigures>,
    /// The feature's warnings.
    pub warnings: Vec<Warning>,
    /// Below the nozzle's resolution (issue 31, item 4): how narrow, and what nozzle would lay
    /// it; `None` when the beads lay it.
    pub below_resolution: Option<crate::resolution::BelowResolution>,
    /// What holds up its layers (issue 31): measured from the features alone for planar
    /// layers, as laid for curved ones; `None` where nothing was measured.
    pub held: Option<crate::support::Held>,
    /// The machining allowance its beads leave over its nominal faces (issue 37, item 2);
    /// `None` without one.
    pub allowance: Option<slicer::allowance::AllowanceLeft>,
    /// Its grown solid (volume, folds) with a machining allowance.
    pub grown: Option<slicer::Grown>,
}

/// What the lay stage returns.
#[derive(Debug)]
pub struct Laid {
    /// The features laid, in build order.
    pub features: Vec<LaidFeature>,
    /// Their paths joined in build order, with their file-wide ids (the sequence stage).
    pub toolpath: ToolPath,
    /// Warnings of the part (features below the build plate).
    pub warnings: Vec<Warning>,
}

/// Fills and lays every feature of `extracted` in build order. Features are filled a few at a
/// time in parallel, as many as there are threads, so memory holds no more than that many
/// fills; then laid one after the other, each from where the one before ended. Past
/// `options.stop_at` no further group of features is begun ([`PlanError::TimeLimit`]); with
/// [`crate::Options::fail_fast`], none after a group with a curved feature the support gate
/// refuses ([`PlanError::Unsupported`]).
pub fn lay(
    extracted: &Extracted,
    process: &Process,
    machine: &MachineProfile,
    options: &crate::Options,
    tell: &dyn Fn(Progress),
) -> Result<Laid, PlanError> {
    let stop_at = options.stop_at;
    let fail_fast = options.fail_fast && !options.keep_going;
    let base = process.base();
    // Curved features an earlier placement found not held up (their layers do not change
    // with the placement): refused before anything is laid.
    let known = options.known_unsupported.filter(|_| fail_fast);
    if let Some(known) = known {
        let lines = known_lines(extracted, process, known)?;
        if !lines.is_empty() {
            return Err(PlanError::Unsupported {
                lines,
                earlier: true,
            });
        }
    }
    // What holds up each planar layer, from the features alone (issue 31).
    // Support material (issue 33) carries what it can; `held` is what it leaves.
    let crate::support::Planar {
        mut held,
        columns,
        mut meshes,
    } = crate::support::planar(
        &extracted.assembly,
        process,
        machine.bead().width,
        slicer::support::Carry::Until(stop_at),
    )?;
    let window = rayon::current_num_threads().max(1);
    let mut plans = vec![];
    let mut cursor: Option<P3> = None;
    let mut features = vec![];
    let mut warnings = vec![];
    let mut grown = vec![];
    for chunk in extracted.order.chunks(window) {
        crate::in_time(stop_at)?;
        // Curved features of the last group whose layers are not held up.
        let mut unsupported = vec![];
        let fills: Vec<Result<_, PlanError>> = chunk
            .par_iter()
            .map(|&slot| {
                let t = &extracted.assembly.trees[slot.tree];
                let params = process.feature_params(&base, slot.offset, extracted.feature(slot))?;
                let f = extracted.feature(slot);
                let meshed = meshes.get(&extracted.id(slot));
                let fill = fill_feature_on(t, f, &params, machine.bead(), meshed)?;
                let fill = match columns.get(&extracted.id(slot)) {
                    Some(c) => fill.with_support(c, &params),
                    None => fill,
                };
                Ok((params, fill))
            })
            .collect();
        for (&slot, fill) in chunk.iter().zip(fills) {
            let id = extracted.id(slot);
            tell(Progress::Feature { id });
            let (params, fill) = fill?;
            let plan = fill.lay(cursor);
            let (plan, fallback) =
                offset_if_transition_misses(extracted, slot, &params, plan, cursor, machine)?;
            cursor = plan.exit().map(P3::from).or(cursor);
            let (laid, below) = laid_feature(extracted, slot, &params, &plan, fallback, machine);
            let mut plan = plan;
            // Below the nozzle's resolution (issue 31, item 4): named, and judged within the
            // share of it narrower than the nozzle lays.
            let t = &extracted.assembly.trees[slot.tree];
            let below_resolution = crate::resolution::below_resolution(
                t,
                extracted.feature(slot),
                &params,
                &plan.points,
                machine.min_bead_width(),
                machine.nozzle_diameter,
                meshes.get(&id),
            )?;
            // Its mesh is not needed again.
            meshes.remove(&id);
            let mut laid = laid.widen(&mut plan.points, machine);
            if let Some(b) = &below_resolution {
                laid.planned.tolerance = crate::resolution::tolerance(b.narrow_share);
                laid.warnings.push(Warning::feature(
                    id,
                    WarningKind::Planner(crate::resolution::warning(
                        id,
                        b,
                        machine.min_bead_width(),
                    )),
                ));
            }
            laid.below_resolution = below_resolution;
            laid.warnings.extend(below.clone());
            // Curved layers' support is measured as they are laid.
            if let Some(ff) = &plan.freeform {
                let h = crate::support::Held {
                    support: ff.support,
                    angle_deg: params.overhang_angle_deg,
                    kind: extracted.feature(slot).kind,
                };
                if let Some(line) = crate::support::line(id, &h) {
                    unsupported.push(line);
                    let key = CurvedKey::of(t, extracted.feature(slot), &params);
                    if let (Some(known), Some(key)) = (known, key) {
                        known.add(key, h);
                    }
                }
                held.insert(id, h);
            }
            laid.held = held.get(&id).copied();
            warnings.extend(below);
            if params.machining_allowance > 0.0 {
                grown.push((features.len(), slot, params.clone()));
            }
            features.push(laid);
            plans.push((id, plan));
            tell(Progress::FeatureDone);
        }
        // The support gate will refuse the plan: with fail_fast, nothing more is laid.
        if fail_fast && !unsupported.is_empty() {
            return Err(PlanError::Unsupported {
                lines: unsupported,
                earlier: false,
            });
        }
    }
    measure_allowance(extracted, &grown, &plans, &mut features)?;
    tell(Progress::Planned);
    Ok(Laid {
        features,
        toolpath: slicer::sequence(plans),
        warnings,
    })
}

/// One [`crate::support::line`] for each curved feature of `extracted` that `known` holds
/// (an earlier placement found its layers not held up), in build order, with its id here.
fn known_lines(
    extracted: &Extracted,
    process: &Process,
    known: &KnownUnsupported,
) -> Result<Vec<String>, PlanError> {
    let base = process.base();
    let mut lines = vec![];
    for &slot in &extracted.order {
        let f = extracted.feature(slot);
        if f.kind != features::FeatureKind::Freeform {
            continue;
        }
        let params = process.feature_params(&base, slot.offset, f)?;
        let t = &extracted.assembly.trees[slot.tree];
        let held = CurvedKey::of(t, f, &params).and_then(|k| known.find(&k));
        if let Some(h) = held {
            lines.extend(crate::support::line(extracted.id(slot), &h));
        }
    }
    Ok(lines)
}

/// The machining allowance the part's beads leave over each grown feature's nominal faces
/// (issue 37, item 2): `grown` holds each such feature's index in `features`, slot and
/// parameters. A feature whose offset folded says where.
fn measure_allowance(
    extracted: &Extracted,
    grown: &[(usize, Slot, LayerParams)],
    plans: &[(usize, FeaturePlan)],
    features: &mut [LaidFeature],
) -> Result<(), PlanError> {
    if grown.is_empty() {
        return Ok(());
    }
    let envelope = slicer::allowance::Envelope::new(plans.iter().map(|(_, p)| p.points.as_slice()));
    let measured: Vec<Result<_, PlanError>> = grown
        .par_iter()
        .map(|(i, slot, params)| {
            let t = &extracted.assembly.trees[slot.tree];
            let left = slicer::allowance::allowance_left(
                t,
                extracted.feature(*slot),
                params,
                &envelope,
                extracted.plates[slot.tree].as_ref(),
            )?;
            Ok((*i, left, params.tolerance))
        })
        .collect();
    for m in measured {
        let (i, left, tolerance) = m?;
        let Some(laid) = features.get_mut(i) else {
            continue;
        };
        let id = laid.planned.id;
        if let Some(a) = left.as_ref().filter(|a| a.min < a.requested - tolerance) {
            let at = a.thinnest_at;
            laid.warnings.push(Warning::feature(
                id,
                WarningKind::Planner(format!(
                    "feature {id}: its beads leave {:.3} mm of machining allowance near ({:.2}, {:.2}, {:.2}) mm, under the {} mm asked less the {tolerance} mm tolerance (the preview colours the allowance left): a thinner layer or bead follows the offset closer",
                    a.min, at[0], at[1], at[2], a.requested
                )),
            ));
        }
        laid.allowance = left;
        if let Some(g) = plans.get(i).and_then(|p| p.1.figures.grown.clone()) {
            if let Some(at) = g.folds.first() {
                laid.warnings.push(Warning::feature(
                    id,
                    WarningKind::Planner(format!(
                        "feature {id}: its machining allowance folds over itself at {} place(s), first near ({:.2}, {:.2}, {:.2}) mm (a concave radius under the allowance): filled there, the allowance larger",
                        g.folds.len(),
                        at[0],
                        at[1],
                        at[2]
                    )),
                ));
            }
            laid.grown = Some(g);
        }
    }
    Ok(())
}

/// Transition layers chosen by `auto` that miss the feature's volume by more than the
/// self-check allows: the feature is laid on offset layers instead, with the miss.
fn offset_if_transition_misses(
    extracted: &Extracted,
    slot: Slot,
    params: &LayerParams,
    plan: FeaturePlan,
    cursor: Option<P3>,
    machine: &MachineProfile,
) -> Result<(FeaturePlan, Option<f64>), PlanError> {
    let transition = plan
        .freeform
        .is_some_and(|ff| ff.layers == Layering::Transition);
    if params.layer_strategy != LayerStrategy::Auto || !transition {
        return Ok((plan, None));
    }
    let f = extracted.feature(slot);
    let bead = machine.bead();
    // What the self-check expects: the sparse part at its density, the rest at the fill ratio.
    let fig = &plan.figures;
    let expected = slicer::verify::expected_volume(
        planned_volume(f, &plan.figures),
        params.filling_ratio,
        fig.sparse_volume,
        fig.sparse_density(params.infill_density),
    );
    let rel = plan.figures.filament * bead.filament_area()
        / expected.max(crate::tolerance::VOLUME_MM3)
        - 1.0;
    if rel.abs() <= VOLUME_TOLERANCE {
        return Ok((plan, None));
    }
    let offset_params = LayerParams {
        layer_strategy: LayerStrategy::Offset,
        ..params.clone()
    };
    let t = &extracted.assembly.trees[slot.tree];
    let plan = fill_feature(t, f, &offset_params, bead)?.lay(cursor);
    Ok((plan, Some(rel)))
}

/// The volume a feature's plan is checked against: its grown solid's where a machining
/// allowance grew it (issue 37, item 2), else its own.
fn planned_volume(f: &features::Feature, fig: &slicer::figures::FeatureFigures) -> f64 {
    fig.grown.as_ref().map_or(f.volume, |g| g.planned_volume())
}

/// The figures of feature `slot` as laid in `plan`, and the part's warning when it reaches
/// below the build plate.
fn laid_feature(
    extracted: &Extracted,
    slot: Slot,
    params: &LayerParams,
    plan: &FeaturePlan,
    fallback: Option<f64>,
    machine: &MachineProfile,
) -> (LaidFeature, Option<Warning>) {
    let id = extracted.id(slot);
    let f = extracted.feature(slot);
    let t = &extracted.assembly.trees[slot.tree];
    let fig = &plan.figures;
    let extruded = fig.filament * machine.bead().filament_area();
    let mut warnings: Vec<Warning> = fig
        .warnings
        .iter()
        .map(|w| Warning::feature(id, WarningKind::Planner(w.clone())))
        .collect();
    warnings
        .extend(fallback.map(|missed| Warning::feature(id, WarningKind::OffsetLayers { missed })));
    // Below the build plate (the base feature's reference plane): any point of the feature,
    // planned or not (a planar layer starts at its reference plane, so what lies below that is
    // not printed).
    let below = extracted.plates[slot.tree].as_ref().and_then(|plate| {
        let planned = plan
            .points
            .iter()
            .map(|q| -plate.height(&P3::from(q.p)))
            .fold(0.0f64, f64::max);
        let depth = planned.max(fig.below_plate);
        (depth > crate::tolerance::BELOW_PLATE_MM)
            .then(|| Warning::feature(id, WarningKind::BelowPlate { depth }))
    });
    let laid = LaidFeature {
        entry: FeatureEntry::new(t, f, slot.offset),
        planned: PlannedFeature {
            id,
            kind: f.kind.as_str().to_string(),
            volume: planned_volume(f, fig),
            fill: params.filling_ratio,
            sparse: fig.sparse_volume,
            density: fig.sparse_density(params.infill_density),
            layers: fig.layers,
            extruded,
            tolerance: VOLUME_TOLERANCE,
            // A bead min_bead_width wide, as long, min_layer_height thick.
            smallest_bead: machine.min_bead_width().powi(2) * params.min_layer_height,
        },
        layers: fig.layers,
        points: fig.points,
        print_length: fig.print_length,
        travel_length: fig.travel_length,
        extruded,
        widened: 0.0,
        support_volume: fig.support_filament * machine.bead().filament_area(),
        thickness: fig.thickness,
        freeform: plan.freeform,
        warnings,
        below_resolution: None,
        held: None,
        allowance: None,
        grown: None,
    };
    (laid, below)
}

impl LaidFeature {
    /// Printability (issue 21): every print point whose bead is narrower than the machine's
    /// `min_bead_width` (a thin wall's or a blade tip's, which the nozzle lays poorly) is
    /// widened to it, its filament scaled with the width (Eq. 1 is linear in it), so the nozzle
    /// lays a bead it can and the material it takes is counted. The self-check keeps comparing
    /// what was planned for the feature's volume; the report gives the volume added apart
    /// (`widened_volume_mm3`), and the program and the estimate carry it.
    fn widen(mut self, points: &mut [PathPoint], machine: &MachineProfile) -> LaidFeature {
        let min_bead = machine.min_bead_width();
        let (mut narrow, mut prints, mut thinnest, mut added) = (0, 0, f64::INFINITY, 0.0);
        for q in points
            .iter_mut()
            .filter(|q| q.kind == MoveKind::Print && !q.role.is_support())
        {
            prints += 1;
            if q.width < min_bead as f32 && q.width > 0.0 {
                narrow += 1;
                thinnest = thinnest.min(f64::from(q.width));
                let e = q.e * min_bead / f64::from(q.width);
                added += e - q.e;
                q.e = e;
                q.width = min_bead as f32;
            }
        }
        self.widened = added * machine.bead().filament_area();
        if narrow > 0 {
            let id = self.planned.id;
            // The widening's line comes before the below-plate one, after the planner's.
            self.warnings.push(Warning::feature(
                id,
                WarningKind::Widened {
                    points: narrow,
                    prints,
                    min_bead,
                    thinnest,
                    added_mm3: self.widened,
                    extruded_mm3: self.extruded,
                },
            ));
        }
        self
    }
}
