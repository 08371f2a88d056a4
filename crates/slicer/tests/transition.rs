//! Transition layers (issue 17; Isa & Lazoglu 2019, Eq. 1 and 4): checked on every print point
//! against the fixtures' exact faces, not against the planner's own top field: thickness within
//! its bounds, the last layer on the top, each layer resting on the one below, volume.

use brep::math::{P3, V3};
use brep::mesh::{mesh_faces, Mesh, MeshOptions};
mod support;

use features::{FeatureKind, FeatureTree};
use slicer::freeform::plan_freeform;
use slicer::params::{LayerParams, LayerStrategy};
use slicer::planar::Bead;
use slicer::toolpath::{MoveKind, PathPoint};
use std::collections::HashMap;
use support::{distance_to_mesh, tree};

const BEAD: Bead = Bead {
    width: 0.45,
    filament_diameter: 1.75,
};

/// Print points of one layer on a hash grid, for the nearest one to a query.
struct Grid {
    cell: f64,
    cells: HashMap<(i64, i64, i64), Vec<P3>>,
}

impl Grid {
    fn new(points: impl Iterator<Item = P3>, cell: f64) -> Grid {
        let mut g = Grid {
            cell,
            cells: HashMap::new(),
        };
        g.add(points);
        g
    }

    fn add(&mut self, points: impl Iterator<Item = P3>) {
        let cell = self.cell;
        for p in points {
            let k = (
                (p.x / cell).floor() as i64,
                (p.y / cell).floor() as i64,
                (p.z / cell).floor() as i64,
            );
            self.cells.entry(k).or_default().push(p);
        }
    }

    /// Points within one cell's reach of `p`.
    fn near(&self, p: &P3) -> Vec<P3> {
        let c = |x: f64| (x / self.cell).floor() as i64;
        let mut out = vec![];
        for a in c(p.x) - 1..=c(p.x) + 1 {
            for b in c(p.y) - 1..=c(p.y) + 1 {
                for d in c(p.z) - 1..=c(p.z) + 1 {
                    if let Some(v) = self.cells.get(&(a, b, d)) {
                        out.extend(v.iter().filter(|q| (*q - p).norm() <= self.cell));
                    }
                }
            }
        }
        out
    }
}

/// Plans freeform feature `id` of `name` with the default process (layer_strategy = auto),
/// asserts it got transition layers, and checks the properties on every print point.
fn check_transition(name: &str, t: &FeatureTree, id: usize) {
    check_transition_along(name, t, id, None);
}

