//! The layout rules of the workspace (issue 15), checked on the sources: no file of library code
//! over 1,000 lines, no two modules of one crate importing each other, the posts not depending
//! on the slicer, and Eq. 1 written once; functions a reader can hold (issue 32): no library
//! function over 150 lines, and no bare float literal below 1e-6 outside a crate's tolerance
//! module.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

const LIBRARIES: [&str; 8] = [
    "brep",
    "meshfile",
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

/// Crates whose library code is checked by the function-length and tolerance rules: the
/// libraries, the viewer and the command (its binary is library code for this purpose).
const CODE_CRATES: [&str; 10] = [
    "brep",
    "meshfile",
    "features",
    "toolpath",
    "collide",
    "slicer",
    "robot-post",
    "plan",
    "preview",
    "cli",
];

/// Functions the rules leave alone, by crate, file (under `src/`) and name: none (issue 32's
/// `plan_into` and `cli::plan::run` are stages now).
const EXEMPT_FUNCTIONS: [(&str, &str, &str); 0] = [];

/// Files the tolerance rule leaves alone, by crate and file (under `src/`): none.
const EXEMPT_FILES: [(&str, &str); 0] = [];

/// A library source file: its crate, its path under `src/` and its lines (1-based numbers)
/// with test code left out: files named `tests.rs` or under a `tests/` folder, and every item
/// marked `#[cfg(test)]` (a `mod tests { … }` block, a helper).
struct Source {
    krate: &'static str,
    rel: String,
    lines: Vec<(usize, String)>,
}

fn library_sources() -> Vec<Source> {
    let mut out = vec![];
    for krate in CODE_CRATES {
        let src = root().join("crates").join(krate).join("src");
        let mut files = vec![];
        rust_files(&src, &mut files);
        files.sort();
        assert!(!files.is_empty(), "{krate} has no sources");
        for f in files {
            let rel = f
                .strip_prefix(&src)
                .expect("under src")
                .to_string_lossy()
                .replace('\\', "/");
            if rel == "tests.rs"
                || rel.ends_with("/tests.rs")
                || rel.split('/').any(|c| c == "tests")
            {
                continue;
            }
            let text = std::fs::read_to_string(&f).expect("reads");
            let all: Vec<&str> = text.lines().collect();
            let mut lines = vec![];
            let mut i = 0;
            while i < all.len() {
                if all[i].trim() == "#[cfg(test)]" && i + 1 < all.len() {
                    // Skip the item: a declaration ending in `;` or a block closed at its indent.
                    let item = all[i + 1];
                    let indent = item.len() - item.trim_start().len();
                    let mut k = i + 1;
                    if !item.trim_end().ends_with(';') {
                        while k < all.len() && !is_close(all[k], indent) {
                            k += 1;
                        }
                    }
                    i = k + 1;
                    continue;
                }
                lines.push((i + 1, all[i].to_string()));
                i += 1;
            }
            out.push(Source { krate, rel, lines });
        }
    }
    out
}

/// Whether `line` is a closing brace at `indent`.
fn is_close(line: &str, indent: usize) -> bool {
    let t = line.trim_end();
    t.len() == indent + 1 && t.ends_with('}') && t[..indent].trim().is_empty()
}

/// The name of the function a line declares (`pub(crate) const fn name(`), if it does.
fn declared_fn(line: &str) -> Option<&str> {
    let mut rest = line.trim_start();
    loop {
        if let Some(r) = rest.strip_prefix("pub(") {
            rest = r.split_once(')')?.1.trim_start();
        } else if let Some(r) = ["pub ", "const ", "async ", "unsafe ", "extern \"C\" "]
            .iter()
            .find_map(|k| rest.strip_prefix(k))
        {
            rest = r.trim_start();
        } else {
            break;
        }
    }
    let rest = rest.strip_prefix("fn ")?;
    let name: &str = &rest[..rest
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(rest.len())];
    (!name.is_empty()).then_some(name)
}

/// Every function of the library code: crate, file, name, first line and length in lines
/// (from the `fn` line to its closing brace).
fn functions() -> Vec<(&'static str, String, String, usize, usize)> {
    let mut out = vec![];
    for s in library_sources() {
        let lines = &s.lines;
        for (i, (n, line)) in lines.iter().enumerate() {
            let Some(name) = declared_fn(line) else {
                continue;
            };
            let indent = line.len() - line.trim_start().len();
            // The signature ends at the line ending in `{` (a body) or `;` (a declaration).
            // (`}`: a body on one line).
            let Some(open) = (i..lines.len()).find(|&j| {
                let t = lines[j].1.trim_end();
                t.ends_with('{') || t.ends_with(';') || t.ends_with('}')
            }) else {
                continue;
            };
            if !lines[open].1.trim_end().ends_with('{') {
                continue;
            }
            let close = (open + 1..lines.len())
                .find(|&k| is_close(&lines[k].1, indent))
                .unwrap_or(lines.len() - 1);
            out.push((
                s.krate,
                s.rel.clone(),
                name.to_string(),
                *n,
                lines[close].0 - n + 1,
            ));
        }
    }
    out
}

#[test]
fn no_library_function_is_over_150_lines() {
    let functions = functions();
    assert!(
        functions.len() > 500,
        "the scan finds functions ({})",
        functions.len()
    );
    let long: Vec<String> = functions
        .iter()
        .filter(|(k, rel, name, _, _)| {
            !EXEMPT_FUNCTIONS.contains(&(*k, rel.as_str(), name.as_str()))
        })
        .filter(|f| f.4 > 150)
        .map(|(k, rel, name, n, len)| format!("{k}/src/{rel}:{n} {name} ({len} lines)"))
        .collect();
    assert!(long.is_empty(), "split along the steps: {long:?}");
}

/// The code of a line: string and character literals blanked, the comment cut off. `in_string`
/// carries a string literal over line ends.
fn code_of(line: &str, in_string: &mut bool) -> String {
    let chars: Vec<char> = line.chars().collect();
    let mut out = String::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if *in_string {
            match c {
                '\\' => i += 1,
                '"' => *in_string = false,
                _ => {}
            }
            out.push(' ');
        } else if c == '\'' && chars.get(i + 1) == Some(&'\\') {
            // An escaped character literal `'\\n'`, `'\\''`.
            i += 3;
            out.push(' ');
        } else if c == '\'' && chars.get(i + 2) == Some(&'\'') {
            // A character literal `'x'`.
            i += 2;
            out.push(' ');
        } else if c == '/' && chars.get(i + 1) == Some(&'/') {
            break;
        } else if c == '"' {
            *in_string = true;
            out.push(' ');
        } else {
            out.push(c);
        }
        i += 1;
    }
    out
}

