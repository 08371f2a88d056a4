//! Records, entities and sections, on top of the lexer's tokens.

use super::lexer::{describe, is_kw_char, is_kw_start, upper, Parser};
use super::model::{
    Entity, Instance, P21Error, P21File, Param, Record, SkippedLine, MAX_DEPTH, SKIPPED_TEXT,
};
use std::collections::HashMap;

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
    p.file().map_err(|e| match e {
        P21Error::NotPart21 if is_stl(bytes) => P21Error::Stl,
        e => e,
    })
}

/// Whether `bytes` are an STL mesh: ASCII (`solid` then a `facet` within the first lines) or
/// binary (an 80-byte header and a triangle count that gives the file's length exactly).
fn is_stl(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(1024)];
    let text = String::from_utf8_lossy(head).to_ascii_lowercase();
    if text.trim_start().starts_with("solid") && text.contains("facet") {
        return true;
    }
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        return 84 + 50 * n == bytes.len() as u64;
    }
    false
}

impl<'a> Parser<'a> {
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
        let (header, header_skipped) = self.header_records()?;

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
            header_skipped,
            index,
        })
    }

    /// Header records up to and including `ENDSEC;`, and the lines skipped as no record.
    ///
    /// A line that does not parse as a record (a merge-conflict marker such as `<<<<<<< HEAD`,
    /// a stray word) is skipped from where the record started to the end of its line, and
    /// listed: the header carries no geometry. The DATA section stays strict; a `DATA`
    /// keyword or an entity `#id` where a header record belongs is still an error (the
    /// header's `ENDSEC;` is missing).
    fn header_records(&mut self) -> Result<(Vec<Record>, Vec<SkippedLine>), P21Error> {
        let mut out = Vec::new();
        let mut skipped = Vec::new();
        loop {
            self.skip_ws()?;
            let (start, line) = (self.pos, self.line);
            let cause = match self.peek() {
                None => return Err(self.truncated()),
                Some(c) if is_kw_start(c) => {
                    let kw = self.keyword()?;
                    if kw.eq_ignore_ascii_case(b"ENDSEC") {
                        self.expect(b';', "expected ';' after endsec")?;
                        return Ok((out, skipped));
                    }
                    if kw.eq_ignore_ascii_case(b"DATA") {
                        return Err(self.syntax("expected header record or endsec, found DATA"));
                    }
                    let rec = self.record_body(kw).and_then(|rec| {
                        self.expect(b';', "expected ';' after header record")
                            .map(|()| rec)
                    });
                    match rec {
                        Ok(rec) => {
                            out.push(rec);
                            continue;
                        }
                        Err(e @ P21Error::Truncated { .. }) => return Err(e),
                        Err(P21Error::Syntax { msg, .. }) => msg,
                        Err(e) => e.to_string(),
                    }
                }
                Some(b'#') => {
                    return Err(self.syntax("expected header record or endsec, found '#'"));
                }
                Some(c) => format!("expected header record or endsec, found {}", describe(c)),
            };
            self.entity = None;
            self.pos = start;
            self.line = line;
            let text = self.rest_of_line();
            skipped.push(SkippedLine { line, text, cause });
        }
    }

    /// The text from `pos` to the end of its line (trimmed, at most [`SKIPPED_TEXT`]
    /// characters); `pos` moves past the line's end.
    fn rest_of_line(&mut self) -> String {
        let start = self.pos;
        while let Some(c) = self.peek() {
            self.pos += 1;
            if c == b'\n' {
                self.newline();
                break;
            }
        }
        let raw = String::from_utf8_lossy(self.slice(start, self.pos));
        raw.trim().chars().take(SKIPPED_TEXT).collect()
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
