//! The program run symbolically: statements in order, calls, triggers, the extruder, the feed
//! and the ready handshake, and the interrupts' routines.

use super::source::{call_name, Module, Statement};
use super::values::{
    aggregate, analog_assignment, input, output_assignment, pos_aggregate, AXIS_KEYS, FRAME_KEYS,
};
use super::{err, KrlError, KrlInterrupt, KrlMove, KrlRead, KrlReady, Motion, Target};
use std::collections::BTreeMap;

/// What an interrupt's routine does: it may set analog and digital outputs, then `BRAKE`.
pub(super) fn routine(
    file: &str,
    body: &[Statement],
    irq: &mut KrlInterrupt,
) -> Result<(), KrlError> {
    for s in body {
        let upper = s.text.to_ascii_uppercase();
        if irq.brakes {
            return Err(err(file, s.line, "a statement after BRAKE"));
        }
        if upper.trim() == "BRAKE" {
            irq.brakes = true;
        } else if let Some((n, v)) = analog_assignment(&upper) {
            irq.analog.push((n, v.map_err(|r| err(file, s.line, r))?));
        } else if let Some((n, on)) = output_assignment(&upper) {
            irq.outputs.push((n, on));
        } else {
            return Err(err(
                file,
                s.line,
                format!("unexpected `{}` in an interrupt routine", s.text),
            ));
        }
    }
    Ok(())
}

/// The running program.
pub(super) struct Run<'a> {
    pub(super) modules: &'a BTreeMap<String, Module>,
    pub(super) main: String,
    pub(super) out: KrlRead,
    pub(super) initialised: bool,
    pub(super) extruder: bool,
    pub(super) pending: Option<bool>,
    /// The feed set at the start of the next motion, and the feed in force.
    pub(super) pending_feed: Option<f64>,
    pub(super) feed: Option<f64>,
    pub(super) vel: Option<f64>,
    pub(super) stack: Vec<String>,
    /// `IF`s open.
    pub(super) if_depth: usize,
    /// Inside a `SPLINE` block: the segments read so far.
    pub(super) block: Option<usize>,
}

