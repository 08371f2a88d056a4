//! The Marlin post end to end: the program is re-parsed with the `gcode` crate and must
//! reproduce `toolpath.csv` (issue "features plan").

use gcode::{Code, Value};
use robot_post::toolpath::Role;
use robot_post::{marlin, MachineKind, MachineProfile, MoveKind, PathPoint, PostError, ToolPath};

const W: f64 = 0.45;
const T: f64 = 0.2;

fn profile() -> MachineProfile {
    MachineProfile::builtin(MachineKind::Marlin)
}

fn point(feature: usize, layer: usize, kind: MoveKind, p: [f64; 3], e: f64) -> PathPoint {
    PathPoint {
        feature: feature as u32,
        layer: layer as u32,
        kind,
        p,
        axis: [0.0, 0.0, 1.0],
        e,
        thickness: T as f32,
        width: W as f32,
        role: robot_post::toolpath::Role::Perimeter,
    }
}

/// A square of side `side` at centre `c`, on `layers` layers 0.2 mm apart from part Z `base`,
/// as one feature: a travel to the first corner, then four print moves per layer, each with
/// the filament length of Isa & Lazoglu 2019, Eq. 1.
fn squares(
    path: &mut ToolPath,
    m: &MachineProfile,
    feature: usize,
    layer: usize,
    c: [f64; 2],
    side: f64,
    z: f64,
) {
    let h = side / 2.0;
    let corners = [
        [c[0] - h, c[1] - h],
        [c[0] + h, c[1] - h],
        [c[0] + h, c[1] + h],
        [c[0] - h, c[1] + h],
        [c[0] - h, c[1] - h],
    ];
    path.points.push(point(
        feature,
        layer,
        MoveKind::Travel,
        [corners[0][0], corners[0][1], z],
        0.0,
    ));
    for pair in corners.windows(2) {
        let len = ((pair[1][0] - pair[0][0]).powi(2) + (pair[1][1] - pair[0][1]).powi(2)).sqrt();
        let e = m.filament_length(W, T, len);
        path.points.push(point(
            feature,
            layer,
            MoveKind::Print,
            [pair[1][0], pair[1][1], z],
            e,
        ));
    }
}

/// Three layers; on each, feature 1 (a 20 mm square) then feature 2 (a 7.5 mm square beside
/// it). The part's lowest bead bottom is at part Z 5, so the post must shift it down by 5.
fn synthetic() -> ToolPath {
    let m = profile();
    let mut path = ToolPath::default();
    for layer in 0..3 {
        let z = 5.0 + T * (layer as f64 + 1.0);
        squares(&mut path, &m, 1, layer, [-12.5, 40.0], 20.0, z);
        squares(&mut path, &m, 2, layer, [15.25, 33.0], 7.5, z);
    }
    path
}

/// A print move read back: machine position, E, and the `;LAYER:`/`;FEATURE:` in force.
type PrintMove = ([f64; 3], f64, Option<usize>, Option<usize>);

/// What the test reads back from the program.
#[derive(Debug, Default)]
struct Parsed {
    offset: Option<[f64; 3]>,
    /// Print moves: machine position, E, and the `;LAYER:`/`;FEATURE:` in force.
    prints: Vec<PrintMove>,
    /// Net E of the moves without X/Y/Z before each print move (since the previous one).
    gaps: Vec<f64>,
    travels: usize,
    layer_comments: usize,
    feature_comments: usize,
}

fn literal(v: &Value) -> f64 {
    match v {
        Value::Literal(x) => f64::from(*x),
        other => panic!("not a literal: {other:?}"),
    }
}

