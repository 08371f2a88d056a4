//! What is deposited: grains sampled along the beads' top centrelines, kept in a hierarchy of
//! occupied cells (1 mm up to 64 mm) so a query visits only the cells near the head's surface
//! and skips whole boxes the head's distance bound clears.

use crate::head::HeadShape;
use std::collections::{HashMap, HashSet};
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

/// A point of deposited material and the feature that laid it.
#[derive(Debug, Clone, Copy)]
struct Grain {
    p: V3,
    feature: usize,
}

/// The material deposited so far.
#[derive(Default)]
pub struct Deposit {
    /// Finest cells and their grains.
    cells: HashMap<Key, Vec<Grain>, Fast>,
    /// `coarse[k]`: occupied cells of side `CELL · 2^(k+1)`.
    coarse: Vec<HashSet<Key, Fast>>,
    /// The top level's cells, in the order they were first occupied.
    top: Vec<Key>,
    /// Highest grain, mm (−∞ when empty).
    z_max: f64,
}

impl Deposit {
    /// Nothing deposited.
    pub fn new() -> Deposit {
        Deposit {
            coarse: vec![HashSet::default(); LEVELS],
            z_max: f64::NEG_INFINITY,
            ..Deposit::default()
        }
    }

    /// Highest deposited grain, mm; −∞ when nothing is deposited.
    pub fn z_max(&self) -> f64 {
        self.z_max
    }

    /// Deposits one grain at `p`, laid by `feature`.
    pub fn add(&mut self, p: V3, feature: usize) {
        let key = p.map(|x| (x / CELL).floor() as i32);
        self.cells
            .entry(key)
            .or_default()
            .push(Grain { p, feature });
        for (k, level) in self.coarse.iter_mut().enumerate() {
            let up = key.map(|i| i >> (k + 1));
            if !level.insert(up) {
                break;
            }
            if k + 1 == LEVELS {
                self.top.push(up);
            }
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
        self.top.iter().find_map(|&key| q.visit(LEVELS, key))
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

    /// The occupied cell `key` of `level` (0 the finest), known to be occupied.
    fn visit(&self, level: usize, key: Key) -> Option<usize> {
        let size = CELL * (1u32 << level) as f64;
        let centre = key.map(|i| (i as f64 + 0.5) * size);
        let rho = size * 0.5 * 3f64.sqrt();
        // No point of the box lies deeper than `tol` inside the head.
        if self.distance(centre) - rho >= -self.tol {
            return None;
        }
        if level == 0 {
            let grains = self.d.cells.get(&key)?;
            return grains
                .iter()
                .find(|g| self.distance(g.p) < -self.tol)
                .map(|g| g.feature);
        }
        for c in 0..8 {
            let child = [
                key[0] * 2 + (c & 1),
                key[1] * 2 + ((c >> 1) & 1),
                key[2] * 2 + ((c >> 2) & 1),
            ];
            let occupied = if level == 1 {
                self.d.cells.contains_key(&child)
            } else {
                self.d.coarse[level - 2].contains(&child)
            };
            if occupied {
                if let Some(f) = self.visit(level - 1, child) {
                    return Some(f);
                }
            }
        }
        None
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
