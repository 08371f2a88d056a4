//! A plan checks itself: every feature it lists got layers, and puts down the material the
//! feature holds. A plan that silently loses material is the worst defect a planner can ship.

/// How far a feature's extruded volume may stray from what it should be, as a fraction.
pub const VOLUME_TOLERANCE: f64 = 0.03;

/// What went wrong with one feature's plan.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanProblem {
    /// Nothing was laid down.
    #[error("feature {id} ({kind}): no layer planned for its {volume:.3} mm^3")]
    NoLayers {
        /// Feature id in the plan.
        id: usize,
        /// `two5d` or `freeform`.
        kind: String,
        /// The feature's volume, mm³.
        volume: f64,
    },
    /// The extruded volume is off by more than the feature's tolerance ([`VOLUME_TOLERANCE`]
    /// unless it is below the nozzle's resolution).
    #[error(
        "feature {id} ({kind}): {extruded:.3} mm^3 extruded for {expected:.3} mm^3 expected ({}), {percent:+.2} %",
        model(*.volume, *.fill, *.sparse, *.density)
    )]
    Volume {
        /// Feature id in the plan.
        id: usize,
        /// `two5d` or `freeform`.
        kind: String,
        /// The feature's volume, mm³.
        volume: f64,
        /// The fill it was planned with (`filling_ratio`).
        fill: f64,
        /// The volume of its layers laid sparse, mm³ ([`PlannedFeature::sparse`]).
        sparse: f64,
        /// The sparse infill's density ([`PlannedFeature::density`]).
        density: f64,
        /// What it should put down ([`PlannedFeature::expected`]), mm³.
        expected: f64,
        /// What the plan puts down, mm³.
        extruded: f64,
        /// `(extruded − expected) / expected`, in percent.
        percent: f64,
    },
}

/// How the expected volume is made, for [`PlanProblem::Volume`]'s message: `volume V mm^3 x
/// fill f`, and with sparse infill `(volume V − sparse S) mm^3 x fill f + S mm^3 x density d`.
fn model(volume: f64, fill: f64, sparse: f64, density: f64) -> String {
    if sparse > 0.0 {
        format!(
            "(volume {volume:.3} - sparse {sparse:.3}) mm^3 x fill {fill} + {sparse:.3} mm^3 x density {density:.4}"
        )
    } else {
        format!("volume {volume:.3} mm^3 x fill {fill}")
    }
}

impl PlanProblem {
    /// The id of the feature it is about.
    pub fn id(&self) -> usize {
        match self {
            PlanProblem::NoLayers { id, .. } | PlanProblem::Volume { id, .. } => *id,
        }
    }
}

/// What the plan did with one feature.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedFeature {
    /// Feature id in the plan.
    pub id: usize,
    /// `two5d` or `freeform`.
    pub kind: String,
    /// The feature's solid volume, mm³.
    pub volume: f64,
    /// Its `filling_ratio`: beads `w` wide laid `w / filling_ratio` apart cover that share of
    /// each layer, perimeters, skins and solid infill alike.
    pub fill: f64,
    /// The volume of its layers laid as sparse infill, mm³ (each layer's sparse area × its
    /// thickness, from the regions the planner filled; 0 without sparse infill).
    pub sparse: f64,
    /// The share of `sparse` its beads cover: `infill_density`, or the gyroid's mean over the
    /// feature's sparse layers (its lines are longer at some heights than at others).
    pub density: f64,
    /// Layers planned.
    pub layers: usize,
    /// Bead volume put down (Eq. 1 filament length × filament area), mm³.
    pub extruded: f64,
    /// How far `extruded` may stray from `volume × fill`, as a fraction: [`VOLUME_TOLERANCE`],
    /// or more for a feature below the nozzle's resolution (the plan crate's `resolution`
    /// module derives it from the share of the feature narrower than the nozzle lays).
    pub tolerance: f64,
    /// The least material the nozzle lays, mm³: a bead `min_bead_width` wide, as long and
    /// `min_layer_height` thick (0 for none). A miss smaller than that is below the nozzle's
    /// resolution, and so is a feature holding less (a sliver 0.01 mm thick, a face's
    /// 0.001 mm³ stretch): it passes with no layer, as the planner's warning that it has no
    /// printable layer says.
    pub smallest_bead: f64,
}

impl PlannedFeature {
    /// What the plan should put down, mm³: the solid part of the volume (perimeters, skins,
    /// solid infill) × `fill`, and the sparse part × `density`:
    /// `(volume − sparse) × fill + sparse × density`. The volume is the solid's own (not the
    /// layers' areas summed), so a lost layer or feature still shows.
    pub fn expected(&self) -> f64 {
        expected_volume(self.volume, self.fill, self.sparse, self.density)
    }
}

