//! Layer parameters of a feature (the paper's per-feature process keys) and their defaults.
//!
//! A process file gives one [`LayerParams`] for the whole part and, per feature, a
//! [`LayerParamsPatch`] that overrides some keys ([`LayerParams::patched`]). Both read and write
//! with serde using the paper's key names (`layer_height_pattern`, `path_mode`, ...); enum values
//! are snake case (`uniform`, `contour_zigzag`). A misspelled key is an error, not a silent
//! default.

use crate::tolerance::{COUNT_SLACK, HEIGHT_SLACK, ZERO_AXIS};
use serde::{Deserialize, Serialize};

/// The most layers [`LayerParams::layer_heights`] returns; more means the parameters are wrong
/// (a 1 m part at 1 µm layers), and an empty list is returned instead of exhausting memory.
pub const MAX_LAYERS: usize = 1_000_000;

/// The default overhang limit, degrees from the build direction (issue 31): what FDM prints
/// without support on common materials (45° is the usual rule, 50–60° the usual reach).
pub const DEFAULT_OVERHANG_ANGLE_DEG: f64 = 50.0;

/// A piece of a stack between two steps of [`LayerParams::layer_heights_through`] within this
/// share of a whole number of layers (a model in inches) takes that many, a little thicker.
const STEP_COUNT_SLACK: f64 = 1e-3;

/// `overhang_angle_deg` must stay under this: at 90° a layer may reach out without limit.
pub const MAX_OVERHANG_ANGLE_DEG: f64 = 90.0;

/// Widest brim and farthest skirt (`brim_width_mm`, `skirt_distance_mm`), mm.
pub const MAX_ADHESION_MM: f64 = 100.0;

/// Largest `machining_allowance`, mm: more is a different part, not a workblank of this one.
pub const MAX_MACHINING_ALLOWANCE: f64 = 50.0;

/// Most skirt loops (`skirt_loops`).
pub const MAX_SKIRT_LOOPS: usize = 100;

/// How a planar layer is filled (the paper's `path_mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PathMode {
    /// Parallel lines in one direction, each a separate path, all printed the same way.
    Raster,
    /// The raster lines joined into continuous paths; the direction turns 90° every layer.
    Zigzag,
    /// Successive inward offsets of the boundary until the region is used up.
    Contour,
    /// `perimeters` offsets of the boundary, then zig-zag infill inside them.
    ContourZigzag,
}

/// The pattern of sparse infill (issue 33, the process key `infill_pattern`), laid where a
/// planar layer's interior is neither perimeter nor solid skin when `infill_density` < 1
/// ([`crate::fill::sparse`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InfillPattern {
    /// Parallel lines at `raster_angle_deg`, turned 90° every other layer (the default).
    #[default]
    Rectilinear,
    /// Lines in both directions on every layer, each direction twice as far apart.
    Grid,
    /// Lines in three directions 60° apart on every layer, each three times as far apart,
    /// crossing in common points (triangles).
    Triangles,
    /// The gyroid's section at the layer's height: wave lines that shift from layer to layer.
    Gyroid,
}

/// How layer thicknesses are chosen (the paper's `layer_height_pattern`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LayerHeightPattern {
    /// Every layer `uniform_layer_height` thick (adjusted so the top lands on the top).
    Uniform,
    /// Layer `i` is `adaptive_layer_height[i]` thick (the list repeats if it is short).
    Adaptive,
}

/// How a freeform feature's layers are shaped (issue 17, `layer_strategy`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LayerStrategy {
    /// Offsets of the reference surface (feature-based AM paper): exact where the feature's
    /// top is itself an offset; the top is cut by the last layers elsewhere.
    Offset,
    /// Transition layers that morph the base into the top (Isa & Lazoglu 2019, Eq. 4): the
    /// last layer lies on the top. An error where the top comes so close to the base that no
    /// number of layers keeps every point's thickness within
    /// `[min_layer_height, max_layer_height]`.
    Transition,
    /// Transition layers where the top is not an offset of the reference within `tolerance`
    /// and they can keep the thickness bounds; offset layers (with a warning saying why)
    /// where they cannot.
    Auto,
}

/// How the tool axis of a freeform feature's wall paths is chosen (issue 17,
/// `wall_orientation`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum WallOrientation {
    /// Along the layer surface's normal (TSN) like every other path.
    Normal,
    /// Side-surface tangent (SST, Isa & Lazoglu 2019, Eq. 3) on the outermost ring of each
    /// layer: perpendicular to the side surface's normal and the path's tangent.
    Sst,
}

