//! What is deposited: grains sampled along the beads' top centrelines, kept in an octree of
//! occupied cells (1 mm up to 64 mm), each with the tight box of its grains, so a query visits
//! only the boxes near the head's surface: a box is skipped when the head's distance bound
//! clears it, or when it lies wholly at or below the tip's level across the tool axis (the
//! layers the tip rests on).

use crate::head::HeadShape;
use std::cell::Cell;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use toolpath::vec3::{dot, norm, sub, V3};

/// Side of the finest cells, mm.
const CELL: f64 = 1.0;
/// Coarser levels above the finest: the top cells are `CELL · 2^LEVELS` (64 mm).
const LEVELS: usize = 6;
/// Largest spacing of grains along a bead, mm.
pub const GRAIN_SPACING: f64 = 0.5;

/// A cell index at some level.
type Key = [i32; 3];

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

/// A point of deposited material and the feature that laid it. Single precision: a tenth of a
/// micrometre at a metre from the origin, far below the tolerance.
#[derive(Debug, Clone, Copy)]
struct Grain {
    p: [f32; 3],
    feature: u32,
}

/// No child, no grain.
const NONE: u32 = u32::MAX;

/// A cell of the hierarchy: the tight box of the grains under it, its occupied children, and
/// (the finest cells) its grains, as an index into [`Deposit`]'s cells.
#[derive(Debug, Clone)]
struct Node {
    lo: [f32; 3],
    hi: [f32; 3],
    children: [u32; 8],
    first: u32,
}

/// The material deposited so far: an octree of cells `CELL · 2^k` on a fixed lattice, each
/// holding the tight box of its grains, under top cells found by hashing their index.
#[derive(Default)]
pub struct Deposit {
    nodes: Vec<Node>,
    /// The grains of each finest cell.
    cells: Vec<Vec<Grain>>,
    /// Top cells (side `CELL · 2^LEVELS`) by index.
    top: HashMap<Key, u32, Fast>,
    /// The top cells' nodes, in the order they were first occupied.
    roots: Vec<u32>,
    /// Highest grain, mm (−∞ when empty).
    z_max: f64,
    /// The finest cell of the last grain found inside the head: asked first next time, since
    /// the moves after a colliding one mostly meet the same material.
    hint: Cell<u32>,
}

impl Deposit {
    /// Nothing deposited.
    pub fn new() -> Deposit {
        Deposit {
            z_max: f64::NEG_INFINITY,
            hint: Cell::new(NONE),
            ..Deposit::default()
        }
    }

    /// Highest deposited grain, mm; −∞ when nothing is deposited.
    pub fn z_max(&self) -> f64 {
        self.z_max
    }

    fn node(&mut self, p: [f32; 3]) -> u32 {
        self.nodes.push(Node {
            lo: p,
            hi: p,
            children: [NONE; 8],
            first: NONE,
        });
        (self.nodes.len() - 1) as u32
    }

    /// Deposits one grain at `p`, laid by `feature`.
    pub fn add(&mut self, p: V3, feature: usize) {
        let key = p.map(|x| (x / CELL).floor() as i32);
        let top = key.map(|i| i >> LEVELS);
        let p32 = p.map(|x| x as f32);
        let mut at = match self.top.get(&top) {
            Some(&n) => n,
            None => {
                let n = self.node(p32);
                self.top.insert(top, n);
                self.roots.push(n);
                n
            }
        };
        for level in (0..=LEVELS).rev() {
            let node = &mut self.nodes[at as usize];
            node.lo = std::array::from_fn(|k| node.lo[k].min(p32[k]));
            node.hi = std::array::from_fn(|k| node.hi[k].max(p32[k]));
            if level == 0 {
                if node.first == NONE {
                    node.first = self.cells.len() as u32;
                    self.cells.push(vec![]);
                }
                self.cells[node.first as usize].push(Grain {
                    p: p32,
                    feature: feature as u32,
                });
                break;
            }
            let bit = |i: i32| ((i >> (level - 1)) & 1) as usize;
            let slot = bit(key[0]) | bit(key[1]) << 1 | bit(key[2]) << 2;
            at = match node.children[slot] {
                NONE => {
                    let n = self.node(p32);
                    self.nodes[at as usize].children[slot] = n;
                    n
                }
                n => n,
            };
        }
        self.z_max = self.z_max.max(p[2]);
    }

