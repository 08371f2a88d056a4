//! A small reader of the KRL programs [`crate::kuka::kuka`] writes: it checks their structure
//! and runs them symbolically, returning the motions in order with the extruder's state.
//!
//! Structure checked: every `.src` has its `.dat` and the other way round; a `.src` is
//! optional `&` header lines, then `DEF <file name>( )` ... `END`; a `.dat` is
//! `DEFDAT <file name>` ... `ENDDAT` holding only `DECL AXIS` lines; `;FOLD`/`;ENDFOLD` are
//! balanced in every file; every statement is one the post writes, and every aggregate is well
//! formed (a frame has X, Y, Z, A, B, C once each, an axis A1..A6, all finite numbers); `BAS
//! (#INITMOV,0 )`, `$BASE` and `$TOOL` come before the first motion; every called part is
//! present, and exactly one module (the main program) is called by none.
//!
//! Semantics: `$OUT[n] = ...` switches at once; `TRIGGER WHEN DISTANCE=0 ... DO $OUT[n]=...`
//! switches at the start of the next motion; either way a motion's `extruder` is the state
//! during that motion. `TRIGGER WHEN DISTANCE=0 ... DO $ANOUT[n]=v` (the filament feed, one
//! analog output, `v` within 0..1) sets the output at the start of the next motion: a
//! motion's `feed` is the value in force during it.

use std::collections::{BTreeMap, BTreeSet};

/// Why a KRL program could not be read: the file, the one-based line (0 for the whole file)
/// and the reason.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}:{line}: {reason}")]
pub struct KrlError {
    /// The file name.
    pub file: String,
    /// One-based line number, 0 when the problem is the whole file.
    pub line: usize,
    /// What is wrong.
    pub reason: String,
}

/// The kind of motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// `PTP`.
    Ptp,
    /// `LIN`.
    Lin,
}

/// Where a motion goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    /// A tool pose in `$BASE`: `[X, Y, Z, A, B, C]`.
    Frame([f64; 6]),
    /// Joint angles A1..A6 (degrees).
    Axis([f64; 6]),
}

/// One motion of the program, as run.
#[derive(Debug, Clone, PartialEq)]
pub struct KrlMove {
    /// PTP or LIN.
    pub motion: Motion,
    /// The target.
    pub target: Target,
    /// KUKA's Status and Turn of a Cartesian `PTP` (`{.., S 'B010', T 'B000010'}`), when
    /// given.
    pub status_turn: Option<(u8, u8)>,
    /// Ends with `C_DIS`.
    pub approximated: bool,
    /// The extruder output's state during the motion.
    pub extruder: bool,
    /// `$VEL.CP` in force (m/s).
    pub vel_cp: Option<f64>,
    /// The feed's analog output `$ANOUT[n]` in force (0..1), once set.
    pub feed: Option<f64>,
    /// The file the motion is in.
    pub file: String,
    /// Its one-based line.
    pub line: usize,
    /// The comment after the statement, if any (the post writes `UNREACHABLE` and
    /// `WRIST SINGULAR`).
    pub note: Option<String>,
}

/// A program read back.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct KrlRead {
    /// The main module's name (lower case).
    pub main: String,
    /// `$BASE` as last set.
    pub base: Option<[f64; 6]>,
    /// `$TOOL` as last set.
    pub tool: Option<[f64; 6]>,
    /// The base number of `BAS (#BASE, n)`, when the program selects one (`base` is then the
    /// frame its comment `; assumed BASE_DATA[n] = {..}` states).
    pub base_index: Option<u32>,
    /// The tool number of `BAS (#TOOL, n)`, as `base_index`.
    pub tool_index: Option<u32>,
    /// The main program's `; part offset X.. Y.. Z..` comment.
    pub offset: Option<[f64; 3]>,
    /// `$APO.CDIS` as last set (mm).
    pub apo_cdis: Option<f64>,
    /// The output number the extruder statements switch.
    pub extruder_output: Option<u32>,
    /// The analog output number the feed statements set.
    pub feed_output: Option<u32>,
    /// The modules called from the main program, in order (lower case).
    pub calls: Vec<String>,
    /// The motions, in the order the robot makes them.
    pub moves: Vec<KrlMove>,
}

