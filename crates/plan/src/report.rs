//! The plan's report, `plan.json` (schema `features.plan/1`): what was planned for each feature
//! and what the post found. These types *are* the schema: serialising them writes the file.

use features::{Feature, FeatureTree};
use robot_post::delta5::KinematicFigures;
use robot_post::kuka::KukaFigures;
use serde::Serialize;
use slicer::orient::OrientationFigures;

/// Schema name of `plan.json`.
pub const PLAN_SCHEMA: &str = "features.plan/1";

/// `x` rounded to `1 / scale` (`scale` a power of ten), never `-0`.
pub fn round(x: f64, scale: f64) -> f64 {
    (x * scale).round() / scale + 0.0
}

/// A feature's reference, as reported.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReferenceEntry {
    /// `build_plate`, or the kind of the host face's surface.
    pub surface: String,
    /// STEP `#id` of the host face.
    pub step_face: Option<u64>,
    /// Unit normal into the feature (planes and the build plate), rounded to 1e-6.
    pub normal: Option<[f64; 3]>,
}

/// What a feature is: the fields `features extract --json` and `plan.json` share.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeatureEntry {
    /// File-wide id.
    pub id: usize,
    /// `two5d`, `freeform`, or `pedestal` (the prism under the part, [`crate::pedestal`]).
    pub kind: String,
    /// What it looks like (`stretch`, `brep_freeform`, ...).
    pub subtype: String,
    /// What it is built on.
    pub reference: ReferenceEntry,
    /// File-wide ids of the features it is built on.
    pub parents: Vec<usize>,
    /// Solid volume, mm³, rounded to 1e-3.
    pub volume_mm3: f64,
    /// STEP `#id`s of its faces (none for a mesh's body: its triangles are no STEP faces).
    pub faces: Vec<u64>,
    /// Concave loops at its root.
    pub root_loops: usize,
}

impl FeatureEntry {
    /// Feature `f` of `tree`, its ids numbered from `offset` (the features of earlier solids).
    pub fn new(tree: &FeatureTree, f: &Feature, offset: usize) -> FeatureEntry {
        let r = &f.reference;
        FeatureEntry {
            id: offset + f.id,
            kind: f.kind.as_str().to_string(),
            subtype: f.subtype.clone(),
            reference: ReferenceEntry {
                surface: r.surface.clone(),
                step_face: r.step_face,
                normal: r.normal.map(|n| n.map(|x| round(x, 1e6))),
            },
            parents: f.parents.iter().map(|p| offset + p).collect(),
            volume_mm3: round(f.volume, 1e3),
            faces: match tree.brep.origin {
                brep::topology::Origin::Step => f.step_faces(&tree.brep),
                brep::topology::Origin::Mesh => vec![],
            },
            root_loops: f.root_loops,
        }
    }
}

/// What the freeform planner reports of a curved feature.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FreeformEntry {
    /// `native` (the surface's parameters) or `projection` (tangent-plane chart).
    pub chart: String,
    /// Print points with nothing under them.
    pub overhang_points: usize,
    /// Smallest concave radius of the reference under the feature, mm; `null` when none.
    pub concave_radius_mm: Option<f64>,
    /// The layers it got: `offset` (offsets of the reference surface) or `transition`
    /// (morphing the base into the top; `layer_strategy`).
    pub layer_strategy: String,
}

/// What the post found for one feature, by machine.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum PostEntry {
    /// 5-axis printer: kinematic error of the posted moves.
    Delta5 {
        /// Largest deviation of a posted move from the planned path, mm.
        kinematic_error_max_mm: f64,
        /// Mean deviation, mm.
        kinematic_error_mean_mm: f64,
        /// Print segments subdivided to bound the error.
        subdivided_segments: usize,
        /// Points where C is undefined (axis along B's singular direction).
        singular_points: usize,
        /// Largest C step between consecutive moves, degrees.
        c_step_max_deg: f64,
    },
    /// KUKA cell: reach and wrist checks.
    Kuka {
        /// Points the robot cannot reach.
        unreachable_points: usize,
        /// Points in or near the wrist singularity.
        wrist_singular_points: usize,
        /// Changes of arm configuration along the path.
        configuration_changes: usize,
    },
}

impl PostEntry {
    /// The delta5 post's figures, rounded as reported.
    pub fn delta5(k: &KinematicFigures) -> PostEntry {
        PostEntry::Delta5 {
            kinematic_error_max_mm: round(k.max_mm, 1e6),
            kinematic_error_mean_mm: round(k.mean_mm, 1e6),
            subdivided_segments: k.subdivided_segments,
            singular_points: k.singular_points,
            c_step_max_deg: round(k.max_c_step_deg, 1e6),
        }
    }

