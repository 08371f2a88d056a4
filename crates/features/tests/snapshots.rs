//! The feature trees of the fixtures, pinned. Each snapshot was read against the part it comes
//! from (fixtures/README.md describes them) before it was accepted.

use brep::topology::SolidId;
use features::{extract, ExtractOptions};
use std::fmt::Write as _;
use std::path::PathBuf;

fn tree_text(name: &str) -> String {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
    let part = brep::read_step(dir.join(format!("{name}.step"))).expect("reads");
    let t = extract(&part.brep, SolidId(0), &ExtractOptions::default()).expect("extracts");
    let mut s = String::new();
    let _ = writeln!(
        s,
        "part volume {:.1} mm^3, genus {:?}, depth {}",
        t.part_volume, t.genus, t.depth
    );
    for f in &t.features {
        let n = f
            .reference
            .normal
            .map(|n| {
                format!(
                    " normal ({:.3}, {:.3}, {:.3})",
                    n[0] + 0.0,
                    n[1] + 0.0,
                    n[2] + 0.0
                )
            })
            .unwrap_or_default();
        let _ = writeln!(
            s,
            "feature {}: {} {} on {}{} parents {:?} depth {} root_loops {} volume {:.1}",
            f.id,
            f.kind.as_str(),
            f.subtype,
            f.reference.surface,
            n,
            f.parents,
            f.depth,
            f.root_loops,
            f.volume
        );
    }
    let _ = writeln!(s, "build order {:?}", t.build_order);
    for w in &t.warnings {
        let _ = writeln!(s, "warning: {w}");
    }
    s
}

macro_rules! snap {
    ($($name:ident),*) => {$(
        #[test]
        fn $name() {
            insta::assert_snapshot!(stringify!($name), tree_text(stringify!($name)));
        }
    )*};
}

snap!(
    impeller,
    capsule,
    fan,
    plate_boss_boss,
    sphere_boss,
    arch,
    inch_block,
    boss_fillet,
    void_box
);

#[test]
fn box_fixture() {
    insta::assert_snapshot!("box", tree_text("box"));
}
