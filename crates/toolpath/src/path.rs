//! The planned tool path the posts consume (the planner fills it), and its `toolpath.csv` form.

use crate::fixed::{push_fixed_bytes, push_integer_bytes};
use crate::role::Role;

/// Why a tool path could not be read or used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ToolPathError {
    /// A `toolpath.csv` line could not be read.
    #[error("tool path CSV line {line}: {reason}")]
    Csv {
        /// One-based line number.
        line: usize,
        /// What is wrong with the line.
        reason: String,
    },
    /// A path point holds a NaN or infinite number.
    #[error("tool path point {index} (feature {feature}, layer {layer}): {field} is not a finite number")]
    NonFinite {
        /// Zero-based index of the point in the path.
        index: usize,
        /// The point's feature.
        feature: usize,
        /// The point's layer.
        layer: usize,
        /// The field that is not finite.
        field: &'static str,
    },
}

/// Whether the nozzle deposits on the segment ending at a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MoveKind {
    /// Depositing: the segment from the previous point to this one lays a bead.
    Print,
    /// Moving without depositing.
    Travel,
}

impl MoveKind {
    /// `print` or `travel`, as in `toolpath.csv`.
    pub fn as_str(self) -> &'static str {
        match self {
            MoveKind::Print => "print",
            MoveKind::Travel => "travel",
        }
    }
}

/// One point of the path: where the segment ending here goes, and what it deposits.
///
/// A path holds millions of these (NIST CTC-05: 4.6 million), so the point is kept to 80 bytes:
/// ids as `u32`, and the bead's thickness and width in single precision (a step of 0.03 nm at
/// 0.45 mm, far below the 4 decimals `toolpath.csv` gives them). Positions, axes and filament
/// lengths stay in double precision: the posts and checks compute with them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathPoint {
    /// Id of the feature this point belongs to.
    pub feature: u32,
    /// Layer index within the path (the `;LAYER:` number of G-code viewers).
    pub layer: u32,
    /// Print or travel.
    pub kind: MoveKind,
    /// Nozzle tip position in part coordinates (mm).
    pub p: [f64; 3],
    /// Unit tool axis, from the deposit towards the nozzle (+Z for a 3-axis printer).
    pub axis: [f64; 3],
    /// Filament length (mm) fed on the segment ending here; 0 on travel.
    pub e: f64,
    /// Layer (bead) thickness Δl at this point (mm).
    pub thickness: f32,
    /// Bead width w at this point (mm).
    pub width: f32,
    /// What the path this point belongs to is for (a travel point: the path it leads to).
    pub role: Role,
}

/// A planned path: points in the order the machine visits them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ToolPath {
    /// The points, in machine order.
    pub points: Vec<PathPoint>,
}

/// The header line of `toolpath.csv`.
pub const CSV_HEADER: &str = "feature,layer,move,x,y,z,i,j,k,e,thickness,width,role";

impl ToolPath {
    /// The path as CSV: the header exactly [`CSV_HEADER`]
    /// (`feature,layer,move,x,y,z,i,j,k,e,thickness,width,role`), then one line per point;
    /// `move` is `print` or `travel`; coordinates, axis and `e` with 6 decimals, thickness and
    /// width with 4, fixed-point (never exponent notation, no `-0`); `role` last (appended
    /// after the older columns, which keep their places), [`Role::as_str`]. Lines end with
    /// `\n`.
    pub fn to_csv(&self) -> String {
        let mut out = Vec::with_capacity(64 * (self.points.len() + 1));
        // Writing to memory cannot fail, and the text is ASCII.
        let _ = self.write_csv(&mut out);
        String::from_utf8(out).unwrap_or_default()
    }

    /// Writes [`ToolPath::to_csv`]'s text to `w` a block of lines at a time, without holding
    /// it in memory: the lines of a few blocks are made in parallel, then written in order.
    pub fn write_csv(&self, w: &mut impl std::io::Write) -> std::io::Result<()> {
        use rayon::prelude::*;
        /// Points a block of lines holds.
        const BLOCK: usize = 1 << 14;
        writeln!(w, "{CSV_HEADER}")?;
        let at_once = BLOCK * rayon::current_num_threads().max(1);
        for points in self.points.chunks(at_once) {
            let blocks: Vec<Vec<u8>> = points
                .par_chunks(BLOCK)
                .map(|block| {
                    let mut text = Vec::with_capacity(112 * block.len());
                    for q in block {
                        csv_line(&mut text, q);
                    }
                    text
                })
                .collect();
            for text in &blocks {
                w.write_all(text)?;
            }
        }
        Ok(())
    }