/// Whether planar layers get support material where they overhang (issue 33, the process key
/// `support_material`): `"auto"` (the default) or `"off"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SupportMaterial {
    /// Columns under every overhang of a two5d feature's planar layers that can stand on the
    /// plate or on the feature's own lower layers ([`crate::support_material`]).
    Auto,
    /// No support: an overhang refuses the plan as the support check finds it.
    Off,
}

/// Whether the part stands on a printed pedestal (issue 31, the process key `pedestal`): a
/// prism under its build-plate face that lifts it off the table where the head would meet the
/// table. Written `"auto"`, `"off"` or a height in mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pedestal {
    /// The least whole number of layers that leaves no move of the head hitting the table,
    /// none when nothing hits it (the default).
    Auto,
    /// Never a pedestal.
    Off,
    /// A pedestal of this height (mm; rounded up to whole layers), 0 for none.
    Height(f64),
}

impl Serialize for Pedestal {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Pedestal::Auto => s.serialize_str("auto"),
            Pedestal::Off => s.serialize_str("off"),
            Pedestal::Height(h) => s.serialize_f64(*h),
        }
    }
}

impl<'de> Deserialize<'de> for Pedestal {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        /// A number or a word, as the file gives it.
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Given {
            Height(f64),
            Word(String),
        }
        match Given::deserialize(d)? {
            Given::Height(h) => Ok(Pedestal::Height(h)),
            Given::Word(w) => match w.as_str() {
                "auto" => Ok(Pedestal::Auto),
                "off" => Ok(Pedestal::Off),
                _ => Err(serde::de::Error::custom(format!(
                    "pedestal must be \"auto\", \"off\" or a height in mm, got \"{w}\""
                ))),
            },
        }
    }
}

/// How the part is cut into what is planned (issue 33, the process key `slicing`): the part's,
/// so set in `[defaults]` only.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Slicing {
    /// `features` on a machine that can tilt its tool axis; on one that prints only along +Z,
    /// `planar` when some feature grows along another direction (the default).
    #[default]
    Auto,
    /// Each recognised AM feature planned on its own reference (two5d or freeform layers).
    Features,
    /// Each solid planned whole as one two5d feature, in planar layers along +Z from its
    /// lowest point, as a planar slicer slices it.
    Planar,
}

impl<'de> Deserialize<'de> for Slicing {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let w = String::deserialize(d)?;
        match w.as_str() {
            "auto" => Ok(Slicing::Auto),
            "features" => Ok(Slicing::Features),
            "planar" => Ok(Slicing::Planar),
            _ => Err(serde::de::Error::custom(format!(
                "slicing must be \"auto\", \"features\" or \"planar\", got \"{w}\""
            ))),
        }
    }
}

impl Slicing {
    /// The name as written in a process file (`auto`, `features`, `planar`).
    pub fn as_str(self) -> &'static str {
        match self {
            Slicing::Auto => "auto",
            Slicing::Features => "features",
            Slicing::Planar => "planar",
        }
    }
}

/// Default `top_solid_layers`.
pub const DEFAULT_TOP_SOLID_LAYERS: usize = 4;
/// Default `bottom_solid_layers`.
pub const DEFAULT_BOTTOM_SOLID_LAYERS: usize = 3;
/// Default `solid_infill_below_area`, mm² (PrusaSlicer's).
pub const DEFAULT_SOLID_INFILL_BELOW_AREA: f64 = 70.0;