impl Run<'_> {
    /// The statements of the extruder's signals: the ready handshake (`$TIMER`, `WAIT FOR`,
    /// `IF NOT $IN[n] THEN`, `HALT`, `ENDIF`), an interrupt's declaration and switching on,
    /// and the feed's analog output set at once; whether `upper` (the statement, upper case)
    /// is one.
    fn signal(&mut self, m: &Module, s: &Statement, upper: &str) -> Result<bool, KrlError> {
        let (file, line) = (m.src_file.as_str(), s.line);
        let compact: String = upper.chars().filter(|c| !c.is_whitespace()).collect();
        if let Some(rest) = upper.strip_prefix("INTERRUPT DECL ") {
            let bad = || {
                err(
                    file,
                    line,
                    format!("`{}` is not `INTERRUPT DECL n WHEN .. DO name( )`", s.text),
                )
            };
            let (n, rest) = rest.trim().split_once(' ').ok_or_else(bad)?;
            let number: u32 = n.parse().map_err(|_| bad())?;
            let rest = rest.trim().strip_prefix("WHEN ").ok_or_else(bad)?;
            let (condition, routine) = rest.split_once(" DO ").ok_or_else(bad)?;
            let routine = call_name(routine.trim())
                .ok_or_else(bad)?
                .to_ascii_uppercase();
            if !m.locals.contains_key(&routine) {
                return Err(err(
                    file,
                    line,
                    format!("`{routine}` is not a routine of this module"),
                ));
            }
            self.out.interrupts.push(KrlInterrupt {
                number,
                condition: condition.chars().filter(|c| !c.is_whitespace()).collect(),
                routine,
                on: false,
                analog: vec![],
                outputs: vec![],
                brakes: false,
            });
            return Ok(true);
        }
        if let Some(n) = upper.strip_prefix("INTERRUPT ON ") {
            let n: u32 = n
                .trim()
                .parse()
                .map_err(|_| err(file, line, format!("bad interrupt number in `{}`", s.text)))?;
            // The system's interrupts (declared GLOBAL elsewhere) are switched on too.
            if let Some(irq) = self.out.interrupts.iter_mut().find(|i| i.number == n) {
                irq.on = true;
            }
            return Ok(true);
        }
        if let Some((n, v)) = analog_assignment(upper) {
            let v = v.map_err(|r| err(file, line, r))?;
            self.feed_output(file, line, n)?;
            self.feed = Some(v);
            self.pending_feed = None;
            return Ok(true);
        }
        let timer = |r: &str| -> Option<u32> { r.strip_suffix(']')?.parse().ok() };
        if let Some((lhs, rhs)) = compact.split_once('=') {
            let value_ok = match lhs.strip_prefix("$TIMER_STOP[").map(timer) {
                Some(Some(_)) => rhs == "TRUE" || rhs == "FALSE",
                Some(None) => false,
                None => match lhs.strip_prefix("$TIMER[").map(timer) {
                    Some(Some(_)) => rhs.parse::<i64>().is_ok(),
                    Some(None) => false,
                    None => return self.flow(file, line, upper),
                },
            };
            if !value_ok {
                return Err(err(file, line, format!("bad timer statement `{}`", s.text)));
            }
            return Ok(true);
        }
        self.flow(file, line, upper)
    }

    /// `WAIT FOR`, `IF NOT $IN[n] THEN`, `HALT` and `ENDIF` of the ready handshake.
    fn flow(&mut self, file: &str, line: usize, upper: &str) -> Result<bool, KrlError> {
        if let Some(cond) = upper.strip_prefix("WAIT FOR ") {
            let cond = cond.trim();
            if let Some((inp, timeout)) = cond.split_once(" OR ") {
                let bad = || err(file, line, format!("unexpected wait `{cond}`"));
                let n = input(inp).ok_or_else(bad)?;
                let t: String = timeout.chars().filter(|c| !c.is_whitespace()).collect();
                let ms = t
                    .strip_prefix("($TIMER[")
                    .and_then(|r| r.split_once("]>="))
                    .and_then(|(_, v)| v.strip_suffix(')'))
                    .and_then(|v| v.parse::<f64>().ok())
                    .ok_or_else(bad)?;
                if self.out.ready.is_some() {
                    return Err(err(file, line, "a second wait for the ready input"));
                }
                self.out.ready = Some(KrlReady {
                    input: n,
                    timeout_s: ms / 1000.0,
                    before_move: self.out.moves.len(),
                    halts: false,
                });
            } else if input(cond).is_none() {
                return Err(err(file, line, format!("unexpected wait `{cond}`")));
            }
            return Ok(true);
        }
        if let Some(cond) = upper
            .strip_prefix("IF NOT ")
            .and_then(|r| r.trim().strip_suffix(" THEN"))
        {
            if input(cond).is_none() {
                return Err(err(file, line, format!("unexpected condition `{cond}`")));
            }
            self.if_depth += 1;
            return Ok(true);
        }
        match upper.trim() {
            "HALT" if self.if_depth > 0 => {
                if let Some(r) = self.out.ready.as_mut() {
                    r.halts = true;
                }
                Ok(true)
            }
            "ENDIF" if self.if_depth > 0 => {
                self.if_depth -= 1;
                Ok(true)
            }
            "HALT" | "ENDIF" => Err(err(file, line, format!("`{upper}` outside an IF"))),
            _ => Ok(false),
        }
    }

    /// The feed's analog output is `$ANOUT[n]`, the same throughout.
    fn feed_output(&mut self, file: &str, line: usize, n: u32) -> Result<(), KrlError> {
        match self.out.feed_output {
            Some(k) if k != n => Err(err(
                file,
                line,
                format!("sets $ANOUT[{n}], the feed is $ANOUT[{k}]"),
            )),
            _ => {
                self.out.feed_output = Some(n);
                Ok(())
            }
        }
    }

    pub(super) fn module(&mut self, name: &str) -> Result<(), KrlError> {
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
        if self.block.is_some() {
            return Err(err(&m.src_file, 0, "SPLINE without ENDSPLINE"));
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

    /// A trigger's action (`rest`, after `DO`): the extruder's output or the feed's analog
    /// output, set at the start of the next motion.
    fn trigger(&mut self, file: &str, line: usize, rest: &str) -> Result<(), KrlError> {
        if let Some((n, v)) = analog_assignment(rest) {
            let v = v.map_err(|r| err(file, line, r))?;
            self.feed_output(file, line, n)?;
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
        Ok(())
    }

    /// A statement inside a `SPLINE` block (`upper`, upper case): a segment, a trigger on its
    /// path, or `ENDSPLINE`.
    fn spline_statement(
        &mut self,
        m: &Module,
        s: &Statement,
        upper: &str,
        segments: usize,
    ) -> Result<(), KrlError> {
        let (file, line) = (m.src_file.as_str(), s.line);
        if upper.trim() == "ENDSPLINE" {
            if segments == 0 {
                return Err(err(file, line, "an empty SPLINE block"));
            }
            self.block = None;
            return Ok(());
        }
        if let Some(rest) = upper.strip_prefix("TRIGGER WHEN PATH=0 ONSTART DELAY=0 DO ") {
            return self.trigger(file, line, rest);
        }
        if let Some(rest) = upper.strip_prefix("SPL ").or(upper.strip_prefix("SLIN ")) {
            self.block = Some(segments + 1);
            return self.motion(m, s, upper, rest);
        }
        Err(err(
            file,
            line,
            format!("`{}` inside a SPLINE block", s.text),
        ))
    }

    fn statement(&mut self, m: &Module, s: &Statement) -> Result<(), KrlError> {
        let file = m.src_file.as_str();
        let line = s.line;
        let upper = s.text.to_ascii_uppercase();
        if let Some(segments) = self.block {
            return self.spline_statement(m, s, &upper, segments);
        }
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
        if upper.starts_with("GLOBAL INTERRUPT DECL ") {
            return Ok(());
        }
        if self.signal(m, s, &upper)? {
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
            return self.trigger(file, line, rest);
        }
        if let Some(rest) = upper.strip_prefix("PTP ").or(upper.strip_prefix("LIN ")) {
            return self.motion(m, s, &upper, rest);
        }
        if upper.trim() == "SPLINE" {
            self.block = Some(0);
            return Ok(());
        }
        if let Some(callee) = call_name(&s.text) {
            if self.stack.len() == 1 {
                self.out.calls.push(callee.clone());
            }
            return self.module(&callee);
        }
        Err(err(file, line, format!("unknown statement `{}`", s.text)))
    }

    /// A `PTP`, `LIN`, `SPL` or `SLIN` statement (`rest` after the keyword, `upper` the whole upper-cased):
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
        let motion = match upper.split_whitespace().next() {
            Some("PTP") => Motion::Ptp,
            Some("SPL") => Motion::Spl,
            Some("SLIN") => Motion::Slin,
            _ => Motion::Lin,
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
