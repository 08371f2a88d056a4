//! The KRL text of a program: the `.src` and `.dat` files (split into parts when long), KRL
//! names and frame aggregates.

use super::cell::{ExtruderSwitch, KrlFrame, KrlMotion, KukaCell};
use super::checks::{KukaFigures, Reach};
use super::motion::{Kind, Step};
use super::opw::bits_text;
use super::signals::{interrupt_lines, ready_lines, reset_lines, stop_routine};
use crate::gcode::{comment_text, push_line};
use crate::machine::MachineProfile;
use crate::sink::{insert_notes, write_file, Chunked, ProgramSink};
use crate::PostError;
use std::collections::BTreeMap;
use toolpath::{fixed, ToolPath};

/// Longest KRL name (identifiers and module names).
pub const KRL_NAME_MAX: usize = 24;

/// Name of the home position declared in the main program's `.dat`.
pub const HOME_NAME: &str = "XHOME_PRINT";

/// `s` as a KRL identifier of at most `max` characters: ASCII letters, digits and `_`
/// (others become `_`), starting with a letter, lower case, not a KRL keyword; `features`
/// when nothing is left.
pub fn krl_name(s: &str, max: usize) -> String {
    let mut name: String = s
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    if name.trim_matches('_').is_empty() {
        name = "features".into();
    }
    if !name.starts_with(|c: char| c.is_ascii_alphabetic()) {
        name.insert_str(0, "p_");
    }
    const KEYWORDS: &[&str] = &[
        "and",
        "anin",
        "anout",
        "axis",
        "b_and",
        "b_exor",
        "b_not",
        "b_or",
        "bool",
        "brake",
        "c_dis",
        "c_ori",
        "c_ptp",
        "c_vel",
        "case",
        "char",
        "circ",
        "circ_rel",
        "const",
        "continue",
        "decl",
        "def",
        "default",
        "defdat",
        "deffct",
        "delay",
        "distance",
        "do",
        "e6axis",
        "e6pos",
        "else",
        "end",
        "enddat",
        "endfct",
        "endfor",
        "endif",
        "endloop",
        "endswitch",
        "endwhile",
        "enum",
        "exit",
        "exor",
        "ext",
        "extfct",
        "extruder_stop",
        "false",
        "for",
        "frame",
        "global",
        "goto",
        "halt",
        "if",
        "import",
        "int",
        "interrupt",
        "is",
        "lin",
        "lin_rel",
        "loop",
        "main",
        "not",
        "or",
        "pos",
        "prio",
        "ptp",
        "ptp_rel",
        "public",
        "pulse",
        "real",
        "repeat",
        "resume",
        "return",
        "sec",
        "signal",
        "struc",
        "switch",
        "then",
        "to",
        "trigger",
        "true",
        "until",
        "wait",
        "when",
        "while",
        "xhome_print",
    ];
    if KEYWORDS.contains(&name.as_str()) {
        name.push_str("_prg");
    }
    name.truncate(max.max(1));
    name
}

/// A KRL frame aggregate `{X .., Y .., Z .., A .., B .., C ..}`: mm with 3 decimals, degrees
/// with 4.
pub fn frame_text(f: &[f64; 6]) -> String {
    format!(
        "{{X {}, Y {}, Z {}, A {}, B {}, C {}}}",
        fixed(f[0], 3),
        fixed(f[1], 3),
        fixed(f[2], 3),
        fixed(f[3], 4),
        fixed(f[4], 4),
        fixed(f[5], 4)
    )
}

/// A KRL POS aggregate `{X .., Y .., Z .., A .., B .., C .., S 'B..', T 'B..'}`: the frame of
/// [`frame_text`] with KUKA's Status (3 bits) and Turn (6 bits) of the joints it is reached
/// with, in binary as KRL writes them.
pub fn pos_text(f: &[f64; 6], status: u8, turn: u8) -> String {
    let frame = frame_text(f);
    format!(
        "{}, S {}, T {}}}",
        &frame[..frame.len() - 1],
        bits_text(status, 3),
        bits_text(turn, 6)
    )
}

/// The program's lines, one per step ([`Steps::push`]), and what writing them finds.
struct Steps<'a> {
    cell: &'a KukaCell,
    path: &'a ToolPath,
    /// The reach check of the motions, as they are written.
    reach: Reach<'a>,
    /// The `$VEL.CP` in force.
    vel: Option<f64>,
    /// Print LINs whose feed ratio is beyond the analog output's full scale, and the largest
    /// such ratio.
    beyond: (usize, f64),
    /// The file being written and the lines written into it so far.
    file: String,
    line: usize,
    /// Inside a `SPLINE` block; a block the last file ended is to go on in this one.
    in_block: bool,
    reopen: bool,
}