// The sparse-infill keys at their defaults are left out when the parameters are written (a
// program's header, plan.json), so a plan without sparse infill reads as it did before them.
fn is_one(x: &f64) -> bool {
    *x == 1.0
}
fn is_rectilinear(p: &InfillPattern) -> bool {
    *p == InfillPattern::Rectilinear
}
fn is_default_top(n: &usize) -> bool {
    *n == DEFAULT_TOP_SOLID_LAYERS
}
fn is_default_bottom(n: &usize) -> bool {
    *n == DEFAULT_BOTTOM_SOLID_LAYERS
}
fn is_default_below_area(a: &f64) -> bool {
    *a == DEFAULT_SOLID_INFILL_BELOW_AREA
}
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// Layer and path parameters of one feature.
///
/// Missing keys take their defaults when deserialising (`{}` is [`LayerParams::default`]);
/// unknown keys are an error.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(default, deny_unknown_fields)]
pub struct LayerParams {
    /// Geometric tolerance, mm (chords of curved boundaries and offsets). Default 0.05.
    pub tolerance: f64,
    /// Uniform or adaptive layer thickness. Default uniform.
    pub layer_height_pattern: LayerHeightPattern,
    /// Layer thickness for the uniform pattern, mm. Default 0.2.
    pub uniform_layer_height: f64,
    /// Thickness of successive layers for the adaptive pattern, mm. Default empty.
    pub adaptive_layer_height: Vec<f64>,
    /// Spacing between neighbouring path centre lines, mm; `None` (the default) means bead width
    /// divided by `filling_ratio`.
    pub uniform_offset: Option<f64>,
    /// Spacing per layer for the adaptive pattern, mm (repeats if short); empty (the default)
    /// means the uniform spacing on every layer.
    pub adaptive_offset: Vec<f64>,
    /// Fill pattern. Default `contour_zigzag`.
    pub path_mode: PathMode,
    /// Bead width over path spacing, in (0, 1]. Default 1 (beads touch).
    pub filling_ratio: f64,
    /// Number of perimeters for `contour_zigzag`. Default 2.
    pub perimeters: usize,
    /// Share of the sparse interior of planar layers that infill lines cover, in (0, 1]: lines
    /// `bead width / infill_density` apart in the `infill_pattern`, inside the perimeters, away
    /// from the solid skins. Default 1: no sparse infill, every layer solid (as before issue
    /// 33). Curved layers stay solid whatever it is.
    #[serde(skip_serializing_if = "is_one")]
    pub infill_density: f64,
    /// Pattern of sparse infill ([`InfillPattern`]). Default `rectilinear`.
    #[serde(skip_serializing_if = "is_rectilinear")]
    pub infill_pattern: InfillPattern,
    /// Layers of solid skin under every top surface of a planar feature (the part of a layer
    /// that one of the next `top_solid_layers` layers does not cover). Default 4.
    #[serde(skip_serializing_if = "is_default_top")]
    pub top_solid_layers: usize,
    /// Layers of solid skin over every bottom surface (the part of a layer that one of the
    /// `bottom_solid_layers` layers below does not cover). Default 3.
    #[serde(skip_serializing_if = "is_default_bottom")]
    pub bottom_solid_layers: usize,
    /// A piece of a layer's sparse interior smaller than this (mm²) is laid solid (as
    /// PrusaSlicer's key of that name): a pattern whose lines lie millimetres apart cannot
    /// lay its density in it. Default 70.
    #[serde(skip_serializing_if = "is_default_below_area")]
    pub solid_infill_below_area: f64,
    /// Direction of raster and zig-zag lines, degrees from +x. Default 45; zig-zag adds 90° on
    /// odd layers.
    pub raster_angle_deg: f64,
    /// Tool axis of every point of a freeform feature's curved layers: `None` (the default)
    /// puts it along the layer surface's normal at the point; a vector fixes it (the paper:
    /// "the direction could be constant for the entire layers if needed"). Normalised on use.
    pub fixed_tool_axis: Option<[f64; 3]>,
    /// Offset, transition or (the default) automatic choice of a freeform feature's layers.
    pub layer_strategy: LayerStrategy,
    /// Tool axis of wall paths: layer normal (the default) or side-surface tangent.
    pub wall_orientation: WallOrientation,
    /// Thinnest local thickness of a transition layer, mm. Default 0.1.
    pub min_layer_height: f64,
    /// Thickest local thickness of a transition layer, mm. Default 0.3.
    pub max_layer_height: f64,
    /// Overhang limit, degrees from the build direction: a layer's bead must lie within
    /// `h·tan(overhang_angle_deg)` of the layer below it (h the layer's thickness), or on
    /// material laid before, or on the plate ([`crate::support`]). Default 50.
    pub overhang_angle_deg: f64,
    /// Support material under the overhangs of planar layers ([`SupportMaterial`]). Default
    /// `auto`.
    pub support_material: SupportMaterial,
    /// Gap between the top of the support and the surface it holds, mm (≥ 0; rounded to whole
    /// layers). Default 0.2 (one layer).
    pub support_contact_distance: f64,
    /// Gap between the support and the part's section beside it, mm (≥ 0). Default 0.5.
    pub support_xy_distance: f64,
    /// Sparse support's bead width over line spacing, in (0, 1]. Default 0.2.
    pub support_density: f64,
    /// Denser layers at the top of the support, right under the held surface (0 for none).
    /// Default 2.
    pub support_interface_layers: usize,
    /// Those layers' bead width over line spacing, in (0, 1]. Default 0.7.
    pub support_interface_density: f64,
    /// The part's pedestal ([`Pedestal`]); the part's, so set in `[defaults]` only. Default
    /// `auto`.
    pub pedestal: Pedestal,
    /// How far the pedestal's outline lies inside the build-plate face's, mm (≥ 0). Default 0.
    pub pedestal_inset: f64,
    /// Skirt loops around the first layer (issue 33; Marlin programs), 0 for none; the part's,
    /// so set in `[defaults]` only. Default 1.
    pub skirt_loops: usize,
    /// Gap between the skirt and the first layer's outline (its brim included), mm (≥ 0).
    /// Default 6.
    pub skirt_distance_mm: f64,
    /// Brim: loops on the first layer touching the part's outline outward, this wide, mm (≥ 0,
    /// 0 for none; Marlin programs). Default 0.
    pub brim_width_mm: f64,
    /// Runs of print moves along a circle written as `G2`/`G3` within `tolerance` (Marlin
    /// programs; issue 33). Default false.
    pub arc_fitting: bool,
    /// How the part is cut into what is planned ([`Slicing`]); the part's, so set in
    /// `[defaults]` only. Default `auto`.
    pub slicing: Slicing,
    /// Machining allowance, mm (issue 37, item 2; the seed's `tolerance` read as "the
    /// machining allowance for the following post-process"): the feature's faces, but those on
    /// the build plate and those it grows from, are offset outward by this on their exact
    /// surfaces, neighbouring faces extended or trimmed to meet, and that grown solid is
    /// planned (`brep::mesh::offset`). Default 0 (the nominal part).
    #[serde(skip_serializing_if = "is_zero")]
    pub machining_allowance: f64,
    /// How far the feature's base lies above its reference surface: the `machining_allowance`
    /// of the feature it grows from, whose offset face it then stands on. Set by the planner
    /// from the parent's parameters, never read from a file.
    #[serde(skip)]
    pub base_allowance: f64,
}