    /// The KUKA post's figures.
    pub fn kuka(k: &KukaFigures) -> PostEntry {
        PostEntry::Kuka {
            unreachable_points: k.unreachable_points,
            wrist_singular_points: k.wrist_singular_points,
            configuration_changes: k.configuration_changes,
        }
    }
}

/// One feature in `plan.json`: what it is, what was planned, what smoothing and the post found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeatureReport {
    /// What the feature is.
    #[serde(flatten)]
    pub feature: FeatureEntry,
    /// Layers that print.
    pub layers: usize,
    /// Tool path points.
    pub points: usize,
    /// Printed length, mm.
    pub print_length_mm: f64,
    /// Travel length, mm.
    pub travel_length_mm: f64,
    /// Bead volume planned for the feature (Eq. 1 filament × filament area), mm³: what the
    /// self-check compares with the feature's volume.
    pub extruded_volume_mm3: f64,
    /// What the self-check expects it to extrude, mm³: the volume laid solid × `filling_ratio`
    /// and the volume of its layers laid sparse (issue 33) × the infill's density
    /// (`slicer::verify::PlannedFeature::expected`); the check passes within ±3 %.
    pub expected_volume_mm3: f64,
    /// Volume of its layers laid as sparse infill, mm³ (each layer's sparse area × its
    /// thickness, planar or curved); 0 when solid.
    pub sparse_volume_mm3: f64,
    /// Bead volume added over that by widening beads narrower than the machine's
    /// `min_bead_width` to it, mm³ (the program lays both).
    pub widened_volume_mm3: f64,
    /// Bead volume of support material laid with its planar layers, mm³ (issue 33; the
    /// program lays it, the self-check leaves it out); 0 without support.
    pub support_volume_mm3: f64,
    /// Set when the feature is below the nozzle's resolution (a share of it narrower than
    /// `min_bead_width`): its narrowest width and the nozzle it would need
    /// ([`crate::resolution`]); `null` otherwise.
    pub below_resolution: Option<crate::resolution::BelowResolution>,
    /// Thinnest layer, mm.
    pub thickness_min_mm: f64,
    /// Mean layer, mm.
    pub thickness_mean_mm: f64,
    /// Thickest layer, mm.
    pub thickness_max_mm: f64,
    /// Area of its layers that nothing holds up within the overhang limit
    /// (`overhang_angle_deg`), summed over its layers, mm² rounded to 1e-3; 0 when supported
    /// (issue 31, [`crate::support`]), by the layers below or by support material.
    pub unsupported_area_mm2: f64,
    /// Curved features only.
    #[serde(flatten)]
    pub freeform: Option<FreeformEntry>,
    /// Things to know about this feature.
    pub warnings: Vec<String>,
    /// Tool-axis smoothing before and after (features with points).
    #[serde(flatten)]
    pub orientation: Option<OrientationFigures>,
    /// The post's figures (delta5 and KUKA).
    #[serde(flatten)]
    pub post: Option<PostEntry>,
    /// Moves of the head into material or the table left after avoidance.
    #[serde(flatten)]
    pub collision: CollisionEntry,
    /// The pedestal's height, mm (the `pedestal` feature only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pedestal_height_mm: Option<f64>,
    /// The machining allowance asked for and left (issue 37, item 2); absent without one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub machining_allowance: Option<AllowanceEntry>,
}

/// A grown feature's machining allowance in `plan.json` (issue 37, item 2): what was asked,
/// the grown solid planned, and what the beads leave over the nominal faces
/// ([`slicer::allowance`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AllowanceEntry {
    /// `machining_allowance`, mm.
    pub requested_mm: f64,
    /// Least allowance the beads leave over a nominal face, mm (at least the allowance less
    /// the tolerance where the plan keeps it).
    pub min_mm: f64,
    /// Most, mm.
    pub max_mm: f64,
    /// Nominal points measured.
    pub samples: usize,
    /// Where the least was measured (nominal point, mm).
    pub thinnest_at: [f64; 3],
    /// Volume of the grown solid planned instead of the nominal one, mm³.
    pub grown_volume_mm3: f64,
    /// Planar layers: the volume of the layers that cover it (each the union of its sections
    /// over its thickness, the stair-steps kept outside the allowance), mm³; what the
    /// self-check expects. `null` for curved layers, checked against the grown solid's.
    pub layered_volume_mm3: Option<f64>,
    /// Places where the offset folded over itself (a concave radius under the allowance),
    /// filled as a larger allowance.
    pub folds: usize,
}