/// What a feature of `volume` mm³ laid at `fill` should put down, `sparse` mm³ of it as sparse
/// infill at `density`: `(volume − sparse) × fill + sparse × density`
/// ([`PlannedFeature::expected`]).
pub fn expected_volume(volume: f64, fill: f64, sparse: f64, density: f64) -> f64 {
    (volume - sparse) * fill + sparse * density
}

/// Checks one feature's plan: at least one layer, and extruded volume within its
/// `tolerance` (at least [`VOLUME_TOLERANCE`]) of [`PlannedFeature::expected`], unless what
/// it misses is no more than the smallest bead (`smallest_bead`).
pub fn check_planned(f: &PlannedFeature) -> Option<PlanProblem> {
    let expected = f.expected();
    let smallest = if f.smallest_bead.is_finite() {
        f.smallest_bead.max(0.0)
    } else {
        0.0
    };
    if (f.extruded - expected).abs() <= smallest {
        return None;
    }
    if f.layers == 0 || f.extruded <= 0.0 {
        return Some(PlanProblem::NoLayers {
            id: f.id,
            kind: f.kind.clone(),
            volume: f.volume,
        });
    }
    let rel = (f.extruded - expected) / expected.max(crate::tolerance::VOLUME_FLOOR);
    (rel.abs() > f.tolerance.max(VOLUME_TOLERANCE)).then(|| PlanProblem::Volume {
        id: f.id,
        kind: f.kind.clone(),
        volume: f.volume,
        fill: f.fill,
        sparse: f.sparse,
        density: f.density,
        expected,
        extruded: f.extruded,
        percent: rel * 100.0,
    })
}

/// Checks every feature of a plan; the problems in feature order.
pub fn check_plan(features: &[PlannedFeature]) -> Vec<PlanProblem> {
    features.iter().filter_map(check_planned).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f(layers: usize, extruded: f64, fill: f64) -> PlannedFeature {
        PlannedFeature {
            id: 3,
            kind: "freeform".into(),
            volume: 100.0,
            fill,
            sparse: 0.0,
            density: 1.0,
            layers,
            extruded,
            tolerance: VOLUME_TOLERANCE,
            smallest_bead: 0.0,
        }
    }

    #[test]
    fn a_feature_with_no_layer_is_a_problem() {
        assert!(matches!(
            check_planned(&f(0, 0.0, 1.0)),
            Some(PlanProblem::NoLayers { id: 3, .. })
        ));
        // Unless it holds less than the smallest bead: then no miss is above resolution.
        let speck = PlannedFeature {
            volume: 0.003,
            smallest_bead: 0.0058,
            ..f(0, 0.0, 1.0)
        };
        assert!(check_planned(&speck).is_none());
        let pin = PlannedFeature {
            volume: 0.02,
            ..speck
        };
        assert!(matches!(
            check_planned(&pin),
            Some(PlanProblem::NoLayers { .. })
        ));
    }

    #[test]
    fn ten_percent_short_is_a_problem_and_within_three_is_not() {
        let p = check_planned(&f(10, 90.0, 1.0)).expect("short");
        assert!(p.to_string().contains("-10.00 %"), "{p}");
        assert!(check_planned(&f(10, 102.9, 1.0)).is_none());
        assert!(check_planned(&f(10, 97.1, 1.0)).is_none());
        assert!(check_planned(&f(10, 103.1, 1.0)).is_some());
    }

    #[test]
    fn a_feature_below_resolution_is_judged_by_its_own_tolerance() {
        let wide = PlannedFeature {
            tolerance: 0.3,
            ..f(10, 75.0, 1.0)
        };
        assert!(check_planned(&wide).is_none());
        assert!(check_planned(&PlannedFeature {
            extruded: 65.0,
            ..wide.clone()
        })
        .is_some());
        // Never tighter than the plan's.
        let tight = PlannedFeature {
            tolerance: 0.0,
            ..f(10, 98.0, 1.0)
        };
        assert!(check_planned(&tight).is_none());
    }

    #[test]
    fn the_fill_sets_what_is_expected() {
        assert!(check_planned(&f(10, 80.0, 0.8)).is_none());
        assert!(check_planned(&f(10, 100.0, 0.8)).is_some());
        assert_eq!(check_plan(&[f(10, 80.0, 0.8), f(0, 0.0, 1.0)]).len(), 1);
    }

    /// Sparse infill: 60 of the 100 mm³ laid at density 0.2 should put down 40 + 12 mm³;
    /// the solid volume would be far off, and a lost layer's worth still shows.
    #[test]
    fn the_sparse_part_is_expected_at_its_density() {
        let sparse = |extruded| PlannedFeature {
            sparse: 60.0,
            density: 0.2,
            ..f(10, extruded, 1.0)
        };
        assert!((sparse(52.0).expected() - 52.0).abs() < 1e-9);
        assert!(check_planned(&sparse(52.0)).is_none());
        assert!(check_planned(&sparse(100.0)).is_some());
        let p = check_planned(&sparse(48.0)).expect("short by a layer");
        assert!(p.to_string().contains("sparse 60.000"), "{p}");
    }
}
