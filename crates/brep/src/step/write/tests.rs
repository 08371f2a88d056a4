use super::text::{knot_runs, wrap};
use super::*;
use crate::curve::Curve;
use crate::math::{Frame, P3, V3};
use crate::surface::Surface;

#[test]
fn reals_read_back_exactly_and_always_have_a_point() {
    let xs = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.5,
        1e-7,
        -1.5e-7,
        1e-4,
        9.99e-5,
        123456.789,
        1e15,
        1e300,
        -2.5e-300,
        0.1,
        1.0 / 3.0,
        6000.0,
        1e14,
        f64::MIN_POSITIVE,
        f64::MAX,
    ];
    for x in xs {
        let s = real(x);
        assert!(s.contains('.'), "{x} -> {s}");
        assert!(
            !s.contains('e') && !s.contains("inf") && !s.contains("NaN"),
            "{s}"
        );
        let mant_ok = s.split('E').next().unwrap().ends_with('.')
            || s.split('E').next().unwrap().contains('.');
        assert!(mant_ok);
        // Part 21 and Rust agree on `1.E-07`-style text.
        let back: f64 = s.parse().unwrap();
        assert_eq!(back, x, "{x} -> {s}");
        // And our Part 21 parser reads it as the same number.
        let file = format!("ISO-10303-21;HEADER;ENDSEC;DATA;#1=A({s});ENDSEC;END-ISO-10303-21;");
        let f = crate::p21::parse(file.as_bytes()).unwrap();
        let p = &f.get(1).unwrap().instance.record("A").unwrap().params[0];
        assert_eq!(crate::step::read::as_real(p), Some(x), "{s}");
    }
    assert_eq!(real(1e-7), "1.E-07");
    assert_eq!(real(1.5e-7), "1.5E-07");
    assert_eq!(real(2.0), "2.");
    assert_eq!(real(-0.25), "-0.25");
    assert_eq!(real(1e20), "1.E+20");
    assert_eq!(real(f64::NAN), "0.");
}

#[test]
fn strings_escape_quotes_backslashes_and_unicode() {
    assert_eq!(string("it's"), "'it''s'");
    assert_eq!(string("a\\b"), "'a\\\\b'");
    assert_eq!(
        string("café 😀"),
        "'caf\\X2\\00E9\\X0\\ \\X2\\D83DDE00\\X0\\'"
    );
    for s in ["it's", "a\\b", "café 😀", "", "tab\there"] {
        let file = format!(
            "ISO-10303-21;HEADER;ENDSEC;DATA;#1=A({});ENDSEC;END-ISO-10303-21;",
            string(s)
        );
        let f = crate::p21::parse(file.as_bytes()).unwrap();
        let p = &f.get(1).unwrap().instance.record("A").unwrap().params[0];
        assert_eq!(p, &crate::p21::Param::Str(s.to_string()));
    }
}

#[test]
fn knots_become_distinct_values_and_multiplicities() {
    let (m, k) = knot_runs(&[0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0]);
    assert_eq!(m, "(3,1,3)");
    assert_eq!(k, "(0.,0.5,1.)");
}

#[test]
fn long_lines_wrap_outside_strings() {
    let long = format!(
        "A('{}',{})",
        "x,".repeat(60),
        (0..40)
            .map(|i| format!("#{i}"))
            .collect::<Vec<_>>()
            .join(",")
    );
    let w = wrap(&long);
    assert!(w.lines().count() > 1);
    assert!(w.contains(&"x,".repeat(60)), "a string was broken");
    assert_eq!(
        w.split_whitespace().collect::<String>(),
        long.split_whitespace().collect::<String>()
    );
}

// ---------- every curve and surface kind, on hand-made B-reps ----------

use crate::curve::NurbsData;
use crate::surface::{NurbsSurfaceData, Revolution};
use crate::topology::*;
use std::f64::consts::{FRAC_PI_2, PI};
use truck_geometry::prelude as tg;

fn fixture(name: &str) -> Brep {
    let p = format!("{}/../../fixtures/{name}.step", env!("CARGO_MANIFEST_DIR"));
    crate::read_step(p).expect("fixture reads").brep
}

fn keep(name: &str, text: &str) {
    if let Ok(dir) = std::env::var("BREP_WRITE_DIR") {
        std::fs::write(format!("{dir}/{name}.step"), text).unwrap();
    }
}

