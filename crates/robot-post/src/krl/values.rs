//! The values a KRL statement holds: aggregates (frames, POS with Status and Turn, axes),
//! output assignments, inputs, and the comments the post states values in.

/// `$IN[n]` → n.
pub(super) fn input(s: &str) -> Option<u32> {
    s.trim()
        .strip_prefix("$IN[")?
        .strip_suffix(']')?
        .parse()
        .ok()
}

/// `X1.5 Y-2 Z3` → `[1.5, -2, 3]`.
pub(super) fn parse_offset(s: &str) -> Option<[f64; 3]> {
    let mut v = [0.0; 3];
    let mut words = s.split_whitespace();
    for (k, letter) in ["X", "Y", "Z"].iter().enumerate() {
        v[k] = words.next()?.strip_prefix(letter)?.parse().ok()?;
    }
    Some(v)
}

/// `BASE_DATA[n] = {X .., ...} (...)` → `(("BASE", n), frame)`.
pub(super) fn assumed_frame(s: &str) -> Result<((String, u32), [f64; 6]), String> {
    let bad = || format!("`assumed {s}` is not `assumed BASE_DATA[n] = {{..}}`");
    let (what, rest) = s.split_once("_DATA[").ok_or_else(bad)?;
    let (n, rest) = rest.split_once(']').ok_or_else(bad)?;
    let n: u32 = n.trim().parse().map_err(|_| bad())?;
    let rest = rest.trim().strip_prefix('=').ok_or_else(bad)?.trim();
    let close = rest.find('}').ok_or_else(bad)?;
    let frame = aggregate(&rest[..=close].to_ascii_uppercase(), &FRAME_KEYS)?;
    Ok(((what.trim().to_ascii_uppercase(), n), frame))
}

pub(super) const FRAME_KEYS: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];
pub(super) const AXIS_KEYS: [&str; 6] = ["A1", "A2", "A3", "A4", "A5", "A6"];

/// The components `K v` of a KRL aggregate `{K v, K v, ...}` (upper case), in order.
pub(super) fn components(s: &str) -> Result<Vec<(&str, &str)>, String> {
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
pub(super) fn aggregate(s: &str, keys: &[&str; 6]) -> Result<[f64; 6], String> {
    let (v, st) = pos_aggregate(s, keys)?;
    match st {
        None => Ok(v),
        Some(_) => Err(format!("unexpected component `S` or `T` in {s}")),
    }
}

/// An aggregate's six numbers, with the Status and Turn when given.
pub(super) type Pos = ([f64; 6], Option<(u8, u8)>);

/// A KRL aggregate with exactly `keys`, each once, and optionally the Status `S` and Turn `T`
/// of a POS (both or neither, as binary `'B..'` or decimal integers of 3 and 6 bits).
pub(super) fn pos_aggregate(s: &str, keys: &[&str; 6]) -> Result<Pos, String> {
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
pub(super) fn output_assignment(s: &str) -> Option<(u32, bool)> {
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
pub(super) fn analog_assignment(s: &str) -> Option<(u32, Result<f64, String>)> {
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
