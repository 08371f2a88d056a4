//! What is deposited: grains sampled along the beads' top centrelines, kept as occupied cells of
//! a quarter millimetre (a 64-bit mask per millimetre cell) under an octree of cells up to
//! 1,024 mm, each with the tight box of its quarter cells, so a query visits only the boxes near
//! the head's surface: a box is skipped when the head's distance bound clears it, or when it
//! lies wholly at or below the tip's level across the tool axis (the layers the tip rests on).
//! A quarter cell counts as inside the head when all of it is (its centre deeper than the
//! tolerance plus its half-diagonal).

use crate::head::HeadShape;
use std::cell::Cell;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use toolpath::vec3::{dot, norm, scale, sub, V3};

/// Side of the finest cells (one mask each), mm.
const CELL: f64 = 1.0;
/// Quarter cells per side of a finest cell (4 × 4 × 4 = 64 bits).
const SPLIT: i32 = 4;
/// Side of a quarter cell, mm.
const SUB: f64 = CELL / SPLIT as f64;
/// Coarser levels above the finest: the top cells are `CELL · 2^LEVELS` (1,024 mm), so a
/// part has few of them, each asked by every query.
const LEVELS: usize = 10;
/// Largest spacing of grains along a bead, mm.
pub const GRAIN_SPACING: f64 = 0.5;
/// Half the diagonal of a quarter cell, mm: how far its centre may lie from a grain in it.
pub const GRAIN_SLACK: f64 = SUB * 0.866_025_403_784_438_6;

/// A cell index at some level.
type Key = [i32; 3];

/// `x.floor() as i32` without a call into libm (saturating alike).
fn floor_i32(x: f64) -> i32 {
    let i = x as i32;
    if f64::from(i) > x {
        i.saturating_sub(1)
    } else {
        i
    }
}

/// `x.fract()` without a call into libm: `x` less its integer part (a NaN stays NaN; a
/// magnitude of 2^52 or more is whole already).
fn fract(x: f64) -> f64 {
    if x.abs() < 4_503_599_627_370_496.0 {
        x - (x as i64) as f64
    } else if x.is_finite() {
        0.0
    } else {
        f64::NAN
    }
}

/// The centre of quarter cell `sub` of the finest cell `key`.
fn centre(key: Key, sub: [i32; 3]) -> [f32; 3] {
    std::array::from_fn(|k| (f64::from(key[k]) * CELL + (f64::from(sub[k]) + 0.5) * SUB) as f32)
}

/// A multiplicative hash for cell keys (the std SipHash dominates the lookups otherwise).
#[derive(Default, Clone, Copy)]
pub(crate) struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    fn write_i32(&mut self, v: i32) {
        self.write_u64(v as u32 as u64);
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_usize(&mut self, v: usize) {
        self.write_u64(v as u64);
    }
}

type Fast = BuildHasherDefault<KeyHasher>;

/// A finest cell: which quarter cells hold material (a 64-bit mask in two halves, so a leaf
/// takes 20 bytes: its index is the path to it), their lowest and highest index per axis, and
/// the first feature that laid any.
#[derive(Debug, Clone, Copy)]
struct Leaf {
    mask: [u32; 2],
    lo: [u8; 3],
    hi: [u8; 3],
    feature: u32,
}

/// No child.
const NONE: u32 = u32::MAX;

impl Leaf {
    /// Its quarter cells, bit `x + 4·y + 16·z`.
    fn mask(&self) -> u64 {
        u64::from(self.mask[0]) | u64::from(self.mask[1]) << 32
    }

    /// The centre and half extents of the box of its occupied quarter cells' centres, for the
    /// leaf of finest-cell index `key`.
    fn centres_box(&self, key: Key) -> (V3, V3) {
        let origin = key.map(|i| f64::from(i) * CELL);
        let centre = std::array::from_fn(|k| {
            origin[k] + (0.5 * (f64::from(self.lo[k]) + f64::from(self.hi[k])) + 0.5) * SUB
        });
        let half = std::array::from_fn(|k| 0.5 * f64::from(self.hi[k] - self.lo[k]) * SUB);
        (centre, half)
    }
}

/// The index of child `slot` of the cell `cell` one level up.
fn child_cell(cell: Key, slot: usize) -> Key {
    std::array::from_fn(|i| cell[i] << 1 | ((slot >> i) & 1) as i32)
}

