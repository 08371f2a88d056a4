//! Mesh files planned (issue 37, item 1): STL (binary and ASCII), 3MF and OBJ of fixtures,
//! each planned on Marlin as `mesh_two5d` features, extrude what the STEP file's planar plan
//! extrudes; a mesh with a hole is refused with its open edges, a small gap welded with a
//! warning; 3MF units and build items are honoured; `inspect` measures the mesh as the STEP.

#[path = "common/cli.rs"]
mod cli;

use cli::{fixture, stderr, Scratch, BIN};
use meshfile::Object;
use serde_json::Value;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("runs")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The fixture's binary STL written by `features mesh`.
fn stl_of(step: &str, scratch: &Scratch) -> PathBuf {
    let out = scratch.path(&step.replace(".step", ".stl"));
    let o = run(&["mesh", s(&fixture(step)), "-o", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    out
}

/// The one object of a mesh file, its corners welded.
fn object(path: &Path) -> Object {
    let f = meshfile::read(path).unwrap();
    meshfile::weld::weld(&f.objects[0], 0.0).object
}

fn obj_text(o: &Object) -> String {
    let mut t = String::from("# written by the mesh input tests\no part\n");
    for p in &o.positions {
        t += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for tri in &o.triangles {
        t += &format!("f {} {} {}\n", tri[0] + 1, tri[1] + 1, tri[2] + 1);
    }
    t
}

fn ascii_stl(o: &Object) -> String {
    let mut t = String::from("solid part\n");
    for tri in &o.triangles {
        t += " facet normal 0 0 0\n  outer loop\n";
        for &i in tri {
            let p = o.positions[i as usize];
            t += &format!("   vertex {} {} {}\n", p[0], p[1], p[2]);
        }
        t += "  endloop\n endfacet\n";
    }
    t + "endsolid part\n"
}

/// A 3MF package of `objects` (each a build item with its transform, 12 numbers or none), in
/// `unit`, coordinates divided by `mm_per_unit`.
fn threemf(objects: &[(&Object, Option<&str>)], unit: &str, mm_per_unit: f64) -> Vec<u8> {
    let mut model = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"{unit}\" xml:lang=\"en-US\" xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\">\n <resources>\n"
    );
    for (k, (o, _)) in objects.iter().enumerate() {
        model += &format!(
            "  <object id=\"{}\" type=\"model\"><mesh><vertices>\n",
            k + 1
        );
        for p in &o.positions {
            let p = p.map(|x| x / mm_per_unit);
            model += &format!(
                "   <vertex x=\"{}\" y=\"{}\" z=\"{}\"/>\n",
                p[0], p[1], p[2]
            );
        }
        model += "  </vertices><triangles>\n";
        for t in &o.triangles {
            model += &format!(
                "   <triangle v1=\"{}\" v2=\"{}\" v3=\"{}\"/>\n",
                t[0], t[1], t[2]
            );
        }
        model += "  </triangles></mesh></object>\n";
    }
    model += " </resources>\n <build>\n";
    for (k, (_, transform)) in objects.iter().enumerate() {
        match transform {
            Some(t) => model += &format!("  <item objectid=\"{}\" transform=\"{t}\"/>\n", k + 1),
            None => model += &format!("  <item objectid=\"{}\"/>\n", k + 1),
        }
    }
    model += " </build>\n</model>\n";
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let opts = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    let files = [
        ("[Content_Types].xml", "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Types xmlns=\"http://schemas.openxmlformats.org/package/2006/content-types\"><Default Extension=\"rels\" ContentType=\"application/vnd.openxmlformats-package.relationships+xml\"/><Default Extension=\"model\" ContentType=\"application/vnd.ms-package.3dmanufacturing-3dmodel+xml\"/></Types>\n".to_string()),
        ("_rels/.rels", "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Relationships xmlns=\"http://schemas.openxmlformats.org/package/2006/relationships\"><Relationship Target=\"/3D/3dmodel.model\" Id=\"rel0\" Type=\"http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\"/></Relationships>\n".to_string()),
        ("3D/3dmodel.model", model),
    ];
    for (name, text) in files {
        zip.start_file(name, opts).unwrap();
        zip.write_all(text.as_bytes()).unwrap();
    }
    zip.finish().unwrap().into_inner()
}

/// Plans `part` on Marlin into `out`: the report, after asserting exit 0.
fn plan(part: &Path, out: &Path, extra: &[&str]) -> Value {
    let mut args = vec![
        "plan",
        s(part),
        "-o",
        s(out),
        "--placement-time-limit",
        "inf",
    ];
    args.extend(extra);
    let o = run(&args);
    assert!(o.status.success(), "{}: {}", part.display(), stderr(&o));
    serde_json::from_str(&std::fs::read_to_string(out.join("plan.json")).unwrap()).unwrap()
}

/// The bead a plan lays, mm³: each feature's extruded volume with its widening.
fn extruded(report: &Value) -> f64 {
    report["features"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            f["extruded_volume_mm3"].as_f64().unwrap() + f["widened_volume_mm3"].as_f64().unwrap()
        })
        .sum()
}

/// Plans the STEP fixture in planar layers and its mesh in each of `formats`: every mesh plan
/// is of `mesh_two5d` features, sliced planar, extruding within 2 % of the STEP plan.
fn plans_like_the_step_file(step: &str, formats: &[&str]) {
    let scratch = Scratch::new(&format!("plans-{step}"));
    let want = extruded(&plan(
        &fixture(step),
        &scratch.path("step"),
        &["--set", "slicing=planar"],
    ));
    let stl = stl_of(step, &scratch);
    let o = object(&stl);
    for format in formats {
        let part = match *format {
            "stl" => stl.clone(),
            "obj" => {
                let p = scratch.path("part.obj");
                std::fs::write(&p, obj_text(&o)).unwrap();
                p
            }
            "3mf" => {
                let p = scratch.path("part.3mf");
                std::fs::write(&p, threemf(&[(&o, None)], "millimeter", 1.0)).unwrap();
                p
            }
            _ => unreachable!(),
        };
        let report = plan(&part, &scratch.path(format), &[]);
        assert_eq!(report["slicing"], "planar", "{step} {format}");
        for f in report["features"].as_array().unwrap() {
            assert_eq!(f["subtype"], "mesh_two5d", "{step} {format}");
            assert_eq!(f["kind"], "two5d", "{step} {format}");
        }
        let got = extruded(&report);
        assert!(
            (got - want).abs() <= 0.02 * want,
            "{step} as {format}: {got:.1} mm^3 extruded, the STEP file's planar plan {want:.1}"
        );
    }
}

#[test]
fn a_box_as_stl_obj_and_3mf_plans_like_the_step_file() {
    plans_like_the_step_file("box.step", &["stl", "obj", "3mf"]);
}

#[test]
fn plate_boss_boss_as_stl_and_3mf_plans_like_the_step_file() {
    plans_like_the_step_file("plate_boss_boss.step", &["stl", "3mf"]);
}

#[test]
fn sphere_boss_as_stl_and_obj_plans_like_the_step_file() {
    plans_like_the_step_file("sphere_boss.step", &["stl", "obj"]);
}

#[test]
fn a_mesh_with_a_face_removed_is_refused_with_its_open_edges() {
    let scratch = Scratch::new("open");
    let mut o = object(&stl_of("box.step", &scratch));
    o.triangles.pop();
    // ASCII STL, read as such.
    let part = scratch.path("holed.stl");
    std::fs::write(&part, ascii_stl(&o)).unwrap();
    let out = scratch.path("out");
    for cmd in ["plan", "extract"] {
        let args: Vec<&str> = match cmd {
            "plan" => vec!["plan", s(&part), "-o", s(&out)],
            _ => vec!["extract", s(&part)],
        };
        let r = run(&args);
        let err = stderr(&r);
        assert_eq!(r.status.code(), Some(2), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.starts_with(&format!("features: {}: ", part.display())),
            "{err}"
        );
        assert!(
            err.contains("3 open edge(s) and 0 non-manifold edge(s)"),
            "{err}"
        );
    }
    assert!(!out.exists(), "nothing written");
    // `inspect` tells the same counts, and the volume of what is left.
    let r = run(&["inspect", s(&part), "--json"]);
    assert!(r.status.success(), "{}", stderr(&r));
    let j: Value = serde_json::from_slice(&r.stdout).unwrap();
    assert_eq!(j["objects"][0]["open_edges"], 3);
    assert_eq!(j["objects"][0]["non_manifold_edges"], 0);
    assert_eq!(j["objects"][0]["closed"], false);
}

#[test]
fn a_gap_within_the_tolerance_is_welded_with_a_warning() {
    let scratch = Scratch::new("gap");
    let o = object(&stl_of("box.step", &scratch));
    // One triangle's corner its own vertex, 0.01 mm off (the tolerance is 0.05 mm).
    let mut gapped = o.clone();
    let moved = gapped.triangles[0][0] as usize;
    let p = gapped.positions[moved];
    gapped.positions.push([p[0] + 0.01, p[1], p[2]]);
    gapped.triangles[0][0] = gapped.positions.len() as u32 - 1;
    let part = scratch.path("gapped.obj");
    std::fs::write(&part, obj_text(&gapped)).unwrap();
    let r = run(&["inspect", s(&part), "--json"]);
    let j: Value = serde_json::from_slice(&r.stdout).unwrap();
    assert!(j["objects"][0]["open_edges"].as_u64().unwrap() > 0, "{j}");
    assert_eq!(j["objects"][0]["closed"], true, "{j}");
    let out = scratch.path("out");
    let r = run(&["plan", s(&part), "-o", s(&out)]);
    let err = stderr(&r);
    assert!(r.status.success(), "{err}");
    assert!(
        err.lines().any(|l| l.contains(": warning: ")
            && l.contains("closed by welding 1 vertice(s) within 0.05 mm")),
        "{err}"
    );
    // A gap wider than the tolerance is refused: the corner's two edges of the moved triangle
    // and the two of its neighbours they no longer meet are open.
    gapped.positions.last_mut().unwrap()[0] += 0.5;
    std::fs::write(&part, obj_text(&gapped)).unwrap();
    let r = run(&["plan", s(&part), "-o", s(&scratch.path("wide"))]);
    assert_eq!(r.status.code(), Some(2), "{}", stderr(&r));
    assert!(stderr(&r).contains("4 open edge(s)"), "{}", stderr(&r));
}

#[test]
fn a_3mf_s_unit_and_build_items_are_honoured() {
    let scratch = Scratch::new("3mf");
    let o = object(&stl_of("box.step", &scratch));
    let volume = |path: &Path| -> f64 {
        let r = run(&["inspect", s(path), "--json"]);
        assert!(r.status.success(), "{}", stderr(&r));
        let j: Value = serde_json::from_slice(&r.stdout).unwrap();
        j["objects"][0]["volume_mm3"].as_f64().unwrap()
    };
    for (unit, mm) in [("millimeter", 1.0), ("inch", 25.4), ("centimeter", 10.0)] {
        let p = scratch.path(&format!("box_{unit}.3mf"));
        std::fs::write(&p, threemf(&[(&o, None)], unit, mm)).unwrap();
        let v = volume(&p);
        assert!((v - 6000.0).abs() < 0.01, "{unit}: {v}");
    }
    // The same box at the same place in inches, unlabelled: 25.4³ times smaller.
    let p = scratch.path("box_mm_as_inch.3mf");
    std::fs::write(&p, threemf(&[(&o, None)], "millimeter", 25.4)).unwrap();
    assert!((volume(&p) - 6000.0 / 25.4f64.powi(3)).abs() < 1e-3);
    // Two build items of one box, the second moved 40 mm along +X and 5 mm up: two features,
    // the lower built first.
    let p = scratch.path("two.3mf");
    std::fs::write(
        &p,
        threemf(
            &[(&o, Some("1 0 0 0 1 0 0 0 1 40 0 5")), (&o, None)],
            "millimeter",
            1.0,
        ),
    )
    .unwrap();
    let r = run(&["extract", s(&p), "--json"]);
    assert!(r.status.success(), "{}", stderr(&r));
    let j: Value = serde_json::from_slice(&r.stdout).unwrap();
    let features = j["features"].as_array().unwrap();
    assert_eq!(features.len(), 2, "{j}");
    assert!(features.iter().all(|f| f["subtype"] == "mesh_two5d"));
    assert!((j["part"]["volume_mm3"].as_f64().unwrap() - 12000.0).abs() < 0.01);
    let r = run(&["inspect", s(&p), "--json"]);
    let j: Value = serde_json::from_slice(&r.stdout).unwrap();
    // The first item is the moved one: its box starts at x = 40, z = 5.
    assert_eq!(
        j["objects"][0]["bbox"][0],
        serde_json::json!([40.0, 0.0, 5.0])
    );
    assert_eq!(
        j["objects"][1]["bbox"][0],
        serde_json::json!([0.0, 0.0, 0.0])
    );
}

#[test]
fn inspect_measures_the_mesh_as_the_step_file() {
    let scratch = Scratch::new("inspect");
    for step in ["plate_boss_boss.step", "sphere_boss.step"] {
        let r = run(&["inspect", s(&fixture(step)), "--json"]);
        let j: Value = serde_json::from_slice(&r.stdout).unwrap();
        let want = j["solids"][0]["volume_mm3"].as_f64().unwrap();
        let stl = stl_of(step, &scratch);
        let r = run(&["inspect", s(&stl), "--json"]);
        assert!(r.status.success(), "{}", stderr(&r));
        let j: Value = serde_json::from_slice(&r.stdout).unwrap();
        let o = &j["objects"][0];
        let got = o["volume_mm3"].as_f64().unwrap();
        assert!(
            (got - want).abs() <= 0.005 * want,
            "{step}: {got} against {want}"
        );
        assert_eq!(o["open_edges"], 0);
        assert_eq!(o["non_manifold_edges"], 0);
        assert_eq!(o["closed"], true);
        assert_eq!(o["bodies"], 1);
        assert!(o["area_mm2"].as_f64().unwrap() > 0.0);
        let text = String::from_utf8(run(&["inspect", s(&stl)]).stdout).unwrap();
        assert!(
            text.contains("edges:       0 open, 0 non-manifold"),
            "{text}"
        );
    }
}

#[test]
fn a_mesh_stands_on_its_largest_face_and_previews() {
    // A box on its side: --orient auto ranks the triangles' directions by area (one mesh of
    // them all) and stands it on a 30 x 20 face, whose two triangles face -Y.
    let scratch = Scratch::new("orient");
    let o = object(&stl_of("box.step", &scratch));
    let mut side = o.clone();
    for p in &mut side.positions {
        *p = [p[0], -p[2], p[1]];
    }
    let part = scratch.path("side.obj");
    std::fs::write(&part, obj_text(&side)).unwrap();
    let report = plan(&part, &scratch.path("out"), &["--orient", "auto"]);
    assert_eq!(report["features"][0]["subtype"], "mesh_two5d");
    let down = report["placement"]["down"].as_array().unwrap();
    let down: Vec<f64> = down.iter().map(|x| x.as_f64().unwrap()).collect();
    assert!(down[1].abs() > 0.99, "{down:?}");
    assert!((extruded(&report) - 6000.0).abs() < 0.02 * 6000.0);
    let page = scratch.path("side.html");
    let r = run(&["preview", s(&part), "-o", s(&page)]);
    assert!(r.status.success(), "{}", stderr(&r));
    assert!(page.exists());
}

#[test]
fn a_needle_triangle_is_split_away_without_a_warning() {
    // A 10 mm cube whose top diagonal is split at (5 5 10) by a triangle of no area (a mended
    // T-junction): closed and manifold, but no plane holds the needle.
    let scratch = Scratch::new("needle");
    let part = scratch.path("needle.obj");
    let text = "v 0 0 0\nv 10 0 0\nv 10 10 0\nv 0 10 0\nv 0 0 10\nv 10 0 10\nv 10 10 10\nv 0 10 10\nv 5 5 10\n\
                f 1 4 3\nf 1 3 2\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 3 4 8\nf 3 8 7\nf 1 5 8\nf 1 8 4\n\
                f 2 3 7\nf 2 7 6\nf 5 6 9\nf 9 6 7\nf 5 9 7\n";
    std::fs::write(&part, text).unwrap();
    let out = scratch.path("out");
    let r = run(&["plan", s(&part), "-o", s(&out)]);
    let err = stderr(&r);
    assert!(r.status.success(), "{err}");
    assert!(!err.contains("warning"), "{err}");
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("plan.json")).unwrap()).unwrap();
    assert!((extruded(&report) - 1000.0).abs() < 0.02 * 1000.0);
}
