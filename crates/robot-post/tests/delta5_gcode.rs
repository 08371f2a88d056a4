//! The 5-axis (tilting B, rotating C bed) post end to end: the program is re-parsed with the
//! `gcode` crate, taken back to the part with the forward kinematics and compared with
//! `toolpath.csv` (issue "5-axis delta printer post", Isa & Lazoglu 2019 §4).

use gcode::{Code, Value};
use robot_post::delta5::{forward, inverse};
use robot_post::machine::DELTA5_TOML;
use robot_post::toolpath::Role;
use robot_post::{
    delta5, Delta5Program, MachineKind, MachineProfile, MoveKind, PathPoint, PostError, ToolPath,
};

const W: f64 = 0.45;
const T: f64 = 0.2;
/// Sphere of the curved layers: centre and radius (part coordinates, mm).
const CENTRE: [f64; 3] = [0.0, 0.0, -2.0];
const R: f64 = 20.0;

fn profile() -> MachineProfile {
    MachineProfile::builtin(MachineKind::Delta5)
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = norm(v);
    [v[0] / n, v[1] / n, v[2] / n]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn angle_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
    let (a, b) = (unit(a), unit(b));
    norm(cross(a, b))
        .atan2(a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
        .to_degrees()
}

fn distance_to_segment(x: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = sub(b, a);
    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let w = sub(x, a);
    let f = if dd > 0.0 {
        ((w[0] * d[0] + w[1] * d[1] + w[2] * d[2]) / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm(sub(x, [a[0] + d[0] * f, a[1] + d[1] * f, a[2] + d[2] * f]))
}

/// The unit normal of the sphere at polar angle `psi` from +Z and azimuth `alpha` (degrees).
fn polar(psi: f64, alpha: f64) -> [f64; 3] {
    let (p, a) = (psi.to_radians(), alpha.to_radians());
    [p.sin() * a.cos(), p.sin() * a.sin(), p.cos()]
}

/// The point of the sphere with normal `n`, and `n` as its tool axis.
fn on_sphere(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    (
        [
            CENTRE[0] + R * n[0],
            CENTRE[1] + R * n[1],
            CENTRE[2] + R * n[2],
        ],
        n,
    )
}

/// One path of `feature`: a travel to the first point, print moves through the rest, each
/// with the filament of Isa & Lazoglu 2019, Eq. 1.
fn add_path(
    path: &mut ToolPath,
    m: &MachineProfile,
    feature: usize,
    layer: usize,
    points: &[([f64; 3], [f64; 3])],
) {
    for (k, &(p, axis)) in points.iter().enumerate() {
        let (kind, e) = if k == 0 {
            (MoveKind::Travel, 0.0)
        } else {
            let len = norm(sub(p, points[k - 1].0));
            (MoveKind::Print, m.filament_length(W, T, len))
        };
        path.points.push(PathPoint {
            feature: feature as u32,
            layer: layer as u32,
            kind,
            p,
            axis,
            e,
            thickness: T as f32,
            width: W as f32,
            role: robot_post::toolpath::Role::Perimeter,
        });
    }
}

/// A latitude circle of the sphere at polar angle `psi`, sampled about every 0.6 mm (at least
/// `min_points` segments), closed.
fn latitude(psi: f64, min_points: usize) -> Vec<([f64; 3], [f64; 3])> {
    let length = 2.0 * std::f64::consts::PI * R * psi.to_radians().sin();
    let n = ((length / 0.6).ceil() as usize).max(min_points);
    (0..=n)
        .map(|k| on_sphere(polar(psi, 360.0 * k as f64 / n as f64)))
        .collect()
}

/// A path over the sphere whose normals pass `delta` degrees from the pole (0: through it),
/// from `u` = −8° to 8° in steps of `step` degrees, turned by `azimuth` about Z.
fn past_the_pole(delta: f64, step: f64, azimuth: f64) -> Vec<([f64; 3], [f64; 3])> {
    let (d, az) = (delta.to_radians(), azimuth.to_radians());
    let steps = (16.0 / step).round() as i64;
    (0..=steps)
        .map(|k| {
            let u = (-8.0 + step * k as f64).to_radians();
            let n = [d.cos() * u.sin(), d.sin(), d.cos() * u.cos()];
            let n = [
                n[0] * az.cos() - n[1] * az.sin(),
                n[0] * az.sin() + n[1] * az.cos(),
                n[2],
            ];
            on_sphere(n)
        })
        .collect()
}

/// Features, in build order:
/// 1. two5d, +Z: two layers of a 24 mm square;
/// 2. two5d on a plane tilted 35° (normal at azimuth 30°): two layers of a 10 mm square;
/// 3. curved layers on a sphere, axes = normals: latitude circles from 60° down to 3° off the
///    pole;
/// 4. a path whose normals pass through the pole n = (0, 0, 1) (a meridian, including the pole);
/// 5. one passing 0.7° from the pole (inside the 2° singularity cone);
/// 6. one passing 3° from the pole (outside it).
fn synthetic() -> ToolPath {
    let m = profile();
    let mut path = ToolPath::default();
    for layer in 0..2 {
        let z = T * (layer as f64 + 1.0);
        let square: Vec<_> = [[-12.0, -12.0], [12.0, -12.0], [12.0, 12.0], [-12.0, 12.0]]
            .iter()
            .chain(std::iter::once(&[-12.0, -12.0]))
            .map(|c| ([c[0], c[1], z], [0.0, 0.0, 1.0]))
            .collect();
        add_path(&mut path, &m, 1, layer, &square);
    }
    let n2 = polar(35.0, 30.0);
    let u = unit(cross([0.0, 0.0, 1.0], n2));
    let v = cross(n2, u);
    for layer in 0..2 {
        let o = T * (layer as f64 + 1.0);
        let base = [8.0 + o * n2[0], 6.0 + o * n2[1], 10.0 + o * n2[2]];
        let corners = [
            [-5.0, -5.0],
            [5.0, -5.0],
            [5.0, 5.0],
            [-5.0, 5.0],
            [-5.0, -5.0],
        ];
        let square: Vec<_> = corners
            .iter()
            .map(|c| {
                (
                    [
                        base[0] + c[0] * u[0] + c[1] * v[0],
                        base[1] + c[0] * u[1] + c[1] * v[1],
                        base[2] + c[0] * u[2] + c[1] * v[2],
                    ],
                    n2,
                )
            })
            .collect();
        add_path(&mut path, &m, 2, 2 + layer, &square);
    }
    for (layer, psi) in [60.0, 40.0, 20.0, 8.0, 3.0].into_iter().enumerate() {
        add_path(&mut path, &m, 3, 4 + layer, &latitude(psi, 8));
    }
    add_path(&mut path, &m, 4, 9, &past_the_pole(0.0, 1.0, 25.0));
    add_path(&mut path, &m, 5, 10, &past_the_pole(0.7, 1.0, -40.0));
    add_path(&mut path, &m, 6, 11, &past_the_pole(3.0, 1.0, 110.0));
    path
}

fn literal(v: &Value) -> f64 {
    match v {
        Value::Literal(x) => f64::from(*x),
        other => panic!("not a literal: {other:?}"),
    }
}

/// One `G0`/`G1` read back: the joints before and after, E and F, and the comments in force.
#[derive(Debug, Clone, Copy)]
struct Move {
    rapid: bool,
    from: [f64; 5],
    to: [f64; 5],
    /// X, Y, Z, B or C given.
    moved: bool,
    e: Option<f64>,
    f: Option<f64>,
    layer: Option<usize>,
    feature: Option<usize>,
}

impl Move {
    fn is_print(&self) -> bool {
        !self.rapid && self.moved && self.e.is_some()
    }
}

#[derive(Debug, Default)]
struct Parsed {
    moves: Vec<Move>,
    offset: Option<[f64; 3]>,
    safe_z: Option<f64>,
}

fn parse(program: &str) -> Parsed {
    let gc =
        gcode::parse(program).unwrap_or_else(|d| panic!("gcode crate refused the program: {d:?}"));
    let mut out = Parsed::default();
    let (mut layer, mut feature) = (None, None);
    let mut pos = [f64::NAN; 5];
    // The profile's start and end G-code (the purge line) are not the part's moves.
    let mut custom = false;
    for block in &gc.blocks {
        for c in &block.comments {
            let text = c.value.trim();
            if text == "start_gcode" || text == "end_gcode" {
                custom = true;
            } else if text == "end of start_gcode" {
                custom = false;
            } else if let Some(n) = text.strip_prefix("FEATURE_LAYER:") {
                layer = Some(n.parse().unwrap());
            } else if let Some(n) = text.strip_prefix("FEATURE:") {
                feature = Some(n.parse().unwrap());
            } else if let Some(rest) = text.strip_prefix("offset ") {
                let v: Vec<f64> = rest
                    .split_whitespace()
                    .take(3)
                    .map(|w| w[1..].parse().unwrap())
                    .collect();
                out.offset = Some([v[0], v[1], v[2]]);
            } else if let Some(rest) = text.strip_prefix("safe height Z") {
                out.safe_z = rest.split_whitespace().next().map(|w| w.parse().unwrap());
            }
        }
        for code in block.codes.iter().filter(|_| !custom) {
            let Code::General(g) = code else { continue };
            let major = g.number.major();
            if major != 0 && major != 1 {
                continue;
            }
            let from = pos;
            let (mut e, mut f, mut moved) = (None, None, false);
            for a in &g.args {
                let v = literal(&a.value);
                match a.letter.to_ascii_uppercase() {
                    'X' => (pos[0], moved) = (v, true),
                    'Y' => (pos[1], moved) = (v, true),
                    'Z' => (pos[2], moved) = (v, true),
                    'B' => (pos[3], moved) = (v, true),
                    'C' => (pos[4], moved) = (v, true),
                    'E' => e = Some(v),
                    'F' => f = Some(v),
                    other => panic!("unexpected argument {other}"),
                }
            }
            assert!(f.is_some_and(|f| f > 0.0), "every move has a feed: {g}");
            out.moves.push(Move {
                rapid: major == 0,
                from,
                to: pos,
                moved,
                e,
                f,
                layer,
                feature,
            });
        }
    }
    out
}

/// Runs the post on the path after a round trip through `toolpath.csv`, and reads the program
/// back; returns the CSV's path too (what the program must reproduce).
fn run(path: &ToolPath, m: &MachineProfile) -> (ToolPath, Delta5Program, Parsed) {
    let from_csv = ToolPath::from_csv(&path.to_csv()).unwrap();
    let program = delta5(&from_csv, m, "sphere.step").unwrap();
    let parsed = parse(&program.gcode);
    (from_csv, program, parsed)
}

/// Walks the program's print moves along the planned print points: every move ends on its
/// planned segment, each planned point is reached with its filament (a point merged into the
/// next move, its filament with that move). Returns, per planned print point the program
/// moves to, the index of the move that reaches it.
fn match_points(planned: &ToolPath, parsed: &Parsed, m: &MachineProfile) -> Vec<(usize, usize)> {
    let g = m.delta5.as_ref().unwrap();
    let offset = parsed.offset.expect("offset comment");
    let prints: Vec<&Move> = parsed.moves.iter().filter(|mv| mv.is_print()).collect();
    let mut k = 0;
    let mut out = Vec::new();
    let mut carry = 0.0;
    for (i, q) in planned.points.iter().enumerate() {
        if q.kind != MoveKind::Print {
            continue;
        }
        let a = if i > 0 { planned.points[i - 1].p } else { q.p };
        // A planned move that goes nowhere on the machine is merged into the next: the
        // machine is already at the point and the next move does not end there; its filament
        // goes with the next move.
        let here = match prints.get(k) {
            Some(mv) => mv.from,
            None => prints[k - 1].to,
        };
        let ends_here = |mv: &Move| norm(sub(forward(mv.to, g, offset).0, q.p)) <= 0.01;
        if norm(sub(forward(here, g, offset).0, q.p)) <= 0.01
            && !prints.get(k).is_some_and(|mv| ends_here(mv))
        {
            carry += q.e;
            continue;
        }
        let mut e_sum = -std::mem::take(&mut carry);
        loop {
            assert!(k < prints.len(), "program ends before planned point {i}");
            let mv = prints[k];
            k += 1;
            let (p, _) = forward(mv.to, g, offset);
            let off = distance_to_segment(p, a, q.p);
            assert!(
                off <= 0.01,
                "point {i}: move {k} is {off} mm off its segment"
            );
            e_sum += mv.e.unwrap();
            if norm(sub(p, q.p)) <= 0.01 && (e_sum - q.e).abs() <= 1.5e-5 {
                assert_eq!(mv.feature, Some(q.feature as usize), "point {i}");
                assert_eq!(mv.layer, Some(q.layer as usize), "point {i}");
                out.push((i, k - 1));
                break;
            }
        }
    }
    assert_eq!(
        k,
        prints.len(),
        "print moves left after the last planned point"
    );
    out
}

#[test]
fn delta5_program_reparsed_reproduces_toolpath_csv() {
    let m = profile();
    let g = m.delta5.clone().unwrap();
    let (planned, program, parsed) = run(&synthetic(), &m);
    let offset = parsed.offset.unwrap();
    assert_eq!(offset, program.offset);
    let prints: Vec<&Move> = parsed.moves.iter().filter(|mv| mv.is_print()).collect();
    let cone = g.singularity_cone_deg;
    let (mut patched, mut worst_position, mut worst_axis) = (0, 0.0f64, 0.0f64);
    for (i, k) in match_points(&planned, &parsed, &m) {
        let q = &planned.points[i];
        let (p, axis) = forward(prints[k].to, &g, offset);
        worst_position = worst_position.max(norm(sub(p, q.p)));
        assert!(norm(sub(p, q.p)) <= 0.01, "point {i}");
        let off_pole = angle_deg(q.axis, [0.0, 0.0, 1.0]);
        let dev = angle_deg(axis, q.axis);
        if off_pole > cone {
            worst_axis = worst_axis.max(dev);
            assert!(dev <= 0.1, "point {i}: axis {dev}° off");
        } else {
            // Patched: off by at most the axis's own distance from the pole (≤ the cone).
            patched += 1;
            assert!(
                dev <= off_pole + 1e-3,
                "point {i}: axis {dev}° off, {off_pole}° from +Z"
            );
        }
        if q.feature == 4 {
            // Through the pole on a great circle: the patch is exact.
            assert!(dev <= 0.1, "point {i}: axis {dev}° off");
        }
    }
    eprintln!("round trip: position {worst_position:.5} mm, axis {worst_axis:.5}° outside the cone, {patched} patched points");
    // The +Z features have every point at the pole, the pole paths some.
    let counted: usize = program.figures.values().map(|f| f.singular_points).sum();
    assert_eq!(counted, patched);
    assert!(program.figures[&5].singular_points > 0 && program.figures[&6].singular_points == 0);
    // Every planned print point in the figures.
    for (f, k) in &program.figures {
        let n = planned
            .points
            .iter()
            .filter(|q| q.feature as usize == *f && q.kind == MoveKind::Print)
            .count();
        assert!(k.print_moves >= n, "feature {f}");
        assert_eq!(
            k.print_moves,
            prints.iter().filter(|mv| mv.feature == Some(*f)).count()
        );
    }
}

#[test]
fn delta5_axes_exact_without_a_cone() {
    // With no cone, only the pole itself is patched, and every axis is reproduced.
    let mut m = profile();
    m.delta5.as_mut().unwrap().singularity_cone_deg = 0.0;
    let g = m.delta5.clone().unwrap();
    let (planned, _, parsed) = run(&synthetic(), &m);
    let offset = parsed.offset.unwrap();
    let prints: Vec<&Move> = parsed.moves.iter().filter(|mv| mv.is_print()).collect();
    for (i, k) in match_points(&planned, &parsed, &m) {
        let (p, axis) = forward(prints[k].to, &g, offset);
        let q = &planned.points[i];
        assert!(norm(sub(p, q.p)) <= 0.01, "point {i}");
        assert!(angle_deg(axis, q.axis) <= 0.1, "point {i}");
    }
}

/// Total C travel of a feature's print moves (degrees).
fn c_travel(parsed: &Parsed, feature: usize) -> f64 {
    parsed
        .moves
        .iter()
        .filter(|mv| mv.is_print() && mv.feature == Some(feature))
        .map(|mv| (mv.to[4] - mv.from[4]).abs())
        .sum()
}

#[test]
fn delta5_singularity_cone_keeps_c_steps_small() {
    let m = profile();
    let g = m.delta5.clone().unwrap();
    let (_, program, parsed) = run(&synthetic(), &m);
    // No print move turns C further than the profile allows (4-decimal rounding aside).
    let mut largest = 0.0f64;
    for mv in parsed.moves.iter().filter(|mv| mv.is_print()) {
        let step = (mv.to[4] - mv.from[4]).abs();
        largest = largest.max(step);
        assert!(step <= g.max_c_step_deg + 1e-3, "{mv:?}");
    }
    eprintln!("largest C step of a print move: {largest:.4}°");
    for k in program.figures.values() {
        assert!(k.max_c_step_deg <= g.max_c_step_deg + 1e-9);
    }
    // Through the pole on a great circle: C does not move at all (B changes sign instead).
    // (C is near 1800° there: the f32 the gcode crate reads carries 1e-4° of noise per move.)
    assert!(c_travel(&parsed, 4) < 0.01, "{}", c_travel(&parsed, 4));
    // 0.7° from the pole, tracking the azimuth would swing C through 180° − 2·atan(tan 0.7° /
    // sin 8°) ≈ 170°; the patch interpolates across the cone instead.
    let patched = c_travel(&parsed, 5);
    assert!(patched < 90.0, "C turns {patched}° near the pole");
    // Without the cone it does swing round (in steps the C limit splits).
    let mut bare = m.clone();
    bare.delta5.as_mut().unwrap().singularity_cone_deg = 0.0;
    let (_, _, unpatched) = run(&synthetic(), &bare);
    let swing = c_travel(&unpatched, 5);
    let d = 0.7f64.to_radians();
    let expected = 180.0 - 2.0 * (d.tan() / 8f64.to_radians().sin()).atan().to_degrees();
    assert!(swing > expected - 1.0, "C swing {swing}° vs {expected}°");
    for mv in unpatched.moves.iter().filter(|mv| mv.is_print()) {
        assert!((mv.to[4] - mv.from[4]).abs() <= g.max_c_step_deg + 1e-3);
    }
    eprintln!("C travel near the pole: {patched:.2}° patched, {swing:.2}° unpatched");
}

#[test]
fn delta5_c_is_unwrapped_or_kept_within_its_limits() {
    let m = profile();
    let mut path = ToolPath::default();
    for layer in 0..5 {
        add_path(&mut path, &m, 1, layer, &latitude(45.0, 8));
    }
    let (_, _, parsed) = run(&path, &m);
    // Five turns the same way: C climbs past 1800° with no jump of a whole turn anywhere.
    let c_max = parsed
        .moves
        .iter()
        .map(|mv| mv.to[4])
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(c_max >= 5.0 * 360.0 - 1.0, "{c_max}");
    for mv in parsed.moves.iter().filter(|mv| mv.from[4].is_finite()) {
        assert!((mv.to[4] - mv.from[4]).abs() < 180.0, "{mv:?}");
    }

    // Limited to ±360°: each turn is brought back into the limits (on a travel).
    let mut limited = m.clone();
    let g = limited.delta5.as_mut().unwrap();
    g.c_continuous = false;
    g.c_limits_deg = [-360.0, 360.0];
    let (planned, _, parsed) = run(&path, &limited);
    for mv in &parsed.moves {
        if mv.to[4].is_finite() {
            assert!(mv.to[4].abs() <= 360.0 + 1e-4, "{mv:?}");
        }
    }
    match_points(&planned, &parsed, &limited);
    // A whole turn does not fit in 300°... limits of 360° that are not aligned with it: refused.
    let g = limited.delta5.as_mut().unwrap();
    g.c_limits_deg = [-200.0, 200.0];
    let err = delta5(&path, &limited, "x").unwrap_err();
    assert!(
        matches!(err, PostError::Delta5CLimits { feature: 1, .. }),
        "{err:?}"
    );
    let msg = err.to_string();
    assert!(msg.contains("feature 1") && !msg.contains('\n'), "{msg}");
}

#[test]
fn delta5_kinematic_error_within_the_goal() {
    let m = profile();
    let g = m.delta5.clone().unwrap();
    let (planned, program, parsed) = run(&synthetic(), &m);
    let offset = parsed.offset.unwrap();
    // Recompute the error from the program alone: the controller's linear interpolation at
    // its resolutions, taken back to the part, against the planned segment.
    let mut recomputed: std::collections::BTreeMap<usize, (f64, f64, usize)> = Default::default();
    let prints: Vec<&Move> = parsed.moves.iter().filter(|mv| mv.is_print()).collect();
    let matched = match_points(&planned, &parsed, &m);
    let mut first = 0;
    for &(i, last) in &matched {
        let q = &planned.points[i];
        let a = planned.points[i - 1].p;
        for mv in &prints[first..=last] {
            let (j0, j1) = (mv.from, mv.to);
            let steps = [
                (j1[0] - j0[0]).abs() / g.resolution_xyz,
                (j1[1] - j0[1]).abs() / g.resolution_xyz,
                (j1[2] - j0[2]).abs() / g.resolution_xyz,
                (j1[3] - j0[3]).abs() / g.resolution_b_deg,
                (j1[4] - j0[4]).abs() / g.resolution_c_deg,
            ]
            .into_iter()
            .fold(1.0, f64::max)
            .ceil() as usize;
            let entry = recomputed.entry(q.feature as usize).or_default();
            for s in 1..=steps {
                let f = s as f64 / steps as f64;
                let j: [f64; 5] = std::array::from_fn(|k| j0[k] + (j1[k] - j0[k]) * f);
                let (p, _) = forward(j, &g, offset);
                let d = distance_to_segment(p, a, q.p);
                entry.0 = entry.0.max(d);
                entry.1 += d;
                entry.2 += 1;
            }
        }
        first = last + 1;
    }
    for (f, k) in &program.figures {
        let (max, sum, n) = recomputed[f];
        eprintln!(
            "feature {f}: kinematic error max {:.5} mm, mean {:.5} mm, {} segments subdivided, {} moves, {} singular, axis {:.4}°",
            k.max_mm, k.mean_mm, k.subdivided_segments, k.print_moves, k.singular_points, k.max_axis_deviation_deg
        );
        assert!(
            k.max_mm <= g.kinematic_error_goal,
            "feature {f}: {}",
            k.max_mm
        );
        // The figures are the program's (f32 parsing and rounding aside).
        assert!(
            (max - k.max_mm).abs() <= 2e-3,
            "feature {f}: {max} vs {}",
            k.max_mm
        );
        assert!((sum / n as f64 - k.mean_mm).abs() <= 2e-3, "feature {f}");
        assert!(k.mean_mm <= k.max_mm && k.samples > 0);
    }
}

#[test]
fn delta5_subdivides_where_rotation_carries_the_error() {
    // A coarse latitude circle 45° off the pole: twelve 30° turns of C with the nozzle still.
    let m = profile();
    let mut path = ToolPath::default();
    let psi: f64 = 45.0;
    let circle: Vec<_> = (0..=12)
        .map(|k| on_sphere(polar(psi, 30.0 * k as f64)))
        .collect();
    add_path(&mut path, &m, 7, 0, &circle);
    // Neither the C step nor the goal splitting anything: the joint interpolation sweeps the
    // arc instead of the chord, so the error is the arc's sagitta r·(1 − cos 15°).
    let mut loose = m.clone();
    let g = loose.delta5.as_mut().unwrap();
    g.max_c_step_deg = 180.0;
    g.kinematic_error_goal = 10.0;
    let unsplit = delta5(&path, &loose, "x").unwrap();
    let r = R * psi.to_radians().sin();
    let sagitta = r * (1.0 - 15f64.to_radians().cos());
    let k = &unsplit.figures[&7];
    assert_eq!(k.subdivided_segments, 0);
    assert!(
        (k.max_mm - sagitta).abs() <= 0.01 * sagitta + 2e-3,
        "{} vs {sagitta}",
        k.max_mm
    );
    // With the goal (and no C step limit) every segment is split and the error meets it.
    let mut goal_only = loose.clone();
    goal_only.delta5.as_mut().unwrap().kinematic_error_goal = 0.05;
    let split = delta5(&path, &goal_only, "x").unwrap();
    let k = &split.figures[&7];
    assert_eq!(k.subdivided_segments, 12);
    assert!(k.max_mm <= 0.05, "{}", k.max_mm);
    // Splitting a turn by n divides the sagitta by about n²: no more moves than that needs.
    let needed = (sagitta / 0.05).sqrt().ceil() as usize;
    assert!(k.print_moves <= 12 * 2 * needed, "{} moves", k.print_moves);
    eprintln!(
        "coarse circle: {:.4} mm unsplit (sagitta {sagitta:.4}), {:.4} mm in {} moves",
        unsplit.figures[&7].max_mm, k.max_mm, k.print_moves
    );
}

#[test]
fn delta5_extrusion_feed_and_travel() {
    let m = profile();
    let g = m.delta5.clone().unwrap();
    let (planned, program, parsed) = run(&synthetic(), &m);
    let offset = parsed.offset.unwrap();
    // E total of the print moves equals the path's.
    let e_path: f64 = planned.points.iter().map(|q| q.e).sum();
    let e_prints: f64 = parsed
        .moves
        .iter()
        .filter(|mv| mv.is_print())
        .map(|mv| mv.e.unwrap())
        .sum();
    assert!((e_prints - e_path).abs() <= 1e-4, "{e_prints} vs {e_path}");
    // Retraction balances between print moves.
    let mut gap = 0.0f64;
    for mv in &parsed.moves {
        if mv.is_print() {
            assert!(gap.abs() < 1e-6, "net E {gap} before {mv:?}");
            gap = 0.0;
        } else if let Some(e) = mv.e {
            gap += e;
        }
    }
    // F keeps the planned deposition speed along the part: part length × F / machine distance.
    let matched = match_points(&planned, &parsed, &m);
    let prints: Vec<&Move> = parsed.moves.iter().filter(|mv| mv.is_print()).collect();
    let mut first = 0;
    let mut checked = 0;
    let mut clamped = 0;
    for &(i, last) in &matched {
        let q = &planned.points[i];
        let bottom = q.p[2] - T * unit(q.axis)[2] + offset[2];
        let v = if bottom <= 0.01 {
            m.first_layer_speed
        } else {
            m.print_speed
        };
        for mv in &prints[first..=last] {
            let (p0, _) = forward(mv.from, &g, offset);
            let (p1, _) = forward(mv.to, &g, offset);
            let part = norm(sub(p1, p0));
            let xyz = norm(sub(
                [mv.to[0], mv.to[1], mv.to[2]],
                [mv.from[0], mv.from[1], mv.from[2]],
            ));
            let rotary = (mv.to[3] - mv.from[3]).hypot(mv.to[4] - mv.from[4]);
            let distance = if xyz > 1e-9 { xyz } else { rotary };
            if part < 0.1 || distance <= 0.0 {
                continue;
            }
            let f = mv.f.unwrap();
            let speed = part * f / 60.0 / distance;
            let tol = v * (0.004 / part + 0.001 / f + 2e-3);
            // A feed clamped to max_feed_mm_min is slower over the part, never faster.
            let max_feed = m.max_feed_mm_min();
            assert!(f <= max_feed, "point {i}: F{f} above {max_feed}");
            if f == max_feed {
                assert!(speed <= v + tol, "point {i}: {speed} mm/s vs {v}: {mv:?}");
                clamped += 1;
                continue;
            }
            assert!(
                (speed - v).abs() <= tol,
                "point {i}: {speed} mm/s vs {v}: {mv:?}"
            );
            checked += 1;
        }
        first = last + 1;
    }
    assert!(checked > 100, "{checked}");
    // Moves slowed to max_feed_mm_min are counted in the program's figure, and warned of
    // only where they are more than 1 % of the print moves.
    assert_eq!(program.feed_clamped_moves, clamped);
    let print_moves: usize = program.figures.values().map(|k| k.print_moves).sum();
    assert_eq!(
        clamped as f64 > robot_post::delta5::FEED_CLAMP_WARN_SHARE * print_moves as f64,
        program
            .warnings
            .iter()
            .any(|w| w.contains("max_feed_mm_min")),
        "{clamped} clamped of {print_moves}: {:?}",
        program.warnings
    );
    // Every position inside the envelope; every large reorientation at the safe height.
    let safe_z = parsed.safe_z.expect("safe height comment");
    assert!((safe_z - program.safe_z).abs() < 1e-3);
    let mut reorientations = 0;
    for mv in parsed.moves.iter().filter(|mv| mv.to[0].is_finite()) {
        assert!(mv.to[0].abs() <= 100.0 && mv.to[1].abs() <= 100.0, "{mv:?}");
        assert!(mv.to[2] >= g.z_min && mv.to[2] <= m.bed_size[2], "{mv:?}");
        let turn = (mv.to[3] - mv.from[3])
            .abs()
            .max((mv.to[4] - mv.from[4]).abs());
        if turn > g.reorient_lift_deg {
            assert!(mv.rapid && (mv.to[2] - safe_z).abs() < 1e-3, "{mv:?}");
            reorientations += 1;
        }
    }
    assert!(reorientations >= 2, "{reorientations}");
    // The safe height clears the part wherever the bed turns: above every planned point at the
    // largest and smallest B the program uses, for any C.
    let g_pivot_z = g.b_axis_z;
    for q in &planned.points {
        let t = [
            q.p[0] + offset[0],
            q.p[1] + offset[1],
            q.p[2] + offset[2] + g.table_above_b_axis,
        ];
        assert!(g_pivot_z + norm(t) < safe_z);
    }
}

#[test]
fn delta5_numbers_are_fixed_point() {
    let program = delta5(&synthetic(), &profile(), "sphere.step")
        .unwrap()
        .gcode;
    // The program's own lines: the profile's start and end G-code are the user's text.
    let start = program.find("; end of start_gcode").unwrap();
    let end = program.find("; end_gcode").unwrap();
    for line in program[..program.find("; start_gcode").unwrap()]
        .lines()
        .chain(program[start..end].lines())
    {
        let code = line.split(';').next().unwrap_or("");
        let lower = code.to_ascii_lowercase();
        assert!(!lower.contains("nan") && !lower.contains("inf"), "`{line}`");
        assert!(!code.contains("e+") && !code.contains("e-"), "`{line}`");
        for word in code.split_whitespace() {
            let (letter, number) = word.split_at(1);
            let decimals = number.split('.').nth(1).map(str::len);
            match letter {
                "X" | "Y" | "Z" => assert_eq!(decimals, Some(3), "`{line}`"),
                "B" | "C" => assert_eq!(decimals, Some(4), "`{line}`"),
                "E" if !code.starts_with("G92") => assert_eq!(decimals, Some(5), "`{line}`"),
                "F" if code.starts_with("G1 X") => assert_eq!(decimals, Some(3), "`{line}`"),
                "F" | "S" => assert!(number.bytes().all(|c| c.is_ascii_digit()), "`{line}`"),
                _ => {}
            }
            assert!(
                number != "-0.000" && number != "-0.0000" && number != "-0.00000",
                "`{line}`"
            );
        }
    }
    let lines: Vec<&str> = program.lines().collect();
    assert_eq!(lines[0], "; generated by features from sphere.step");
    assert!(lines.iter().any(|l| l.starts_with("; offset X")));
    assert!(lines.iter().any(|l| l.contains("feature 3: max ")));
    assert!(program.ends_with("G28 ; home\nM84 ; motors off\n"));
}

#[test]
fn delta5_error_plot_is_svg() {
    let program = delta5(&synthetic(), &profile(), "a<b>&\"c\".step").unwrap();
    let svg = &program.error_plot_svg;
    assert!(svg.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""));
    assert!(svg.trim_end().ends_with("</svg>"));
    assert!(
        svg.contains("kinematic error (mm)") && svg.contains("length along the printed path (mm)")
    );
    assert!(svg.contains("class=\"goal\"") && svg.contains("goal 0.050 mm"));
    assert!(svg.contains("a&lt;b&gt;&amp;&quot;c&quot;.step"));
    for f in program.figures.keys() {
        assert!(
            svg.contains(&format!("class=\"feature-{f}\"")),
            "feature {f}"
        );
        assert!(svg.contains(&format!(">feature {f}</text>")), "feature {f}");
    }
    // Every plotted point inside the 900 x 420 canvas.
    for line in svg.lines().filter(|l| l.starts_with("<polyline")) {
        let points = line
            .split("points=\"")
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap();
        for pair in points.split_whitespace() {
            let (x, y) = pair.split_once(',').unwrap();
            let (x, y): (f64, f64) = (x.parse().unwrap(), y.parse().unwrap());
            assert!(
                (0.0..=900.0).contains(&x) && (0.0..=420.0).contains(&y),
                "{pair}"
            );
        }
    }
    assert_eq!(svg.matches("<svg").count(), 1);
}

#[test]
fn delta5_refuses_what_it_cannot_print() {
    let m = profile();
    // Another kind of machine.
    let err = delta5(
        &synthetic(),
        &MachineProfile::builtin(MachineKind::Marlin),
        "x",
    )
    .unwrap_err();
    assert!(err.to_string().contains("not `delta5`"), "{err}");
    assert!(matches!(err, PostError::WrongMachine { .. }));
    // A non-finite number.
    let mut path = synthetic();
    path.points[4].axis[1] = f64::NAN;
    let msg = delta5(&path, &m, "x").unwrap_err().to_string();
    assert!(
        msg.contains("point 4") && msg.contains(": j is not a finite"),
        "{msg}"
    );
    // An axis beyond the B limits (±90°): pointing below the horizon.
    let mut path = synthetic();
    for q in path
        .points
        .iter_mut()
        .filter(|q| q.feature == 2 && q.layer == 3)
    {
        q.feature = 9;
        q.axis = unit([1.0, 0.2, -0.3]);
    }
    let err = delta5(&path, &m, "x").unwrap_err();
    assert!(
        matches!(err, PostError::Delta5Axis { feature: 9, .. }),
        "{err:?}"
    );
    let msg = err.to_string();
    assert!(
        msg.contains("feature 9") && msg.contains("B limits") && !msg.contains('\n'),
        "{msg}"
    );
    // A zero axis.
    let mut path = synthetic();
    path.points[7].axis = [0.0; 3];
    let f = path.points[7].feature;
    let msg = delta5(&path, &m, "x").unwrap_err().to_string();
    assert!(
        msg.contains(&format!("feature {f}")) && msg.contains("not a direction"),
        "{msg}"
    );
    // A part leaving the work envelope: a 300 mm square on a 200 mm machine.
    let mut big = ToolPath::default();
    let corners = [[-150.0, -150.0], [150.0, -150.0], [150.0, 150.0]];
    let square: Vec<_> = corners
        .iter()
        .map(|c| ([c[0], c[1], T], [0.0, 0.0, 1.0]))
        .collect();
    add_path(&mut big, &m, 4, 0, &square);
    let err = delta5(&big, &m, "big.step").unwrap_err();
    assert!(
        matches!(err, PostError::Delta5Envelope { feature: 4, .. }),
        "{err:?}"
    );
    let msg = err.to_string();
    assert!(
        msg.contains("feature 4") && msg.contains("mm below -100.000") && !msg.contains('\n'),
        "{msg}"
    );
    // A tall part tilted far: its top swings below the lowest Z the nozzle reaches.
    let mut tall = ToolPath::default();
    let column: Vec<_> = [[-1.0, 0.0, T], [0.0, 0.0, T], [0.0, 0.0, 150.0]]
        .iter()
        .map(|&p| (p, [0.0, 0.0, 1.0]))
        .collect();
    add_path(&mut tall, &m, 1, 0, &column);
    let tip: Vec<_> = [[0.0, 0.0, 150.0], [1.0, 0.0, 150.0]]
        .iter()
        .map(|&p| (p, unit([-1.0, 0.0, 0.05])))
        .collect();
    add_path(&mut tall, &m, 5, 1, &tip);
    let err = delta5(&tall, &m, "tall.step").unwrap_err();
    assert!(
        matches!(err, PostError::Delta5Envelope { feature: 5, .. }),
        "{err:?}"
    );
    // An invalid profile.
    let mut bad = m.clone();
    bad.delta5.as_mut().unwrap().max_c_step_deg = 0.0;
    assert!(matches!(
        delta5(&synthetic(), &bad, "x"),
        Err(PostError::ProfileValue {
            field: "delta5.max_c_step_deg",
            ..
        })
    ));
}

#[test]
fn delta5_edge_cases() {
    let m = profile();
    // Empty path: header and footer only.
    let empty = delta5(&ToolPath::default(), &m, "empty.step").unwrap();
    assert!(empty.figures.is_empty() && !parse(&empty.gcode).moves.iter().any(|mv| mv.is_print()));
    gcode::parse(&empty.gcode).unwrap();
    assert!(empty.error_plot_svg.contains("</svg>"));
    // A path starting with a print point travels to it first.
    let mut path = ToolPath::default();
    add_path(&mut path, &m, 0, 0, &latitude(30.0, 8));
    path.points[0].kind = MoveKind::Print;
    path.points[0].e = 0.01;
    let (planned, program, parsed) = run(&path, &m);
    match_points(&planned, &parsed, &m);
    let e: f64 = parsed
        .moves
        .iter()
        .filter(|mv| mv.is_print())
        .map(|mv| mv.e.unwrap())
        .sum();
    let e_path: f64 = planned.points.iter().map(|q| q.e).sum();
    assert!((e - e_path).abs() < 1e-4);
    assert!(program.gcode.find("G0 X").unwrap() < program.gcode.find("G1 X").unwrap());
    // No hop, no retraction, no heated bed.
    let mut bare = m.clone();
    (bare.z_hop, bare.retraction_length, bare.bed_temperature) = (0.0, 0.0, 0.0);
    let (planned, program, parsed) = run(&synthetic(), &bare);
    // (The heating is the profile's start_gcode: its placeholders give the bed 0 degrees.)
    let own = &program.gcode[program.gcode.find("; end of start_gcode").unwrap()..];
    assert!(program.gcode.contains("M140 S0 ; bed") && !own.contains("G1 E"));
    match_points(&planned, &parsed, &bare);
}

#[test]
fn delta5_inverse_and_forward_agree() {
    let g = profile().delta5.unwrap();
    // Eq. 9–12 against the forward kinematics over a grid of axes, each from a previous C.
    for psi in [0.5, 10.0, 45.0, 89.0] {
        for alpha in (0..12).map(|k| -180.0 + 30.0 * k as f64 + 7.0) {
            let axis = polar(psi, alpha);
            for previous in [None, Some(0.0), Some(170.0), Some(-725.0)] {
                let (b, c) = inverse(axis, previous, &g).unwrap();
                let (_, back) = forward([0.0, 0.0, 0.0, b, c], &g, [0.0; 3]);
                assert!(angle_deg(axis, back) < 1e-9);
                if let Some(p) = previous {
                    assert!((c - p).abs() <= 90.0 + 1e-9, "{p} -> {c}");
                }
            }
        }
    }
}

#[test]
fn delta5_profile_table_is_documented_and_checked() {
    let m = profile();
    let g = m.delta5.clone().unwrap();
    assert_eq!(
        (g.resolution_xyz, g.resolution_b_deg, g.resolution_c_deg),
        (0.1, 0.06, 0.1)
    );
    assert_eq!(g.kinematic_error_goal, 0.05);
    // Every key of the table has a comment line above it.
    let table = DELTA5_TOML.split("\n[delta5]\n").nth(1).unwrap();
    let lines: Vec<&str> = table.lines().collect();
    let keys: Vec<&str> = lines
        .iter()
        .filter(|l| !l.starts_with('#') && l.contains(" = "))
        .map(|l| l.split(" = ").next().unwrap())
        .collect();
    assert_eq!(keys.len(), 16);
    for (i, l) in lines.iter().enumerate() {
        if !l.starts_with('#') && l.contains(" = ") {
            assert!(
                lines[i - 1].starts_with('#') || lines[i - 1].contains(" = "),
                "{l}"
            );
        }
    }
    // Unknown and missing keys refused, naming them; bad values refused, one line each.
    let unknown = DELTA5_TOML.replace("z_min = -50.0", "z_min = -50.0\nzmin = 1.0");
    let missing = DELTA5_TOML.replace("max_c_step_deg = 5.0", "");
    let cone = DELTA5_TOML.replace("singularity_cone_deg = 2.0", "singularity_cone_deg = 50.0");
    let b = DELTA5_TOML.replace(
        "b_limits_deg = [-90.0, 90.0]",
        "b_limits_deg = [10.0, 90.0]",
    );
    let c = DELTA5_TOML.replace(
        "c_limits_deg = [-360.0, 360.0]",
        "c_limits_deg = [0.0, 100.0]",
    );
    let res = DELTA5_TOML.replace("resolution_b_deg = 0.06", "resolution_b_deg = -0.06");
    let goal = DELTA5_TOML.replace("kinematic_error_goal = 0.05", "kinematic_error_goal = nan");
    for (text, needle) in [
        (unknown.as_str(), "zmin"),
        (missing.as_str(), "max_c_step_deg"),
        (cone.as_str(), "singularity_cone_deg"),
        (b.as_str(), "b_limits_deg"),
        (c.as_str(), "c_limits_deg"),
        (res.as_str(), "resolution_b_deg"),
        (goal.as_str(), "kinematic_error_goal"),
    ] {
        assert_ne!(text, DELTA5_TOML, "{needle}");
        let e = MachineProfile::from_toml(text).unwrap_err().to_string();
        assert!(e.contains(needle), "{e}");
        assert!(!e.contains('\n'), "{e}");
    }
    // A z_min above the envelope's top is refused when posting.
    let mut high = m.clone();
    high.delta5.as_mut().unwrap().z_min = 500.0;
    let msg = delta5(&synthetic(), &high, "x").unwrap_err().to_string();
    assert!(msg.contains("z_min"), "{msg}");
}

/// The delta5 program carries the same `;TYPE:` comments as Marlin's (one writer for both):
/// two latitude circles of one layer, the outer `External perimeter` and the inner
/// `Perimeter`, then one circle on the next layer, `Perimeter` again; every print move lies
/// under a `;TYPE:` of its layer.
#[test]
fn delta5_type_comments_follow_the_roles() {
    let m = profile();
    let mut path = ToolPath::default();
    for (layer, psi) in [(0, 30.0), (0, 25.0), (1, 20.0)] {
        let from = path.points.len();
        add_path(&mut path, &m, 1, layer, &latitude(psi, 16));
        let role = if psi == 30.0 {
            Role::ExternalPerimeter
        } else {
            Role::Perimeter
        };
        for q in &mut path.points[from..] {
            q.role = role;
        }
    }
    let program = delta5(&path, &m, "sphere.step").unwrap().gcode;
    let types: Vec<&str> = program
        .lines()
        .filter_map(|l| l.strip_prefix(";TYPE:"))
        .collect();
    assert_eq!(types, ["External perimeter", "Perimeter", "Perimeter"]);
    let mut typed = false;
    // The planned moves: between the profile's start_gcode (its purge line prints, untyped)
    // and its end_gcode.
    for l in program
        .lines()
        .skip_while(|l| *l != "; end of start_gcode")
        .take_while(|l| *l != "; end_gcode")
    {
        if l == ";LAYER_CHANGE" {
            typed = false;
        } else if l.starts_with(";TYPE:") {
            typed = true;
        } else if l.starts_with("G1 ") && l.contains(" E") && !l.contains(" E-") {
            assert!(typed, "{l}");
        }
    }
}

/// `joints.csv` gives, for every move from the path's first on, the B and C the program's
/// line sets (modal), within the B limits (those B and C reproduce the planned axes:
/// `delta5_program_reparsed_reproduces_toolpath_csv`).
#[test]
fn delta5_joints_csv_follows_the_moves() {
    let m = profile();
    let path = synthetic();
    let program = delta5(&path, &m, "sphere.step").unwrap();
    let mut rows = program.joints_csv.lines();
    assert_eq!(rows.next(), Some(robot_post::delta5::DELTA5_JOINTS_HEADER));
    let rows: Vec<Vec<&str>> = rows.map(|r| r.split(',').collect()).collect();
    // The program's moves after the start G-code: the path starts at the first `;LAYER:`.
    let start = program.gcode.find(";LAYER:").expect("a layer");
    let (mut b, mut c) = (String::new(), String::new());
    let mut n = 0;
    for line in program.gcode[start..].lines() {
        let code = line.split(';').next().unwrap_or_default();
        let mut words = code.split_whitespace();
        if !matches!(words.next(), Some("G0" | "G1")) {
            continue;
        }
        let words: Vec<&str> = words.collect();
        if !words
            .iter()
            .any(|w| w.starts_with(['X', 'Y', 'Z', 'B', 'C']))
        {
            continue;
        }
        for w in &words {
            if let Some(v) = w.strip_prefix('B') {
                b = v.to_string();
            }
            if let Some(v) = w.strip_prefix('C') {
                c = v.to_string();
            }
        }
        let row = &rows[n];
        assert_eq!(row[0], (n + 1).to_string());
        assert_eq!((row[1], row[2]), (b.as_str(), c.as_str()), "{line}");
        n += 1;
    }
    assert_eq!(n, rows.len(), "one row per move");
    assert!(n > path.points.len() / 2);
    // B and C of the rows are within the machine's limits.
    let g = m.delta5.as_ref().expect("delta5");
    for row in &rows {
        if let Ok(b) = row[1].parse::<f64>() {
            assert!(
                b >= g.b_limits_deg[0] - 1e-4 && b <= g.b_limits_deg[1] + 1e-4,
                "{row:?}"
            );
        }
    }
}