impl Default for LayerParams {
    fn default() -> Self {
        LayerParams {
            tolerance: 0.05,
            layer_height_pattern: LayerHeightPattern::Uniform,
            uniform_layer_height: 0.2,
            adaptive_layer_height: Vec::new(),
            uniform_offset: None,
            adaptive_offset: Vec::new(),
            path_mode: PathMode::ContourZigzag,
            filling_ratio: 1.0,
            perimeters: 2,
            infill_density: 1.0,
            infill_pattern: InfillPattern::Rectilinear,
            top_solid_layers: DEFAULT_TOP_SOLID_LAYERS,
            bottom_solid_layers: DEFAULT_BOTTOM_SOLID_LAYERS,
            solid_infill_below_area: DEFAULT_SOLID_INFILL_BELOW_AREA,
            raster_angle_deg: 45.0,
            fixed_tool_axis: None,
            layer_strategy: LayerStrategy::Auto,
            wall_orientation: WallOrientation::Normal,
            min_layer_height: 0.1,
            max_layer_height: 0.3,
            overhang_angle_deg: DEFAULT_OVERHANG_ANGLE_DEG,
            support_material: SupportMaterial::Auto,
            support_contact_distance: 0.2,
            support_xy_distance: 0.5,
            support_density: 0.2,
            support_interface_layers: 2,
            support_interface_density: 0.7,
            pedestal: Pedestal::Auto,
            pedestal_inset: 0.0,
            skirt_loops: 1,
            skirt_distance_mm: 6.0,
            brim_width_mm: 0.0,
            arc_fitting: false,
            slicing: Slicing::Auto,
            machining_allowance: 0.0,
            base_allowance: 0.0,
        }
    }
}

