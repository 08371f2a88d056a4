//! Tests of the layer parameters and their `--set` patches.
use super::*;

#[test]
fn defaults_match_the_issue() {
    let p = LayerParams::default();
    assert_eq!(p.tolerance, 0.05);
    assert_eq!(p.layer_height_pattern, LayerHeightPattern::Uniform);
    assert_eq!(p.uniform_layer_height, 0.2);
    assert!(p.adaptive_layer_height.is_empty());
    assert_eq!(p.uniform_offset, None);
    assert!(p.adaptive_offset.is_empty());
    assert_eq!(p.path_mode, PathMode::ContourZigzag);
    assert_eq!(p.filling_ratio, 1.0);
    assert_eq!(p.perimeters, 2);
    assert_eq!(p.raster_angle_deg, 45.0);
    assert_eq!(p.validate(), Ok(()));
}

#[test]
fn spacing_is_width_over_filling_ratio_unless_given() {
    let mut p = LayerParams {
        filling_ratio: 0.8,
        ..LayerParams::default()
    };
    assert!((p.spacing(0.4) - 0.5).abs() < 1e-12);
    p.uniform_offset = Some(0.45);
    assert_eq!(p.spacing(0.4), 0.45);
    assert_eq!(p.spacing_for_layer(0.4, 3), 0.45);
    p.layer_height_pattern = LayerHeightPattern::Adaptive;
    p.adaptive_layer_height = vec![0.2];
    p.adaptive_offset = vec![0.4, 0.5];
    assert_eq!(p.spacing_for_layer(0.4, 0), 0.4);
    assert_eq!(p.spacing_for_layer(0.4, 3), 0.5);
}

#[test]
fn stepped_heights_put_a_layer_boundary_on_each_step() {
    // A clip 1.6 mm high: pads 0.3 mm thick, legs, a plate 0.3 mm thick (psstep13's
    // inductor terminal), at 0.2 mm layers.
    let p = LayerParams::default();
    let h = p.layer_heights_through(1.6, &[0.3, 1.3, 0.3]);
    let mut z = 0.0;
    let mut tops = vec![];
    for dl in &h {
        assert!(*dl <= p.uniform_layer_height + 1e-9 && *dl >= p.min_layer_height);
        z += dl;
        tops.push(z);
    }
    assert!((z - 1.6).abs() < 1e-9);
    for step in [0.3, 1.3] {
        assert!(
            tops.iter().any(|t| (t - step).abs() < 1e-9),
            "{step}: {tops:?}"
        );
    }
    assert_eq!(h.len(), 2 + 5 + 2);
    // A step nearer than min_layer_height to the bottom, the top or the step before is
    // passed over; no steps, or the adaptive pattern, give layer_heights.
    assert_eq!(
        p.layer_heights_through(1.0, &[0.05, 0.95]),
        p.layer_heights(1.0)
    );
    assert_eq!(p.layer_heights_through(1.0, &[]), p.layer_heights(1.0));
    let h = p.layer_heights_through(1.0, &[0.4, 0.45]);
    assert_eq!(h.len(), 2 + 3, "{h:?}");
}

#[test]
fn uniform_heights_land_on_the_top() {
    let p = LayerParams::default();
    let h = p.layer_heights(10.0);
    assert_eq!(h.len(), 50);
    assert!((h.iter().sum::<f64>() - 10.0).abs() < 1e-9);
    // 1.05 / 0.2 = 5.25 -> 6 layers of 0.175.
    let h = p.layer_heights(1.05);
    assert_eq!(h.len(), 6);
    assert!(h.iter().all(|&t| (t - 0.175).abs() < 1e-12));
    // Thinner than a layer: one layer of the whole extent.
    assert_eq!(p.layer_heights(0.05), vec![0.05]);
    assert!(p.layer_heights(0.0).is_empty());
    assert!(p.layer_heights(-1.0).is_empty());
    assert!(p.layer_heights(f64::NAN).is_empty());
    assert!(p.layer_heights(f64::INFINITY).is_empty());
}

