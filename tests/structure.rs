//! The layout rules of the workspace (issue 15), checked on the sources: no file of library code
//! over 1,000 lines, no two modules of one crate importing each other, the posts not depending
//! on the slicer, and Eq. 1 written once.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

const LIBRARIES: [&str; 7] = [
    "brep",
    "features",
    "toolpath",
    "collide",
    "slicer",
    "robot-post",
    "plan",
];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The module path of a source file: `src/a/b.rs` and `src/a/b/mod.rs` are `a::b`.
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).expect("under src");
    let mut parts: Vec<String> = rel
        .iter()
        .map(|c| c.to_string_lossy().trim_end_matches(".rs").to_string())
        .collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
        parts.pop();
    }
    parts
}

/// Module paths named in code (not comments) as `crate::…` or `super::…`.
fn references(text: &str, module: &[String]) -> Vec<Vec<String>> {
    // `super` of module `a::b` (file `a/b.rs` or `a/b/mod.rs`) is `a`.
    let parent = module[..module.len().saturating_sub(1)].to_vec();
    let mut out = vec![];
    for line in text.lines() {
        let code = line.trim_start();
        if code.starts_with("//") {
            continue;
        }
        let code = code.split("//").next().unwrap_or("");
        for (prefix, base) in [("crate::", &vec![]), ("super::", &parent)] {
            let mut rest = code;
            while let Some(i) = rest.find(prefix) {
                let before = rest[..i].chars().last();
                rest = &rest[i + prefix.len()..];
                if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
                    continue;
                }
                let mut path = base.to_vec();
                for seg in rest.split("::") {
                    let name: String = seg
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                        .collect();
                    if name.is_empty() || name.starts_with(|c: char| c.is_uppercase()) {
                        break;
                    }
                    path.push(name);
                    if !seg.chars().all(|c| c.is_alphanumeric() || c == '_') {
                        break;
                    }
                }
                out.push(path);
            }
        }
    }
    out
}

#[test]
fn no_library_file_is_over_a_thousand_lines() {
    let mut long = vec![];
    for krate in LIBRARIES {
        let mut files = vec![];
        rust_files(&root().join("crates").join(krate).join("src"), &mut files);
        assert!(!files.is_empty(), "{krate} has no sources");
        for f in files {
            let n = std::fs::read_to_string(&f).expect("reads").lines().count();
            if n > 1000 {
                long.push(format!("{} ({n} lines)", f.display()));
            }
        }
    }
    assert!(long.is_empty(), "split by concern: {long:?}");
}

#[test]
fn no_two_modules_of_a_crate_import_each_other() {
    let mut cycles = vec![];
    for krate in LIBRARIES {
        let src = root().join("crates").join(krate).join("src");
        let mut files = vec![];
        rust_files(&src, &mut files);
        let modules: BTreeSet<Vec<String>> = files.iter().map(|f| module_of(&src, f)).collect();
        let mut uses: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
        for f in &files {
            let m = module_of(&src, f);
            let text = std::fs::read_to_string(f).expect("reads");
            for r in references(&text, &m) {
                // The longest prefix of the path that is a file of the crate.
                let Some(target) = (1..=r.len())
                    .rev()
                    .map(|k| r[..k].to_vec())
                    .find(|p| modules.contains(p))
                else {
                    continue;
                };
                if target != m {
                    uses.entry(m.clone()).or_default().insert(target);
                }
            }
        }
        for (a, targets) in &uses {
            for b in targets {
                if a < b && uses.get(b).is_some_and(|t| t.contains(a)) {
                    cycles.push(format!("{krate}: {} <-> {}", a.join("::"), b.join("::")));
                }
            }
        }
    }
    assert!(
        cycles.is_empty(),
        "modules importing each other: {cycles:?}"
    );
}

#[test]
fn the_posts_do_not_depend_on_the_slicer() {
    let toml = std::fs::read_to_string(root().join("crates/robot-post/Cargo.toml")).expect("reads");
    assert!(
        !toml.contains("slicer"),
        "robot-post's Cargo.toml names the slicer"
    );
    // The collision check, which the posts' profiles name, reads the tool path only.
    for krate in ["toolpath", "collide"] {
        let toml = std::fs::read_to_string(root().join(format!("crates/{krate}/Cargo.toml")))
            .expect("reads");
        for upstream in ["brep", "features", "slicer"] {
            assert!(
                !toml.contains(&format!("{upstream} =")),
                "{krate} depends on {upstream}"
            );
        }
    }
}

