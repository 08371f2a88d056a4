//! The file around the entities: header, product structure, representation context and the
//! bodies, in one exchange file.

use super::text::{ref_list, string, wrap};
use super::writer::{Body, Writer};
use crate::math::{Frame, P3};
use crate::topology::{Brep, FaceId, SolidId};

/// Writes the given solids (each a set of shells: outer first, then voids) as one STEP file.
pub fn write_step(brep: &Brep, solids: &[SolidId], name: &str) -> String {
    let bodies: Vec<Body> = solids
        .iter()
        .filter_map(|s| {
            let solid = &brep.solids[s.idx()];
            let (outer, voids) = solid.shells.split_first()?;
            Some(Body {
                name: solid.name.clone(),
                outer: brep.shells[outer.idx()].faces.clone(),
                voids: voids
                    .iter()
                    .map(|v| brep.shells[v.idx()].faces.clone())
                    .collect(),
            })
        })
        .collect();
    write_bodies(brep, &bodies, name)
}

/// For solids that exist only as face lists (a feature being extracted): each entry is (outer
/// shell faces, void shells' faces). Void faces are taken in the convention of the reader (see
/// the module documentation): a face copied from a void shell of a read solid is written as it
/// was read.
pub fn write_step_shells(
    brep: &Brep,
    shells: &[(Vec<FaceId>, Vec<Vec<FaceId>>)],
    name: &str,
) -> String {
    let bodies: Vec<Body> = shells
        .iter()
        .map(|(outer, voids)| Body {
            name: String::new(),
            outer: outer.clone(),
            voids: voids.clone(),
        })
        .collect();
    write_bodies(brep, &bodies, name)
}

/// The timestamp written into `FILE_NAME` (fixed, so that output is reproducible).
const TIMESTAMP: &str = "2024-01-01T00:00:00";

fn write_bodies(brep: &Brep, bodies: &[Body], name: &str) -> String {
    let mut w = Writer::new(brep);
    let app_protocol = w.reserve();
    let app_context = w.reserve();
    let sdr = w.reserve();
    let pds = w.reserve();
    let pd = w.reserve();
    let pdf = w.reserve();
    let product = w.reserve();
    let product_context = w.reserve();
    let pd_context = w.reserve();
    let rep = w.reserve();
    let qname = string(name);
    w.set(
        app_protocol,
        format!(
            "APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,#{app_context})"
        ),
    );
    w.set(
        app_context,
        "APPLICATION_CONTEXT('core data for automotive mechanical design processes')".into(),
    );
    w.set(
        sdr,
        format!("SHAPE_DEFINITION_REPRESENTATION(#{pds},#{rep})"),
    );
    w.set(pds, format!("PRODUCT_DEFINITION_SHAPE('','',#{pd})"));
    w.set(
        pd,
        format!("PRODUCT_DEFINITION('design','',#{pdf},#{pd_context})"),
    );
    w.set(
        pdf,
        format!("PRODUCT_DEFINITION_FORMATION('','',#{product})"),
    );
    w.set(
        product,
        format!("PRODUCT({qname},{qname},'',(#{product_context}))"),
    );
    w.set(
        product_context,
        format!("PRODUCT_CONTEXT('',#{app_context},'mechanical')"),
    );
    w.set(
        pd_context,
        format!("PRODUCT_DEFINITION_CONTEXT('part definition',#{app_context},'design')"),
    );
    let axes = w.placement(&Frame::world(P3::origin()));
    let mut items = vec![axes];
    for b in bodies {
        if let Some(s) = w.body(b) {
            items.push(s);
        }
    }
    // The geometric context: millimetres, radians, steradians, 1e-7 mm uncertainty.
    let mm = w.add("( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )".into());
    let rad = w.add("( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) )".into());
    let sr = w.add("( NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT() )".into());
    let unc = w.add(format!(
        "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-07),#{mm},'distance_accuracy_value','confusion accuracy')"
    ));
    let ctx = w.add(format!(
        "( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#{unc})) GLOBAL_UNIT_ASSIGNED_CONTEXT((#{mm},#{rad},#{sr})) REPRESENTATION_CONTEXT('','') )"
    ));
    w.set(
        rep,
        format!(
            "ADVANCED_BREP_SHAPE_REPRESENTATION('',{},#{ctx})",
            ref_list(&items)
        ),
    );
    w.add(format!(
        "PRODUCT_RELATED_PRODUCT_CATEGORY('part',$,(#{product}))"
    ));

    let mut out =
        String::with_capacity(w.entities.iter().map(|e| e.len() + 12).sum::<usize>() + 512);
    out.push_str("ISO-10303-21;\nHEADER;\n");
    out.push_str("FILE_DESCRIPTION(('B-rep solids written by features'),'2;1');\n");
    out.push_str(&wrap(&format!(
        "FILE_NAME({qname},'{TIMESTAMP}',(''),(''),'features brep writer','features','');"
    )));
    out.push_str("FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n");
    for (k, e) in w.entities.iter().enumerate() {
        out.push_str(&wrap(&format!("#{} = {};", k + 1, e)));
    }
    out.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
    out
}