/// One statement of a module's body.
#[derive(Debug, Clone)]
struct Statement {
    line: usize,
    text: String,
    note: Option<String>,
}

#[derive(Debug, Default)]
struct Module {
    src_file: String,
    body: Vec<Statement>,
    /// `DECL AXIS` of the `.dat`, by lower-case name.
    axes: BTreeMap<String, [f64; 6]>,
    offset: Option<[f64; 3]>,
    /// The frames the comments `; assumed BASE_DATA[n] = {..}` (`TOOL_DATA`) state, by
    /// (`BASE` or `TOOL`, n).
    assumed: BTreeMap<(String, u32), [f64; 6]>,
}

fn err(file: &str, line: usize, reason: impl Into<String>) -> KrlError {
    KrlError {
        file: file.to_string(),
        line,
        reason: reason.into(),
    }
}

/// Reads the files (`(name, text)`, as [`crate::kuka::KrlProgram::files`]), checks their
/// structure and runs the main program. See the module documentation.
pub fn read(files: &[(String, String)]) -> Result<KrlRead, KrlError> {
    let mut modules: BTreeMap<String, Module> = BTreeMap::new();
    let mut dats: BTreeSet<String> = BTreeSet::new();
    for (name, text) in files {
        let lower = name.to_ascii_lowercase();
        if let Some(stem) = lower.strip_suffix(".src") {
            if modules.contains_key(stem) {
                return Err(err(name, 0, "a second .src of the same module"));
            }
            let module = read_src(name, stem, text)?;
            modules.insert(stem.to_string(), module);
        } else if let Some(stem) = lower.strip_suffix(".dat") {
            if !dats.insert(stem.to_string()) {
                return Err(err(name, 0, "a second .dat of the same module"));
            }
        } else {
            return Err(err(name, 0, "neither a .src nor a .dat file"));
        }
    }
    for (name, text) in files {
        let lower = name.to_ascii_lowercase();
        if let Some(stem) = lower.strip_suffix(".dat") {
            let module = modules
                .get_mut(stem)
                .ok_or_else(|| err(name, 0, "a .dat without its .src"))?;
            module.axes = read_dat(name, stem, text)?;
        }
    }
    if let Some((stem, m)) = modules.iter().find(|(s, _)| !dats.contains(*s)) {
        return Err(err(&m.src_file, 0, format!("no {stem}.dat")));
    }

    // The call graph: exactly one module is called by none.
    let mut called = BTreeSet::new();
    for m in modules.values() {
        for s in &m.body {
            if let Some(callee) = call_name(&s.text) {
                if !modules.contains_key(&callee) {
                    return Err(err(
                        &m.src_file,
                        s.line,
                        format!("calls `{callee}`, which is not present"),
                    ));
                }
                called.insert(callee);
            }
        }
    }
    let roots: Vec<&String> = modules.keys().filter(|k| !called.contains(*k)).collect();
    let main = match roots.as_slice() {
        [one] => (*one).clone(),
        [] => return Err(err("", 0, "no main program (every module is called)")),
        many => {
            return Err(err(
                "",
                0,
                format!(
                    "{} modules are called by none: {}",
                    many.len(),
                    many.iter()
                        .map(|s| s.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ))
        }
    };
    let mut run = Run {
        modules: &modules,
        main: main.clone(),
        out: KrlRead {
            main: main.clone(),
            offset: modules.get(&main).and_then(|m| m.offset),
            ..KrlRead::default()
        },
        initialised: false,
        extruder: false,
        pending: None,
        pending_feed: None,
        feed: None,
        vel: None,
        stack: Vec::new(),
    };
    run.module(&main)?;
    Ok(run.out)
}

/// The lower-case callee of a call statement `name( )`, if it is one.
fn call_name(s: &str) -> Option<String> {
    let open = s.find('(')?;
    let name = s[..open].trim();
    let args = s[open..].trim();
    let ident = !name.is_empty()
        && name.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    (ident && args.replace(' ', "") == "()").then(|| name.to_ascii_lowercase())
}

/// Splits a line into its statement and comment, and tracks folds.
fn split_comment(line: &str) -> (&str, Option<&str>) {
    match line.find(';') {
        Some(i) => (line[..i].trim(), Some(line[i + 1..].trim())),
        None => (line.trim(), None),
    }
}

/// Fold depth after `comment` (a `;FOLD` opens, a `;ENDFOLD` closes).
fn fold(file: &str, line: usize, comment: Option<&str>, depth: &mut usize) -> Result<(), KrlError> {
    let Some(c) = comment else { return Ok(()) };
    let word = c
        .split_whitespace()
        .next()
        .unwrap_or("")
        .to_ascii_uppercase();
    if word == "FOLD" {
        *depth += 1;
    } else if word == "ENDFOLD" {
        if *depth == 0 {
            return Err(err(file, line, ";ENDFOLD without ;FOLD"));
        }
        *depth -= 1;
    }
    Ok(())
}

fn read_src(file: &str, stem: &str, text: &str) -> Result<Module, KrlError> {
    let mut module = Module {
        src_file: file.to_string(),
        ..Module::default()
    };
    let mut depth = 0;
    let mut state = 0; // 0 before DEF, 1 in the body, 2 after END
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let (stmt, comment) = split_comment(raw);
        fold(file, line, comment, &mut depth)?;
        if let Some(c) = comment {
            if let Some(rest) = c.strip_prefix("part offset ") {
                module.offset = parse_offset(rest);
            }
            if let Some(rest) = c.strip_prefix("assumed ") {
                let (key, frame) = assumed_frame(rest).map_err(|r| err(file, line, r))?;
                module.assumed.insert(key, frame);
            }
        }
        if stmt.is_empty() {
            continue;
        }
        let upper = stmt.to_ascii_uppercase();
        match state {
            0 if stmt.starts_with('&') => {}
            0 => {
                let name = upper.strip_prefix("DEF ").and_then(call_name);
                if name.as_deref() != Some(stem) {
                    return Err(err(
                        file,
                        line,
                        format!("expected `DEF {stem}( )`, got `{stmt}`"),
                    ));
                }
                state = 1;
            }
            1 if upper == "END" => state = 2,
            1 if upper.starts_with("DEF ") || upper.starts_with("DEFDAT ") => {
                return Err(err(file, line, "a second DEF before END"));
            }
            1 => module.body.push(Statement {
                line,
                text: stmt.to_string(),
                note: comment.filter(|c| !c.is_empty()).map(str::to_string),
            }),
            _ => return Err(err(file, line, format!("`{stmt}` after END"))),
        }
    }
    ended(file, state, depth, "DEF", "END")?;
    Ok(module)
}

fn read_dat(file: &str, stem: &str, text: &str) -> Result<BTreeMap<String, [f64; 6]>, KrlError> {
    let mut axes = BTreeMap::new();
    let mut depth = 0;
    let mut state = 0;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let (stmt, comment) = split_comment(raw);
        fold(file, line, comment, &mut depth)?;
        if stmt.is_empty() {
            continue;
        }
        let upper = stmt.to_ascii_uppercase();
        match state {
            0 if stmt.starts_with('&') => {}
            0 => {
                let name = upper.strip_prefix("DEFDAT ").map(str::trim);
                let name = name.map(|n| n.strip_suffix(" PUBLIC").unwrap_or(n).trim());
                if name.map(str::to_ascii_lowercase).as_deref() != Some(stem) {
                    return Err(err(
                        file,
                        line,
                        format!("expected `DEFDAT {stem}`, got `{stmt}`"),
                    ));
                }
                state = 1;
            }
            1 if upper == "ENDDAT" => state = 2,
            1 => {
                let Some(rest) = upper.strip_prefix("DECL AXIS ") else {
                    return Err(err(file, line, format!("unexpected `{stmt}` in a .dat")));
                };
                let (name, value) = rest
                    .split_once('=')
                    .ok_or_else(|| err(file, line, "DECL without a value"))?;
                let v = aggregate(&value.trim().to_ascii_uppercase(), &AXIS_KEYS)
                    .map_err(|r| err(file, line, r))?;
                axes.insert(name.trim().to_ascii_lowercase(), v);
            }
            _ => return Err(err(file, line, format!("`{stmt}` after ENDDAT"))),
        }
    }
    ended(file, state, depth, "DEFDAT", "ENDDAT")?;
    Ok(axes)
}

