//! End-to-end tests of the `features` binary: `inspect`, `mesh`, error reporting.

use serde_json::Value;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_features");

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name)
}

fn fixture_json(name: &str) -> Value {
    let text = std::fs::read_to_string(fixture(name)).expect("fixture json");
    serde_json::from_str(&text).expect("fixture json parses")
}

fn run(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(BIN)
        .args(args)
        .env_remove("FEATURES_TEST_PANIC")
        .output()
        .expect("the binary runs")
}

/// A directory under the system temp dir, unique per process and test, removed on drop.
struct TempDir(PathBuf);

impl TempDir {
    fn new(test: &str) -> Self {
        let p = std::env::temp_dir().join(format!("features-cli-{}-{test}", std::process::id()));
        let _ = std::fs::remove_dir_all(&p);
        std::fs::create_dir_all(&p).expect("temp dir");
        TempDir(p)
    }
    fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
    fn write(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, bytes).expect("write temp file");
        p
    }
    fn names(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(&self.0)
            .expect("list temp dir")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Exit code 2 (not 3: no panic reached the last line of defence), and stderr is exactly one
/// non-empty line `features: <path>: <cause>` naming `path`.
fn assert_one_line_failure(out: &Output, path: &Path, what: &str) {
    let err = stderr(out);
    assert_eq!(
        out.status.code(),
        Some(2),
        "{what}: exit code; stderr: {err}"
    );
    assert!(
        !err.contains("panicked") && !err.contains("internal error"),
        "{what}: a panic escaped: {err}"
    );
    assert!(err.ends_with('\n'), "{what}: stderr not one line: {err:?}");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 1, "{what}: stderr is not one line: {err:?}");
    let line = lines[0];
    let prefix = format!("features: {}: ", path.display());
    assert!(
        line.starts_with(&prefix) && line.len() > prefix.len(),
        "{what}: stderr `{line}` does not start with `{prefix}` and a cause"
    );
}

/// A deterministic xorshift64 byte stream.
fn xorshift_bytes(mut state: u64, n: usize) -> Vec<u8> {
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        out.extend_from_slice(&state.to_le_bytes());
    }
    out.truncate(n);
    out
}

/// Every bad input the reader must refuse cleanly, written into `dir`.
fn bad_inputs(dir: &TempDir) -> Vec<(&'static str, PathBuf)> {
    let box_step = std::fs::read_to_string(fixture("box.step")).expect("box.step");

    let data = box_step.find("DATA;").expect("DATA section");
    let end = box_step[data..].find("ENDSEC;").expect("end of DATA") + data;
    let truncated = &box_step[..(data + end) / 2];

    let needle = "ORIENTED_EDGE('',*,*,#21,.T.)";
    assert!(box_step.contains(needle), "box.step changed: no `{needle}`");
    let dangling = box_step.replacen(needle, "ORIENTED_EDGE('',*,*,#999999,.T.)", 1);

    let no_solid = "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('no solid'),'2;1');\n\
                    FILE_NAME('no_solid.step','2024-01-01T00:00:00',(''),(''),'','','');\n\
                    FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\n\
                    DATA;\n#1 = CARTESIAN_POINT('',(0.,0.,0.));\nENDSEC;\nEND-ISO-10303-21;\n";

    vec![
        ("missing file", dir.path("missing.step")),
        ("empty file", dir.write("empty.step", b"")),
        (
            "text, not Part 21",
            dir.write("text.step", b"This is a text file.\nIt is not STEP.\n"),
        ),
        (
            "truncated in DATA",
            dir.write("truncated.step", truncated.as_bytes()),
        ),
        (
            "4 KB random bytes",
            dir.write("random.step", &xorshift_bytes(0x9E37_79B9_7F4A_7C15, 4096)),
        ),
        (
            "dangling #id",
            dir.write("dangling.step", dangling.as_bytes()),
        ),
        ("no solid", dir.write("no_solid.step", no_solid.as_bytes())),
    ]
}