#[test]
fn eq_1_is_written_once() {
    // `4·w·Δl·L / (π·D²)`, the filament length of a bead: a product by 4 divided by π in one
    // expression of code (comments left out).
    let mut found = vec![];
    for krate in LIBRARIES.iter().chain(&["cli"]) {
        let mut files = vec![];
        rust_files(&root().join("crates").join(krate).join("src"), &mut files);
        for f in files {
            let text = std::fs::read_to_string(&f).expect("reads");
            let code: String = text
                .lines()
                .filter(|l| !l.trim_start().starts_with("//"))
                .flat_map(|l| l.split_whitespace().chain([" "]))
                .collect::<Vec<_>>()
                .join(" ");
            let mut rest = code.as_str();
            while let Some(i) = rest.find("4.0 *") {
                let expr = rest[i..].split(';').next().unwrap_or("");
                // A product divided by π (not a product with π, as a solid angle's 4π).
                if expr
                    .find('/')
                    .zip(expr.find("PI"))
                    .is_some_and(|(d, pi)| d < pi)
                {
                    found.push(f.display().to_string());
                }
                rest = &rest[i + 1..];
            }
        }
    }
    assert_eq!(found.len(), 1, "Eq. 1 at {found:?}");
}

/// Most lines the README may have: a map of the project, the reference lives in `docs/`.
const README_MAX_LINES: usize = 150;

#[test]
fn the_readme_is_a_map_of_at_most_150_lines() {
    let readme = std::fs::read_to_string(root().join("README.md")).expect("README.md");
    let lines = readme.lines().count();
    assert!(
        lines <= README_MAX_LINES,
        "README.md has {lines} lines, at most {README_MAX_LINES}: move reference text to docs/"
    );
    for page in ["plan.md", "profiles.md", "design.md", "measurements.md"] {
        assert!(
            readme.contains(&format!("](docs/{page})")),
            "README.md links docs/{page}"
        );
    }
}

/// GitHub's anchor of a heading: lower case, letters, digits, `-` and `_` kept, spaces made
/// `-`, everything else dropped.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// The anchors of a Markdown file's headings (outside fenced code).
fn anchors(text: &str) -> BTreeSet<String> {
    let mut fenced = false;
    let mut out = BTreeSet::new();
    for line in text.lines() {
        if line.starts_with("```") {
            fenced = !fenced;
        } else if !fenced && line.starts_with('#') {
            out.insert(anchor(line.trim_start_matches('#')));
        }
    }
    out
}

/// The targets of a Markdown file's inline links `](target)`.
fn link_targets(text: &str) -> Vec<String> {
    text.split("](")
        .skip(1)
        .filter_map(|rest| rest.split_once(')').map(|(t, _)| t.to_string()))
        .collect()
}

#[test]
fn every_link_of_the_readme_and_docs_reaches_a_file_and_heading() {
    let mut pages = vec![root().join("README.md")];
    let docs = root().join("docs");
    for e in std::fs::read_dir(&docs).expect("docs/").flatten() {
        if e.path().extension().is_some_and(|x| x == "md") {
            pages.push(e.path());
        }
    }
    let mut broken = vec![];
    for page in &pages {
        let text = std::fs::read_to_string(page).expect("a page");
        for target in link_targets(&text) {
            if target.starts_with("http://") || target.starts_with("https://") {
                continue;
            }
            let (file, heading) = match target.split_once('#') {
                Some((f, h)) => (f, Some(h)),
                None => (target.as_str(), None),
            };
            let path = if file.is_empty() {
                page.clone()
            } else {
                page.parent().expect("a folder").join(file)
            };
            if !path.exists() {
                broken.push(format!("{}: {target} (no such file)", page.display()));
                continue;
            }
            if let Some(h) = heading {
                let linked = std::fs::read_to_string(&path).unwrap_or_default();
                if !anchors(&linked).contains(h) {
                    broken.push(format!("{}: {target} (no such heading)", page.display()));
                }
            }
        }
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}