/// [`check_transition`], the layers compared by their feet on the reference, or, with
/// `along`, by their projection along that direction (a feature whose reference's offsets
/// fold, whose layers are translates of it) and their height along it.
fn check_transition_along(name: &str, t: &FeatureTree, id: usize, along: Option<V3>) {
    let f = &t.features[id];
    assert_eq!(f.kind, FeatureKind::Freeform, "{name} feature {id}");
    let params = LayerParams::default();
    let plan = plan_freeform(t, f, &params, BEAD, None)
        .unwrap_or_else(|e| panic!("{name} feature {id}: {e}"));
    let ff = plan.freeform.expect("freeform figures");
    assert_eq!(
        ff.layers,
        slicer::figures::Layering::Transition,
        "{name} feature {id}: auto chose offset layers"
    );
    let pts: Vec<PathPoint> = plan.points.clone();
    let prints: Vec<&PathPoint> = pts.iter().filter(|p| p.kind == MoveKind::Print).collect();
    assert!(
        prints.len() > 100,
        "{name} feature {id}: too few print points"
    );
    // Thickness bounds, unit axes.
    for p in &prints {
        assert!(
            f64::from(p.thickness) >= params.min_layer_height - 1e-9
                && f64::from(p.thickness) <= params.max_layer_height + 1e-9,
            "{name} feature {id}: thickness {} outside [{}, {}]",
            p.thickness,
            params.min_layer_height,
            params.max_layer_height
        );
        let a = V3::from(p.axis);
        assert!((a.norm() - 1.0).abs() < 1e-6, "axis not unit");
    }
    // The top: the feature's faces other than its healing faces and its sides, i.e. those
    // its last layer's points lie on. Meshed finely, independently of the planner.
    let faces: Vec<_> = f
        .faces
        .iter()
        .copied()
        .filter(|x| !f.heal_faces.contains(x))
        .collect();
    let shells: Vec<Mesh> = faces
        .iter()
        .map(|x| mesh_faces(&t.brep, &[*x], &MeshOptions::with_tolerance(0.005)).expect("meshes"))
        .collect();
    let last = prints.iter().map(|p| p.layer).max().expect("layers");
    let (mut worst, mut worst_axis, mut interior) = (0.0f64, 0.0f64, 0usize);
    for p in prints.iter().filter(|p| p.layer == last) {
        let x = P3::from(p.p);
        // The nearest face and how far the next one is (a side, near the top's edge).
        let mut near: Vec<(f64, usize)> = shells
            .iter()
            .enumerate()
            .map(|(k, m)| (distance_to_mesh(m, &x), k))
            .collect();
        near.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (d, k) = near[0];
        let side = near.get(1).map_or(f64::INFINITY, |x| x.0);
        // The exact surface's normal at the point's foot (the mesh's facets stray by degrees).
        let s = t.brep.face_surface(faces[k]);
        let (u, v) = s.project(&x, None);
        let n = s.normal(u, v).expect("normal");
        worst = worst.max(d);
        assert!(
            d <= params.tolerance,
            "{name} feature {id}: last-layer point {x:?} lies {d:.4} mm off the top"
        );
        // The bead's centre, half its thickness down the axis, lies that far under the top.
        let c = x - V3::from(p.axis) * (0.5 * f64::from(p.thickness));
        let dc = shells
            .iter()
            .map(|m| distance_to_mesh(m, &c))
            .fold(f64::INFINITY, f64::min);
        assert!(
            (dc - 0.5 * f64::from(p.thickness)).abs() <= params.tolerance,
            "{name} feature {id}: last-layer bead centre {dc:.4} mm under the top, half its thickness is {:.4}",
            0.5 * p.thickness
        );
        // TSN: on the top, the axis is the top's normal, 0.3 mm or more from its edges.
        let ang = V3::from(p.axis)
            .dot(&n)
            .abs()
            .clamp(0.0, 1.0)
            .acos()
            .to_degrees();
        if side > 0.3 {
            interior += 1;
            worst_axis = worst_axis.max(ang);
        }
    }
    assert!(
        interior >= 5,
        "{name} feature {id}: no last-layer point on the top"
    );
    // Within 2°: the normal comes from the top's distance field by central differences (the
    // impeller's blade tips: 1.8° at worst, under 0.6° but for two points).
    assert!(
        worst_axis < 2.0,
        "{name} feature {id}: last-layer axis {worst_axis:.2}° off the top's normal"
    );
    // Support: every point of a layer but the first has points of the layer printed before it
    // within a bead's reach, and lies farther from the reference than they do.
    let rf = f.reference.face.expect("reference face");
    let surf = t.brep.face_surface(rf);
    // Each layer's beads, sampled every 0.05 mm along its print moves, by their foot on the
    // reference and their distance from it.
    // A point whose nearest point on the reference is on its face's boundary (off its normal:
    // a blade overhanging the hub's eye) has no foot to compare by, and is left out.
    let foot = |x: &P3| {
        if let Some(a) = along {
            let h = x.coords.dot(&a);
            return Some((x - a * h, h));
        }
        let (u, v) = surf.project(x, None);
        let f = surf.eval(u, v);
        let r = x - f;
        let n = surf.normal(u, v)?;
        (r.norm() < 1e-9 || r.normalize().dot(&n).abs() > 0.9998).then_some((f, r.norm()))
    };
    let mut by_layer: HashMap<usize, Vec<(P3, f64)>> = HashMap::new();
    for w in pts.windows(2) {
        if w[1].kind != MoveKind::Print {
            continue;
        }
        let (a, b) = (P3::from(w[0].p), P3::from(w[1].p));
        let n = ((b - a).norm() / 0.05).ceil().max(1.0) as usize;
        let v = by_layer.entry(w[1].layer as usize).or_default();
        for i in 0..=n {
            v.extend(foot(&(a + (b - a) * (i as f64 / n as f64))));
        }
    }
    // Something printed before every point within 0.3 mm of its foot, and nothing printed
    // before it over the same foot (within 0.1 mm) higher than it.
    let reach = 0.3;
    let (mut lonely, mut below, mut all) = (0usize, 0usize, 0usize);
    let mut worst_below = 0.0f64;
    // What is printed before each layer (a hybrid's transition band rests on offset layers
    // that end at different heights), on one grid that grows layer by layer.
    let mut order: Vec<usize> = by_layer.keys().copied().collect();
    order.sort_unstable();
    let mut built = Grid::new(std::iter::empty(), reach);
    let mut heights: HashMap<[i64; 3], f64> = HashMap::new();
    let key = |p: &P3| [p.x, p.y, p.z].map(|c| (c * 1e6).round() as i64);
    for (i, &l) in order.iter().enumerate() {
        if i > 0 {
            for x in prints
                .iter()
                .filter(|p| p.layer as usize == l)
                .map(|p| P3::from(p.p))
            {
                let Some((fx, dx)) = foot(&x) else {
                    continue;
                };
                all += 1;
                let near = built.near(&fx);
                if near.is_empty() {
                    lonely += 1;
                    continue;
                }
                // Directly under it: feet within a tenth of a millimetre.
                let top_under = near
                    .iter()
                    .filter(|f| (*f - fx).norm() <= 0.1)
                    .map(|f| heights[&key(f)])
                    .fold(f64::NEG_INFINITY, f64::max);
                if dx < top_under - 0.02 {
                    below += 1;
                    worst_below = worst_below.max(top_under - dx);
                }
            }
        }
        for (f, d) in &by_layer[&l] {
            let e = heights.entry(key(f)).or_insert(*d);
            *e = e.max(*d);
        }
        built.add(by_layer[&l].iter().map(|x| x.0));
    }
    assert!(
        (lonely as f64) < 0.01 * all as f64,
        "{name} feature {id}: {lonely} of {all} points with nothing printed before them within {reach} mm"
    );
    // With offset layers first, the transition band starts on their staircase: where the top
    // is steep over the reference, two of its steps fall within 0.1 mm, and a point beside the
    // cliff sits under the stack next to it (impeller blade: 1.6 % of its points, by up to
    // 0.33 mm). From the base, none may.
    let allowed = if plan
        .layers
        .iter()
        .any(|l| matches!(l.surface, slicer::LayerSurface::Offset { .. }))
    {
        0.02 * all as f64
    } else {
        0.0
    };
    assert!(
        below as f64 <= allowed,
        "{name} feature {id}: {below} of {all} points lie under what is printed before them, by up to {worst_below:.3} mm"
    ); // Volume (Eq. 1 with each point's thickness).
    let area = std::f64::consts::PI * BEAD.filament_diameter.powi(2) / 4.0;
    let extruded: f64 = prints.iter().map(|p| p.e).sum::<f64>() * area;
    let err = extruded / f.volume - 1.0;
    assert!(
        err.abs() <= 0.02,
        "{name} feature {id}: extruded {extruded:.1} mm³ for {:.1} mm³ ({:+.2} %)",
        f.volume,
        100.0 * err
    );
    eprintln!(
        "{name} feature {id}: {} layers, thickness {:.3}..{:.3} mm, last layer ≤ {worst:.4} mm off the top, axis ≤ {worst_axis:.2}° off its normal, volume {:+.2} %, {below} of {all} points under what was printed before them, {lonely} with nothing printed near under them",
        plan.layers.len(),
        plan.figures.thickness.0,
        plan.figures.thickness.2,
        100.0 * err
    );
}