#[test]
fn inspect_bad_inputs_fail_with_one_line() {
    let dir = TempDir::new("inspect_bad_inputs");
    for (what, path) in bad_inputs(&dir) {
        for json in [false, true] {
            let mut args = vec!["inspect".as_ref(), path.as_os_str()];
            if json {
                args.push("--json".as_ref());
            }
            let out = run(&args);
            assert_one_line_failure(&out, &path, what);
            assert!(out.stdout.is_empty(), "{what}: wrote to stdout");
        }
    }
}

#[test]
fn mesh_bad_inputs_fail_with_one_line_and_no_file() {
    let dir = TempDir::new("mesh_bad_inputs");
    let inputs = bad_inputs(&dir);
    let before = dir.names();
    for (what, path) in &inputs {
        for ext in ["stl", "obj"] {
            let outp = dir.path(&format!("out.{ext}"));
            let out = run(&[
                "mesh".as_ref(),
                path.as_os_str(),
                "-o".as_ref(),
                outp.as_os_str(),
            ]);
            assert_one_line_failure(&out, path, what);
            assert!(out.stdout.is_empty(), "{what}: wrote to stdout");
            assert!(!outp.exists(), "{what}: {} was written", outp.display());
            assert_eq!(dir.names(), before, "{what}: files left behind");
        }
    }
}

#[test]
fn dangling_reference_names_the_ids() {
    let dir = TempDir::new("dangling_ids");
    let (_, path) = bad_inputs(&dir)
        .into_iter()
        .find(|(w, _)| *w == "dangling #id")
        .unwrap();
    let out = run(&["inspect".as_ref(), path.as_os_str()]);
    assert_one_line_failure(&out, &path, "dangling");
    assert!(stderr(&out).contains("#999999"), "{}", stderr(&out));
}

// The trigger exists only in debug builds (see `run` in crates/cli/src/main.rs).
#[cfg(debug_assertions)]
#[test]
fn caught_panic_is_one_line_with_exit_3() {
    let out = Command::new(BIN)
        .args(["inspect".as_ref(), fixture("box.step").as_os_str()])
        .env("FEATURES_TEST_PANIC", "1")
        .output()
        .expect("the binary runs");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert_eq!(err.lines().count(), 1, "{err:?}");
    assert!(!err.contains("panicked"), "{err}");
    let prefix = format!(
        "features: {}: internal error: ",
        fixture("box.step").display()
    );
    assert!(err.starts_with(&prefix), "{err}");
}

fn inspect_json(name: &str) -> Value {
    let path = fixture(name);
    let out = run(&["inspect".as_ref(), path.as_os_str(), "--json".as_ref()]);
    assert_eq!(out.status.code(), Some(0), "{name}: {}", stderr(&out));
    assert!(out.stderr.is_empty(), "{name}: stderr {}", stderr(&out));
    serde_json::from_slice(&out.stdout).expect("inspect --json prints JSON")
}

fn keys(v: &Value) -> Vec<&str> {
    v.as_object()
        .expect("an object")
        .keys()
        .map(String::as_str)
        .collect()
}