/// The end-of-file check of a module read by states 0 (before `open`), 1 (inside), 2 (after
/// `close`): it must have opened and closed, with every fold closed.
fn ended(file: &str, state: u8, depth: usize, open: &str, close: &str) -> Result<(), KrlError> {
    match state {
        0 => Err(err(file, 0, format!("no {open}"))),
        1 => Err(err(file, 0, format!("{open} without {close}"))),
        _ if depth != 0 => Err(err(file, 0, format!("{depth} ;FOLD without ;ENDFOLD"))),
        _ => Ok(()),
    }
}

/// `X1.5 Y-2 Z3` → `[1.5, -2, 3]`.
fn parse_offset(s: &str) -> Option<[f64; 3]> {
    let mut v = [0.0; 3];
    let mut words = s.split_whitespace();
    for (k, letter) in ["X", "Y", "Z"].iter().enumerate() {
        v[k] = words.next()?.strip_prefix(letter)?.parse().ok()?;
    }
    Some(v)
}

/// `BASE_DATA[n] = {X .., ...} (...)` → `(("BASE", n), frame)`.
fn assumed_frame(s: &str) -> Result<((String, u32), [f64; 6]), String> {
    let bad = || format!("`assumed {s}` is not `assumed BASE_DATA[n] = {{..}}`");
    let (what, rest) = s.split_once("_DATA[").ok_or_else(bad)?;
    let (n, rest) = rest.split_once(']').ok_or_else(bad)?;
    let n: u32 = n.trim().parse().map_err(|_| bad())?;
    let rest = rest.trim().strip_prefix('=').ok_or_else(bad)?.trim();
    let close = rest.find('}').ok_or_else(bad)?;
    let frame = aggregate(&rest[..=close].to_ascii_uppercase(), &FRAME_KEYS)?;
    Ok(((what.trim().to_ascii_uppercase(), n), frame))
}

