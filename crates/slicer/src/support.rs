//! Support (issue 31): every bead must rest on the bead below it, on material laid before it,
//! or on the build plate, within an overhang limit (`overhang_angle_deg`, degrees from the
//! build direction).
//!
//! - **A planar layer** is supported where it lies inside the layer below grown by
//!   `h·tan(angle)` (h the layer's thickness): a wall may lean out by that much a layer. What
//!   lies outside is unsupported ([`unsupported_area`]).
//! - **The first layer of a feature** rests on what was built before it: its parent features,
//!   whose material lies just below its reference plane (their sections half its first layer
//!   below that plane), or the plate, for the base feature (its reference plane is the plate).
//! - **Curved layers** (freeform features) are measured as they are laid (the layer below
//!   along the tool axis, `crate::freeform`); [`feature_support`] gives `None` for them.
//!
//! Everything here is a function of the extracted features and their layer parameters: no
//! path is filled, so a placement can be ranked by it ([`feature_support`] sections the
//! feature's mesh at each layer's middle, as the planar planner does, and stops there).

use crate::error::FeatureError;
use crate::feature_mesh::{feature_mesh, slicing_tolerance, Allowance, PlanarMesh};
use crate::fill::{outside_grown, pieces_outside};
use crate::geom2d::{region_area, Region};
use crate::params::{LayerParams, SupportMaterial};
use crate::support_material::SupportRegions;
use brep::section::Plane;
use features::{Feature, FeatureKind, FeatureTree};
use rayon::prelude::*;

/// Pieces of a layer's unsupported region smaller than this many square bead widths are
/// slivers, not overhangs, and are not counted (0.48 mm² for a 0.4 mm bead).
///
/// Why: a bead spans a gap of a few of its widths, held at both ends (a bridge), so a hole
/// that small in the support costs nothing. And the sections are polygons of a mesh chorded
/// within the slicing tolerance (a quarter of `tolerance`, 0.0125 mm): on a curved wall leaning
/// inward the section one layer up may still poke past the grown section below where the
/// plane crosses a facet's diagonal, by at most that chord error along at most a facet
/// (hundredths of a mm by a few mm: well under a square bead). A real overhang is not lost
/// to this: a wall leaning past the limit leaves a strip along the whole wall, one piece
/// `h·(tan θ − tan α)` wide (0.11 mm for 60° at 0.2 mm layers), over the threshold once it runs
/// 4.4 mm; a ceiling or a plate over a boss leaves pieces of its whole area. No distance is
/// added to the reach, so the limit itself is not loosened.
pub const SLIVER_BEADS: f64 = 3.0;

/// What [`feature_support`] found of one feature.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FeatureSupport {
    /// The feature's index in its tree.
    pub feature: usize,
    /// Unsupported area summed over its layers, mm² (the area of its overhangs seen along
    /// its build direction); 0 when every layer is supported.
    pub area_mm2: f64,
    /// Layers with unsupported area.
    pub layers: usize,
    /// The layer (1-based) with the most unsupported area, and that area (mm²).
    pub worst: Option<(usize, f64)>,
}

impl FeatureSupport {
    /// Adds layer `layer`'s (1-based) unsupported area `area` (mm², 0 for none).
    pub fn add(&mut self, layer: usize, area: f64) {
        if area <= 0.0 {
            return;
        }
        self.area_mm2 += area;
        self.layers += 1;
        if self.worst.is_none_or(|(_, a)| area > a) {
            self.worst = Some((layer, area));
        }
    }
}

/// How far (mm) a layer `h` thick may reach out past the layer below at an overhang limit of
/// `angle_deg` degrees from the build direction: `h·tan(angle)`.
pub fn reach(h: f64, angle_deg: f64) -> f64 {
    h * angle_deg.to_radians().tan()
}

/// The least area (mm²) of a piece of unsupported region that counts, for beads
/// `bead_width` wide: [`SLIVER_BEADS`] square bead widths.
pub fn sliver_area(bead_width: f64) -> f64 {
    SLIVER_BEADS * bead_width * bead_width
}

