//! Entity names of the STEP schemas the reader claims (AP203 ed1 and ed2, AP214 ed1 to ed3,
//! AP242 ed1 to ed4): every ENTITY of their long-form EXPRESS schemas, listed in
//! `entity_names.txt` beside this file with the sources it was extracted from
//! (`scripts/schema_names.sh` extracts a schema's names and checks the list against them). A
//! name outside the list in a file is warned about, naming its `#id`, so a misspelt entity is
//! not skipped in silence.

use std::sync::OnceLock;

/// Known entity names, sorted (`entity_names.txt`, its `#` lines left out).
pub(crate) fn known() -> &'static [&'static str] {
    static KNOWN: OnceLock<Vec<&'static str>> = OnceLock::new();
    KNOWN.get_or_init(|| {
        include_str!("entity_names.txt")
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty() && !l.starts_with('#'))
            .collect()
    })
}

/// Whether `name` is an entity name the reader knows.
pub(crate) fn is_known(name: &str) -> bool {
    let up = name.to_ascii_uppercase();
    known().binary_search(&up.as_str()).is_ok()
}

/// The known name nearest to `name`, when it is within two edits (a misspelling).
pub(crate) fn nearest(name: &str) -> Option<&'static str> {
    let up = name.to_ascii_uppercase();
    known()
        .iter()
        .map(|k| (edits(&up, k), *k))
        .filter(|(d, _)| *d <= 2)
        .min_by_key(|(d, _)| *d)
        .map(|(_, k)| k)
}

/// Levenshtein distance.
fn edits(a: &str, b: &str) -> usize {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_list_is_sorted_and_a_misspelling_finds_its_entity() {
        let known = super::known();
        assert!(known.windows(2).all(|w| w[0] < w[1]));
        // Every protocol's: AP203 ed1, AP214, AP242 ed4.
        for name in [
            "CC_DESIGN_APPROVAL",
            "CONSTRUCTIVE_GEOMETRY_REPRESENTATION_RELATIONSHIP",
            "TESSELLATED_SOLID",
            "ADVANCED_BREP_SHAPE_REPRESENTATION",
        ] {
            assert!(super::is_known(name), "{name}");
        }
        assert!(known.len() > 2400, "{}", known.len());
        assert!(super::is_known("cartesian_point"));
        assert!(!super::is_known("CARTESIAN_POINTX"));
        assert_eq!(super::nearest("CARTESIAN_POINTX"), Some("CARTESIAN_POINT"));
    }
}
