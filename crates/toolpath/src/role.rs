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
}

impl Role {
    /// Every role, in the order above.
    pub const ALL: [Role; 7] = [
        Role::ExternalPerimeter,
        Role::Perimeter,
        Role::SolidInfill,
        Role::InternalInfill,
        Role::GapFill,
        Role::SupportMaterial,
        Role::SupportMaterialInterface,
    ];

    /// True for support material's beads ([`Role::SupportMaterial`],
    /// [`Role::SupportMaterialInterface`]), which are not the part's.
    pub fn is_support(self) -> bool {
        matches!(self, Role::SupportMaterial | Role::SupportMaterialInterface)
    }

    /// The role's name in `toolpath.csv`: `external_perimeter`, `perimeter`, `solid_infill`,
    /// `internal_infill`, `gap_fill`, `support_material`, `support_material_interface`.
    pub fn as_str(self) -> &'static str {
        match self {
            Role::ExternalPerimeter => "external_perimeter",
            Role::Perimeter => "perimeter",
            Role::SolidInfill => "solid_infill",
            Role::InternalInfill => "internal_infill",
            Role::GapFill => "gap_fill",
            Role::SupportMaterial => "support_material",
            Role::SupportMaterialInterface => "support_material_interface",
        }
    }

    /// The role named `s` ([`Role::as_str`]), if any.
    pub fn parse(s: &str) -> Option<Role> {
        Role::ALL.into_iter().find(|r| r.as_str() == s)
    }

    /// PrusaSlicer's name of the role, as its `;TYPE:` comment writes it and its G-code viewer
    /// lists it: `External perimeter`, `Perimeter`, `Solid infill`, `Internal infill`,
    /// `Gap fill`, `Support material`, `Support material interface`.
    pub fn prusa_name(self) -> &'static str {
        match self {
            Role::ExternalPerimeter => "External perimeter",
            Role::Perimeter => "Perimeter",
            Role::SolidInfill => "Solid infill",
            Role::InternalInfill => "Internal infill",
            Role::GapFill => "Gap fill",
            Role::SupportMaterial => "Support material",
            Role::SupportMaterialInterface => "Support material interface",
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