fn parse(program: &str) -> Parsed {
    let gc =
        gcode::parse(program).unwrap_or_else(|d| panic!("gcode crate refused the program: {d:?}"));
    let mut out = Parsed::default();
    let (mut layer, mut feature) = (None, None);
    let mut pos = [f64::NAN; 3];
    let mut gap = 0.0;
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
                out.layer_comments += 1;
            } else if let Some(n) = text.strip_prefix("FEATURE:") {
                feature = Some(n.parse().unwrap());
                out.feature_comments += 1;
            } else if let Some(rest) = text.strip_prefix("offset ") {
                let v: Vec<f64> = rest
                    .split_whitespace()
                    .take(3)
                    .map(|w| w[1..].parse().unwrap())
                    .collect();
                out.offset = Some([v[0], v[1], v[2]]);
            }
        }
        for code in block.codes.iter().filter(|_| !custom) {
            let Code::General(g) = code else { continue };
            let major = g.number.major();
            if major != 0 && major != 1 {
                continue;
            }
            let mut e = None;
            let mut moved = false;
            for a in &g.args {
                match a.letter.to_ascii_uppercase() {
                    'X' => (pos[0], moved) = (literal(&a.value), true),
                    'Y' => (pos[1], moved) = (literal(&a.value), true),
                    'Z' => (pos[2], moved) = (literal(&a.value), true),
                    'E' => e = Some(literal(&a.value)),
                    'F' => assert!(literal(&a.value) > 0.0),
                    other => panic!("unexpected argument {other}"),
                }
            }
            match (major, e, moved) {
                (1, Some(e), true) => {
                    out.prints.push((pos, e, layer, feature));
                    out.gaps.push(gap);
                    gap = 0.0;
                }
                (1, Some(e), false) => gap += e,
                (0, None, true) => out.travels += 1,
                other => panic!("unexpected move {other:?} in {g}"),
            }
        }
    }
    out
}

#[test]
fn marlin_program_reparsed_reproduces_toolpath_csv() {
    let m = profile();
    let path = synthetic();
    // What the planner writes and what the post is given must agree: read the CSV back.
    let csv = path.to_csv();
    let from_csv = ToolPath::from_csv(&csv).unwrap();
    let program = marlin(&from_csv, &m, "squares.step").unwrap();
    let parsed = parse(&program);

    let offset = parsed.offset.expect("offset comment");
    // XY bounding-box centre on the bed centre (110, 110); lowest bead bottom (part Z 5) on Z0.
    let (lo_x, hi_x, lo_y, hi_y) = (-22.5, 19.0, 29.25, 50.0);
    assert!(
        (offset[0] - (110.0 - (lo_x + hi_x) / 2.0)).abs() < 1e-3,
        "{offset:?}"
    );
    assert!(
        (offset[1] - (110.0 - (lo_y + hi_y) / 2.0)).abs() < 1e-3,
        "{offset:?}"
    );
    assert!((offset[2] + 5.0).abs() < 1e-9, "{offset:?}");

    let expected: Vec<&PathPoint> = from_csv
        .points
        .iter()
        .filter(|q| q.kind == MoveKind::Print)
        .collect();
    assert_eq!(parsed.prints.len(), expected.len());
    for (i, ((pos, e, layer, feature), q)) in parsed.prints.iter().zip(&expected).enumerate() {
        for k in 0..3 {
            assert!(
                (pos[k] - offset[k] - q.p[k]).abs() <= 1e-3,
                "print {i}: {pos:?} vs {:?}",
                q.p
            );
        }
        assert!((e - q.e).abs() <= 1e-5, "print {i}: E {e} vs {}", q.e);
        assert_eq!(*layer, Some(q.layer as usize), "print {i}");
        assert_eq!(*feature, Some(q.feature as usize), "print {i}");
    }
    // Retraction balances: no net filament over any travel between two print moves.
    for (i, g) in parsed.gaps.iter().enumerate() {
        assert!(g.abs() < 1e-9, "net E {g} before print {i}");
    }
    // A retraction and an un-retraction around every travel after the first.
    let retracts = program
        .lines()
        .filter(|l| l.starts_with("G1 E-0.80000 F2100"))
        .count();
    let unretracts = program
        .lines()
        .filter(|l| l.starts_with("G1 E0.80000 F2100"))
        .count();
    assert_eq!(
        (retracts, unretracts),
        (6, 5),
        "five travels between prints, one at the end"
    );
    assert!(parsed.travels >= 6);
    // One layer per (feature, layer) run over the build order: features 1, 2, 1, 2, 1, 2 on
    // their layers 0, 0, 1, 1, 2, 2 are six layers, numbered 0 to 5 by `;LAYER:`.
    assert_eq!((parsed.layer_comments, parsed.feature_comments), (6, 6));
    let global: Vec<usize> = program
        .lines()
        .filter_map(|l| l.strip_prefix(";LAYER:"))
        .map(|n| n.parse().unwrap())
        .collect();
    assert_eq!(global, (0..6).collect::<Vec<_>>());
    assert_eq!(program.matches(";LAYER_CHANGE\n;Z:").count(), 6);

    // And the original path (not only its CSV form) is reproduced within the CSV's rounding.
    for (q, r) in path.points.iter().zip(&from_csv.points) {
        assert!((q.e - r.e).abs() <= 5e-7 && (q.p[0] - r.p[0]).abs() <= 5e-7);
    }
}