impl LayerParams {
    /// Spacing between neighbouring path centre lines for a bead `bead_width` mm wide:
    /// `uniform_offset` if given, else `bead_width / filling_ratio`.
    ///
    /// Meaningful only for parameters that pass [`LayerParams::validate`].
    pub fn spacing(&self, bead_width: f64) -> f64 {
        match self.uniform_offset {
            Some(s) => s,
            None => bead_width / self.filling_ratio,
        }
    }

    /// True when planar layers get sparse infill: `infill_density` below 1 and a path mode
    /// with infill lines (every mode but `contour`, whose rings fill the whole layer).
    pub fn sparse_infill(&self) -> bool {
        self.infill_density < 1.0 && self.path_mode != PathMode::Contour
    }

    /// Spacing for layer number `layer`: with the adaptive pattern and a non-empty
    /// `adaptive_offset`, that list's entry for the layer (the list repeats); otherwise
    /// [`LayerParams::spacing`].
    pub fn spacing_for_layer(&self, bead_width: f64, layer: usize) -> f64 {
        match self.layer_height_pattern {
            LayerHeightPattern::Adaptive if !self.adaptive_offset.is_empty() => {
                self.adaptive_offset[layer % self.adaptive_offset.len()]
            }
            _ => self.spacing(bead_width),
        }
    }

    /// Thicknesses of successive layers stacking up to `extent` mm.
    ///
    /// - uniform: `n = ceil(extent / h - 1e-9)` layers of `extent / n` each, so the top of the
    ///   last layer lands on the top;
    /// - adaptive: the `adaptive_layer_height` list, repeated or cut short to cover `extent`,
    ///   the last layer trimmed to end on the top (a remainder under 1e-9 mm is merged into the
    ///   layer below rather than kept as a sliver).
    ///
    /// Empty when `extent` is not positive and finite, when the parameters fail
    /// [`LayerParams::validate`] for the heights, or when more than [`MAX_LAYERS`] layers would
    /// be needed.
    pub fn layer_heights(&self, extent: f64) -> Vec<f64> {
        if !(extent.is_finite() && extent > 0.0) {
            return Vec::new();
        }
        match self.layer_height_pattern {
            LayerHeightPattern::Uniform => {
                let h = self.uniform_layer_height;
                if !(h.is_finite() && h > 0.0) {
                    return Vec::new();
                }
                let n = (extent / h - COUNT_SLACK).ceil().max(1.0);
                if !n.is_finite() || n > MAX_LAYERS as f64 {
                    return Vec::new();
                }
                let n = n as usize;
                vec![extent / n as f64; n]
            }
            LayerHeightPattern::Adaptive => {
                let list = &self.adaptive_layer_height;
                if list.is_empty() || list.iter().any(|h| !(h.is_finite() && *h > 0.0)) {
                    return Vec::new();
                }
                let eps = HEIGHT_SLACK;
                let mut out = Vec::new();
                let mut z = 0.0;
                for &h in list.iter().cycle() {
                    let remaining = extent - z;
                    if remaining <= eps {
                        break;
                    }
                    if out.len() >= MAX_LAYERS {
                        return Vec::new();
                    }
                    let dl = h.min(remaining);
                    out.push(dl);
                    z += dl;
                }
                // Land exactly on the top: a sub-eps remainder goes into the last layer.
                if let Some(last) = out.last_mut() {
                    *last += extent - z;
                }
                out
            }
        }
    }

    /// [`LayerParams::layer_heights`] with a layer boundary at each height of `steps` (where a
    /// two5d feature's section changes at once: its faces parallel to the layers), for the
    /// uniform pattern: the stack is cut at those heights and each piece gets
    /// `n = ceil(piece / h − 0.001)` layers of `piece / n`. A slab 0.3 mm thick (a contact's
    /// pad, a clip's plate) took one layer of 0.2 mm or two (33 % short or over, the layer's
    /// middle deciding); it now takes two of 0.15 mm. A step nearer than `min_layer_height`
    /// (at most `h`) to the one kept before it or to the top is passed over: no layer is
    /// thinner than that, and what lies between is as quantised as before. The adaptive
    /// pattern keeps its list.
    pub fn layer_heights_through(&self, extent: f64, steps: &[f64]) -> Vec<f64> {
        let h = self.uniform_layer_height;
        let least = self.min_layer_height.min(h);
        if self.layer_height_pattern != LayerHeightPattern::Uniform
            || steps.is_empty()
            || !(least.is_finite() && least > 0.0 && extent.is_finite() && extent > 0.0)
        {
            return self.layer_heights(extent);
        }
        let mut steps: Vec<f64> = steps.iter().copied().filter(|s| s.is_finite()).collect();
        steps.sort_by(f64::total_cmp);
        let mut cuts = vec![];
        let mut last = 0.0;
        for s in steps {
            if s - last >= least && extent - s >= least {
                cuts.push(s);
                last = s;
            }
        }
        cuts.push(extent);
        let mut out = vec![];
        let mut a = 0.0;
        for b in cuts {
            let piece = b - a;
            let n = (piece / h - STEP_COUNT_SLACK).ceil().max(1.0);
            if !n.is_finite() || out.len() as f64 + n > MAX_LAYERS as f64 {
                return Vec::new();
            }
            out.extend(std::iter::repeat_n(piece / n, n as usize));
            a = b;
        }
        out
    }

