//! The cursor over the raw bytes and its tokens: whitespace and comments, keywords,
//! enumerations, numbers, strings (with their escapes) and binaries.

use super::model::{P21Error, Param};

/// Cursor over the input. Invariant: `pos <= b.len()`.
pub(super) struct Parser<'a> {
    pub(super) b: &'a [u8],
    pub(super) pos: usize,
    /// 1-based line of `b[pos]`.
    pub(super) line: u32,
    /// Id of the entity being parsed, for error messages.
    pub(super) entity: Option<u64>,
    /// Parameters of the lists being parsed, innermost last: each list is
    /// moved out in one exact-size allocation when it closes.
    pub(super) scratch: Vec<Param>,
}

#[inline]
pub(super) fn is_kw_start(c: u8) -> bool {
    c.is_ascii_alphabetic() || c == b'_' || c == b'!'
}

/// Bytes allowed after the first character of a keyword: `A-Z a-z 0-9 _`.
static KW_CHAR: [bool; 256] = {
    let mut t = [false; 256];
    let mut c = 0;
    while c < 256 {
        let b = c as u8;
        t[c] = b.is_ascii_alphanumeric() || b == b'_';
        c += 1;
    }
    t
};

#[inline]
pub(super) fn is_kw_char(c: u8) -> bool {
    KW_CHAR[usize::from(c)]
}

/// An ASCII keyword slice as an upper-case `String`.
pub(super) fn upper(s: &[u8]) -> String {
    let mut v = s.to_vec();
    v.make_ascii_uppercase();
    // Callers pass ASCII-only slices, so this never falls back.
    String::from_utf8(v).unwrap_or_default()
}

/// Exact powers of ten representable in an f64.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Describe an unexpected byte for a message, without quoting letters.
pub(super) fn describe(c: u8) -> String {
    match c {
        b'\'' => "a quote".to_string(),
        0x21..=0x7e if !c.is_ascii_alphanumeric() => format!("'{}'", char::from(c)),
        b'0'..=b'9' => "a digit".to_string(),
        b'a'..=b'z' | b'A'..=b'Z' => "a letter".to_string(),
        _ => format!("byte 0x{c:02x}"),
    }
}

impl<'a> Parser<'a> {
    #[inline]
    pub(super) fn peek(&self) -> Option<u8> {
        self.b.get(self.pos).copied()
    }

