//! The parsed form of an exchange file: parameters, records, instances, entities, errors.

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
    /// Lines of the HEADER section that hold no record and were skipped (a merge-conflict
    /// marker, a stray word): the header carries no geometry, so they do not stop the reading.
    pub header_skipped: Vec<SkippedLine>,
    /// Instance id to position in `entities`, built while parsing.
    pub(super) index: HashMap<u64, usize>,
}

/// A line of the HEADER section that was skipped ([`P21File::header_skipped`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SkippedLine {
    /// 1-based line number.
    pub line: u32,
    /// The line's text, trimmed and cut to [`SKIPPED_TEXT`] characters.
    pub text: String,
    /// Why it is not a record.
    pub cause: String,
}

/// Characters of a skipped header line kept in [`SkippedLine::text`].
pub const SKIPPED_TEXT: usize = 60;

impl P21File {
    /// The entity `#id`, if the file defines it. Uses the index built by
    /// [`parse`](super::parse); entities added to or moved in `entities` afterwards may not
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
    /// The file is an STL mesh.
    #[error("an STL mesh, not a STEP file: features plans from the exact B-rep of a STEP file (AP203, AP214 or AP242), which triangles no longer hold; export STEP from the CAD system")]
    Stl,
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
