//! The extruder's signals around the motions: the ready handshake before the first print move,
//! the feed and extruder outputs reset at the end, and the interrupt that resets them when the
//! robot stops on an error.

use super::cell::KukaCell;
use toolpath::fixed;

/// The interrupt number (priority) of [`STOP_ROUTINE`]'s declaration: free for programs on a
/// KUKA controller (3 is the system's `IR_STOPM`, 40 to 80 are reserved).
pub const STOP_INTERRUPT: u32 = 10;

/// The local subroutine the interrupt on `$STOPMESS` calls: feed and extruder off, then
/// `BRAKE`.
pub const STOP_ROUTINE: &str = "EXTRUDER_STOP";

/// The timer the ready handshake times its wait with: `$TIMER[READY_TIMER]`.
pub const READY_TIMER: u32 = 1;

/// The lines of the ready handshake (with `ready_input` set): wait for `$IN[n]` at most
/// `ready_timeout` seconds (timed by `$TIMER[`[`READY_TIMER`]`]`); if it is not on by then,
/// `HALT` (the operator's start goes on), then wait for it without a limit.
pub(super) fn ready_lines(cell: &KukaCell) -> Vec<String> {
    let Some(n) = cell.ready_input else {
        return vec![];
    };
    let t = READY_TIMER;
    let s = fixed(cell.ready_timeout, 0);
    let ms = (cell.ready_timeout * 1000.0).round();
    vec![
        format!("; wait for the extruder's ready signal $IN[{n}], at most {s} s ($TIMER[{t}])"),
        format!("$TIMER[{t}] = 0"),
        format!("$TIMER_STOP[{t}] = FALSE"),
        format!("WAIT FOR $IN[{n}] OR ($TIMER[{t}] >= {ms:.0})"),
        format!("$TIMER_STOP[{t}] = TRUE"),
        format!("IF NOT $IN[{n}] THEN"),
        format!("  ; not ready after {s} s: check the extruder; start again to wait for $IN[{n}]"),
        "  HALT".into(),
        format!("  WAIT FOR $IN[{n}]"),
        "ENDIF".into(),
    ]
}

/// The outputs reset: the feed's analog output to 0 and the extruder's output off.
pub(super) fn reset_lines(cell: &KukaCell) -> [String; 2] {
    [
        format!("$ANOUT[{}] = 0", cell.feed_output),
        format!("$OUT[{}] = FALSE", cell.extruder_output),
    ]
}

/// The INI's fold declaring the interrupt on `$STOPMESS` that calls [`STOP_ROUTINE`], and
/// switching it on.
pub(super) fn interrupt_lines() -> Vec<String> {
    vec![
        "  ;FOLD EXTRUDER STOP".into(),
        format!("  INTERRUPT DECL {STOP_INTERRUPT} WHEN $STOPMESS==TRUE DO {STOP_ROUTINE}( )"),
        format!("  INTERRUPT ON {STOP_INTERRUPT}"),
        "  ;ENDFOLD (EXTRUDER STOP)".into(),
    ]
}

/// The local subroutine [`STOP_ROUTINE`], after the main program's `END`.
pub(super) fn stop_routine(cell: &KukaCell) -> Vec<String> {
    let mut lines = vec![
        String::new(),
        format!("DEF {STOP_ROUTINE}( )"),
        "; the robot stopped on an error ($STOPMESS): feed and extruder off, then brake".into(),
    ];
    lines.extend(reset_lines(cell));
    lines.extend(["BRAKE".into(), "END".into()]);
    lines
}
