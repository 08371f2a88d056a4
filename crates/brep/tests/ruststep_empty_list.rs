//! Pins why `brep::p21` exists instead of `ruststep::parser`: ruststep 0.4
//! rejects the empty list `()`, which is valid ISO 10303-21 and which real
//! writers emit (NIST, Shapr3D: `DRAUGHTING_MODEL('',(),#10);`).
//!
//! If this test starts failing because ruststep accepts the file, the
//! workaround may be reconsidered.

/// A minimal valid exchange file whose entity #11 holds `list`.
fn file_with(list: &str) -> String {
    format!(
        "ISO-10303-21;
HEADER;
FILE_DESCRIPTION(('empty list'),'2;1');
FILE_NAME('empty_list.step','2024-01-01T00:00:00',('a'),('b'),'c','d','e');
FILE_SCHEMA(('AUTOMOTIVE_DESIGN'));
ENDSEC;
DATA;
#8=(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.));
#9=UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-05),#8,'DISTANCE_ACCURACY_VALUE','tolerance');
#10=(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#9))GLOBAL_UNIT_ASSIGNED_CONTEXT((#8))REPRESENTATION_CONTEXT('',''));
#11=DRAUGHTING_MODEL('',{list},#10);
#12=CARTESIAN_POINT('',(0.,0.,0.));
ENDSEC;
END-ISO-10303-21;
"
    )
}

#[test]
fn ruststep_rejects_empty_list_but_p21_accepts_it() {
    let text = file_with("()");
    assert!(
        ruststep::parser::parse(&text).is_err(),
        "ruststep 0.4 now accepts an empty list: the workaround may be unnecessary"
    );
    let parsed = brep::p21::parse(text.as_bytes()).expect("brep::p21 parses the empty list");
    let model = parsed.get(11).expect("#11");
    let record = model.instance.record("DRAUGHTING_MODEL").expect("record");
    assert_eq!(record.params[1], brep::p21::Param::List(Vec::new()));
}

#[test]
fn ruststep_accepts_same_file_with_non_empty_list() {
    // Control: the only difference is `(#12)` instead of `()`, so the failure
    // above is due to the empty list and nothing else in the file.
    let text = file_with("(#12)");
    assert!(ruststep::parser::parse(&text).is_ok());
    assert!(brep::p21::parse(text.as_bytes()).is_ok());
}
