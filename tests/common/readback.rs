//! Reading a plan back in the end-to-end tests (`plan`, `collisions`): the program's moves and
//! the header's part offset, and the rows of `toolpath.csv`.

/// The program's `G0`/`G1` moves, as (rapid, `[X, Y, Z, B, C]` after the move, E), modal.
#[allow(dead_code)]
pub fn moves(program: &str) -> Vec<(bool, [f64; 5], Option<f64>)> {
    let mut at = [0.0f64; 5];
    let mut out = vec![];
    for line in program.lines() {
        let code = line.split(';').next().unwrap_or("").trim();
        let mut words = code.split_whitespace();
        let cmd = words.next().unwrap_or("");
        if cmd != "G0" && cmd != "G1" {
            continue;
        }
        let mut e = None;
        for w in words {
            let (k, v) = w.split_at(1);
            let v: f64 = v.parse().expect("number");
            match k {
                "X" => at[0] = v,
                "Y" => at[1] = v,
                "Z" => at[2] = v,
                "B" => at[3] = v,
                "C" => at[4] = v,
                "E" => e = Some(v),
                _ => {}
            }
        }
        out.push((cmd == "G0", at, e));
    }
    out
}

/// The header's `; offset X.. Y.. Z..` (machine or table = part + offset).
pub fn offset(program: &str) -> [f64; 3] {
    let v: Vec<f64> = program
        .lines()
        .find_map(|l| l.strip_prefix("; offset "))
        .expect("offset comment")
        .split_whitespace()
        .take(3)
        .map(|w| w[1..].parse().expect("offset number"))
        .collect();
    [v[0], v[1], v[2]]
}

/// One row of `toolpath.csv`. Each test reads the columns it checks.
#[allow(dead_code)]
#[derive(Debug, Clone, Copy)]
pub struct Row {
    pub feature: usize,
    pub layer: usize,
    pub print: bool,
    pub p: [f64; 3],
    pub axis: [f64; 3],
    pub e: f64,
    pub thickness: f64,
    pub width: f64,
    /// Support material's bead (role `support_material` or `support_material_interface`).
    pub support: bool,
    /// The skirt's or the brim's bead (role `skirt` or `brim`), laid around the part.
    pub adhesion: bool,
    /// A gap fill's bead (role `gap_fill`).
    pub gap_fill: bool,
}

/// The rows of `toolpath.csv`, its header checked (other tools read these columns by place).
pub fn rows(csv: &str) -> Vec<Row> {
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("feature,layer,move,x,y,z,i,j,k,e,thickness,width,role")
    );
    lines
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            let f = |k: usize| c[k].parse::<f64>().expect("number");
            Row {
                feature: c[0].parse().expect("feature"),
                layer: c[1].parse().expect("layer"),
                print: c[2] == "print",
                p: [f(3), f(4), f(5)],
                axis: [f(6), f(7), f(8)],
                e: f(9),
                thickness: f(10),
                width: f(11),
                support: c.get(12).is_some_and(|r| r.starts_with("support_material")),
                adhesion: c.get(12).is_some_and(|r| *r == "skirt" || *r == "brim"),
                gap_fill: c.get(12).is_some_and(|r| *r == "gap_fill"),
            }
        })
        .collect()
}

/// An extruding move as PrusaSlicer's G-code viewer takes it: a `G1`, `G2` or `G3` that moves
/// and feeds filament (E > 0; the filament fed in place by a lone `G1 E` is not one).
#[allow(dead_code)]
#[derive(Debug, Clone)]
pub struct Extrusion {
    /// Its line in the program, from 1.
    pub line: usize,
    /// The `;TYPE:` written last before it, if any (the viewer's "Unknown" otherwise).
    pub role: Option<String>,
    /// Where it goes, machine coordinates: its start, the points of an arc at most `step`
    /// apart, its end.
    pub points: Vec<[f64; 3]>,
    /// Filament fed, mm.
    pub e: f64,
    /// `G2` or `G3`.
    pub arc: bool,
}

/// Every extruding move of `program` ([`Extrusion`]; absolute XYZ, relative E, modal),
/// `G2`/`G3` arcs (centre at the start plus `I`/`J`) interpolated at most `step` mm apart.
#[allow(dead_code)]
pub fn extrusions(program: &str, step: f64) -> Vec<Extrusion> {
    let mut at = [0.0f64; 3];
    let mut role: Option<String> = None;
    let mut out = vec![];
    for (n, line) in program.lines().enumerate() {
        if let Some(t) = line.strip_prefix(";TYPE:") {
            role = Some(t.trim().to_string());
            continue;
        }
        let code = line.split(';').next().unwrap_or("").trim();
        let mut words = code.split_whitespace();
        let cmd = words.next().unwrap_or("");
        if !matches!(cmd, "G0" | "G1" | "G2" | "G3") {
            continue;
        }
        let (mut to, mut e, mut ij) = (at, 0.0, [0.0f64; 2]);
        for w in words {
            let (k, v) = w.split_at(1);
            let v: f64 = v.parse().expect("number");
            match k {
                "X" => to[0] = v,
                "Y" => to[1] = v,
                "Z" => to[2] = v,
                "E" => e = v,
                "I" => ij[0] = v,
                "J" => ij[1] = v,
                _ => {}
            }
        }
        let arc = matches!(cmd, "G2" | "G3");
        let mut points = vec![at];
        if arc {
            let c = [at[0] + ij[0], at[1] + ij[1]];
            let r = ij[0].hypot(ij[1]);
            let a0 = (at[1] - c[1]).atan2(at[0] - c[0]);
            let a1 = (to[1] - c[1]).atan2(to[0] - c[0]);
            let tau = std::f64::consts::TAU;
            // Counter-clockwise for G3, clockwise for G2; the same point: a whole turn.
            let mut sweep = if cmd == "G3" {
                (a1 - a0).rem_euclid(tau)
            } else {
                -(a0 - a1).rem_euclid(tau)
            };
            if sweep == 0.0 {
                sweep = if cmd == "G3" { tau } else { -tau };
            }
            let k = ((sweep.abs() * r / step).ceil() as usize).max(1);
            for i in 1..k {
                let a = a0 + sweep * i as f64 / k as f64;
                let f = i as f64 / k as f64;
                points.push([
                    c[0] + r * a.cos(),
                    c[1] + r * a.sin(),
                    at[2] + f * (to[2] - at[2]),
                ]);
            }
        }
        points.push(to);
        let moved = to != at;
        at = to;
        if cmd != "G0" && e > 0.0 && moved {
            out.push(Extrusion {
                line: n + 1,
                role: role.clone(),
                points,
                e,
                arc,
            });
        }
    }
    out
}

/// The layers PrusaSlicer's G-code viewer counts in the extruding moves: a new one wherever a
/// move's end Z differs from the last layer's by more than its epsilon.
#[allow(dead_code)]
pub fn viewer_layers(extrusions: &[Extrusion]) -> Vec<f64> {
    /// The viewer's layer epsilon, mm.
    const EPSILON: f64 = 1e-4;
    let mut zs: Vec<f64> = vec![];
    for x in extrusions {
        let z = x.points.last().map_or(0.0, |p| p[2]);
        if zs.last().is_none_or(|&l| (z - l).abs() > EPSILON) {
            zs.push(z);
        }
    }
    zs
}