#[test]
fn marlin_numbers_are_fixed_point() {
    let program = marlin(&synthetic(), &profile(), "squares.step").unwrap();
    // The program's own lines: the profile's start and end G-code are the user's text.
    let start = program.find("; end of start_gcode").unwrap();
    let end = program.find("; end_gcode").unwrap();
    for line in program[..program.find("; start_gcode").unwrap()]
        .lines()
        .chain(program[start..end].lines())
    {
        let code = line.split(';').next().unwrap_or("");
        let b = code.as_bytes();
        for i in 1..b.len().saturating_sub(1) {
            let exponent = matches!(b[i], b'e' | b'E')
                && (b[i - 1].is_ascii_digit() || b[i - 1] == b'.')
                && (b[i + 1].is_ascii_digit() || b[i + 1] == b'+' || b[i + 1] == b'-');
            assert!(!exponent, "exponent in `{line}`");
        }
        let lower = code.to_ascii_lowercase();
        assert!(!lower.contains("nan") && !lower.contains("inf"), "`{line}`");
        assert!(!line.contains("NaN"), "`{line}`");
        assert!(
            !code.contains("-0.000 ") && !code.ends_with("-0.000"),
            "`{line}`"
        );
        for word in code.split_whitespace() {
            let (letter, number) = word.split_at(1);
            match letter {
                // The motion limits (M201, M204, M205) in whole units.
                _ if code.starts_with("M20") => {
                    assert!(number.bytes().all(|c| c.is_ascii_digit()), "`{line}`")
                }
                "X" | "Y" | "Z" if !code.starts_with("G28") => {
                    assert_eq!(number.split('.').nth(1).map(str::len), Some(3), "`{line}`")
                }
                "E" if !code.starts_with("G92") => {
                    assert_eq!(number.split('.').nth(1).map(str::len), Some(5), "`{line}`")
                }
                "F" | "S" => assert!(number.bytes().all(|c| c.is_ascii_digit()), "`{line}`"),
                _ => {}
            }
        }
    }
}

#[test]
fn marlin_header_and_footer() {
    let program = marlin(&synthetic(), &profile(), "dir/squares.step\nG28").unwrap();
    let lines: Vec<&str> = program.lines().collect();
    assert_eq!(
        lines[0],
        "; generated by features from dir/squares.step G28"
    );
    let codes: Vec<&str> = lines
        .iter()
        .map(|l| l.split(';').next().unwrap_or("").trim())
        .filter(|c| !c.is_empty())
        .collect();
    assert_eq!(
        &codes[..20],
        [
            "G21",
            "G90",
            "M83",
            "M201 X1500 Y1500",
            "M204 P1000 T1500",
            "M205 X10 Y10",
            "M140 S60",
            "M104 S210",
            "G28",
            "M190 S60",
            "M109 S210",
            "G92 E0",
            // The purge line on the first layer's height, its filament for that thickness.
            "G0 X0.000 Y0.000 Z0.200 F7200",
            "G1 X100 E3.74177 F1200",
            "G0 Z2 F7200",
            "G90",
            "M83",
            "G0 X89.250 Y100.375 Z0.400 F7200",
            "G0 Z0.200 F7200",
            // The first layer without the fan (fan_first_layer 0).
            "M107",
        ]
    );
    // The fan at fan_speed 100 % from the second layer: M106 S255 right after its layer
    // comments, before its first print move.
    let second = lines.iter().position(|l| *l == ";LAYER:2").unwrap();
    let fan = lines
        .iter()
        .position(|l| l.starts_with("M106 S255"))
        .unwrap();
    assert!(fan > second, "{fan} {second}");
    assert!(lines[second..fan].iter().all(|l| !l.starts_with("G1 X")));
    assert!(lines.iter().any(|l| l.starts_with("; offset X")));
    let tail = &codes[codes.len() - 7..];
    assert_eq!(
        tail,
        [
            "G1 E-0.80000 F2100",
            "G0 Z10.600 F7200",
            "M107",
            "M104 S0",
            "M140 S0",
            "G28 X0 Y0",
            "M84"
        ]
    );
    // First layer at 20 mm/s, later layers at 40 mm/s.
    let own = codes.iter().position(|c| *c == "G0 Z2 F7200").unwrap();
    let codes = &codes[own..];
    let f1200 = codes
        .iter()
        .filter(|c| c.starts_with("G1 X") && c.ends_with("F1200"))
        .count();
    let f2400 = codes
        .iter()
        .filter(|c| c.starts_with("G1 X") && c.ends_with("F2400"))
        .count();
    assert_eq!((f1200, f2400), (8, 16));
}