impl Steps<'_> {
    /// Appends the line of `step` (and its line break) to `out`.
    fn push(&mut self, step: &Step, out: &mut String) {
        let cell = self.cell;
        let (out_n, feed_out) = (cell.extruder_output, cell.feed_output);
        if std::mem::take(&mut self.reopen) {
            // A block cut at the end of the last part goes on here, unless it ends at once.
            if matches!(step, Step::SplineEnd) {
                self.in_block = false;
                return;
            }
            self.line += 1;
            push_line(out, "SPLINE");
            self.in_block = true;
        }
        // Inside a spline block a trigger refers to the path of its segments.
        let trigger = if self.in_block {
            "TRIGGER WHEN PATH=0 ONSTART DELAY=0 DO"
        } else {
            "TRIGGER WHEN DISTANCE=0 DELAY=0 DO"
        };
        let line = match step {
            Step::SplineStart => {
                self.in_block = true;
                "SPLINE".into()
            }
            Step::SplineEnd => {
                self.in_block = false;
                "ENDSPLINE".into()
            }
            Step::Comment(c) => format!("; {}", comment_text(c)),
            Step::Vel(v) => {
                self.vel = Some(*v);
                format!("$VEL.CP = {}", fixed(*v, 4))
            }
            Step::Extruder(on) => {
                let state = if *on { "TRUE" } else { "FALSE" };
                match cell.extruder_switch {
                    ExtruderSwitch::Out => format!("$OUT[{out_n}] = {state}"),
                    ExtruderSwitch::Trigger => format!("{trigger} $OUT[{out_n}]={state}"),
                }
            }
            Step::Feed(ratio) => {
                let v = ratio / cell.feed_ratio_full_scale;
                if v > 1.0 {
                    self.beyond = (self.beyond.0 + 1, self.beyond.1.max(*ratio));
                }
                format!(
                    "{trigger} $ANOUT[{feed_out}]={}",
                    fixed(v.clamp(0.0, 1.0), 5)
                )
            }
            Step::WaitReady => ready_lines(cell).join("\n"),
            Step::Move {
                kind, pose, point, ..
            } => {
                let feature = self.path.points[*point].feature;
                let at = (self.file.as_str(), self.line + 1);
                let solved = self.reach.motion(pose, *point, feature as usize, at);
                let f = solved.frame;
                let mut line = match (kind, solved.joints) {
                    (Kind::Ptp, Some((_, s, t))) => format!("PTP {}", pos_text(&f, s, t)),
                    (Kind::Ptp, None) => format!("PTP {}", frame_text(&f)),
                    (Kind::Lin, _) => format!("LIN {} C_DIS", frame_text(&f)),
                    (Kind::Spl, _) => format!("SPL {}", frame_text(&f)),
                    (Kind::Slin, _) => format!("SLIN {}", frame_text(&f)),
                };
                if let Some(note) = solved.note {
                    line.push_str(" ; ");
                    line.push_str(note);
                }
                line
            }
        };
        self.line += 1 + line.matches('\n').count();
        push_line(out, &line);
    }

    /// Writes the lines of `steps` after `text` (what the file starts with) into the file
    /// `name` of `sink` as they are made ([`Chunked`]), up to and including the step of its
    /// `motions`th motion (all of them when `None`), then `end`.
    fn write(
        &mut self,
        steps: impl Iterator<Item = Step>,
        motions: Option<usize>,
        mut text: String,
        end: &str,
        sink: &mut dyn ProgramSink,
        name: &str,
    ) -> Result<(), PostError> {
        let mut file = Chunked::open(sink, name)?;
        self.file = name.to_string();
        self.line = text.matches('\n').count();
        let mut seen = 0;
        for step in steps {
            self.push(&step, &mut text);
            file.pass_on(&mut text)?;
            if matches!(step, Step::Move { .. }) {
                seen += 1;
                if Some(seen) == motions {
                    break;
                }
            }
        }
        if std::mem::take(&mut self.in_block) {
            // A part ends inside a block: it ends here and goes on in the next part.
            push_line(&mut text, "ENDSPLINE");
            self.reopen = true;
        }
        text.push_str(end);
        file.finish(&text)
    }
}