#[test]
fn adaptive_heights_cycle_and_trim() {
    let p = LayerParams {
        layer_height_pattern: LayerHeightPattern::Adaptive,
        adaptive_layer_height: vec![0.1, 0.2, 0.3],
        ..LayerParams::default()
    };
    let h = p.layer_heights(1.0);
    // 0.1 0.2 0.3 0.1 0.2 | 0.1 trimmed from 0.3
    assert_eq!(h.len(), 6);
    for (a, b) in h.iter().zip([0.1, 0.2, 0.3, 0.1, 0.2, 0.1]) {
        assert!((a - b).abs() < 1e-9, "{h:?}");
    }
    assert!((h.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    // Shorter than the list: truncated.
    let h = p.layer_heights(0.25);
    assert_eq!(h.len(), 2);
    assert!((h[1] - 0.15).abs() < 1e-12);
    // An exact multiple leaves no sliver.
    let h = p.layer_heights(0.6);
    assert_eq!(h.len(), 3);
    // Empty list: nothing (validate says why).
    let q = LayerParams {
        adaptive_layer_height: vec![],
        ..p.clone()
    };
    assert!(q.layer_heights(1.0).is_empty());
    assert!(q.validate().unwrap_err().contains("adaptive_layer_height"));
}

#[test]
fn absurd_layer_counts_give_nothing() {
    let p = LayerParams {
        uniform_layer_height: 1e-9,
        ..LayerParams::default()
    };
    assert!(p.layer_heights(1000.0).is_empty());
    let p = LayerParams {
        layer_height_pattern: LayerHeightPattern::Adaptive,
        adaptive_layer_height: vec![1e-9],
        ..LayerParams::default()
    };
    assert!(p.layer_heights(1000.0).is_empty());
}

#[test]
fn the_pedestal_is_a_word_or_a_height() {
    let read = |v: &str| toml::from_str::<LayerParamsPatch>(&format!("pedestal = {v}"));
    assert_eq!(read("\"auto\"").unwrap().pedestal, Some(Pedestal::Auto));
    assert_eq!(read("\"off\"").unwrap().pedestal, Some(Pedestal::Off));
    assert_eq!(read("2.4").unwrap().pedestal, Some(Pedestal::Height(2.4)));
    assert_eq!(read("3").unwrap().pedestal, Some(Pedestal::Height(3.0)));
    assert!(read("\"tall\"").is_err());
    let bad = LayerParams {
        pedestal: Pedestal::Height(-1.0),
        ..LayerParams::default()
    };
    assert!(bad.validate().unwrap_err().contains("pedestal"));
    let bad = LayerParams {
        pedestal_inset: -0.5,
        ..LayerParams::default()
    };
    assert!(bad.validate().unwrap_err().contains("pedestal_inset"));
    // Written back as read.
    let p = LayerParams::default().patched(&read("2.4").unwrap());
    let text = toml::to_string(&p).unwrap();
    assert!(text.contains("pedestal = 2.4"), "{text}");
}

#[test]
fn validate_names_the_key() {
    let bad = |f: fn(&mut LayerParams), key: &str| {
        let mut p = LayerParams::default();
        f(&mut p);
        let e = p.validate().unwrap_err();
        assert!(e.contains(key), "{e}");
        assert!(!e.contains('\n'));
    };
    bad(|p| p.tolerance = 0.0, "tolerance");
    bad(|p| p.uniform_layer_height = -0.2, "uniform_layer_height");
    bad(
        |p| p.uniform_layer_height = f64::NAN,
        "uniform_layer_height",
    );
    bad(
        |p| p.adaptive_layer_height = vec![0.2, 0.0],
        "adaptive_layer_height[1]",
    );
    bad(|p| p.uniform_offset = Some(0.0), "uniform_offset");
    bad(
        |p| p.adaptive_offset = vec![f64::INFINITY],
        "adaptive_offset[0]",
    );
    bad(|p| p.filling_ratio = 0.0, "filling_ratio");
    bad(|p| p.filling_ratio = 1.01, "filling_ratio");
    bad(|p| p.raster_angle_deg = f64::NAN, "raster_angle_deg");
    bad(
        |p| p.support_contact_distance = -0.1,
        "support_contact_distance",
    );
    bad(|p| p.support_xy_distance = f64::NAN, "support_xy_distance");
    bad(|p| p.support_density = 0.0, "support_density");
    bad(
        |p| p.support_interface_density = 1.5,
        "support_interface_density",
    );
    let p = LayerParams {
        filling_ratio: 1.0,
        ..LayerParams::default()
    };
    assert_eq!(p.validate(), Ok(()));
}

#[test]
fn serde_uses_the_paper_keys() {
    let p: LayerParams = serde_json::from_str(
        r#"{"layer_height_pattern":"adaptive","adaptive_layer_height":[0.1,0.2],
            "path_mode":"contour_zigzag","filling_ratio":0.9}"#,
    )
    .unwrap();
    assert_eq!(p.layer_height_pattern, LayerHeightPattern::Adaptive);
    assert_eq!(p.adaptive_layer_height, vec![0.1, 0.2]);
    assert_eq!(p.filling_ratio, 0.9);
    assert_eq!(p.tolerance, 0.05);
    let p: LayerParams = serde_json::from_str("{}").unwrap();
    assert_eq!(p, LayerParams::default());
    let json = serde_json::to_string(&LayerParams::default()).unwrap();
    assert!(json.contains(r#""path_mode":"contour_zigzag""#), "{json}");
    assert!(
        json.contains(r#""layer_height_pattern":"uniform""#),
        "{json}"
    );
    let back: LayerParams = serde_json::from_str(&json).unwrap();
    assert_eq!(back, LayerParams::default());
    for (s, m) in [
        ("raster", PathMode::Raster),
        ("zigzag", PathMode::Zigzag),
        ("contour", PathMode::Contour),
        ("contour_zigzag", PathMode::ContourZigzag),
    ] {
        assert_eq!(
            serde_json::from_str::<PathMode>(&format!("\"{s}\"")).unwrap(),
            m
        );
    }
    assert!(serde_json::from_str::<LayerParams>(r#"{"layer_hieght":0.2}"#).is_err());
    assert!(serde_json::from_str::<LayerParams>(r#"{"path_mode":"spiral"}"#).is_err());
}

#[test]
fn patch_overrides_only_what_it_sets() {
    let base = LayerParams::default();
    let patch: LayerParamsPatch =
        serde_json::from_str(r#"{"path_mode":"raster","uniform_offset":0.5,"perimeters":3}"#)
            .unwrap();
    let p = base.patched(&patch);
    assert_eq!(p.path_mode, PathMode::Raster);
    assert_eq!(p.uniform_offset, Some(0.5));
    assert_eq!(p.perimeters, 3);
    assert_eq!(p.tolerance, base.tolerance);
    assert_eq!(p.raster_angle_deg, base.raster_angle_deg);
    assert_eq!(base.patched(&LayerParamsPatch::default()), base);
    let all: LayerParamsPatch = serde_json::from_str(
        r#"{"tolerance":0.01,"layer_height_pattern":"adaptive","uniform_layer_height":0.3,
            "adaptive_layer_height":[0.1],"uniform_offset":0.4,"adaptive_offset":[0.4],
            "path_mode":"zigzag","filling_ratio":0.5,"perimeters":1,"raster_angle_deg":0}"#,
    )
    .unwrap();
    let p = base.patched(&all);
    assert_eq!(p.tolerance, 0.01);
    assert_eq!(p.layer_height_pattern, LayerHeightPattern::Adaptive);
    assert_eq!(p.uniform_layer_height, 0.3);
    assert_eq!(p.adaptive_layer_height, vec![0.1]);
    assert_eq!(p.adaptive_offset, vec![0.4]);
    assert_eq!(p.path_mode, PathMode::Zigzag);
    assert_eq!(p.filling_ratio, 0.5);
    assert_eq!(p.perimeters, 1);
    assert_eq!(p.raster_angle_deg, 0.0);
    // A misspelled key is an error, naming the key.
    let e = serde_json::from_str::<LayerParamsPatch>(r#"{"filing_ratio":0.5}"#).unwrap_err();
    assert!(e.to_string().contains("filing_ratio"), "{e}");
    // Serialises only what it sets.
    let json = serde_json::to_string(&patch).unwrap();
    assert_eq!(
        json,
        r#"{"uniform_offset":0.5,"path_mode":"raster","perimeters":3}"#
    );
}