#[test]
fn marlin_refuses_a_feature_not_along_plus_z() {
    let mut path = synthetic();
    for q in path
        .points
        .iter_mut()
        .filter(|q| q.feature == 2 && q.layer == 1)
    {
        q.feature = 7;
        q.axis = [1.0, 0.0, 0.0];
    }
    let err = marlin(&path, &profile(), "tilted.step").unwrap_err();
    assert!(
        matches!(err, PostError::ToolAxis { feature: 7, .. }),
        "{err:?}"
    );
    let msg = err.to_string();
    assert!(
        msg.contains("feature 7") && msg.contains("`delta5`") && msg.contains("`kuka`"),
        "{msg}"
    );
    assert!(!msg.contains('\n'));
    // Within 1e-6 of +Z is accepted.
    let mut path = synthetic();
    path.points[3].axis = [1e-7, -1e-7, 1.0 - 1e-7];
    marlin(&path, &profile(), "x").unwrap();
}

#[test]
fn marlin_refuses_a_part_larger_than_the_bed() {
    let m = profile();
    let mut path = ToolPath::default();
    squares(&mut path, &m, 1, 0, [0.0, 0.0], 300.0, 0.2);
    let err = marlin(&path, &m, "big.step").unwrap_err();
    assert!(matches!(err, PostError::DoesNotFit { .. }), "{err:?}");
    let msg = err.to_string();
    // 300 mm plus a bead width, on a 220 mm bed.
    assert!(
        msg.contains("X 80.450 mm") && msg.contains("Y 80.450 mm") && !msg.contains("Z "),
        "{msg}"
    );
    assert!(msg.contains("220x220x250"), "{msg}");

    let mut tall = ToolPath::default();
    for layer in 0..1300 {
        squares(
            &mut tall,
            &m,
            1,
            layer,
            [0.0, 0.0],
            10.0,
            0.2 * (layer as f64 + 1.0),
        );
    }
    let msg = marlin(&tall, &m, "tall.step").unwrap_err().to_string();
    assert!(msg.contains("Z 10.000 mm") && !msg.contains("X "), "{msg}");

    // Exactly the bed's width (with the bead) fits.
    let mut fits = ToolPath::default();
    squares(&mut fits, &m, 1, 0, [0.0, 0.0], 220.0 - W, 0.2);
    marlin(&fits, &m, "fits.step").unwrap();
}

#[test]
fn marlin_refuses_other_profiles_and_bad_numbers() {
    let err = marlin(
        &synthetic(),
        &MachineProfile::builtin(MachineKind::Kuka),
        "x",
    )
    .unwrap_err();
    assert!(err.to_string().contains("not `marlin`"), "{err}");
    let mut m = profile();
    m.print_speed = f64::NAN;
    assert!(matches!(
        marlin(&synthetic(), &m, "x"),
        Err(PostError::ProfileValue { .. })
    ));
    let mut path = synthetic();
    path.points[4].e = f64::INFINITY;
    let msg = marlin(&path, &profile(), "x").unwrap_err().to_string();
    assert!(msg.contains("point 4") && msg.contains(" e "), "{msg}");
}

