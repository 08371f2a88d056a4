//! Where each solid stands: the file's representations joined by their placements
//! (`REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION` with an `ITEM_DEFINED_TRANSFORMATION`, as
//! NEXT_ASSEMBLY_USAGE_OCCURRENCEs place components; `MAPPED_ITEM`), walked from the
//! representations nothing places, so a component placed twice gives two solids.
//!
//! Representations joined by a `SHAPE_REPRESENTATION_RELATIONSHIP` without a transformation
//! (a part's shape representation and the B-rep representation holding its solid) share one
//! frame. A solid no representation reaches is read once where it stands.

use super::placement::Placement;
use super::topology::BodyKind;
use super::translator::{Translator, R};
use crate::math::Frame;
use crate::step::p21::Param;
use std::collections::{HashMap, HashSet};

/// How many placements deep an assembly may nest before the walk stops (a cycle).
const MAX_DEPTH: usize = 32;

/// How many placed representations the walk visits at most (a file nesting a few components
/// many times over would otherwise take exponential time).
const MAX_VISITS: usize = 100_000;

impl<'a> Translator<'a> {
    /// Every placed instance of the bodies, in file order of the bodies: `(body, kind,
    /// placement)`, `None` where the body stands as written.
    pub(super) fn placed_bodies(
        &mut self,
        bodies: &[(u64, BodyKind)],
    ) -> R<Vec<(u64, BodyKind, Option<Placement>)>> {
        let reps = self.representations();
        // Representations sharing a frame, by union-find.
        let mut group: HashMap<u64, u64> = reps.keys().map(|&r| (r, r)).collect();
        fn find(g: &mut HashMap<u64, u64>, x: u64) -> u64 {
            let mut r = x;
            while let Some(&p) = g.get(&r) {
                if p == r {
                    break;
                }
                r = p;
            }
            g.insert(x, r);
            r
        }
        let parents = self.parent_reps();
        // (parent representation, child representation, child-to-parent placement)
        let mut links: Vec<(u64, u64, Placement)> = vec![];
        for e in &self.file.entities {
            let i = &e.instance;
            let Some(rr) = i
                .record("REPRESENTATION_RELATIONSHIP")
                .or_else(|| i.record("SHAPE_REPRESENTATION_RELATIONSHIP"))
            else {
                continue;
            };
            let (Some(Param::Ref(r1)), Some(Param::Ref(r2))) = (rr.params.get(2), rr.params.get(3))
            else {
                continue;
            };
            let (r1, r2) = (*r1, *r2);
            if !(reps.contains_key(&r1) && reps.contains_key(&r2)) {
                continue;
            }
            match i.record("REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION") {
                None => {
                    let (a, b) = (find(&mut group, r1), find(&mut group, r2));
                    group.insert(a, b);
                }
                Some(rt) => {
                    // The parent is the assembly's representation where the occurrence names
                    // it; otherwise rep_2, as most writers have it.
                    let one_is_parent = parents.contains(&r1) && !parents.contains(&r2);
                    let (parent, child) = if one_is_parent { (r1, r2) } else { (r2, r1) };
                    let p = self
                        .reference(e.id, rt, 0)
                        .and_then(|tr| self.transformation(tr, e.id, &reps, one_is_parent));
                    match p {
                        Ok(p) => links.push((parent, child, p)),
                        Err(err) => self
                            .brep
                            .warnings
                            .push(format!("{err}; the component stands as written")),
                    }
                }
            }
        }
        // MAPPED_ITEMs: the mapped representation placed into the one listing the item.
        for (&rep, (items, _)) in &reps {
            for &it in items {
                let Some(ent) = self.file.get(it) else {
                    continue;
                };
                let Some(mi) = ent.instance.record("MAPPED_ITEM") else {
                    continue;
                };
                match self.mapped_item(it, mi, rep, &reps) {
                    Ok(Some((mapped, p))) => links.push((rep, mapped, p)),
                    Ok(None) => {}
                    Err(err) => self
                        .brep
                        .warnings
                        .push(format!("{err}; the mapped representation is not placed")),
                }
            }
        }
        // Walk from the groups nothing places.
        let mut children: HashMap<u64, Vec<(u64, Placement)>> = HashMap::new();
        let mut placed: HashSet<u64> = HashSet::new();
        for (p, c, pl) in links {
            let (gp, gc) = (find(&mut group, p), find(&mut group, c));
            if gp == gc {
                continue; // placed into its own frame: no placement at all
            }
            children.entry(gp).or_default().push((gc, pl));
            placed.insert(gc);
        }
        let mut members: HashMap<u64, Vec<u64>> = HashMap::new();
        let mut rep_ids: Vec<u64> = reps.keys().copied().collect();
        rep_ids.sort_unstable();
        for &r in &rep_ids {
            let g = find(&mut group, r);
            members.entry(g).or_default().push(r);
        }
        let kinds: HashMap<u64, BodyKind> = bodies.iter().copied().collect();
        let mut instances: HashMap<u64, Vec<Placement>> = HashMap::new();
        let mut roots: Vec<u64> = members
            .keys()
            .copied()
            .filter(|g| !placed.contains(g))
            .collect();
        roots.sort_unstable();
        let mut stack: Vec<(u64, Placement, usize)> = roots
            .into_iter()
            .map(|g| (g, Placement::identity(), 0))
            .collect();
        let mut visits = 0usize;
        while let Some((g, pl, depth)) = stack.pop() {
            visits += 1;
            if visits > MAX_VISITS {
                self.brep.warnings.push(format!(
                    "assembly of more than {MAX_VISITS} placed representations: the rest not placed"
                ));
                break;
            }
            for r in members.get(&g).into_iter().flatten() {
                for it in &reps[r].0 {
                    if kinds.contains_key(it) {
                        let v = instances.entry(*it).or_default();
                        if !v.iter().any(|q| q.near(&pl)) {
                            v.push(pl);
                        }
                    }
                }
            }
            if depth >= MAX_DEPTH {
                continue;
            }
            for (c, inner) in children.get(&g).into_iter().flatten() {
                stack.push((*c, pl.then(inner), depth + 1));
            }
        }
        let mut out = vec![];
        for &(id, kind) in bodies {
            match instances.get(&id) {
                Some(v) if !v.is_empty() => {
                    for pl in v {
                        out.push((id, kind, (!pl.is_identity()).then_some(*pl)));
                    }
                }
                _ => out.push((id, kind, None)),
            }
        }
        Ok(out)
    }