const FRAME_KEYS: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];
const AXIS_KEYS: [&str; 6] = ["A1", "A2", "A3", "A4", "A5", "A6"];

/// The components `K v` of a KRL aggregate `{K v, K v, ...}` (upper case), in order.
fn components(s: &str) -> Result<Vec<(&str, &str)>, String> {
    let inner = s
        .strip_prefix('{')
        .and_then(|r| r.strip_suffix('}'))
        .ok_or_else(|| format!("`{s}` is not an aggregate {{...}}"))?;
    inner
        .split(',')
        .map(|part| {
            let mut words = part.split_whitespace();
            match (words.next(), words.next(), words.next()) {
                (Some(key), Some(value), None) => Ok((key, value)),
                _ => Err(format!("`{}` is not `KEY value` in {s}", part.trim())),
            }
        })
        .collect()
}

/// A KRL aggregate `{K v, K v, ...}` (upper case) with exactly `keys`, each once, as numbers
/// in `keys`' order.
fn aggregate(s: &str, keys: &[&str; 6]) -> Result<[f64; 6], String> {
    let (v, st) = pos_aggregate(s, keys)?;
    match st {
        None => Ok(v),
        Some(_) => Err(format!("unexpected component `S` or `T` in {s}")),
    }
}

/// An aggregate's six numbers, with the Status and Turn when given.
type Pos = ([f64; 6], Option<(u8, u8)>);