    #[inline]
    pub(super) fn slice(&self, start: usize, end: usize) -> &'a [u8] {
        self.b.get(start..end).unwrap_or(&[])
    }

    pub(super) fn newline(&mut self) {
        self.line = self.line.saturating_add(1);
    }

    pub(super) fn truncated(&self) -> P21Error {
        P21Error::Truncated { line: self.line }
    }

    pub(super) fn too_deep(&self) -> P21Error {
        P21Error::TooDeep { line: self.line }
    }

    /// A syntax error; names the current entity if there is one.
    pub(super) fn syntax(&self, msg: &str) -> P21Error {
        let msg = match self.entity {
            Some(id) => format!("{msg} in entity #{id}"),
            None => msg.to_string(),
        };
        P21Error::Syntax {
            line: self.line,
            msg,
        }
    }

    /// Truncated at end of input, otherwise a syntax error `msg`.
    pub(super) fn unexpected(&self, msg: &str) -> P21Error {
        match self.peek() {
            None => self.truncated(),
            Some(_) => self.syntax(msg),
        }
    }

    /// Skip whitespace and comments.
    #[inline]
    pub(super) fn skip_ws(&mut self) -> Result<(), P21Error> {
        // Fast exit: most tokens are not preceded by whitespace.
        match self.b.get(self.pos) {
            Some(b' ' | b'\t' | b'\r' | b'\n' | 0x0b | 0x0c | b'/') => {}
            _ => return Ok(()),
        }
        let b = self.b;
        let mut i = self.pos;
        loop {
            match b.get(i) {
                Some(b' ' | b'\t' | b'\r' | 0x0b | 0x0c) => i += 1,
                Some(b'\n') => {
                    i += 1;
                    self.newline();
                }
                Some(b'/') if b.get(i + 1) == Some(&b'*') => {
                    self.pos = i;
                    self.skip_comment()?;
                    i = self.pos;
                }
                // A lone '/' as the very last byte may be a cut-off comment.
                Some(b'/') if i + 1 == b.len() => {
                    self.pos = i;
                    return Err(self.truncated());
                }
                _ => {
                    self.pos = i;
                    return Ok(());
                }
            }
        }
    }

    /// Skip a `/* ... */` comment starting at `pos`.
    pub(super) fn skip_comment(&mut self) -> Result<(), P21Error> {
        let mut i = self.pos + 2;
        loop {
            match self.b.get(i) {
                None => {
                    self.pos = self.b.len();
                    return Err(self.truncated());
                }
                Some(b'*') if self.b.get(i + 1) == Some(&b'/') => {
                    self.pos = i + 2;
                    return Ok(());
                }
                Some(b'\n') => {
                    self.newline();
                    i += 1;
                }
                Some(_) => i += 1,
            }
        }
    }

    /// Skip whitespace, then consume `c` or fail with `msg`.
    pub(super) fn expect(&mut self, c: u8, msg: &str) -> Result<(), P21Error> {
        self.skip_ws()?;
        if self.peek() == Some(c) {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.unexpected(msg))
        }
    }

    /// A section-level word such as `ISO-10303-21`, `DATA`, `ENDSEC`.
    pub(super) fn word(&mut self) -> &'a [u8] {
        let start = self.pos;
        while let Some(&c) = self.b.get(self.pos) {
            if is_kw_char(c) || c == b'-' {
                self.pos += 1;
            } else {
                break;
            }
        }
        self.slice(start, self.pos)
    }

    /// An entity or type keyword, optionally `!`-prefixed (user-defined).
    pub(super) fn keyword(&mut self) -> Result<&'a [u8], P21Error> {
        let start = self.pos;
        if self.peek() == Some(b'!') {
            self.pos += 1;
        }
        let body = self.pos;
        let rest = self.b.get(body..).unwrap_or(&[]);
        self.pos = body
            + rest
                .iter()
                .position(|&c| !is_kw_char(c))
                .unwrap_or(rest.len());
        if self.pos == body {
            return Err(self.unexpected("expected a keyword after '!'"));
        }
        Ok(self.slice(start, self.pos))
    }

    /// `.NAME.` starting at the first dot.
    pub(super) fn enumeration(&mut self) -> Result<String, P21Error> {
        self.pos += 1;
        let start = self.pos;
        match self.peek() {
            Some(c) if c.is_ascii_alphabetic() || c == b'_' => {}
            Some(c) if c.is_ascii_digit() => {
                return Err(self.syntax("a real needs a digit before its decimal point"))
            }
            _ => return Err(self.unexpected("expected enumeration name after '.'")),
        }
        while let Some(&c) = self.b.get(self.pos) {
            if is_kw_char(c) {
                self.pos += 1;
            } else {
                break;
            }
        }
        let name = self.slice(start, self.pos);
        if self.peek() != Some(b'.') {
            return Err(self.unexpected("expected '.' after enumeration name"));
        }
        self.pos += 1;
        Ok(upper(name))
    }

    /// An integer or a real, in one scan that also accumulates the
    /// significant digits and the decimal exponent.
    ///
    /// Reals whose significant digits fit in 53 bits and whose decimal
    /// exponent is within ±22 are converted exactly by one correctly rounded
    /// multiplication or division (Clinger's fast path); all others go to the
    /// standard library's general algorithm.
    pub(super) fn number(&mut self) -> Result<Param, P21Error> {
        const LIMIT: u64 = 1 << 53;
        let b = self.b;
        let start = self.pos;
        let mut i = start;
        let neg = match b.get(i) {
            Some(b'-') => {
                i += 1;
                true
            }
            Some(b'+') => {
                i += 1;
                false
            }
            _ => false,
        };
        // m holds the digits from the first non-zero one; it is exact while
        // nsig <= 19.
        let mut m: u64 = 0;
        let mut nsig: u32 = 0;
        let int_start = i;
        while let Some(&c) = b.get(i) {
            let d = c.wrapping_sub(b'0');
            if d > 9 {
                break;
            }
            m = m.wrapping_mul(10).wrapping_add(u64::from(d));
            nsig = nsig.saturating_add(u32::from(m != 0));
            i += 1;
        }
        if i == int_start {
            self.pos = i;
            return Err(self.unexpected("expected digits after sign"));
        }
        let mut real = false;
        let mut exp: i64 = 0;
        if b.get(i) == Some(&b'.') {
            real = true;
            i += 1;
            while let Some(&c) = b.get(i) {
                let d = c.wrapping_sub(b'0');
                if d > 9 {
                    break;
                }
                m = m.wrapping_mul(10).wrapping_add(u64::from(d));
                nsig = nsig.saturating_add(u32::from(m != 0));
                exp -= 1;
                i += 1;
            }
        }
        if let Some(b'E' | b'e') = b.get(i) {
            real = true;
            i += 1;
            let eneg = match b.get(i) {
                Some(b'-') => {
                    i += 1;
                    true
                }
                Some(b'+') => {
                    i += 1;
                    false
                }
                _ => false,
            };
            let exp_start = i;
            let mut e: i64 = 0;
            while let Some(&c) = b.get(i) {
                let d = c.wrapping_sub(b'0');
                if d > 9 {
                    break;
                }
                e = (e * 10 + i64::from(d)).min(1_000_000); // saturate: out of fast range anyway
                i += 1;
            }
            if i == exp_start {
                self.pos = i;
                return Err(self.unexpected("expected digits in exponent of real"));
            }
            exp += if eneg { -e } else { e };
        }
        self.pos = i;
        if real {
            if nsig <= 19 {
                // Trailing zeros (common in 20-digit writers) cost no precision.
                // `is_multiple_of` needs Rust 1.87; the workspace MSRV is 1.85.
                #[allow(clippy::manual_is_multiple_of)]
                while m >= LIMIT && m % 10 == 0 {
                    m /= 10;
                    exp += 1;
                }
                if m < LIMIT && (-22..=22).contains(&exp) {
                    let v = if m == 0 {
                        0.0
                    } else if exp >= 0 {
                        m as f64 * POW10[exp as usize]
                    } else {
                        m as f64 / POW10[(-exp) as usize]
                    };
                    return Ok(Param::Real(if neg { -v } else { v }));
                }
            }
            std::str::from_utf8(self.slice(start, i))
                .ok()
                .and_then(|t| t.parse::<f64>().ok())
                .map(Param::Real)
                .ok_or_else(|| self.syntax("invalid real"))
        } else if nsig <= 18 {
            // Below 10^18: no overflow possible.
            let v = m as i64;
            Ok(Param::Int(if neg { -v } else { v }))
        } else {
            std::str::from_utf8(self.slice(start, i))
                .ok()
                .and_then(|t| t.parse::<i64>().ok())
                .map(Param::Int)
                .ok_or_else(|| self.syntax("integer does not fit in 64 bits"))
        }
    }

    /// A quoted string starting at its opening quote.
    pub(super) fn string(&mut self) -> Result<String, P21Error> {
        let start = self.pos + 1;
        let mut i = start;
        let mut plain = true;
        loop {
            match self.b.get(i) {
                None => {
                    self.pos = self.b.len();
                    return Err(self.truncated());
                }
                Some(b'\'') => {
                    if self.b.get(i + 1) == Some(&b'\'') {
                        plain = false;
                        i += 2;
                    } else {
                        break;
                    }
                }
                Some(b'\\' | b'\r') => {
                    plain = false;
                    i += 1;
                }
                Some(b'\n') => {
                    plain = false;
                    self.newline();
                    i += 1;
                }
                Some(_) => i += 1,
            }
        }
        let raw = self.slice(start, i);
        self.pos = i + 1;
        if plain {
            Ok(match std::str::from_utf8(raw) {
                Ok(s) => s.to_owned(),
                Err(_) => {
                    let mut s = String::with_capacity(raw.len() + raw.len() / 2);
                    push_lossy(&mut s, raw);
                    s
                }
            })
        } else {
            Ok(decode_string(raw))
        }
    }

    /// A binary `"hex"` starting at its opening quote; line breaks inside
    /// are ignored.
    pub(super) fn binary(&mut self) -> Result<String, P21Error> {
        let start = self.pos + 1;
        let mut i = start;
        let mut breaks = false;
        loop {
            match self.b.get(i) {
                None => {
                    self.pos = self.b.len();
                    return Err(self.truncated());
                }
                Some(b'"') => break,
                Some(c) if c.is_ascii_hexdigit() => i += 1,
                Some(b'\r') => {
                    breaks = true;
                    i += 1;
                }
                Some(b'\n') => {
                    breaks = true;
                    self.newline();
                    i += 1;
                }
                Some(_) => {
                    self.pos = i;
                    return Err(self.syntax("invalid character in binary"));
                }
            }
        }
        let raw = self.slice(start, i);
        self.pos = i + 1;
        let hex: String = if breaks {
            raw.iter()
                .filter(|c| c.is_ascii_hexdigit())
                .map(|&c| char::from(c))
                .collect()
        } else {
            String::from_utf8_lossy(raw).into_owned()
        };
        Ok(hex)
    }
}