    /// Checks the parameters; the error is one line naming the offending key.
    pub fn validate(&self) -> Result<(), String> {
        fn positive(key: &str, v: f64) -> Result<(), String> {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!("{key} must be a positive number of mm, got {v}"))
            }
        }
        positive("tolerance", self.tolerance)?;
        positive("uniform_layer_height", self.uniform_layer_height)?;
        for (i, &h) in self.adaptive_layer_height.iter().enumerate() {
            positive(&format!("adaptive_layer_height[{i}]"), h)?;
        }
        if self.layer_height_pattern == LayerHeightPattern::Adaptive
            && self.adaptive_layer_height.is_empty()
        {
            return Err(
                "adaptive_layer_height must list at least one height when layer_height_pattern is adaptive"
                    .to_string(),
            );
        }
        if let Some(s) = self.uniform_offset {
            positive("uniform_offset", s)?;
        }
        for (i, &s) in self.adaptive_offset.iter().enumerate() {
            positive(&format!("adaptive_offset[{i}]"), s)?;
        }
        let r = self.filling_ratio;
        if !(r.is_finite() && r > 0.0 && r <= 1.0) {
            return Err(format!("filling_ratio must be in (0, 1], got {r}"));
        }
        let d = self.infill_density;
        if !(d.is_finite() && d > 0.0 && d <= 1.0) {
            return Err(format!("infill_density must be in (0, 1], got {d}"));
        }
        let a = self.solid_infill_below_area;
        if !(a.is_finite() && a >= 0.0) {
            return Err(format!(
                "solid_infill_below_area must be 0 mm^2 or more, got {a}"
            ));
        }
        if !self.raster_angle_deg.is_finite() {
            return Err(format!(
                "raster_angle_deg must be a finite number of degrees, got {}",
                self.raster_angle_deg
            ));
        }
        positive("min_layer_height", self.min_layer_height)?;
        positive("max_layer_height", self.max_layer_height)?;
        if self.min_layer_height > self.max_layer_height {
            return Err(format!(
                "min_layer_height ({}) must not exceed max_layer_height ({})",
                self.min_layer_height, self.max_layer_height
            ));
        }
        let a = self.overhang_angle_deg;
        if !(a.is_finite() && a > 0.0 && a < MAX_OVERHANG_ANGLE_DEG) {
            return Err(format!(
                "overhang_angle_deg must be more than 0 and less than {MAX_OVERHANG_ANGLE_DEG} degrees, got {a}"
            ));
        }
        for (key, d) in [
            ("support_contact_distance", self.support_contact_distance),
            ("support_xy_distance", self.support_xy_distance),
        ] {
            if !(d.is_finite() && d >= 0.0) {
                return Err(format!("{key} must be 0 mm or more, got {d}"));
            }
        }
        for (key, r) in [
            ("support_density", self.support_density),
            ("support_interface_density", self.support_interface_density),
        ] {
            if !(r.is_finite() && r > 0.0 && r <= 1.0) {
                return Err(format!("{key} must be in (0, 1], got {r}"));
            }
        }
        if let Pedestal::Height(h) = self.pedestal {
            if !(h.is_finite() && h >= 0.0) {
                return Err(format!(
                    "pedestal must be \"auto\", \"off\" or a height of 0 mm or more, got {h}"
                ));
            }
        }
        let inset = self.pedestal_inset;
        if !(inset.is_finite() && inset >= 0.0) {
            return Err(format!("pedestal_inset must be 0 mm or more, got {inset}"));
        }
        for (key, d) in [
            ("skirt_distance_mm", self.skirt_distance_mm),
            ("brim_width_mm", self.brim_width_mm),
        ] {
            if !(d.is_finite() && (0.0..=MAX_ADHESION_MM).contains(&d)) {
                return Err(format!("{key} must be 0 to {MAX_ADHESION_MM} mm, got {d}"));
            }
        }
        if self.skirt_loops > MAX_SKIRT_LOOPS {
            return Err(format!(
                "skirt_loops must be 0 to {MAX_SKIRT_LOOPS}, got {}",
                self.skirt_loops
            ));
        }
        let m = self.machining_allowance;
        if !(m.is_finite() && (0.0..=MAX_MACHINING_ALLOWANCE).contains(&m)) {
            return Err(format!(
                "machining_allowance must be 0 to {MAX_MACHINING_ALLOWANCE} mm, got {m}"
            ));
        }
        if let Some(a) = self.fixed_tool_axis {
            let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            if !(n.is_finite() && n > ZERO_AXIS) {
                return Err(format!(
                    "fixed_tool_axis must be a non-zero finite vector, got {a:?}"
                ));
            }
        }
        Ok(())
    }

    /// These parameters with every key the patch sets replaced by the patch's value.
    pub fn patched(&self, p: &LayerParamsPatch) -> LayerParams {
        let mut out = self.clone();
        if let Some(v) = p.tolerance {
            out.tolerance = v;
        }
        if let Some(v) = p.layer_height_pattern {
            out.layer_height_pattern = v;
        }
        if let Some(v) = p.uniform_layer_height {
            out.uniform_layer_height = v;
        }
        if let Some(v) = &p.adaptive_layer_height {
            out.adaptive_layer_height = v.clone();
        }
        if let Some(v) = p.uniform_offset {
            out.uniform_offset = Some(v);
        }
        if let Some(v) = &p.adaptive_offset {
            out.adaptive_offset = v.clone();
        }
        if let Some(v) = p.path_mode {
            out.path_mode = v;
        }
        if let Some(v) = p.filling_ratio {
            out.filling_ratio = v;
        }
        if let Some(v) = p.perimeters {
            out.perimeters = v;
        }
        if let Some(v) = p.infill_density {
            out.infill_density = v;
        }
        if let Some(v) = p.infill_pattern {
            out.infill_pattern = v;
        }
        if let Some(v) = p.top_solid_layers {
            out.top_solid_layers = v;
        }
        if let Some(v) = p.bottom_solid_layers {
            out.bottom_solid_layers = v;
        }
        if let Some(v) = p.solid_infill_below_area {
            out.solid_infill_below_area = v;
        }
        if let Some(v) = p.raster_angle_deg {
            out.raster_angle_deg = v;
        }
        if let Some(v) = p.fixed_tool_axis {
            out.fixed_tool_axis = Some(v);
        }
        if let Some(v) = p.layer_strategy {
            out.layer_strategy = v;
        }
        if let Some(v) = p.wall_orientation {
            out.wall_orientation = v;
        }
        if let Some(v) = p.min_layer_height {
            out.min_layer_height = v;
        }
        if let Some(v) = p.max_layer_height {
            out.max_layer_height = v;
        }
        if let Some(v) = p.overhang_angle_deg {
            out.overhang_angle_deg = v;
        }
        if let Some(v) = p.support_material {
            out.support_material = v;
        }
        if let Some(v) = p.support_contact_distance {
            out.support_contact_distance = v;
        }
        if let Some(v) = p.support_xy_distance {
            out.support_xy_distance = v;
        }
        if let Some(v) = p.support_density {
            out.support_density = v;
        }
        if let Some(v) = p.support_interface_layers {
            out.support_interface_layers = v;
        }
        if let Some(v) = p.support_interface_density {
            out.support_interface_density = v;
        }
        if let Some(v) = p.pedestal {
            out.pedestal = v;
        }
        if let Some(v) = p.pedestal_inset {
            out.pedestal_inset = v;
        }
        if let Some(v) = p.skirt_loops {
            out.skirt_loops = v;
        }
        if let Some(v) = p.skirt_distance_mm {
            out.skirt_distance_mm = v;
        }
        if let Some(v) = p.brim_width_mm {
            out.brim_width_mm = v;
        }
        if let Some(v) = p.arc_fitting {
            out.arc_fitting = v;
        }
        if let Some(v) = p.slicing {
            out.slicing = v;
        }
        if let Some(v) = p.machining_allowance {
            out.machining_allowance = v;
        }
        out
    }
}

