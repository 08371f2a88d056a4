//! Fixed-point text of a number, as every program and `toolpath.csv` write it.
//!
//! The text is exactly Rust's `format!("{x:.d$}")` (the exact binary value rounded to `d`
//! decimals, a tie to the even last digit) with `-0` written `0`. For the decimals the programs
//! use (at most 9) and magnitudes under 2^63 / 10^9 it is computed in integers: `x = m·2^e`
//! exactly, so `x·10^d = m·10^d·2^e` with `m·10^d < 2^83`, shifted and rounded in `u128`.
//! That is the same number `format!` prints, at a fraction of its cost (the standard
//! formatter falls back to big-number arithmetic for many values); other inputs take
//! `format!` itself.

/// `x` in fixed-point with `decimals` places: never exponent notation, never `-0`.
pub fn fixed(x: f64, decimals: usize) -> String {
    let mut s = String::new();
    push_fixed(&mut s, x, decimals);
    s
}

/// Appends [`fixed`]`(x, decimals)` to `out` without a new allocation.
pub fn push_fixed(out: &mut String, x: f64, decimals: usize) {
    match scaled(x, decimals) {
        Some((negative, n)) => push_scaled(out, negative, n, decimals),
        None => push_formatted(out, x, decimals),
    }
}

/// The largest decimals and magnitude taken in integers.
const MAX_DECIMALS: usize = 9;
const MAX_MAGNITUDE: f64 = 9.0e9;

/// `(sign, round(|x|·10^decimals))`, rounded half to even, where the integer path applies.
fn scaled(x: f64, decimals: usize) -> Option<(bool, u64)> {
    if decimals > MAX_DECIMALS || !x.is_finite() || x.abs() >= MAX_MAGNITUDE {
        return None;
    }
    let bits = x.to_bits();
    let negative = bits >> 63 == 1;
    let biased = ((bits >> 52) & 0x7ff) as i32;
    let fraction = bits & ((1u64 << 52) - 1);
    // x = m · 2^e exactly.
    let (m, e) = if biased == 0 {
        (fraction, -1074)
    } else {
        (fraction | (1u64 << 52), biased - 1075)
    };
    let n = m as u128 * 10u128.pow(decimals as u32);
    let q = if e >= 0 {
        // |x| < 9e9 < 2^34 and m ≥ 2^52 for a normal number, so e ≤ 0 except for
        // integers, whose shift stays far inside u128.
        n << e
    } else {
        let s = (-e) as u32;
        if s >= 127 {
            // Below 2^-74 · 10^9: rounds to zero (far from a half).
            0
        } else {
            let q = n >> s;
            let r = n & ((1u128 << s) - 1);
            let half = 1u128 << (s - 1);
            if r > half || (r == half && q & 1 == 1) {
                q + 1
            } else {
                q
            }
        }
    };
    // Below 9e9 · 10^9 < 2^64: the digits are made in 64 bits (a 128-bit division by ten is
    // a library call).
    u64::try_from(q).ok().map(|q| (negative, q))
}

/// Writes the integer `n` as a fixed-point number with `decimals` places (at most
/// [`MAX_SCALED_DECIMALS`]), `-` before it when `negative` and `n` is not 0: `n = 7, decimals
/// = 5` is `0.00007`. For quantities kept in integer units (a program's E, in 0.00001 mm).
pub fn push_scaled(out: &mut String, negative: bool, n: u64, decimals: usize) {
    let mut text = Text::new();
    // ASCII digits, a point and a sign: always UTF-8.
    out.push_str(std::str::from_utf8(text.scaled(negative, n, decimals)).unwrap_or_default());
}