/// A KRL aggregate with exactly `keys`, each once, and optionally the Status `S` and Turn `T`
/// of a POS (both or neither, as binary `'B..'` or decimal integers of 3 and 6 bits).
fn pos_aggregate(s: &str, keys: &[&str; 6]) -> Result<Pos, String> {
    let mut v = [f64::NAN; 6];
    let mut seen = [false; 6];
    let (mut status, mut turn) = (None, None);
    for (key, value) in components(s)? {
        if key == "S" || key == "T" {
            let (slot, bits) = if key == "S" {
                (&mut status, 3)
            } else {
                (&mut turn, 6)
            };
            if slot.is_some() {
                return Err(format!("component `{key}` twice in {s}"));
            }
            let n = match value.strip_prefix("'B").and_then(|b| b.strip_suffix('\'')) {
                Some(b) => u8::from_str_radix(b, 2).ok(),
                None => value.parse::<u8>().ok(),
            };
            match n {
                Some(n) if u32::from(n) < 1 << bits => *slot = Some(n),
                _ => return Err(format!("`{value}` is not a {bits}-bit {key} in {s}")),
            }
            continue;
        }
        let k = keys
            .iter()
            .position(|&x| x == key)
            .ok_or_else(|| format!("unexpected component `{key}` in {s}"))?;
        if seen[k] {
            return Err(format!("component `{key}` twice in {s}"));
        }
        let x: f64 = value
            .parse()
            .map_err(|_| format!("`{value}` is not a number in {s}"))?;
        if !x.is_finite() {
            return Err(format!("`{value}` is not finite in {s}"));
        }
        seen[k] = true;
        v[k] = x;
    }
    if let Some(k) = seen.iter().position(|s| !s) {
        return Err(format!("component `{}` missing in {s}", keys[k]));
    }
    match (status, turn) {
        (Some(s), Some(t)) => Ok((v, Some((s, t)))),
        (None, None) => Ok((v, None)),
        _ => Err(format!("`S` without `T` or `T` without `S` in {s}")),
    }
}

/// `$OUT[n]=TRUE` → `(n, true)`.
fn output_assignment(s: &str) -> Option<(u32, bool)> {
    let s: String = s.chars().filter(|c| !c.is_whitespace()).collect();
    let rest = s.strip_prefix("$OUT[")?;
    let (n, rest) = rest.split_once(']')?;
    let value = rest.strip_prefix('=')?;
    let on = match value {
        "TRUE" => true,
        "FALSE" => false,
        _ => return None,
    };
    Some((n.parse().ok()?, on))
}

/// `$ANOUT[n]=0.5` → `(n, 0.5)`.
fn analog_assignment(s: &str) -> Option<(u32, Result<f64, String>)> {
    let s: String = s.chars().filter(|c| !c.is_whitespace()).collect();
    let rest = s.strip_prefix("$ANOUT[")?;
    let (n, rest) = rest.split_once(']')?;
    let value = rest.strip_prefix('=')?;
    let v = match value.parse::<f64>() {
        Ok(v) if (-1.0..=1.0).contains(&v) => Ok(v),
        _ => Err(format!("`{value}` is not an analog value within -1..1")),
    };
    Some((n.parse().ok()?, v))
}

/// The running program.
struct Run<'a> {
    modules: &'a BTreeMap<String, Module>,
    main: String,
    out: KrlRead,
    initialised: bool,
    extruder: bool,
    pending: Option<bool>,
    /// The feed set at the start of the next motion, and the feed in force.
    pending_feed: Option<f64>,
    feed: Option<f64>,
    vel: Option<f64>,
    stack: Vec<String>,
}

