//! A rigid placement of a body (an assembly's component): what the reader applies to every
//! point and direction it reads while the body is placed.

use crate::math::{Frame, P3, V3};
use crate::tolerance::{ROTATION_EQUAL, ROTATION_IDENTITY, SHIFT_ZERO};
use nalgebra::Matrix3;

/// A rigid placement: `p -> rot * p + shift` (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Placement {
    pub(super) rot: Matrix3<f64>,
    pub(super) shift: V3,
}

impl Placement {
    pub(super) fn identity() -> Self {
        Placement {
            rot: Matrix3::identity(),
            shift: V3::zeros(),
        }
    }

    /// The rotation of matrix `m` (rows first) about the origin.
    pub(super) fn rotation(m: [[f64; 3]; 3]) -> Self {
        Placement {
            rot: Matrix3::from_fn(|r, c| m[r][c]),
            shift: V3::zeros(),
        }
    }

    /// The placement taking `from`'s frame onto `to`'s.
    pub(super) fn between(from: &Frame, to: &Frame) -> Self {
        let a = Matrix3::from_columns(&[from.x, from.y, from.z]);
        let b = Matrix3::from_columns(&[to.x, to.y, to.z]);
        let rot = b * a.transpose();
        Placement {
            rot,
            shift: to.origin.coords - rot * from.origin.coords,
        }
    }

    /// `self` after `inner`: a point placed by `inner`, then by `self`.
    pub(super) fn then(&self, inner: &Placement) -> Self {
        Placement {
            rot: self.rot * inner.rot,
            shift: self.rot * inner.shift + self.shift,
        }
    }

    pub(super) fn point(&self, p: P3) -> P3 {
        P3::from(self.rot * p.coords + self.shift)
    }

    pub(super) fn dir(&self, v: V3) -> V3 {
        self.rot * v
    }

    pub(super) fn is_identity(&self) -> bool {
        (self.rot - Matrix3::identity()).abs().max() < ROTATION_IDENTITY
            && self.shift.norm() < SHIFT_ZERO
    }

    pub(super) fn near(&self, o: &Placement) -> bool {
        (self.rot - o.rot).abs().max() < ROTATION_EQUAL && (self.shift - o.shift).norm() < 1e-6
    }
}
