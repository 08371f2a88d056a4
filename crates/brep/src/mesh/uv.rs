//! Boundary points in a face's parameter domain and what is measured on them: singular
//! (pole) points and signed areas.

use crate::surface::Surface;
use crate::tolerance::SINGULAR_RATIO;

/// A boundary point of a face in its parameter domain.
#[derive(Debug, Clone, Copy)]
pub(super) struct Pt {
    pub(super) uv: [f64; 2],
    pub(super) idx: u32,
    /// 0: regular; 1: `u` is free here (`S_u = 0`); 2: `v` is free (`S_v = 0`).
    pub(super) sing: u8,
}

pub(super) fn singular_kind(s: &Surface, uv: [f64; 2]) -> u8 {
    let (su, sv) = s.derivs(uv[0], uv[1]);
    let (a, b) = (su.norm(), sv.norm());
    if a < SINGULAR_RATIO * b {
        1
    } else if b < SINGULAR_RATIO * a {
        2
    } else {
        0
    }
}

pub(super) fn signed_area(poly: &[Pt]) -> f64 {
    let n = poly.len();
    let mut a = 0.0;
    for k in 0..n {
        let p = poly[k].uv;
        let q = poly[(k + 1) % n].uv;
        a += p[0] * q[1] - q[0] * p[1];
    }
    0.5 * a
}
