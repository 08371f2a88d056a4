//! A triangle mesh's volume, area and box.

/// Volume (signed: positive for a closed surface whose triangles run counter-clockwise seen
/// from outside), area and bounding box of a mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measures {
    /// Enclosed volume, mm³ (the divergence theorem over the triangles).
    pub volume: f64,
    /// Surface area, mm².
    pub area: f64,
    /// Least corner of the box, mm.
    pub min: [f64; 3],
    /// Greatest corner of the box, mm.
    pub max: [f64; 3],
}

/// The measures of `triangles` over `positions`.
pub fn measure(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Measures {
    let mut m = Measures {
        volume: 0.0,
        area: 0.0,
        min: [f64::INFINITY; 3],
        max: [f64::NEG_INFINITY; 3],
    };
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let (u, v) = (sub(b, a), sub(c, a));
        let n = cross(u, v);
        m.area += 0.5 * dot(n, n).sqrt();
        m.volume += dot(a, cross(b, c)) / 6.0;
        for p in [a, b, c] {
            m.min = [0, 1, 2].map(|k| m.min[k].min(p[k]));
            m.max = [0, 1, 2].map(|k| m.max[k].max(p[k]));
        }
    }
    m
}

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_unit_tetrahedron() {
        let p = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]];
        let m = super::measure(&p, &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]);
        assert!((m.volume - 1.0 / 6.0).abs() < 1e-12);
        assert!((m.area - (1.5 + 0.5 * 3f64.sqrt())).abs() < 1e-12);
        assert_eq!((m.min, m.max), ([0.0; 3], [1.0; 3]));
    }
}
