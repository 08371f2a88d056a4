//! A fast, panic-free reader for ISO 10303-21 (STEP Part 21) exchange files.
//!
//! [`parse`] makes a single pass over the raw bytes and builds a [`P21File`]:
//! the HEADER records plus every entity instance of every DATA section, in
//! file order, with a by-id index. It does not interpret any schema; that is
//! the job of the layers above.
//!
//! Robustness guarantees, on any input whatsoever:
//! - no panic, and no stack overflow: parameter nesting is capped at
//!   [`MAX_DEPTH`] levels and reported as [`P21Error::TooDeep`];
//! - memory use is proportional to the input size;
//! - bytes that are not UTF-8 inside strings never cause an error: valid UTF-8
//!   runs are kept, every other byte is read as Latin-1.
//!
//! Tolerated beyond the letter of the standard, because real writers do it:
//! line breaks inside strings (dropped, since writers wrap long lines there),
//! lower-case keywords (upper-cased), a UTF-8 byte-order mark, reals without a
//! decimal point but with an exponent (`1E5`), and anything after
//! `END-ISO-10303-21;`. ANCHOR, REFERENCE and SIGNATURE sections are skipped.

mod lexer;
mod model;
mod parser;

pub use model::*;
pub use parser::parse;

#[cfg(test)]
// `is_multiple_of` needs Rust 1.87; the workspace MSRV is 1.85.
#[allow(clippy::manual_is_multiple_of)]
mod tests;