    /// Reads CSV written by [`ToolPath::to_csv`]. The first line must be the header exactly;
    /// blank lines are skipped and `\r\n` line ends accepted. Numbers must be finite. The
    /// error names the line and field.
    pub fn from_csv(text: &str) -> Result<ToolPath, ToolPathError> {
        let mut lines = text.lines().enumerate();
        let header = lines.next().map(|(_, l)| l.trim()).unwrap_or("");
        let header = header.strip_prefix('\u{feff}').unwrap_or(header);
        if header != CSV_HEADER {
            return Err(ToolPathError::Csv {
                line: 1,
                reason: format!("the header must be `{CSV_HEADER}`, got `{}`", clip(header)),
            });
        }
        let mut points = Vec::new();
        for (i, line) in lines {
            let line_no = i + 1;
            let line = line.trim();
            if line.is_empty() {
                continue;
            }
            let err = |reason: String| ToolPathError::Csv {
                line: line_no,
                reason,
            };
            let f: Vec<&str> = line.split(',').map(str::trim).collect();
            if f.len() != 13 {
                return Err(err(format!("expected 13 fields, got {}", f.len())));
            }
            let int = |k: usize, name: &str| {
                f[k].parse::<u32>()
                    .map_err(|_| err(format!("{name} `{}` is not a whole number", clip(f[k]))))
            };
            let num = |k: usize, name: &str| match f[k].parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(err(format!(
                    "{name} `{}` is not a finite number",
                    clip(f[k])
                ))),
            };
            // Thickness and width are kept in single precision (a 0.1 nm step at 1 mm).
            let num32 = |k: usize, name: &str| match num(k, name).map(|v| v as f32) {
                Ok(v) if !v.is_finite() => {
                    Err(err(format!("{name} `{}` is too large", clip(f[k]))))
                }
                v => v,
            };
            let kind = match f[2] {
                "print" => MoveKind::Print,
                "travel" => MoveKind::Travel,
                other => {
                    return Err(err(format!(
                        "move `{}` is neither `print` nor `travel`",
                        clip(other)
                    )))
                }
            };
            points.push(PathPoint {
                feature: int(0, "feature")?,
                layer: int(1, "layer")?,
                kind,
                p: [num(3, "x")?, num(4, "y")?, num(5, "z")?],
                axis: [num(6, "i")?, num(7, "j")?, num(8, "k")?],
                e: num(9, "e")?,
                thickness: num32(10, "thickness")?,
                width: num32(11, "width")?,
                role: Role::parse(f[12]).ok_or_else(|| {
                    err(format!(
                        "role `{}` is not one of {}",
                        clip(f[12]),
                        role_names()
                    ))
                })?,
            });
        }
        Ok(ToolPath { points })
    }

    /// The first point holding a NaN or infinite number, as an error.
    pub fn check_finite(&self) -> Result<(), ToolPathError> {
        for (index, q) in self.points.iter().enumerate() {
            let fields = [
                ("x", q.p[0]),
                ("y", q.p[1]),
                ("z", q.p[2]),
                ("i", q.axis[0]),
                ("j", q.axis[1]),
                ("k", q.axis[2]),
                ("e", q.e),
                ("thickness", f64::from(q.thickness)),
                ("width", f64::from(q.width)),
            ];
            if let Some((field, _)) = fields.iter().find(|(_, v)| !v.is_finite()) {
                return Err(ToolPathError::NonFinite {
                    index,
                    feature: q.feature as usize,
                    layer: q.layer as usize,
                    field,
                });
            }
        }
        Ok(())
    }
}

/// The roles' CSV names, for an error message.
fn role_names() -> String {
    Role::ALL.map(Role::as_str).join(", ")
}

/// `s` cut to 40 characters for an error message, with control characters replaced.
fn clip(s: &str) -> String {
    let mut out: String = s
        .chars()
        .take(40)
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    if s.chars().count() > 40 {
        out.push('…');
    }
    out
}

