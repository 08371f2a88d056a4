//! The preview page opens in a real browser (headless Chromium) and draws (issue 19): the page
//! a plan writes and the one `features preview` writes. `.ci/run` installs Debian's chromium
//! when it is missing and sets `FEATURES_REQUIRE_BROWSER=1`, so there the browser must be
//! found; elsewhere a machine without Chromium skips these tests and says so.
//!
//! A refused plan's page (issue 31) and the simulation view's pages (issue 36 item 2) are built
//! here directly with `preview::html`; set `FEATURES_KEEP_PREVIEW=DIR` to keep those pages and
//! their screenshots in `DIR` to look at.

use preview::{
    FeatureMesh, HeadShape, HeadSize, MachineShape, Mark, MarkKind, Preview, SimArm, SimFlags,
    SimMachine, SimMargins, SimMove, SimTable, Simulation,
};
use robot_post::kuka::Pose;
use robot_post::{MachineKind, MachineProfile};
use slicer::toolpath::{MoveKind, PathPoint, Role, ToolPath};
use std::path::{Path, PathBuf};
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_features");

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name)
}

/// The Chromium to run, if any.
fn chromium() -> Option<PathBuf> {
    let named = std::env::var_os("CHROMIUM").map(PathBuf::from);
    let found = named.into_iter().chain(
        [
            "/usr/bin/chromium",
            "/usr/bin/chromium-browser",
            "/usr/bin/google-chrome",
        ]
        .iter()
        .map(PathBuf::from),
    );
    let c = found.into_iter().find(|p| p.is_file());
    if c.is_none() {
        assert!(
            std::env::var_os("FEATURES_REQUIRE_BROWSER").is_none(),
            "FEATURES_REQUIRE_BROWSER is set but no Chromium was found (apt-get install chromium)"
        );
        eprintln!("no Chromium on this machine: the browser test is skipped");
    }
    c
}

fn headless(browser: &Path, page: &Path, extra: &[&str]) -> std::process::Output {
    headless_url(browser, &format!("file://{}", page.display()), extra)
}

fn headless_url(browser: &Path, url: &str, extra: &[&str]) -> std::process::Output {
    Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-dev-shm-usage",
            "--enable-unsafe-swiftshader",
            "--use-angle=swiftshader",
            "--window-size=1000,700",
            "--virtual-time-budget=10000",
        ])
        .args(extra)
        .arg(url)
        .output()
        .expect("chromium runs")
}

/// The DOM of the page at `url` once its script ran (`--dump-dom`), which must have run
/// without an error (`what` names the page in the failure).
fn dom_at(browser: &Path, url: &str, what: &str) -> String {
    let out = headless_url(browser, url, &["--dump-dom"]);
    let dom = String::from_utf8_lossy(&out.stdout).into_owned();
    assert_eq!(
        body_attribute(&dom, "data-error"),
        None,
        "{what}: script error"
    );
    dom
}

/// [`dom_at`] of the page in the file `page`.
fn dom_of(browser: &Path, page: &Path, what: &str) -> String {
    dom_at(browser, &format!("file://{}", page.display()), what)
}

/// With `FEATURES_KEEP_PREVIEW=DIR`, the files of `dir` whose names `wanted` copied into DIR
/// to look at.
fn keep_pages(dir: &Path, wanted: impl Fn(&str) -> bool) {
    let Some(keep) = std::env::var_os("FEATURES_KEEP_PREVIEW") else {
        return;
    };
    let keep = PathBuf::from(keep);
    std::fs::create_dir_all(&keep).unwrap();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        if e.file_name().to_str().is_some_and(&wanted) {
            std::fs::copy(e.path(), keep.join(e.file_name())).unwrap();
        }
    }
}