fn rel_err(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn inspect_json_box() {
    let v = inspect_json("box.step");
    assert_eq!(
        keys(&v),
        ["source", "units", "file_units", "solids", "warnings"]
    );
    assert_eq!(v["source"], fixture("box.step").display().to_string());
    assert_eq!(v["units"], "mm");
    assert_eq!(v["file_units"], "mm");
    assert!(v["warnings"].as_array().expect("warnings array").is_empty());
    let solids = v["solids"].as_array().expect("solids array");
    assert_eq!(solids.len(), 1);
    let s = &solids[0];
    assert_eq!(
        keys(s),
        [
            "volume_mm3",
            "area_mm2",
            "faces",
            "edges",
            "vertices",
            "genus",
            "closed",
            "surfaces",
            "bbox",
            "step_id",
            "curves",
            "voids",
            "watertight"
        ]
    );
    let vol = s["volume_mm3"].as_f64().expect("volume");
    assert!(rel_err(vol, 6000.0) < 1e-3, "volume {vol}");
    assert!(rel_err(s["area_mm2"].as_f64().unwrap(), 2200.0) < 1e-3);
    assert_eq!(s["faces"], 6);
    assert_eq!(s["edges"], 12);
    assert_eq!(s["vertices"], 8);
    assert_eq!(s["surfaces"]["plane"], 6);
    assert_eq!(s["closed"], true);
    assert_eq!(s["genus"], 0);
    assert_eq!(s["watertight"], true);
    assert_eq!(s["voids"], 0);
    let bbox: Vec<Vec<f64>> = serde_json::from_value(s["bbox"].clone()).expect("bbox");
    let want = [[0.0, 0.0, 0.0], [20.0, 30.0, 10.0]];
    for (got, want) in bbox.iter().flatten().zip(want.iter().flatten()) {
        assert!((got - want).abs() < 1e-3, "bbox {bbox:?}");
    }
}

/// Whether `text` holds a number in exponent notation (`1e-5`, `2.5E+3`).
fn has_exponent(text: &str) -> bool {
    let b = text.as_bytes();
    (1..b.len().saturating_sub(1)).any(|i| {
        (b[i] == b'e' || b[i] == b'E')
            && b[i - 1].is_ascii_digit()
            && (b[i + 1].is_ascii_digit() || b[i + 1] == b'-' || b[i + 1] == b'+')
    })
}

#[test]
fn inspect_json_numbers_are_plain_decimals() {
    assert!(has_exponent("[1.5e-7]") && has_exponent("2E+3") && !has_exponent("\"file\""));
    for name in ["inch_block.step", "capsule.step", "box.step"] {
        let path = fixture(name);
        let out = run(&["inspect".as_ref(), path.as_os_str(), "--json".as_ref()]);
        assert_eq!(out.status.code(), Some(0), "{name}: {}", stderr(&out));
        let v: Value = serde_json::from_slice(&out.stdout).expect("JSON");
        let numbers = serde_json::to_string(&v["solids"]).unwrap();
        assert!(
            !has_exponent(&numbers),
            "{name}: exponent notation in {numbers}"
        );
    }
}

#[test]
fn inspect_json_two_solids() {
    let v = inspect_json("two_solids.step");
    let solids = v["solids"].as_array().expect("solids");
    assert_eq!(solids.len(), 2);
    let want = fixture_json("two_solids.json");
    for (s, w) in solids.iter().zip(want["volumes_mm3"].as_array().unwrap()) {
        let (got, want) = (s["volume_mm3"].as_f64().unwrap(), w.as_f64().unwrap());
        assert!(rel_err(got, want) < 1e-3, "volume {got} vs {want}");
    }
}

#[test]
fn inspect_json_inch_block() {
    let v = inspect_json("inch_block.step");
    assert_eq!(v["units"], "mm");
    assert_eq!(v["file_units"], "inch");
    let want = fixture_json("inch_block.json")["volumes_mm3"][0]
        .as_f64()
        .unwrap();
    let got = v["solids"][0]["volume_mm3"].as_f64().unwrap();
    assert!(rel_err(got, want) < 1e-3, "volume {got} vs {want}");
}

#[test]
fn inspect_text_report() {
    let path = fixture("box.step");
    let out = run(&["inspect".as_ref(), path.as_os_str()]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = stdout(&out);
    for want in [
        format!("file:        {}", path.display()),
        "schema:".into(),
        "file units:  mm".into(),
        "volume:      6000.000 mm^3".into(),
        "area:        2200.000 mm^2".into(),
        "6 faces, 12 edges, 8 vertices".into(),
        "surfaces:    plane 6".into(),
        "curves:      line 12".into(),
        "genus:       0".into(),
        "closed:      yes".into(),
        "watertight:  yes".into(),
        "bbox:".into(),
        "warnings:    none".into(),
    ] {
        assert!(text.contains(&want), "no `{want}` in\n{text}");
    }
}

/// A triangle soup read back from a mesh file.
type Soup = Vec<[[f32; 3]; 3]>;

fn read_stl(bytes: &[u8]) -> Soup {
    assert!(bytes.len() >= 84, "STL shorter than its header");
    assert!(
        !bytes.starts_with(b"solid"),
        "binary STL header starts with `solid`"
    );
    let n = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
    assert_eq!((bytes.len() - 84) % 50, 0, "STL length");
    assert_eq!(n, (bytes.len() - 84) / 50, "STL count vs length");
    let f = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
    let mut soup = vec![];
    for i in 0..n {
        let r = 84 + 50 * i;
        let normal = [f(r), f(r + 4), f(r + 8)];
        let t: [[f32; 3]; 3] =
            std::array::from_fn(|k| std::array::from_fn(|j| f(r + 12 + 12 * k + 4 * j)));
        // The stored normal agrees with the vertex order.
        let c = cross(sub(t[1], t[0]), sub(t[2], t[0]));
        let len = dot(c, c).sqrt();
        if len > 1e-9 {
            let cos = dot(c, normal.map(f64::from)) / len;
            assert!(cos > 0.99, "facet {i}: normal {normal:?} vs winding {c:?}");
        }
        soup.push(t);
    }
    soup
}

/// Reads an OBJ, returning the triangles and the group names.
fn read_obj(text: &str) -> (Soup, Vec<String>) {
    let mut v: Vec<[f32; 3]> = vec![];
    let mut soup = vec![];
    let mut groups = vec![];
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let p: Vec<f32> = it.map(|x| x.parse().expect("v coordinate")).collect();
                assert_eq!(p.len(), 3, "{line}");
                v.push([p[0], p[1], p[2]]);
            }
            Some("f") => {
                let idx: Vec<usize> = it.map(|x| x.parse().expect("f index")).collect();
                assert_eq!(idx.len(), 3, "{line}");
                soup.push(std::array::from_fn(|k| {
                    assert!(idx[k] >= 1 && idx[k] <= v.len(), "{line}: bad index");
                    v[idx[k] - 1]
                }));
            }
            Some("o") => groups.push(it.collect::<Vec<_>>().join(" ")),
            _ => {}
        }
    }
    (soup, groups)
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f64; 3] {
    std::array::from_fn(|k| a[k] as f64 - b[k] as f64)
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Welds by exact `f32` position and checks that every edge is shared by exactly two
/// triangles, once in each direction. Returns the enclosed (signed) volume.
fn check_closed_and_volume(soup: &Soup, what: &str) -> f64 {
    assert!(!soup.is_empty(), "{what}: no triangles");
    let mut ids: HashMap<[u32; 3], usize> = HashMap::new();
    let mut id = |p: [f32; 3]| {
        let n = ids.len();
        *ids.entry(p.map(f32::to_bits)).or_insert(n)
    };
    let mut edges: HashMap<(usize, usize), (u32, u32)> = HashMap::new();
    let mut volume = 0.0;
    for t in soup {
        let v = t.map(&mut id);
        assert!(
            v[0] != v[1] && v[1] != v[2] && v[0] != v[2],
            "{what}: degenerate triangle {t:?}"
        );
        for k in 0..3 {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            let e = edges.entry((a.min(b), a.max(b))).or_default();
            if a < b {
                e.0 += 1
            } else {
                e.1 += 1
            }
        }
        let p = t.map(|q| q.map(|x| x as f64));
        volume += dot(p[0], cross(p[1], p[2])) / 6.0;
    }
    let bad = edges.values().filter(|&&(f, b)| f != 1 || b != 1).count();
    assert_eq!(
        bad,
        0,
        "{what}: {bad} of {} edges not shared by two triangles",
        edges.len()
    );
    volume
}

fn mesh_to(dir: &TempDir, fixture_name: &str, out_name: &str, extra: &[&str]) -> (PathBuf, Output) {
    let input = fixture(fixture_name);
    let outp = dir.path(out_name);
    let mut args = vec![
        "mesh".as_ref(),
        input.as_os_str(),
        "-o".as_ref(),
        outp.as_os_str(),
    ];
    args.extend(extra.iter().map(std::ffi::OsStr::new));
    let out = run(&args);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{fixture_name}: {}",
        stderr(&out)
    );
    assert!(out.stderr.is_empty(), "{}", stderr(&out));
    let summary = stdout(&out);
    assert_eq!(summary.lines().count(), 1, "summary: {summary}");
    for want in ["triangles", "vertices", "watertight: yes"] {
        assert!(summary.contains(want), "no `{want}` in summary: {summary}");
    }
    (outp, out)
}