/// The id of the tree's first freeform feature (a blade of the impeller or the fan).
fn first_freeform(t: &FeatureTree) -> usize {
    t.features
        .iter()
        .find(|f| f.kind == FeatureKind::Freeform)
        .expect("a freeform feature")
        .id
}

#[test]
fn domed_pad_transition_layers_end_on_its_spherical_top() {
    check_transition("domed_pad", &tree("domed_pad"), 1);
}

#[test]
fn sphere_boss_transition_layers_morph_the_sphere_into_the_flat_top() {
    check_transition("sphere_boss", &tree("sphere_boss"), 1);
}

#[test]
fn capsule_bosses_get_transition_layers() {
    let t = tree("capsule");
    for f in t
        .features
        .iter()
        .filter(|f| f.kind == FeatureKind::Freeform)
    {
        check_transition("capsule", &t, f.id);
    }
}

#[test]
fn impeller_blade_gets_offset_layers_then_a_transition_band_to_its_tip() {
    // Its tip lies 2.9 to 11 mm over the hub along the hub's normals: no one N keeps
    // [0.1, 0.3] mm, so offset layers first, then a transition band (crate::transition).
    let t = tree("impeller");
    check_transition("impeller", &t, first_freeform(&t));
}

/// Offset deterioration (feature-based AM paper, Fig. 9; issue 17, item 5): the rib stands
/// 9 mm tall in a trough of radius 4 mm, so its reference's offsets fold 4 mm up. Its layers
/// are translates of the trough along the trough bottom's normal, +Z
/// (fixtures/make_fixtures.py, `make_trough_rib`), morphed into its flat top.
#[test]
fn trough_rib_is_carried_over_its_valley_by_transition_layers() {
    let t = tree("trough_rib");
    let id = first_freeform(&t);
    check_transition_along("trough_rib", &t, id, Some(V3::z()));
    let plan = plan_freeform(&t, &t.features[id], &LayerParams::default(), BEAD, None)
        .expect("the rib plans");
    assert_eq!(
        plan.freeform.expect("freeform").chart,
        slicer::figures::LayerChart::Translate
    );
    // Every print point within the rib: |y| ≤ 1, z ≤ 19, above the trough's surface.
    for p in plan.points.iter().filter(|p| p.kind == MoveKind::Print) {
        let [x, y, z] = p.p;
        let floor = 14.0 - (16.0 - y * y).max(0.0).sqrt();
        assert!(
            x.abs() <= 10.0 + 1e-6 && y.abs() <= 1.0 + 1e-6 && z <= 19.0 + 1e-6 && z > floor,
            "print point {:?} outside the rib",
            p.p
        );
    }
}

