//! Tests of the layer mesh, its distance fields and iso-lines.

use super::field::sqrt_at_most;
use super::mesh::{lattice_step, MAX_CELLS};
use super::*;
use crate::geom2d::{dist2, Point2, Region};
use brep::math::P3;

fn square(a: f64) -> Region {
    Region {
        outer: vec![[0.0, 0.0], [a, 0.0], [a, a], [0.0, a]],
        holes: vec![],
    }
}

#[test]
fn the_square_limit_answers_as_the_root_does() {
    for r in [0.0, 1e-300, 0.3, 0.675, 1.0, 2.0f64.sqrt(), 1e10] {
        let lim = sqrt_at_most(r);
        assert!(lim.sqrt() <= r, "{r}");
        assert!(f64::from_bits(lim.to_bits() + 1).sqrt() > r, "{r}");
        for k in -50i64..50 {
            let x = f64::from_bits((lim.to_bits() as i64 + k).max(0) as u64);
            assert_eq!(x.sqrt() <= r, x <= lim, "r {r}, x {x}");
        }
    }
}

#[test]
fn marching_on_a_flat_square_gives_euclidean_distance() {
    let mut m = LayerMesh::build(&square(10.0), 0.25);
    m.p = m.q.iter().map(|q| P3::new(q[0], q[1], 0.0)).collect();
    let seeds: Vec<(u32, f64)> = (0..m.q.len() as u32)
        .filter(|&v| m.boundary[v as usize])
        .map(|v| (v, 0.0))
        .collect();
    let d = m.march(&m.boundary_seeds(0.5));
    let _ = seeds;
    let mut worst = 0.0f64;
    let mut bias = 0.0;
    for (q, d) in m.q.iter().zip(&d) {
        let exact = q[0].min(q[1]).min(10.0 - q[0]).min(10.0 - q[1]);
        worst = worst.max((d - exact).abs());
        bias += d - exact;
    }
    assert!(bias.abs() / (m.q.len() as f64) < 0.01, "bias {bias}");
    // Exact seeds at the boundary, planar fronts: exact up to the square's corners.
    assert!(worst < 0.05, "worst error {worst}");
    // Iso-line at 2 mm: a square ring 6 mm a side.
    let rings = m.iso_lines(&d, 2.0, &d);
    assert_eq!(rings.len(), 1);
    assert!(rings[0].closed);
    let len: f64 = rings[0]
        .q
        .windows(2)
        .map(|w| dist2(w[0], w[1]).sqrt())
        .sum();
    assert!((len - 24.0).abs() < 1.0, "ring length {len}");
}

#[test]
fn marching_on_a_cylinder_measures_along_the_surface() {
    // Chart (s, t) = (R·angle, z) of a cylinder of radius 5: distances from the line s = 0
    // are arc lengths, which the chart keeps, not chords.
    let r = 5.0;
    let mut m = LayerMesh::build(&square(10.0), 0.2);
    m.p =
        m.q.iter()
            .map(|q| P3::new(r * (q[0] / r).cos(), r * (q[0] / r).sin(), q[1]))
            .collect();
    let seeds: Vec<(u32, f64)> = (0..m.q.len() as u32)
        .filter(|&v| m.q[v as usize][0] < 1e-9)
        .map(|v| (v, 0.0))
        .collect();
    let d = m.march(&seeds);
    for (q, d) in m.q.iter().zip(&d) {
        assert!((d - q[0]).abs() < 0.05 + 0.01 * q[0], "at {q:?}: {d}");
    }
}

