//! Small vector types and placements shared by curves and surfaces.

use crate::tolerance::{NONZERO, PARALLEL};

/// A point in model space, in millimetres.
pub type P3 = nalgebra::Point3<f64>;
/// A vector in model space.
pub type V3 = nalgebra::Vector3<f64>;

/// A right-handed orthonormal frame: STEP's `AXIS2_PLACEMENT_3D`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Location of the frame.
    pub origin: P3,
    /// First axis (STEP `ref_direction`, orthogonalised against `z`).
    pub x: V3,
    /// Second axis, `z × x`.
    pub y: V3,
    /// Main axis (STEP `axis`).
    pub z: V3,
}

impl Frame {
    /// The world frame at `origin`.
    pub fn world(origin: P3) -> Self {
        Frame {
            origin,
            x: V3::x(),
            y: V3::y(),
            z: V3::z(),
        }
    }

    /// Builds a frame the way ISO 10303-42 builds an `axis2_placement_3d`: `z` defaults to +Z,
    /// `x` is the reference direction projected orthogonal to `z` (an arbitrary perpendicular when
    /// absent or parallel). Returns `None` when `z` has zero length.
    pub fn from_axes(origin: P3, z: Option<V3>, x_ref: Option<V3>) -> Option<Self> {
        let z = z.unwrap_or_else(V3::z).try_normalize(NONZERO)?;
        let x = x_ref
            .and_then(|r| (r - z * r.dot(&z)).try_normalize(PARALLEL))
            .unwrap_or_else(|| any_perpendicular(&z));
        let y = z.cross(&x);
        Some(Frame { origin, x, y, z })
    }

    /// Local coordinates of `p` in this frame.
    pub fn local(&self, p: &P3) -> V3 {
        let d = p - self.origin;
        V3::new(d.dot(&self.x), d.dot(&self.y), d.dot(&self.z))
    }

    /// The point with local coordinates `(a, b, c)`.
    pub fn at(&self, a: f64, b: f64, c: f64) -> P3 {
        self.origin + self.x * a + self.y * b + self.z * c
    }

    /// The vector with local components `(a, b, c)`.
    pub fn vec(&self, a: f64, b: f64, c: f64) -> V3 {
        self.x * a + self.y * b + self.z * c
    }
}

/// A unit vector perpendicular to the unit vector `v`.
pub fn any_perpendicular(v: &V3) -> V3 {
    let a = if v.x.abs() < 0.6 { V3::x() } else { V3::y() };
    (a - v * a.dot(v)).normalize()
}

/// Wraps `x` into `[lo, lo + period)`.
pub fn wrap(x: f64, lo: f64, period: f64) -> f64 {
    let r = (x - lo).rem_euclid(period);
    lo + r
}

/// The value `x + k·period` nearest to `reference`.
pub fn nearest_periodic(x: f64, reference: f64, period: f64) -> f64 {
    x + ((reference - x) / period).round() * period
}

/// An axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: P3,
    /// Largest corner.
    pub max: P3,
}

impl Aabb {
    /// An empty box (grows from nothing).
    pub fn empty() -> Self {
        Aabb {
            min: P3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
            max: P3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
        }
    }
    /// Grows the box to hold `p`.
    pub fn add(&mut self, p: &P3) {
        self.min = self.min.inf(p);
        self.max = self.max.sup(p);
    }
    /// Whether nothing was added.
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x
    }
    /// Whether `p` lies in the box, its faces included.
    pub fn contains(&self, p: &P3) -> bool {
        (0..3).all(|k| p[k] >= self.min[k] && p[k] <= self.max[k])
    }
    /// Length of the diagonal (0 when empty).
    pub fn diagonal(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            (self.max - self.min).norm()
        }
    }
}
