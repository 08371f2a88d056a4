//! What a bead is for in its layer, as slicers name extrusion roles.

/// The role of the path a point belongs to: its outermost ring, another ring, infill, a gap
/// fill, or support material under it. G-code posts write it as PrusaSlicer's `;TYPE:` comment ([`Role::prusa_name`]),
/// `toolpath.csv` as its `role` column ([`Role::as_str`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Role {
    /// The outermost ring of a region (about its outer boundary and about each hole): the
    /// bead on the part's surface.
    ExternalPerimeter,
    /// A ring inside the outermost one.
    Perimeter,
    /// Infill lines laid edge to edge: where the fill is solid (`filling_ratio` 1), on a
    /// feature's bottom and top layers, and on the solid skins of sparse infill.
    SolidInfill,
    /// Infill lines laid apart: sparse infill (`infill_density` below 1) away from the skins,
    /// or every line of a `filling_ratio` below 1 on the layers between.
    InternalInfill,
    /// Beads as wide as a strip narrower than a ring leaves, or spurs into sharp corners.
    GapFill,
    /// Sparse lines of support material under an overhang: not the part's.
    SupportMaterial,
    /// The denser layers of support material right under the surface it holds.
    SupportMaterialInterface,
    /// A loop around the part's first layer, apart from it, that primes the nozzle (issue 33,
    /// `skirt_loops`): not the part's.
    Skirt,
    /// Loops on the first layer touching the part's outline outward, holding it to the plate
    /// (issue 33, `brim_width_mm`): not the part's.
    Brim,
}

impl Role {
    /// Every role, in the order above.
    pub const ALL: [Role; 9] = [
        Role::ExternalPerimeter,
        Role::Perimeter,
        Role::SolidInfill,
        Role::InternalInfill,
        Role::GapFill,
        Role::SupportMaterial,
        Role::SupportMaterialInterface,
        Role::Skirt,
        Role::Brim,
    ];

    /// True for support material's beads ([`Role::SupportMaterial`],
    /// [`Role::SupportMaterialInterface`]), which are not the part's.
    pub fn is_support(self) -> bool {
        matches!(self, Role::SupportMaterial | Role::SupportMaterialInterface)
    }

    /// True for the part's own beads: false for support material, skirt and brim, which the
    /// self-check does not count as the part's volume.
    pub fn is_part(self) -> bool {
        !(self.is_support() || matches!(self, Role::Skirt | Role::Brim))
    }

    /// The role's name in `toolpath.csv`: `external_perimeter`, `perimeter`, `solid_infill`,
    /// `internal_infill`, `gap_fill`, `support_material`, `support_material_interface`, `skirt`,
    /// `brim`.
    pub fn as_str(self) -> &'static str {
        match self {
            Role::ExternalPerimeter => "external_perimeter",
            Role::Perimeter => "perimeter",
            Role::SolidInfill => "solid_infill",
            Role::InternalInfill => "internal_infill",
            Role::GapFill => "gap_fill",
            Role::SupportMaterial => "support_material",
            Role::SupportMaterialInterface => "support_material_interface",
            Role::Skirt => "skirt",
            Role::Brim => "brim",
        }
    }

    /// The role named `s` ([`Role::as_str`]), if any.
    pub fn parse(s: &str) -> Option<Role> {
        Role::ALL.into_iter().find(|r| r.as_str() == s)
    }

    /// PrusaSlicer's name of the role, as its `;TYPE:` comment writes it and its G-code viewer
    /// lists it: `External perimeter`, `Perimeter`, `Solid infill`, `Internal infill`,
    /// `Gap fill`, `Support material`, `Support material interface`, and `Skirt/Brim` for
    /// both the skirt and the brim (the viewer has one type for them).
    pub fn prusa_name(self) -> &'static str {
        match self {
            Role::ExternalPerimeter => "External perimeter",
            Role::Perimeter => "Perimeter",
            Role::SolidInfill => "Solid infill",
            Role::InternalInfill => "Internal infill",
            Role::GapFill => "Gap fill",
            Role::SupportMaterial => "Support material",
            Role::SupportMaterialInterface => "Support material interface",
            Role::Skirt | Role::Brim => "Skirt/Brim",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for r in Role::ALL {
            assert_eq!(Role::parse(r.as_str()), Some(r));
        }
        assert_eq!(Role::parse("Perimeter"), None);
    }
}