#[test]
fn clipping_cuts_at_the_crossings_and_runs_on_to_the_edge() {
    /// 0.45 mm beads run on to the region's boundary.
    const TO_BOUNDARY: RunOn = RunOn {
        width: 0.45,
        edge: 0.0,
    };
    let flat = |a: Point2, b: Point2| (a[0] - b[0]).hypot(a[1] - b[1]);
    // `other` falls to 0 (the boundary) at both ends of the line.
    let line = IsoLine {
        q: vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]],
        other: vec![0.0, 1.0, 1.0, 0.0],
        closed: false,
        ..IsoLine::default()
    };
    let pieces = clip_reaching(&line, 0.5, TO_BOUNDARY, flat);
    assert_eq!(pieces.len(), 1);
    let p = &pieces[0];
    assert_eq!(p.body, vec![[0.5, 0.0], [1.0, 0.0], [2.0, 0.0], [2.5, 0.0]]);
    // On to a hundredth of a bead before the boundary.
    let m = crate::fill::END_MARGIN * 0.45;
    assert_eq!(p.head.len(), 1);
    assert!((p.head[0][0] - m).abs() < 1e-12, "{:?}", p.head);
    assert!((p.tail[0][0] - (3.0 - m)).abs() < 1e-12, "{:?}", p.tail);
    let reversed = p.clone().reversed();
    assert_eq!(reversed.head, p.tail);
    assert_eq!(reversed.clone().reaching().len(), 6);
    // Inside rings, on only to the level of the last ring's bead edge.
    let ringed = clip_reaching(
        &line,
        0.5,
        RunOn {
            width: 0.45,
            edge: 0.25,
        },
        flat,
    );
    assert!(
        (ringed[0].head[0][0] - (0.25 + m)).abs() < 1e-12,
        "{:?}",
        ringed[0].head
    );
    assert!(
        (ringed[0].tail[0][0] - (2.75 - m)).abs() < 1e-12,
        "{:?}",
        ringed[0].tail
    );
    // A dip that does not reach the boundary: the two pieces run on to meet halfway.
    let line = IsoLine {
        q: (0..5).map(|i| [i as f64, 0.0]).collect(),
        other: vec![0.0, 1.0, 0.2, 1.0, 0.0],
        closed: false,
        ..IsoLine::default()
    };
    let pieces = clip_reaching(&line, 0.5, TO_BOUNDARY, flat);
    assert_eq!(pieces.len(), 2);
    let (a, b) = (&pieces[0], &pieces[1]);
    assert!((a.body[a.body.len() - 1][0] - 1.625).abs() < 1e-12);
    assert_eq!(a.tail.last(), Some(&[2.0, 0.0]));
    assert_eq!(b.head.first(), Some(&[2.0, 0.0]));
}

#[test]
fn a_large_region_gets_a_coarser_lattice_not_none() {
    let big = square(400.0);
    let s = lattice_step(&big.outer, 0.15);
    let cells = (400.0 / s) * (400.0 / s);
    assert!(
        s > 0.15 && (cells - MAX_CELLS).abs() < 1.0,
        "step {s}, {cells} cells"
    );
    let small = square(5.0);
    assert_eq!(lattice_step(&small.outer, 0.15), 0.15);
}

#[test]
fn a_ray_up_the_distance_across_a_slanted_strip_stops_on_its_middle() {
    // A strip 0.6 mm wide and 20 mm long, turned 0.3 rad to the lattice of 0.15 mm: from the
    // iso-line 0.05 mm inside it, each ray up the distance to the boundary stops near the
    // strip's middle, 0.3 mm from both sides, within a third of a lattice step, and reads the
    // strip's half width there within a tenth, 0.3 mm on average: the piecewise-linear
    // field's own highest point read 0.45 to 0.56 mm for the 0.6 mm strip.
    let (c, s) = (0.3f64.cos(), 0.3f64.sin());
    let rot = |x: f64, y: f64| [x * c - y * s, x * s + y * c];
    let (len, wd) = (20.0, 0.6);
    let region = Region {
        outer: vec![rot(0.0, 0.0), rot(len, 0.0), rot(len, wd), rot(0.0, wd)],
        holes: vec![],
    };
    let mut m = LayerMesh::build(&region, 0.15);
    m.p = m.q.iter().map(|q| P3::new(q[0], q[1], 0.0)).collect();
    let d = m.march(&m.boundary_seeds(0.5));
    let (mut checked, mut off) = (0, 0.0);
    for line in m.iso_lines(&d, 0.05, &d) {
        for (q, low) in line.q.iter().zip(&line.low) {
            // Back in the strip's frame: away from its ends.
            let x = q[0] * c + q[1] * s;
            if !(2.0..len - 2.0).contains(&x) {
                continue;
            }
            let up = m.ascent(&d, *low).expect("a slope");
            let top = m.ray_max(&d, *low, *q, up, 0.3).expect("a ridge");
            let y = -top.at[0] * s + top.at[1] * c;
            assert!((y - 0.5 * wd).abs() < 0.05, "{q:?}: stops {y} across");
            assert!(
                (top.height - 0.5 * wd).abs() < 0.03,
                "{q:?}: {}",
                top.height
            );
            assert!(top.sampled <= top.height + 1e-12);
            off += top.height - 0.5 * wd;
            checked += 1;
        }
    }
    assert!(checked > 100, "{checked} points");
    let bias = off / checked as f64;
    assert!(
        bias.abs() < 0.005,
        "half width read {bias} mm off on average"
    );
}

