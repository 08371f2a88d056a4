//! Part 21 text: reals, strings, lists, knot runs and line wrapping.

/// A full knot vector as STEP's (multiplicities, distinct knots) lists.
pub(super) fn knot_runs(knots: &[f64]) -> (String, String) {
    let mut distinct: Vec<f64> = vec![];
    let mut mults: Vec<usize> = vec![];
    for &k in knots {
        match distinct.last() {
            Some(&last) if last == k => *mults.last_mut().unwrap() += 1,
            _ => {
                distinct.push(k);
                mults.push(1);
            }
        }
    }
    let m: Vec<String> = mults.iter().map(|m| m.to_string()).collect();
    (format!("({})", m.join(",")), real_list(&distinct))
}

pub(super) fn ref_list(ids: &[u64]) -> String {
    let v: Vec<String> = ids.iter().map(|i| format!("#{i}")).collect();
    format!("({})", v.join(","))
}

pub(super) fn real_list(xs: &[f64]) -> String {
    let v: Vec<String> = xs.iter().map(|&x| real(x)).collect();
    format!("({})", v.join(","))
}

pub(super) fn logical(b: bool) -> &'static str {
    if b {
        ".T."
    } else {
        ".F."
    }
}

/// A Part 21 real: always a decimal point, an `E±XX` exponent for very small or large
/// magnitudes, and the shortest digits that read back as the same `f64`. Non-finite values
/// (which a valid B-rep never holds) are written as `0.`.
pub fn real(x: f64) -> String {
    if !x.is_finite() || x == 0.0 {
        return "0.".into();
    }
    let a = x.abs();
    if (1e-4..1e15).contains(&a) {
        // Display gives the shortest round-trip digits without an exponent.
        let mut s = format!("{x}");
        if !s.contains('.') {
            s.push('.');
        }
        return s;
    }
    // LowerExp gives the shortest round-trip digits as `d[.ddd]e[-]x`.
    let s = format!("{x:e}");
    let (mant, exp) = s.split_once('e').expect("LowerExp has an exponent");
    let exp: i32 = exp.parse().expect("integer exponent");
    let mut m = mant.to_string();
    if !m.contains('.') {
        m.push('.');
    }
    format!("{m}E{}{:02}", if exp < 0 { '-' } else { '+' }, exp.abs())
}

/// A Part 21 string literal, quotes included: `'` and `\` doubled, characters outside printable
/// ASCII in `\X2\…\X0\` (UTF-16) form.
pub fn string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('\'');
    let mut wide: Vec<u16> = vec![];
    let flush = |wide: &mut Vec<u16>, out: &mut String| {
        if !wide.is_empty() {
            out.push_str("\\X2\\");
            for u in wide.drain(..) {
                out.push_str(&format!("{u:04X}"));
            }
            out.push_str("\\X0\\");
        }
    };
    for ch in s.chars() {
        if (' '..='~').contains(&ch) {
            flush(&mut wide, &mut out);
            match ch {
                '\'' => out.push_str("''"),
                '\\' => out.push_str("\\\\"),
                c => out.push(c),
            }
        } else {
            let mut buf = [0u16; 2];
            wide.extend_from_slice(ch.encode_utf16(&mut buf));
        }
    }
    flush(&mut wide, &mut out);
    out.push('\'');
    out
}

/// Breaks a long entity or header line after commas (outside strings) so that lines stay near
/// 80 characters; a line always ends with `\n`.
pub(super) fn wrap(s: &str) -> String {
    const WIDTH: usize = 76;
    if s.len() <= WIDTH {
        return format!("{s}\n");
    }
    let mut out = String::with_capacity(s.len() + s.len() / 32);
    let mut col = 0;
    let mut in_string = false;
    for ch in s.chars() {
        out.push(ch);
        col += 1;
        if ch == '\'' {
            in_string = !in_string;
        }
        if ch == ',' && !in_string && col >= WIDTH - 12 {
            out.push_str("\n  ");
            col = 2;
        }
    }
    out.push('\n');
    out
}
