//! The machine around a refused plan: its bed or turning table (grey, translucent) and the
//! print head where the first failure is (red, translucent), as triangles and wire lines the
//! viewer draws as they are.

use crate::encode::base64_f32;
use crate::tolerance::AXIS_MIN_LENGTH;

/// Segments of a circle drawn (the table's rim, the head's rings).
const CIRCLE_SEGMENTS: usize = 48;

/// Lines drawn across a bed each way (a grid of this many cells).
const BED_GRID_CELLS: usize = 10;

/// Generator lines drawn along the head's cone and body.
const HEAD_GENERATORS: usize = 8;

/// Largest cone half-angle drawn (degrees): a wider one would be a flat disc at infinity.
const MAX_HALF_ANGLE_DEG: f64 = 85.0;

/// The machine's bed or table, in the tool path's frame (part coordinates, mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MachineShape {
    /// A flat bed: the rectangle `min`..`max` (XY) at height `z`.
    Bed {
        /// The rectangle's least corner (XY), mm.
        min: [f64; 2],
        /// The rectangle's greatest corner (XY), mm.
        max: [f64; 2],
        /// Height of the bed's surface, mm.
        z: f64,
    },
    /// A turning table (delta5's B/C bed): a disc of `radius` about `centre` (XY) at height
    /// `z`, fixed in the part's frame since it turns with the part.
    Table {
        /// XY of the disc's centre (the C axis), mm.
        centre: [f64; 2],
        /// Height of the table's surface, mm.
        z: f64,
        /// Radius of the disc, mm.
        radius: f64,
    },
}

/// The print head at one pose, in the tool path's frame (part coordinates, mm and degrees): a
/// cone from the tip up the tool axis, then a cylinder (the body), as the machine profile's
/// `[head]` table and `collide::Head` describe it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadShape {
    /// The nozzle's tip, mm.
    pub tip: [f64; 3],
    /// The tool axis: unit, from the tip towards the body (normalised when drawn; +Z if zero).
    pub axis: [f64; 3],
    /// Radius of the cone at the tip, mm.
    pub tip_radius: f64,
    /// Half-angle of the cone, degrees (drawn up to 85°).
    pub half_angle_deg: f64,
    /// Length of the cone up the axis from the tip, mm.
    pub cone_length: f64,
    /// Radius of the body cylinder, mm.
    pub body_radius: f64,
    /// The body's top, measured from the tip up the axis (as `collide::Head::body_length`, not
    /// from the cone's top): the body spans `cone_length..body_length`; none is drawn when this
    /// is not above `cone_length`.
    pub body_length: f64,
}

/// The print head's figures, without a pose (as the machine profile's `[head]` table): a
/// [`HeadShape`] once placed at a tip along an axis ([`HeadSize::at`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadSize {
    /// Radius of the cone at the tip, mm.
    pub tip_radius: f64,
    /// Half-angle of the cone, degrees.
    pub half_angle_deg: f64,
    /// Length of the cone up the axis from the tip, mm.
    pub cone_length: f64,
    /// Radius of the body cylinder, mm.
    pub body_radius: f64,
    /// The body's top, measured from the tip up the axis, mm.
    pub body_length: f64,
}

impl HeadSize {
    /// The head with its tip at `tip` and its axis (tip towards body) along `axis`.
    pub fn at(&self, tip: [f64; 3], axis: [f64; 3]) -> HeadShape {
        HeadShape {
            tip,
            axis,
            tip_radius: self.tip_radius,
            half_angle_deg: self.half_angle_deg,
            cone_length: self.cone_length,
            body_radius: self.body_radius,
            body_length: self.body_length,
        }
    }
}

/// Triangles (9 floats each) and line segments (6 floats each) to draw.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Overlay {
    /// Triangle corners, xyz each.
    pub tri: Vec<f32>,
    /// Segment ends, xyz each.
    pub lines: Vec<f32>,
}

impl Overlay {
    fn triangle(&mut self, a: [f64; 3], b: [f64; 3], c: [f64; 3]) {
        self.tri
            .extend([a, b, c].iter().flatten().map(|&x| x as f32));
    }

    fn line(&mut self, a: [f64; 3], b: [f64; 3]) {
        self.lines
            .extend([a, b].iter().flatten().map(|&x| x as f32));
    }

    /// The overlay as the viewer reads it, or `null` when there is nothing to draw.
    pub fn json(&self) -> serde_json::Value {
        if self.tri.is_empty() && self.lines.is_empty() {
            return serde_json::Value::Null;
        }
        serde_json::json!({ "tri": base64_f32(&self.tri), "lines": base64_f32(&self.lines) })
    }
}

