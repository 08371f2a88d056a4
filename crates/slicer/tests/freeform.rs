//! Curved layers of freeform features, checked against the exact reference surfaces of the
//! fixtures: offset distance, containment, tool axis, volume, support.

use brep::math::{P3, V3};
use brep::mesh::{mesh_faces, Mesh, MeshOptions};
mod support;

use features::{FeatureKind, FeatureTree};
use slicer::freeform::plan_freeform;
use slicer::params::{LayerParams, LayerStrategy, PathMode};
use slicer::planar::{Bead, FeatureError};
use slicer::toolpath::{MoveKind, PathPoint};
use std::collections::HashMap;
use support::{distance_to_mesh, tree};

const BEAD: Bead = Bead {
    width: 0.45,
    filament_diameter: 1.75,
};

fn mesh_of(t: &FeatureTree, id: usize) -> Mesh {
    let f = &t.features[id];
    mesh_faces(&t.brep, &f.faces, &MeshOptions::with_tolerance(0.01)).expect("meshes")
}

/// Points within `r` of a query, over a hash grid of samples of the print segments.
struct Near {
    cell: f64,
    grid: HashMap<(i64, i64, i64), Vec<P3>>,
}

impl Near {
    fn new(points: &[PathPoint], cell: f64) -> Near {
        let mut grid: HashMap<(i64, i64, i64), Vec<P3>> = HashMap::new();
        let key = |p: &P3| {
            (
                (p.x / cell).floor() as i64,
                (p.y / cell).floor() as i64,
                (p.z / cell).floor() as i64,
            )
        };
        for w in points.windows(2) {
            if w[1].kind != MoveKind::Print {
                continue;
            }
            let (a, b) = (P3::from(w[0].p), P3::from(w[1].p));
            let n = ((b - a).norm() / 0.05).ceil().max(1.0) as usize;
            for i in 0..=n {
                let p = a + (b - a) * (i as f64 / n as f64);
                grid.entry(key(&p)).or_default().push(p);
            }
        }
        Near { cell, grid }
    }

    fn distance(&self, p: &P3) -> f64 {
        let c = |x: f64| (x / self.cell).floor() as i64;
        let (i, j, k) = (c(p.x), c(p.y), c(p.z));
        let mut best = f64::INFINITY;
        for a in i - 1..=i + 1 {
            for b in j - 1..=j + 1 {
                for d in k - 1..=k + 1 {
                    if let Some(v) = self.grid.get(&(a, b, d)) {
                        for q in v {
                            best = best.min((q - p).norm());
                        }
                    }
                }
            }
        }
        best
    }
}

struct Checked {
    overhang_points: usize,
    layers: usize,
    volume: f64,
    extruded: f64,
}