/// A feature's colliding moves (issue 18): the moves, print or travel, whose swept head meets
/// material deposited before them or the table.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct CollisionEntry {
    /// Colliding moves.
    pub collisions: usize,
    /// The first of them; `null` when none.
    pub first_collision: Option<FirstCollision>,
    /// Print moves that collided with the tool axes as smoothed and are clear with the axes
    /// tilted inside the orientation's tolerance cone (not counted in `collisions`).
    pub collisions_cleared_by_tilt: usize,
}

/// Where the first colliding move of a feature meets what.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FirstCollision {
    /// Tip position (part coordinates, mm, rounded to 1e-3) where the head meets it.
    pub position: [f64; 3],
    /// The feature id whose material it meets, or `"table"`.
    pub hits: HitEntry,
}

/// What a colliding move hits: a feature id, or a name (`"table"`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum HitEntry {
    /// Material of this feature.
    Feature(usize),
    /// Something not a feature: `"table"`.
    Named(String),
}

/// The settings a plan was made with: the planner's version and the full process and machine
/// tables (every key, defaults included), so that a plan can be made again.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SettingsEntry {
    /// The version of the planner (the `features` workspace).
    pub version: &'static str,
    /// `defaults` (every layer parameter), `features` (each overridden feature's full
    /// parameters, by id) and `orientation` (smoothing).
    pub process: serde_json::Value,
    /// The machine profile, every key.
    pub machine: serde_json::Value,
}

impl SettingsEntry {
    /// The settings as `key = value` lines (`process.defaults.tolerance = 0.05`,
    /// `machine.nozzle_diameter = 0.4`) for programs' headers, after the version line.
    pub fn lines(&self) -> Vec<String> {
        fn flatten(prefix: &str, v: &serde_json::Value, out: &mut Vec<String>) {
            match v {
                serde_json::Value::Object(m) => {
                    for (k, x) in m {
                        flatten(&format!("{prefix}.{k}"), x, out);
                    }
                }
                serde_json::Value::Null => {}
                x => out.push(format!("{prefix} = {x}")),
            }
        }
        let mut out = vec![format!("features {}", self.version)];
        flatten("process", &self.process, &mut out);
        flatten("machine", &self.machine, &mut out);
        out
    }
}

/// How the part was turned to stand on the build plate (`--base-face`, `--orient auto`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlacementEntry {
    /// STEP `#id` of the planar face put on the plate; `null`: the part stands as modelled
    /// (turned about +Z only).
    pub base_face: Option<u64>,
    /// Its outward normal in the file's frame: the direction turned to −Z.
    pub down: [f64; 3],
    /// The rotation applied about the file's origin (rows first): plate = rotation × file.
    pub rotation: [[f64; 3]; 3],
    /// Why this face: `base-face` (chosen), the `auto` rule and its figures, or the placement
    /// found after the part as modelled was refused ([`crate::retry`]).
    pub rule: String,
    /// The turn about +Z (degrees, counter-clockwise seen from above) after the face was
    /// turned down, to fit the bed or work envelope; 0 when none.
    #[serde(skip_serializing_if = "is_zero")]
    pub turn_deg: f64,
    /// The placements tried before this one and what each failed on ([`crate::retry`]), the
    /// part as modelled first.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub tried: Vec<TriedEntry>,
}

/// A placement tried and what refused it (`placement.tried` in `plan.json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TriedEntry {
    /// The placement, e.g. `the part as modelled`, `face #342 (outward normal 0 0 1 down)`.
    pub candidate: String,
    /// The refusal's line.
    pub failure: String,
}

/// Whether `x` is 0 (a field left out of `plan.json`).
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// One reason a plan was refused, where it is (`failures` in `plan.json`, on a refused plan).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FailureEntry {
    /// The gate that refused it: `selfcheck`, `collisions`, `machine`, `reach` or `strict`.
    pub gate: &'static str,
    /// The feature it is about; `null`: the whole plan.
    pub feature: Option<usize>,
    /// Where (part coordinates, mm, rounded to 1e-3): the first colliding move's contact; `null`
    /// where the gate names no place.
    pub position: Option<[f64; 3]>,
    /// What it is, one line.
    pub text: String,
}

/// Where the plan moved the part on a KUKA cell's table to bring every point into reach.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MovedEntry {
    /// The cell's `part_position` the program is written for (`$BASE` X, Y, mm).
    pub part_position: [f64; 2],
    /// How far from the profile's place, mm.
    pub distance_mm: f64,
    /// Points out of reach at the profile's place.
    pub unreachable_before: usize,
}

