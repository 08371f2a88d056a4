//! The report, built once from the stages' values after the last one ([`Stages::assemble`]).

use crate::estimate::Estimate;
use crate::extract::Extracted;
use crate::gates::Passed;
use crate::head::Checked;
use crate::lay::LaidFeature;
use crate::report::{
    round, FeatureReport, FreeformEntry, MovedEntry, PlacementEntry, PlanReport, PostEntry,
    SettingsEntry, PLAN_SCHEMA,
};
use crate::warning::{texts, Warning, WarningKind};
use crate::{Options, Plan};
use robot_post::machine::MachineProfile;
use robot_post::{PostFigures, Program};
use slicer::orient::OrientationFigures;

/// What the post stage made: the program, and where the part was moved into reach first.
#[derive(Debug, Clone, Copy)]
pub struct Posted<'a> {
    /// The post's program (its figures and warnings).
    pub program: &'a Program,
    /// Where the part was moved on a KUKA table, when it was.
    pub moved: Option<&'a crate::reach::Moved>,
}

/// What the stages up to the head check made, carried to the gates, the post and the report.
#[derive(Debug)]
pub struct Stages {
    /// The extract stage's features.
    pub extracted: Extracted,
    /// How the place stage turned the part.
    pub placement: Option<PlacementEntry>,
    /// What the lay stage laid, per feature in build order.
    pub features: Vec<LaidFeature>,
    /// The lay stage's warnings of the part.
    pub warnings: Vec<Warning>,
    /// The head-check stage's path and collisions (the skirt and brim added to the path).
    pub checked: Checked,
    /// The skirt and brim laid before the part, if any ([`crate::adhesion`]).
    pub adhesion: Option<crate::report::AdhesionEntry>,
}

impl Stages {
    /// The plan, its report made from every stage's value: `posted` is the post's (`None`:
    /// refused before it), `passed` what the gates let pass.
    pub fn assemble(
        self,
        machine: &MachineProfile,
        options: &Options,
        posted: Option<Posted>,
        passed: Passed,
        est: &Estimate,
        settings: SettingsEntry,
    ) -> Plan {
        let Stages {
            extracted,
            placement,
            features,
            warnings,
            checked,
            adhesion,
        } = self;
        let program = posted.map(|p| p.program);
        let mut features = features;
        let allowance_left = features
            .iter_mut()
            .filter_map(|f| {
                let a = f.allowance.as_mut()?;
                Some((f.planned.id, std::mem::take(&mut a.measured)))
            })
            .collect();
        let filament_area = machine.bead().filament_area();
        // The pedestal first (printed first), then the part's features in build order.
        let reports: Vec<FeatureReport> = checked
            .pedestal
            .as_ref()
            .map(|p| pedestal_report(p.report(filament_area), &checked, program))
            .into_iter()
            .chain(
                features
                    .into_iter()
                    .map(|f| feature_report(f, &checked, program)),
            )
            .collect();
        // The part's warnings: the lay stage's, extraction's, the post's, then what the
        // gates let pass.
        let mut all = warnings;
        all.extend(extracted.warnings.iter().cloned());
        all.extend(
            extracted
                .assembly
                .all_warnings()
                .into_iter()
                .map(|w| Warning::part(WarningKind::Extraction(w))),
        );
        all.extend(checked.part_warnings.iter().cloned());
        if let Some(p) = program {
            all.extend(
                p.warnings
                    .iter()
                    .map(|w| Warning::part(WarningKind::Post(w.clone()))),
            );
        }
        all.extend(passed.warnings);
        let report = PlanReport {
            schema: PLAN_SCHEMA,
            source: options.source.clone(),
            machine: machine.name.clone(),
            slicing: extracted.slicing.as_str(),
            complete: passed.complete,
            support_features: crate::report::support_features(&reports),
            features: reports,
            skirt_brim: adhesion,
            warnings: texts(&all),
            estimated_time_s: round(est.time_s, 1e1),
            filament_mm: round(est.filament_mm, 1e2),
            filament_g: round(est.filament_g, 1e2),
            feed_clamped_moves: program.and_then(|p| p.feed_clamped_moves),
            settings,
            placement,
            moved_on_table: posted.and_then(|p| p.moved).map(|m| MovedEntry {
                part_position: m.part_position.map(|x| round(x, 1e3)),
                distance_mm: round(m.distance_mm, 1e3),
                unreachable_before: m.unreachable_before,
            }),
            failures: vec![],
            outputs: vec![],
        };
        Plan {
            report,
            toolpath: checked.toolpath,
            program: vec![],
            assembly: extracted.assembly,
            collisions: checked.avoided,
            part_warnings: all,
            allowance_left,
        }
    }
}