/// Opens `page`, checks that its script drew without an error, and that the screenshot holds a
/// picture: a share of pixels off the background, in several colours.
fn assert_draws(browser: &Path, page: &Path, dir: &Path) {
    let dom = headless(browser, page, &["--dump-dom"]);
    let dom = String::from_utf8_lossy(&dom.stdout);
    let body = dom
        .split("<body")
        .nth(1)
        .and_then(|b| b.split('>').next())
        .unwrap_or("");
    assert!(!body.contains("data-error"), "script error: {body}");
    let drawn: u64 = body
        .split("data-drawn=\"")
        .nth(1)
        .and_then(|s| s.split('"').next())
        .and_then(|s| s.parse().ok())
        .expect("the page says it drew");
    assert!(drawn > 0);
    let shot = dir.join("shot.png");
    let out = headless(
        browser,
        page,
        &[&format!("--screenshot={}", shot.display())],
    );
    assert!(shot.is_file(), "{}", String::from_utf8_lossy(&out.stderr));
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&shot).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let px = info.color_type.samples();
    let (w, h) = (info.width as usize, info.height as usize);
    // The view is right of the 300 px side panel; its background is (245, 246, 249).
    let mut off = 0usize;
    let mut all = 0usize;
    let mut colours = std::collections::HashSet::new();
    for y in 0..h {
        for x in 320..w {
            let i = (y * w + x) * px;
            let c = [buf[i], buf[i + 1], buf[i + 2]];
            all += 1;
            let bg = [245i32, 246, 249];
            if (0..3).any(|k| (c[k] as i32 - bg[k]).abs() > 12) {
                off += 1;
                colours.insert([c[0] / 32, c[1] / 32, c[2] / 32]);
            }
        }
    }
    let share = off as f64 / all.max(1) as f64;
    assert!(
        share > 0.03,
        "only {:.1} % of the view was drawn",
        100.0 * share
    );
    assert!(colours.len() >= 4, "{} colours", colours.len());
}