/// The skirt and brim laid on the first layer (issue 33, [`crate::adhesion`]): `plan.json`'s
/// `skirt_brim`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AdhesionEntry {
    /// Skirt loops laid (one per island of the first layer that lies apart from the others).
    pub skirt_loops: usize,
    /// Brim loops laid.
    pub brim_loops: usize,
    /// Their points in the tool path (in no feature's `points`).
    pub points: usize,
    /// Their bead length, mm.
    pub length_mm: f64,
    /// Their bead volume, mm³ (not the part's: the self-check leaves it out).
    pub volume_mm3: f64,
}

/// A support feature (issue 37 item 3): the support material under one feature, which is its
/// child (built on it, layer by layer with it).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SupportFeatureEntry {
    /// File-wide id: after the part's features and the pedestal.
    pub id: usize,
    /// `support`.
    pub kind: &'static str,
    /// The features it carries (file-wide ids).
    pub children: Vec<usize>,
    /// Its bead volume, mm³ (the children's `support_volume_mm3`).
    pub volume_mm3: f64,
}

/// A support feature for each feature of `features` with support material, numbered after
/// the highest of their ids.
pub fn support_features(features: &[FeatureReport]) -> Vec<SupportFeatureEntry> {
    let next = features.iter().map(|f| f.feature.id + 1).max().unwrap_or(0);
    features
        .iter()
        .filter(|f| f.support_volume_mm3 > 0.0)
        .enumerate()
        .map(|(k, f)| SupportFeatureEntry {
            id: next + k,
            kind: "support",
            children: vec![f.feature.id],
            volume_mm3: f.support_volume_mm3,
        })
        .collect()
}

/// `plan.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanReport {
    /// [`PLAN_SCHEMA`].
    pub schema: &'static str,
    /// The STEP file, as given.
    pub source: String,
    /// The machine profile's name.
    pub machine: String,
    /// How the part was sliced: `features` (each recognised feature on its own reference) or
    /// `planar` (each solid whole, in planar layers along +Z); the process key `slicing`.
    pub slicing: &'static str,
    /// Whether every feature passed the self-check.
    pub complete: bool,
    /// Every feature, in build order.
    pub features: Vec<FeatureReport>,
    /// Support material as features of the model (issue 37, the seed's `support_structure`):
    /// one for each feature support material carries, with that feature as its child; laid
    /// with it, layer by layer ([`SupportFeatureEntry`]).
    pub support_features: Vec<SupportFeatureEntry>,
    /// The skirt and brim laid before the part (Marlin; absent when none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub skirt_brim: Option<AdhesionEntry>,
    /// Things to know about the plan.
    pub warnings: Vec<String>,
    /// Estimated printing time, s ([`crate::estimate`]: each move at its speed).
    pub estimated_time_s: f64,
    /// Filament fed, mm.
    pub filament_mm: f64,
    /// Its mass, g (`filament_density`, PLA's 1.24 g/cm³ by default).
    pub filament_g: f64,
    /// Print moves the delta5 post slowed to the machine's `max_feed_mm_min` (a warning too
    /// when more than 1 % of them); absent for other machines.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub feed_clamped_moves: Option<usize>,
    /// The settings the plan was made with.
    pub settings: SettingsEntry,
    /// How the part was turned onto the plate, when it was (set by the caller that turned it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub placement: Option<PlacementEntry>,
    /// Where the part was moved on a KUKA table into reach, when it was.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub moved_on_table: Option<MovedEntry>,
    /// Why the plan was refused, when it was (then `complete` is false and no program was
    /// written).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub failures: Vec<FailureEntry>,
    /// The files the plan was written to, beside `plan.json` (set by whoever writes them; the
    /// command line lists them so that the next plan there replaces them, its stale files
    /// removed).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub outputs: Vec<String>,
}

impl PlanReport {
    /// Every warning of the plan once, in order: the part's, then each feature's that the
    /// part's list does not already hold.
    pub fn every_warning(&self) -> Vec<&str> {
        let mut out: Vec<&str> = vec![];
        let all = self
            .warnings
            .iter()
            .chain(self.features.iter().flat_map(|f| f.warnings.iter()));
        for w in all {
            if !out.contains(&w.as_str()) {
                out.push(w);
            }
        }
        out
    }

    /// Points the robot cannot reach, over every feature (KUKA plans; 0 otherwise).
    pub fn unreachable_points(&self) -> usize {
        self.features
            .iter()
            .map(|f| match f.post {
                Some(PostEntry::Kuka {
                    unreachable_points, ..
                }) => unreachable_points,
                _ => 0,
            })
            .sum()
    }

    /// The report as pretty JSON with a final newline.
    pub fn to_json(&self) -> Result<String, serde_json::Error> {
        let mut text = serde_json::to_string_pretty(self)?;
        text.push('\n');
        Ok(text)
    }
}