#[test]
fn fan_blade_transition_layers_end_on_its_tip() {
    let t = tree("fan");
    check_transition("fan", &t, first_freeform(&t));
}

#[test]
fn a_top_too_close_to_the_base_for_the_bounds_keeps_offset_layers_or_is_refused_when_forced() {
    // Impeller blade, with every transition layer 0.3 mm thick: its tip's 2.9 to 11 mm over
    // the hub would need at least 37 layers and at most 9, and a band over offset layers at
    // least 11 and at most 9.
    let t = tree("impeller");
    let f = &t.features[first_freeform(&t)];
    let tight = LayerParams {
        min_layer_height: 0.3,
        max_layer_height: 0.3,
        ..LayerParams::default()
    };
    let auto = plan_freeform(&t, f, &tight, BEAD, None).expect("plans");
    assert_eq!(
        auto.freeform.expect("figures").layers,
        slicer::figures::Layering::Offset
    );
    assert!(
        auto.figures
            .warnings
            .iter()
            .any(|w| w.contains("offset layers, not transition layers")),
        "{:?}",
        auto.figures.warnings
    );
    let forced = LayerParams {
        layer_strategy: LayerStrategy::Transition,
        ..tight
    };
    let e = plan_freeform(&t, f, &forced, BEAD, None)
        .map(|_| ())
        .expect_err("forced transition layers are refused");
    let msg = e.to_string();
    assert!(
        msg.contains("min_layer_height") && msg.contains("max_layer_height"),
        "{msg}"
    );
}

#[test]
fn sst_wall_axes_are_perpendicular_to_the_side_face_and_the_path() {
    use slicer::params::WallOrientation;
    // The domed pad's sides are four planes; its top a sphere, its base the cylinder.
    let t = tree("domed_pad");
    let f = &t.features[1];
    let params = LayerParams {
        wall_orientation: WallOrientation::Sst,
        ..LayerParams::default()
    };
    let plan = plan_freeform(&t, f, &params, BEAD, None).expect("plans");
    let sides: Vec<(Mesh, V3)> = f
        .faces
        .iter()
        .filter(|x| !f.heal_faces.contains(x))
        .filter_map(|x| match t.brep.face_surface(*x) {
            brep::surface::Surface::Plane { .. } => {
                let m = mesh_faces(&t.brep, &[*x], &MeshOptions::with_tolerance(0.005))
                    .expect("meshes");
                let tri = m.triangles()[0];
                let [a, b, c] = tri.map(|k| m.positions[k as usize]);
                let n = (b - a).cross(&(c - a)).normalize();
                Some((m, n))
            }
            _ => None,
        })
        .collect();
    assert_eq!(sides.len(), 4, "the pad's four planar sides");
    let pts = &plan.points;
    let (mut walls, mut worst_n, mut worst_t) = (0usize, 0.0f64, 0.0f64);
    for i in 1..pts.len() - 1 {
        let (a, p, b) = (&pts[i - 1], &pts[i], &pts[i + 1]);
        if p.kind != MoveKind::Print || b.kind != MoveKind::Print || a.kind != MoveKind::Print {
            continue;
        }
        let axis = V3::from(p.axis);
        let centre = P3::from(p.p) - axis * (0.5 * f64::from(p.thickness));
        let mut near: Vec<(f64, V3)> = sides
            .iter()
            .map(|(m, n)| (distance_to_mesh(m, &centre), *n))
            .collect();
        near.sort_by(|x, y| x.0.total_cmp(&y.0));
        // A wall bead along one side, not at a corner where two meet.
        if near[0].0 > 0.3 || near[1].0 < 0.6 {
            continue;
        }
        let tangent = (P3::from(b.p) - P3::from(a.p)).normalize();
        let off_n = axis.dot(&near[0].1).abs().asin().to_degrees();
        let off_t = axis.dot(&tangent).abs().asin().to_degrees();
        walls += 1;
        worst_n = worst_n.max(off_n);
        worst_t = worst_t.max(off_t);
    }
    assert!(walls > 500, "only {walls} wall beads");
    assert!(
        worst_n < 1.0 && worst_t < 1.0,
        "SST axes {worst_n:.3}° off perpendicular to the side normal, {worst_t:.3}° to the path"
    );
    eprintln!("domed_pad SST: {walls} wall beads, axes within {worst_n:.3}° of the side plane and {worst_t:.3}° of perpendicular to the path");
}