/// The vertex nearest `at` in chart coordinates.
fn nearest(m: &LayerMesh, at: Point2) -> usize {
    (0..m.q.len())
        .min_by(|&a, &b| dist2(m.q[a], at).total_cmp(&dist2(m.q[b], at)))
        .unwrap_or(0)
}

/// `edge_at` measures the lattice on the layer surface: the step on a flat square, and on a
/// chart that squeezes the layer 5 to 1 across (a lattice made for one place of a chart that
/// stretches unevenly) the edge of an equilateral triangle of the squeezed triangles' area.
#[test]
fn the_edge_at_a_vertex_is_the_lattice_step_on_the_surface() {
    let mut m = LayerMesh::build(&square(4.0), 0.1);
    m.p = m.q.iter().map(|q| P3::new(q[0], q[1], 0.0)).collect();
    let v = nearest(&m, [2.0, 2.0]);
    let e = m.edge_at(v);
    assert!((e - 0.1).abs() < 0.01, "{e}");
    m.p = m.q.iter().map(|q| P3::new(q[0], 0.2 * q[1], 0.0)).collect();
    let squeezed = m.edge_at(v);
    let want = 0.1 * 0.2f64.sqrt();
    assert!(
        (squeezed - want).abs() < 0.1 * want,
        "{squeezed} for {want}"
    );
}

/// A search by steps looks no farther than its lattice edges: a peak 0.5 mm off is the
/// local maximum within 1 mm, and not within 1 mm but 2 edges of 0.1 mm, which still see the
/// nearest neighbour.
#[test]
fn a_search_by_steps_stays_within_its_edges() {
    let mut m = LayerMesh::build(&square(4.0), 0.1);
    m.p = m.q.iter().map(|q| P3::new(q[0], q[1], 0.0)).collect();
    let v = nearest(&m, [2.0, 2.0]);
    let peak = nearest(&m, [2.5, 2.0]);
    let mut f = vec![0.0; m.q.len()];
    f[peak] = 1.0;
    let mut mask = vec![false; m.q.len()];
    mask[v] = true;
    let cap = vec![f64::INFINITY; m.q.len()];
    let wide = m.local_max(&f, Reach::Within(1.0), &mask, &cap);
    assert_eq!(wide[v], 1.0);
    let steps = Reach::Steps {
        most: 1.0,
        steps: 2.0,
    };
    assert_eq!(m.local_max(&f, steps, &mask, &cap)[v], 0.0);
    // Its nearest neighbour lies within the 2 edges.
    f[peak] = 0.0;
    let closest = (0..m.q.len())
        .filter(|&x| x != v)
        .min_by(|&a, &b| dist2(m.q[a], m.q[v]).total_cmp(&dist2(m.q[b], m.q[v])))
        .expect("a neighbour");
    f[closest] = 1.0;
    assert_eq!(m.local_max(&f, steps, &mask, &cap)[v], 1.0);
}
