//! Figures of a planned feature (layers, points, lengths, filament), shared by the planners.

/// Figures of one planned feature.
#[derive(Debug, Clone, Default)]
pub struct FeatureFigures {
    /// Layers planned.
    pub layers: usize,
    /// Path points written.
    pub points: usize,
    /// Printed length, mm.
    pub print_length: f64,
    /// Travel length, mm.
    pub travel_length: f64,
    /// Filament fed for the part's beads, mm (what the self-check compares with the volume).
    pub filament: f64,
    /// Filament fed for support material's beads, mm (planar layers, issue 33): not the
    /// part's; the points carry it like any other.
    pub support_filament: f64,
    /// Volume of the feature's layers laid as sparse infill (issue 33): each layer's sparse
    /// area × its thickness, summed, mm³; 0 without sparse infill. Its beads cover
    /// `sparse_laid` of it, so the self-check expects that much less there.
    pub sparse_volume: f64,
    /// The share of `sparse_volume` its lines cover, mm³: each layer's sparse volume × its
    /// density (`infill_density`, or the gyroid's at the layer's height).
    pub sparse_laid: f64,
    /// Thinnest, mean and thickest layer, mm.
    pub thickness: (f64, f64, f64),
    /// How far (mm) the feature's surface reaches below its tree's build plate (the base
    /// feature's reference plane): 0 when it does not. Measured on the mesh the feature is
    /// sliced from (its vertices lie on the exact faces, within the slicing tolerance of the
    /// lowest point of a curved face), so the feature is not meshed a second time for it.
    pub below_plate: f64,
    /// The solid planned when the feature is grown by a machining allowance (issue 37, item
    /// 2): its volume (what the self-check expects instead of the nominal one) and where the
    /// offset folded; `None` for the nominal feature.
    pub grown: Option<crate::feature_mesh::Grown>,
    /// Things to know.
    pub warnings: Vec<String>,
}

impl FeatureFigures {
    /// The mean share of the sparse volume its lines cover (`sparse_laid / sparse_volume`):
    /// `density` (the feature's `infill_density`) when nothing is sparse.
    pub fn sparse_density(&self, density: f64) -> f64 {
        if self.sparse_volume > 0.0 {
            self.sparse_laid / self.sparse_volume
        } else {
            density
        }
    }

    /// Closes feature `id`'s figures: its `points`, and its layers from the thicknesses of the
    /// layers that printed (thinnest, mean, thickest; zeros and a warning when none did).
    pub(crate) fn finish(&mut self, id: usize, points: usize, printed: &[f64]) {
        self.points = points;
        self.layers = printed.len();
        self.thickness = if printed.is_empty() {
            (0.0, 0.0, 0.0)
        } else {
            let (lo, hi, sum) = printed
                .iter()
                .fold((f64::INFINITY, 0.0f64, 0.0), |(lo, hi, sum), &t| {
                    (lo.min(t), hi.max(t), sum + t)
                });
            (lo, sum / printed.len() as f64, hi)
        };
        if printed.is_empty() {
            self.warnings.push(format!(
                "feature {id} has no printable layer (thinner than a bead?)"
            ));
        }
    }
}

/// Figures of a freeform feature's layers, beyond [`FeatureFigures`].
#[derive(Debug, Clone, Copy, Default)]
pub struct FreeformFigures {
    /// The chart the feature's layers were laid in.
    pub chart: LayerChart,
    /// Smallest radius of a concave valley of the reference under the feature, mm (infinite
    /// when it curves away from the feature everywhere).
    pub concave_radius: f64,
    /// Print points with nothing under them: on layer k ≥ 2 more than half a bead outside
    /// layer k−1's region, or on layer 1 over the reference surface's continuation past its
    /// face (overhangs the reference surface's offsets cannot avoid, e.g. a wall leaning
    /// over the reference).
    pub overhang_points: usize,
    /// First and last layer (1-based) with such points.
    pub overhang_layers: Option<(usize, usize)>,
    /// The bead laid more than `h·tan(overhang_angle_deg)` off the layer below (or off the
    /// reference face, under the first layer), as area (mm²: length × width), layers whose
    /// area is a sliver left out ([`crate::support::SLIVER_BEADS`]).
    pub support: crate::support::FeatureSupport,
    /// The layers the feature got.
    pub layers: Layering,
}

/// The chart a curved feature's layers were laid in.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum LayerChart {
    /// The reference surface's own parameters.
    #[default]
    Native,
    /// A tangent-plane projection.
    Projection,
    /// Levels translated along one direction, where the reference's offsets fold.
    Translate,
}

impl LayerChart {
    /// Its name in `plan.json`: `native`, `projection` or `translate`.
    pub fn as_str(self) -> &'static str {
        match self {
            LayerChart::Native => "native",
            LayerChart::Projection => "projection",
            LayerChart::Translate => "translate",
        }
    }
}

/// The layers a curved feature got (`layer_strategy` in `plan.json`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Layering {
    /// Offsets of the reference surface.
    #[default]
    Offset,
    /// Layers morphing the base into the top (seed 000, Eq. 4–8).
    Transition,
}

impl Layering {
    /// Its name in `plan.json`: `offset` or `transition`.
    pub fn as_str(self) -> &'static str {
        match self {
            Layering::Offset => "offset",
            Layering::Transition => "transition",
        }
    }
}
