//! Figures of a planned feature (layers, points, lengths, filament), shared by the planners.

use crate::toolpath::PathPoint;

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
    /// Filament fed, mm.
    pub filament: f64,
    /// Thinnest, mean and thickest layer, mm.
    pub thickness: (f64, f64, f64),
    /// Things to know.
    pub warnings: Vec<String>,
}

impl FeatureFigures {
    /// Closes feature `id`'s figures: its points in `out`, and its layers from the thicknesses
    /// of the layers that printed (thinnest, mean, thickest; zeros and a warning when none did).
    pub(crate) fn finish(&mut self, id: usize, out: &[PathPoint], printed: &[f64]) {
        self.points = out.iter().filter(|p| p.feature == id).count();
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