/// The `.src` and `.dat` files of the program of `steps` (`moves` motions, each checked as its
/// line is written: [`Reach`]), written into `sink` as their lines are made ([`Chunked`]):
/// `<name>.src` (with `notes` after the line naming the source) and `<name>.dat`, then the
/// parts' `.src` and `.dat` in order when the program is split. Returns the figures of the
/// check, its warnings pushed onto `warnings`.
#[allow(clippy::too_many_arguments)]
pub(super) fn write_files(
    m: &MachineProfile,
    path: &ToolPath,
    steps: impl Iterator<Item = Step>,
    moves: usize,
    reach: Reach,
    offset: [f64; 3],
    job: (&str, &str, &[String]),
    sink: &mut dyn ProgramSink,
    warnings: &mut Vec<String>,
) -> Result<BTreeMap<usize, KukaFigures>, PostError> {
    let (program_name, source, notes) = job;
    let cell = reach.cell;
    let feed_out = cell.feed_output;
    let per = cell.max_moves_per_file.max(1);
    let parts = if moves > per { moves.div_ceil(per) } else { 0 };
    let digits = parts.to_string().len().max(3);
    let name = if parts > 0 {
        krl_name(program_name, KRL_NAME_MAX - 2 - digits)
    } else {
        krl_name(program_name, KRL_NAME_MAX)
    };
    let part_name = |i: usize| format!("{name}_p{:0digits$}", i + 1);

    let src = comment_text(source);
    let mut main = main_header(m, cell, &name, &src, offset, (moves, parts, per));
    if parts > 0 {
        main.extend((0..parts).map(|i| format!("{}( )", part_name(i))));
    }
    let mut head = join(&main);
    insert_notes(&mut head, notes);
    let mut tail: Vec<String> = reset_lines(cell).into();
    tail.extend([format!("PTP {HOME_NAME}"), "END".into()]);
    tail.extend(stop_routine(cell));
    let tail = join(&tail);
    let h = cell.home;
    let dat = join(&[
        "&ACCESS RVP".into(),
        "&REL 1".into(),
        format!("DEFDAT {name}"),
        format!("; generated by features from {src}"),
        format!(
            "DECL AXIS {HOME_NAME} = {{A1 {}, A2 {}, A3 {}, A4 {}, A5 {}, A6 {}}}",
            fixed(h[0], 3),
            fixed(h[1], 3),
            fixed(h[2], 3),
            fixed(h[3], 3),
            fixed(h[4], 3),
            fixed(h[5], 3)
        ),
        "ENDDAT".into(),
    ]);
    let mut lines = Steps {
        cell,
        path,
        reach,
        vel: None,
        beyond: (0, 0.0),
        file: String::new(),
        line: 0,
        in_block: false,
        reopen: false,
    };
    let main_src = format!("{name}.src");
    let mut steps = steps;
    if parts == 0 {
        lines.write(steps, None, head, &tail, sink, &main_src)?;
        write_file(sink, &format!("{name}.dat"), dat.as_bytes())?;
    } else {
        head.push_str(&tail);
        write_file(sink, &main_src, head.as_bytes())?;
        write_file(sink, &format!("{name}.dat"), dat.as_bytes())?;
        for i in 0..parts {
            let pname = part_name(i);
            let mut text = join(&[
                "&ACCESS RVP".into(),
                "&REL 1".into(),
                format!("DEF {pname}( )"),
                format!(
                    "; part {} of {parts} of {name}, generated by features from {src}",
                    i + 1
                ),
            ]);
            // The speed in force, unless the part's first motion sets its own.
            let mut first = Vec::new();
            for step in steps.by_ref() {
                let motion = matches!(step, Step::Move { .. });
                first.push(step);
                if motion {
                    break;
                }
            }
            let sets_vel = first.iter().any(|s| matches!(s, Step::Vel(_)));
            if let (Some(v), false) = (lines.vel, sets_vel) {
                push_line(&mut text, &format!("$VEL.CP = {}", fixed(v, 4)));
            }
            // The last part takes the steps after the last motion too.
            let motions = (i + 1 < parts).then_some(per);
            let part = first.into_iter().chain(steps.by_ref());
            lines.write(part, motions, text, "END\n", sink, &format!("{pname}.src"))?;
            let dat = join(&[
                "&ACCESS RVP".into(),
                "&REL 1".into(),
                format!("DEFDAT {pname}"),
                format!("; part {} of {parts} of {name}", i + 1),
                "ENDDAT".into(),
            ]);
            write_file(sink, &format!("{pname}.dat"), dat.as_bytes())?;
        }
    }
    let (beyond, most) = lines.beyond;
    if beyond > 0 {
        warnings.push(format!(
            "{beyond} print LIN(s) need a feed ratio above kuka.feed_ratio_full_scale {} mm/mm (up to {}): $ANOUT[{feed_out}] is held at 1.0 there, under-extruding",
            fixed(cell.feed_ratio_full_scale, 5),
            fixed(most, 5)
        ));
    }
    Ok(lines.reach.finish(path, warnings))
}