#[test]
fn mesh_stl_cylinder_is_closed_with_right_volume() {
    let dir = TempDir::new("mesh_stl_cylinder");
    let (outp, _) = mesh_to(&dir, "cylinder.step", "cylinder.stl", &[]);
    assert_eq!(dir.names(), ["cylinder.stl"], "temporary files left behind");
    let bytes = std::fs::read(&outp).expect("STL written");
    let header = String::from_utf8_lossy(&bytes[..80]);
    assert!(header.contains("cylinder.step"), "header: {header}");
    let soup = read_stl(&bytes);
    let vol = check_closed_and_volume(&soup, "cylinder.stl");
    let want = std::f64::consts::PI * 100.0 * 25.0;
    assert!(rel_err(vol, want) < 0.01, "volume {vol} vs {want}");
}

#[test]
fn mesh_tolerance_refines_the_mesh() {
    let dir = TempDir::new("mesh_tolerance");
    let (coarse, _) = mesh_to(&dir, "cylinder.step", "coarse.stl", &["--tolerance", "0.5"]);
    let (fine, _) = mesh_to(&dir, "cylinder.step", "fine.stl", &["--tolerance", "0.01"]);
    let coarse = read_stl(&std::fs::read(coarse).unwrap());
    let fine = read_stl(&std::fs::read(fine).unwrap());
    assert!(
        fine.len() > coarse.len(),
        "{} vs {}",
        fine.len(),
        coarse.len()
    );
    let want = std::f64::consts::PI * 100.0 * 25.0;
    let (vc, vf) = (
        check_closed_and_volume(&coarse, "coarse"),
        check_closed_and_volume(&fine, "fine"),
    );
    assert!(rel_err(vf, want) < rel_err(vc, want), "{vf} vs {vc}");
    assert!(rel_err(vf, want) < 2e-3, "fine volume {vf}");
}

