//! Plane sections of a closed triangle mesh: the exact cross-section of the meshed solid.
//!
//! Every mesh edge that crosses the plane is shared by two triangles, so the segments each
//! triangle contributes chain into closed loops through the edges' crossing points. Vertices
//! exactly on the plane are taken as lying just above it (a symbolic perturbation), so no
//! segment degenerates. Loops run counter-clockwise about the plane normal around material
//! (outer boundaries) and clockwise around holes.

use crate::math::{any_perpendicular, P3, V3};
use crate::mesh::Mesh;
use crate::tolerance::NONZERO;
use std::collections::HashMap;

/// A plane with an in-plane frame, for 2-D coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// A point of the plane.
    pub origin: P3,
    /// Unit normal.
    pub normal: V3,
    /// First in-plane axis.
    pub u: V3,
    /// Second in-plane axis, `normal × u`.
    pub v: V3,
}

impl Plane {
    /// The plane through `origin` with unit normal `normal`; its `u` axis is world X projected
    /// into the plane (or Y when X is nearly normal to it).
    pub fn new(origin: P3, normal: V3) -> Self {
        let n = normal.try_normalize(NONZERO).unwrap_or_else(V3::z);
        let u = [V3::x(), V3::y()]
            .iter()
            .map(|a| a - n * a.dot(&n))
            .find(|a| a.norm() > 1e-3)
            .map(|a| a.normalize())
            .unwrap_or_else(|| any_perpendicular(&n));
        Plane {
            origin,
            normal: n,
            u,
            v: n.cross(&u),
        }
    }
    /// The same frame moved along the normal by `d`.
    pub fn offset(&self, d: f64) -> Plane {
        Plane {
            origin: self.origin + self.normal * d,
            ..*self
        }
    }
    /// Signed distance of `p` above the plane.
    pub fn height(&self, p: &P3) -> f64 {
        (p - self.origin).dot(&self.normal)
    }
    /// In-plane coordinates of `p` (projected).
    pub fn to_2d(&self, p: &P3) -> [f64; 2] {
        let d = p - self.origin;
        [d.dot(&self.u), d.dot(&self.v)]
    }
    /// The point of the plane at in-plane coordinates `q`, lifted by `h` along the normal.
    pub fn to_3d(&self, q: [f64; 2], h: f64) -> P3 {
        self.origin + self.u * q[0] + self.v * q[1] + self.normal * h
    }
}

/// The closed loops where `plane` cuts the mesh, as 3-D points on the plane. Open chains (a
/// mesh that is not closed) are dropped.
pub fn section(mesh: &Mesh, plane: &Plane) -> Vec<Vec<P3>> {
    let d: Vec<f64> = mesh.positions.iter().map(|p| plane.height(p)).collect();
    let above = |i: u32| d[i as usize] >= 0.0;
    let cross = |a: u32, b: u32| -> P3 {
        let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
        let (da, db) = (d[a as usize], d[b as usize]);
        let t = if (da - db).abs() > 0.0 {
            da / (da - db)
        } else {
            0.5
        };
        pa + (pb - pa) * t.clamp(0.0, 1.0)
    };
    // Segment from the crossing on one edge to the crossing on another, keyed by edges.
    let mut next: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
    let mut point: HashMap<(u32, u32), P3> = HashMap::new();
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    for t in mesh.triangles() {
        // The lone vertex on its side, then the other two in triangle order.
        let Some(lone) = lone_vertex([above(t[0]), above(t[1]), above(t[2])]) else {
            continue;
        };
        let (a, b, c) = (t[lone], t[(lone + 1) % 3], t[(lone + 2) % 3]);
        let (e1, e2) = (key(a, b), key(a, c));
        let (p1, p2) = (cross(a, b), cross(a, c));
        point.insert(e1, p1);
        point.insert(e2, p2);
        // Orient so material is on the left looking down the normal, i.e. along normal × N_t
        // for the triangle's outward normal N_t: for a triangle wound counter-clockwise about
        // N_t, from the crossing on (a, b) to the one on (a, c) when the lone vertex is above,
        // the other way when it is below. Read from the winding, not from the crossing points,
        // which coincide where the level runs through a vertex.
        if above(a) {
            next.insert(e1, e2);
        } else {
            next.insert(e2, e1);
        }
    }
    let mut loops = vec![];
    let mut used: std::collections::HashSet<(u32, u32)> = std::collections::HashSet::new();
    let mut starts: Vec<(u32, u32)> = next.keys().copied().collect();
    starts.sort_unstable();
    for s in starts {
        if used.contains(&s) {
            continue;
        }
        let mut lp = vec![];
        let mut k = s;
        let closed = loop {
            if !used.insert(k) {
                break k == s;
            }
            lp.push(point[&k]);
            match next.get(&k) {
                Some(&n) => k = n,
                None => break false,
            }
        };
        if closed && lp.len() >= 3 {
            loops.push(lp);
        }
    }
    loops
}

