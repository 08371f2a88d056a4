//! `brep::write`: every fixture and corpus file (both shared sets) read, written back with
//! `write_step`, and read
//! again must give the same B-rep: same solids, shells, faces, loops, coedges, edges and vertices
//! in the same order, the same surface and curve parametrisations, the same volume and area to
//! 1e-6 relative, closed and watertight. Subsets written with `write_step_shells` hold only what
//! their faces reach.
//!
//! Set `BREP_WRITE_DIR` to keep the written files (for checking them with OpenCASCADE).

use brep::solid::report_solid;
use brep::topology::{Brep, FaceId, SolidId};
use brep::write::{write_step, write_step_shells};
use std::path::{Path, PathBuf};

fn fixtures_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures")
}

/// The shared corpora found beside the repository (`corpus`, `corpus-more`).
fn corpus_dirs() -> Vec<PathBuf> {
    ["corpus", "corpus-more"]
        .iter()
        .map(|d| {
            PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("../../../shared")
                .join(d)
        })
        .filter(|d| d.is_dir())
        .collect()
}

fn step_files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("directory exists")
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| {
            p.extension()
                .is_some_and(|x| x.eq_ignore_ascii_case("step") || x.eq_ignore_ascii_case("stp"))
        })
        .collect();
    v.sort();
    v
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-12)
}

fn keep(name: &str, text: &str) {
    if let Ok(dir) = std::env::var("BREP_WRITE_DIR") {
        let p = PathBuf::from(dir).join(format!("{name}.step"));
        std::fs::write(&p, text).expect("write kept file");
        eprintln!("kept {}", p.display());
    }
}

/// The written text parses as Part 21 and refers only to entities it defines.
fn check_text(what: &str, text: &str) {
    let f = brep::p21::parse(text.as_bytes())
        .unwrap_or_else(|e| panic!("{what}: written text does not parse: {e}"));
    assert_eq!(f.first_dangling_ref(), None, "{what}: dangling reference");
    assert_eq!(
        f.schemas(),
        vec!["AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }".to_string()],
        "{what}"
    );
    assert!(text.is_ascii(), "{what}: non-ASCII output");
}