/// Append `raw` to `out`: valid UTF-8 as is, every other byte as Latin-1.
fn push_lossy(out: &mut String, raw: &[u8]) {
    for chunk in raw.utf8_chunks() {
        out.push_str(chunk.valid());
        out.extend(chunk.invalid().iter().map(|&c| char::from(c)));
    }
}

/// Value of an ASCII hex digit.
fn hex_val(c: u8) -> Option<u32> {
    char::from(c).to_digit(16)
}

/// Read `n` hex digits at the start of `s`.
fn hex_at(s: &[u8], n: usize) -> Option<u32> {
    let digits = s.get(..n)?;
    digits
        .iter()
        .try_fold(0u32, |acc, &c| Some((acc << 4) | hex_val(c)?))
}

/// Decode string content (between the quotes) with `''`, control
/// directives and line breaks.
fn decode_string(raw: &[u8]) -> String {
    let filtered: Vec<u8>;
    let raw = if raw.iter().any(|&c| c == b'\n' || c == b'\r') {
        filtered = raw
            .iter()
            .copied()
            .filter(|&c| c != b'\n' && c != b'\r')
            .collect();
        &filtered[..]
    } else {
        raw
    };
    let mut out = String::with_capacity(raw.len());
    let mut run = 0; // start of the pending run of ordinary bytes
    let mut i = 0;
    while let Some(&c) = raw.get(i) {
        match c {
            b'\'' => {
                push_lossy(&mut out, raw.get(run..i).unwrap_or(&[]));
                out.push('\'');
                i += if raw.get(i + 1) == Some(&b'\'') { 2 } else { 1 };
                run = i;
            }
            b'\\' => {
                push_lossy(&mut out, raw.get(run..i).unwrap_or(&[]));
                i += directive(raw.get(i..).unwrap_or(&[]), &mut out);
                run = i;
            }
            _ => i += 1,
        }
    }
    push_lossy(&mut out, raw.get(run..).unwrap_or(&[]));
    out
}