#[test]
fn mesh_obj_sphere_boss_is_closed_with_right_volume() {
    let dir = TempDir::new("mesh_obj_sphere_boss");
    let (outp, _) = mesh_to(&dir, "sphere_boss.step", "sphere_boss.obj", &[]);
    assert_eq!(
        dir.names(),
        ["sphere_boss.obj"],
        "temporary files left behind"
    );
    let text = std::fs::read_to_string(&outp).expect("OBJ written");
    let (soup, groups) = read_obj(&text);
    assert_eq!(groups, ["solid_1"]);
    let vol = check_closed_and_volume(&soup, "sphere_boss.obj");
    let want = fixture_json("sphere_boss.json")["volumes_mm3"][0]
        .as_f64()
        .unwrap();
    assert!(rel_err(vol, want) < 0.01, "volume {vol} vs {want}");
}

#[test]
fn mesh_obj_two_solids_has_one_group_per_solid() {
    let dir = TempDir::new("mesh_obj_two_solids");
    let (outp, out) = mesh_to(&dir, "two_solids.step", "two.obj", &[]);
    assert!(stdout(&out).contains("2 solids"), "{}", stdout(&out));
    let (soup, groups) = read_obj(&std::fs::read_to_string(outp).unwrap());
    assert_eq!(groups, ["solid_1", "solid_2"]);
    let vol = check_closed_and_volume(&soup, "two.obj");
    assert!(rel_err(vol, 7000.0) < 1e-6, "volume {vol}");
}