fn nurbs_curve(knots: Vec<f64>, pts: &[(P3, f64)]) -> Curve {
    let cps = pts
        .iter()
        .map(|(p, w)| tg::Vector4::new(p.x * w, p.y * w, p.z * w, *w))
        .collect();
    let bs = tg::BSplineCurve::new(tg::KnotVec::from(knots), cps);
    Curve::Nurbs(Box::new(NurbsData::new(tg::NurbsCurve::new(bs))))
}

/// A degree-1 patch equal to the plane `frame` (same parametrisation) over `[u0,u1]×[v0,v1]`,
/// with weight `w` everywhere.
fn nurbs_plane(frame: &Frame, (u0, u1): (f64, f64), (v0, v1): (f64, f64), w: f64) -> Surface {
    let ku = tg::KnotVec::from(vec![u0, u0, u1, u1]);
    let kv = tg::KnotVec::from(vec![v0, v0, v1, v1]);
    let cps: Vec<Vec<tg::Vector4>> = [u0, u1]
        .iter()
        .map(|&u| {
            [v0, v1]
                .iter()
                .map(|&v| {
                    let p = frame.at(u, v, 0.0);
                    tg::Vector4::new(p.x * w, p.y * w, p.z * w, w)
                })
                .collect()
        })
        .collect();
    let bs = tg::BSplineSurface::new((ku, kv), cps);
    Surface::Nurbs(Box::new(NurbsSurfaceData::new(tg::NurbsSurface::new(bs))))
}

fn measure(b: &Brep) -> crate::SolidReport {
    crate::solid::report_solid(b, SolidId(0)).expect("measurable")
}

fn round_trip(b: &Brep, name: &str) -> Brep {
    let solids: Vec<SolidId> = b.solid_ids().collect();
    let text = write_step(b, &solids, name);
    keep(name, &text);
    let f = crate::p21::parse(text.as_bytes()).expect("parses");
    assert_eq!(f.first_dangling_ref(), None);
    crate::read_step_bytes(text.as_bytes())
        .expect("reads back")
        .brep
}

/// Every face and edge of `b` evaluates the same in `c`, met in the same traversal order
/// (faces, loops, coedges) with the same parametrisation.
fn assert_same_geometry(b: &Brep, c: &Brep) {
    assert_eq!(b.faces.len(), c.faces.len());
    assert_eq!(b.edges.len(), c.edges.len());
    for (fa, fb) in b.faces.iter().zip(&c.faces) {
        let (sa, sb) = (&b.surfaces[fa.surface.idx()], &c.surfaces[fb.surface.idx()]);
        assert_eq!(sa.kind(), sb.kind());
        assert_eq!(fa.same_sense, fb.same_sense);
        for (u, v) in [
            (0.1, 0.2),
            (0.7, -0.3),
            (1.9, 0.6),
            (3.0, 0.9),
            (-1.2, 0.05),
        ] {
            let (pa, pb) = (sa.eval(u, v), sb.eval(u, v));
            assert!((pa - pb).norm() < 1e-9, "{} moved at ({u},{v})", sa.kind());
            if let (Some(na), Some(nb)) = (sa.normal(u, v), sb.normal(u, v)) {
                assert!(na.dot(&nb) > 1.0 - 1e-9, "{} normal flipped", sa.kind());
            }
        }
        assert_eq!(fa.loops.len(), fb.loops.len());
        for (la, lb) in fa.loops.iter().zip(&fb.loops) {
            let (la, lb) = (&b.loops[la.idx()], &c.loops[lb.idx()]);
            assert_eq!(la.coedges.len(), lb.coedges.len());
            for (ka, kb) in la.coedges.iter().zip(&lb.coedges) {
                let (ka, kb) = (&b.coedges[ka.idx()], &c.coedges[kb.idx()]);
                assert_eq!(ka.forward, kb.forward);
                let (ea, eb) = (b.edge(ka.edge), c.edge(kb.edge));
                let (ca, cb) = (&b.curves[ea.curve.idx()], &c.curves[eb.curve.idx()]);
                assert_eq!(ca.kind(), cb.kind());
                for k in 0..=8 {
                    let f = k as f64 / 8.0;
                    let pa = ca.eval(ea.t_start + f * (ea.t_end - ea.t_start));
                    let pb = cb.eval(eb.t_start + f * (eb.t_end - eb.t_start));
                    assert!(
                        (pa - pb).norm() < 1e-9,
                        "{} edge moved at {f}: {pa} vs {pb}",
                        ca.kind()
                    );
                    // The same parametrisation, not only the same point set.
                    let t = ea.t_start + f * (ea.t_end - ea.t_start);
                    assert!(
                        (ca.eval(t) - cb.eval(t)).norm() < 1e-9,
                        "{} reparametrised",
                        ca.kind()
                    );
                }
            }
        }
    }
}