    /// The representation a MAPPED_ITEM `it` (record `mi`, listed by `rep`) maps and its
    /// placement into `rep`; `None` when it maps no representation of a known kind.
    fn mapped_item(
        &mut self,
        it: u64,
        mi: &crate::step::p21::Record,
        rep: u64,
        reps: &HashMap<u64, (Vec<u64>, u64)>,
    ) -> R<Option<(u64, Placement)>> {
        let source = self.reference(it, mi, 1)?;
        let target = self.reference(it, mi, 2)?;
        let (_, rm) = self.record(source, it, &["REPRESENTATION_MAP"])?;
        let origin = self.reference(source, rm, 0)?;
        let mapped = self.reference(source, rm, 1)?;
        let (Some(m), Some(r)) = (reps.get(&mapped), reps.get(&rep)) else {
            return Ok(None);
        };
        let from = self.frame_in(origin, source, Some(m.1))?;
        let to = self.frame_in(target, it, Some(r.1))?;
        Ok(Some((mapped, Placement::between(&from, &to))))
    }

    /// Each representation's items and context.
    fn representations(&self) -> HashMap<u64, (Vec<u64>, u64)> {
        let mut out = HashMap::new();
        for e in &self.file.entities {
            for name in e.instance.names() {
                if !name.ends_with("REPRESENTATION")
                    || name.contains("RELATIONSHIP")
                    || name == "SHAPE_DEFINITION_REPRESENTATION"
                {
                    continue;
                }
                let Some(r) = e.instance.record(name) else {
                    continue;
                };
                let (Some(Param::List(items)), Some(Param::Ref(ctx))) =
                    (r.params.get(1), r.params.get(2))
                else {
                    continue;
                };
                let items = items
                    .iter()
                    .filter_map(|p| match p {
                        Param::Ref(x) => Some(*x),
                        _ => None,
                    })
                    .collect();
                out.insert(e.id, (items, *ctx));
                break;
            }
        }
        out
    }