/// A cell of the hierarchy above the finest: the tight box of the quarter-cell centres under
/// it and its occupied children (nodes, or at level 1 leaves).
#[derive(Debug, Clone)]
struct Node {
    lo: [f32; 3],
    hi: [f32; 3],
    children: [u32; 8],
}

impl Node {
    /// The centre and half extents of its box of quarter-cell centres, the half extents grown
    /// by a little for the single-precision corners.
    fn centres_box(&self) -> (V3, V3) {
        let centre = std::array::from_fn(|k| 0.5 * f64::from(self.lo[k] + self.hi[k]));
        let half = std::array::from_fn(|k| 0.5 * f64::from(self.hi[k] - self.lo[k]) + 1e-4);
        (centre, half)
    }
}

/// The material deposited so far.
#[derive(Default)]
pub struct Deposit {
    nodes: Vec<Node>,
    leaves: Vec<Leaf>,
    /// Top cells (side `CELL · 2^LEVELS`) by index.
    top: HashMap<Key, u32, Fast>,
    /// The top cells' indices and nodes, in the order they were first occupied.
    roots: Vec<(Key, u32)>,
    /// The last leaf written and the nodes above it (top first): beads run on, so the next
    /// grain mostly falls in the same leaf.
    last: Option<(Key, u32, [u32; LEVELS])>,
    /// Highest grain, mm (−∞ when empty).
    z_max: f64,
    /// The last leaf found inside the head: asked first next time, since the moves after a
    /// colliding one mostly meet the same material.
    hint: Cell<(u32, Key)>,
}

impl Deposit {
    /// Nothing deposited.
    pub fn new() -> Deposit {
        Deposit {
            z_max: f64::NEG_INFINITY,
            hint: Cell::new((NONE, [0; 3])),
            ..Deposit::default()
        }
    }

    /// Highest deposited grain, mm; −∞ when nothing is deposited.
    pub fn z_max(&self) -> f64 {
        self.z_max
    }

    /// A node with an empty box (the grain that makes it widens it at once).
    fn node(&mut self) -> u32 {
        self.nodes.push(Node {
            lo: [f32::INFINITY; 3],
            hi: [f32::NEG_INFINITY; 3],
            children: [NONE; 8],
        });
        (self.nodes.len() - 1) as u32
    }

    /// The leaf of `key` and the nodes above it, made where missing. The descent starts at the
    /// lowest node the last leaf written shares with it (beads run on: mostly its parent),
    /// else at the top cell.
    fn find(&mut self, key: Key, feature: usize) -> (u32, [u32; LEVELS]) {
        let mut path = [NONE; LEVELS];
        let shared = self.last.and_then(|(k, _, above)| {
            let level = (1..=LEVELS).find(|&l| (0..3).all(|i| k[i] >> l == key[i] >> l))?;
            path[..=LEVELS - level].copy_from_slice(&above[..=LEVELS - level]);
            Some((level, above[LEVELS - level]))
        });
        let (from, mut at) = match shared {
            Some(s) => s,
            None => {
                let top = key.map(|i| i >> LEVELS);
                let n = match self.top.get(&top) {
                    Some(&n) => n,
                    None => {
                        let n = self.node();
                        self.top.insert(top, n);
                        self.roots.push((top, n));
                        n
                    }
                };
                (LEVELS, n)
            }
        };
        for level in (1..=from).rev() {
            path[LEVELS - level] = at;
            let bit = |i: i32| ((i >> (level - 1)) & 1) as usize;
            let slot = bit(key[0]) | bit(key[1]) << 1 | bit(key[2]) << 2;
            let child = self.nodes[at as usize].children[slot];
            let child = if child != NONE {
                child
            } else if level == 1 {
                self.leaves.push(Leaf {
                    mask: [0; 2],
                    lo: [SPLIT as u8; 3],
                    hi: [0; 3],
                    feature: feature as u32,
                });
                (self.leaves.len() - 1) as u32
            } else {
                self.node()
            };
            self.nodes[at as usize].children[slot] = child;
            at = child;
        }
        (at, path)
    }

