//! Tests of [`crate::tilt`].

use super::*;
use crate::check::tilt;
use crate::head::Head;
use crate::scene::{check, test_point as pt};
use crate::table::Table;
use toolpath::MoveKind;

/// A wall 10 mm tall along y at x = 0 (feature 0), then feature 1 printed along it 12 mm
/// beside it at the plate, its planned axes +Z but for a gentle wave: the head's body (20 mm
/// round, from 8 mm up) holds the wall's top as planned; tilted away by some 10° it does not.
fn wall_and_line() -> (ToolPath, Vec<V3>) {
    let mut points = vec![];
    for layer in 0..50 {
        let z = 0.2 * (layer + 1) as f64;
        points.push(pt(0, layer, MoveKind::Travel, [0.0, -30.0, z]));
        points.push(pt(0, layer, MoveKind::Print, [0.0, 30.0, z]));
    }
    points.push(pt(1, 0, MoveKind::Travel, [12.0, -40.0, 0.2]));
    for i in 0..=160 {
        let y = -40.0 + 0.5 * i as f64;
        let lean = 0.05 * (y / 7.0).sin();
        let mut q = pt(1, 0, MoveKind::Print, [12.0, y, 0.2]);
        q.axis = unit([lean, 0.0, 1.0]).unwrap();
        points.push(q);
    }
    let planned = points.iter().map(|q| q.axis).collect();
    (ToolPath { points }, planned)
}

/// Depth (mm) material must lie inside the head for the brute-force check below: the
/// planner's tolerance (0.1), a grain's quarter cell (0.22) and the grain spacing (0.25).
const DEPTH: f64 = 0.6;

/// Independent of the planner's deposit: whether any point of the beads before `i` (every
/// 0.1 mm along each) lies more than [`DEPTH`] inside the default head at point `i`, or the
/// head more than that below the plate z = 0 (rims sampled).
fn brute_hits(points: &[PathPoint], i: usize) -> bool {
    let (tip_r, tan, nozzle, body_r, body) = (0.5, 30f64.to_radians().tan(), 8.0, 20.0, 60.0);
    let q = &points[i];
    let a = unit(q.axis).unwrap();
    let inside = |m: V3| {
        let d = sub(m, q.p);
        let h = dot(d, a);
        let r = norm(sub(d, scale(a, h)));
        let cone = h > DEPTH && h < nozzle - DEPTH && r < tip_r + h * tan - DEPTH;
        let cyl = h > nozzle + DEPTH && h < body - DEPTH && r < body_r - DEPTH;
        cone || cyl
    };
    let group = (q.feature, q.layer);
    let before = points
        .iter()
        .position(|p| (p.feature, p.layer) == group)
        .unwrap();
    for j in 1..before {
        if points[j].kind != MoveKind::Print {
            continue;
        }
        let (u, v) = (points[j - 1].p, points[j].p);
        let n = (norm(sub(v, u)) / 0.1).ceil() as usize;
        for t in 0..=n {
            if inside(add(u, scale(sub(v, u), t as f64 / n as f64))) {
                return true;
            }
        }
    }
    // The plate: the head's rims.
    let e1 = unit(cross(a, [0.0, 1.0, 0.0])).unwrap();
    let e2 = cross(a, e1);
    [
        (0.0, tip_r),
        (nozzle, tip_r + nozzle * tan),
        (nozzle, body_r),
        (body, body_r),
    ]
    .iter()
    .any(|&(h, r)| {
        (0..64).any(|k| {
            let f = std::f64::consts::TAU * k as f64 / 64.0;
            let p = add(
                add(q.p, scale(a, h)),
                add(scale(e1, r * f.cos()), scale(e2, r * f.sin())),
            );
            p[2] < -DEPTH
        })
    })
}

