//! The bead a machine lays, and the filament fed for it (Isa & Lazoglu 2019, Eq. 1).

/// What the planner and the posts need to know about the machine's bead.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bead {
    /// Bead width `w`, mm.
    pub width: f64,
    /// Filament diameter `D`, mm.
    pub filament_diameter: f64,
}

impl Bead {
    /// Eq. 1 (Isa & Lazoglu 2019): filament length (mm) fed for a bead of width `width`,
    /// layer thickness `thickness` (Δl) and length `length` (L), from this bead's filament of
    /// diameter D: `4·w·Δl·L / (π·D²)`. The width is an argument, not [`Bead::width`], since a
    /// planned bead may be narrower or wider than the machine's.
    pub fn filament_length(&self, width: f64, thickness: f64, length: f64) -> f64 {
        4.0 * width * thickness * length
            / (std::f64::consts::PI * self.filament_diameter * self.filament_diameter)
    }

    /// Cross-section area of the filament (mm²), `π·D²/4`: a filament length times it is the
    /// volume put down.
    pub fn filament_area(&self) -> f64 {
        std::f64::consts::PI * self.filament_diameter.powi(2) / 4.0
    }
}

#[cfg(test)]
mod tests {
    use super::Bead;

    #[test]
    fn extrusion_follows_isa_lazoglu_eq1() {
        let b = Bead {
            width: 0.45,
            filament_diameter: 1.75,
        };
        // A 10 mm bead 0.45 x 0.2 mm: 0.9 mm³ of 1.75 mm filament, 2.405 mm² → 0.37418 mm.
        let e = b.filament_length(0.45, 0.2, 10.0);
        assert!((e - 0.9 / b.filament_area()).abs() < 1e-12);
        assert!((e - 0.37418).abs() < 1e-5);
    }
}
