//! Geometry primitives: points, directions, vectors, placements and positive lengths.

use super::translator::{as_real, Translator, R};
use crate::math::{Frame, P3, V3};
use crate::step::p21::Record;
use crate::tolerance::NONZERO;

impl<'a> Translator<'a> {
    // ---------- geometry primitives ----------

    pub(super) fn point(&self, id: u64, from: u64) -> R<P3> {
        let (_, r) = self.record(id, from, &["CARTESIAN_POINT"])?;
        let l = self.list(id, r, 1)?;
        let c: Vec<f64> = l.iter().filter_map(as_real).collect();
        if c.len() != l.len() || c.len() < 2 || c.iter().any(|x| !x.is_finite()) {
            return Err(self.bad(id, "coordinates are not 2 or 3 finite numbers"));
        }
        let z = c.get(2).copied().unwrap_or(0.0);
        let p = P3::new(c[0], c[1], z) * self.mm;
        Ok(self.place.map_or(p, |pl| pl.point(p)))
    }

    pub(super) fn direction(&self, id: u64, from: u64) -> R<V3> {
        let (_, r) = self.record(id, from, &["DIRECTION"])?;
        let l = self.list(id, r, 1)?;
        let c: Vec<f64> = l.iter().filter_map(as_real).collect();
        if c.len() != l.len() || c.len() < 2 || c.iter().any(|x| !x.is_finite()) {
            return Err(self.bad(id, "direction ratios are not 2 or 3 finite numbers"));
        }
        let v = V3::new(c[0], c[1], c.get(2).copied().unwrap_or(0.0));
        let v = v
            .try_normalize(NONZERO)
            .ok_or_else(|| self.bad(id, "zero-length direction"))?;
        Ok(self.place.map_or(v, |pl| pl.dir(v)))
    }

    pub(super) fn vector(&self, id: u64, from: u64) -> R<(V3, f64)> {
        let (kind, r) = self.record(id, from, &["VECTOR", "DIRECTION"])?;
        if kind == "DIRECTION" {
            return Ok((self.direction(id, from)?, 1.0));
        }
        let d = self.reference(id, r, 1)?;
        let mag = self.real(id, r, 2)?;
        Ok((self.direction(d, id)?, mag * self.mm))
    }

    pub(super) fn placement(&self, id: u64, from: u64) -> R<Frame> {
        let (_, r) = self.record(id, from, &["AXIS2_PLACEMENT_3D"])?;
        let o = self.reference(id, r, 1)?;
        let origin = self.point(o, id)?;
        let z = match self.opt_reference(id, r, 2)? {
            Some(d) => Some(self.direction(d, id)?),
            None => None,
        };
        let x = match self.opt_reference(id, r, 3)? {
            Some(d) => Some(self.direction(d, id)?),
            None => None,
        };
        Frame::from_axes(origin, z, x).ok_or_else(|| self.bad(id, "degenerate placement"))
    }

    pub(super) fn positive(&self, id: u64, r: &Record, i: usize, what: &str) -> R<f64> {
        let x = self.real(id, r, i)? * self.mm;
        if !(x.is_finite() && x > 0.0) {
            return Err(self.bad(id, format!("{what} must be positive, found {x}")));
        }
        Ok(x)
    }
}
