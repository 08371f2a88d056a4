//! Features below the nozzle's resolution (issue 31, item 4): a contact 0.3 mm wide, a pin
//! thinner than a bead. Their fill lays beads as wide as they are, narrower than the
//! machine's `min_bead_width`; the plan widens those beads to it (`widen_narrow_beads`), so
//! what is printed there is as much as the nozzle allows, not the feature. Such a feature is
//! named (a warning and `below_resolution` in `plan.json`, with its narrowest width and the
//! nozzle it would need) and judged by the self-check with a tolerance derived from the
//! share of it that narrow ([`tolerance`]), not failed at [`VOLUME_TOLERANCE`].

use features::{Feature, FeatureTree};
use serde::Serialize;
use slicer::params::LayerParams;
use slicer::toolpath::{MoveKind, PathPoint};
use slicer::verify::VOLUME_TOLERANCE;

/// A feature's beads narrower than `min_bead_width` must carry at least this share of its
/// planned material before its sections are measured ([`below_resolution`]): most features
/// have some (the spurs into sharp corners, the gap fill between a wall's rings), and a
/// feature without any is not below resolution.
pub const NARROW_BEAD_SHARE: f64 = 0.01;

/// A feature is below resolution when its sections' regions narrower than `min_bead_width`
/// hold at least this share of it (not a sliver at its top or bottom).
pub const BELOW_RESOLUTION_SHARE: f64 = 0.01;

/// A feature below the nozzle's resolution (`below_resolution` in `plan.json`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BelowResolution {
    /// The narrowest full width of a region of its layers' sections, mm.
    pub narrowest_mm: f64,
    /// The nozzle whose narrowest bead, at this machine's ratio of `min_bead_width` to
    /// `nozzle_diameter`, is that width, mm.
    pub nozzle_needed_mm: f64,
    /// The share of the feature in regions narrower than `min_bead_width`.
    pub narrow_share: f64,
    /// How far the self-check lets its extruded volume stray from volume × fill, percent
    /// ([`tolerance`]).
    pub tolerance_pct: f64,
}

/// Whether feature `f`, planned with `params` as `points` (before its narrow beads are
/// widened), is below the resolution of a nozzle `nozzle` mm across that lays beads
/// `min_bead` mm wide at the narrowest: its beads narrower than that carry at least
/// [`NARROW_BEAD_SHARE`] of its material, and its sections' regions narrower than that hold at
/// least [`BELOW_RESOLUTION_SHARE`] of it ([`slicer::resolution::narrow_sections`]; two5d
/// features only; `meshed`: its planar mesh made already).
#[allow(clippy::too_many_arguments)]
pub fn below_resolution(
    tree: &FeatureTree,
    f: &Feature,
    params: &LayerParams,
    points: &[PathPoint],
    min_bead: f64,
    nozzle: f64,
    meshed: Option<&slicer::planar::PlanarMesh>,
) -> Result<Option<BelowResolution>, slicer::planar::FeatureError> {
    let (mut total, mut narrow) = (0.0, 0.0);
    for q in points
        .iter()
        .filter(|q| q.kind == MoveKind::Print && q.width > 0.0 && q.e > 0.0)
        // The part's beads: support material is not the feature.
        .filter(|q| !q.role.is_support())
    {
        total += q.e;
        if q.width < min_bead as f32 {
            narrow += q.e;
        }
    }
    if total <= 0.0 || narrow < NARROW_BEAD_SHARE * total || min_bead.is_nan() || min_bead <= 0.0 {
        return Ok(None);
    }
    let Some(n) = slicer::resolution::narrow_sections(tree, f, params, min_bead, meshed)? else {
        return Ok(None);
    };
    Ok(
        (n.share >= BELOW_RESOLUTION_SHARE).then(|| BelowResolution {
            narrowest_mm: n.narrowest,
            nozzle_needed_mm: nozzle * n.narrowest / min_bead,
            narrow_share: n.share,
            tolerance_pct: 100.0 * tolerance(n.share),
        }),
    )
}

