//! The machine's table as the head sees it, in part coordinates: a plane under the part (a
//! robot cell's table, a 3-axis bed) or a disc that tilts and turns with the part (a B/C bed),
//! so stays fixed in the part's frame.

use crate::head::HeadShape;
use toolpath::vec3::{add, scale, V3};

/// The table, in part coordinates. Its surface is the plane `z` (the lowest bead bottom).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Table {
    /// An unbounded plane at height `z`.
    Plane {
        /// Height of the table surface, mm.
        z: f64,
    },
    /// A disc of `radius` about `centre` (XY) at height `z`: the table of a B/C bed, which moves
    /// with the part.
    Disc {
        /// XY of the disc's centre (the C axis), mm.
        centre: [f64; 2],
        /// Height of the table surface, mm.
        z: f64,
        /// Radius of the disc, mm.
        radius: f64,
    },
}

/// The height of the lowest point of the head with its tip at height `tip_z` and unit tool
/// axis `axis`: on one of its rims ([`HeadShape::rims`]).
fn lowest(shape: &HeadShape, tip_z: f64, axis: V3) -> f64 {
    let side = (1.0 - axis[2] * axis[2]).max(0.0).sqrt();
    shape
        .rims()
        .iter()
        .map(|&(h, r)| tip_z + h * axis[2] - r * side)
        .fold(f64::INFINITY, f64::min)
}

/// Points sampled around a rim of the head when it reaches below the table surface.
const RIM_SAMPLES: usize = 32;

/// `(cos t, sin t)` at the rim samples' angles `t = 2πk / RIM_SAMPLES`, computed once.
fn rim_angles() -> &'static [(f64, f64); RIM_SAMPLES] {
    static ANGLES: std::sync::OnceLock<[(f64, f64); RIM_SAMPLES]> = std::sync::OnceLock::new();
    ANGLES.get_or_init(|| {
        std::array::from_fn(|k| {
            let t = std::f64::consts::TAU * k as f64 / RIM_SAMPLES as f64;
            (t.cos(), t.sin())
        })
    })
}

impl Table {
    /// Whether the head with its tip at `tip` and unit tool axis `axis` reaches more than `tol`
    /// below the table surface (within the disc). The head's lowest points lie on its rims
    /// (the circles of [`HeadShape::rims`]); those are checked exactly against the plane, and,
    /// for a disc, sampled where they are below it.
    pub fn hits(&self, shape: &HeadShape, tip: V3, axis: V3, tol: f64) -> bool {
        let z = self.surface();
        if lowest(shape, tip[2], axis) >= z - tol {
            return false;
        }
        self.hits_below(shape, tip, axis, tol)
    }

    /// Whether the head with its tip anywhere on the segment from `a` to `b` and the unit tool
    /// axis `axis` all along stays more than a hair above `tol` below the table surface (its
    /// lowest point rises and falls with the tip's height): then [`Table::hits`] is false at
    /// every tip on it.
    pub fn clear_along(&self, shape: &HeadShape, a: V3, b: V3, axis: V3, tol: f64) -> bool {
        lowest(shape, a[2].min(b[2]), axis) >= self.surface() - tol + 1e-5
    }

    /// How far (mm) the head with its tip at `tip` and unit tool axis `axis` reaches below the
    /// table's surface (the plane's; 0 when it does not): the lift along +Z that brings its
    /// lowest point up onto the surface.
    pub fn depth_below(&self, shape: &HeadShape, tip: V3, axis: V3) -> f64 {
        (self.surface() - lowest(shape, tip[2], axis)).max(0.0)
    }

    /// The table's surface's height, mm.
    pub fn surface(&self) -> f64 {
        match *self {
            Table::Plane { z } | Table::Disc { z, .. } => z,
        }
    }

    /// [`Table::hits`] once the head's lowest point is below the surface by more than `tol`.
    fn hits_below(&self, shape: &HeadShape, tip: V3, axis: V3, tol: f64) -> bool {
        let (z, disc) = match *self {
            Table::Plane { z } => (z, None),
            Table::Disc { centre, z, radius } => (z, Some((centre, radius))),
        };
        let Some((centre, radius)) = disc else {
            return true;
        };
        // Two directions across the axis.
        let u = if axis[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let u = toolpath::vec3::unit(toolpath::vec3::sub(
            u,
            scale(axis, toolpath::vec3::dot(u, axis)),
        ))
        .unwrap_or([1.0, 0.0, 0.0]);
        let v = toolpath::vec3::cross(axis, u);
        for &(h, r) in &shape.rims() {
            let c = add(tip, scale(axis, h));
            for &(cos, sin) in rim_angles() {
                let p = add(c, add(scale(u, r * cos), scale(v, r * sin)));
                if p[2] < z - tol && (p[0] - centre[0]).hypot(p[1] - centre[1]) <= radius {
                    return true;
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Head;

    #[test]
    fn a_tilted_head_meets_the_table_near_it_only() {
        let s = Head::default().shape();
        let up = [0.0, 0.0, 1.0];
        let plane = Table::Plane { z: 0.0 };
        assert!(!plane.hits(&s, [0.0, 0.0, 0.2], up, 0.1));
        // Tilted 80° next to the table: the body's rim dips below it.
        let a = 80f64.to_radians();
        let tilted = [a.sin(), 0.0, a.cos()];
        assert!(plane.hits(&s, [0.0, 0.0, 0.2], tilted, 0.1));
        let disc = Table::Disc {
            centre: [0.0, 0.0],
            z: 0.0,
            radius: 100.0,
        };
        assert!(disc.hits(&s, [0.0, 0.0, 0.2], tilted, 0.1));
        // Far beyond the disc's edge the same tilt is clear.
        assert!(!disc.hits(&s, [300.0, 0.0, 0.2], tilted, 0.1));
        // A segment cleared whole has no tip on it that hits; one dipping under is not cleared.
        for (a, b, axis) in [
            ([0.0, 0.0, 0.2], [50.0, 0.0, 0.2], up),
            ([0.0, 0.0, 0.2], [50.0, 0.0, -0.5], up),
            ([0.0, 0.0, 30.0], [50.0, 0.0, 20.0], tilted),
            ([0.0, 0.0, 1.0], [50.0, 0.0, 0.5], tilted),
        ] {
            for table in [plane, disc] {
                let hits = (1..=100).any(|k| {
                    let t = k as f64 / 100.0;
                    let tip = std::array::from_fn(|i| a[i] + (b[i] - a[i]) * t);
                    table.hits(&s, tip, axis, 0.1)
                });
                assert!(!(hits && table.clear_along(&s, a, b, axis, 0.1)));
            }
        }
        assert!(plane.clear_along(&s, [0.0, 0.0, 0.2], [50.0, 0.0, 0.2], up, 0.1));
        assert!(!plane.clear_along(&s, [0.0, 0.0, 0.2], [50.0, 0.0, -0.5], up, 0.1));
    }
}