/// Decode one control directive at the start of `s` (which starts with a
/// backslash) into `out`; returns the number of bytes consumed (at least 1).
/// Unknown or malformed directives are kept literally.
fn directive(s: &[u8], out: &mut String) -> usize {
    if s.get(1) == Some(&b'\\') {
        out.push('\\');
        return 2;
    }
    if s.starts_with(b"\\S\\") {
        match s.get(3) {
            // `\S\''`: the quote is doubled in the file.
            Some(b'\'') => {
                out.push(char::from(b'\'' | 0x80));
                return if s.get(4) == Some(&b'\'') { 5 } else { 4 };
            }
            Some(&c) if (0x20..0x7f).contains(&c) => {
                out.push(char::from(c | 0x80));
                return 4;
            }
            _ => {}
        }
    }
    if s.len() >= 4 && s[1] == b'P' && s[2].is_ascii_uppercase() && s[3] == b'\\' {
        // Code page switch: ignored, `\S\` is read as Latin-1 (best effort).
        return 4;
    }
    if s.starts_with(b"\\X\\") {
        if let Some(v) = hex_at(s.get(3..).unwrap_or(&[]), 2) {
            out.extend(char::from_u32(v));
            return 5;
        }
    }
    if s.starts_with(b"\\X2\\") {
        let mut i = 4;
        let mut units: Vec<u16> = Vec::new();
        while let Some(v) = hex_at(s.get(i..).unwrap_or(&[]), 4) {
            units.push(v as u16);
            i += 4;
        }
        if s.get(i..).is_some_and(|t| t.starts_with(b"\\X0\\")) {
            out.extend(
                char::decode_utf16(units.iter().copied())
                    .map(|r| r.unwrap_or(char::REPLACEMENT_CHARACTER)),
            );
            return i + 4;
        }
    }
    if s.starts_with(b"\\X4\\") {
        let mut i = 4;
        let mut chars = String::new();
        while let Some(v) = hex_at(s.get(i..).unwrap_or(&[]), 8) {
            chars.push(char::from_u32(v).unwrap_or(char::REPLACEMENT_CHARACTER));
            i += 8;
        }
        if s.get(i..).is_some_and(|t| t.starts_with(b"\\X0\\")) {
            out.push_str(&chars);
            return i + 4;
        }
    }
    out.push('\\');
    1
}