/// Compares two B-reps that should be the same, entity by entity (in order), and geometry by
/// evaluation at the same parameters.
fn compare_structure(what: &str, a: &Brep, b: &Brep, failures: &mut Vec<String>) {
    let mut fail = |m: String| failures.push(format!("{what}: {m}"));
    if a.solids.len() != b.solids.len() {
        fail(format!(
            "{} solids read back as {}",
            a.solids.len(),
            b.solids.len()
        ));
        return;
    }
    let close =
        |p: &brep::math::P3, q: &brep::math::P3| (p - q).norm() <= 1e-9 * (1.0 + p.coords.norm());
    for (sa, sb) in a.solids.iter().zip(&b.solids) {
        if sa.shells.len() != sb.shells.len() {
            fail(format!(
                "solid #{}: {} shells read back as {}",
                sa.step_id,
                sa.shells.len(),
                sb.shells.len()
            ));
            continue;
        }
        if sa.name != sb.name {
            fail(format!(
                "solid #{}: name {:?} read back as {:?}",
                sa.step_id, sa.name, sb.name
            ));
        }
        for (sha, shb) in sa.shells.iter().zip(&sb.shells) {
            let (sha, shb) = (&a.shells[sha.idx()], &b.shells[shb.idx()]);
            if sha.faces.len() != shb.faces.len() || sha.void != shb.void {
                fail(format!(
                    "shell #{}: {} faces (void {}) read back as {} (void {})",
                    sha.step_id,
                    sha.faces.len(),
                    sha.void,
                    shb.faces.len(),
                    shb.void
                ));
                continue;
            }
            for (&fa, &fb) in sha.faces.iter().zip(&shb.faces) {
                let (ta, tb) = (a.face(fa), b.face(fb));
                let id = ta.step_id;
                if ta.same_sense != tb.same_sense {
                    fail(format!("face #{id}: same_sense changed"));
                }
                let (ka, kb) = (a.face_surface(fa), b.face_surface(fb));
                if ka.kind() != kb.kind() {
                    fail(format!(
                        "face #{id}: {} read back as {}",
                        ka.kind(),
                        kb.kind()
                    ));
                    continue;
                }
                // The same parametrisation: equal points at equal (u, v) around the face's
                // vertices (or the surface's own range for faces without edges).
                let mut uvs = vec![];
                for v in a.vertices_of(&[fa]) {
                    let (u, w) = a.face_project(fa, &a.vertices[v.idx()].point);
                    uvs.push((u, w));
                    uvs.push((u + 0.01, w - 0.01));
                }
                if uvs.is_empty() {
                    uvs = vec![(0.1, 0.2), (1.0, -0.3), (2.0, 0.5)];
                }
                for (u, w) in uvs {
                    let (p, q) = (ka.eval(u, w), kb.eval(u, w));
                    if !close(&p, &q) {
                        fail(format!(
                            "face #{id}: surface point at ({u}, {w}) moved by {:.3e}",
                            (p - q).norm()
                        ));
                        break;
                    }
                    if let (Some(na), Some(nb)) = (a.face_normal(fa, u, w), b.face_normal(fb, u, w))
                    {
                        if na.dot(&nb) < 1.0 - 1e-9 {
                            fail(format!("face #{id}: outward normal at ({u}, {w}) changed"));
                            break;
                        }
                    }
                }
                if ta.loops.len() != tb.loops.len() {
                    fail(format!(
                        "face #{id}: {} loops read back as {}",
                        ta.loops.len(),
                        tb.loops.len()
                    ));
                    continue;
                }
                for (la, lb) in ta.loops.iter().zip(&tb.loops) {
                    let (la, lb) = (&a.loops[la.idx()], &b.loops[lb.idx()]);
                    if la.coedges.len() != lb.coedges.len()
                        || la.vertex.is_some() != lb.vertex.is_some()
                    {
                        fail(format!(
                            "loop #{}: {} coedges read back as {}",
                            la.step_id,
                            la.coedges.len(),
                            lb.coedges.len()
                        ));
                        continue;
                    }
                    if let (Some(va), Some(vb)) = (la.vertex, lb.vertex) {
                        if !close(&a.vertices[va.idx()].point, &b.vertices[vb.idx()].point) {
                            fail(format!("loop #{}: vertex moved", la.step_id));
                        }
                    }
                    for (ca, cb) in la.coedges.iter().zip(&lb.coedges) {
                        let (ca, cb) = (&a.coedges[ca.idx()], &b.coedges[cb.idx()]);
                        if ca.forward != cb.forward {
                            fail(format!("coedge #{}: direction changed", ca.step_id));
                        }
                        let (ea, eb) = (a.edge(ca.edge), b.edge(cb.edge));
                        for (va, vb) in [(ea.start, eb.start), (ea.end, eb.end)] {
                            if !close(&a.vertices[va.idx()].point, &b.vertices[vb.idx()].point) {
                                fail(format!("edge #{}: vertex moved", ea.step_id));
                            }
                        }
                        if (ea.start == ea.end) != (eb.start == eb.end) {
                            fail(format!("edge #{}: closedness changed", ea.step_id));
                        }
                        let (cva, cvb) = (a.edge_curve(ca.edge), b.edge_curve(cb.edge));
                        if cva.kind() != cvb.kind() {
                            fail(format!(
                                "edge #{}: {} read back as {}",
                                ea.step_id,
                                cva.kind(),
                                cvb.kind()
                            ));
                            continue;
                        }
                        let scale = 1.0 + ea.t_start.abs().max(ea.t_end.abs());
                        if (ea.t_start - eb.t_start).abs() > 1e-9 * scale
                            || (ea.t_end - eb.t_end).abs() > 1e-9 * scale
                        {
                            fail(format!(
                                "edge #{}: range [{}, {}] read back as [{}, {}]",
                                ea.step_id, ea.t_start, ea.t_end, eb.t_start, eb.t_end
                            ));
                        }
                        for k in 0..=4 {
                            let t = ea.t_start + (ea.t_end - ea.t_start) * k as f64 / 4.0;
                            if !close(&cva.eval(t), &cvb.eval(t)) {
                                fail(format!("edge #{}: curve point at t={t} moved", ea.step_id));
                                break;
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Reads `path`, writes all its solids, reads them back and checks everything; returns the
/// failures and the written text (None when the original cannot be read).
fn round_trip(path: &Path) -> (Vec<String>, Option<String>) {
    let name = path.file_stem().unwrap().to_string_lossy().to_string();
    let first = match brep::read_step(path) {
        Ok(p) => p.brep,
        Err(e) => {
            eprintln!("{name}: not readable by our reader ({e}); skipped");
            return (vec![], None);
        }
    };
    let solids: Vec<SolidId> = first.solid_ids().collect();
    let t0 = std::time::Instant::now();
    let text = write_step(&first, &solids, &name);
    let dt_write = t0.elapsed();
    keep(&format!("{name}_rt"), &text);
    check_text(&name, &text);
    let mut failures = vec![];
    let second = match brep::read_step_bytes(text.as_bytes()) {
        Ok(p) => p.brep,
        Err(e) => {
            return (
                vec![format!("{name}: written file does not read back: {e}")],
                Some(text),
            )
        }
    };
    if second.units.first().map(|u| u.name.as_str()) != Some("mm") {
        failures.push(format!("{name}: units read back as {:?}", second.units));
    }
    compare_structure(&name, &first, &second, &mut failures);
    if first.solids.len() != second.solids.len() {
        return (failures, Some(text));
    }
    for s in first.solid_ids() {
        let ra = report_solid(&first, s);
        let rb = report_solid(&second, s);
        let (ra, rb) = match (ra, rb) {
            (Ok(a), Ok(b)) => (a, b),
            (Err(e), _) => {
                eprintln!(
                    "{name}: solid {} cannot be measured on the first read ({e}); counts only",
                    s.0
                );
                continue;
            }
            (_, Err(e)) => {
                failures.push(format!(
                    "{name}: solid {} read back cannot be measured: {e}",
                    s.0
                ));
                continue;
            }
        };
        if (ra.faces, ra.edges, ra.vertices, ra.voids)
            != (rb.faces, rb.edges, rb.vertices, rb.voids)
        {
            failures.push(format!(
                "{name}: solid {} F/E/V/voids {:?} read back as {:?}",
                s.0,
                (ra.faces, ra.edges, ra.vertices, ra.voids),
                (rb.faces, rb.edges, rb.vertices, rb.voids)
            ));
        }
        if ra.surfaces != rb.surfaces || ra.curves != rb.curves {
            failures.push(format!(
                "{name}: solid {} kinds {:?}/{:?} read back as {:?}/{:?}",
                s.0, ra.surfaces, ra.curves, rb.surfaces, rb.curves
            ));
        }
        let tol_abs = 1e-9 * ra.bbox.diagonal().powi(3).max(1.0);
        if rel(rb.volume, ra.volume) > 1e-6 && (rb.volume - ra.volume).abs() > tol_abs {
            failures.push(format!(
                "{name}: solid {} volume {} read back as {}",
                s.0, ra.volume, rb.volume
            ));
        }
        if rel(rb.area, ra.area) > 1e-6 {
            failures.push(format!(
                "{name}: solid {} area {} read back as {}",
                s.0, ra.area, rb.area
            ));
        }
        if (ra.closed, ra.watertight) != (rb.closed, rb.watertight) || ra.genus != rb.genus {
            failures.push(format!(
                "{name}: solid {} closed/watertight/genus {:?} read back as {:?}",
                s.0,
                (ra.closed, ra.watertight, ra.genus),
                (rb.closed, rb.watertight, rb.genus)
            ));
        }
        if ra.closed && ra.watertight {
            eprintln!(
                "{name}: solid {}: V {:.6} -> {:.6}, A {:.6} -> {:.6}, {} faces, closed, watertight",
                s.0, ra.volume, rb.volume, ra.area, rb.area, rb.faces
            );
        } else {
            eprintln!(
                "{name}: solid {}: V {:.6} -> {:.6} (first read: closed {}, watertight {}; same after)",
                s.0, ra.volume, rb.volume, ra.closed, ra.watertight
            );
        }
    }
    eprintln!(
        "{name}: {} bytes written in {:.1} ms",
        text.len(),
        dt_write.as_secs_f64() * 1e3
    );
    (failures, Some(text))
}

#[test]
fn every_fixture_round_trips() {
    let mut failures = vec![];
    let files = step_files(&fixtures_dir());
    assert!(files.len() >= 10, "fixtures found: {}", files.len());
    for f in files {
        let (fl, text) = round_trip(&f);
        assert!(text.is_some(), "{}: fixture must be readable", f.display());
        failures.extend(fl);
    }
    assert!(
        failures.is_empty(),
        "round-trip failures:\n{}",
        failures.join("\n")
    );
}

#[test]
fn fixture_round_trip_is_closed_and_watertight() {
    // Every fixture is a closed, watertight solid; so must its round trip be.
    for f in step_files(&fixtures_dir()) {
        let part = brep::read_step(&f).unwrap();
        let solids: Vec<SolidId> = part.brep.solid_ids().collect();
        let back = brep::read_step_bytes(write_step(&part.brep, &solids, "x").as_bytes())
            .unwrap()
            .brep;
        for s in back.solid_ids() {
            let r = report_solid(&back, s).unwrap();
            assert!(
                r.closed && r.watertight,
                "{}: solid {} closed {} watertight {}",
                f.display(),
                s.0,
                r.closed,
                r.watertight
            );
        }
    }
}

#[test]
fn every_corpus_file_round_trips() {
    let dirs = corpus_dirs();
    if dirs.is_empty() {
        eprintln!("../shared/corpus not found beside the repository; corpus round trip skipped");
        return;
    }
    let mut failures = vec![];
    for dir in dirs {
        for f in step_files(&dir) {
            failures.extend(round_trip(&f).0);
        }
    }
    assert!(
        failures.is_empty(),
        "corpus round-trip failures:\n{}",
        failures.join("\n")
    );
}

#[test]
fn writing_the_same_solids_twice_gives_the_same_text() {
    let part = brep::read_step(fixtures_dir().join("fan.step")).unwrap();
    let solids: Vec<SolidId> = part.brep.solid_ids().collect();
    let a = write_step(&part.brep, &solids, "fan");
    let b = write_step(&part.brep, &solids, "fan");
    assert_eq!(a, b);
    // And a written file written again is the same text (the reader keeps order and values).
    let back = brep::read_step_bytes(a.as_bytes()).unwrap().brep;
    let c = write_step(&back, &solids, "fan");
    assert_eq!(a, c, "write(read(write(x))) differs from write(x)");
}

fn outer_faces(b: &Brep, s: SolidId) -> Vec<FaceId> {
    b.shells[b.solids[s.idx()].shells[0].idx()].faces.clone()
}

#[test]
fn an_outer_shell_written_alone_keeps_its_volume() {
    for name in ["impeller", "plate_boss_boss", "capsule"] {
        let part = brep::read_step(fixtures_dir().join(format!("{name}.step"))).unwrap();
        let b = &part.brep;
        let faces = outer_faces(b, SolidId(0));
        let text = write_step_shells(b, &[(faces.clone(), vec![])], name);
        check_text(name, &text);
        let back = brep::read_step_bytes(text.as_bytes()).unwrap().brep;
        assert_eq!(back.solids.len(), 1);
        let (ra, rb) = (
            report_solid(b, SolidId(0)).unwrap(),
            report_solid(&back, SolidId(0)).unwrap(),
        );
        assert!(
            rel(rb.volume, ra.volume) < 1e-6,
            "{name}: {} vs {}",
            rb.volume,
            ra.volume
        );
        assert!(rb.closed && rb.watertight, "{name}");
        assert_eq!(rb.faces, faces.len());
    }
}

#[test]
fn a_void_box_written_without_its_void_is_the_full_box() {
    let part = brep::read_step(fixtures_dir().join("void_box.step")).unwrap();
    let b = &part.brep;
    let solid = &b.solids[0];
    assert_eq!(solid.shells.len(), 2);
    let outer = outer_faces(b, SolidId(0));
    let void = b.shells[solid.shells[1].idx()].faces.clone();
    // Outer shell only: the 40 mm cube.
    let text = write_step_shells(b, &[(outer.clone(), vec![])], "box_only");
    check_text("box_only", &text);
    assert!(!text.contains("BREP_WITH_VOIDS") && !text.contains("SPHERICAL_SURFACE"));
    let back = brep::read_step_bytes(text.as_bytes()).unwrap().brep;
    let r = report_solid(&back, SolidId(0)).unwrap();
    assert!(rel(r.volume, 64000.0) < 1e-9, "{}", r.volume);
    // Outer and void through write_step_shells: the same file as write_step.
    let with_void = write_step_shells(b, &[(outer, vec![void])], "void_box");
    let via_solid = write_step(b, &[SolidId(0)], "void_box");
    let back = brep::read_step_bytes(with_void.as_bytes()).unwrap().brep;
    let r2 = report_solid(&back, SolidId(0)).unwrap();
    let r0 = report_solid(b, SolidId(0)).unwrap();
    assert!(
        rel(r2.volume, r0.volume) < 1e-9,
        "{} vs {}",
        r2.volume,
        r0.volume
    );
    assert_eq!(r2.voids, 1);
    assert!(back.shells[back.solids[0].shells[1].idx()].void);
    let named = format!("BREP_WITH_VOIDS({}", brep::write::string(&solid.name));
    assert_eq!(with_void, via_solid.replace(&named, "BREP_WITH_VOIDS(''"));
}

#[test]
fn a_subset_holds_only_what_its_faces_reach() {
    let part = brep::read_step(fixtures_dir().join("two_solids.step")).unwrap();
    let b = &part.brep;
    assert_eq!(b.solids.len(), 2);
    for s in b.solid_ids() {
        let faces = b.solid_faces(s);
        let text = write_step(b, &[s], "one");
        check_text("one", &text);
        let count = |what: &str| text.matches(&format!("= {what}(")).count();
        assert_eq!(count("ADVANCED_FACE"), faces.len());
        assert_eq!(count("EDGE_CURVE"), b.edges_of(&faces).len());
        assert_eq!(count("VERTEX_POINT"), b.vertices_of(&faces).len());
        let back = brep::read_step_bytes(text.as_bytes()).unwrap().brep;
        assert_eq!(back.solids.len(), 1);
        assert_eq!(back.faces.len(), faces.len());
        assert_eq!(back.edges.len(), b.edges_of(&faces).len());
        assert_eq!(back.vertices.len(), b.vertices_of(&faces).len());
        let (ra, rb) = (
            report_solid(b, s).unwrap(),
            report_solid(&back, SolidId(0)).unwrap(),
        );
        assert!(rel(rb.volume, ra.volume) < 1e-6);
    }
    // Both solids in one file, each written once; a face list given twice is written twice.
    let text = write_step(b, &[SolidId(0), SolidId(1)], "both");
    let back = brep::read_step_bytes(text.as_bytes()).unwrap().brep;
    assert_eq!(back.solids.len(), 2);
    assert_eq!(back.faces.len(), b.faces.len());
}

#[test]
fn surfaces_and_curves_are_written_once_each() {
    let part = brep::read_step(fixtures_dir().join("impeller.step")).unwrap();
    let b = &part.brep;
    let faces = b.solid_faces(SolidId(0));
    let text = write_step(b, &[SolidId(0)], "impeller");
    let mut surfaces: Vec<u32> = faces.iter().map(|f| b.face(*f).surface.0).collect();
    surfaces.sort();
    surfaces.dedup();
    assert_eq!(text.matches("= ADVANCED_FACE(").count(), faces.len());
    let mut curves: Vec<u32> = b
        .edges_of(&faces)
        .iter()
        .map(|e| b.edge(*e).curve.0)
        .collect();
    curves.sort();
    curves.dedup();
    assert_eq!(
        text.matches("= EDGE_CURVE(").count(),
        b.edges_of(&faces).len()
    );
    // Faces on one surface share its entity: count the distinct surface references.
    let f = brep::p21::parse(text.as_bytes()).unwrap();
    let mut face_surfaces: Vec<u64> = f
        .entities
        .iter()
        .filter_map(|e| e.instance.record("ADVANCED_FACE"))
        .filter_map(|r| match r.params[2] {
            brep::p21::Param::Ref(x) => Some(x),
            _ => None,
        })
        .collect();
    face_surfaces.sort();
    face_surfaces.dedup();
    assert_eq!(face_surfaces.len(), surfaces.len());
    let mut edge_curves: Vec<u64> = f
        .entities
        .iter()
        .filter_map(|e| e.instance.record("EDGE_CURVE"))
        .filter_map(|r| match r.params[3] {
            brep::p21::Param::Ref(x) => Some(x),
            _ => None,
        })
        .collect();
    edge_curves.sort();
    edge_curves.dedup();
    assert_eq!(edge_curves.len(), curves.len());
}