    /// Deposits one grain at `p`, laid by `feature`: its quarter cell is occupied.
    pub fn add(&mut self, p: V3, feature: usize) {
        let key = p.map(|x| floor_i32(x / CELL));
        let sub: [i32; 3] =
            std::array::from_fn(|k| ((fract(fract(p[k] / CELL) + 1.0)) * SPLIT as f64) as i32);
        let sub = sub.map(|s| s.clamp(0, SPLIT - 1));
        let (leaf, path) = match self.last {
            Some((k, leaf, path)) if k == key => (leaf, path),
            _ => {
                let (leaf, path) = self.find(key, feature);
                self.last = Some((key, leaf, path));
                (leaf, path)
            }
        };
        let bit = 1u64 << (sub[0] + SPLIT * sub[1] + SPLIT * SPLIT * sub[2]);
        let l = &mut self.leaves[leaf as usize];
        if l.mask() & bit == 0 {
            let mask = l.mask() | bit;
            l.mask = [mask as u32, (mask >> 32) as u32];
            let (lo, hi) = (l.lo, l.hi);
            l.lo = std::array::from_fn(|k| l.lo[k].min(sub[k] as u8));
            l.hi = std::array::from_fn(|k| l.hi[k].max(sub[k] as u8));
            // A quarter cell inside the leaf's box of quarter cells already lies in every box
            // above it (each holds the centres of its leaves' lowest and highest quarter cell
            // per axis); otherwise the boxes grow from the bottom up, as far as one changes.
            if (l.lo, l.hi) != (lo, hi) {
                let c = centre(key, sub);
                for &n in path.iter().rev() {
                    let node = &mut self.nodes[n as usize];
                    let (lo, hi) = (node.lo, node.hi);
                    node.lo = std::array::from_fn(|k| node.lo[k].min(c[k]));
                    node.hi = std::array::from_fn(|k| node.hi[k].max(c[k]));
                    if (node.lo, node.hi) == (lo, hi) {
                        break;
                    }
                }
            }
        }
        self.z_max = self.z_max.max(p[2]);
    }

    /// The highest of the grains [`Deposit::add_bead`] puts from `a` to `b`, exactly: their
    /// heights `a + (b − a)·k/n` rise (or fall) with `k` in floating point too, so the top
    /// is the last grain's or the first's.
    pub fn bead_top(a: V3, b: V3) -> f64 {
        let n = Self::bead_grains(a, b);
        let at = |k: usize| a[2] + (b[2] - a[2]) * (k as f64 / n as f64);
        at(n).max(at(1))
    }

    /// How many grains [`Deposit::add_bead`] puts from `a` to `b`.
    fn bead_grains(a: V3, b: V3) -> usize {
        (norm(sub(b, a)) / GRAIN_SPACING).ceil().clamp(1.0, 1e5) as usize
    }

    /// Deposits the bead from `a` to `b` as grains at most [`GRAIN_SPACING`] apart (`b`
    /// included, `a` not: it ends the bead before).
    pub fn add_bead(&mut self, a: V3, b: V3, feature: usize) {
        let n = Self::bead_grains(a, b);
        for k in 1..=n {
            let t = k as f64 / n as f64;
            self.add(std::array::from_fn(|i| a[i] + (b[i] - a[i]) * t), feature);
        }
    }

    /// The feature of a quarter cell lying wholly more than `tol` inside the head with its tip at
    /// `tip` and unit tool axis `axis`, if any (the first feature that laid material in its
    /// millimetre cell).
    pub fn first_inside(&self, shape: &HeadShape, tip: V3, axis: V3, tol: f64) -> Option<usize> {
        let q = Query {
            d: self,
            shape,
            tip,
            axis,
            tol,
        };
        let (hint, key) = self.hint.get();
        if hint != NONE {
            if let Some(f) = q.leaf(hint, key) {
                return Some(f);
            }
        }
        let found = self
            .roots
            .iter()
            .find_map(|&(cell, n)| q.visit(n, LEVELS, cell));
        if let Some((f, leaf)) = found {
            self.hint.set(leaf);
            return Some(f);
        }
        None
    }
}

/// Slack (mm) of [`Deposit::may_meet_along`]'s tests, for the rounding of the positions a sweep
/// interpolates between its ends.
const SWEEP_SLACK: f64 = 1e-6;

impl Deposit {
    /// Whether a quarter cell may lie wholly more than `tol` inside the head anywhere along
    /// the tip's move from `a` to `b` with the unit tool axis `axis` all along: when not,
    /// [`Deposit::first_inside`] finds nothing at any tip on that segment. Box by box it tests
    /// what a cell inside needs at some tip of the segment (the head's distance bound is at
    /// least `−h` and `r −` [`HeadShape::widest`], and inside only below its top): a height up
    /// the axis over `tol` plus the cell's slack, under the body's top, and a distance from
    /// the axis under the widest radius.
    pub fn may_meet_along(&self, shape: &HeadShape, a: V3, b: V3, axis: V3, tol: f64) -> bool {
        let along = sub(b, a);
        let s = Sweep {
            a,
            b,
            axis,
            across: sub(along, scale(axis, dot(along, axis))),
            depth: tol + GRAIN_SLACK,
            top: shape.top(),
            widest: shape.widest(),
        };
        self.roots
            .iter()
            .any(|&(cell, n)| s.visit(self, n, LEVELS, cell))
    }
}