/// [`push_fixed`] onto bytes (a block of `toolpath.csv`'s lines, written out as bytes):
/// the same text, without a UTF-8 check per number.
pub fn push_fixed_bytes(out: &mut Vec<u8>, x: f64, decimals: usize) {
    match scaled(x, decimals) {
        Some((negative, n)) => out.extend_from_slice(Text::new().scaled(negative, n, decimals)),
        None => {
            let mut s = String::new();
            push_formatted(&mut s, x, decimals);
            out.extend_from_slice(s.as_bytes());
        }
    }
}

/// The decimal digits of `n` onto bytes (an id in `toolpath.csv`).
pub fn push_integer_bytes(out: &mut Vec<u8>, n: u64) {
    out.extend_from_slice(Text::new().scaled(false, n, 0));
}

/// The most decimals [`push_scaled`] writes (more are taken as this many).
pub const MAX_SCALED_DECIMALS: usize = 40;

/// "00" to "99": two digits at a time.
const PAIRS: &[u8; 200] = b"\
0001020304050607080910111213141516171819\
2021222324252627282930313233343536373839\
4041424344454647484950515253545556575859\
6061626364656667686970717273747576777879\
8081828384858687888990919293949596979899";

/// A number's text made from its last digit back (20 digits of a `u64`, a point, up to
/// [`MAX_SCALED_DECIMALS`] decimals and a sign fit).
struct Text([u8; 64]);

impl Text {
    fn new() -> Self {
        Text([0; 64])
    }

    /// Puts one digit before `end`.
    fn digit(&mut self, end: &mut usize, d: u64) {
        *end -= 1;
        self.0[*end] = b'0' + d as u8;
    }

    /// Puts the two digits of `d` (below 100) before `end`.
    fn pair(&mut self, end: &mut usize, d: u64) {
        *end -= 2;
        let k = 2 * d as usize;
        self.0[*end..*end + 2].copy_from_slice(&PAIRS[k..k + 2]);
    }

    /// Writes [`push_scaled`]'s text at the end of the buffer, and gives it.
    fn scaled(&mut self, negative: bool, n: u64, decimals: usize) -> &[u8] {
        let decimals = decimals.min(MAX_SCALED_DECIMALS);
        let mut end = self.0.len();
        let mut v = n;
        // The decimals (zeros where `n` has run out), two at a time, then the point.
        for _ in 0..decimals / 2 {
            self.pair(&mut end, v % 100);
            v /= 100;
        }
        if decimals % 2 == 1 {
            self.digit(&mut end, v % 10);
            v /= 10;
        }
        if decimals > 0 {
            end -= 1;
            self.0[end] = b'.';
        }
        // The whole part: one digit at least.
        while v >= 100 {
            self.pair(&mut end, v % 100);
            v /= 100;
        }
        if v >= 10 {
            self.pair(&mut end, v);
        } else {
            self.digit(&mut end, v);
        }
        if negative && n != 0 {
            end -= 1;
            self.0[end] = b'-';
        }
        &self.0[end..]
    }
}

/// The standard formatter, with `-0` written `0`.
fn push_formatted(out: &mut String, x: f64, decimals: usize) {
    use std::fmt::Write as _;
    let start = out.len();
    // Writing to a String cannot fail.
    let _ = write!(out, "{x:.decimals$}");
    let written = &out.as_bytes()[start..];
    if written.first() == Some(&b'-') && written[1..].iter().all(|&b| b == b'0' || b == b'.') {
        out.remove(start);
    }
}

#[cfg(test)]
mod tests {
    use super::{
        fixed, push_fixed_bytes, push_formatted, push_integer_bytes, push_scaled,
        MAX_SCALED_DECIMALS,
    };

    fn reference(x: f64, d: usize) -> String {
        let mut s = String::new();
        push_formatted(&mut s, x, d);
        s
    }

    #[test]
    fn fixed_point_without_negative_zero_or_exponent() {
        assert_eq!(fixed(-0.0, 3), "0.000");
        assert_eq!(fixed(-0.0004, 3), "0.000");
        assert_eq!(fixed(-0.0005001, 3), "-0.001");
        assert_eq!(fixed(1e-12, 5), "0.00000");
        assert_eq!(fixed(1.5e21, 1), "1500000000000000000000.0");
        assert_eq!(fixed(2100.4, 0), "2100");
        assert_eq!(fixed(-0.4, 0), "0");
        assert_eq!(fixed(12.3456789, 6), "12.345679");
    }