#[test]
fn a_box_with_every_kind_of_straight_edge_and_flat_face_round_trips() {
    let mut b = fixture("box");
    let before = measure(&b).volume;
    for k in 0..b.edges.len() {
        let e = b.edges[k].clone();
        let (ps, pe) = (
            b.vertices[e.start.idx()].point,
            b.vertices[e.end.idx()].point,
        );
        let len = (pe - ps).norm();
        let dir = (pe - ps) / len;
        let (curve, t0, t1) = match k % 5 {
            // Runs against its trimmed basis, which starts 5 mm before the edge.
            0 => (
                Curve::Trimmed {
                    basis: Box::new(Curve::Line {
                        origin: ps - dir * 5.0,
                        dir,
                    }),
                    t0: 5.0 + len,
                    t1: 5.0,
                },
                1.0,
                0.0,
            ),
            1 => (
                Curve::Polyline(vec![ps, ps + dir * (0.3 * len), pe]),
                0.0,
                2.0,
            ),
            // A rational straight segment (uneven weights: non-uniform speed).
            2 => (
                nurbs_curve(vec![0.0, 0.0, 1.0, 1.0], &[(ps, 1.0), (pe, 3.0)]),
                0.0,
                1.0,
            ),
            // A trim of a trim of a longer line, run backwards by the edge.
            3 => (
                Curve::Trimmed {
                    basis: Box::new(Curve::Trimmed {
                        basis: Box::new(Curve::Line {
                            origin: pe + dir * 2.0,
                            dir: -dir,
                        }),
                        t0: 0.0,
                        t1: 4.0 + len,
                    }),
                    t0: 2.0 / (4.0 + len),
                    t1: (2.0 + len) / (4.0 + len),
                },
                1.0,
                0.0,
            ),
            _ => continue,
        };
        let id = CurveId(b.curves.len() as u32);
        b.curves.push(curve);
        let e = &mut b.edges[k];
        (e.curve, e.t_start, e.t_end) = (id, t0, t1);
        let c = &b.curves[id.idx()];
        assert!((c.eval(t0) - ps).norm() < 1e-9 && (c.eval(t1) - pe).norm() < 1e-9);
    }
    for k in 0..b.faces.len() {
        let f = FaceId(k as u32);
        let Surface::Plane { frame } = b.face_surface(f).clone() else {
            panic!("box faces are planes")
        };
        let uvs: Vec<(f64, f64)> = b
            .vertices_of(&[f])
            .iter()
            .map(|v| b.face_project(f, &b.vertices[v.idx()].point))
            .collect();
        let ur = uvs.iter().fold((f64::MAX, f64::MIN), |r, p| {
            (r.0.min(p.0 - 1.0), r.1.max(p.0 + 1.0))
        });
        let vr = uvs.iter().fold((f64::MAX, f64::MIN), |r, p| {
            (r.0.min(p.1 - 1.0), r.1.max(p.1 + 1.0))
        });
        let s = match k % 3 {
            0 => Surface::Extrusion {
                profile: Box::new(Curve::Line {
                    origin: frame.origin,
                    dir: frame.x,
                }),
                dir: frame.y,
            },
            1 => Surface::Offset {
                basis: Box::new(Surface::Plane {
                    frame: Frame {
                        origin: frame.origin - frame.z * 2.5,
                        ..frame
                    },
                }),
                distance: 2.5,
            },
            _ => nurbs_plane(&frame, ur, vr, 2.0),
        };
        let id = SurfaceId(b.surfaces.len() as u32);
        b.surfaces.push(s);
        b.faces[k].surface = id;
    }
    let r = measure(&b);
    assert!(r.closed && r.watertight);
    assert!(
        (r.volume - before).abs() < 1e-6 * before,
        "{} vs {before}",
        r.volume
    );
    let c = round_trip(&b, "synthetic_box");
    assert_same_geometry(&b, &c);
    let r2 = measure(&c);
    assert!(r2.closed && r2.watertight);
    assert!(
        (r2.volume - r.volume).abs() < 1e-9 * r.volume,
        "{} vs {}",
        r2.volume,
        r.volume
    );
    assert_eq!(r.curves, r2.curves);
    assert_eq!(r.surfaces, r2.surfaces);
}