/// The self-check's tolerance for a feature below resolution whose regions narrower than
/// `min_bead_width` hold the share `narrow_share` of it: [`VOLUME_TOLERANCE`] plus that
/// share, `tolerance = 0.03 + V_narrow / V`.
///
/// Derivation: where the feature is narrower than `min_bead_width` its fill lays beads as wide
/// as it is, down to a fifth of a bead, and leaves out what is narrower still (or the margin
/// a bead's middle keeps inside a sliver), and a stretch too short or too thin for the
/// lattice the fill reads its widths on gets less or more than it holds; so what is planned
/// there may miss those stretches by up to all of their volume, `V_narrow` (measured on the
/// layers' own sections, [`slicer::resolution::narrow_sections`]), and no more. The rest of
/// the feature is held to the plan's 3 %. (The program then lays the narrow beads
/// `min_bead_width` wide: that material is reported apart, `widened_volume_mm3`, and is not in
/// the self-check.) A feature with no narrow region is not below resolution and keeps
/// [`VOLUME_TOLERANCE`]; a feature with no layer at all fails whatever its share.
pub fn tolerance(narrow_share: f64) -> f64 {
    if narrow_share.is_finite() && narrow_share > 0.0 {
        VOLUME_TOLERANCE + narrow_share.min(1.0)
    } else {
        VOLUME_TOLERANCE
    }
}

/// The warning line of a feature below resolution.
pub fn warning(id: usize, b: &BelowResolution, min_bead: f64) -> String {
    format!(
        "feature {id}: below the nozzle's resolution: {:.1} % of it narrower than min_bead_width {min_bead} mm, down to {:.3} mm; a nozzle of {:.2} mm would lay it (judged by the self-check within {:.1} %)",
        100.0 * b.narrow_share,
        b.narrowest_mm,
        b.nozzle_needed_mm,
        b.tolerance_pct
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bead(width: f64, e: f64) -> PathPoint {
        PathPoint {
            feature: 1,
            layer: 0,
            kind: MoveKind::Print,
            p: [0.0; 3],
            axis: [0.0, 0.0, 1.0],
            e,
            thickness: 0.2,
            width: width as f32,
            role: slicer::toolpath::Role::GapFill,
        }
    }

    #[test]
    fn a_feature_with_few_narrow_beads_is_not_measured() {
        // A wall of full beads with 0.5 % of its material in narrow spur tips: its sections
        // are not measured (the tree is never read).
        let mut points: Vec<_> = (0..199).map(|_| bead(0.45, 0.1)).collect();
        points.push(bead(0.13, 0.1));
        let part = brep::read_step(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/families/thin_wall_2.step"
        ))
        .expect("reads");
        let assembly = features::extract_all(&part.brep, &Default::default()).expect("features");
        let t = &assembly.trees[0];
        let params = LayerParams::default();
        let none = below_resolution(t, &t.features[0], &params, &points, 0.24, 0.4, None);
        assert!(matches!(none, Ok(None)));
        // The same plate's contact (0.297 mm wide) is below the resolution of a nozzle whose
        // narrowest bead is 0.4 mm (not of the delta5's, 0.24 mm), and nothing else is.
        let narrow: Vec<_> = (0..20).map(|_| bead(0.15, 0.01)).collect();
        let contact = t
            .features
            .iter()
            .filter_map(|f| {
                below_resolution(t, f, &params, &narrow, 0.4, 0.6, None)
                    .ok()
                    .flatten()
            })
            .collect::<Vec<_>>();
        assert_eq!(contact.len(), 1, "{contact:?}");
        let b = contact[0];
        assert!((b.narrowest_mm - 0.2967).abs() < 0.01, "{b:?}");
        assert!((b.nozzle_needed_mm - 0.6 * b.narrowest_mm / 0.4).abs() < 1e-12);
        assert!(b.narrow_share > 0.9, "{b:?}");
    }

    #[test]
    fn the_tolerance_grows_with_the_narrow_share() {
        assert_eq!(tolerance(0.0), VOLUME_TOLERANCE);
        assert!((tolerance(0.2) - (VOLUME_TOLERANCE + 0.2)).abs() < 1e-12);
        assert_eq!(tolerance(f64::NAN), VOLUME_TOLERANCE);
    }
}
