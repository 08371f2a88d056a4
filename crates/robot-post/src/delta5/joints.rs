//! `joints.csv` of a delta5 program: the bed's B and C after every move from the path's first
//! to the end (the start G-code's own moves, such as the purge line, left out), as the
//! program's `G0`/`G1` lines give them.

/// The joint table's header: the move's number, then B and C in degrees.
pub const DELTA5_JOINTS_HEADER: &str = "move,B,C";

/// The rows of the joint table, made from the program's moves as they are written
/// ([`JointRows::scan`]).
#[derive(Debug, Default)]
pub(super) struct JointRows {
    /// The table's text not yet handed on.
    pub(super) text: String,
    /// Moves so far, and the B and C in force (as written).
    moves: usize,
    b: String,
    c: String,
}

impl JointRows {
    /// The table, its header written.
    pub(super) fn new() -> JointRows {
        JointRows {
            text: format!("{DELTA5_JOINTS_HEADER}\n"),
            ..JointRows::default()
        }
    }

    /// A row for every move of `gcode` (a `G0` or `G1` line naming an axis; a retraction,
    /// `G1 E.. F..`, is none): its number (from 1, in the program's order) and the B and C in
    /// force after it, as the program writes them (B and C are modal; empty before the first
    /// gives them).
    pub(super) fn scan(&mut self, gcode: &str) {
        for line in gcode.lines() {
            let code = line.split(';').next().unwrap_or_default();
            let mut words = code.split_whitespace();
            if !matches!(words.next(), Some("G0" | "G1")) {
                continue;
            }
            let mut moves = false;
            for w in words {
                match w.split_at(1) {
                    ("B", v) => (self.b, moves) = (v.to_string(), true),
                    ("C", v) => (self.c, moves) = (v.to_string(), true),
                    ("X" | "Y" | "Z", _) => moves = true,
                    _ => {}
                }
            }
            if moves {
                self.moves += 1;
                self.text
                    .push_str(&format!("{},{},{}\n", self.moves, self.b, self.c));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_follow_the_moves() {
        let mut rows = JointRows::new();
        rows.scan("G0 Z5 F600\nG0 X1 Y2 Z3 B10.5000 C-3.0000 F600 ; travel\nG1 E-0.8 F2100\n");
        rows.scan("G1 X2 Y2 Z3 C-4.0000 E0.1 F900\n;LAYER:1\n");
        assert_eq!(
            rows.text,
            "move,B,C\n1,,\n2,10.5000,-3.0000\n3,10.5000,-4.0000\n"
        );
    }
}