/// The area (mm²) of `layer` outside `below` grown by `reach` mm, in pieces of `sliver` mm² or
/// more (smaller pieces are slivers: [`SLIVER_BEADS`]). `tol` is the chord tolerance of the
/// growth's round corners. Empty `below`: the whole layer is unsupported.
pub fn unsupported_area(
    layer: &[Region],
    below: &[Region],
    reach: f64,
    sliver: f64,
    tol: f64,
) -> f64 {
    pieces_outside(layer, below, reach.max(0.0), tol)
        .into_iter()
        .filter(|a| *a >= sliver)
        .sum()
}

/// A planar section of `mesh` by `plane`, as regions in the plane's frame, simplified within
/// `near` as the fill simplifies the sections it lays (`planar::fill_two5d`).
fn section_regions(mesh: &brep::mesh::Mesh, plane: &Plane, near: f64) -> Vec<Region> {
    crate::fill::simplified(crate::planar::section_regions(mesh, plane, plane), near)
}

/// The support of a two5d feature's planar layers (as [`crate::planar`] lays them: parallel to
/// its reference plane, each cut at its middle), for beads `bead_width` wide: each layer
/// against the one below grown by [`reach`], the first against the sections of its parents
/// half its thickness below its reference plane. A base feature (no parent) stands on the
/// plate when `earlier` is empty (nothing to check), else on `earlier`: the features of the
/// file's other solids built before it, for a solid whose base lies above the plate. `None`
/// for a freeform feature, whose curved layers are measured as they are laid. Nothing is
/// filled, and no support material is counted ([`planar_support`] does).
pub fn feature_support(
    tree: &FeatureTree,
    f: &Feature,
    params: &LayerParams,
    bead_width: f64,
    earlier: &[(&FeatureTree, &Feature)],
) -> Result<Option<FeatureSupport>, FeatureError> {
    let support = planar_support(tree, f, params, bead_width, earlier, 0.0, Carry::Not, None)?;
    Ok(support.map(|p| p.left))
}

/// Whether [`planar_support`] counts what support material carries, and until when.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Carry {
    /// No support material: the overhangs alone.
    Not,
    /// Support material carries what it can (unless `support_material = "off"`); its columns
    /// are given up past the instant, if one is given ([`FeatureError::TimeLimit`]).
    Until(Option<std::time::Instant>),
}

/// What holds up a two5d feature's planar layers, with support material ([`planar_support`]).
#[derive(Debug, Clone, Default)]
pub struct PlanarSupport {
    /// The unsupported area the layers below leave (what the support check finds).
    pub overhang: FeatureSupport,
    /// What is left of it unsupported after support material; `overhang` when there is none.
    pub left: FeatureSupport,
    /// The support material's regions, layer by layer (empty without support).
    pub columns: SupportRegions,
    /// Each layer's section at its middle, simplified as the fill lays it: the fill's own
    /// sections (a feature not grown by an allowance), made once
    /// ([`crate::planar::PlanarMesh::mid_sections`]).
    pub sections: Vec<Vec<Region>>,
}

/// What feature `f`'s first layer rests on: the sections by `cut` (half that layer's thickness
/// below its reference plane) of its parents, or for a base feature of `earlier` (the solids
/// built before a lifted one), each grown by its allowance (which lifted this feature's base),
/// simplified within `near`; `None` on the plate (neither: nothing to check).
fn foundation(
    tree: &FeatureTree,
    f: &Feature,
    earlier: &[(&FeatureTree, &Feature)],
    cut: &Plane,
    params: &LayerParams,
    near: f64,
) -> Result<Option<Vec<Region>>, FeatureError> {
    let under: Vec<(&FeatureTree, &Feature)> = match f.parents.is_empty() {
        false => f
            .parents
            .iter()
            .map(|&p| (tree, &tree.features[p]))
            .collect(),
        true => earlier.to_vec(),
    };
    if under.is_empty() {
        return Ok(None);
    }
    let tol = slicing_tolerance(params);
    let mut regions = vec![];
    for (t, g) in under {
        let mesh = feature_mesh(t, g, tol, Allowance::of_parent(params))?;
        regions.extend(section_regions(&mesh, cut, near));
    }
    Ok(Some(regions))
}

