//! The translator's state and its access to records: typed parameters, references and errors
//! naming the entity.

use crate::step::error::ReadError;
use crate::step::p21::{Entity, P21File, Param, Record};
use crate::topology::*;
use std::collections::HashMap;

pub(super) type R<T> = Result<T, ReadError>;

pub(super) struct Translator<'a> {
    pub(super) file: &'a P21File,
    pub(super) brep: Brep,
    /// Millimetres per file length unit.
    pub(super) mm: f64,
    /// Radians per file plane-angle unit.
    pub(super) rad: f64,
    pub(super) vertices: HashMap<u64, VertexId>,
    pub(super) edges: HashMap<u64, EdgeId>,
    pub(super) curves: HashMap<u64, CurveId>,
    pub(super) surfaces: HashMap<u64, (SurfaceId, bool)>,
    pub(super) depth: u32,
    /// (count, worst distance, worst edge id) of edge ends off their curve.
    pub(super) off_curve: (usize, f64, u64),
    /// Where the body being read is placed (an assembly's component), if anywhere.
    pub(super) place: Option<super::placement::Placement>,
}

pub(super) fn names_of(e: &Entity) -> String {
    e.instance.names().join("+")
}

impl<'a> Translator<'a> {
    pub(super) fn new(file: &'a P21File) -> Self {
        Translator {
            file,
            brep: Brep::default(),
            mm: 1.0,
            rad: 1.0,
            vertices: HashMap::new(),
            edges: HashMap::new(),
            curves: HashMap::new(),
            surfaces: HashMap::new(),
            depth: 0,
            off_curve: (0, 0.0, 0),
            place: None,
        }
    }

    // ---------- access helpers ----------

    pub(super) fn entity(&self, id: u64, from: u64) -> R<&'a Entity> {
        self.file
            .get(id)
            .ok_or(ReadError::Dangling { from, missing: id })
    }

    /// The record of entity `id` named one of `names` (simple or part of a complex entity).
    pub(super) fn record(
        &self,
        id: u64,
        from: u64,
        names: &[&'static str],
    ) -> R<(&'static str, &'a Record)> {
        let e = self.entity(id, from)?;
        for n in names {
            if let Some(r) = e.instance.record(n) {
                return Ok((n, r));
            }
        }
        Err(ReadError::Entity {
            id,
            entity: names_of(e),
            msg: format!(
                "expected {} here (referenced from #{from})",
                names.join(" or ")
            ),
        })
    }

    pub(super) fn bad(&self, id: u64, msg: impl Into<String>) -> ReadError {
        let entity = self.file.get(id).map(names_of).unwrap_or_default();
        ReadError::Entity {
            id,
            entity,
            msg: msg.into(),
        }
    }

    pub(super) fn param<'r>(&self, id: u64, r: &'r Record, i: usize) -> R<&'r Param> {
        r.params.get(i).ok_or_else(|| {
            self.bad(
                id,
                format!(
                    "{} has {} parameters, expected more than {i}",
                    r.name,
                    r.params.len()
                ),
            )
        })
    }

    pub(super) fn real(&self, id: u64, r: &Record, i: usize) -> R<f64> {
        let p = self.param(id, r, i)?;
        as_real(p).ok_or_else(|| {
            self.bad(
                id,
                format!("parameter {} of {} is not a number", i + 1, r.name),
            )
        })
    }

    pub(super) fn int(&self, id: u64, r: &Record, i: usize) -> R<i64> {
        match self.param(id, r, i)? {
            Param::Int(n) => Ok(*n),
            Param::Real(x) if x.fract() == 0.0 && x.abs() < 1e15 => Ok(*x as i64),
            _ => Err(self.bad(
                id,
                format!("parameter {} of {} is not an integer", i + 1, r.name),
            )),
        }
    }

    pub(super) fn bool(&self, id: u64, r: &Record, i: usize) -> R<bool> {
        match self.param(id, r, i)? {
            Param::Enum(e) if e.eq_ignore_ascii_case("T") => Ok(true),
            Param::Enum(e) if e.eq_ignore_ascii_case("F") => Ok(false),
            Param::Null | Param::Derived => Ok(true),
            _ => Err(self.bad(
                id,
                format!("parameter {} of {} is not .T. or .F.", i + 1, r.name),
            )),
        }
    }

    pub(super) fn reference(&self, id: u64, r: &Record, i: usize) -> R<u64> {
        match self.param(id, r, i)? {
            Param::Ref(x) => Ok(*x),
            _ => Err(self.bad(
                id,
                format!("parameter {} of {} is not a #reference", i + 1, r.name),
            )),
        }
    }

    pub(super) fn opt_reference(&self, id: u64, r: &Record, i: usize) -> R<Option<u64>> {
        match self.param(id, r, i)? {
            Param::Ref(x) => Ok(Some(*x)),
            Param::Null | Param::Derived => Ok(None),
            _ => Err(self.bad(
                id,
                format!("parameter {} of {} is not a #reference", i + 1, r.name),
            )),
        }
    }

    pub(super) fn list<'r>(&self, id: u64, r: &'r Record, i: usize) -> R<&'r [Param]> {
        match self.param(id, r, i)? {
            Param::List(l) => Ok(l),
            _ => Err(self.bad(
                id,
                format!("parameter {} of {} is not a list", i + 1, r.name),
            )),
        }
    }

    pub(super) fn refs(&self, id: u64, r: &Record, i: usize) -> R<Vec<u64>> {
        self.list(id, r, i)?
            .iter()
            .map(|p| match p {
                Param::Ref(x) => Ok(*x),
                _ => Err(self.bad(
                    id,
                    format!("parameter {} of {} holds a non-reference", i + 1, r.name),
                )),
            })
            .collect()
    }

    pub(super) fn name(r: &Record) -> String {
        match r.params.first() {
            Some(Param::Str(s)) => s.clone(),
            _ => String::new(),
        }
    }

    /// Forgets the entities read so far, so that a body read again (placed elsewhere) gets
    /// geometry of its own.
    pub(super) fn forget_read(&mut self) {
        self.vertices.clear();
        self.edges.clear();
        self.curves.clear();
        self.surfaces.clear();
    }

    pub(super) fn enter(&mut self, id: u64) -> R<()> {
        self.depth += 1;
        if self.depth > 24 {
            return Err(self.bad(id, "geometry nested too deep (a reference cycle?)"));
        }
        Ok(())
    }
}

/// A real from a parameter, looking through typed wrappers like `LENGTH_MEASURE(2.)`.
pub(crate) fn as_real(p: &Param) -> Option<f64> {
    match p {
        Param::Real(x) => Some(*x),
        Param::Int(n) => Some(*n as f64),
        Param::Typed(_, inner) => as_real(inner),
        _ => None,
    }
}
