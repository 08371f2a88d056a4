//! A two5d feature's planar mesh and layer sections are made once for its support, fill and
//! resolution check (`PlanarMesh`, with the support's sections): the fill on them is the fill
//! that meshes and cuts the feature itself, point for point.

use features::{extract_all, ExtractOptions, FeatureKind};
use slicer::feature_fill::fill_feature_on;
use slicer::fill_feature;
use slicer::params::LayerParams;
use slicer::planar::{Bead, PlanarMesh};
use slicer::support::{planar_support, Carry};

const BEAD: Bead = Bead {
    width: 0.45,
    filament_diameter: 1.75,
};

fn fixture(file: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(file)
}

#[test]
fn a_fill_on_the_supports_mesh_and_sections_is_the_fill_itself() {
    let mut checked = 0;
    for file in ["plate_boss_boss.step", "families/pin_2.step"] {
        let part = brep::read_step(fixture(file)).expect("reads the fixture");
        let assembly = extract_all(&part.brep, &ExtractOptions::default()).expect("extracts");
        for t in &assembly.trees {
            for f in t.features.iter().filter(|f| f.kind == FeatureKind::Two5d) {
                for params in [
                    LayerParams::default(),
                    LayerParams {
                        path_mode: slicer::PathMode::Contour,
                        ..LayerParams::default()
                    },
                ] {
                    let own = fill_feature(t, f, &params, BEAD).expect("fills").lay(None);
                    let mut pm = PlanarMesh::of(t, f, &params).expect("meshes");
                    let support =
                        planar_support(t, f, &params, BEAD.width, &[], 0.0, Carry::Not, Some(&pm))
                            .expect("finds the support")
                            .expect("a two5d feature's support");
                    assert_eq!(
                        support.sections.len(),
                        own.figures.layers,
                        "{file} #{}",
                        f.id
                    );
                    pm.mid_sections = Some(support.sections);
                    let shared = fill_feature_on(t, f, &params, BEAD, Some(&pm))
                        .expect("fills")
                        .lay(None);
                    assert!(!own.points.is_empty());
                    assert_eq!(shared.points, own.points, "{file} feature {}", f.id);
                    checked += 1;
                }
            }
        }
    }
    assert!(checked >= 6, "{checked} fills compared");
}