/// The unit circle's points at `CIRCLE_SEGMENTS + 1` angles (the first repeated last).
fn circle() -> impl Iterator<Item = (f64, f64)> {
    (0..=CIRCLE_SEGMENTS).map(|k| {
        let t = std::f64::consts::TAU * k as f64 / CIRCLE_SEGMENTS as f64;
        (t.cos(), t.sin())
    })
}

/// The bed or table as a translucent surface and its outline: a bed with a grid, a table with
/// its rim and two diameters. Nothing for a shape with a non-finite figure.
pub(crate) fn machine_overlay(m: &MachineShape) -> Overlay {
    let mut o = Overlay::default();
    match *m {
        MachineShape::Bed { min, max, z } => {
            if !min.iter().chain(&max).chain([&z]).all(|x| x.is_finite()) {
                return o;
            }
            let (x0, x1) = (min[0].min(max[0]), min[0].max(max[0]));
            let (y0, y1) = (min[1].min(max[1]), min[1].max(max[1]));
            o.triangle([x0, y0, z], [x1, y0, z], [x1, y1, z]);
            o.triangle([x0, y0, z], [x1, y1, z], [x0, y1, z]);
            for k in 0..=BED_GRID_CELLS {
                let t = k as f64 / BED_GRID_CELLS as f64;
                let x = x0 + t * (x1 - x0);
                let y = y0 + t * (y1 - y0);
                o.line([x, y0, z], [x, y1, z]);
                o.line([x0, y, z], [x1, y, z]);
            }
        }
        MachineShape::Table { centre, z, radius } => {
            if !centre.iter().chain([&z, &radius]).all(|x| x.is_finite()) {
                return o;
            }
            let r = radius.abs();
            let at = |c: f64, s: f64| [centre[0] + r * c, centre[1] + r * s, z];
            let rim: Vec<[f64; 3]> = circle().map(|(c, s)| at(c, s)).collect();
            let mid = [centre[0], centre[1], z];
            for w in rim.windows(2) {
                o.triangle(mid, w[0], w[1]);
                o.line(w[0], w[1]);
            }
            o.line(at(-1.0, 0.0), at(1.0, 0.0));
            o.line(at(0.0, -1.0), at(0.0, 1.0));
        }
    }
    o
}

