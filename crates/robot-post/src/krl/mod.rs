//! A small reader of the KRL programs [`crate::kuka::kuka`] writes: it checks their structure
//! and runs them symbolically, returning the motions in order with the extruder's state.
//!
//! Structure checked (`.csv` files beside the program, such as `joints.csv`, are passed
//! over): every `.src` has its `.dat` and the other way round; a `.src` is
//! optional `&` header lines, then `DEF <file name>( )` ... `END`, then local subroutines
//! `DEF name( )` ... `END` (an interrupt's routine); a `.dat` is
//! `DEFDAT <file name>` ... `ENDDAT` holding only `DECL AXIS` lines; `;FOLD`/`;ENDFOLD` are
//! balanced in every file; every statement is one the post writes, and every aggregate is well
//! formed (a frame has X, Y, Z, A, B, C once each, an axis A1..A6, all finite numbers; a
//! `PTP`'s frame may carry the Status `S` and Turn `T`, both or neither); `BAS
//! (#INITMOV,0 )`, `$BASE` and `$TOOL` (or `BAS (#BASE, n)` and `BAS (#TOOL, n)` after the
//! comments `; assumed BASE_DATA[n] = {..}` stating their frames) come before the first
//! motion; every called part is present, and exactly one module (the main program) is called
//! by none; `IF` ... `ENDIF` are balanced; an interrupt's routine is a local subroutine of its
//! module that sets outputs and then may `BRAKE`.
//!
//! Semantics: `$OUT[n] = ...` switches at once; `TRIGGER WHEN DISTANCE=0 ... DO $OUT[n]=...`
//! switches at the start of the next motion; either way a motion's `extruder` is the state
//! during that motion. `TRIGGER WHEN DISTANCE=0 ... DO $ANOUT[n]=v` (the filament feed, one
//! analog output, `v` within 0..1) sets the output at the start of the next motion: a
//! motion's `feed` is the value in force during it; `$ANOUT[n] = v` sets it at once. The
//! ready handshake (`$TIMER`, `WAIT FOR $IN[n] OR ($TIMER[t] >= ms)`, `IF NOT $IN[n] THEN
//! HALT ... ENDIF`) is recorded where it stands among the motions ([`KrlReady`]); interrupts
//! with what their routines do ([`KrlInterrupt`]).

use std::collections::{BTreeMap, BTreeSet};

mod run;
mod source;
mod values;

use run::{routine, Run};
use source::{call_name, read_dat, read_src, Module};

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
    /// `SPL`, a spline segment of a `SPLINE` block.
    Spl,
    /// `SLIN`, a straight segment of a `SPLINE` block.
    Slin,
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
    /// The wait for the extruder's ready input, if the program has one.
    pub ready: Option<KrlReady>,
    /// The interrupts the program declares (not the system's `GLOBAL` ones).
    pub interrupts: Vec<KrlInterrupt>,
    /// The feed's analog output when the program ends (the value last set, at once or by a
    /// trigger of a motion).
    pub end_feed: Option<f64>,
    /// The extruder's output when the program ends.
    pub end_extruder: bool,
}

/// The wait for the extruder's ready input: `WAIT FOR $IN[n] OR ($TIMER[t] >= ms)`, then
/// `IF NOT $IN[n] THEN ... HALT ... ENDIF`.
#[derive(Debug, Clone, PartialEq)]
pub struct KrlReady {
    /// The input waited for.
    pub input: u32,
    /// The longest wait before the program halts (s).
    pub timeout_s: f64,
    /// How many motions the program made before the wait (the index of the next motion in
    /// [`KrlRead::moves`]).
    pub before_move: usize,
    /// The program halts when the input is not on after the wait.
    pub halts: bool,
}

/// An interrupt the program declares: `INTERRUPT DECL n WHEN condition DO routine( )`, and
/// what its routine (a local subroutine) does.
#[derive(Debug, Clone, PartialEq)]
pub struct KrlInterrupt {
    /// Its number (priority).
    pub number: u32,
    /// The condition, upper case, without spaces (`$STOPMESS==TRUE`).
    pub condition: String,
    /// The routine called (upper case).
    pub routine: String,
    /// Switched on (`INTERRUPT ON n`) after its declaration.
    pub on: bool,
    /// The analog outputs the routine sets, `(n, value)` in order.
    pub analog: Vec<(u32, f64)>,
    /// The digital outputs the routine sets, `(n, state)` in order.
    pub outputs: Vec<(u32, bool)>,
    /// The routine ends with `BRAKE` (after the outputs).
    pub brakes: bool,
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
        } else if !lower.ends_with(".csv") {
            // A table beside the program (joints.csv) is not KRL.
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
        if_depth: 0,
        block: None,
    };
    run.module(&main)?;
    if run.if_depth > 0 {
        return Err(err(&run.main, 0, "IF without ENDIF"));
    }
    run.out.end_feed = run.feed;
    run.out.end_extruder = run.extruder;
    let main_module = modules.get(&main);
    for irq in &mut run.out.interrupts {
        let body = main_module.and_then(|m| m.locals.get(&irq.routine).map(|b| (m, b)));
        let Some((m, body)) = body else {
            return Err(err(&main, 0, format!("no routine `{}`", irq.routine)));
        };
        routine(&m.src_file, body, irq)?;
    }
    Ok(run.out)
}