#[test]
fn a_cylinder_with_elliptic_rims_and_an_offset_side_round_trips() {
    let mut b = fixture("cylinder");
    for c in b.curves.iter_mut() {
        if let Curve::Circle { frame, radius } = c.clone() {
            *c = Curve::Ellipse {
                frame,
                a: radius,
                b: radius,
            };
        }
    }
    for s in b.surfaces.iter_mut() {
        if let Surface::Cylinder { frame, radius } = s.clone() {
            *s = Surface::Offset {
                basis: Box::new(Surface::Cylinder {
                    frame,
                    radius: radius - 1.5,
                }),
                distance: 1.5,
            };
        }
    }
    let r = measure(&b);
    assert!(r.closed && r.watertight);
    let c = round_trip(&b, "synthetic_cylinder");
    assert_same_geometry(&b, &c);
    let r2 = measure(&c);
    assert!(
        (r2.volume - r.volume).abs() < 1e-9 * r.volume,
        "{} vs {}",
        r2.volume,
        r.volume
    );
    assert_eq!(r2.curves.get("ellipse"), Some(&2));
    assert_eq!(r2.surfaces.get("offset"), Some(&1));
}

/// One face on `surface` bounded by one loop of the given (curve, t_start, t_end) edges, each
/// with its own vertices (the reader does not check that loops connect).
fn one_face(surface: Surface, same_sense: bool, edges: Vec<(Curve, f64, f64)>) -> Brep {
    let mut b = Brep::default();
    b.surfaces.push(surface);
    b.solids.push(Solid {
        step_id: 0,
        name: "it's a test".into(),
        shells: vec![ShellId(0)],
    });
    b.shells.push(Shell {
        step_id: 0,
        faces: vec![FaceId(0)],
        void: false,
    });
    b.faces.push(Face {
        step_id: 0,
        surface: SurfaceId(0),
        same_sense,
        loops: vec![LoopId(0)],
        shell: ShellId(0),
    });
    b.loops.push(Loop {
        step_id: 0,
        face: FaceId(0),
        outer: true,
        coedges: vec![],
        vertex: None,
    });
    for (k, (c, t0, t1)) in edges.into_iter().enumerate() {
        let (p0, p1) = (c.eval(t0), c.eval(t1));
        let v = b.vertices.len() as u32;
        b.vertices.push(Vertex {
            step_id: 0,
            point: p0,
        });
        b.vertices.push(Vertex {
            step_id: 0,
            point: p1,
        });
        b.curves.push(c);
        b.edges.push(Edge {
            step_id: 0,
            curve: CurveId(k as u32),
            start: VertexId(v),
            end: VertexId(v + 1),
            t_start: t0,
            t_end: t1,
            coedges: vec![CoedgeId(k as u32)],
        });
        b.coedges.push(Coedge {
            step_id: 0,
            edge: EdgeId(k as u32),
            forward: k % 2 == 0,
            lp: LoopId(0),
        });
        b.loops[0].coedges.push(CoedgeId(k as u32));
    }
    b
}