/// The main program's lines up to its calls of the parts: the header comments (source,
/// machine, offset, tool, extruder, filament feed, motions), the initialisation folds, the
/// frames and speeds, and the move home; `(moves, parts, per)` counts the motions, the parts and
/// the motions per part.
fn main_header(
    m: &MachineProfile,
    cell: &KukaCell,
    name: &str,
    src: &str,
    offset: [f64; 3],
    (moves, parts, per): (usize, usize, usize),
) -> Vec<String> {
    let out = cell.extruder_output;
    let feed_out = cell.feed_output;
    let switch = match cell.extruder_switch {
        ExtruderSwitch::Out => format!("$OUT[{out}] between motions (exact stop)"),
        ExtruderSwitch::Trigger => format!("$OUT[{out}] by TRIGGER at the motion's start"),
    };

    let mut lines = vec![
        "&ACCESS RVP".into(),
        "&REL 1".into(),
        format!("DEF {name}( )"),
        format!("; generated by features from {src}"),
        format!("; machine: {} (kuka)", comment_text(&m.name)),
        format!(
            "; part offset X{} Y{} Z{} (base = part + offset)",
            fixed(offset[0], 3),
            fixed(offset[1], 3),
            fixed(offset[2], 3)
        ),
        "; tool: Z along the nozzle into the deposit (the tool path axis is -Z of $TOOL)".into(),
        format!(
            "; extruder: {switch}; set on its controller: nozzle {} C, bed {} C, filament {} mm",
            fixed(m.nozzle_temperature, 0),
            fixed(m.bed_temperature, 0),
            fixed(m.filament_diameter, 2)
        ),
        format!(
            "; filament feed per print motion: $ANOUT[{feed_out}] = feed ratio / {} (feed ratio = filament mm per mm of path, the plan's for that motion), set by TRIGGER where the motion starts; the extruder feeds $ANOUT[{feed_out}] x {} mm of filament per mm the tool moves",
            fixed(cell.feed_ratio_full_scale, 5),
            fixed(cell.feed_ratio_full_scale, 5)
        ),
    ];
    if cell.motion == KrlMotion::Spline {
        lines.push(format!(
            "; print paths: SPLINE blocks through the points left once those within {} mm of a straight run are dropped; SPL where a cubic through the neighbours stays within {} mm of the plan, SLIN elsewhere; the feed set by TRIGGER WHEN PATH=0 ONSTART where a segment starts",
            fixed(cell.spline_tolerance / 2.0, 3),
            fixed(cell.spline_tolerance, 3)
        ));
    }
    lines.extend([
        format!(
            "; {moves} motions{}",
            if parts > 0 {
                format!(" in {parts} parts of at most {per}")
            } else {
                String::new()
            }
        ),
        ";FOLD INI".into(),
        "  ;FOLD BASISTECH INI".into(),
        "    GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )".into(),
        "    INTERRUPT ON 3".into(),
        "    BAS (#INITMOV,0 )".into(),
        "  ;ENDFOLD (BASISTECH INI)".into(),
    ]);
    lines.extend(interrupt_lines());
    lines.extend([";ENDFOLD (INI)".into(), ";FOLD FRAMES AND SPEEDS".into()]);
    lines.extend(frame_lines("BASE", &cell.base, cell.base_index));
    lines.extend(frame_lines("TOOL", &cell.tool, cell.tool_index));
    lines.extend([
        "$ADVANCE = 3".into(),
        format!("$APO.CDIS = {}", fixed(cell.apo_cdis, 3)),
        ";ENDFOLD (FRAMES AND SPEEDS)".into(),
        format!("$OUT[{out}] = FALSE"),
        format!("PTP {HOME_NAME}"),
    ]);
    lines
}

/// The lines that set `$BASE` or `$TOOL` (`what`, `BASE` or `TOOL`) to `frame`: with the
/// controller's number `index`, `BAS (#BASE, n)` after a comment stating the frame assumed to
/// be in `BASE_DATA[n]` (`TOOL_DATA[n]`); without, the assignment of the frame itself.
fn frame_lines(what: &str, frame: &KrlFrame, index: Option<u32>) -> Vec<String> {
    let text = frame_text(&frame.to_array());
    match index {
        Some(n) => vec![
            format!("; assumed {what}_DATA[{n}] = {text} (check it on the controller)"),
            format!("BAS (#{what}, {n})"),
        ],
        None => vec![format!("${what} = {text}")],
    }
}

/// Lines joined with `\n`, ending with one.
pub(super) fn join(lines: &[String]) -> String {
    let mut s = lines.join("\n");
    s.push('\n');
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn krl_names() {
        assert_eq!(krl_name("impeller", 24), "impeller");
        assert_eq!(krl_name("My Part-2.step", 24), "my_part_2_step");
        assert_eq!(krl_name("3d", 24), "p_3d");
        assert_eq!(krl_name("", 24), "features");
        assert_eq!(krl_name("LIN", 24), "lin_prg");
        assert_eq!(krl_name("a_very_long_name_for_a_program", 19).len(), 19);
    }
}