/// A head swept along a segment with one tool axis, asked of a [`Deposit`].
struct Sweep {
    a: V3,
    b: V3,
    axis: V3,
    /// The segment across the axis.
    across: V3,
    depth: f64,
    top: f64,
    widest: f64,
}

impl Sweep {
    /// Whether the box of `centre` ± `half` may hold a point inside the head at some tip of the
    /// segment (see [`Deposit::may_meet_along`]).
    fn may_hold(&self, centre: V3, half: V3) -> bool {
        let (da, db) = (sub(centre, self.a), sub(centre, self.b));
        let (ha, hb) = (dot(da, self.axis), dot(db, self.axis));
        let reach = half[0] * self.axis[0].abs()
            + half[1] * self.axis[1].abs()
            + half[2] * self.axis[2].abs();
        if ha.max(hb) + reach <= self.depth - SWEEP_SLACK
            || ha.min(hb) - reach >= self.top + SWEEP_SLACK
        {
            return false;
        }
        // The centre's distance from the axis at the nearest tip: from the segment across it.
        let off = sub(da, scale(self.axis, ha));
        let len = dot(self.across, self.across);
        let t = if len > 0.0 {
            (dot(off, self.across) / len).clamp(0.0, 1.0)
        } else {
            0.0
        };
        norm(sub(off, scale(self.across, t))) - norm(half) < self.widest + SWEEP_SLACK
    }

    /// Whether node `n` (of `level`, 1 and up, cell index `cell` there) may hold a cell
    /// inside the head.
    fn visit(&self, d: &Deposit, n: u32, level: usize, cell: Key) -> bool {
        let node = &d.nodes[n as usize];
        let (centre, half) = node.centres_box();
        if !self.may_hold(centre, half) {
            return false;
        }
        (0..8).any(|slot| {
            let c = node.children[slot];
            if c == NONE {
                return false;
            }
            let key = child_cell(cell, slot);
            if level == 1 {
                let (centre, half) = d.leaves[c as usize].centres_box(key);
                self.may_hold(centre, half.map(|x| x + crate::tolerance::CELL_PAD))
            } else {
                self.visit(d, c, level - 1, key)
            }
        })
    }
}

/// One head position asked of a [`Deposit`].
struct Query<'a> {
    d: &'a Deposit,
    shape: &'a HeadShape,
    tip: V3,
    axis: V3,
    tol: f64,
}

