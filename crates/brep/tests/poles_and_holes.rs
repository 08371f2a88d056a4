//! A closed surface of revolution whose face is bounded by its two poles (vertex loops) and by
//! holes alone, none of them winding round the axis: Onshape writes a sphere with three holes so
//! (`onshape_abc_0_13.step`, face #179). The face is the whole surface less the holes; meshed as
//! the holes alone it read 349.8 mm² instead of OpenCASCADE's 790.1 mm², and the part 10.8 %
//! over its volume.
//!
//! The part here: a sphere R = 10 (a rational cubic semicircle revolved about Z, as Onshape
//! writes it) cut by the plane x = ±6, once beside the seam (+x) and once across it (−x: the
//! generatrix, so the seam, lies at −x). Exact figures: the sphere less a cap of height 4.

use brep::solid::report_solid;
use brep::topology::SolidId;
use std::f64::consts::PI;

/// The part's STEP text, with the plane at `x = side * 6`.
fn part(side: f64) -> String {
    let (c, n) = if side > 0.0 {
        ("6.", "(1.,0.,0.)")
    } else {
        ("-6.", "(-1.,0.,0.)")
    };
    format!(
        "ISO-10303-21;
HEADER;
FILE_DESCRIPTION((''),'2;1');
FILE_NAME('poles_and_holes','2024-01-01T00:00:00',(''),(''),'','','');
FILE_SCHEMA(('AUTOMOTIVE_DESIGN {{ 1 0 10303 214 1 1 1 1 }}'));
ENDSEC;
DATA;
#1 = CARTESIAN_POINT('',(0.,0.,0.));
#2 = DIRECTION('',(0.,0.,1.));
#4 = DIRECTION('',{n});
#5 = DIRECTION('',(0.,1.,0.));
#6 = CARTESIAN_POINT('',(0.,0.,-10.));
#7 = CARTESIAN_POINT('',(-20.,0.,-10.));
#8 = CARTESIAN_POINT('',(-20.,0.,10.));
#9 = CARTESIAN_POINT('',(0.,0.,10.));
#10 = (BOUNDED_CURVE() B_SPLINE_CURVE(3,(#6,#7,#8,#9),.UNSPECIFIED.,.F.,.F.) B_SPLINE_CURVE_WITH_KNOTS((4,4),(0.,1.),.UNSPECIFIED.) CURVE() GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_CURVE((1.,0.333333333333333,0.333333333333333,1.)) REPRESENTATION_ITEM(''));
#11 = AXIS1_PLACEMENT('',#1,#2);
#12 = SURFACE_OF_REVOLUTION('',#10,#11);
#22 = VERTEX_POINT('',#6);
#23 = VERTEX_POINT('',#9);
#24 = VERTEX_LOOP('',#22);
#25 = VERTEX_LOOP('',#23);
#26 = FACE_BOUND('',#24,.T.);
#27 = FACE_BOUND('',#25,.T.);
#30 = CARTESIAN_POINT('',({c},0.,0.));
#31 = AXIS2_PLACEMENT_3D('',#30,#4,#5);
#32 = CIRCLE('',#31,8.);
#33 = CARTESIAN_POINT('',({c},8.,0.));
#34 = VERTEX_POINT('',#33);
#35 = EDGE_CURVE('',#34,#34,#32,.T.);
#36 = ORIENTED_EDGE('',*,*,#35,.F.);
#37 = EDGE_LOOP('',(#36));
#38 = FACE_BOUND('',#37,.T.);
#39 = ORIENTED_EDGE('',*,*,#35,.T.);
#40 = PLANE('',#31);
#41 = EDGE_LOOP('',(#39));
#42 = FACE_OUTER_BOUND('',#41,.T.);
#50 = ADVANCED_FACE('',(#26,#27,#38),#12,.T.);
#51 = ADVANCED_FACE('',(#42),#40,.T.);
#52 = CLOSED_SHELL('',(#50,#51));
#53 = MANIFOLD_SOLID_BREP('',#52);
ENDSEC;
END-ISO-10303-21;
"
    )
}

#[test]
fn a_face_of_two_poles_and_holes_is_the_surface_less_the_holes() {
    let (r, h): (f64, f64) = (10.0, 4.0);
    let volume = 4.0 / 3.0 * PI * r.powi(3) - PI * h * h * (3.0 * r - h) / 3.0;
    let area = 4.0 * PI * r * r - 2.0 * PI * r * h + PI * (r * r - (r - h) * (r - h));
    for side in [1.0, -1.0] {
        let part = brep::read_step_bytes(part(side).as_bytes()).expect("reads");
        let rep = report_solid(&part.brep, SolidId(0)).expect("meshes");
        assert!(
            rep.closed && rep.watertight,
            "x = {side}*6: closed {} watertight {}: {:?}",
            rep.closed,
            rep.watertight,
            rep.findings
        );
        assert!(
            (rep.volume - volume).abs() <= 1e-3 * volume,
            "x = {side}*6: volume {} vs exact {volume}",
            rep.volume
        );
        assert!(
            (rep.area - area).abs() <= 1e-3 * area,
            "x = {side}*6: area {} vs exact {area}",
            rep.area
        );
    }
}
