//! Orientation smoothing (Chalvin et al. 2022, Eq. 3–7): smoother axes, every axis unit and
//! inside its tolerance cone, zero phase, median against spikes, runs kept apart, only axes
//! changed, and the `[orientation]` process table.

use slicer::orient::{
    angle_between, cone_correct, continuous_paths, filter_axes, orientation_step_rate, smooth,
    Filter, OrientationFigures, SmoothParams,
};
use slicer::toolpath::{MoveKind, PathPoint, ToolPath};

const FILTERS: [Filter; 2] = [Filter::MovingAverage, Filter::Median];

fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// The unit axis tilted `deg` degrees from +Z towards +X.
fn tilt_x(deg: f64) -> [f64; 3] {
    let t = deg.to_radians();
    [t.sin(), 0.0, t.cos()]
}

/// A deterministic pseudo-random number in [-1, 1) (xorshift; no dependency).
fn noise(state: &mut u64) -> f64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    (*state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

fn point(feature: usize, layer: usize, kind: MoveKind, p: [f64; 3], axis: [f64; 3]) -> PathPoint {
    PathPoint {
        feature: feature as u32,
        layer: layer as u32,
        kind,
        p,
        axis,
        e: if kind == MoveKind::Print { 0.01 } else { 0.0 },
        thickness: 0.2,
        width: 0.4,
        role: slicer::toolpath::Role::Perimeter,
    }
}

/// One bead along +X at the given abscissae: a travel point at the first, print points after.
fn run(feature: usize, layer: usize, xs: &[f64], axes: &[[f64; 3]]) -> Vec<PathPoint> {
    assert_eq!(xs.len(), axes.len());
    xs.iter()
        .zip(axes)
        .enumerate()
        .map(|(i, (&x, &a))| {
            let kind = if i == 0 {
                MoveKind::Travel
            } else {
                MoveKind::Print
            };
            point(feature, layer, kind, [x, 0.0, layer as f64 * 0.2], a)
        })
        .collect()
}

fn params(filter: Filter, window_mm: f64, cone_angle_deg: f64) -> SmoothParams {
    SmoothParams {
        enabled: true,
        filter,
        window_mm,
        cone_angle_deg,
    }
}

/// Axes of a straight bead that jitter by up to `amp` degrees about +Z, both ways.
fn noisy_axes(n: usize, amp: f64, seed: u64) -> Vec<[f64; 3]> {
    let mut st = seed;
    (0..n)
        .map(|_| {
            let a = amp.to_radians() * noise(&mut st);
            let b = amp.to_radians() * noise(&mut st);
            unit([a.sin(), b.sin(), 1.0])
        })
        .collect()
}

fn uneven_xs(n: usize, seed: u64) -> Vec<[f64; 1]> {
    let mut st = seed;
    let mut x = 0.0;
    (0..n)
        .map(|_| {
            let here = x;
            x += 0.3 + 0.25 * (noise(&mut st) + 1.0);
            [here]
        })
        .collect()
}

fn xs_of(v: &[[f64; 1]]) -> Vec<f64> {
    v.iter().map(|a| a[0]).collect()
}

#[test]
fn noisy_axes_get_smaller_steps_and_rates() {
    for filter in FILTERS {
        for seed in [1u64, 77, 4242] {
            let xs = xs_of(&uneven_xs(80, seed));
            let mut path = ToolPath {
                points: run(0, 0, &xs, &noisy_axes(80, 12.0, seed ^ 0x9e37)),
            };
            let (step0, rate0) = orientation_step_rate(&path.points);
            let figs = smooth(&mut path, &params(filter, 5.0, 60.0));
            let (step1, rate1) = orientation_step_rate(&path.points);
            assert!(
                step1 < 0.5 * step0,
                "{filter:?} seed {seed}: step {step0} -> {step1}"
            );
            assert!(
                rate1 < rate0,
                "{filter:?} seed {seed}: rate {rate0} -> {rate1}"
            );
            let f = figs[&0];
            assert_eq!(f.step_max_deg_before, step0);
            assert_eq!(f.rate_max_deg_per_mm_before, rate0);
            assert_eq!(f.step_max_deg_after, step1);
            assert_eq!(f.rate_max_deg_per_mm_after, rate1);
        }
    }
}

/// Axes that swing hard: ±70° about Y alternating with tilts about X, so that the smoothed
/// axes leave narrow cones.
fn wild_axes(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut st = seed;
    (0..n)
        .map(|i| {
            let big = if (i / 3) % 2 == 0 { 70.0 } else { -70.0 };
            let a = (big + 15.0 * noise(&mut st)).to_radians();
            let b = (40.0 * noise(&mut st)).to_radians();
            unit([a.sin() * b.cos(), b.sin(), a.cos() * b.cos()])
        })
        .collect()
}

#[test]
fn every_smoothed_axis_is_unit_and_inside_its_cone() {
    for filter in FILTERS {
        for gamma in [0.2, 2.0, 10.0, 30.0, 60.0, 90.0, 140.0, 180.0] {
            let xs = xs_of(&uneven_xs(60, 9));
            let original = run(3, 1, &xs, &wild_axes(60, 5));
            let mut path = ToolPath {
                points: original.clone(),
            };
            smooth(&mut path, &params(filter, 4.0, gamma));
            let half = 0.5 * f64::to_radians(gamma);
            let mut on_boundary = 0;
            let mut moved = 0;
            for (q, o) in path.points.iter().zip(&original) {
                assert!((norm(q.axis) - 1.0).abs() < 1e-12, "{:?}", q.axis);
                let a = angle_between(q.axis, o.axis);
                assert!(
                    a <= half + 1e-9,
                    "{filter:?} γ {gamma}: axis {:?} is {}° from {:?}",
                    q.axis,
                    a.to_degrees(),
                    o.axis
                );
                if (a - half).abs() < 1e-9 {
                    on_boundary += 1;
                }
                if a > 1e-6 {
                    moved += 1;
                }
            }
            // The test bites: axes did move, and in narrow cones the correction was needed.
            assert!(moved > 30, "{filter:?} γ {gamma}: only {moved} axes moved");
            if gamma <= 30.0 {
                assert!(
                    on_boundary > 10,
                    "{filter:?} γ {gamma}: {on_boundary} axes on the cone"
                );
            }
        }
    }
}

#[test]
fn cone_correction_rotates_onto_the_boundary_towards_the_smoothed_axis() {
    let b = unit([0.2, -0.1, 1.0]);
    for (t, gamma) in [
        (unit([1.0, 0.3, 0.2]), 60.0),
        (unit([-0.5, 1.0, 0.1]), 20.0),
        (unit([0.0, 0.0, -1.0]), 90.0),
        (unit([0.3, 0.3, -1.0]), 1.0),
    ] {
        let half = 0.5 * f64::to_radians(gamma);
        let alpha = angle_between(t, b);
        assert!(alpha > half, "test vector inside its cone");
        let c = cone_correct(t, b, gamma);
        assert!((norm(c) - 1.0).abs() < 1e-12);
        // On the boundary (Eq. 7)...
        assert!((angle_between(c, b) - half).abs() < 1e-12, "{c:?}");
        // ... on the great circle from b to T_S, between them: the rotation is in their plane
        // and towards T_S (Eq. 5–6), not away from it.
        let n = [
            b[1] * t[2] - b[2] * t[1],
            b[2] * t[0] - b[0] * t[2],
            b[0] * t[1] - b[1] * t[0],
        ];
        if norm(n) > 1e-6 {
            let off_plane = (c[0] * n[0] + c[1] * n[1] + c[2] * n[2]) / norm(n);
            assert!(off_plane.abs() < 1e-12, "{c:?} leaves the plane of b, T_S");
            assert!((angle_between(c, t) - (alpha - half)).abs() < 1e-12);
        }
    }
    // Inside the cone: kept (Eq. 7, first case).
    let t = unit([0.25, -0.1, 1.0]);
    assert!(angle_between(t, b) < 0.5 * f64::to_radians(60.0));
    assert_eq!(cone_correct(t, b, 60.0), t);
}

#[test]
fn constant_axis_is_unchanged() {
    let xs = xs_of(&uneven_xs(40, 3));
    let a = unit([0.3, -0.4, 0.8]);
    for filter in FILTERS {
        for w in [0.1, 2.0, 50.0] {
            let original = run(0, 0, &xs, &vec![a; 40]);
            let mut path = ToolPath {
                points: original.clone(),
            };
            let figs = smooth(&mut path, &params(filter, w, 60.0));
            for q in &path.points {
                for (got, want) in q.axis.iter().zip(a) {
                    assert!((got - want).abs() < 1e-14, "{filter:?} w {w}: {:?}", q.axis);
                }
            }
            assert!(figs[&0].step_max_deg_after < 1e-9);
        }
    }
}

/// A path symmetric about its middle (spacing mirrored) whose axis tilt about Y is odd about
/// the middle: +θ(s) before, −θ(s) after, with noise mirrored too.
fn odd_symmetric_path(n: usize) -> (Vec<f64>, Vec<[f64; 3]>) {
    let gaps: Vec<f64> = uneven_xs(n / 2, 11)
        .windows(2)
        .map(|w| w[1][0] - w[0][0])
        .collect();
    let mut all_gaps = gaps.clone();
    all_gaps.push(0.4);
    all_gaps.push(0.4);
    all_gaps.extend(gaps.iter().rev());
    let mut xs = vec![0.0];
    for g in &all_gaps {
        xs.push(xs[xs.len() - 1] + g);
    }
    let m = xs.len();
    let mid = m / 2;
    let mut st = 99u64;
    let mut tilt = vec![0.0; m];
    for i in 0..mid {
        let t = 25.0 + 10.0 * noise(&mut st);
        tilt[i] = t;
        tilt[m - 1 - i] = -t;
    }
    let axes = tilt.iter().map(|&t| tilt_x(t)).collect();
    (xs, axes)
}

#[test]
fn zero_phase_symmetric_input_gives_symmetric_output() {
    let (xs, axes) = odd_symmetric_path(41);
    let m = xs.len();
    assert_eq!(m % 2, 1, "odd count so the middle is a point");
    for filter in FILTERS {
        for w in [0.7, 3.0, 8.0] {
            let mut path = ToolPath {
                points: run(0, 0, &xs, &axes),
            };
            smooth(&mut path, &params(filter, w, 180.0));
            let out: Vec<[f64; 3]> = path.points.iter().map(|q| q.axis).collect();
            // Mirror image: x flips sign, z stays.
            for i in 0..m {
                let (a, b) = (out[i], out[m - 1 - i]);
                assert!(
                    (a[0] + b[0]).abs() < 1e-12 && (a[2] - b[2]).abs() < 1e-12,
                    "{filter:?} w {w}: {i}: {a:?} vs {b:?}"
                );
            }
            // No lag: the middle stays upright.
            assert!(
                out[m / 2][0].abs() < 1e-12,
                "{filter:?} w {w}: {:?}",
                out[m / 2]
            );
        }
    }
    // The moving average actually acts near the middle (not a trivial pass-through).
    let mut path = ToolPath {
        points: run(0, 0, &xs, &axes),
    };
    smooth(&mut path, &params(Filter::MovingAverage, 3.0, 180.0));
    assert!(angle_between(path.points[m / 2 - 1].axis, axes[m / 2 - 1]) > 1f64.to_radians());
}

#[test]
fn median_removes_a_single_spike_and_the_average_only_spreads_it() {
    let xs: Vec<f64> = (0..30).map(|i| i as f64 * 0.5).collect();
    let mut axes = vec![[0.0, 0.0, 1.0]; 30];
    axes[14] = tilt_x(45.0);
    let mut path = ToolPath {
        points: run(0, 0, &xs, &axes),
    };
    smooth(&mut path, &params(Filter::Median, 1.5, 180.0));
    for q in &path.points {
        assert!(
            angle_between(q.axis, [0.0, 0.0, 1.0]) < 1e-12,
            "{:?}",
            q.axis
        );
    }
    // In a 60° cone the spike may only come back 30° of its 45°: the rest of the path is
    // upright and the spike's point on its cone, towards upright.
    let mut path = ToolPath {
        points: run(0, 0, &xs, &axes),
    };
    smooth(&mut path, &params(Filter::Median, 1.5, 60.0));
    for (i, q) in path.points.iter().enumerate() {
        let want = if i == 14 {
            tilt_x(15.0)
        } else {
            [0.0, 0.0, 1.0]
        };
        assert!(angle_between(q.axis, want) < 1e-12, "{i}: {:?}", q.axis);
    }
    let mut path = ToolPath {
        points: run(0, 0, &xs, &axes),
    };
    smooth(&mut path, &params(Filter::MovingAverage, 1.5, 60.0));
    let spike = angle_between(path.points[14].axis, [0.0, 0.0, 1.0]).to_degrees();
    let next = angle_between(path.points[15].axis, [0.0, 0.0, 1.0]).to_degrees();
    assert!(spike > 0.1 && spike < 45.0, "{spike}");
    assert!(next > 0.1 && next < spike, "{next}");
}

#[test]
fn window_larger_than_the_path() {
    let xs = xs_of(&uneven_xs(25, 21));
    let axes = noisy_axes(25, 20.0, 8);
    let len = xs[xs.len() - 1] - xs[0];
    // Larger than the path, still local: smoother, unit, in the cone.
    for filter in FILTERS {
        let mut path = ToolPath {
            points: run(0, 0, &xs, &axes),
        };
        let figs = smooth(&mut path, &params(filter, 2.0 * len, 60.0));
        assert!(figs[&0].step_max_deg_after < figs[&0].step_max_deg_before);
        for (q, a) in path.points.iter().zip(&axes) {
            assert!((norm(q.axis) - 1.0).abs() < 1e-12);
            assert!(angle_between(q.axis, *a) <= 30f64.to_radians() + 1e-9);
        }
    }
    // Far larger: the moving average tends to the path's mean axis everywhere (the integral of
    // the axis, linear between points, over arc length).
    let mut mean = [0.0; 3];
    for i in 0..axes.len() - 1 {
        let h = xs[i + 1] - xs[i];
        for j in 0..3 {
            mean[j] += 0.5 * h * (axes[i][j] + axes[i + 1][j]);
        }
    }
    let mean = unit(mean);
    let s: Vec<f64> = xs.iter().map(|x| x - xs[0]).collect();
    let out = filter_axes(&s, &axes, Filter::MovingAverage, 1e6 * len);
    for o in &out {
        assert!(angle_between(*o, mean) < 1e-5, "{o:?} vs {mean:?}");
    }
    // The median's window then holds every point with its full weight: one value everywhere.
    let out = filter_axes(&s, &axes, Filter::Median, 10.0 * len);
    for o in &out {
        assert_eq!(*o, out[0]);
    }
}

#[test]
fn disabled_leaves_the_path_bit_identical() {
    let xs = xs_of(&uneven_xs(30, 2));
    let mut points = run(0, 0, &xs, &noisy_axes(30, 15.0, 1));
    points.extend(run(1, 0, &xs, &noisy_axes(30, 15.0, 2)));
    let original = ToolPath { points };
    let mut path = original.clone();
    let p = SmoothParams {
        enabled: false,
        ..SmoothParams::default()
    };
    let figs = smooth(&mut path, &p);
    assert_eq!(path, original);
    assert_eq!(figs.len(), 2);
    for f in figs.values() {
        assert!(f.step_max_deg_before > 1.0);
        assert_eq!(f.step_max_deg_after, f.step_max_deg_before);
        assert_eq!(f.rate_max_deg_per_mm_after, f.rate_max_deg_per_mm_before);
    }
    // And enabled does change it (the comparison above can fail).
    let figs = smooth(&mut path, &SmoothParams::default());
    assert_ne!(path, original);
    assert!(figs[&0].step_max_deg_after < figs[&0].step_max_deg_before);
}

/// Two features, two layers each, joined by travels, with a short bead and a lone travel.
fn mixed_path() -> ToolPath {
    let xs: Vec<f64> = (0..20).map(|i| i as f64 * 0.6).collect();
    let mut points = Vec::new();
    let mut seed = 5;
    for feature in [4, 7] {
        for layer in 0..2 {
            points.extend(run(feature, layer, &xs, &noisy_axes(20, 25.0, seed)));
            seed += 1;
        }
    }
    // A lone travel point, then a 2-point bead of feature 7 layer 1, kept as they are.
    points.push(point(7, 1, MoveKind::Travel, [0.0, 5.0, 0.2], tilt_x(40.0)));
    points.push(point(
        7,
        1,
        MoveKind::Travel,
        [0.0, 6.0, 0.2],
        tilt_x(-40.0),
    ));
    points.push(point(7, 1, MoveKind::Print, [1.0, 6.0, 0.2], tilt_x(40.0)));
    ToolPath { points }
}

#[test]
fn only_axes_change_and_runs_are_smoothed_apart() {
    let original = mixed_path();
    let runs = continuous_paths(&original.points);
    assert_eq!(runs.len(), 6);
    assert_eq!(runs[0], 0..20);
    assert_eq!(runs[5].len(), 2);
    let mut path = original.clone();
    let figs = smooth(&mut path, &params(Filter::MovingAverage, 3.0, 60.0));
    assert_eq!(figs.keys().copied().collect::<Vec<_>>(), vec![4, 7]);
    assert_eq!(path.points.len(), original.points.len());
    for (q, o) in path.points.iter().zip(&original.points) {
        assert_eq!(
            (q.feature, q.layer, q.kind, q.p, q.e, q.thickness, q.width),
            (o.feature, o.layer, o.kind, o.p, o.e, o.thickness, o.width)
        );
    }
    let n = original.points.len();
    // The lone travel and the short bead keep their axes.
    for i in n - 3..n {
        assert_eq!(path.points[i].axis, original.points[i].axis);
    }
    // Each run smoothed on its own: smoothing one run alone gives the same axes.
    for r in &runs[..4] {
        let mut alone = ToolPath {
            points: original.points[r.clone()].to_vec(),
        };
        smooth(&mut alone, &params(Filter::MovingAverage, 3.0, 60.0));
        assert_eq!(alone.points, path.points[r.clone()]);
        // The bead's start (a travel point) is part of it and smoothed.
        assert_ne!(path.points[r.start].axis, original.points[r.start].axis);
    }
    // Figures per feature are the worst of its runs.
    for (f, fig) in &figs {
        let (mut step, mut rate) = (0.0f64, 0.0f64);
        for r in runs
            .iter()
            .filter(|r| original.points[r.start].feature as usize == *f)
        {
            let (s, t) = orientation_step_rate(&original.points[r.clone()]);
            step = step.max(s);
            rate = rate.max(t);
        }
        assert_eq!(
            (fig.step_max_deg_before, fig.rate_max_deg_per_mm_before),
            (step, rate)
        );
        if *f == 4 {
            assert!(fig.step_max_deg_after < fig.step_max_deg_before);
        } else {
            // Feature 7's worst step is the 2-point bead's 80°, which is left alone.
            assert!((fig.step_max_deg_before - 80.0).abs() < 1e-9);
            assert_eq!(fig.step_max_deg_after, fig.step_max_deg_before);
        }
    }
}

#[test]
fn step_and_rate_of_hand_made_points() {
    let z = [0.0, 0.0, 1.0];
    let points = vec![
        point(0, 0, MoveKind::Travel, [0.0, 0.0, 0.0], tilt_x(-50.0)),
        point(0, 0, MoveKind::Print, [0.0, 0.0, 0.0], z),
        // 2 mm, 10°: 5°/mm.
        point(0, 0, MoveKind::Print, [2.0, 0.0, 0.0], tilt_x(10.0)),
        // 1 mm, 20°: 20°/mm.
        point(0, 0, MoveKind::Print, [2.0, 1.0, 0.0], tilt_x(30.0)),
        // A zero-length print segment: 15° step, no rate.
        point(0, 0, MoveKind::Print, [2.0, 1.0, 0.0], tilt_x(45.0)),
        // Travel (90°) and a new layer's first print (80°) are not print segments of a bead.
        point(0, 0, MoveKind::Travel, [0.0, 0.0, 0.2], tilt_x(-45.0)),
        point(0, 1, MoveKind::Print, [0.0, 1.0, 0.2], tilt_x(35.0)),
    ];
    let (step, rate) = orientation_step_rate(&points);
    // The first print segment is 50° over no length.
    assert!((step - 50.0).abs() < 1e-9, "{step}");
    assert!((rate - 20.0).abs() < 1e-9, "{rate}");
    let (step, rate) = orientation_step_rate(&points[1..]);
    assert!((step - 20.0).abs() < 1e-9, "{step}");
    assert!((rate - 20.0).abs() < 1e-9, "{rate}");
    assert_eq!(orientation_step_rate(&points[..1]), (0.0, 0.0));
}

#[derive(serde::Deserialize)]
struct Process {
    #[serde(default)]
    orientation: SmoothParams,
}

#[test]
fn orientation_table_parses_with_defaults_and_refuses_unknown_keys() {
    let d = SmoothParams::default();
    assert!(d.enabled);
    assert_eq!(d.filter, Filter::MovingAverage);
    assert_eq!(d.cone_angle_deg, 60.0);
    assert!(d.window_mm > 0.0);
    assert_eq!(d.validate(), Ok(()));

    let p: Process = toml::from_str("").expect("empty file");
    assert_eq!(p.orientation, d);
    let p: Process = toml::from_str("[orientation]\n").expect("empty table");
    assert_eq!(p.orientation, d);
    let p: Process = toml::from_str("[orientation]\nfilter = \"median\"\ncone_angle_deg = 90\n")
        .expect("partial table");
    assert_eq!(
        p.orientation,
        SmoothParams {
            filter: Filter::Median,
            cone_angle_deg: 90.0,
            ..d.clone()
        }
    );
    let p: Process = toml::from_str(
        "[orientation]\nenabled = false\nfilter = \"moving_average\"\nwindow_mm = 12.5\n",
    )
    .expect("full table");
    assert_eq!(
        p.orientation,
        SmoothParams {
            enabled: false,
            window_mm: 12.5,
            ..d.clone()
        }
    );

    let e = toml::from_str::<Process>("[orientation]\nwindow = 3.0\n")
        .err()
        .expect("unknown key refused");
    assert!(e.to_string().contains("window"), "{e}");
    assert!(toml::from_str::<Process>("[orientation]\nfilter = \"gaussian\"\n").is_err());
    assert!(toml::from_str::<Process>("[orientation]\nwindow_mm = \"wide\"\n").is_err());

    // Round trip through TOML.
    let text = toml::to_string(&p.orientation).expect("serialise");
    let back: SmoothParams = toml::from_str(&text).expect("re-read");
    assert_eq!(back, p.orientation);
}

#[test]
fn validate_names_the_key() {
    for w in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let p = SmoothParams {
            window_mm: w,
            ..SmoothParams::default()
        };
        let e = p.validate().unwrap_err();
        assert!(e.starts_with("window_mm"), "{e}");
        assert!(!e.contains('\n'));
    }
    for g in [0.0, -10.0, 180.5, f64::NAN] {
        let p = SmoothParams {
            cone_angle_deg: g,
            ..SmoothParams::default()
        };
        let e = p.validate().unwrap_err();
        assert!(e.starts_with("cone_angle_deg"), "{e}");
        assert!(!e.contains('\n'));
    }
    let p = SmoothParams {
        cone_angle_deg: 180.0,
        ..SmoothParams::default()
    };
    assert_eq!(p.validate(), Ok(()));
    // Invalid options leave a path alone rather than producing garbage.
    let original = ToolPath {
        points: run(0, 0, &[0.0, 1.0, 2.0, 3.0], &noisy_axes(4, 20.0, 3)),
    };
    let mut path = original.clone();
    smooth(
        &mut path,
        &SmoothParams {
            window_mm: f64::NAN,
            ..SmoothParams::default()
        },
    );
    assert_eq!(path, original);
}

#[test]
fn figures_serialise_under_plan_json_keys() {
    let f = OrientationFigures {
        step_max_deg_before: 1.0,
        step_max_deg_after: 2.0,
        rate_max_deg_per_mm_before: 3.0,
        rate_max_deg_per_mm_after: 4.0,
    };
    let v = serde_json::to_value(f).expect("json");
    assert_eq!(v["orientation_step_max_deg_before"], 1.0);
    assert_eq!(v["orientation_step_max_deg_after"], 2.0);
    assert_eq!(v["orientation_rate_max_deg_per_mm_before"], 3.0);
    assert_eq!(v["orientation_rate_max_deg_per_mm_after"], 4.0);
}