/// The pedestal's report, with what the head check and the post found of it.
fn pedestal_report(
    mut r: FeatureReport,
    checked: &Checked,
    program: Option<&Program>,
) -> FeatureReport {
    let id = r.feature.id;
    r.points = checked.points.get(&id).copied().unwrap_or(0);
    r.collision = checked.collisions.get(&id).cloned().unwrap_or_default();
    r.post = program.and_then(|p| p.figures.get(&id)).map(post_entry);
    r
}

/// What the post measured of one feature, as reported.
fn post_entry(k: &PostFigures) -> PostEntry {
    match k {
        PostFigures::Delta5(k) => PostEntry::delta5(k),
        PostFigures::Kuka(k) => PostEntry::kuka(k),
    }
}

/// One feature's report from what the stages made of it.
fn feature_report(f: LaidFeature, checked: &Checked, program: Option<&Program>) -> FeatureReport {
    let id = f.planned.id;
    let mut warnings = f.warnings;
    warnings.extend(
        checked
            .warnings
            .iter()
            .filter(|w| w.feature == Some(id))
            .cloned(),
    );
    FeatureReport {
        feature: f.entry,
        layers: f.layers,
        points: checked.points.get(&id).copied().unwrap_or(0),
        print_length_mm: round(f.print_length, 1e3),
        travel_length_mm: round(f.travel_length, 1e3),
        extruded_volume_mm3: round(f.extruded, 1e3),
        expected_volume_mm3: round(f.planned.expected(), 1e3),
        sparse_volume_mm3: round(f.planned.sparse, 1e3),
        widened_volume_mm3: round(f.widened, 1e3),
        support_volume_mm3: round(f.support_volume, 1e3),
        below_resolution: f
            .below_resolution
            .map(|b| crate::resolution::BelowResolution {
                narrowest_mm: round(b.narrowest_mm, 1e3),
                nozzle_needed_mm: round(b.nozzle_needed_mm, 1e3),
                narrow_share: round(b.narrow_share, 1e4),
                tolerance_pct: round(b.tolerance_pct, 1e2),
            }),
        thickness_min_mm: round(f.thickness.0, 1e6),
        thickness_mean_mm: round(f.thickness.1, 1e6),
        thickness_max_mm: round(f.thickness.2, 1e6),
        unsupported_area_mm2: round(f.held.map_or(0.0, |h| h.support.area_mm2), 1e3),
        freeform: f.freeform.map(|ff| FreeformEntry {
            chart: ff.chart.as_str().to_string(),
            overhang_points: ff.overhang_points,
            concave_radius_mm: ff
                .concave_radius
                .is_finite()
                .then(|| round(ff.concave_radius, 1e3)),
            layer_strategy: ff.layers.as_str().to_string(),
        }),
        warnings: texts(&warnings),
        orientation: checked.orientation.get(&id).map(|o| OrientationFigures {
            step_max_deg_before: round(o.step_max_deg_before, 1e6),
            step_max_deg_after: round(o.step_max_deg_after, 1e6),
            rate_max_deg_per_mm_before: round(o.rate_max_deg_per_mm_before, 1e6),
            rate_max_deg_per_mm_after: round(o.rate_max_deg_per_mm_after, 1e6),
        }),
        post: program.and_then(|p| p.figures.get(&id)).map(post_entry),
        collision: checked.collisions.get(&id).cloned().unwrap_or_default(),
        pedestal_height_mm: None,
        machining_allowance: f.allowance.map(|a| crate::report::AllowanceEntry {
            requested_mm: a.requested,
            min_mm: round(a.min, 1e3),
            max_mm: round(a.max, 1e3),
            samples: a.samples,
            thinnest_at: a.thinnest_at.map(|x| round(x, 1e3)),
            grown_volume_mm3: round(f.grown.as_ref().map_or(0.0, |g| g.volume), 1e3),
            layered_volume_mm3: f
                .grown
                .as_ref()
                .and_then(|g| g.layered_volume)
                .map(|v| round(v, 1e3)),
            folds: f.grown.as_ref().map_or(0, |g| g.folds.len()),
        }),
    }
}