#[test]
fn mesh_unknown_extension_fails_and_writes_nothing() {
    let dir = TempDir::new("mesh_unknown_ext");
    for name in ["out.xyz", "out"] {
        let outp = dir.path(name);
        let out = run(&[
            "mesh".as_ref(),
            fixture("box.step").as_os_str(),
            "-o".as_ref(),
            outp.as_os_str(),
        ]);
        assert_one_line_failure(&out, &outp, name);
        assert!(out.stdout.is_empty());
        assert!(dir.names().is_empty(), "{name}: wrote {:?}", dir.names());
    }
}

#[test]
fn mesh_into_missing_directory_fails_with_one_line() {
    let dir = TempDir::new("mesh_missing_dir");
    let outp = dir.path("no/such/dir/out.stl");
    let out = run(&[
        "mesh".as_ref(),
        fixture("box.step").as_os_str(),
        "-o".as_ref(),
        outp.as_os_str(),
    ]);
    assert_one_line_failure(&out, &outp, "missing output dir");
    assert!(dir.names().is_empty(), "wrote {:?}", dir.names());
}

#[test]
fn usage_errors_exit_2() {
    for args in [
        vec![],
        vec!["frobnicate"],
        vec!["inspect"],
        vec!["mesh", "x.step"],
        vec!["mesh", "x.step", "-o", "x.stl", "--tolerance", "0"],
        vec!["mesh", "x.step", "-o", "x.stl", "--tolerance", "abc"],
    ] {
        let out = Command::new(BIN).args(&args).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(!stderr(&out).contains("panicked"), "{args:?}");
    }
}

#[test]
fn help_mentions_the_verbs() {
    let out = Command::new(BIN).arg("--help").output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    let text = stdout(&out);
    assert!(
        text.contains("inspect") && text.contains("mesh") && text.contains("extract"),
        "{text}"
    );
    for verb in ["inspect", "mesh", "extract"] {
        let out = Command::new(BIN).args([verb, "--help"]).output().unwrap();
        assert_eq!(out.status.code(), Some(0), "{verb} --help");
        assert!(stdout(&out).contains("Usage: features"), "{verb} --help");
    }
    let out = Command::new(BIN).args(["mesh", "--help"]).output().unwrap();
    assert!(stdout(&out).contains("[default: 0.05]"));
}

#[test]
fn mesh_failure_after_writing_removes_the_temporary_file() {
    // The output name is taken by a directory: the mesh is written to the temporary file, then
    // the rename fails. The temporary file must go, and the directory stay as it was.
    let dir = TempDir::new("mesh_rename_fails");
    let outp = dir.path("taken.stl");
    std::fs::create_dir(&outp).unwrap();
    std::fs::write(outp.join("keep"), b"x").unwrap();
    let out = run(&[
        "mesh".as_ref(),
        fixture("box.step").as_os_str(),
        "-o".as_ref(),
        outp.as_os_str(),
    ]);
    assert_one_line_failure(&out, &outp, "output is a directory");
    assert!(out.stdout.is_empty());
    assert_eq!(dir.names(), ["taken.stl"], "temporary file left behind");
    assert!(outp.join("keep").exists());
}

// ---------- features extract ----------

#[test]
fn extract_bad_inputs_fail_with_one_line_and_export_nothing() {
    let dir = TempDir::new("extract_bad_inputs");
    for (what, path) in bad_inputs(&dir) {
        let export = dir.path(&format!("out-{what}").replace(' ', "_"));
        let out = run(&[
            "extract".as_ref(),
            path.as_os_str(),
            "--json".as_ref(),
            "--export".as_ref(),
            export.as_os_str(),
        ]);
        assert_one_line_failure(&out, &path, what);
        assert!(out.stdout.is_empty(), "{what}: wrote to stdout");
        assert!(!export.exists(), "{what}: created the export directory");
    }
}

