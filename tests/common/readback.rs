//! Reading a plan back in the end-to-end tests (`plan`, `collisions`): the program's moves and
//! the header's part offset, and the rows of `toolpath.csv`.

/// The program's `G0`/`G1` moves, as (rapid, `[X, Y, Z, B, C]` after the move, E), modal.
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
            }
        })
        .collect()
}
