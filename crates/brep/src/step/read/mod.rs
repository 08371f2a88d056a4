//! Translation of a parsed Part 21 file into our [`Brep`] (AP203, AP214 and AP242 share the
//! topology and geometry entities read here).
//!
//! Handles, beyond what truck-stepio 0.3 does: the file's length and plane-angle units, closed
//! edges and seam edges (any edge shape goes into our arena unchanged), `BREP_WITH_VOIDS`,
//! `OFFSET_SURFACE`, `RECTANGULAR_TRIMMED_SURFACE`, `TRIMMED_CURVE`, and `SURFACE_CURVE`s taken by
//! their 3-D curve (so a seam that ends at a sphere's pole reads like any other edge). Each solid
//! stands where its assembly places it (`assembly`): a component placed twice is two solids.

mod assembly;
mod curves;
mod geometry;
mod placement;
mod schema_names;
mod surfaces;
mod topology;
mod translator;
mod units;

// The writer's tests read reals back the way the reader does.
#[cfg(test)]
pub(crate) use translator::as_real;

use crate::step::error::ReadError;
use crate::step::p21::P21File;
use crate::topology::{Brep, LengthUnit};
use translator::{Translator, R};

/// Reads a parsed file into a B-rep of every solid it holds.
pub fn translate(file: &P21File) -> R<Brep> {
    translate_turned(file, None)
}

/// [`translate`], every solid turned by the rotation `turn` (a proper rotation matrix, rows
/// first) about the file's origin, as if the file placed it so.
pub fn translate_turned(file: &P21File, turn: Option<[[f64; 3]; 3]>) -> R<Brep> {
    let global = turn.map(placement::Placement::rotation);
    if let Some((from, missing)) = file.first_dangling_ref() {
        return Err(ReadError::Dangling { from, missing });
    }
    let mut t = Translator::new(file);
    let contexts = t.item_contexts();
    let bodies = t.find_bodies()?;
    if bodies.is_empty() {
        return Err(ReadError::NoSolid(t.why_no_solid()));
    }
    let default_units = t.default_units();
    let mut unit_names: Vec<LengthUnit> = vec![];
    for (id, kind, place) in t.placed_bodies(&bodies)? {
        let units = contexts
            .get(&id)
            .and_then(|c| t.context_units(*c).ok())
            .unwrap_or_else(|| default_units.clone());
        t.mm = units.0.mm_per_unit;
        t.rad = units.1;
        if !unit_names.contains(&units.0) {
            unit_names.push(units.0.clone());
        }
        t.place = match (&global, place) {
            (Some(g), Some(p)) => Some(g.then(&p)),
            (Some(g), None) => Some(*g),
            (None, p) => p,
        };
        t.forget_read();
        t.read_body(id, kind)?;
    }
    // Faces whose normal runs against their neighbours' are turned round, as OpenCASCADE heals
    // them on reading.
    for k in 0..t.brep.shells.len() {
        let sh = crate::topology::ShellId(k as u32);
        if !t.shell_is_closed(sh) {
            continue;
        }
        let turned = crate::orient::orient_shell(&mut t.brep, sh);
        if !turned.is_empty() {
            let ids: Vec<String> = turned
                .iter()
                .map(|f| format!("#{}", t.brep.faces[f.idx()].step_id))
                .collect();
            let sid = t.brep.shells[k].step_id;
            t.brep.warnings.push(format!(
                "shell #{sid}: face(s) {} faced against the rest of the shell; turned round",
                ids.join(", ")
            ));
        }
    }
    if t.off_curve.0 > 0 {
        t.brep.warnings.push(format!(
            "{} edge ends lie off their curves by up to {:.3} mm (worst at #{})",
            t.off_curve.0, t.off_curve.1, t.off_curve.2
        ));
    }
    t.brep.units = unit_names;
    for l in &file.header_skipped {
        t.brep.warnings.push(format!(
            "line {}: header line `{}` skipped: {}",
            l.line, l.text, l.cause
        ));
    }
    // Entities of no schema the reader knows (a misspelt name): skipped, but said.
    let unknown: Vec<(u64, &str)> = file
        .entities
        .iter()
        .flat_map(|e| {
            e.instance
                .names()
                .into_iter()
                .filter(|n| !schema_names::is_known(n))
                .map(move |n| (e.id, n))
        })
        .collect();
    for (id, name) in unknown.iter().take(5) {
        let hint = schema_names::nearest(name)
            .map(|k| format!(" (did you mean {k}?)"))
            .unwrap_or_default();
        t.brep
            .warnings
            .push(format!("#{id}: unknown entity {name}{hint}; skipped"));
    }
    if unknown.len() > 5 {
        t.brep.warnings.push(format!(
            "{} more entities of unknown names skipped",
            unknown.len() - 5
        ));
    }
    if t.brep.solids.is_empty() {
        let mut why = String::new();
        for w in &t.brep.warnings {
            why.push_str("; ");
            why.push_str(w);
        }
        return Err(ReadError::NoSolid(why));
    }
    Ok(t.brep)
}