    /// The representations of products that an occurrence (NEXT_ASSEMBLY_USAGE_OCCURRENCE and
    /// its kin) names as the assembly.
    fn parent_reps(&self) -> HashSet<u64> {
        let mut assemblies: HashSet<u64> = HashSet::new();
        for e in &self.file.entities {
            let i = &e.instance;
            let r = i
                .record("NEXT_ASSEMBLY_USAGE_OCCURRENCE")
                .or_else(|| i.record("ASSEMBLY_COMPONENT_USAGE"))
                .or_else(|| i.record("PRODUCT_DEFINITION_USAGE"));
            if let Some(Param::Ref(pd)) = r.and_then(|r| r.params.get(3)) {
                assemblies.insert(*pd);
            }
        }
        let mut out = HashSet::new();
        for e in &self.file.entities {
            let Some(sdr) = e.instance.record("SHAPE_DEFINITION_REPRESENTATION") else {
                continue;
            };
            let (Some(Param::Ref(pds)), Some(Param::Ref(rep))) =
                (sdr.params.first(), sdr.params.get(1))
            else {
                continue;
            };
            let def = self
                .file
                .get(*pds)
                .and_then(|p| p.instance.record("PRODUCT_DEFINITION_SHAPE"))
                .and_then(|p| p.params.get(2));
            if let Some(Param::Ref(pd)) = def {
                if assemblies.contains(pd) {
                    out.insert(*rep);
                }
            }
        }
        out
    }

    /// The child-to-parent placement of an ITEM_DEFINED_TRANSFORMATION (`reversed`: its first
    /// item is the parent's).
    fn transformation(
        &mut self,
        id: u64,
        from: u64,
        reps: &HashMap<u64, (Vec<u64>, u64)>,
        reversed: bool,
    ) -> R<Placement> {
        let e = self.entity(id, from)?;
        let Some(r) = e.instance.record("ITEM_DEFINED_TRANSFORMATION") else {
            let names = super::translator::names_of(e);
            self.brep.warnings.push(format!(
                "#{id}: placement {names} not read; the component stands as written"
            ));
            return Ok(Placement::identity());
        };
        let (i1, i2) = (self.reference(id, r, 2)?, self.reference(id, r, 3)?);
        let ctx_of = |item: u64| {
            reps.values()
                .find(|(it, _)| it.contains(&item))
                .map(|r| r.1)
        };
        let f1 = self.frame_in(i1, id, ctx_of(i1))?;
        let f2 = self.frame_in(i2, id, ctx_of(i2))?;
        Ok(if reversed {
            Placement::between(&f2, &f1)
        } else {
            Placement::between(&f1, &f2)
        })
    }

    /// An AXIS2_PLACEMENT_3D read in the length unit of context `ctx`, with no placement.
    fn frame_in(&mut self, id: u64, from: u64, ctx: Option<u64>) -> R<Frame> {
        let saved = (self.mm, self.place.take());
        if let Some(u) = ctx.and_then(|c| self.context_units(c).ok()) {
            self.mm = u.0.mm_per_unit;
        }
        let f = self.placement(id, from);
        (self.mm, self.place) = saved;
        f
    }
}