#[test]
fn a_plans_preview_opens_offline_and_draws() {
    let Some(browser) = chromium() else { return };
    let dir = std::env::temp_dir().join(format!("features-preview-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = dir.join("plan");
    let o = Command::new(BIN)
        .arg("plan")
        .arg(fixture("plate_boss_boss.step"))
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let page = out.join("preview.html");
    let text = std::fs::read_to_string(&page).unwrap();
    for bad in ["http:", "https:", "//"] {
        assert!(!text.contains(bad), "the page refers to `{bad}`");
    }
    assert_draws(&browser, &page, &dir);
    // The features alone.
    let alone = dir.join("capsule.html");
    let o = Command::new(BIN)
        .arg("preview")
        .arg(fixture("capsule.step"))
        .arg("-o")
        .arg(&alone)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_draws(&browser, &alone, &dir);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A screenshot's pixels, RGB(A) rows.
struct Shot {
    w: usize,
    h: usize,
    px: usize,
    buf: Vec<u8>,
}

impl Shot {
    /// Takes the screenshot of `page` (written to `dir/name.html`), at 1000 × 700.
    fn of(browser: &Path, page: &str, dir: &Path, name: &str) -> Shot {
        let file = dir.join(format!("{name}.html"));
        std::fs::write(&file, page).unwrap();
        let png = dir.join(format!("{name}.png"));
        Shot::at(browser, &format!("file://{}", file.display()), &png)
    }

    /// Takes the screenshot of the page at `url` into `png`, at 1000 × 700.
    fn at(browser: &Path, url: &str, png: &Path) -> Shot {
        let out = headless_url(browser, url, &[&format!("--screenshot={}", png.display())]);
        assert!(png.is_file(), "{}", String::from_utf8_lossy(&out.stderr));
        let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(png).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        Shot {
            w: info.width as usize,
            h: info.height as usize,
            px: info.color_type.samples(),
            buf,
        }
    }

    /// Pixels of the view (right of the 300 px side panel) for which `keep` holds.
    fn count(&self, keep: impl Fn([u8; 3]) -> bool) -> usize {
        let mut n = 0;
        for y in 0..self.h {
            for x in VIEW_LEFT..self.w {
                let i = (y * self.w + x) * self.px;
                n += usize::from(keep([self.buf[i], self.buf[i + 1], self.buf[i + 2]]));
            }
        }
        n
    }

    /// Pure red pixels: the marks' colour, which nothing else on the page is drawn in.
    fn red(&self) -> usize {
        self.count(|c| c[0] >= 220 && c[1] <= 40 && c[2] <= 40)
    }

    /// The simulated machine's orange (1, 0.36, 0), shaded: green about 0.36 of red, no blue.
    /// Neither a feature's colour nor the colour ramps have it (the palette's orange has green
    /// half of red, the ramp's warm end some blue).
    fn orange(&self) -> usize {
        self.count(is_orange)
    }

    /// Which pixels of the view are [`Shot::orange`]'s, row by row.
    fn orange_mask(&self) -> Vec<bool> {
        let mut out = Vec::with_capacity(self.w * self.h);
        for y in 0..self.h {
            for x in VIEW_LEFT..self.w {
                let i = (y * self.w + x) * self.px;
                out.push(is_orange([self.buf[i], self.buf[i + 1], self.buf[i + 2]]));
            }
        }
        out
    }

    /// Pixels off the view's background (245, 246, 249).
    fn drawn(&self) -> usize {
        let bg = [245i32, 246, 249];
        self.count(|c| (0..3).any(|k| (i32::from(c[k]) - bg[k]).abs() > 12))
    }
}

/// The simulated machine's orange ([`Shot::orange`]).
fn is_orange(c: [u8; 3]) -> bool {
    let (r, g, b) = (f64::from(c[0]), f64::from(c[1]), f64::from(c[2]));
    r >= 60.0 && b <= 0.04 * r && (0.3 * r..=0.42 * r).contains(&g)
}

/// First pixel column of the view, past the side panel.
const VIEW_LEFT: usize = 320;

/// Pure red pixels a single mark (a dot of 9 × 9 px, a 5 px thick segment) covers at least.
const MIN_MARK_PIXELS: usize = 30;

/// A box's surface as a feature mesh.
fn box_mesh(id: usize, label: &str, lo: [f32; 3], hi: [f32; 3]) -> FeatureMesh {
    let positions = (0..8)
        .map(|k| {
            [
                if k & 1 == 0 { lo[0] } else { hi[0] },
                if k & 2 == 0 { lo[1] } else { hi[1] },
                if k & 4 == 0 { lo[2] } else { hi[2] },
            ]
        })
        .collect();
    let quads = [
        [0, 1, 3, 2],
        [4, 6, 7, 5],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 5, 7, 3],
    ];
    let triangles = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    FeatureMesh {
        id,
        label: label.into(),
        positions,
        triangles,
        allowance: None,
    }
}

/// The allowance ramp's warm end (least left), shaded: green about half of red, a little blue.
fn is_warm(c: [u8; 3]) -> bool {
    let (r, g, b) = (f64::from(c[0]), f64::from(c[1]), f64::from(c[2]));
    r >= 60.0 && (0.38 * r..=0.56 * r).contains(&g) && (0.08 * r..=0.22 * r).contains(&b)
}

/// The ramp's cool end (most left): blue, little red or green.
fn is_cool(c: [u8; 3]) -> bool {
    let (r, g, b) = (f64::from(c[0]), f64::from(c[1]), f64::from(c[2]));
    b >= 60.0 && r <= 0.3 * b && g <= 0.3 * b
}

#[test]
fn the_part_is_coloured_by_the_machining_allowance_left() {
    let Some(browser) = chromium() else { return };
    let dir = std::env::temp_dir().join(format!("features-allowance-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    // Three boxes side by side: a millimetre left over the first, two over the second, the
    // third not measured.
    let boxes: Vec<FeatureMesh> = [1.0f32, 2.0, f32::NAN]
        .iter()
        .enumerate()
        .map(|(i, &left)| {
            let x = -30.0 + 22.0 * i as f32;
            let mut m = box_mesh(i, "two5d", [x, -10.0, 0.0], [x + 18.0, 10.0, 12.0]);
            m.allowance = Some(preview::MeshAllowance {
                requested: 1.0,
                left: vec![left; m.positions.len()],
            });
            m
        })
        .collect();
    let page = preview::html(&Preview {
        title: "allowance".into(),
        features: boxes,
        ..Preview::default()
    });
    let file = dir.join("allowance.html");
    std::fs::write(&file, &page).unwrap();
    // At first each feature has its own colour; `#part=allowance` (as choosing "machining
    // allowance left" does) colours the two measured boxes' corners by what was left.
    let dom = dom_of(&browser, &file, "by feature");
    assert_eq!(
        body_attribute(&dom, "data-part-colour").as_deref(),
        Some("feature")
    );
    let url = format!("file://{}#part=allowance", file.display());
    let dom = dom_at(&browser, &url, "by the allowance");
    assert_eq!(
        body_attribute(&dom, "data-part-colour").as_deref(),
        Some("allowance")
    );
    // 12 triangles a box, 3 corners each, two boxes measured.
    assert_eq!(
        body_attribute(&dom, "data-allowance-vertices").as_deref(),
        Some("72")
    );
    assert_eq!(
        body_attribute(&dom, "data-allowance-range").as_deref(),
        Some("1 2")
    );
    assert!(
        dom.contains("1.000 to 2.000 mm"),
        "the legend gives the range"
    );
    // The picture: the first box warm, the second cool; by feature, neither.
    let coloured = Shot::at(&browser, &url, &dir.join("allowance.png"));
    let plain = Shot::of(&browser, &page, &dir, "plain");
    let (warm, cool) = (coloured.count(is_warm), coloured.count(is_cool));
    assert!(
        warm > 2000 && cool > 2000,
        "{warm} warm, {cool} cool pixels"
    );
    assert!(
        plain.count(is_warm) < warm / 10 && plain.count(is_cool) < cool / 10,
        "by feature: {} warm, {} cool pixels",
        plain.count(is_warm),
        plain.count(is_cool)
    );
    keep_pages(&dir, |f| ["allowance.html", "allowance.png"].contains(&f));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A small two-feature path: rectangular rings on a 40 × 30 × 4 mm plate, then circles of a
/// boss (radius 6 mm, 12 mm high) on it, 0.4 mm layers.
fn synthetic_path() -> ToolPath {
    let mut points = vec![];
    let mut push = |feature: usize, layer: usize, p: [f64; 3], kind: MoveKind| {
        points.push(PathPoint {
            feature: feature as u32,
            layer: layer as u32,
            kind,
            p,
            axis: [0.0, 0.0, 1.0],
            e: 0.0,
            thickness: 0.4,
            width: 0.45,
            role: Role::Perimeter,
        })
    };
    for layer in 0..10 {
        let z = 0.4 * (layer + 1) as f64;
        for ring in 0..4 {
            let d = 0.5 * ring as f64;
            let corners = [
                [d, d],
                [40.0 - d, d],
                [40.0 - d, 30.0 - d],
                [d, 30.0 - d],
                [d, d],
            ];
            for (k, c) in corners.iter().enumerate() {
                let kind = if k == 0 {
                    MoveKind::Travel
                } else {
                    MoveKind::Print
                };
                push(0, layer, [c[0], c[1], z], kind);
            }
        }
    }
    for layer in 0..30 {
        let z = 4.0 + 0.4 * (layer + 1) as f64;
        for k in 0..=36 {
            let t = std::f64::consts::TAU * k as f64 / 36.0;
            let kind = if k == 0 {
                MoveKind::Travel
            } else {
                MoveKind::Print
            };
            push(
                1,
                layer,
                [20.0 + 6.0 * t.cos(), 15.0 + 6.0 * t.sin(), z],
                kind,
            );
        }
    }
    ToolPath { points }
}

/// One mark of each kind, all inside the part's box (so that they do not move the view).
fn one_of_each() -> Vec<Mark> {
    vec![
        Mark {
            kind: MarkKind::Collision,
            feature: Some(1),
            text: "move 412: the body meets the table 3.1 mm deep".into(),
            points: vec![[32.0, 15.0, 10.0], [26.0, 15.0, 10.0]],
        },
        Mark {
            kind: MarkKind::Unsupported,
            feature: Some(1),
            text: "layer 20: 14.0 mm² unsupported".into(),
            points: vec![
                [8.0, 4.0, 12.0],
                [14.0, 4.0, 12.0],
                [14.0, 9.0, 12.0],
                [8.0, 9.0, 12.0],
            ],
        },
        Mark {
            kind: MarkKind::Unreachable,
            feature: Some(0),
            text: "point 77 is out of the arm's reach".into(),
            points: vec![[36.0, 26.0, 4.0]],
        },
        Mark {
            kind: MarkKind::SelfCheck,
            feature: Some(1),
            text: "self-check: deposited volume -6.2 % of the feature's".into(),
            points: vec![[14.0, 21.0, 16.0], [20.0, 22.0, 16.0], [26.0, 21.0, 16.0]],
        },
        Mark {
            kind: MarkKind::Machine,
            feature: None,
            text: "needs B 126.254 degrees, outside the B limits".into(),
            points: vec![[2.0, 28.0, 0.4], [20.0, 28.0, 0.4]],
        },
    ]
}

/// The page of a refused plan of [`synthetic_path`] with `marks`, the bed and the head (or
/// neither).
fn refused_page(path: &ToolPath, marks: Vec<Mark>, machine: bool) -> String {
    let s = 0.5f64.sqrt();
    preview::html(&Preview {
        title: "synthetic plate and boss".into(),
        features: vec![
            box_mesh(0, "two5d plate", [0.0, 0.0, 0.0], [40.0, 30.0, 4.0]),
            box_mesh(1, "two5d boss", [14.0, 9.0, 4.0], [26.0, 21.0, 16.0]),
        ],
        path: Some(path),
        figures: vec![("features".into(), "2".into())],
        refusal: Some(
            "5 problems: collisions, unsupported beads, reach, self-check, B limits".into(),
        ),
        marks,
        machine: machine.then_some(MachineShape::Bed {
            min: [-20.0, -20.0],
            max: [60.0, 50.0],
            z: 0.0,
        }),
        head: machine.then_some(HeadShape {
            tip: [32.0, 15.0, 10.0],
            axis: [s, 0.0, s],
            tip_radius: 0.5,
            half_angle_deg: 30.0,
            cone_length: 8.0,
            body_radius: 20.0,
            body_length: 60.0,
        }),
        simulation: None,
    })
}

/// The value of `attribute` on the page's `<body>` in a DOM dump.
fn body_attribute(dom: &str, attribute: &str) -> Option<String> {
    let body = dom.split("<body").nth(1)?.split('>').next()?;
    let v = body
        .split(&format!("{attribute}=\""))
        .nth(1)?
        .split('"')
        .next()?;
    Some(v.to_string())
}

#[test]
fn a_refused_plans_preview_marks_each_failure_in_red_and_lists_it() {
    let Some(browser) = chromium() else { return };
    let dir = std::env::temp_dir().join(format!("features-refused-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let path = synthetic_path();
    let marks = one_of_each();
    let page = refused_page(&path, marks.clone(), true);
    for bad in ["http:", "https:", "//"] {
        assert!(!page.contains(bad), "the page refers to `{bad}`");
    }

    // The Problems panel lists every mark's text, and the figures say why the plan was refused.
    let file = dir.join("refused.html");
    std::fs::write(&file, &page).unwrap();
    let dom = dom_of(&browser, &file, "refused");
    assert_eq!(
        body_attribute(&dom, "data-marks"),
        Some(marks.len().to_string())
    );
    let list = dom
        .split("id=\"problemlist\"")
        .nth(1)
        .and_then(|s| s.split("id=\"problemsleft\"").next())
        .expect("a Problems list");
    for m in &marks {
        assert!(
            list.contains(&m.text),
            "the Problems panel lacks `{}`",
            m.text
        );
        assert!(list.contains(m.kind.name()));
    }
    assert!(dom.contains("refused: 5 problems"), "no refusal line");
    // `#problem=N` selects the N-th problem (as a click on it does) and centres the view there.
    let url = format!("file://{}#problem=2", file.display());
    let dom = dom_at(&browser, &url, "#problem=2");
    assert!(
        dom.contains("class=\"sel\" data-mark=\"2\"")
            || dom.contains("data-mark=\"2\" class=\"sel\""),
        "the third problem is not selected"
    );

    // Red where the marks are, and nowhere without them.
    let full = Shot::of(&browser, &page, &dir, "refused");
    let without = Shot::of(
        &browser,
        &refused_page(&path, vec![], true),
        &dir,
        "unmarked",
    );
    assert_eq!(without.red(), 0, "red drawn with no marks");
    // The simulation's orange is nowhere else, not even in the boss's palette orange.
    assert_eq!(full.orange(), 0, "orange drawn with no simulation");
    assert!(
        full.red() >= marks.len() * MIN_MARK_PIXELS,
        "{} red pixels",
        full.red()
    );
    for m in &marks {
        let one = Shot::of(
            &browser,
            &refused_page(&path, vec![m.clone()], true),
            &dir,
            "one",
        );
        assert!(
            one.red() >= MIN_MARK_PIXELS && one.red() < full.red(),
            "{}: {} red pixels of {}",
            m.kind.name(),
            one.red(),
            full.red()
        );
    }
    // The bed and the head are drawn: more of the view is off the background with them.
    let bare = Shot::of(&browser, &refused_page(&path, vec![], false), &dir, "bare");
    assert!(
        without.drawn() > bare.drawn() + bare.drawn() / 10,
        "{} pixels drawn with the machine, {} without",
        without.drawn(),
        bare.drawn()
    );
    keep_pages(&dir, |f| ["refused.html", "refused.png"].contains(&f));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A path point of the simulation's paths: a print move of feature 0 (a travel first).
fn sim_point(i: usize, layer: usize, p: [f64; 3], axis: [f64; 3]) -> PathPoint {
    PathPoint {
        feature: 0,
        layer: layer as u32,
        kind: if i == 0 {
            MoveKind::Travel
        } else {
            MoveKind::Print
        },
        p,
        axis,
        e: 0.0,
        thickness: 0.4,
        width: 0.45,
        role: Role::Perimeter,
    }
}

/// The head of a bundled profile.
fn sim_head(m: &MachineProfile) -> HeadSize {
    HeadSize {
        tip_radius: m.head.nozzle_tip_radius,
        half_angle_deg: m.head.nozzle_cone_half_angle_deg,
        cone_length: m.head.nozzle_length,
        body_radius: m.head.body_radius,
        body_length: m.head.body_length,
    }
}

/// Moves of the arm simulation.
const ARM_MOVES: usize = 121;

/// The bundled KUKA cell's arm, its `$BASE` turned by 20° and the part offset, sweeping A1
/// from -35° to 35° while the other joints move too (A5 from 70° to 2°: the wrist ends near its
/// singularity); the tool path is where the post's forward kinematics
/// (`robot_post::kuka::ArmModel::forward`) puts the tool tip, in the part's frame, and move 30
/// is said to collide.
fn arm_simulation() -> (ToolPath, Simulation) {
    let m = MachineProfile::builtin(MachineKind::Kuka);
    let cell = m
        .kuka
        .clone()
        .expect("the bundled KUKA profile has its cell");
    let mut base = cell.base.to_array();
    base[3] = 20.0;
    let offset = [3.0, -2.0, 1.5];
    let part_in_robot = Pose::from_frame(base).compose(&Pose {
        r: Pose::IDENTITY.r,
        t: offset,
    });
    let robot_to_part = part_in_robot.inverse();
    let tool = Pose::from_frame(cell.tool.to_array());
    let mut points = vec![];
    let mut moves = vec![];
    for i in 0..ARM_MOVES {
        let t = i as f64 / (ARM_MOVES - 1) as f64;
        let joints = [
            -35.0 + 70.0 * t,
            -95.0 + 15.0 * t,
            100.0 - 20.0 * t,
            20.0 - 40.0 * t,
            70.0 - 68.0 * t,
            10.0 * t,
        ];
        let at = robot_to_part.compose(&cell.arm.forward(joints).compose(&tool));
        let z = at.z_axis();
        points.push(sim_point(i, i / 20, at.t, [-z[0], -z[1], -z[2]]));
        moves.push(SimMove {
            point: i,
            joints: joints.to_vec(),
            flags: SimFlags {
                collision: i == 30,
                ..SimFlags::default()
            },
        });
    }
    let a = &cell.arm;
    let arm = SimArm {
        a1: a.a1,
        a2: a.a2,
        b: a.b,
        c1: a.c1,
        c2: a.c2,
        c3: a.c3,
        c4: a.c4,
        joint_offsets: a.joint_offsets,
        joint_signs: a.joint_signs,
        joint_min: a.joint_min,
        joint_max: a.joint_max,
        base,
        part_offset: offset,
        tool: cell.tool.to_array(),
    };
    let margins = SimMargins {
        singularity_deg: cell.wrist_singularity_deg,
        ..SimMargins::default()
    };
    let sim = Simulation::new(SimMachine::Arm(arm), sim_head(&m), moves, margins);
    (ToolPath { points }, sim)
}

/// Rings of a dome on the bundled delta5 table (radius 20 mm, 0.4 mm apart), their tool axes
/// tilting out by 3° a ring up to 45°, with B and C by `Simulation::table_from_axes`, checked
/// against the post's own `robot_post::delta5::inverse`; B is said to stop at 48° (the
/// profile's 90° would flag nothing), so the last ring is near its limit.
fn table_simulation() -> (ToolPath, Simulation) {
    let m = MachineProfile::builtin(MachineKind::Delta5);
    let g = m
        .delta5
        .clone()
        .expect("the bundled delta5 profile has its table");
    let mut points = vec![];
    for ring in 0..16 {
        let (s, c) = (3.0 * ring as f64).to_radians().sin_cos();
        for k in 0..=36 {
            let t = std::f64::consts::TAU * k as f64 / 36.0;
            let p = [20.0 * t.cos(), 20.0 * t.sin(), 0.4 * (ring + 1) as f64];
            points.push(sim_point(
                points.len(),
                ring,
                p,
                [s * t.cos(), s * t.sin(), c],
            ));
        }
    }
    let table = SimTable {
        centre: [0.0, 0.0],
        z: 0.0,
        radius: g.table_radius,
        table_above_b_axis: g.table_above_b_axis,
        b_limits_deg: [g.b_limits_deg[0], 48.0],
        c_limits_deg: (!g.c_continuous).then_some(g.c_limits_deg),
    };
    let sim = Simulation::table_from_axes(&points, table, sim_head(&m), SimMargins::default());
    assert_eq!(sim.moves.len(), points.len());
    let mut previous = None;
    for mv in &sim.moves {
        let (b, c) = robot_post::delta5::inverse(points[mv.point].axis, previous, &g)
            .expect("within the B limits");
        assert!(
            (b - mv.joints[0]).abs() < 1e-9 && (c - mv.joints[1]).abs() < 1e-9,
            "move {}: the post says B {b} C {c}, the preview {:?}",
            mv.point,
            mv.joints
        );
        previous = Some(c);
    }
    (ToolPath { points }, sim)
}

/// Three numbers written `x,y,z`.
fn triple(s: &str) -> [f64; 3] {
    let v: Vec<f64> = s.split(',').filter_map(|x| x.parse().ok()).collect();
    assert_eq!(v.len(), 3, "`{s}`");
    [v[0], v[1], v[2]]
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
}

/// Orange pixels the arm or the table covers at least in a screenshot.
const MIN_MACHINE_PIXELS: usize = 2_000;

/// Pixels of the machine's orange that must differ between two moves for the machine to have
/// moved (a link shifted by a few pixels along its length).
const MIN_MOVED_PIXELS: usize = 200;

#[test]
fn the_simulation_view_draws_the_machine_at_the_scrubbers_move() {
    let Some(browser) = chromium() else { return };
    let dir = std::env::temp_dir().join(format!("features-simulation-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (name, (path, sim)) in [("arm", arm_simulation()), ("table", table_simulation())] {
        let flagged = sim.moves.iter().filter(|m| m.flags.any()).count();
        let page = preview::html(&Preview {
            title: format!("simulated {name}"),
            path: Some(&path),
            figures: vec![("moves".into(), sim.moves.len().to_string())],
            simulation: Some(sim.clone()),
            ..Preview::default()
        });
        for bad in ["http:", "https:", "//"] {
            assert!(!page.contains(bad), "the page refers to `{bad}`");
        }
        let file = dir.join(format!("simulation_{name}.html"));
        std::fs::write(&file, &page).unwrap();
        let mut orange = vec![];
        for (at, f) in [("middle", "0.5"), ("end", "1")] {
            let url = format!("file://{}#sim={f}", file.display());
            let dom = dom_at(&browser, &url, name);
            // The scrubber's move: the fraction of the moves (all embedded, so the move itself).
            let shown: usize = body_attribute(&dom, "data-sim-move")
                .and_then(|s| s.parse().ok())
                .expect("the page names the move shown");
            let want = (f.parse::<f64>().unwrap() * (sim.moves.len() - 1) as f64).round();
            assert_eq!(shown, want as usize, "{name} at the {at}");
            // The head's tip and axis as the viewer's kinematics put them (an arm's by the OPW
            // chain, a table's by B and C): on the path's point, along its axis.
            let q = &path.points[sim.moves[shown].point];
            let tip = triple(&body_attribute(&dom, "data-sim-tip").expect("a tip"));
            let axis = triple(&body_attribute(&dom, "data-sim-axis").expect("an axis"));
            assert!(
                distance(tip, q.p) < 0.01,
                "{name}: tip {tip:?}, path {:?}",
                q.p
            );
            assert!(
                distance(axis, q.axis) < 1e-3,
                "{name}: axis {axis:?}, path {:?}",
                q.axis
            );
            // So the panel says nothing of a tool tip off its point.
            let text = dom
                .split("id=\"simtext\">")
                .nth(1)
                .and_then(|t| t.split('<').next())
                .expect("the panel's line");
            assert!(text.starts_with("move "), "{name}: `{text}`");
            assert!(!text.contains("tool tip"), "{name}: `{text}`");
            // Every flagged move is listed.
            assert_eq!(
                body_attribute(&dom, "data-sim-flagged"),
                (flagged > 0).then(|| flagged.to_string()),
                "{name}"
            );
            let png = dir.join(format!("simulation_{name}_{at}.png"));
            orange.push(Shot::at(&browser, &url, &png).orange());
        }
        // The Machine list: move 30 collides and the last few bend the wrist under 5° (the
        // arm), the last ring's 37 moves need B within 5° of its limit (the table).
        let dom = headless(&browser, &file, &["--dump-dom"]);
        let dom = String::from_utf8_lossy(&dom.stdout);
        let list = dom
            .split("id=\"simflaggedlist\"")
            .nth(1)
            .and_then(|s| s.split("id=\"simflaggedleft\"").next())
            .expect("a Machine list");
        if name == "arm" {
            assert!(list.contains("move 30</span>the head collides"), "{list}");
            let singular = list.matches("wrist near its singularity").count();
            assert_eq!(singular, flagged - 1, "{list}");
        } else {
            assert_eq!(flagged, 37);
            assert_eq!(list.matches("B 45.0° within 5° of its limits").count(), 37);
        }
        // The machine is drawn at both moves, and differently: it moved.
        assert!(
            orange.iter().all(|&n| n >= MIN_MACHINE_PIXELS),
            "{name}: {orange:?} orange pixels"
        );
        let (a, b) = (orange[0] as f64, orange[1] as f64);
        assert!(
            (a - b).abs() > 0.05 * a.max(b),
            "{name}: {orange:?} orange pixels at the middle and the end"
        );
        eprintln!("{name}: {orange:?} orange pixels at the middle and the end");
    }
    keep_pages(&dir, |_| true);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The impeller's previews on `kuka` and `delta5` (issue 36 item 2) simulate the program the
/// plan wrote: at the scrubber's middle and end the page draws without a script error, shows
/// the move asked for, and draws the machine (the arm from the post's `joints.csv`, the table
/// by B and C) in its orange, differently at the two moves. `FEATURES_KEEP_PREVIEW=DIR` keeps
/// the screenshots (docs/simulation_*.png are such).
#[test]
fn the_impellers_previews_simulate_the_arm_and_the_table() {
    let Some(browser) = chromium() else { return };
    let dir = std::env::temp_dir().join(format!("features-impeller-sim-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for machine in ["kuka", "delta5"] {
        let out = dir.join(machine);
        let o = Command::new(BIN)
            .arg("plan")
            .arg(fixture("impeller.step"))
            .args(["--machine", machine, "--placement-time-limit", "inf", "-o"])
            .arg(&out)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{machine}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let moves = std::fs::read_to_string(out.join("joints.csv"))
            .unwrap()
            .lines()
            .skip(1)
            .count();
        assert!(moves > 1000, "{machine}: {moves} moves");
        let page = out.join("preview.html");
        let mut orange = vec![];
        for (at, f) in [("middle", "0.5"), ("end", "1")] {
            let url = format!("file://{}#sim={f}", page.display());
            let dom = dom_at(&browser, &url, machine);
            let shown: usize = body_attribute(&dom, "data-sim-move")
                .and_then(|s| s.parse().ok())
                .expect("the page names the move shown");
            if at == "end" {
                assert!(shown > 1000, "{machine}: move {shown} at the end");
            }
            let png = dir.join(format!("simulation_impeller_{machine}_{at}.png"));
            orange.push(Shot::at(&browser, &url, &png).orange_mask());
        }
        let counts: Vec<usize> = orange
            .iter()
            .map(|m| m.iter().filter(|&&o| o).count())
            .collect();
        assert!(
            counts.iter().all(|&n| n >= MIN_MACHINE_PIXELS),
            "{machine}: {counts:?} orange pixels"
        );
        // The machine moved: pixels orange at one move and not at the other (a robot arm two
        // metres long moves a few pixels between two points of a part 100 mm across).
        let moved = orange[0]
            .iter()
            .zip(&orange[1])
            .filter(|(a, b)| a != b)
            .count();
        assert!(
            moved >= MIN_MOVED_PIXELS,
            "{machine}: {counts:?} orange pixels at the middle and the end, {moved} changed"
        );
        eprintln!(
            "impeller {machine}: {counts:?} orange pixels at the middle and the end, {moved} changed"
        );
    }
    keep_pages(&dir, |f| f.ends_with(".png"));
    let _ = std::fs::remove_dir_all(&dir);
}