#[test]
fn marlin_edge_cases_do_not_panic() {
    let m = profile();
    // Empty path: header and footer only.
    let empty = marlin(&ToolPath::default(), &m, "empty.step").unwrap();
    assert!(empty.contains("G28 X0 Y0") && parse(&empty).prints.is_empty());
    gcode::parse(&empty).unwrap();
    // A path starting with a print point travels to it first.
    let path = ToolPath {
        points: vec![point(0, 0, MoveKind::Print, [0.0, 0.0, 0.2], 0.01)],
    };
    let program = marlin(&path, &m, "dot.step").unwrap();
    let g0 = program.find("G0 X110.000 Y110.000").unwrap();
    // The dot goes nowhere once there: its filament is laid in place, not lost.
    let g1 = program.find("G0 Z0.200").unwrap();
    let e = program.find("G1 E0.01000 F2400").unwrap();
    assert!(g0 < g1 && g1 < e, "{program}");
    // No hop, no retraction, no heated bed.
    let mut bare = m.clone();
    (bare.z_hop, bare.retraction_length, bare.bed_temperature) = (0.0, 0.0, 0.0);
    let program = marlin(&synthetic(), &bare, "x").unwrap();
    // (The heating is the profile's start_gcode: its placeholders give the bed 0 degrees.)
    let own = &program[program.find("; end of start_gcode").unwrap()..];
    assert!(program.contains("M140 S0 ; bed") && !own.contains("G1 E"));
    assert_eq!(parse(&program).prints.len(), 24);
    // Pseudo-random paths with extreme figures: an Ok program or an error, never a panic.
    /// xorshift64: deterministic pseudo-random figures, including extreme ones.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
        fn v(&mut self) -> f64 {
            const SPECIALS: [f64; 10] = [
                0.0,
                -0.0,
                1e-300,
                -1e-9,
                1e300,
                -1e300,
                f64::MAX,
                f64::MIN_POSITIVE,
                3.5,
                -7.25,
            ];
            let r = self.next();
            if r % 3 == 0 {
                SPECIALS[(r / 3 % SPECIALS.len() as u64) as usize]
            } else {
                (r % 20_000) as f64 / 100.0 - 100.0
            }
        }
    }
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut programs = 0;
    for _ in 0..300 {
        let n = (rng.next() % 8) as usize;
        let mut points = Vec::new();
        for _ in 0..n {
            let kind = if rng.next() % 2 == 0 {
                MoveKind::Print
            } else {
                MoveKind::Travel
            };
            points.push(PathPoint {
                feature: (rng.next() % 3) as u32,
                layer: (rng.next() % 3) as u32,
                kind,
                p: [rng.v(), rng.v(), rng.v()],
                axis: if rng.next() % 4 == 0 {
                    [rng.v(), rng.v(), rng.v()]
                } else {
                    [0.0, 0.0, 1.0]
                },
                e: rng.v(),
                thickness: rng.v() as f32,
                width: rng.v() as f32,
                role: robot_post::toolpath::Role::Perimeter,
            });
        }
        let path = ToolPath { points };
        if let Ok(program) = marlin(&path, &m, "random") {
            programs += 1;
            // No number written as NaN, infinite or with an exponent (words such as
            // `infill` in the config block are no numbers).
            let odd = |w: &str| {
                let v = w
                    .strip_prefix(|c: char| c.is_ascii_uppercase())
                    .unwrap_or(w);
                matches!(v, "NaN" | "inf" | "-inf")
                    || (v.contains(['e', 'E']) && v.parse::<f64>().is_ok())
            };
            let bad: Vec<&str> = program
                .lines()
                .filter(|l| l.split([' ', ',', ':']).any(odd))
                .collect();
            assert!(bad.is_empty(), "{bad:?}");
            gcode::parse(&program).unwrap();
        }
        let csv = path.to_csv();
        assert_eq!(
            ToolPath::from_csv(&csv)
                .map(|p| p.points.len())
                .unwrap_or(n),
            n
        );
    }
    // Some of them are printable (those with +Z axes inside the bed, and the empty ones).
    assert!(programs > 30, "{programs} programs");
}