/// [`feature_support`], and with [`Carry::Until`] (and `support_material` not `off`) the support
/// material under the unsupported pieces ([`crate::support_material::columns`]): what it
/// carries is no longer unsupported. Columns stand on the plate for a base feature on it (no
/// parent, `earlier` empty), and for the base of a solid lifted `gap` mm over the plate on
/// `earlier` (the solids built before): its columns go on below its first layer down to the
/// plate, landing on the earlier solids where they lie under them ([`crate::support_below`];
/// the regions' [`SupportRegions::below`] layers). Elsewhere they stand on the feature's own
/// lower layers, or at its first layer on what that layer rests on (its parents' sections),
/// never lower. `meshed`: the feature's planar mesh made already (`None`: made here).
#[allow(clippy::too_many_arguments)]
pub fn planar_support(
    tree: &FeatureTree,
    f: &Feature,
    params: &LayerParams,
    bead_width: f64,
    earlier: &[(&FeatureTree, &Feature)],
    gap: f64,
    carry: Carry,
    meshed: Option<&PlanarMesh>,
) -> Result<Option<PlanarSupport>, FeatureError> {
    if f.kind != FeatureKind::Two5d {
        return Ok(None);
    }
    params
        .validate()
        .map_err(|msg| FeatureError::Params { id: f.id, msg })?;
    let tol = slicing_tolerance(params);
    let near = crate::fill::ring_print_tolerance(params.tolerance, bead_width);
    let pm = PlanarMesh::given_or_of(meshed, tree, f, params)?;
    let PlanarMesh {
        plane,
        mesh,
        layers,
        ..
    } = pm.as_ref();
    let plane = *plane;
    let heights: Vec<f64> = layers.iter().map(|l| l.2).collect();
    let mids: Vec<f64> = layers.iter().map(|l| l.0).collect();
    let sections: Vec<Vec<Region>> = mids
        .par_iter()
        .with_max_len(1)
        .map(|&mid| section_regions(mesh, &plane.offset(mid), near))
        .collect();
    let foundation = match heights.first() {
        Some(&h0) => foundation(tree, f, earlier, &plane.offset(-0.5 * h0), params, near)?,
        None => None,
    };
    let sliver = sliver_area(bead_width);
    let angle = params.overhang_angle_deg;
    let chord = params.tolerance;
    let pieces: Vec<Vec<Region>> = (0..sections.len())
        .into_par_iter()
        .with_max_len(1)
        .map(|k| {
            let below = match k {
                0 => match &foundation {
                    Some(r) => r,
                    None => return vec![],
                },
                _ => &sections[k - 1],
            };
            outside_grown(&sections[k], below, reach(heights[k], angle), chord)
                .into_iter()
                .filter(|r| region_area(r) >= sliver)
                .collect()
        })
        .collect();
    let mut overhang = FeatureSupport {
        feature: f.id,
        ..FeatureSupport::default()
    };
    for (k, p) in pieces.iter().enumerate() {
        overhang.add(k + 1, p.iter().map(region_area).sum());
    }
    let stop_at = match carry {
        Carry::Until(stop_at) => stop_at,
        Carry::Not => None,
    };
    if carry == Carry::Not
        || params.support_material == SupportMaterial::Off
        || overhang.area_mm2 <= 0.0
    {
        return Ok(Some(PlanarSupport {
            overhang,
            left: overhang,
            columns: SupportRegions::default(),
            sections,
        }));
    }
    // A lifted solid's base: its layers carried on below its first one, down to the plate.
    let lifted = f.parents.is_empty() && !earlier.is_empty();
    let under = match lifted {
        true => crate::support_below::below(&plane, gap, earlier, params, tol)?,
        false => crate::support_below::Below::default(),
    };
    let u = under.heights.len();
    let c = match u {
        0 => crate::support_material::columns(
            &sections,
            &heights,
            &pieces,
            foundation.as_deref(),
            params,
            sliver,
            stop_at,
        )
        .map_err(|_| FeatureError::TimeLimit(f.id))?,
        _ => {
            let mut all_sections = under.sections;
            all_sections.extend(sections.iter().cloned());
            let mut all_heights = under.heights.clone();
            all_heights.extend(&heights);
            let mut all_pieces = vec![vec![]; u];
            all_pieces.extend(pieces);
            let mut c = crate::support_material::columns(
                &all_sections,
                &all_heights,
                &all_pieces,
                None,
                params,
                sliver,
                stop_at,
            )
            .map_err(|_| FeatureError::TimeLimit(f.id))?;
            c.left.drain(..u);
            c.regions.below = under.heights;
            c
        }
    };
    let mut left = FeatureSupport {
        feature: f.id,
        ..FeatureSupport::default()
    };
    for (k, a) in c.left.iter().enumerate() {
        left.add(k + 1, *a);
    }
    Ok(Some(PlanarSupport {
        overhang,
        left,
        columns: c.regions,
        sections,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom2d::shapes::rect;

    const W: f64 = 0.4;
    const TOL: f64 = 0.05;

    fn disc(r: f64) -> Region {
        let n = 256;
        Region {
            outer: (0..n)
                .map(|i| {
                    let a = std::f64::consts::TAU * i as f64 / n as f64;
                    [r * a.cos(), r * a.sin()]
                })
                .collect(),
            holes: vec![],
        }
    }

    /// The support of a stack of layers `h` thick whose sections are `layer(k)`, the first
    /// on the plate.
    fn stack(n: usize, h: f64, angle: f64, layer: impl Fn(usize) -> Vec<Region>) -> f64 {
        let mut s = FeatureSupport::default();
        for k in 1..n {
            let a = unsupported_area(
                &layer(k),
                &layer(k - 1),
                reach(h, angle),
                sliver_area(W),
                TOL,
            );
            s.add(k + 1, a);
        }
        s.area_mm2
    }

    #[test]
    fn a_plate_over_a_boss_is_unsupported_by_its_area_outside_the_boss() {
        // A 60 × 40 plate's first layer on a boss of radius 5 (the boss's section below).
        let plate = [rect(-30.0, -20.0, 30.0, 20.0)];
        let boss = [disc(5.0)];
        let a = unsupported_area(&plate, &boss, reach(0.2, 50.0), sliver_area(W), TOL);
        // The plate less the boss grown by 0.2·tan 50°.
        let r = 5.0 + reach(0.2, 50.0);
        let expect = 2400.0 - std::f64::consts::PI * r * r;
        assert!((a - expect).abs() < 0.5, "{a} vs {expect}");
        assert!(a > 2300.0);
    }

    #[test]
    fn a_box_is_supported() {
        let a = stack(50, 0.2, 50.0, |_| vec![rect(0.0, 0.0, 20.0, 30.0)]);
        assert_eq!(a, 0.0);
    }

    /// A 20 mm wide block whose +x wall leans out at `lean` degrees from the build direction,
    /// 5 mm tall in 0.2 mm layers, checked at a 50° limit.
    fn leaning(lean: f64) -> f64 {
        let h = 0.2;
        let t = lean.to_radians().tan();
        stack(25, h, 50.0, |k| {
            let x = 10.0 + (k as f64 + 0.5) * h * t;
            vec![rect(0.0, 0.0, x, 20.0)]
        })
    }

    #[test]
    fn a_45_degree_chamfer_is_supported_at_50_and_a_60_degree_one_is_not() {
        assert_eq!(leaning(45.0), 0.0);
        assert_eq!(leaning(0.0), 0.0);
        let a = leaning(60.0);
        // Each of the 24 layers above the first reaches 0.2·(tan 60° − tan 50°) past the
        // grown one below, along the 20 mm wall.
        let per_layer = 0.2 * (60f64.to_radians().tan() - 50f64.to_radians().tan()) * 20.0;
        assert!((a - 24.0 * per_layer).abs() < 0.01 * a, "{a}");
    }

    #[test]
    fn a_shrinking_layer_and_a_sliver_count_nothing() {
        let below = [rect(0.0, 0.0, 20.0, 20.0)];
        // Inside the layer below.
        let inner = [rect(5.0, 5.0, 15.0, 15.0)];
        assert_eq!(
            unsupported_area(&inner, &below, 0.0, sliver_area(W), TOL),
            0.0
        );
        // A sliver: 0.3 × 1 mm out past the reach.
        let nub = [
            rect(0.0, 0.0, 20.0, 20.0),
            rect(20.0, 5.0, 20.3 + reach(0.2, 50.0), 6.0),
        ];
        assert_eq!(
            unsupported_area(&nub, &below, reach(0.2, 50.0), sliver_area(W), TOL),
            0.0
        );
        // Nothing below: all of it.
        let a = unsupported_area(&below, &[], reach(0.2, 50.0), sliver_area(W), TOL);
        assert!((a - 400.0).abs() < 1e-9);
    }
}