/// Two unit vectors across the unit `a`, and `a`: a right-handed frame.
fn frame(a: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let helper = if a[2].abs() < 0.9 {
        [0.0, 0.0, 1.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let cross = |p: [f64; 3], q: [f64; 3]| {
        [
            p[1] * q[2] - p[2] * q[1],
            p[2] * q[0] - p[0] * q[2],
            p[0] * q[1] - p[1] * q[0],
        ]
    };
    let u = cross(a, helper);
    let l = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let u = [u[0] / l, u[1] / l, u[2] / l];
    (u, cross(a, u))
}

/// The head as a translucent solid (the cone's side, the body's underside, side and top) and a
/// wire frame (its rims and a few generators). Nothing for a head with a non-finite figure.
pub(crate) fn head_overlay(h: &HeadShape) -> Overlay {
    let mut o = Overlay::default();
    let figures = [
        h.tip_radius,
        h.half_angle_deg,
        h.cone_length,
        h.body_radius,
        h.body_length,
    ];
    if !h
        .tip
        .iter()
        .chain(&h.axis)
        .chain(&figures)
        .all(|x| x.is_finite())
    {
        return o;
    }
    let l = (h.axis[0] * h.axis[0] + h.axis[1] * h.axis[1] + h.axis[2] * h.axis[2]).sqrt();
    let a = if l > AXIS_MIN_LENGTH {
        [h.axis[0] / l, h.axis[1] / l, h.axis[2] / l]
    } else {
        [0.0, 0.0, 1.0]
    };
    let (u, v) = frame(a);
    let at = |height: f64, r: f64, (c, s): (f64, f64)| {
        let mut p = h.tip;
        for k in 0..3 {
            p[k] += height * a[k] + r * (c * u[k] + s * v[k]);
        }
        p
    };
    let cone = h.cone_length.max(0.0);
    let tan = h
        .half_angle_deg
        .clamp(0.0, MAX_HALF_ANGLE_DEG)
        .to_radians()
        .tan();
    let tip_r = h.tip_radius.abs();
    let mut bands = vec![(0.0, tip_r, cone, tip_r + cone * tan)];
    if h.body_length > cone {
        let br = h.body_radius.abs();
        bands.push((cone, tip_r + cone * tan, cone, br));
        bands.push((cone, br, h.body_length, br));
        bands.push((h.body_length, br, h.body_length, 0.0));
    }
    let ring: Vec<(f64, f64)> = circle().collect();
    for &(h0, r0, h1, r1) in &bands {
        for w in ring.windows(2) {
            let (p, q) = (at(h0, r0, w[0]), at(h0, r0, w[1]));
            let (pp, qq) = (at(h1, r1, w[0]), at(h1, r1, w[1]));
            o.triangle(p, q, qq);
            o.triangle(p, qq, pp);
            o.line(p, q);
            o.line(pp, qq);
        }
        for k in 0..HEAD_GENERATORS {
            let c = ring[k * CIRCLE_SEGMENTS / HEAD_GENERATORS];
            o.line(at(h0, r0, c), at(h1, r1, c));
        }
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points of the overlay's triangles.
    fn corners(o: &Overlay) -> Vec<[f64; 3]> {
        o.tri
            .chunks(3)
            .map(|c| [f64::from(c[0]), f64::from(c[1]), f64::from(c[2])])
            .collect()
    }

    /// Tolerance of the f32 coordinates drawn, mm.
    const F32_TOL: f64 = 1e-4;

    #[test]
    fn a_tilted_head_lies_within_its_cone_and_body() {
        let s = 0.5f64.sqrt();
        let h = HeadShape {
            tip: [10.0, -4.0, 2.0],
            axis: [s, 0.0, s],
            tip_radius: 0.5,
            half_angle_deg: 30.0,
            cone_length: 8.0,
            body_radius: 20.0,
            body_length: 60.0,
        };
        let o = head_overlay(&h);
        assert!(!o.tri.is_empty() && !o.lines.is_empty());
        let cone_top = 0.5 + 8.0 * 30f64.to_radians().tan();
        let (mut highest, mut widest) = (0.0f64, 0.0f64);
        for p in corners(&o) {
            let d = [p[0] - h.tip[0], p[1] - h.tip[1], p[2] - h.tip[2]];
            let along = d[0] * s + d[2] * s;
            let r = ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - along * along)
                .max(0.0)
                .sqrt();
            assert!(along > -F32_TOL && along < 60.0 + F32_TOL, "{along}");
            let limit = if along < 8.0 - F32_TOL {
                0.5 + along * 30f64.to_radians().tan()
            } else {
                20.0f64.max(cone_top)
            };
            assert!(r < limit + F32_TOL, "r {r} at {along}");
            highest = highest.max(along);
            widest = widest.max(r);
        }
        assert!((highest - 60.0).abs() < F32_TOL && (widest - 20.0).abs() < F32_TOL);
    }

    #[test]
    fn a_table_is_a_disc_of_its_radius_and_a_bed_its_rectangle() {
        let t = machine_overlay(&MachineShape::Table {
            centre: [5.0, 5.0],
            z: -1.0,
            radius: 30.0,
        });
        let area: f64 = corners(&t)
            .chunks(3)
            .map(|c| {
                let (a, b) = (
                    [c[1][0] - c[0][0], c[1][1] - c[0][1]],
                    [c[2][0] - c[0][0], c[2][1] - c[0][1]],
                );
                (a[0] * b[1] - a[1] * b[0]).abs() / 2.0
            })
            .sum();
        let disc = std::f64::consts::PI * 30.0 * 30.0;
        // An inscribed 48-gon holds all but 0.3 % of the disc.
        assert!(area < disc && area > 0.99 * disc, "{area} of {disc}");
        assert!(corners(&t).iter().all(|p| (p[2] + 1.0).abs() < F32_TOL));
        let b = machine_overlay(&MachineShape::Bed {
            min: [-100.0, -50.0],
            max: [100.0, 50.0],
            z: 0.0,
        });
        let xs: Vec<f64> = corners(&b).iter().map(|p| p[0]).collect();
        assert_eq!(xs.iter().cloned().fold(f64::INFINITY, f64::min), -100.0);
        assert_eq!(xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max), 100.0);
        let bad = machine_overlay(&MachineShape::Bed {
            min: [f64::NAN, 0.0],
            max: [1.0, 1.0],
            z: 0.0,
        });
        assert_eq!(bad.json(), serde_json::Value::Null);
    }
}