#[test]
fn toolpath_csv_round_trip() {
    let path = synthetic();
    let csv = path.to_csv();
    assert_eq!(
        csv.lines().next(),
        Some("feature,layer,move,x,y,z,i,j,k,e,thickness,width,role")
    );
    assert_eq!(csv.lines().nth(1), Some("1,0,travel,-22.500000,30.000000,5.200000,0.000000,0.000000,1.000000,0.000000,0.2000,0.4500,perimeter"));
    let back = ToolPath::from_csv(&csv).unwrap();
    assert_eq!(back.points.len(), path.points.len());
    for (a, b) in path.points.iter().zip(&back.points) {
        assert_eq!(
            (a.feature, a.layer, a.kind, a.axis),
            (b.feature, b.layer, b.kind, b.axis)
        );
        for k in 0..3 {
            assert!((a.p[k] - b.p[k]).abs() <= 5e-7);
        }
        assert!((a.e - b.e).abs() <= 5e-7);
        assert!((a.thickness - b.thickness).abs() <= 5e-5 && (a.width - b.width).abs() <= 5e-5);
    }
    assert_eq!(back.to_csv(), csv);
}

/// Four squares on layer 0 of one feature, then one on layer 1, with the roles `roles`.
fn squares_with_roles(m: &MachineProfile, roles: &[Role]) -> ToolPath {
    let mut path = ToolPath::default();
    for (k, &role) in roles.iter().enumerate() {
        let layer = usize::from(k + 1 == roles.len());
        let from = path.points.len();
        let side = 30.0 - 4.0 * k as f64;
        squares(
            &mut path,
            m,
            1,
            layer,
            [0.0, 0.0],
            side,
            T * (layer as f64 + 1.0),
        );
        for q in &mut path.points[from..] {
            q.role = role;
        }
    }
    path
}

/// `;TYPE:` is written before a print move whose role differs from the last one written in
/// its layer, and again at the first print move of every layer, with PrusaSlicer's names;
/// every print move (G1 with E > 0) lies under one.
#[test]
fn marlin_type_comments_follow_the_roles() {
    let m = profile();
    let roles = [
        Role::ExternalPerimeter,
        Role::Perimeter,
        Role::Perimeter,
        Role::SolidInfill,
        Role::SolidInfill,
    ];
    let program = marlin(&squares_with_roles(&m, &roles), &m, "roles").unwrap();
    let types: Vec<&str> = program
        .lines()
        .filter_map(|l| l.strip_prefix(";TYPE:"))
        .collect();
    assert_eq!(
        types,
        [
            // The start G-code's purge line.
            "Skirt/Brim",
            "External perimeter",
            "Perimeter",
            "Solid infill",
            "Solid infill"
        ]
    );
    let mut typed = false;
    let mut prints = 0;
    // The planned moves: between the profile's start_gcode (its purge line prints, under
    // `Skirt/Brim`) and its end_gcode.
    for l in program
        .lines()
        .skip_while(|l| *l != "; end of start_gcode")
        .take_while(|l| *l != "; end_gcode")
    {
        if l == ";LAYER_CHANGE" {
            typed = false;
        } else if l.starts_with(";TYPE:") {
            typed = true;
        } else if l.starts_with("G1 X") && l.contains(" E") {
            assert!(typed, "{l}");
            prints += 1;
        }
    }
    assert_eq!(prints, 4 * roles.len());
    // Every role's name, after the start G-code's.
    let names: Vec<&str> = std::iter::once("Skirt/Brim")
        .chain(Role::ALL.iter().map(|r| r.prusa_name()))
        .collect();
    let program = marlin(&squares_with_roles(&m, &Role::ALL), &m, "roles").unwrap();
    let types: Vec<&str> = program
        .lines()
        .filter_map(|l| l.strip_prefix(";TYPE:"))
        .collect();
    assert_eq!(types, names);
}