/// Plans every freeform feature of `name` with `params` and checks the properties on
/// every print point.
fn check(name: &str, params: &LayerParams, check_support: bool) -> Vec<Checked> {
    // The properties of offset layers (transition layers: tests/transition.rs).
    let params = &LayerParams {
        layer_strategy: LayerStrategy::Offset,
        ..params.clone()
    };
    let t = tree(name);
    let area = std::f64::consts::PI * BEAD.filament_diameter.powi(2) / 4.0;
    let mut out = vec![];
    for &k in &t.build_order {
        let f = &t.features[k];
        if f.kind != FeatureKind::Freeform {
            continue;
        }
        let plan = plan_freeform(&t, f, params, BEAD, None)
            .unwrap_or_else(|e| panic!("{name} feature {k}: {e}"));
        let pts: Vec<PathPoint> = plan.points.clone();
        let (fig, ff) = (&plan.figures, plan.freeform.expect("freeform figures"));
        assert_eq!(fig.points, pts.len(), "{name} feature {k}");
        assert_eq!(fig.layers, plan.layers.len(), "{name} feature {k}");
        for l in &plan.layers {
            assert!(
                !l.paths.is_empty(),
                "{name} feature {k}: layer {} without paths",
                l.index
            );
            assert!(l.paths.iter().all(|p| plan
                .path_points(p)
                .1
                .iter()
                .all(|q| q.layer == l.index as u32 && q.thickness == l.thickness as f32)));
        }
        let rf = f.reference.face.expect("reference face");
        let surf = t.brep.face_surface(rf);
        let mesh = mesh_of(&t, k);
        let h = params.uniform_layer_height;
        // Layer tops: the running sum of the thicknesses.
        let mut tops: HashMap<usize, f64> = HashMap::new();
        let mut thick: Vec<(usize, f64)> = pts
            .iter()
            .map(|p| (p.layer as usize, f64::from(p.thickness)))
            .collect();
        thick.sort_by_key(|x| x.0);
        thick.dedup_by_key(|x| x.0);
        let mut z = 0.0;
        let mut last = None;
        for (layer, dl) in thick {
            if let Some(l) = last {
                assert_eq!(layer, l + 1, "{name} feature {k}: layers skip");
            }
            z += dl;
            tops.insert(layer, z);
            last = Some(layer);
        }
        let by_layer = |l: usize| -> Vec<PathPoint> {
            pts.iter()
                .filter(|p| p.layer == l as u32)
                .copied()
                .collect()
        };
        let mut below_cache: HashMap<usize, Near> = HashMap::new();
        let (mut sampled, mut unsupported) = (0usize, 0usize);
        let (mut worst_d, mut worst_axis, mut worst_support) = (0.0f64, 0.0f64, 0.0f64);
        for (i, p) in pts.iter().enumerate() {
            if p.kind != MoveKind::Print {
                continue;
            }
            let x = P3::from(p.p);
            // The nearest point of the reference surface; past the face's parameter range
            // (a blade overhanging the hub's edge) the surface is continued by its tangent
            // plane along the edge, so the offset is the normal component of `x − foot`
            // (equal to the distance wherever the foot is interior).
            let (u, v) = surf.project(&x, None);
            let foot = surf.eval(u, v);
            let n = surf.normal(u, v).expect("normal");
            let n = if n.dot(&(x - foot)) < 0.0 { -n } else { n };
            let d = (x - foot).dot(&n);
            let top = tops[&(p.layer as usize)];
            worst_d = worst_d.max((d - top).abs());
            assert!(
                (d - top).abs() <= 0.02 * h,
                "{name} feature {k} point {i} layer {}: {d} mm off the reference, layer top {top}",
                p.layer
            );
            let a = V3::from(p.axis);
            assert!((a.norm() - 1.0).abs() < 1e-6, "axis not unit");
            let ang = a.dot(&n).clamp(-1.0, 1.0).acos().to_degrees();
            worst_axis = worst_axis.max(ang);
            assert!(
                ang < 1.0,
                "{name} feature {k} point {i}: axis {ang}° off the normal"
            );
            // The bead's middle is inside the feature. Raster and zig-zag line ends with
            // nothing to join run on to the layer region's boundary, which is sampled within
            // the tolerance (issue: "exact boundary curves, sampled within tolerance"): there
            // the middle may lie outside, but no farther than the chord tolerance of the mesh
            // the planner cuts (a quarter of the tolerance; 6 µm seen on the capsule).
            let mid = x - n * (0.5 * f64::from(p.thickness));
            if i % 7 == 0 {
                let w = mesh.winding_number(&mid);
                let at = format!(
                    "{name} feature {k} point {i} layer {} of {}: bead middle outside ({w}) at {:?}",
                    p.layer, fig.layers, p.p
                );
                if matches!(params.path_mode, PathMode::Raster | PathMode::Zigzag) {
                    if w <= 0.5 {
                        let d = distance_to_mesh(&mesh, &mid);
                        assert!(d <= 0.25 * params.tolerance, "{at}, {d} mm off the feature");
                    }
                } else {
                    assert!(w > 0.5, "{at}");
                }
            }
            if !check_support {
                continue;
            }
            // Support-free: below every point is the layer before or the reference surface.
            if p.layer == 0 {
                // On the reference surface under the feature: just above the foot is inside,
                // or on the feature's side within the mesh's chord tolerance (a gap fill's
                // bead on the ridge of a sliver the layer cuts off a blade's root edge).
                let above = foot + n * 0.05;
                let w = mesh.winding_number(&above);
                assert!(
                    w > 0.5 || distance_to_mesh(&mesh, &above) <= 0.25 * params.tolerance,
                    "{name} feature {k} point {i}: first layer off the reference face ({w})"
                );
            } else if i % 7 == 0 {
                // Layer k−1 lies under the bead: a quarter of a layer below the bottom of
                // layer k is still inside the feature (an overhang puts it outside), and the
                // beads of layer k−1 run there (a pocket of the fill is smaller than a bead).
                sampled += 1;
                let below = x - n * (1.25 * f64::from(p.thickness));
                if mesh.winding_number(&below) <= 0.5 {
                    unsupported += 1;
                    continue;
                }
                let near = below_cache
                    .entry((p.layer - 1) as usize)
                    .or_insert_with(|| Near::new(&by_layer((p.layer - 1) as usize), 0.5));
                let gap = near.distance(&(x - n * f64::from(p.thickness)));
                worst_support = worst_support.max(gap);
                assert!(
                    gap <= BEAD.width,
                    "{name} feature {k} point {i} layer {}: {gap} mm from the beads below",
                    p.layer
                );
            }
        }
        // Every overhang the test finds, the planner reported: none where it reported none,
        // and no larger a share of the points than it reported.
        let prints = pts.iter().filter(|p| p.kind == MoveKind::Print).count();
        let reported = ff.overhang_points as f64 / prints.max(1) as f64;
        let found = unsupported as f64 / sampled.max(1) as f64;
        if check_support {
            if ff.overhang_points == 0 {
                assert_eq!(unsupported, 0, "{name} feature {k}: unreported overhang");
            } else {
                assert!(
                    found <= reported + 0.01,
                    "{name} feature {k}: overhang {found} found, {reported} reported"
                );
            }
        }
        let extruded: f64 = pts.iter().map(|p| p.e).sum::<f64>() * area;
        eprintln!(
            "{name} feature {k}: {} layers, {} points, chart {}, concave radius {:.2}, volume {:.2} extruded {:.2} ({:+.2}%), worst offset error {:.4} mm, axis {:.3}°, support gap {:.3} mm, overhang found {found:.4} reported {reported:.4}",
            fig.layers,
            pts.len(),
            ff.chart.as_str(),
            ff.concave_radius,
            f.volume,
            extruded,
            100.0 * (extruded / f.volume - 1.0),
            worst_d,
            worst_axis,
            worst_support
        );
        out.push(Checked {
            overhang_points: ff.overhang_points,
            layers: fig.layers,
            volume: f.volume,
            extruded,
        });
    }
    out
}