#[test]
fn extract_json_plate_boss_boss_has_the_exact_shape() {
    let out = run(&[
        "extract".as_ref(),
        fixture("plate_boss_boss.step").as_os_str(),
        "--json".as_ref(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_str(&stdout(&out)).expect("JSON");
    assert_eq!(
        keys(&v),
        [
            "schema",
            "source",
            "units",
            "part",
            "features",
            "support_features",
            "build_order",
            "depth",
            "concave_loops",
            "warnings"
        ]
    );
    assert_eq!(v["schema"], "features.extract/1");
    // The bosses stand on the plate: no support.
    assert_eq!(v["support_features"], serde_json::json!([]));
    // Both roots of the two bosses are split off, each naming the feature it bounds.
    let loops = v["concave_loops"].as_array().expect("concave_loops array");
    assert_eq!(loops.len(), 2);
    for l in loops {
        assert_eq!(l["split"], true, "{l}");
        assert!(l["feature"].as_u64().is_some_and(|k| k == 1 || k == 2));
        assert!(!l["edges"].as_array().unwrap().is_empty());
    }
    assert_eq!(v["units"], "mm");
    assert_eq!(
        keys(&v["part"]),
        ["volume_mm3", "area_mm2", "faces", "genus"]
    );
    let reference = fixture_json("plate_boss_boss.json");
    let want = reference["volumes_mm3"][0].as_f64().unwrap();
    assert!(rel_err(v["part"]["volume_mm3"].as_f64().unwrap(), want) < 1e-3);
    let feats = v["features"].as_array().unwrap();
    assert_eq!(feats.len(), 3);
    for (k, f) in feats.iter().enumerate() {
        assert_eq!(
            keys(f),
            [
                "id",
                "kind",
                "subtype",
                "reference",
                "parents",
                "volume_mm3",
                "faces",
                "root_loops"
            ]
        );
        assert_eq!(keys(&f["reference"]), ["surface", "step_face", "normal"]);
        assert_eq!(f["id"], k);
        assert_eq!(f["kind"], "two5d");
    }
    assert_eq!(feats[0]["reference"]["surface"], "build_plate");
    assert_eq!(feats[1]["parents"], serde_json::json!([0]));
    assert_eq!(feats[2]["parents"], serde_json::json!([1]));
    assert_eq!(v["build_order"], serde_json::json!([0, 1, 2]));
    assert_eq!(v["depth"], 2);
    // Every part face is in exactly one feature.
    let mut faces: Vec<u64> = feats
        .iter()
        .flat_map(|f| {
            f["faces"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_u64().unwrap())
        })
        .collect();
    let n = faces.len();
    faces.sort_unstable();
    faces.dedup();
    assert_eq!(faces.len(), n);
    assert_eq!(n as u64, v["part"]["faces"].as_u64().unwrap());
    let sum: f64 = feats
        .iter()
        .map(|f| f["volume_mm3"].as_f64().unwrap())
        .sum();
    assert!(rel_err(sum, want) < 5e-3, "features add up to {sum}");
}

#[test]
fn extract_export_writes_closed_solids_that_read_back() {
    let dir = TempDir::new("extract_export");
    let export = dir.path("capsule");
    let out = run(&[
        "extract".as_ref(),
        fixture("capsule.step").as_os_str(),
        "--json".as_ref(),
        "--export".as_ref(),
        export.as_os_str(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_str(&stdout(&out)).expect("JSON");
    let feats = v["features"].as_array().unwrap();
    assert_eq!(feats.len(), 3, "capsule: body and two bosses");
    for f in feats {
        let id = f["id"].as_u64().unwrap();
        let step = export.join(format!("feature_{id}.step"));
        let stl = export.join(format!("feature_{id}.stl"));
        assert!(stl.exists());
        let back = run(&["inspect".as_ref(), step.as_os_str(), "--json".as_ref()]);
        assert!(back.status.success(), "{}", stderr(&back));
        let r: Value = serde_json::from_str(&stdout(&back)).expect("JSON");
        let s = &r["solids"][0];
        assert_eq!(s["closed"], true);
        assert_eq!(s["watertight"], true);
        let vol = s["volume_mm3"].as_f64().unwrap();
        assert!(
            rel_err(vol, f["volume_mm3"].as_f64().unwrap()) < 5e-3,
            "feature {id}: {vol}"
        );
        let soup = read_stl(&std::fs::read(&stl).unwrap());
        let stl_vol = check_closed_and_volume(&soup, "exported stl");
        assert!(
            rel_err(stl_vol, vol) < 0.02,
            "feature {id}: stl {stl_vol} vs {vol}"
        );
    }
    // No temporary files left behind.
    assert!(std::fs::read_dir(&export).unwrap().all(|e| !e
        .unwrap()
        .file_name()
        .to_string_lossy()
        .ends_with(".tmp")));
}

#[test]
fn extract_text_tree_shows_the_chain() {
    let out = run(&[
        "extract".as_ref(),
        fixture("plate_boss_boss.step").as_os_str(),
    ]);
    assert!(out.status.success());
    let text = stdout(&out);
    assert!(
        text.contains("feature 0  two5d stretch  on the build plate"),
        "{text}"
    );
    assert!(text.contains("└─ feature 1"), "{text}");
    assert!(text.contains("   └─ feature 2"), "{text}");
}

/// A file whose header holds a merge conflict and whose data holds an entity of no schema
/// (that the solid does not use) is read; `extract` and `plan` both say what the reader
/// skipped, on stderr or stdout and in their JSON.
#[test]
fn the_readers_warnings_reach_extract_and_plan() {
    let dir = TempDir::new("reader-warnings");
    let text = std::fs::read_to_string(fixture("box.step")).expect("box.step");
    let text = text
        .replacen("HEADER;\n", "HEADER;\n<<<<<<< HEAD\n", 1)
        .replacen("DATA;\n", "DATA;\n#999999=MISSPELT_ENTITY_NAME('x');\n", 1);
    assert!(text.contains("<<<<<<<") && text.contains("MISSPELT"));
    let part = dir.write("conflict.step", text.as_bytes());
    let said = |all: &str| {
        all.contains("line 3: header line `<<<<<<< HEAD` skipped")
            && all.contains("#999999: unknown entity MISSPELT_ENTITY_NAME")
    };

    let extract = run(&["extract".as_ref(), part.as_os_str()]);
    assert_eq!(extract.status.code(), Some(0), "{}", stderr(&extract));
    let shown = format!("{}{}", stdout(&extract), stderr(&extract));
    assert!(said(&shown), "{shown}");
    let json = run(&["extract".as_ref(), part.as_os_str(), "--json".as_ref()]);
    assert_eq!(json.status.code(), Some(0), "{}", stderr(&json));
    let v: Value = serde_json::from_slice(&json.stdout).expect("json");
    let warnings = v["warnings"].to_string();
    assert!(said(&warnings), "{warnings}");

    let out = dir.path("plan");
    let plan = run(&[
        "plan".as_ref(),
        part.as_os_str(),
        "--machine".as_ref(),
        "marlin".as_ref(),
        "--orient".as_ref(),
        "modelled".as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert_eq!(plan.status.code(), Some(0), "{}", stderr(&plan));
    assert!(said(&stderr(&plan)), "{}", stderr(&plan));
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("plan.json")).expect("plan.json"))
            .expect("json");
    let warnings = report["warnings"].to_string();
    assert!(said(&warnings), "{warnings}");
}
