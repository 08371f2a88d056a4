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

use std::collections::HashMap;

/// Deepest parameter nesting accepted. The parameter list of a record is
/// level 1; each nested list or typed parameter adds one level.
pub const MAX_DEPTH: u32 = 64;

/// One parameter value of a record.
#[derive(Debug, Clone, PartialEq)]
pub enum Param {
    /// An integer, e.g. `3` or `-12`.
    Int(i64),
    /// A real, e.g. `1.`, `-0.`, `1.E-05`.
    Real(f64),
    /// A string with quotes removed and Part 21 escapes decoded to UTF-8.
    Str(String),
    /// An enumeration value without its dots, e.g. `T` for `.T.`.
    Enum(String),
    /// An entity instance reference `#id`.
    Ref(u64),
    /// An aggregate `( ... )`, possibly empty.
    List(Vec<Param>),
    /// A typed parameter such as `LENGTH_MEASURE(2.)`: type name and value.
    Typed(String, Box<Param>),
    /// The unset value `$`.
    Null,
    /// The derived value `*`.
    Derived,
    /// A binary `"0F3"`: the hexadecimal digits between the quotes, the first
    /// one being the count of unused bits.
    Binary(String),
}

/// An entity name with its parameter list, e.g. `CARTESIAN_POINT('',(0.,0.,0.))`.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// The entity (type) name, upper case as written in a valid file.
    pub name: String,
    /// The parameters, in order.
    pub params: Vec<Param>,
}

/// The body of an entity instance.
#[derive(Debug, Clone, PartialEq)]
pub enum Instance {
    /// `#1=NAME(...);`
    Simple(Record),
    /// `#1=(A(...)B(...));`, an instance of a combination of entity types.
    Complex(Vec<Record>),
}

impl Instance {
    /// The record named `name` (ASCII case-insensitive): for a simple
    /// instance the record itself if its name matches, for a complex one the
    /// part with that name.
    pub fn record(&self, name: &str) -> Option<&Record> {
        self.records()
            .iter()
            .find(|r| r.name.eq_ignore_ascii_case(name))
    }

    /// The entity names of the instance: one for a simple instance, the
    /// parts in file order for a complex one.
    pub fn names(&self) -> Vec<&str> {
        self.records().iter().map(|r| r.name.as_str()).collect()
    }

    /// All records of the instance (one for a simple instance).
    fn records(&self) -> &[Record] {
        match self {
            Instance::Simple(r) => std::slice::from_ref(r),
            Instance::Complex(v) => v,
        }
    }
}

/// One entity instance of a DATA section.
#[derive(Debug, Clone, PartialEq)]
pub struct Entity {
    /// The instance name: `45` for `#45`.
    pub id: u64,
    /// The 1-based line on which `#id=` starts.
    pub line: u32,
    /// The instance body.
    pub instance: Instance,
}

/// A parsed exchange file.
#[derive(Debug, Clone)]
pub struct P21File {
    /// The HEADER section records (FILE_DESCRIPTION, FILE_NAME, FILE_SCHEMA, ...).
    pub header: Vec<Record>,
    /// The entities of all DATA sections, in file order.
    pub entities: Vec<Entity>,
    /// Instance id to position in `entities`, built while parsing.
    index: HashMap<u64, usize>,
}

impl P21File {
    /// The entity `#id`, if the file defines it. Uses the index built by
    /// [`parse`]; entities added to or moved in `entities` afterwards may not
    /// be found.
    pub fn get(&self, id: u64) -> Option<&Entity> {
        self.index
            .get(&id)
            .and_then(|&i| self.entities.get(i))
            .filter(|e| e.id == id)
    }

    /// The schema names listed by FILE_SCHEMA in the header, e.g.
    /// `AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }`. Empty if there is none.
    pub fn schemas(&self) -> Vec<String> {
        let mut out = Vec::new();
        for r in self.header.iter().filter(|r| r.name == "FILE_SCHEMA") {
            match r.params.first() {
                Some(Param::List(items)) => {
                    for p in items {
                        if let Param::Str(s) = p {
                            out.push(s.clone());
                        }
                    }
                }
                Some(Param::Str(s)) => out.push(s.clone()),
                _ => {}
            }
        }
        out
    }

    /// The first reference, in file order, to an instance the file does not
    /// define: `(id of the referring entity, missing id)`.
    pub fn first_dangling_ref(&self) -> Option<(u64, u64)> {
        // Explicit stack: no recursion, whatever the nesting.
        let mut stack: Vec<&Param> = Vec::new();
        for e in &self.entities {
            for r in e.instance.records() {
                stack.clear();
                stack.extend(r.params.iter().rev());
                while let Some(p) = stack.pop() {
                    match p {
                        Param::Ref(id) if !self.index.contains_key(id) => return Some((e.id, *id)),
                        Param::List(v) => stack.extend(v.iter().rev()),
                        Param::Typed(_, inner) => stack.push(inner),
                        _ => {}
                    }
                }
            }
        }
        None
    }
}

/// Why a file could not be parsed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum P21Error {
    /// Zero bytes, or only whitespace.
    #[error("empty file")]
    Empty,
    /// The file does not start (after whitespace and comments) with `ISO-10303-21;`.
    #[error("not a step part 21 file: it does not start with iso-10303-21")]
    NotPart21,
    /// Malformed content at `line`; `msg` is one line and names the entity.
    #[error("syntax error at line {line}: {msg}")]
    Syntax {
        /// 1-based line of the offending token.
        line: u32,
        /// What was expected or found, e.g. `expected ';' after entity #45`.
        msg: String,
    },
    /// The input ended inside a token, an entity or a section, or before
    /// `END-ISO-10303-21;`.
    #[error("file truncated at line {line}: input ended before end-iso-10303-21")]
    Truncated {
        /// 1-based line at which the input ended.
        line: u32,
    },
    /// Two instances share the same id.
    #[error("duplicate entity #{id} at line {line}")]
    DuplicateId {
        /// The repeated instance id.
        id: u64,
        /// 1-based line of the second definition.
        line: u32,
    },
    /// Parameter nesting deeper than [`MAX_DEPTH`].
    #[error("parameter nesting deeper than 64 levels at line {line}")]
    TooDeep {
        /// 1-based line where the limit was exceeded.
        line: u32,
    },
}

