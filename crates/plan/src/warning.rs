//! What a plan warns of ([`Warning`]): typed where the plan makes it, its text made only when
//! it is shown (`plan.json`, stderr).

use slicer::verify::PlanProblem;

/// How the warning of a feature reaching below the build plate ends
/// ([`WarningKind::BelowPlate`]).
pub const BELOW_PLATE: &str = "below the build plate";

/// One thing to know about a plan: of a feature (its file-wide id) or of the whole part.
#[derive(Debug, Clone, PartialEq)]
pub struct Warning {
    /// The feature it is about; `None`: the part.
    pub feature: Option<usize>,
    /// What it is.
    pub kind: WarningKind,
}

/// What a [`Warning`] says.
#[derive(Debug, Clone, PartialEq)]
pub enum WarningKind {
    /// A feature's planner said this (the slicer's own warnings).
    Planner(String),
    /// The STEP reader said this of the file (skipped header lines, unknown entities, faces
    /// turned round, edge ends off their curves).
    Reader(String),
    /// Extraction said this of the part (overlapping or floating solids, kept loops).
    Extraction(String),
    /// The post said this of the program.
    Post(String),
    /// Transition layers chosen by `auto` missed the feature's volume by `missed` (a share):
    /// the feature got offset layers.
    OffsetLayers {
        /// What the transition layers missed the volume by, a share (−0.05: 5 % short).
        missed: f64,
    },
    /// Beads narrower than the machine's `min_bead_width` were widened to it.
    Widened {
        /// Print points widened.
        points: usize,
        /// Print points of the feature.
        prints: usize,
        /// `min_bead_width`, mm.
        min_bead: f64,
        /// The narrowest bead before widening, mm.
        thinnest: f64,
        /// Volume added, mm³.
        added_mm3: f64,
        /// The feature's planned volume, mm³.
        extruded_mm3: f64,
    },
    /// Some of the feature lies below the build plate.
    BelowPlate {
        /// How far, mm.
        depth: f64,
    },
    /// Tool axes were tilted towards +Z to stay within a B/C bed's B limit.
    TiltLimited {
        /// Axes tilted.
        axes: usize,
        /// The largest tilt, degrees.
        worst_deg: f64,
        /// The B limit, degrees.
        limit_deg: f64,
    },
    /// The self-check failed for the feature and `keep_going` wrote the plan anyway.
    SelfCheck(PlanProblem),
    /// The head collides and `allow_collisions` wrote the plan anyway: the feature's line.
    Collisions(String),
    /// Layers nothing holds up and `keep_going` wrote the plan anyway: the feature's line.
    Unsupported(String),
    /// The part's solids overlap (bodies pushed into each other): `slicing = "auto"` planned
    /// it whole in planar layers, each layer the union of the solids' sections; feature by
    /// feature, each solid is planned whole and the material they share is laid twice.
    OverlappingSolids,
    /// A recognised feature grows along another direction than +Z on a machine that prints
    /// only along +Z: `slicing = "auto"` planned the part whole in planar layers.
    PlanarInstead {
        /// The recognised feature's file-wide id.
        feature: usize,
        /// Its kind (`two5d`, `freeform`).
        kind: &'static str,
        /// The unit direction it grows along, where one is known.
        along: Option<[f64; 3]>,
    },
}

impl Warning {
    /// A warning of feature `id`.
    pub fn feature(id: usize, kind: WarningKind) -> Warning {
        Warning {
            feature: Some(id),
            kind,
        }
    }

    /// A warning of the whole part.
    pub fn part(kind: WarningKind) -> Warning {
        Warning {
            feature: None,
            kind,
        }
    }
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let id = self.feature.unwrap_or_default();
        match &self.kind {
            WarningKind::Planner(t)
            | WarningKind::Reader(t)
            | WarningKind::Extraction(t)
            | WarningKind::Post(t)
            | WarningKind::Collisions(t)
            | WarningKind::Unsupported(t) => f.write_str(t),
            WarningKind::OffsetLayers { missed } => write!(
                f,
                "feature {id}: offset layers, not transition layers: these missed its volume by {:+.2} %",
                100.0 * missed
            ),
            WarningKind::Widened {
                points,
                prints,
                min_bead,
                thinnest,
                added_mm3,
                extruded_mm3,
            } => write!(
                f,
                "feature {id}: {:.1} % of its print points ({points} of {prints}) lay beads narrower than min_bead_width {min_bead} mm, down to {thinnest:.3} mm: widened to {min_bead} mm, {added_mm3:.1} mm^3 more than planned ({:.1} % of the feature's {extruded_mm3:.1} mm^3)",
                100.0 * *points as f64 / (*prints).max(1) as f64,
                100.0 * added_mm3 / extruded_mm3.max(crate::tolerance::VOLUME_MM3)
            ),
            WarningKind::BelowPlate { depth } => {
                write!(f, "feature {id} reaches {depth:.3} mm {BELOW_PLATE}")
            }
            WarningKind::TiltLimited {
                axes,
                worst_deg,
                limit_deg,
            } => write!(
                f,
                "feature {id}: {axes} tool axes tilted by up to {worst_deg:.3} degrees towards +Z to stay within the machine's B limit of {limit_deg} degrees"
            ),
            WarningKind::SelfCheck(p) => write!(f, "{p}"),
            WarningKind::OverlappingSolids => f.write_str(
                "the part's solids overlap: planned whole in planar layers along +Z, each layer \
                 the union of their sections (feature by feature, the material they share would \
                 be laid twice; unite them in CAD to plan their features)",
            ),
            WarningKind::PlanarInstead {
                feature,
                kind,
                along,
            } => {
                // Rounded first, so that no "-0.000" is written.
                let r = |x: f64| (x * 1e3).round() / 1e3 + 0.0;
                match along {
                    Some(d) => write!(
                        f,
                        "feature {feature} ({kind}) grows along ({:.3}, {:.3}, {:.3})",
                        r(d[0]),
                        r(d[1]),
                        r(d[2])
                    )?,
                    None => write!(f, "feature {feature} ({kind}) grows from a curved surface")?,
                }
                f.write_str(": planned with the part in planar layers along +Z; a 5-axis machine (delta5, kuka) prints it without support")
            }
        }
    }
}

/// The warnings' texts, in order.
pub fn texts(warnings: &[Warning]) -> Vec<String> {
    warnings.iter().map(Warning::to_string).collect()
}