#[test]
fn tilt_clears_a_line_beside_a_wall_inside_the_cone_and_continuously() {
    let head = Head::default();
    let table = Some(Table::Plane { z: 0.0 });
    let (path, planned) = wall_and_line();
    let limits = TiltLimits {
        cone_half_deg: 30.0,
        max_from_z_deg: Some(45.0),
        window_mm: 5.0,
    };
    let given = check(&path, &head, table);
    let prints = |c: &[Collision]| c.iter().filter(|c| c.kind == MoveKind::Print).count();
    assert!(
        prints(&given) > 100,
        "the wall is in the way: {}",
        given.len()
    );
    let t = tilt(&path, &planned, &head, table, &limits);
    // Only axes change.
    assert_eq!(t.path.points.len(), path.points.len());
    for (a, b) in t.path.points.iter().zip(&path.points) {
        assert_eq!(
            (a.p, a.kind, a.feature, a.layer, a.e),
            (b.p, b.kind, b.feature, b.layer, b.e)
        );
    }
    // (c) Fewer colliding moves, as the check finds them again, and what tilt counts.
    let after = check(&t.path, &head, table);
    assert_eq!(after, t.left);
    assert!(
        prints(&after) < prints(&given),
        "{} → {}",
        prints(&given),
        prints(&after)
    );
    let cleared: usize = t.cleared.values().sum();
    assert_eq!(cleared, prints(&given) - prints(&after));
    // The moves cleared are clear by the brute-force check, which finds them colliding
    // as given.
    let mut seen = 0;
    for c in &given {
        if c.kind == MoveKind::Print && after.iter().all(|d| d.index != c.index) {
            assert!(!brute_hits(&t.path.points, c.index), "move {}", c.index);
            seen += usize::from(brute_hits(&path.points, c.index));
        }
    }
    assert!(
        seen > 0,
        "the brute-force check sees the given moves collide"
    );
    // (a) Every axis unit, within the cone about its planned axis and the B limit.
    for (q, &b) in t.path.points.iter().zip(&planned) {
        assert!((norm(q.axis) - 1.0).abs() < 1e-9);
        let off = angle(q.axis, unit(b).unwrap()).to_degrees();
        assert!(off <= limits.cone_half_deg + 1e-6, "{off}");
        assert!(angle(q.axis, [0.0, 0.0, 1.0]).to_degrees() <= 45.0 + 1e-6);
    }
    // Continuous: along the bead each step turns at most the step as given plus the
    // blend's slope over the step's length (the turn field is that Lipschitz in arc
    // length, and turning two axes by turns ω, ω' moves them apart by at most |ω − ω'|).
    let mut tilted = 0;
    for j in 1..path.points.len() {
        let (p0, p1) = (&path.points[j - 1], &path.points[j]);
        if p1.kind != MoveKind::Print || p0.feature != p1.feature {
            continue;
        }
        let (t0, t1) = (&t.path.points[j - 1], &t.path.points[j]);
        let len = norm(sub(p1.p, p0.p));
        let before = angle(p0.axis, p1.axis);
        let step = angle(t0.axis, t1.axis);
        assert!(
            step <= before + limits.slope() * len + 1e-9,
            "{j}: {step} vs {before}"
        );
        tilted += usize::from(angle(t1.axis, p1.axis) > 1e-6);
    }
    assert!(tilted > 0);
    // No cone, no tilt.
    let none = TiltLimits {
        cone_half_deg: 0.0,
        ..limits
    };
    let t0 = tilt(&path, &planned, &head, table, &none);
    assert_eq!(t0.path, path);
    assert!(t0.cleared.is_empty());
}

#[test]
fn blend_holds_keys_and_fades_over_a_window() {
    let s: Vec<f64> = (0..40).map(|i| i as f64 * 0.5).collect();
    let mut keys = BTreeMap::new();
    keys.insert(4, [0.0, 0.2, 0.0]);
    keys.insert(8, [0.0, 0.1, 0.0]);
    let f = blend(&keys, &s, 5.0);
    assert_eq!(f[4], [0.0, 0.2, 0.0]);
    assert_eq!(f[8], [0.0, 0.1, 0.0]);
    // Held back to the start, linear between, gone a window after the last key.
    assert_eq!(f[0], f[4]);
    assert!((f[6][1] - 0.15).abs() < 1e-12);
    assert!(f[8 + 10..].iter().all(|w| norm(*w) == 0.0));
    // Per step: the larger of the change between the keys over their distance (0.1 over
    // 2 mm) and the last key's turn over the window (0.1 over 5 mm), times 0.5 mm.
    for j in 1..s.len() {
        assert!(norm(sub(f[j], f[j - 1])) <= 0.1 / 2.0 * 0.5 + 1e-12);
    }
}

/// A line printed 17 mm over the table with the tool axis level (the B limit's clamp) and
/// planned 12° below level: the head's body clears the table only from some 16° above level,
/// and the cone about the planned axis reaches 18°. The clear turns lie between the rings'
/// 15° and 20° (outside the cone); the fine steps towards the highest allowed axis find them.
#[test]
fn tilt_finds_clear_axes_near_the_cone_rim_over_the_table() {
    let below = 12f64.to_radians();
    let planned_axis = [0.0, -below.cos(), -below.sin()];
    let mut points = vec![pt(0, 0, MoveKind::Travel, [-20.0, 0.0, 17.0])];
    for i in 0..=40 {
        points.push(pt(0, 0, MoveKind::Print, [-20.0 + i as f64, 0.0, 17.0]));
    }
    for q in &mut points {
        q.axis = [0.0, -1.0, 0.0];
    }
    let path = ToolPath { points };
    let planned = vec![planned_axis; path.points.len()];
    let head = Head::default();
    let table = Some(Table::Plane { z: 0.0 });
    let limits = TiltLimits {
        cone_half_deg: 30.0,
        max_from_z_deg: None,
        window_mm: 5.0,
    };
    let given = check(&path, &head, table);
    assert!(
        given.iter().filter(|c| c.kind == MoveKind::Print).count() > 30,
        "level, the head meets the table: {given:?}"
    );
    let out = tilt(&path, &planned, &head, table, &limits);
    assert!(out.left.is_empty(), "{:?}", out.left);
    assert_eq!(check(&out.path, &head, table), vec![]);
    for q in &out.path.points {
        let up = q.axis[2].asin().to_degrees();
        assert!(up > 15.0 && up <= 18.0 + 1e-6, "{up}° above level");
        assert!(angle(q.axis, planned_axis).to_degrees() <= 30.0 + 1e-6);
    }
}