/// Per-feature overrides of [`LayerParams`]: every key optional, unknown keys an error.
///
/// `uniform_offset` here sets a spacing; a patch cannot reset it to "bead width / filling ratio".
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
#[serde(default, deny_unknown_fields)]
pub struct LayerParamsPatch {
    /// Overrides [`LayerParams::tolerance`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// Overrides [`LayerParams::layer_height_pattern`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub layer_height_pattern: Option<LayerHeightPattern>,
    /// Overrides [`LayerParams::uniform_layer_height`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub uniform_layer_height: Option<f64>,
    /// Overrides [`LayerParams::adaptive_layer_height`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub adaptive_layer_height: Option<Vec<f64>>,
    /// Overrides [`LayerParams::uniform_offset`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub uniform_offset: Option<f64>,
    /// Overrides [`LayerParams::adaptive_offset`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub adaptive_offset: Option<Vec<f64>>,
    /// Overrides [`LayerParams::path_mode`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub path_mode: Option<PathMode>,
    /// Overrides [`LayerParams::filling_ratio`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub filling_ratio: Option<f64>,
    /// Overrides [`LayerParams::perimeters`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub perimeters: Option<usize>,
    /// Overrides [`LayerParams::infill_density`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub infill_density: Option<f64>,
    /// Overrides [`LayerParams::infill_pattern`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub infill_pattern: Option<InfillPattern>,
    /// Overrides [`LayerParams::top_solid_layers`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub top_solid_layers: Option<usize>,
    /// Overrides [`LayerParams::bottom_solid_layers`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bottom_solid_layers: Option<usize>,
    /// Overrides [`LayerParams::solid_infill_below_area`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub solid_infill_below_area: Option<f64>,
    /// Overrides [`LayerParams::raster_angle_deg`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub raster_angle_deg: Option<f64>,
    /// Overrides [`LayerParams::fixed_tool_axis`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fixed_tool_axis: Option<[f64; 3]>,
    /// Overrides [`LayerParams::layer_strategy`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub layer_strategy: Option<LayerStrategy>,
    /// Overrides [`LayerParams::wall_orientation`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wall_orientation: Option<WallOrientation>,
    /// Overrides [`LayerParams::min_layer_height`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_layer_height: Option<f64>,
    /// Overrides [`LayerParams::max_layer_height`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_layer_height: Option<f64>,
    /// Overrides [`LayerParams::overhang_angle_deg`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub overhang_angle_deg: Option<f64>,
    /// Overrides [`LayerParams::support_material`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub support_material: Option<SupportMaterial>,
    /// Overrides [`LayerParams::support_contact_distance`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub support_contact_distance: Option<f64>,
    /// Overrides [`LayerParams::support_xy_distance`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub support_xy_distance: Option<f64>,
    /// Overrides [`LayerParams::support_density`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub support_density: Option<f64>,
    /// Overrides [`LayerParams::support_interface_layers`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub support_interface_layers: Option<usize>,
    /// Overrides [`LayerParams::support_interface_density`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub support_interface_density: Option<f64>,
    /// Overrides [`LayerParams::pedestal`] (`[defaults]` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pedestal: Option<Pedestal>,
    /// Overrides [`LayerParams::pedestal_inset`] (`[defaults]` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pedestal_inset: Option<f64>,
    /// Overrides [`LayerParams::skirt_loops`] (`[defaults]` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub skirt_loops: Option<usize>,
    /// Overrides [`LayerParams::skirt_distance_mm`] (`[defaults]` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub skirt_distance_mm: Option<f64>,
    /// Overrides [`LayerParams::brim_width_mm`] (`[defaults]` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub brim_width_mm: Option<f64>,
    /// Overrides [`LayerParams::arc_fitting`] (`[defaults]` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub arc_fitting: Option<bool>,
    /// Overrides [`LayerParams::slicing`] (`[defaults]` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub slicing: Option<Slicing>,
    /// Overrides [`LayerParams::machining_allowance`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub machining_allowance: Option<f64>,
}

#[cfg(test)]
#[path = "params/tests.rs"]
mod tests;