/// Signed area of a closed 2-D polygon (positive counter-clockwise).
pub fn signed_area(poly: &[[f64; 2]]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|k| {
            let (p, q) = (poly[k], poly[(k + 1) % n]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum::<f64>()
        * 0.5
}

/// The vertex of a triangle alone on its side of a level (`up`: each vertex at or above
/// it), or `None` when all three are on one side and the level misses the triangle: the
/// level crosses the two edges at that vertex.
pub fn lone_vertex(up: [bool; 3]) -> Option<usize> {
    (0..3).find(|&k| up[k] != up[(k + 1) % 3] && up[k] != up[(k + 2) % 3])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{mesh_faces, MeshOptions};

    fn fixture(name: &str) -> crate::StepPart {
        let p = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures")
            .join(name);
        crate::read_step(p).expect("fixture")
    }

    #[test]
    fn box_section_is_one_ccw_rectangle_of_the_right_area() {
        let part = fixture("box.step");
        let b = &part.brep;
        let m = mesh_faces(
            b,
            &b.solid_faces(crate::topology::SolidId(0)),
            &MeshOptions::default(),
        )
        .expect("mesh");
        let bb = m.bbox();
        let plane = Plane::new(P3::new(0.0, 0.0, 0.5 * (bb.min.z + bb.max.z)), V3::z());
        let loops = section(&m, &plane);
        assert_eq!(loops.len(), 1);
        let poly: Vec<[f64; 2]> = loops[0].iter().map(|p| plane.to_2d(p)).collect();
        let want = (bb.max.x - bb.min.x) * (bb.max.y - bb.min.y);
        assert!(
            (signed_area(&poly) - want).abs() < 1e-9 * want,
            "{} vs {want}",
            signed_area(&poly)
        );
    }

    #[test]
    fn levels_through_mesh_vertices_still_close_every_loop() {
        // A level through a ring of the mesh's own vertices (the middle row of a cylinder's
        // grid) makes crossing points coincide; each loop must still close.
        let part = fixture("cylinder.step");
        let b = &part.brep;
        let m = mesh_faces(
            b,
            &b.solid_faces(crate::topology::SolidId(0)),
            &MeshOptions::with_tolerance(0.0125),
        )
        .expect("mesh");
        let bb = m.bbox();
        let mut levels: Vec<f64> = m
            .positions
            .iter()
            .map(|p| p.z)
            .filter(|z| *z > bb.min.z + 1e-6 && *z < bb.max.z - 1e-6)
            .collect();
        levels.sort_by(f64::total_cmp);
        levels.dedup();
        assert!(!levels.is_empty(), "the mesh has vertices between its ends");
        for z in levels {
            let plane = Plane::new(P3::new(0.0, 0.0, z), V3::z());
            let loops = section(&m, &plane);
            assert_eq!(loops.len(), 1, "level {z}");
            let poly: Vec<[f64; 2]> = loops[0].iter().map(|p| plane.to_2d(p)).collect();
            let want = 0.25 * (bb.max.x - bb.min.x) * (bb.max.y - bb.min.y) * std::f64::consts::PI;
            assert!((signed_area(&poly) - want).abs() < 1e-2 * want, "level {z}");
        }
    }

    #[test]
    fn sections_of_a_plate_with_a_hole_have_an_outer_loop_and_a_clockwise_hole() {
        // inch_block: a block with a through hole; the section through the block has a CCW outer
        // boundary and a CW hole whose areas add up to the block's cross-section less the hole.
        let part = fixture("inch_block.step");
        let b = &part.brep;
        let m = mesh_faces(
            b,
            &b.solid_faces(crate::topology::SolidId(0)),
            &MeshOptions::with_tolerance(0.001),
        )
        .expect("mesh");
        let plane = Plane::new(P3::new(0.0, 0.0, 6.0), V3::z());
        let loops = section(&m, &plane);
        let areas: Vec<f64> = loops
            .iter()
            .map(|l| signed_area(&l.iter().map(|p| plane.to_2d(p)).collect::<Vec<_>>()))
            .collect();
        assert_eq!(loops.len(), 2, "{areas:?}");
        let outer = areas.iter().cloned().fold(f64::MIN, f64::max);
        let hole = areas.iter().cloned().fold(f64::MAX, f64::min);
        assert!(outer > 0.0 && hole < 0.0);
        let r = 0.375 * 25.4 / 2.0;
        assert!((outer - 50.8 * 38.1).abs() < 1e-6 * outer);
        assert!(
            (hole + std::f64::consts::PI * r * r).abs() < 1e-3 * (std::f64::consts::PI * r * r),
            "hole {hole}"
        );
    }

    #[test]
    fn tilted_plane_through_a_sphere_gives_a_circle() {
        let part = fixture("sphere.step");
        let b = &part.brep;
        let m = mesh_faces(
            b,
            &b.solid_faces(crate::topology::SolidId(0)),
            &MeshOptions::with_tolerance(0.001),
        )
        .expect("mesh");
        let n = V3::new(1.0, 2.0, 3.0).normalize();
        let plane = Plane::new(P3::origin() + n * 5.0, n);
        let loops = section(&m, &plane);
        assert_eq!(loops.len(), 1);
        let r2 = 12.0f64 * 12.0 - 25.0;
        for p in &loops[0] {
            assert!(plane.height(p).abs() < 1e-9);
            let q = plane.to_2d(p);
            assert!(((q[0] * q[0] + q[1] * q[1]) - r2).abs() < 0.05, "{q:?}");
        }
        let poly: Vec<[f64; 2]> = loops[0].iter().map(|p| plane.to_2d(p)).collect();
        assert!(signed_area(&poly) > 0.0);
    }
}