/// The float literals of a line of code (blanked of strings and comments) whose value is
/// positive and below 1e-6: `1e-9`, `1.0e-12`, `5E-7_f64`, `0.0000001`.
fn small_literals(code: &str) -> Vec<String> {
    let b = code.as_bytes();
    let mut out = vec![];
    let mut i = 0;
    while i < b.len() {
        let starts = b[i].is_ascii_digit()
            && (i == 0
                || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_' || b[i - 1] == b'.'));
        if !starts {
            i += 1;
            continue;
        }
        let mut j = i;
        while j < b.len() && (b[j].is_ascii_digit() || b[j] == b'_') {
            j += 1;
        }
        if j + 1 < b.len() && b[j] == b'.' && b[j + 1].is_ascii_digit() {
            j += 1;
            while j < b.len() && (b[j].is_ascii_digit() || b[j] == b'_') {
                j += 1;
            }
        }
        if j + 1 < b.len()
            && (b[j] == b'e' || b[j] == b'E')
            && (b[j + 1] == b'-' || b[j + 1].is_ascii_digit())
        {
            j += 1;
            if b[j] == b'-' {
                j += 1;
            }
            while j < b.len() && (b[j].is_ascii_digit() || b[j] == b'_') {
                j += 1;
            }
        }
        // A type suffix's `_` (`5E-7_f64`) is not part of the number.
        let text = code[i..j].trim_end_matches('_');
        if let Ok(v) = text.replace('_', "").parse::<f64>() {
            if v > 0.0 && v < 1e-6 {
                out.push(text.to_string());
            }
        }
        i = j.max(i + 1);
    }
    out
}

#[test]
fn the_scan_finds_small_literals() {
    let mut s = false;
    assert_eq!(
        small_literals(&code_of("x < 1e-9 && y > 1.0e-12", &mut s)),
        ["1e-9", "1.0e-12"]
    );
    assert_eq!(
        small_literals(&code_of("a * 5E-7_f64 + 0.0000001", &mut s)),
        ["5E-7", "0.0000001"]
    );
    assert!(small_literals(&code_of("x < 1e-6 || y > 2.5e-3 || v1e-9", &mut s)).is_empty());
    assert!(small_literals(&code_of("// 1e-9 in a comment", &mut s)).is_empty());
    assert!(small_literals(&code_of("f(\"1.E-07\", '\"') // 1e-9", &mut s)).is_empty());
    assert!(!s, "the string closed");
}

#[test]
fn every_crate_names_its_small_tolerances() {
    // The crates that compare floats hold their tolerances in one module, `tolerance.rs`.
    let sources = library_sources();
    let tolerance_module = |krate: &str| {
        sources.iter().any(|s| {
            s.krate == krate && (s.rel == "tolerance.rs" || s.rel.ends_with("/tolerance.rs"))
        })
    };
    for krate in LIBRARIES {
        assert!(tolerance_module(krate), "{krate} has no tolerance module");
    }
    let functions = functions();
    let exempt = |krate: &str, rel: &str, n: usize| {
        EXEMPT_FILES.contains(&(krate, rel))
            || functions.iter().any(|(k, r, name, first, len)| {
                *k == krate
                    && r == rel
                    && EXEMPT_FUNCTIONS.contains(&(krate, rel, name.as_str()))
                    && (*first..first + len).contains(&n)
            })
    };
    let mut bare = vec![];
    let mut count = 0;
    for s in &sources {
        let in_module = s.rel == "tolerance.rs" || s.rel.ends_with("/tolerance.rs");
        let mut in_string = false;
        for (n, line) in &s.lines {
            let found = small_literals(&code_of(line, &mut in_string));
            count += found.len();
            if in_module || found.is_empty() || exempt(s.krate, &s.rel, *n) {
                continue;
            }
            bare.push(format!("{}/src/{}:{n} {}", s.krate, s.rel, found.join(" ")));
        }
    }
    assert!(count > 10, "the scan finds the named tolerances ({count})");
    assert!(
        bare.is_empty(),
        "name these in the crate's tolerance module ({}): {bare:?}",
        bare.len()
    );
}