/// Parse a complete exchange file from raw bytes.
///
/// Returns every HEADER record and every entity of every DATA section.
/// Never panics; see the module documentation for what is tolerated.
pub fn parse(bytes: &[u8]) -> Result<P21File, P21Error> {
    if bytes
        .iter()
        .all(|&c| matches!(c, b' ' | b'\t' | b'\r' | b'\n' | 0x0b | 0x0c))
    {
        return Err(P21Error::Empty);
    }
    let mut p = Parser {
        b: bytes,
        pos: 0,
        line: 1,
        entity: None,
        scratch: Vec::new(),
    };
    if bytes.starts_with(b"\xEF\xBB\xBF") {
        p.pos = 3;
    }
    p.file()
}

/// Cursor over the input. Invariant: `pos <= b.len()`.
struct Parser<'a> {
    b: &'a [u8],
    pos: usize,
    /// 1-based line of `b[pos]`.
    line: u32,
    /// Id of the entity being parsed, for error messages.
    entity: Option<u64>,
    /// Parameters of the lists being parsed, innermost last: each list is
    /// moved out in one exact-size allocation when it closes.
    scratch: Vec<Param>,
}

#[inline]
fn is_kw_start(c: u8) -> bool {
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
fn is_kw_char(c: u8) -> bool {
    KW_CHAR[usize::from(c)]
}

/// An ASCII keyword slice as an upper-case `String`.
fn upper(s: &[u8]) -> String {
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
fn describe(c: u8) -> String {
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
    fn peek(&self) -> Option<u8> {
        self.b.get(self.pos).copied()
    }

    #[inline]
    fn slice(&self, start: usize, end: usize) -> &'a [u8] {
        self.b.get(start..end).unwrap_or(&[])
    }

    fn newline(&mut self) {
        self.line = self.line.saturating_add(1);
    }

    fn truncated(&self) -> P21Error {
        P21Error::Truncated { line: self.line }
    }

    fn too_deep(&self) -> P21Error {
        P21Error::TooDeep { line: self.line }
    }

    /// A syntax error; names the current entity if there is one.
    fn syntax(&self, msg: &str) -> P21Error {
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
    fn unexpected(&self, msg: &str) -> P21Error {
        match self.peek() {
            None => self.truncated(),
            Some(_) => self.syntax(msg),
        }
    }

    /// Skip whitespace and comments.
    #[inline]
    fn skip_ws(&mut self) -> Result<(), P21Error> {
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
    fn skip_comment(&mut self) -> Result<(), P21Error> {
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
    fn expect(&mut self, c: u8, msg: &str) -> Result<(), P21Error> {
        self.skip_ws()?;
        if self.peek() == Some(c) {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.unexpected(msg))
        }
    }

    /// A section-level word such as `ISO-10303-21`, `DATA`, `ENDSEC`.
    fn word(&mut self) -> &'a [u8] {
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
    fn keyword(&mut self) -> Result<&'a [u8], P21Error> {
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

    fn file(&mut self) -> Result<P21File, P21Error> {
        self.skip_ws()?;
        if !self.word().eq_ignore_ascii_case(b"ISO-10303-21") {
            return Err(P21Error::NotPart21);
        }
        self.expect(b';', "expected ';' after iso-10303-21")?;

        self.skip_ws()?;
        if !self.word().eq_ignore_ascii_case(b"HEADER") {
            return Err(self.unexpected("expected header section"));
        }
        self.expect(b';', "expected ';' after header")?;
        let header = self.header_records()?;

        // Real files average about 70 bytes per entity; the cap keeps a huge
        // file of mostly whitespace from reserving memory it never uses.
        let guess = (self.b.len() / 72).min(1 << 20);
        let mut entities = Vec::with_capacity(guess);
        let mut index = HashMap::with_capacity(guess);
        loop {
            self.skip_ws()?;
            let w = self.word();
            if w.eq_ignore_ascii_case(b"DATA") {
                self.skip_ws()?;
                if self.peek() == Some(b'(') {
                    self.pos += 1;
                    self.params(1)?; // data section name and schema: not kept
                }
                self.expect(b';', "expected ';' after data")?;
                self.data_section(&mut entities, &mut index)?;
            } else if w.eq_ignore_ascii_case(b"ANCHOR")
                || w.eq_ignore_ascii_case(b"REFERENCE")
                || w.eq_ignore_ascii_case(b"SIGNATURE")
            {
                self.skip_section()?;
            } else if w.eq_ignore_ascii_case(b"END-ISO-10303-21") {
                self.expect(b';', "expected ';' after end-iso-10303-21")?;
                break; // whatever follows is ignored
            } else {
                return Err(self.unexpected("expected data section or end-iso-10303-21"));
            }
        }
        Ok(P21File {
            header,
            entities,
            index,
        })
    }

    /// Header records up to and including `ENDSEC;`.
    fn header_records(&mut self) -> Result<Vec<Record>, P21Error> {
        let mut out = Vec::new();
        loop {
            self.skip_ws()?;
            match self.peek() {
                None => return Err(self.truncated()),
                Some(c) if is_kw_start(c) => {
                    let kw = self.keyword()?;
                    if kw.eq_ignore_ascii_case(b"ENDSEC") {
                        self.expect(b';', "expected ';' after endsec")?;
                        return Ok(out);
                    }
                    let rec = self.record_body(kw)?;
                    self.expect(b';', "expected ';' after header record")?;
                    out.push(rec);
                }
                Some(c) => {
                    return Err(self.syntax(&format!(
                        "expected header record or endsec, found {}",
                        describe(c)
                    )))
                }
            }
        }
    }

    /// `( params )` after a record name `kw` already consumed.
    fn record_body(&mut self, kw: &[u8]) -> Result<Record, P21Error> {
        self.expect(b'(', "expected '(' after entity name")?;
        let params = self.params(1)?;
        Ok(Record {
            name: upper(kw),
            params,
        })
    }

    /// Entities up to and including `ENDSEC;`.
    fn data_section(
        &mut self,
        entities: &mut Vec<Entity>,
        index: &mut HashMap<u64, usize>,
    ) -> Result<(), P21Error> {
        loop {
            self.skip_ws()?;
            match self.peek() {
                None => return Err(self.truncated()),
                Some(b'#') => {
                    let e = self.entity(entities.len(), index)?;
                    entities.push(e);
                }
                Some(c) if is_kw_start(c) => {
                    if self.word().eq_ignore_ascii_case(b"ENDSEC") {
                        self.expect(b';', "expected ';' after endsec")?;
                        return Ok(());
                    }
                    return Err(self.unexpected("expected '#' or endsec in data section"));
                }
                Some(c) => {
                    return Err(self.syntax(&format!(
                        "expected '#' or endsec in data section, found {}",
                        describe(c)
                    )))
                }
            }
        }
    }

    /// `#id = body ;` starting at `#`; registers the id at position `slot`.
    fn entity(&mut self, slot: usize, index: &mut HashMap<u64, usize>) -> Result<Entity, P21Error> {
        let line = self.line;
        self.pos += 1;
        let id = self.id()?;
        match index.entry(id) {
            std::collections::hash_map::Entry::Occupied(_) => {
                return Err(P21Error::DuplicateId { id, line })
            }
            std::collections::hash_map::Entry::Vacant(v) => {
                v.insert(slot);
            }
        }
        self.entity = Some(id);
        self.expect(b'=', "expected '=' after instance name")?;
        self.skip_ws()?;
        let instance = match self.peek() {
            Some(b'(') => {
                self.pos += 1;
                Instance::Complex(self.complex()?)
            }
            Some(c) if is_kw_start(c) => {
                let kw = self.keyword()?;
                Instance::Simple(self.record_body(kw)?)
            }
            _ => return Err(self.unexpected("expected entity name after '='")),
        };
        self.skip_ws()?;
        match self.peek() {
            Some(b';') => self.pos += 1,
            None => return Err(self.truncated()),
            Some(_) => {
                self.entity = None;
                return Err(self.syntax(&format!("expected ';' after entity #{id}")));
            }
        }
        self.entity = None;
        Ok(Entity { id, line, instance })
    }

    /// The records of a complex instance, after its `(`, through its `)`.
    fn complex(&mut self) -> Result<Vec<Record>, P21Error> {
        let mut out = Vec::new();
        loop {
            self.skip_ws()?;
            match self.peek() {
                None => return Err(self.truncated()),
                Some(b')') if !out.is_empty() => {
                    self.pos += 1;
                    return Ok(out);
                }
                Some(b')') => return Err(self.syntax("empty complex entity")),
                Some(c) if is_kw_start(c) => {
                    let kw = self.keyword()?;
                    out.push(self.record_body(kw)?);
                }
                Some(c) => {
                    return Err(self.syntax(&format!(
                        "expected entity name or ')' in complex entity, found {}",
                        describe(c)
                    )))
                }
            }
        }
    }

    /// Decimal digits of an instance id, right after `#`.
    fn id(&mut self) -> Result<u64, P21Error> {
        let start = self.pos;
        let mut i = start;
        let mut v: u64 = 0;
        let mut overflow = false;
        while let Some(&c) = self.b.get(i) {
            let d = c.wrapping_sub(b'0');
            if d > 9 {
                break;
            }
            match v.checked_mul(10).and_then(|x| x.checked_add(u64::from(d))) {
                Some(x) => v = x,
                None => overflow = true,
            }
            i += 1;
        }
        self.pos = i;
        if self.pos == start {
            return Err(self.unexpected("expected digits after '#'"));
        }
        if overflow {
            return Err(self.syntax("instance id does not fit in 64 bits"));
        }
        Ok(v)
    }

    /// A parameter list after its `(`, through its `)`, at nesting `depth`.
    fn params(&mut self, depth: u32) -> Result<Vec<Param>, P21Error> {
        if depth > MAX_DEPTH {
            return Err(self.too_deep());
        }
        self.skip_ws()?;
        if self.peek() == Some(b')') {
            self.pos += 1;
            return Ok(Vec::new());
        }
        let base = self.scratch.len();
        loop {
            let p = self.param(depth)?;
            self.scratch.push(p);
            self.skip_ws()?;
            match self.peek() {
                Some(b',') => self.pos += 1,
                Some(b')') => {
                    self.pos += 1;
                    return Ok(self.scratch.drain(base..).collect());
                }
                None => return Err(self.truncated()),
                Some(c) => {
                    return Err(self.syntax(&format!(
                        "expected ',' or ')' in parameter list, found {}",
                        describe(c)
                    )))
                }
            }
        }
    }

    /// One parameter, inside a list at nesting `depth`.
    fn param(&mut self, depth: u32) -> Result<Param, P21Error> {
        self.skip_ws()?;
        let Some(c) = self.peek() else {
            return Err(self.truncated());
        };
        match c {
            b'$' => {
                self.pos += 1;
                Ok(Param::Null)
            }
            b'*' => {
                self.pos += 1;
                Ok(Param::Derived)
            }
            b'\'' => self.string().map(Param::Str),
            b'"' => self.binary().map(Param::Binary),
            b'.' => self.enumeration().map(Param::Enum),
            b'#' => {
                self.pos += 1;
                self.id().map(Param::Ref)
            }
            b'(' => {
                self.pos += 1;
                self.params(depth + 1).map(Param::List)
            }
            b'+' | b'-' | b'0'..=b'9' => self.number(),
            c if is_kw_start(c) => {
                let kw = self.keyword()?;
                self.expect(b'(', "expected '(' after type name of typed parameter")?;
                if depth + 1 > MAX_DEPTH {
                    return Err(self.too_deep());
                }
                let inner = self.param(depth + 1)?;
                self.expect(b')', "expected ')' after typed parameter")?;
                Ok(Param::Typed(upper(kw), Box::new(inner)))
            }
            c => Err(self.syntax(&format!("expected a parameter, found {}", describe(c)))),
        }
    }

    /// `.NAME.` starting at the first dot.
    fn enumeration(&mut self) -> Result<String, P21Error> {
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
    fn number(&mut self) -> Result<Param, P21Error> {
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
    fn string(&mut self) -> Result<String, P21Error> {
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
    fn binary(&mut self) -> Result<String, P21Error> {
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

    /// Skip an ANCHOR, REFERENCE or SIGNATURE section through `ENDSEC;`.
    fn skip_section(&mut self) -> Result<(), P21Error> {
        self.expect(b';', "expected ';' after section keyword")?;
        loop {
            self.skip_ws()?;
            match self.peek() {
                None => return Err(self.truncated()),
                Some(b'\'') => {
                    self.string()?;
                }
                Some(b'"') => {
                    self.pos += 1;
                    loop {
                        match self.peek() {
                            None => return Err(self.truncated()),
                            Some(b'"') => {
                                self.pos += 1;
                                break;
                            }
                            Some(b'\n') => {
                                self.newline();
                                self.pos += 1;
                            }
                            Some(_) => self.pos += 1,
                        }
                    }
                }
                Some(c) if is_kw_char(c) => {
                    if self.word().eq_ignore_ascii_case(b"ENDSEC") {
                        return self.expect(b';', "expected ';' after endsec");
                    }
                }
                Some(_) => self.pos += 1,
            }
        }
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

#[cfg(test)]
// `is_multiple_of` needs Rust 1.87; the workspace MSRV is 1.85.
#[allow(clippy::manual_is_multiple_of)]
mod tests {
    use super::*;

    const HEADER: &str = "ISO-10303-21;\nHEADER;\n\
        FILE_DESCRIPTION(('test'),'2;1');\n\
        FILE_NAME('t.step','2024-01-01T00:00:00',(''),(''),'','','');\n\
        FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\n\
        ENDSEC;\n";

    /// A complete file whose DATA section holds `data`; data starts on line 8.
    fn wrap(data: &str) -> String {
        format!("{HEADER}DATA;\n{data}\nENDSEC;\nEND-ISO-10303-21;\n")
    }

    fn ok(data: &str) -> P21File {
        match parse(wrap(data).as_bytes()) {
            Ok(f) => f,
            Err(e) => panic!("parse failed: {e}\n{data}"),
        }
    }

    fn err(data: &str) -> P21Error {
        match parse(wrap(data).as_bytes()) {
            Ok(_) => panic!("parse unexpectedly succeeded:\n{data}"),
            Err(e) => e,
        }
    }

    /// Params of the simple entity `#id`.
    fn params(f: &P21File, id: u64) -> &[Param] {
        match &f.get(id).expect("entity").instance {
            Instance::Simple(r) => &r.params,
            Instance::Complex(_) => panic!("complex"),
        }
    }

    fn one(data: &str) -> Param {
        let f = ok(data);
        params(&f, f.entities[0].id)[0].clone()
    }

    fn s(x: &str) -> Param {
        Param::Str(x.to_string())
    }

    const SMALL: &str = "ISO-10303-21;
HEADER;
/* header comment */
FILE_DESCRIPTION(('small'),'2;1');
FILE_NAME('a.step','2024-01-01',('me'),(''),'x','y','');
FILE_SCHEMA(('CONFIG_CONTROL_DESIGN'));
ENDSEC;
DATA;
#1=CARTESIAN_POINT('',(0.,1.5,-2.E-3));
#2=DIRECTION('',(0.,0.,1.));
#3=(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.));
#4=PLANE_ANGLE_MEASURE_WITH_UNIT(PLANE_ANGLE_MEASURE(0.0174532925),#3);
#5=DRAUGHTING_MODEL('it''s \\X2\\00E9\\X0\\',(),#4);
#6=B_SPLINE_CURVE_WITH_KNOTS('',3,(#1,#1,#1,#1),.UNSPECIFIED.,.F.,.F.,(4,4),(0.,1.),.UNSPECIFIED.);
#7=SOMETHING(\"0F3\",((1,2),()),*);
ENDSEC;
END-ISO-10303-21;
";

    #[test]
    fn p21_small_file_parses() {
        let f = parse(SMALL.as_bytes()).expect("small file");
        assert_eq!(f.header.len(), 3);
        assert_eq!(f.header[0].name, "FILE_DESCRIPTION");
        assert_eq!(f.entities.len(), 7);
        assert_eq!(f.schemas(), vec!["CONFIG_CONTROL_DESIGN".to_string()]);
        assert_eq!(f.first_dangling_ref(), None);
        let e1 = f.get(1).expect("#1");
        assert_eq!(e1.line, 9);
        assert_eq!(
            params(&f, 1),
            &[
                s(""),
                Param::List(vec![Param::Real(0.), Param::Real(1.5), Param::Real(-2e-3)])
            ]
        );
        assert_eq!(params(&f, 5)[0], s("it's é"));
        assert_eq!(params(&f, 5)[1], Param::List(vec![]));
        assert_eq!(f.get(7).expect("#7").line, 15);
        assert!(f.get(8).is_none());
    }

    #[test]
    fn p21_empty_and_whitespace_only() {
        assert_eq!(parse(b"").unwrap_err(), P21Error::Empty);
        assert_eq!(parse(b" \r\n\t \n").unwrap_err(), P21Error::Empty);
    }

    #[test]
    fn p21_not_part21() {
        assert_eq!(
            parse(b"solid foo\nendsolid").unwrap_err(),
            P21Error::NotPart21
        );
        assert_eq!(parse(b"/* c */ HEADER;").unwrap_err(), P21Error::NotPart21);
        assert_eq!(parse(b"\x00\x01\x02").unwrap_err(), P21Error::NotPart21);
        // Leading comments and a byte-order mark are fine.
        let with_bom = [b"\xEF\xBB\xBF/* hi */ ".as_slice(), SMALL.as_bytes()].concat();
        assert!(parse(&with_bom).is_ok());
    }

    #[test]
    fn p21_comments_and_whitespace_everywhere() {
        let text = "/* lead */ ISO-10303-21 /* a */ ;\r\n\tHEADER /* b */;\r\n\
            FILE_DESCRIPTION /* c */ ( /* d */ ( 'x' /* e */ ) , '2;1' ) /* f */ ;\r\n\
            FILE_NAME('','',(''),(''),'','','');\r\n\
            FILE_SCHEMA((/* g */'AP214'));\r\n\
            ENDSEC /* h */ ;\r\n\
            DATA ;\r\n\
            /* before */ #1 /* i */ = /* j */ PLANE /* k */ ( '' , #2 /* l */ ) /* m */ ;\r\n\
            #2\t=\tAXIS2_PLACEMENT_3D('',#3,$,$)\t;\r\n\
            #3 = ( /* n */ NAMED_UNIT ( * ) /* o */ \r\n SI_UNIT ( $ , .METRE. ) /* p */ ) ;\r\n\
            ENDSEC;\r\n\
            END-ISO-10303-21;\r\n";
        let f = parse(text.as_bytes()).expect("comments");
        assert_eq!(f.header.len(), 3);
        assert_eq!(f.schemas(), vec!["AP214".to_string()]);
        assert_eq!(f.entities.len(), 3);
        assert_eq!(f.get(1).expect("#1").line, 8);
        assert_eq!(f.get(3).expect("#3").line, 10);
        assert_eq!(params(&f, 1), &[s(""), Param::Ref(2)]);
        assert_eq!(
            f.get(3).expect("#3").instance.names(),
            vec!["NAMED_UNIT", "SI_UNIT"]
        );
    }

    #[test]
    fn p21_strings_and_directives() {
        assert_eq!(one("#1=A('it''s');"), s("it's"));
        assert_eq!(one("#1=A('''');"), s("'"));
        assert_eq!(one("#1=A('');"), s(""));
        assert_eq!(one("#1=A('caf\\X2\\00E9\\X0\\');"), s("café"));
        assert_eq!(one("#1=A('\\X2\\00E900E8\\X0\\!');"), s("éè!"));
        // Surrogate pair in X2.
        assert_eq!(one("#1=A('\\X2\\D83DDE00\\X0\\');"), s("😀"));
        assert_eq!(one("#1=A('\\X4\\0001F600\\X0\\');"), s("😀"));
        assert_eq!(one("#1=A('caf\\X\\E9');"), s("café"));
        assert_eq!(one("#1=A('\\S\\i');"), s("é"));
        assert_eq!(one("#1=A('\\PA\\\\S\\i');"), s("é"));
        assert_eq!(one("#1=A('C:\\\\dir\\\\f.stp');"), s("C:\\dir\\f.stp"));
        // Unknown or malformed directives are kept literally.
        assert_eq!(one("#1=A('a\\Q\\b');"), s("a\\Q\\b"));
        assert_eq!(one("#1=A('\\X2\\00E');"), s("\\X2\\00E"));
        assert_eq!(one("#1=A('\\X\\G1');"), s("\\X\\G1"));
        assert_eq!(one("#1=A('end\\');"), s("end\\"));
        // Writers wrap long strings: the line break is not part of the value.
        let f = ok("#1=A('Screw0.s\r\ntp');\n#2=B(#1);");
        assert_eq!(params(&f, 1)[0], s("Screw0.stp"));
        assert_eq!(f.get(2).expect("#2").line, 10);
    }

    #[test]
    fn p21_non_utf8_bytes_in_strings() {
        // Latin-1 é (0xE9) and a stray 0xFF; UTF-8 é kept as is.
        let mut text = wrap("#1=A('caf\u{1}','x');").into_bytes();
        let at = text.iter().position(|&c| c == 1).expect("marker");
        text.splice(at..at + 1, [0xE9, 0xFF, b' ', 0xC3, 0xA9]);
        let f = parse(&text).expect("latin-1");
        assert_eq!(params(&f, 1)[0], s("caf\u{e9}\u{ff} é"));
        // Also in the slow path (with a doubled quote).
        let mut text = wrap("#1=A('a''\u{1}');").into_bytes();
        let at = text.iter().position(|&c| c == 1).expect("marker");
        text[at] = 0xE9;
        let f = parse(&text).expect("latin-1 slow");
        assert_eq!(params(&f, 1)[0], s("a'é"));
    }

    #[test]
    fn p21_enums_numbers_and_specials() {
        let f = ok(
            "#1=A(.T.,.F.,.UNSPECIFIED.,$,*,7,-12,+3,0,1.,-0.,1.E-05,1.0E+01,2.5e3,\"0F3\",\"\");",
        );
        let p = params(&f, 1);
        assert_eq!(p[0], Param::Enum("T".into()));
        assert_eq!(p[1], Param::Enum("F".into()));
        assert_eq!(p[2], Param::Enum("UNSPECIFIED".into()));
        assert_eq!(p[3], Param::Null);
        assert_eq!(p[4], Param::Derived);
        assert_eq!(p[5], Param::Int(7));
        assert_eq!(p[6], Param::Int(-12));
        assert_eq!(p[7], Param::Int(3));
        assert_eq!(p[8], Param::Int(0));
        assert_eq!(p[9], Param::Real(1.0));
        match p[10] {
            Param::Real(x) => assert!(x == 0.0 && x.is_sign_negative()),
            ref other => panic!("{other:?}"),
        }
        assert_eq!(p[11], Param::Real(1e-5));
        assert_eq!(p[12], Param::Real(10.0));
        assert_eq!(p[13], Param::Real(2500.0));
        assert_eq!(p[14], Param::Binary("0F3".into()));
        assert_eq!(p[15], Param::Binary(String::new()));
        assert_eq!(one("#1=A(9223372036854775807);"), Param::Int(i64::MAX));
    }

    #[test]
    fn p21_bad_numbers_are_errors_not_panics() {
        for bad in [
            "#1=A(.5);",
            "#1=A(-.5);",
            "#1=A(1.E);",
            "#1=A(-);",
            "#1=A(1.5.2);",
            "#1=A(99999999999999999999);",
            "#1=A(.T);",
            "#1=A(\"0G\");",
        ] {
            let e = err(bad);
            assert!(
                matches!(e, P21Error::Syntax { line: 8, .. }),
                "{bad}: {e:?}"
            );
            assert!(e.to_string().contains("#1"), "{bad}: {e}");
        }
    }

    #[test]
    fn p21_typed_and_nested_params() {
        assert_eq!(
            one("#1=A(LENGTH_MEASURE(2.));"),
            Param::Typed("LENGTH_MEASURE".into(), Box::new(Param::Real(2.0)))
        );
        assert_eq!(
            one("#1=A( OUTER ( INNER ( ( 1 , 2 ) ) ) );"),
            Param::Typed(
                "OUTER".into(),
                Box::new(Param::Typed(
                    "INNER".into(),
                    Box::new(Param::List(vec![Param::Int(1), Param::Int(2)]))
                ))
            )
        );
        assert_eq!(
            one("#1=A(((),(()),((#1,#2),(#3))));"),
            Param::List(vec![
                Param::List(vec![]),
                Param::List(vec![Param::List(vec![])]),
                Param::List(vec![
                    Param::List(vec![Param::Ref(1), Param::Ref(2)]),
                    Param::List(vec![Param::Ref(3)])
                ]),
            ])
        );
        assert_eq!(one("#1=A( ( ) );"), Param::List(vec![]));
        let f = ok("#1=EMPTY();");
        assert!(params(&f, 1).is_empty());
    }

    #[test]
    fn p21_complex_instances() {
        for data in [
            "#3=(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.));",
            "#3 = ( NAMED_UNIT ( * )\n  PLANE_ANGLE_UNIT ( )\n  SI_UNIT ( $ , .RADIAN. ) ) ;",
        ] {
            let f = ok(data);
            let e = f.get(3).expect("#3");
            assert_eq!(e.line, 8);
            let Instance::Complex(recs) = &e.instance else {
                panic!("not complex")
            };
            assert_eq!(recs.len(), 3);
            assert_eq!(
                e.instance.names(),
                vec!["NAMED_UNIT", "PLANE_ANGLE_UNIT", "SI_UNIT"]
            );
            let si = e.instance.record("SI_UNIT").expect("si");
            assert_eq!(si.params, vec![Param::Null, Param::Enum("RADIAN".into())]);
            assert!(e.instance.record("plane_angle_unit").is_some());
            assert!(e.instance.record("LENGTH_UNIT").is_none());
        }
        let f = ok("#1=POINT('');");
        let inst = &f.get(1).expect("#1").instance;
        assert_eq!(inst.record("POINT").map(|r| r.params.len()), Some(1));
        assert!(inst.record("LINE").is_none());
        assert_eq!(inst.names(), vec!["POINT"]);
        assert!(matches!(err("#1=();"), P21Error::Syntax { .. }));
    }

    #[test]
    fn p21_sections() {
        let text = format!(
            "{HEADER}ANCHOR;\n<a> = #1;\nENDSEC;\n\
             DATA('one',('AP214'));\n#1=A(#20);\nENDSEC;\n\
             REFERENCE;\n#9 = <http://x/y#z>;\n'ENDSEC;' /* ENDSEC; */\nENDSEC;\n\
             DATA;\n#20=B(#1);\nENDSEC;\n\
             SIGNATURE;\nQUJDREVG\"0A\"==\nENDSEC;\n\
             END-ISO-10303-21;\ntrailing garbage ignored ((("
        );
        let f = parse(text.as_bytes()).expect("sections");
        assert_eq!(f.entities.len(), 2);
        assert_eq!(f.get(20).expect("#20").line, 18);
        assert_eq!(f.first_dangling_ref(), None);
        // Ids are unique across sections.
        let dup = format!(
            "{HEADER}DATA;\n#1=A();\nENDSEC;\nDATA;\n#1=B();\nENDSEC;\nEND-ISO-10303-21;\n"
        );
        assert_eq!(
            parse(dup.as_bytes()).unwrap_err(),
            P21Error::DuplicateId { id: 1, line: 11 }
        );
    }

    #[test]
    fn p21_ids_order_and_references() {
        let f = ok("#18446744073709551615=A(#7);\n#7=B(#18446744073709551615,#3);\n#3=C((#7));");
        assert_eq!(f.entities.len(), 3);
        assert_eq!(f.entities[0].id, u64::MAX);
        assert_eq!(f.get(u64::MAX).expect("max").line, 8);
        assert_eq!(params(&f, 7)[0], Param::Ref(u64::MAX));
        assert_eq!(f.first_dangling_ref(), None);
        let f = ok("#1=A(#2);\n#2=B((X(#3)),#99);\n#3=C(#1);");
        assert_eq!(f.first_dangling_ref(), Some((2, 99)));
        let f = ok("#1=A(#2);\n#2=B(LIST((#3,(#55))));");
        assert_eq!(f.first_dangling_ref(), Some((2, 3)));
        let e = err("#18446744073709551616=A();");
        assert!(matches!(e, P21Error::Syntax { line: 8, .. }), "{e:?}");
    }

    #[test]
    fn p21_duplicate_id() {
        assert_eq!(
            err("#5=A();\n#6=B();\n#5=C();"),
            P21Error::DuplicateId { id: 5, line: 10 }
        );
    }

    #[test]
    fn p21_too_deep_is_an_error() {
        let deep = format!("#1=A({}1{});", "(".repeat(64), ")".repeat(64));
        assert_eq!(err(&deep), P21Error::TooDeep { line: 8 });
        let ok_depth = format!("#1=A({}1{});", "(".repeat(63), ")".repeat(63));
        ok(&ok_depth);
        let typed = format!("#1=A({}1{});", "T(".repeat(100), ")".repeat(100));
        assert_eq!(err(&typed), P21Error::TooDeep { line: 8 });
        // Huge nesting: no stack overflow.
        let huge = format!("#1=A({}", "(".repeat(1_000_000));
        assert_eq!(err(&huge), P21Error::TooDeep { line: 8 });
    }

    #[test]
    fn p21_truncation_errors() {
        let full = wrap("#1=A('x',(1,2));");
        for (cut, what) in [
            ("#1=A('x',(1", "in list"),
            ("#1=A('x", "in string"),
            ("#1=A", "after name"),
            ("#1=", "after ="),
            ("#1=A('x',(1,2))", "before ;"),
            ("#1=A('x',(1,2));\nENDSEC;\n", "before end"),
        ] {
            let n = full.find(cut).expect("cut") + cut.len();
            let e = parse(&full.as_bytes()[..n]).unwrap_err();
            assert!(matches!(e, P21Error::Truncated { .. }), "{what}: {e:?}");
        }
        assert!(matches!(
            parse(wrap("/* unterminated").as_bytes()).unwrap_err(),
            P21Error::Truncated { .. }
        ));
        let e = parse(b"ISO-10303-21;\nHEADER;\n").unwrap_err();
        assert_eq!(e, P21Error::Truncated { line: 3 });
    }

    #[test]
    fn p21_syntax_error_messages() {
        let e = err("#45=A(1)\n#46=B();");
        assert_eq!(
            e.to_string(),
            "syntax error at line 9: expected ';' after entity #45"
        );
        let e = err("#12=A(1 2);");
        assert_eq!(
            e.to_string(),
            "syntax error at line 8: expected ',' or ')' in parameter list, found a digit in entity #12"
        );
        let e = err("#12 A(1);");
        assert!(e
            .to_string()
            .contains("expected '=' after instance name in entity #12"));
        let e = err("#7=A(%);");
        assert!(e.to_string().contains("found '%' in entity #7"), "{e}");
        let e = err("FOO;");
        assert!(matches!(e, P21Error::Syntax { line: 8, .. }), "{e:?}");
        // Every kind of error displays as one lower-case line without a period.
        let errors = vec![
            P21Error::Empty,
            P21Error::NotPart21,
            P21Error::Truncated { line: 3 },
            P21Error::DuplicateId { id: 5, line: 10 },
            P21Error::TooDeep { line: 8 },
            err("#1=A(\u{7}\u{1b});"),
            err("#1=A()B;"),
            err("#1=1;"),
            err("#1=A(.5);"),
        ];
        for e in errors {
            let text = e.to_string();
            assert!(!text.contains('\n'), "{text}");
            assert!(!text.ends_with('.'), "{text}");
            assert_eq!(text, text.to_lowercase(), "{text}");
        }
    }

    /// Tiny xorshift64 PRNG for the fuzz-style tests.
    struct XorShift(u64);

    impl XorShift {
        fn next(&mut self) -> u64 {
            let mut x = self.0;
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            self.0 = x;
            x
        }
    }

    #[test]
    fn p21_reals_match_std_bit_for_bit() {
        let mut rng = XorShift(0x1234_5678_9ABC_DEF1);
        for _ in 0..5 {
            let mut texts = Vec::new();
            for _ in 0..20_000 {
                let mut t = String::new();
                match rng.next() % 3 {
                    0 => t.push('-'),
                    1 => t.push('+'),
                    _ => {}
                }
                // Zeros are frequent in real files, so draw them often.
                let digit = |rng: &mut XorShift| {
                    if rng.next() % 3 == 0 {
                        '0'
                    } else {
                        char::from(b'0' + (rng.next() % 10) as u8)
                    }
                };
                for _ in 0..=(rng.next() % 12) {
                    t.push(digit(&mut rng));
                }
                t.push('.');
                for _ in 0..(rng.next() % 24) {
                    t.push(digit(&mut rng));
                }
                if rng.next() % 2 == 0 {
                    t.push(if rng.next() % 2 == 0 { 'E' } else { 'e' });
                    match rng.next() % 3 {
                        0 => t.push('-'),
                        1 => t.push('+'),
                        _ => {}
                    }
                    t.push_str(&(rng.next() % 40).to_string());
                }
                texts.push(t);
            }
            let f = ok(&format!("#1=A(({}));", texts.join(",")));
            let Param::List(values) = &params(&f, 1)[0] else {
                panic!("not a list")
            };
            assert_eq!(values.len(), texts.len());
            for (t, v) in texts.iter().zip(values) {
                let want: f64 = t.parse().expect("std parses");
                match v {
                    Param::Real(got) => assert_eq!(got.to_bits(), want.to_bits(), "{t}"),
                    other => panic!("{t}: {other:?}"),
                }
            }
        }
        for t in [
            "0.",
            "-0.",
            "1.E-05",
            "0.0174532925",
            "11.50000000000000000",
            "-7.177253269393304400",
            "0.0000000000000000000",
            "1.000000E-05",
            "100.",
            "1.0E+01",
            "123456789012345678901234567890.",
            "1.E308",
            "4.9E-324",
            "1.E99999999999999999999",
        ] {
            let want: f64 = t.parse().expect("std");
            match one(&format!("#1=A({t});")) {
                Param::Real(got) => assert_eq!(got.to_bits(), want.to_bits(), "{t}"),
                other => panic!("{t}: {other:?}"),
            }
        }
        assert_eq!(one("#1=A(-9223372036854775808);"), Param::Int(i64::MIN));
        assert_eq!(
            one("#1=A(999999999999999999);"),
            Param::Int(999_999_999_999_999_999)
        );
        assert_eq!(one("#1=A(-0000000000000000000000042);"), Param::Int(-42));
        assert!(matches!(
            err("#1=A(9223372036854775808);"),
            P21Error::Syntax { .. }
        ));
    }

    #[test]
    fn p21_random_bytes_never_panic() {
        let mut rng = XorShift(0x9E37_79B9_7F4A_7C15);
        // Pure noise, and noise after a valid prelude.
        for round in 0..2000 {
            let len = (rng.next() % 300) as usize;
            let mut bytes: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
            if round % 2 == 1 {
                bytes.splice(0..0, wrap("").bytes().take(HEADER.len() + 6));
            }
            let _ = parse(&bytes);
        }
        // Token soup: characters that matter to the grammar.
        const ALPHABET: &[u8] = b"#=;(),'\"$*.-+0123456789EAZ_ /*\\\nX2S";
        for _ in 0..5000 {
            let len = (rng.next() % 200) as usize;
            let soup: Vec<u8> = (0..len)
                .map(|_| ALPHABET[(rng.next() % ALPHABET.len() as u64) as usize])
                .collect();
            let mut bytes = format!("{HEADER}DATA;\n").into_bytes();
            bytes.extend_from_slice(&soup);
            let _ = parse(&bytes);
        }
        // Mutations of a valid file.
        let base = SMALL.as_bytes();
        for _ in 0..5000 {
            let mut bytes = base.to_vec();
            for _ in 0..(1 + rng.next() % 4) {
                let at = (rng.next() % bytes.len() as u64) as usize;
                match rng.next() % 3 {
                    0 => bytes[at] = rng.next() as u8,
                    1 => {
                        bytes.remove(at);
                    }
                    _ => bytes.insert(at, ALPHABET[(rng.next() % ALPHABET.len() as u64) as usize]),
                }
            }
            let _ = parse(&bytes);
        }
    }

    #[test]
    fn p21_every_prefix_never_panics() {
        let bytes = SMALL.as_bytes();
        let end = SMALL.find("END-ISO-10303-21;").expect("end") + "END-ISO-10303-21;".len();
        for n in 0..=bytes.len() {
            let r = parse(&bytes[..n]);
            if n >= end {
                assert!(r.is_ok(), "prefix {n}: {r:?}");
            } else {
                assert!(r.is_err(), "prefix {n} parsed");
            }
            if n > 0 && n < end && n > SMALL.find("HEADER").expect("h") {
                assert!(
                    matches!(r, Err(P21Error::Truncated { .. })),
                    "prefix {n}: {r:?}"
                );
            }
        }
    }

    #[test]
    fn p21_corpus_files_parse() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus");
        let Ok(read) = std::fs::read_dir(&dir) else {
            eprintln!("note: {} not found, corpus test skipped", dir.display());
            return;
        };
        let mut paths: Vec<_> = read
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.extension()
                    .is_some_and(|x| x.eq_ignore_ascii_case("step"))
            })
            .collect();
        paths.sort();
        for path in &paths {
            let bytes = std::fs::read(path).expect("read corpus file");
            let f = match parse(&bytes) {
                Ok(f) => f,
                Err(e) => panic!("{}: {e}", path.display()),
            };
            assert!(f.entities.len() > 100, "{}", path.display());
            assert!(!f.schemas().is_empty(), "{}", path.display());
            assert_eq!(f.first_dangling_ref(), None, "{}", path.display());
            for e in &f.entities {
                assert!(std::ptr::eq(f.get(e.id).expect("indexed"), e));
            }
            eprintln!("{}: {} entities", path.display(), f.entities.len());
        }
        assert!(
            paths.len() >= 8,
            "expected the 8 corpus files, found {}",
            paths.len()
        );
    }
}