impl Query<'_> {
    /// The head's distance bound at `p`.
    fn distance(&self, p: V3) -> f64 {
        let d = sub(p, self.tip);
        let h = dot(d, self.axis);
        let r = (dot(d, d) - h * h).max(0.0).sqrt();
        self.shape.distance(h, r)
    }

    /// Whether the box of `centre` ± `half` may hold a point deeper than `depth` inside the
    /// head: not wholly at or below the tip's level, not cleared by the distance bound.
    fn may_hold(&self, centre: V3, half: V3, depth: f64) -> bool {
        let d = sub(centre, self.tip);
        let h = dot(d, self.axis);
        let reach = half[0] * self.axis[0].abs()
            + half[1] * self.axis[1].abs()
            + half[2] * self.axis[2].abs();
        if h + reach <= depth {
            return false;
        }
        let r = (dot(d, d) - h * h).max(0.0).sqrt();
        let rho = norm(half);
        // A box wholly below the body's bottom by more than `depth` (its extent along the axis
        // is exact, unlike the half-diagonal: a layer's flat box grazing the body's bottom rim)
        // can only be deeper than `depth` in the cone.
        if h + reach < self.shape.body_bottom() - depth {
            return self.shape.cone_distance(h, r) - rho < -depth;
        }
        self.shape.distance(h, r) - rho < -depth
    }

    /// The feature of leaf `n` (of index `key`) if one of its quarter cells lies wholly deeper
    /// than the tolerance inside the head.
    fn leaf(&self, n: u32, key: Key) -> Option<usize> {
        let l = &self.d.leaves[n as usize];
        let depth = self.tol + GRAIN_SLACK;
        let (centre, half) = l.centres_box(key);
        if !self.may_hold(centre, half, depth) {
            return None;
        }
        let origin = key.map(|i| f64::from(i) * CELL);
        let mut mask = l.mask();
        while mask != 0 {
            let b = mask.trailing_zeros() as i32;
            mask &= mask - 1;
            let s = [b % SPLIT, (b / SPLIT) % SPLIT, b / (SPLIT * SPLIT)];
            let c: V3 = std::array::from_fn(|k| origin[k] + (f64::from(s[k]) + 0.5) * SUB);
            if self.distance(c) < -depth {
                return Some(l.feature as usize);
            }
        }
        None
    }

    /// The first quarter cell under node `n` (of `level`, 1 and up, cell index `cell` there)
    /// wholly deeper than the tolerance inside the head: its feature, and its leaf with the
    /// leaf's index.
    fn visit(&self, n: u32, level: usize, cell: Key) -> Option<(usize, (u32, Key))> {
        let node = &self.d.nodes[n as usize];
        let (centre, half) = node.centres_box();
        if !self.may_hold(centre, half, self.tol + GRAIN_SLACK) {
            return None;
        }
        (0..8).find_map(|slot| {
            let c = node.children[slot];
            if c == NONE {
                return None;
            }
            let key = child_cell(cell, slot);
            if level == 1 {
                self.leaf(c, key).map(|f| (f, (c, key)))
            } else {
                self.visit(c, level - 1, key)
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Head;

    /// The hierarchy answers as a scan of every grain's quarter cell does.
    #[test]
    fn hierarchy_agrees_with_a_scan() {
        let shape = Head::default().shape();
        let mut d = Deposit::new();
        let mut grains = vec![];
        // A wall 30 mm long, 12 mm tall, at x = 10, and a floor.
        for i in 0..60 {
            for k in 0..60 {
                let p = [10.0, -15.0 + i as f64 * 0.5, k as f64 * 0.2];
                d.add(p, 1);
                grains.push(p);
            }
            let p = [-20.0 + i as f64 * 0.7, 3.0, 0.2];
            d.add(p, 2);
            grains.push(p);
        }
        let up = [0.0, 0.0, 1.0];
        for tip in [
            [0.0, 0.0, 0.4],
            [0.0, 0.0, 5.0],
            [9.0, 0.0, 12.4],
            [10.0, 0.0, 4.0],
            [-31.0, 0.0, 0.0],
            [25.0, 25.0, 3.0],
        ] {
            // Each grain's quarter cell, by its centre.
            let scan = grains.iter().any(|&p| {
                let c = p.map(|x| ((x / SUB).floor() + 0.5) * SUB);
                let v = sub(c, tip);
                let h = dot(v, up);
                shape.distance(h, (dot(v, v) - h * h).max(0.0).sqrt()) < -0.1 - GRAIN_SLACK
            });
            assert_eq!(
                d.first_inside(&shape, tip, up, 0.1).is_some(),
                scan,
                "{tip:?}"
            );
        }
        // A sweep the whole-move test clears meets nothing at any position along it; those
        // it does not clear include every sweep that meets the wall.
        let mut cleared = 0;
        for (a, b) in [
            ([-30.0, 0.0, 0.4], [30.0, 0.0, 0.4]),
            ([-30.0, -30.0, 12.6], [30.0, 30.0, 12.6]),
            ([-30.0, 20.0, 0.4], [30.0, 20.0, 0.4]),
            ([-30.0, 40.0, 0.4], [30.0, 40.0, 0.4]),
            ([-20.0, 3.0, 0.4], [5.0, 3.0, 0.4]),
            ([0.0, 0.0, 30.0], [20.0, 0.0, 30.0]),
            ([0.0, 0.0, 80.0], [20.0, 0.0, 80.0]),
            ([40.0, -40.0, 2.0], [40.0, 40.0, 2.0]),
        ] {
            let may = d.may_meet_along(&shape, a, b, up, 0.1);
            let meets = (0..=600).any(|k| {
                let t = k as f64 / 600.0;
                let tip = std::array::from_fn(|i| a[i] + (b[i] - a[i]) * t);
                d.first_inside(&shape, tip, up, 0.1).is_some()
            });
            assert!(may || !meets, "{a:?} -> {b:?}");
            cleared += usize::from(!may);
        }
        assert!(
            cleared >= 3,
            "the test clears sweeps far from the wall: {cleared}"
        );
        // The wall's side under the body: the tip at 0.4 beside it has the wall 10 mm away.
        assert_eq!(d.first_inside(&shape, [0.0, 0.0, 0.4], up, 0.1), Some(1));
    }
}