impl Run<'_> {
    fn module(&mut self, name: &str) -> Result<(), KrlError> {
        let modules = self.modules;
        let Some(m) = modules.get(name) else {
            return Err(err("", 0, format!("module `{name}` is not present")));
        };
        if self.stack.iter().any(|s| s == name) {
            return Err(err(&m.src_file, 0, format!("`{name}` calls itself")));
        }
        self.stack.push(name.to_string());
        for s in &m.body {
            self.statement(m, s)?;
        }
        self.stack.pop();
        Ok(())
    }

    fn output(&mut self, file: &str, line: usize, n: u32) -> Result<(), KrlError> {
        match self.out.extruder_output {
            Some(k) if k != n => Err(err(
                file,
                line,
                format!("switches $OUT[{n}], the extruder is $OUT[{k}]"),
            )),
            _ => {
                self.out.extruder_output = Some(n);
                Ok(())
            }
        }
    }

    fn statement(&mut self, m: &Module, s: &Statement) -> Result<(), KrlError> {
        let file = m.src_file.as_str();
        let line = s.line;
        let upper = s.text.to_ascii_uppercase();
        let number = |v: &str| -> Result<f64, KrlError> {
            let x: f64 = v
                .trim()
                .parse()
                .map_err(|_| err(file, line, format!("`{}` is not a number", v.trim())))?;
            if x.is_finite() {
                Ok(x)
            } else {
                Err(err(file, line, format!("`{}` is not finite", v.trim())))
            }
        };
        if upper.starts_with("GLOBAL INTERRUPT DECL ") || upper.starts_with("INTERRUPT ON ") {
            return Ok(());
        }
        let compact = upper.replace(' ', "");
        if compact == "BAS(#INITMOV,0)" {
            self.initialised = true;
            return Ok(());
        }
        for what in ["BASE", "TOOL"] {
            let Some(n) = compact
                .strip_prefix(&format!("BAS(#{what},"))
                .and_then(|r| r.strip_suffix(')'))
            else {
                continue;
            };
            let n: u32 = n
                .parse()
                .ok()
                .filter(|n| (1..=32).contains(n))
                .ok_or_else(|| err(file, line, format!("bad {what} number `{n}`")))?;
            let frame = m.assumed.get(&(what.to_string(), n)).ok_or_else(|| {
                err(
                    file,
                    line,
                    format!("BAS (#{what}, {n}) without `; assumed {what}_DATA[{n}] = {{..}}`"),
                )
            })?;
            if what == "BASE" {
                self.out.base = Some(*frame);
                self.out.base_index = Some(n);
            } else {
                self.out.tool = Some(*frame);
                self.out.tool_index = Some(n);
            }
            return Ok(());
        }
        if let Some((lhs, rhs)) = upper.split_once('=') {
            let lhs = lhs.trim();
            let rhs = rhs.trim();
            match lhs {
                "$BASE" | "$TOOL" => {
                    let v = aggregate(rhs, &FRAME_KEYS).map_err(|r| err(file, line, r))?;
                    if lhs == "$BASE" {
                        self.out.base = Some(v);
                    } else {
                        self.out.tool = Some(v);
                    }
                    return Ok(());
                }
                "$ADVANCE" => {
                    return match rhs.parse::<u32>() {
                        Ok(n) if n <= 5 => Ok(()),
                        _ => Err(err(file, line, format!("bad $ADVANCE `{rhs}`"))),
                    };
                }
                "$APO.CDIS" => {
                    self.out.apo_cdis = Some(number(rhs)?);
                    return Ok(());
                }
                "$VEL.CP" => {
                    let v = number(rhs)?;
                    if !(v > 0.0 && v <= 3.0) {
                        return Err(err(file, line, format!("$VEL.CP {v} m/s out of range")));
                    }
                    self.vel = Some(v);
                    return Ok(());
                }
                _ => {}
            }
        }
        if let Some((n, on)) = output_assignment(&upper) {
            self.output(file, line, n)?;
            self.extruder = on;
            return Ok(());
        }
        if let Some(rest) = upper.strip_prefix("TRIGGER WHEN DISTANCE=0 DELAY=0 DO ") {
            if let Some((n, v)) = analog_assignment(rest) {
                let v = v.map_err(|r| err(file, line, r))?;
                match self.out.feed_output {
                    Some(k) if k != n => {
                        return Err(err(
                            file,
                            line,
                            format!("sets $ANOUT[{n}], the feed is $ANOUT[{k}]"),
                        ))
                    }
                    _ => self.out.feed_output = Some(n),
                }
                self.pending_feed = Some(v);
                return Ok(());
            }
            let Some((n, on)) = output_assignment(rest) else {
                return Err(err(
                    file,
                    line,
                    format!("unexpected trigger action `{rest}`"),
                ));
            };
            self.output(file, line, n)?;
            self.pending = Some(on);
            return Ok(());
        }
        if let Some(rest) = upper.strip_prefix("PTP ").or(upper.strip_prefix("LIN ")) {
            return self.motion(m, s, &upper, rest);
        }
        if let Some(callee) = call_name(&s.text) {
            if self.stack.len() == 1 {
                self.out.calls.push(callee.clone());
            }
            return self.module(&callee);
        }
        Err(err(file, line, format!("unknown statement `{}`", s.text)))
    }

    /// A `PTP` or `LIN` statement (`rest` after the keyword, `upper` the whole upper-cased):
    /// its target (an aggregate or a declared axis position), whether it is approximated, and
    /// the extruder, feed and speed in force, as a move of the program.
    fn motion(
        &mut self,
        m: &Module,
        s: &Statement,
        upper: &str,
        rest: &str,
    ) -> Result<(), KrlError> {
        let file = m.src_file.as_str();
        let line = s.line;
        let motion = if upper.starts_with("PTP") {
            Motion::Ptp
        } else {
            Motion::Lin
        };
        if !self.initialised {
            return Err(err(file, line, "a motion before BAS (#INITMOV,0 )"));
        }
        let rest = rest.trim();
        let mut status_turn = None;
        let (target, tail) = if rest.starts_with('{') {
            let close = rest
                .find('}')
                .ok_or_else(|| err(file, line, "unclosed aggregate"))?;
            let agg = &rest[..=close];
            let target = if agg.contains("A1 ") {
                Target::Axis(aggregate(agg, &AXIS_KEYS).map_err(|r| err(file, line, r))?)
            } else {
                let (f, st) = pos_aggregate(agg, &FRAME_KEYS).map_err(|r| err(file, line, r))?;
                if st.is_some() && motion != Motion::Ptp {
                    return Err(err(file, line, "Status and Turn on a LIN"));
                }
                status_turn = st;
                Target::Frame(f)
            };
            (target, rest[close + 1..].trim())
        } else {
            let mut words = rest.split_whitespace();
            let name = words.next().unwrap_or("").to_ascii_lowercase();
            let axes = m
                .axes
                .get(&name)
                .or_else(|| {
                    self.modules
                        .get(&self.main)
                        .and_then(|mm| mm.axes.get(&name))
                })
                .ok_or_else(|| err(file, line, format!("`{name}` is not declared")))?;
            (Target::Axis(*axes), rest[name.len()..].trim())
        };
        let approximated = match (motion, tail) {
            (_, "") => false,
            (Motion::Lin, "C_DIS") => true,
            _ => {
                return Err(err(
                    file,
                    line,
                    format!("unexpected `{tail}` after the target"),
                ))
            }
        };
        if matches!(target, Target::Frame(_))
            && (self.out.base.is_none() || self.out.tool.is_none())
        {
            return Err(err(file, line, "a Cartesian motion before $BASE and $TOOL"));
        }
        if let Some(on) = self.pending.take() {
            self.extruder = on;
        }
        if let Some(v) = self.pending_feed.take() {
            self.feed = Some(v);
        }
        self.out.moves.push(KrlMove {
            motion,
            target,
            status_turn,
            approximated,
            extruder: self.extruder,
            vel_cp: self.vel,
            feed: self.feed,
            file: file.to_string(),
            line,
            note: s.note.clone(),
        });
        Ok(())
    }
}
