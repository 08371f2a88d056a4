//! Reading a program back in the end-to-end tests (`plan`, `collisions`): its moves and the
//! header's part offset.

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