    #[test]
    fn ties_go_to_the_even_digit_as_the_standard_formatter_does() {
        for (x, d) in [
            (0.5, 0),
            (1.5, 0),
            (2.5, 0),
            (-2.5, 0),
            (0.125, 2),
            (0.375, 2),
            (0.0625, 3),
            (-0.0625, 3),
            (1.0 / 1024.0, 9),
            (4.0e9 + 0.5, 0),
        ] {
            assert_eq!(fixed(x, d), reference(x, d), "{x} with {d} decimals");
        }
    }

    /// The integer path prints exactly what `format!` prints, over numbers of every scale
    /// (a fixed xorshift sequence of bit patterns and of decimal-looking values).
    #[test]
    fn same_text_as_the_standard_formatter() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for i in 0..100_000 {
            let r = next();
            let x = match i % 4 {
                // Any finite double.
                0 => f64::from_bits(r),
                // Magnitudes from 1e-12 to 1e10.
                1 => {
                    let m = (r >> 11) as f64 / (1u64 << 53) as f64;
                    let s = 10f64.powi((r % 23) as i32 - 12);
                    if r & 1 == 0 {
                        m * s
                    } else {
                        -m * s
                    }
                }
                // Values near a printed grid (what positions and extrusions look like).
                2 => ((r % 2_000_000_000) as f64 - 1e9) / 10f64.powi((r % 10) as i32),
                // Halves of the last printed digit, the hard cases.
                _ => ((r % 20_000_001) as f64 - 1e7 + 0.5) / 10f64.powi((r % 7) as i32),
            };
            if !x.is_finite() {
                continue;
            }
            for d in [0, 1, 2, 3, 4, 5, 6, 9, 12] {
                assert_eq!(fixed(x, d), reference(x, d), "{x:e} with {d} decimals");
            }
        }
    }

    /// An integer's digits with the point put `decimals` from the end: what `push_scaled`
    /// writes, made with the standard formatter.
    fn scaled_reference(negative: bool, n: u64, decimals: usize) -> String {
        let digits = format!("{n:0>width$}", width = decimals + 1);
        let (whole, part) = digits.split_at(digits.len() - decimals);
        let sign = if negative && n != 0 { "-" } else { "" };
        match decimals {
            0 => format!("{sign}{whole}"),
            _ => format!("{sign}{whole}.{part}"),
        }
    }

    /// Every count of decimals up to the most, over integers of every length (u64's largest
    /// among them), signed and not; the byte writers write the same text as the string ones.
    #[test]
    fn scaled_integers_and_bytes_match_the_standard_formatter() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut values = vec![0, 1, 9, 10, 99, 100, 101, u64::MAX, u64::MAX - 1];
        for _ in 0..2_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            values.push(state >> (state % 64));
        }
        for &n in &values {
            for decimals in 0..=MAX_SCALED_DECIMALS {
                for negative in [false, true] {
                    let mut out = String::from("x");
                    push_scaled(&mut out, negative, n, decimals);
                    assert_eq!(out[1..], scaled_reference(negative, n, decimals));
                }
            }
            let mut bytes = vec![];
            push_integer_bytes(&mut bytes, n);
            assert_eq!(bytes, n.to_string().as_bytes());
            let x = f64::from_bits(n);
            if x.is_finite() {
                for d in [0, 3, 6, 9, 12] {
                    let mut bytes = vec![];
                    push_fixed_bytes(&mut bytes, x, d);
                    assert_eq!(bytes, fixed(x, d).as_bytes(), "{x:e} with {d} decimals");
                }
            }
        }
    }
}
