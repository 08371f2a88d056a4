//! The preview page opens in a real browser (headless Chromium) and draws (issue 19): the page
//! a plan writes and the one `features preview` writes. `.ci/run` installs Debian's chromium
//! when it is missing and sets `FEATURES_REQUIRE_BROWSER=1`, so there the browser must be
//! found; elsewhere a machine without Chromium skips these tests and says so.

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
        .arg(format!("file://{}", page.display()))
        .output()
        .expect("chromium runs")
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