    /// Deposits the bead from `a` to `b` as grains at most [`GRAIN_SPACING`] apart (`b`
    /// included, `a` not: it ends the bead before).
    pub fn add_bead(&mut self, a: V3, b: V3, feature: usize) {
        let n = (norm(sub(b, a)) / GRAIN_SPACING).ceil().clamp(1.0, 1e5) as usize;
        for k in 1..=n {
            let t = k as f64 / n as f64;
            self.add(std::array::from_fn(|i| a[i] + (b[i] - a[i]) * t), feature);
        }
    }

    /// The feature of a grain lying more than `tol` inside the head with its tip at `tip` and
    /// unit tool axis `axis`, if any.
    pub fn first_inside(&self, shape: &HeadShape, tip: V3, axis: V3, tol: f64) -> Option<usize> {
        let q = Query {
            d: self,
            shape,
            tip,
            axis,
            tol,
        };
        let hint = self.hint.get();
        if hint != NONE {
            if let Some(f) = q.grains(&self.nodes[hint as usize]) {
                return Some(f);
            }
        }
        let found = self.roots.iter().find_map(|&n| q.visit(n));
        if let Some((f, leaf)) = found {
            self.hint.set(leaf);
            return Some(f);
        }
        None
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

    /// The feature of the first grain of the finest cell `node` deeper than the tolerance
    /// inside the head.
    fn grains(&self, node: &Node) -> Option<usize> {
        self.d.cells[node.first as usize]
            .iter()
            .find(|g| self.distance(g.p.map(f64::from)) < -self.tol)
            .map(|g| g.feature as usize)
    }

    /// The first grain under node `n` deeper than the tolerance inside the head: its feature
    /// and its finest cell.
    fn visit(&self, n: u32) -> Option<(usize, u32)> {
        let node = &self.d.nodes[n as usize];
        let centre: V3 = std::array::from_fn(|k| 0.5 * f64::from(node.lo[k] + node.hi[k]));
        // Half the box, a little more for the single-precision corners.
        let half: V3 = std::array::from_fn(|k| 0.5 * f64::from(node.hi[k] - node.lo[k]) + 1e-4);
        // Every grain of the box lies at or below the tip's level (the layers under it).
        let h = dot(sub(centre, self.tip), self.axis);
        let reach = half[0] * self.axis[0].abs()
            + half[1] * self.axis[1].abs()
            + half[2] * self.axis[2].abs();
        if h + reach <= self.tol {
            return None;
        }
        // No point of the box lies deeper than the tolerance inside the head.
        if self.distance(centre) - norm(half) >= -self.tol {
            return None;
        }
        if node.first != NONE {
            return self.grains(node).map(|f| (f, n));
        }
        node.children
            .iter()
            .filter(|&&c| c != NONE)
            .find_map(|&c| self.visit(c))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Head;

    /// The hierarchy answers as a scan of every grain does.
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
            let scan = grains.iter().any(|&p| {
                let v = sub(p, tip);
                let h = dot(v, up);
                shape.distance(h, (dot(v, v) - h * h).max(0.0).sqrt()) < -0.1
            });
            assert_eq!(
                d.first_inside(&shape, tip, up, 0.1).is_some(),
                scan,
                "{tip:?}"
            );
        }
        // The wall's side under the body: the tip at 0.4 beside it has the wall 10 mm away.
        assert_eq!(d.first_inside(&shape, [0.0, 0.0, 0.4], up, 0.1), Some(1));
    }
}