fn assert_volume(name: &str, c: &[Checked]) {
    assert!(!c.is_empty(), "{name} has freeform features");
    for x in c {
        assert!(x.layers > 0);
        let r = x.extruded / x.volume - 1.0;
        assert!(
            r.abs() < 0.02,
            "{name}: extruded {} of {} mm³",
            x.extruded,
            x.volume
        );
    }
}

#[test]
fn impeller_blades_lie_on_hub_offsets_inside_supported_and_conserve_volume() {
    let c = check("impeller", &LayerParams::default(), true);
    assert_eq!(c.len(), 6);
    assert_volume("impeller", &c);
}

#[test]
fn fan_blades_lie_on_cylinder_offsets_inside_supported_and_conserve_volume() {
    let c = check("fan", &LayerParams::default(), true);
    assert_eq!(c.len(), 5);
    assert!(
        c.iter().all(|x| x.overhang_points == 0),
        "the fan's blades need no support"
    );
    assert_volume("fan", &c);
}

#[test]
fn capsule_bosses_lie_on_cone_and_sphere_offsets_inside_supported_and_conserve_volume() {
    let c = check("capsule", &LayerParams::default(), true);
    assert_eq!(c.len(), 2);
    assert!(
        c.iter().all(|x| x.overhang_points == 0),
        "the capsule's bosses need no support"
    );
    assert_volume("capsule", &c);
}

#[test]
fn every_path_mode_keeps_points_on_the_offsets_and_inside() {
    // The default contour-zig-zag is checked above; each other mode also puts down each
    // boss's volume within 2 % (raster and zig-zag line ends with nothing to join run on to
    // the boundary).
    for mode in [PathMode::Raster, PathMode::Zigzag, PathMode::Contour] {
        let params = LayerParams {
            path_mode: mode,
            ..LayerParams::default()
        };
        let c = check("capsule", &params, false);
        for x in &c {
            let r = x.extruded / x.volume;
            assert!(
                (r - 1.0).abs() < 0.02,
                "{mode:?}: extruded {r} of the volume"
            );
        }
    }
}

#[test]
fn a_two5d_feature_is_refused_by_the_freeform_planner() {
    let t = tree("capsule");
    let e = plan_freeform(&t, &t.features[0], &LayerParams::default(), BEAD, None).unwrap_err();
    assert!(matches!(e, FeatureError::Freeform { id: 0, .. }), "{e}");
}

#[test]
fn a_fixed_tool_axis_holds_on_every_point_of_the_curved_layers() {
    let t = tree("capsule");
    let params = LayerParams {
        fixed_tool_axis: Some([0.0, 0.0, 2.0]),
        ..LayerParams::default()
    };
    let plan = plan_freeform(&t, &t.features[2], &params, BEAD, None).expect("plans");
    assert!(plan.points.len() > 100);
    for p in &plan.points {
        assert_eq!(p.axis, [0.0, 0.0, 1.0]);
    }
}