/// Appends the line of `q` in toolpath.csv ([`ToolPath::to_csv`]), with its `\n`: ASCII.
fn csv_line(line: &mut Vec<u8>, q: &PathPoint) {
    push_integer_bytes(line, u64::from(q.feature));
    line.push(b',');
    push_integer_bytes(line, u64::from(q.layer));
    line.push(b',');
    line.extend_from_slice(q.kind.as_str().as_bytes());
    for (x, decimals) in [
        (q.p[0], 6),
        (q.p[1], 6),
        (q.p[2], 6),
        (q.axis[0], 6),
        (q.axis[1], 6),
        (q.axis[2], 6),
        (q.e, 6),
        (f64::from(q.thickness), 4),
        (f64::from(q.width), 4),
    ] {
        line.push(b',');
        push_fixed_bytes(line, x, decimals);
    }
    line.push(b',');
    line.extend_from_slice(q.role.as_str().as_bytes());
    line.push(b'\n');
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> ToolPath {
        let pt = |kind, p: [f64; 3], e| PathPoint {
            feature: 3,
            layer: 1,
            kind,
            p,
            axis: [0.0, -0.6, 0.8],
            e,
            thickness: 0.2,
            width: 0.45,
            role: Role::Perimeter,
        };
        ToolPath {
            points: vec![
                pt(MoveKind::Travel, [-1.0, 2.5, 0.4], 0.0),
                pt(MoveKind::Print, [1e-9, -1e-12, 123456.123456789], 0.0374177),
                pt(MoveKind::Print, [-0.0, 1e15, 0.4], 1e-7),
            ],
        }
    }

    #[test]
    fn csv_round_trip_and_exact_header() {
        let p = sample();
        let csv = p.to_csv();
        assert_eq!(
            csv.lines().next(),
            Some("feature,layer,move,x,y,z,i,j,k,e,thickness,width,role")
        );
        assert!(!csv.contains("e-") && !csv.contains("e+") && !csv.contains("-0.000000,"));
        let back = ToolPath::from_csv(&csv).unwrap();
        assert_eq!(back.points.len(), p.points.len());
        for (a, b) in p.points.iter().zip(&back.points) {
            assert_eq!(
                (a.feature, a.layer, a.kind, a.role),
                (b.feature, b.layer, b.kind, b.role)
            );
            for k in 0..3 {
                assert!((a.p[k] - b.p[k]).abs() <= 5e-7);
                assert!((a.axis[k] - b.axis[k]).abs() <= 5e-7);
            }
            assert!((a.e - b.e).abs() <= 5e-7);
            assert!((a.thickness - b.thickness).abs() <= 5e-5);
            assert!((a.width - b.width).abs() <= 5e-5);
        }
        // Written again, the text is identical.
        assert_eq!(back.to_csv(), csv);
        assert_eq!(
            ToolPath::from_csv(&csv.replace('\n', "\r\n")).unwrap(),
            back
        );
    }

    #[test]
    fn csv_errors_name_the_line() {
        let good = sample().to_csv();
        let cases = [
            (String::new(), 1, "header"),
            ("x,y\n".to_string(), 1, "header"),
            (good.replace("travel", "jump"), 2, "move"),
            (good.replacen(",0.2000,", ",NaN,", 1), 2, "thickness"),
            (good.replacen(",0.2000,", ",1e39,", 1), 2, "too large"),
            (
                good.replacen("3,1,print", "4294967296,1,print", 1),
                3,
                "feature",
            ),
            (good.replacen("3,1,print", "-3,1,print", 1), 3, "feature"),
            (format!("{good}1,2,print\n"), 5, "13 fields"),
            (good.replacen(",perimeter\n", ",wall\n", 1), 2, "role"),
        ];
        for (text, line, needle) in cases {
            match ToolPath::from_csv(&text) {
                Err(ToolPathError::Csv { line: l, reason }) => {
                    assert_eq!(l, line, "{reason}");
                    assert!(reason.contains(needle), "{reason}");
                }
                other => panic!("{other:?}"),
            }
        }
        assert_eq!(ToolPath::from_csv(CSV_HEADER).unwrap(), ToolPath::default());
    }

    /// A path of millions of points must fit in memory: the point stays at 80 bytes.
    #[test]
    fn a_point_takes_80_bytes() {
        assert_eq!(std::mem::size_of::<PathPoint>(), 80);
    }
}
