//! Fuzz target: STEP Part 21 reader, B-rep translation, analysis and display meshing.
//!
//! Errors are expected for malformed input; any panic (or abort, hang, OOM) is a bug.
#![no_main]

use libfuzzer_sys::fuzz_target;

/// Larger inputs are skipped so that each iteration stays fast.
const MAX_LEN: usize = 256 * 1024;

fuzz_target!(|data: &[u8]| {
    if data.len() > MAX_LEN {
        return;
    }
    let Ok(part) = brep::read_step_bytes(data) else {
        return;
    };
    let b = &part.brep;
    for s in b.solid_ids() {
        let _ = brep::solid::report_solid(b, s);
        if let Ok(mesh) =
            brep::solid::mesh_solid(b, s, Some(brep::mesh::MeshOptions::with_tolerance(0.5)))
        {
            let _ = mesh.triangles();
        }
    }
});