#[test]
fn every_curve_kind_keeps_its_parametrisation() {
    let f = Frame::from_axes(
        P3::new(1.0, -2.0, 3.0),
        Some(V3::new(0.2, -0.3, 1.0)),
        Some(V3::new(1.0, 0.4, 0.0)),
    )
    .unwrap();
    let line = Curve::Line {
        origin: f.origin,
        dir: f.x,
    };
    let circle = Curve::Circle {
        frame: f,
        radius: 4.0,
    };
    let edges = vec![
        (
            Curve::Ellipse {
                frame: f,
                a: 3.0,
                b: 5.0,
            },
            0.3,
            2.0,
        ),
        (
            Curve::Ellipse {
                frame: f,
                a: 3.0,
                b: 5.0,
            },
            5.0,
            1.0,
        ), // against the curve
        (
            Curve::Hyperbola {
                frame: f,
                a: 2.0,
                b: 1.5,
            },
            -0.7,
            1.1,
        ),
        (
            Curve::Parabola {
                frame: f,
                focal: 0.8,
            },
            1.5,
            -2.0,
        ),
        (
            Curve::Trimmed {
                basis: Box::new(circle.clone()),
                t0: 5.5,
                t1: 7.0,
            },
            0.0,
            1.0,
        ),
        (
            Curve::Trimmed {
                basis: Box::new(circle.clone()),
                t0: 1.0,
                t1: -0.5,
            },
            0.0,
            1.0,
        ),
        (
            Curve::Trimmed {
                basis: Box::new(Curve::Hyperbola {
                    frame: f,
                    a: 2.0,
                    b: 1.5,
                }),
                t0: 0.5,
                t1: -0.5,
            },
            0.0,
            1.0,
        ),
        (
            Curve::Trimmed {
                basis: Box::new(Curve::Parabola {
                    frame: f,
                    focal: 0.8,
                }),
                t0: -1.0,
                t1: 2.0,
            },
            0.0,
            1.0,
        ),
        (
            Curve::Trimmed {
                basis: Box::new(line.clone()),
                t0: -3.0,
                t1: 4.0,
            },
            1.0,
            0.0,
        ),
        (
            Curve::Trimmed {
                basis: Box::new(Curve::Trimmed {
                    basis: Box::new(Curve::Ellipse {
                        frame: f,
                        a: 3.0,
                        b: 5.0,
                    }),
                    t0: 1.0,
                    t1: 3.0,
                }),
                t0: 0.75,
                t1: 0.25,
            },
            0.0,
            1.0,
        ),
        (
            Curve::Polyline(vec![
                f.at(0.0, 0.0, 0.0),
                f.at(1.0, 2.0, 0.5),
                f.at(3.0, -1.0, 0.0),
                f.at(4.0, 0.0, 1.0),
            ]),
            0.5,
            2.5,
        ),
        (
            nurbs_curve(
                vec![0.0, 0.0, 0.0, 0.25, 0.5, 0.5, 1.0, 1.0, 1.0],
                &[
                    (f.at(0.0, 0.0, 0.0), 1.0),
                    (f.at(1.0, 1.0, 0.0), 0.7),
                    (f.at(2.0, 0.0, 1.0), 2.0),
                    (f.at(3.0, 1.0, 0.0), 1.0),
                    (f.at(4.0, -1.0, 0.0), 0.5),
                    (f.at(5.0, 0.0, 0.0), 1.0),
                ],
            ),
            0.9,
            0.1,
        ),
        (
            nurbs_curve(
                vec![-1.0, -1.0, -1.0, 2.0, 2.0, 2.0],
                &[
                    (f.at(0.0, 0.0, 0.0), 1.0),
                    (f.at(1.0, 3.0, 0.0), 1.0),
                    (f.at(2.0, 0.0, 1e-9), 1.0),
                ],
            ),
            -1.0,
            2.0,
        ),
    ];
    let b = one_face(Surface::Plane { frame: f }, true, edges);
    let c = round_trip(&b, "synthetic_curves");
    assert_same_geometry(&b, &c);
    assert_eq!(c.solids[0].name, "it's a test");
    // The written text says what it should.
    let text = write_step(&b, &[SolidId(0)], "curves");
    for kind in [
        "HYPERBOLA(",
        "PARABOLA(",
        "ELLIPSE(",
        "TRIMMED_CURVE(",
        "POLYLINE(",
        "RATIONAL_B_SPLINE_CURVE(",
        "= B_SPLINE_CURVE_WITH_KNOTS(",
    ] {
        assert!(text.contains(kind), "{kind} missing");
    }
    // A trim of a trim is written as one trim of the innermost basis.
    let f = crate::p21::parse(text.as_bytes()).unwrap();
    for e in &f.entities {
        if let Some(r) = e.instance.record("TRIMMED_CURVE") {
            let crate::p21::Param::Ref(basis) = r.params[1] else {
                panic!()
            };
            assert!(f
                .get(basis)
                .unwrap()
                .instance
                .record("TRIMMED_CURVE")
                .is_none());
        }
    }
}

