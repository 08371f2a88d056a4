//! The file's length and plane-angle units, per representation context.

use super::translator::{Translator, R};
use crate::step::p21::Param;
use crate::topology::LengthUnit;
use std::collections::HashMap;

impl<'a> Translator<'a> {
    // ---------- units ----------

    /// Maps each representation item (solid) to the context of its representation.
    pub(super) fn item_contexts(&self) -> HashMap<u64, u64> {
        let mut out = HashMap::new();
        for e in &self.file.entities {
            for name in e.instance.names() {
                if !name.ends_with("REPRESENTATION") || name.contains("RELATIONSHIP") {
                    continue;
                }
                let Some(r) = e.instance.record(name) else {
                    continue;
                };
                if r.params.len() < 3 {
                    continue;
                }
                let (Param::List(items), Param::Ref(ctx)) = (&r.params[1], &r.params[2]) else {
                    continue;
                };
                for it in items {
                    if let Param::Ref(i) = it {
                        out.entry(*i).or_insert(*ctx);
                    }
                }
            }
        }
        out
    }

    pub(super) fn default_units(&mut self) -> (LengthUnit, f64) {
        for e in &self.file.entities {
            if e.instance.record("GLOBAL_UNIT_ASSIGNED_CONTEXT").is_some() {
                if let Ok(u) = self.context_units(e.id) {
                    return u;
                }
            }
        }
        self.brep
            .warnings
            .push("no length unit in the file; assuming millimetres".into());
        (
            LengthUnit {
                name: "mm".into(),
                mm_per_unit: 1.0,
            },
            1.0,
        )
    }

    /// (length unit, radians per angle unit) of a representation context.
    pub(super) fn context_units(&self, ctx: u64) -> R<(LengthUnit, f64)> {
        let (_, r) = self.record(ctx, ctx, &["GLOBAL_UNIT_ASSIGNED_CONTEXT"])?;
        let units = self.refs(ctx, r, 0)?;
        let mut length = None;
        let mut angle = 1.0;
        for u in units {
            let e = self.entity(u, ctx)?;
            if e.instance.record("LENGTH_UNIT").is_some() {
                length = Some(self.length_unit(u, ctx, 0)?);
            } else if e.instance.record("PLANE_ANGLE_UNIT").is_some() {
                angle = self.angle_unit(u, ctx, 0)?;
            }
        }
        let length = length.ok_or_else(|| self.bad(ctx, "context has no length unit"))?;
        Ok((length, angle))
    }

    pub(super) fn length_unit(&self, u: u64, from: u64, depth: u32) -> R<LengthUnit> {
        if depth > 8 {
            return Err(self.bad(u, "unit definitions nested too deep"));
        }
        let e = self.entity(u, from)?;
        if let Some(si) = e.instance.record("SI_UNIT") {
            let prefix = match si.params.first() {
                Some(Param::Enum(p)) => p.to_ascii_uppercase(),
                _ => String::new(),
            };
            let (f, name) = match prefix.as_str() {
                "" => (1000.0, "m"),
                "MILLI" => (1.0, "mm"),
                "CENTI" => (10.0, "cm"),
                "DECI" => (100.0, "dm"),
                "KILO" => (1e6, "km"),
                "MICRO" => (1e-3, "um"),
                "NANO" => (1e-6, "nm"),
                "DECA" => (1e4, "dam"),
                "HECTO" => (1e5, "hm"),
                other => {
                    return Err(self.bad(
                        u,
                        format!("unsupported SI prefix .{other}. on a length unit"),
                    ))
                }
            };
            return Ok(LengthUnit {
                name: name.into(),
                mm_per_unit: f,
            });
        }
        if let Some(cb) = e.instance.record("CONVERSION_BASED_UNIT") {
            let name = Self::name(cb).to_ascii_lowercase();
            let m = self.reference(u, cb, 1)?;
            let (_, mr) = self.record(m, u, &["LENGTH_MEASURE_WITH_UNIT", "MEASURE_WITH_UNIT"])?;
            let value = self.real(m, mr, 0)?;
            let base = self.reference(m, mr, 1)?;
            let base = self.length_unit(base, m, depth + 1)?;
            let f = value * base.mm_per_unit;
            if !(f.is_finite() && f > 0.0) {
                return Err(self.bad(u, "length unit conversion factor is not positive"));
            }
            let name = match name.as_str() {
                "inch" | "in" | "\"" => "inch".to_string(),
                "foot" | "ft" | "feet" => "foot".to_string(),
                "" => format!("{f} mm"),
                n => n.to_string(),
            };
            return Ok(LengthUnit {
                name,
                mm_per_unit: f,
            });
        }
        Err(self.bad(
            u,
            "length unit is neither SI_UNIT nor CONVERSION_BASED_UNIT",
        ))
    }

    pub(super) fn angle_unit(&self, u: u64, from: u64, depth: u32) -> R<f64> {
        if depth > 8 {
            return Err(self.bad(u, "unit definitions nested too deep"));
        }
        let e = self.entity(u, from)?;
        if e.instance.record("SI_UNIT").is_some() {
            return Ok(1.0);
        }
        if let Some(cb) = e.instance.record("CONVERSION_BASED_UNIT") {
            let m = self.reference(u, cb, 1)?;
            let (_, mr) = self.record(
                m,
                u,
                &["PLANE_ANGLE_MEASURE_WITH_UNIT", "MEASURE_WITH_UNIT"],
            )?;
            let value = self.real(m, mr, 0)?;
            let base = self.reference(m, mr, 1)?;
            return Ok(value * self.angle_unit(base, m, depth + 1)?);
        }
        Ok(1.0)
    }
}
