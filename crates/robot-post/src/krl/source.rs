//! The files of a KRL program as text: modules, their statements and comments, folds, and
//! the `.dat` declarations.

use super::values::{aggregate, assumed_frame, parse_offset, AXIS_KEYS};
use super::{err, KrlError};
use std::collections::BTreeMap;

/// One statement of a module's body.
#[derive(Debug, Clone)]
pub(super) struct Statement {
    pub(super) line: usize,
    pub(super) text: String,
    pub(super) note: Option<String>,
}

#[derive(Debug, Default)]
pub(super) struct Module {
    pub(super) src_file: String,
    pub(super) body: Vec<Statement>,
    /// `DECL AXIS` of the `.dat`, by lower-case name.
    pub(super) axes: BTreeMap<String, [f64; 6]>,
    pub(super) offset: Option<[f64; 3]>,
    /// The frames the comments `; assumed BASE_DATA[n] = {..}` (`TOOL_DATA`) state, by
    /// (`BASE` or `TOOL`, n).
    pub(super) assumed: BTreeMap<(String, u32), [f64; 6]>,
    /// Local subroutines after the module's `END`, by upper-case name: their statements.
    pub(super) locals: BTreeMap<String, Vec<Statement>>,
}

/// The lower-case callee of a call statement `name( )`, if it is one.
pub(super) fn call_name(s: &str) -> Option<String> {
    let open = s.find('(')?;
    let name = s[..open].trim();
    let args = s[open..].trim();
    let ident = !name.is_empty()
        && name.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    (ident && args.replace(' ', "") == "()").then(|| name.to_ascii_lowercase())
}

/// Splits a line into its statement and comment, and tracks folds.
pub(super) fn split_comment(line: &str) -> (&str, Option<&str>) {
    match line.find(';') {
        Some(i) => (line[..i].trim(), Some(line[i + 1..].trim())),
        None => (line.trim(), None),
    }
}

/// Fold depth after `comment` (a `;FOLD` opens, a `;ENDFOLD` closes).
pub(super) fn fold(
    file: &str,
    line: usize,
    comment: Option<&str>,
    depth: &mut usize,
) -> Result<(), KrlError> {
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

pub(super) fn read_src(file: &str, stem: &str, text: &str) -> Result<Module, KrlError> {
    let mut module = Module {
        src_file: file.to_string(),
        ..Module::default()
    };
    let mut depth = 0;
    // 0 before DEF, 1 in the body, 2 after END, 3 in a local subroutine.
    let mut state = 0;
    let mut local: Option<String> = None;
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
            1 | 3 if upper == "END" => state = 2,
            1 | 3 if upper.starts_with("DEF ") || upper.starts_with("DEFDAT ") => {
                return Err(err(file, line, "a second DEF before END"));
            }
            1 => module.body.push(Statement {
                line,
                text: stmt.to_string(),
                note: comment.filter(|c| !c.is_empty()).map(str::to_string),
            }),
            3 => {
                if let Some(body) = local.as_ref().and_then(|n| module.locals.get_mut(n)) {
                    body.push(Statement {
                        line,
                        text: stmt.to_string(),
                        note: None,
                    });
                }
            }
            // A local subroutine after the module's END.
            2 if upper.starts_with("DEF ") => {
                let name = upper
                    .strip_prefix("DEF ")
                    .and_then(call_name)
                    .ok_or_else(|| err(file, line, format!("`{stmt}` is not `DEF name( )`")))?
                    .to_ascii_uppercase();
                if name.eq_ignore_ascii_case(stem) || module.locals.contains_key(&name) {
                    return Err(err(file, line, format!("`{name}` defined twice")));
                }
                module.locals.insert(name.clone(), vec![]);
                local = Some(name);
                state = 3;
            }
            _ => return Err(err(file, line, format!("`{stmt}` after END"))),
        }
    }
    ended(file, state, depth, "DEF", "END")?;
    Ok(module)
}

pub(super) fn read_dat(
    file: &str,
    stem: &str,
    text: &str,
) -> Result<BTreeMap<String, [f64; 6]>, KrlError> {
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
pub(super) fn ended(
    file: &str,
    state: u8,
    depth: usize,
    open: &str,
    close: &str,
) -> Result<(), KrlError> {
    match state {
        0 => Err(err(file, 0, format!("no {open}"))),
        1 | 3 => Err(err(file, 0, format!("{open} without {close}"))),
        _ if depth != 0 => Err(err(file, 0, format!("{depth} ;FOLD without ;ENDFOLD"))),
        _ => Ok(()),
    }
}