#[test]
fn every_surface_kind_keeps_its_parametrisation_and_normal() {
    let f = Frame::from_axes(
        P3::new(1.0, -2.0, 3.0),
        Some(V3::new(0.2, -0.3, 1.0)),
        Some(V3::new(1.0, 0.4, 0.0)),
    )
    .unwrap();
    let edge = || {
        vec![(
            Curve::Line {
                origin: f.origin,
                dir: f.x,
            },
            0.0,
            1.0,
        )]
    };
    let profile = nurbs_curve(
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        &[
            (f.at(3.0, 0.0, 0.0), 1.0),
            (f.at(4.0, 0.0, 1.0), 0.6),
            (f.at(2.5, 0.0, 2.0), 1.0),
        ],
    );
    let surfaces = vec![
        Surface::Plane { frame: f },
        Surface::Cylinder {
            frame: f,
            radius: 2.5,
        },
        Surface::Cone {
            frame: f,
            radius: 2.5,
            semi_angle: 0.3,
        },
        Surface::Cone {
            frame: f,
            radius: 0.0,
            semi_angle: PI / 4.0,
        },
        Surface::Sphere {
            frame: f,
            radius: 7.0,
        },
        Surface::Torus {
            frame: f,
            major: 5.0,
            minor: 1.25,
        },
        Surface::Revolution(Box::new(Revolution::new(profile.clone(), f.origin, f.z))),
        Surface::Revolution(Box::new(Revolution::new(
            Curve::Trimmed {
                basis: Box::new(Curve::Circle {
                    frame: Frame::from_axes(f.at(6.0, 0.0, 0.0), Some(f.y), Some(f.x)).unwrap(),
                    radius: 1.0,
                }),
                t0: 0.0,
                t1: -FRAC_PI_2,
            },
            f.origin,
            f.z,
        ))),
        Surface::Extrusion {
            profile: Box::new(profile.clone()),
            dir: f.y,
        },
        Surface::Extrusion {
            profile: Box::new(Curve::Ellipse {
                frame: f,
                a: 2.0,
                b: 1.0,
            }),
            dir: (f.z + f.x * 0.3).normalize(),
        },
        nurbs_plane(&f, (-2.0, 3.0), (-1.0, 4.0), 1.0),
        nurbs_plane(&f, (-2.0, 3.0), (-1.0, 4.0), 0.25),
        Surface::Offset {
            basis: Box::new(Surface::Sphere {
                frame: f,
                radius: 7.0,
            }),
            distance: -1.5,
        },
        Surface::Offset {
            basis: Box::new(nurbs_plane(&f, (-2.0, 3.0), (-1.0, 4.0), 3.0)),
            distance: 0.75,
        },
    ];
    for (k, s) in surfaces.into_iter().enumerate() {
        for same_sense in [true, false] {
            let b = one_face(s.clone(), same_sense, edge());
            let c = round_trip(&b, &format!("synthetic_surface_{k}"));
            assert_same_geometry(&b, &c);
        }
    }
}

#[test]
fn a_rational_bspline_surface_is_one_complex_entity() {
    let f = Frame::world(P3::origin());
    let b = one_face(
        nurbs_plane(&f, (0.0, 1.0), (0.0, 1.0), 2.0),
        true,
        vec![(
            Curve::Line {
                origin: f.origin,
                dir: f.x,
            },
            0.0,
            1.0,
        )],
    );
    let text = write_step(&b, &[SolidId(0)], "rational");
    let f = crate::p21::parse(text.as_bytes()).unwrap();
    let e = f
        .entities
        .iter()
        .find(|e| e.instance.record("RATIONAL_B_SPLINE_SURFACE").is_some())
        .expect("rational surface");
    let names = e.instance.names();
    let mut sorted = names.clone();
    sorted.sort();
    assert_eq!(
        names, sorted,
        "complex entity parts must be in alphabetical order"
    );
    assert!(names.contains(&"B_SPLINE_SURFACE_WITH_KNOTS") && names.contains(&"B_SPLINE_SURFACE"));
}
