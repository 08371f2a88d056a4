use super::*;

const HEADER: &str = "ISO-10303-21;\nHEADER;\n\
        FILE_DESCRIPTION(('test'),'2;1');\n\
        FILE_NAME('t.step','2024-01-01T00:00:00',(''),(''),'','','');\n\
        FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\n\
        ENDSEC;\n";

/// A complete file whose DATA section holds `data`; data starts on line 8.
fn wrap(data: &str) -> String {
    format!("{HEADER}DATA;\n{data}\nENDSEC;\nEND-ISO-10303-21;\n")
}

fn ok(data: &str) -> P21File {
    match parse(wrap(data).as_bytes()) {
        Ok(f) => f,
        Err(e) => panic!("parse failed: {e}\n{data}"),
    }
}

fn err(data: &str) -> P21Error {
    match parse(wrap(data).as_bytes()) {
        Ok(_) => panic!("parse unexpectedly succeeded:\n{data}"),
        Err(e) => e,
    }
}

/// Params of the simple entity `#id`.
fn params(f: &P21File, id: u64) -> &[Param] {
    match &f.get(id).expect("entity").instance {
        Instance::Simple(r) => &r.params,
        Instance::Complex(_) => panic!("complex"),
    }
}

fn one(data: &str) -> Param {
    let f = ok(data);
    params(&f, f.entities[0].id)[0].clone()
}

fn s(x: &str) -> Param {
    Param::Str(x.to_string())
}

const SMALL: &str = "ISO-10303-21;
HEADER;
/* header comment */
FILE_DESCRIPTION(('small'),'2;1');
FILE_NAME('a.step','2024-01-01',('me'),(''),'x','y','');
FILE_SCHEMA(('CONFIG_CONTROL_DESIGN'));
ENDSEC;
DATA;
#1=CARTESIAN_POINT('',(0.,1.5,-2.E-3));
#2=DIRECTION('',(0.,0.,1.));
#3=(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.));
#4=PLANE_ANGLE_MEASURE_WITH_UNIT(PLANE_ANGLE_MEASURE(0.0174532925),#3);
#5=DRAUGHTING_MODEL('it''s \\X2\\00E9\\X0\\',(),#4);
#6=B_SPLINE_CURVE_WITH_KNOTS('',3,(#1,#1,#1,#1),.UNSPECIFIED.,.F.,.F.,(4,4),(0.,1.),.UNSPECIFIED.);
#7=SOMETHING(\"0F3\",((1,2),()),*);
ENDSEC;
END-ISO-10303-21;
";

#[test]
fn p21_small_file_parses() {
    let f = parse(SMALL.as_bytes()).expect("small file");
    assert_eq!(f.header.len(), 3);
    assert_eq!(f.header[0].name, "FILE_DESCRIPTION");
    assert_eq!(f.entities.len(), 7);
    assert_eq!(f.schemas(), vec!["CONFIG_CONTROL_DESIGN".to_string()]);
    assert_eq!(f.first_dangling_ref(), None);
    let e1 = f.get(1).expect("#1");
    assert_eq!(e1.line, 9);
    assert_eq!(
        params(&f, 1),
        &[
            s(""),
            Param::List(vec![Param::Real(0.), Param::Real(1.5), Param::Real(-2e-3)])
        ]
    );
    assert_eq!(params(&f, 5)[0], s("it's é"));
    assert_eq!(params(&f, 5)[1], Param::List(vec![]));
    assert_eq!(f.get(7).expect("#7").line, 15);
    assert!(f.get(8).is_none());
}

#[test]
fn p21_empty_and_whitespace_only() {
    assert_eq!(parse(b"").unwrap_err(), P21Error::Empty);
    assert_eq!(parse(b" \r\n\t \n").unwrap_err(), P21Error::Empty);
}

#[test]
fn p21_not_part21() {
    assert_eq!(
        parse(b"solid foo\nendsolid").unwrap_err(),
        P21Error::NotPart21
    );
    assert_eq!(parse(b"/* c */ HEADER;").unwrap_err(), P21Error::NotPart21);
    assert_eq!(parse(b"\x00\x01\x02").unwrap_err(), P21Error::NotPart21);
    // Leading comments and a byte-order mark are fine.
    let with_bom = [b"\xEF\xBB\xBF/* hi */ ".as_slice(), SMALL.as_bytes()].concat();
    assert!(parse(&with_bom).is_ok());
}

#[test]
fn p21_comments_and_whitespace_everywhere() {
    let text = "/* lead */ ISO-10303-21 /* a */ ;\r\n\tHEADER /* b */;\r\n\
            FILE_DESCRIPTION /* c */ ( /* d */ ( 'x' /* e */ ) , '2;1' ) /* f */ ;\r\n\
            FILE_NAME('','',(''),(''),'','','');\r\n\
            FILE_SCHEMA((/* g */'AP214'));\r\n\
            ENDSEC /* h */ ;\r\n\
            DATA ;\r\n\
            /* before */ #1 /* i */ = /* j */ PLANE /* k */ ( '' , #2 /* l */ ) /* m */ ;\r\n\
            #2\t=\tAXIS2_PLACEMENT_3D('',#3,$,$)\t;\r\n\
            #3 = ( /* n */ NAMED_UNIT ( * ) /* o */ \r\n SI_UNIT ( $ , .METRE. ) /* p */ ) ;\r\n\
            ENDSEC;\r\n\
            END-ISO-10303-21;\r\n";
    let f = parse(text.as_bytes()).expect("comments");
    assert_eq!(f.header.len(), 3);
    assert_eq!(f.schemas(), vec!["AP214".to_string()]);
    assert_eq!(f.entities.len(), 3);
    assert_eq!(f.get(1).expect("#1").line, 8);
    assert_eq!(f.get(3).expect("#3").line, 10);
    assert_eq!(params(&f, 1), &[s(""), Param::Ref(2)]);
    assert_eq!(
        f.get(3).expect("#3").instance.names(),
        vec!["NAMED_UNIT", "SI_UNIT"]
    );
}

#[test]
fn p21_strings_and_directives() {
    assert_eq!(one("#1=A('it''s');"), s("it's"));
    assert_eq!(one("#1=A('''');"), s("'"));
    assert_eq!(one("#1=A('');"), s(""));
    assert_eq!(one("#1=A('caf\\X2\\00E9\\X0\\');"), s("café"));
    assert_eq!(one("#1=A('\\X2\\00E900E8\\X0\\!');"), s("éè!"));
    // Surrogate pair in X2.
    assert_eq!(one("#1=A('\\X2\\D83DDE00\\X0\\');"), s("😀"));
    assert_eq!(one("#1=A('\\X4\\0001F600\\X0\\');"), s("😀"));
    assert_eq!(one("#1=A('caf\\X\\E9');"), s("café"));
    assert_eq!(one("#1=A('\\S\\i');"), s("é"));
    assert_eq!(one("#1=A('\\PA\\\\S\\i');"), s("é"));
    assert_eq!(one("#1=A('C:\\\\dir\\\\f.stp');"), s("C:\\dir\\f.stp"));
    // Unknown or malformed directives are kept literally.
    assert_eq!(one("#1=A('a\\Q\\b');"), s("a\\Q\\b"));
    assert_eq!(one("#1=A('\\X2\\00E');"), s("\\X2\\00E"));
    assert_eq!(one("#1=A('\\X\\G1');"), s("\\X\\G1"));
    assert_eq!(one("#1=A('end\\');"), s("end\\"));
    // Writers wrap long strings: the line break is not part of the value.
    let f = ok("#1=A('Screw0.s\r\ntp');\n#2=B(#1);");
    assert_eq!(params(&f, 1)[0], s("Screw0.stp"));
    assert_eq!(f.get(2).expect("#2").line, 10);
}

#[test]
fn p21_non_utf8_bytes_in_strings() {
    // Latin-1 é (0xE9) and a stray 0xFF; UTF-8 é kept as is.
    let mut text = wrap("#1=A('caf\u{1}','x');").into_bytes();
    let at = text.iter().position(|&c| c == 1).expect("marker");
    text.splice(at..at + 1, [0xE9, 0xFF, b' ', 0xC3, 0xA9]);
    let f = parse(&text).expect("latin-1");
    assert_eq!(params(&f, 1)[0], s("caf\u{e9}\u{ff} é"));
    // Also in the slow path (with a doubled quote).
    let mut text = wrap("#1=A('a''\u{1}');").into_bytes();
    let at = text.iter().position(|&c| c == 1).expect("marker");
    text[at] = 0xE9;
    let f = parse(&text).expect("latin-1 slow");
    assert_eq!(params(&f, 1)[0], s("a'é"));
}

#[test]
fn p21_enums_numbers_and_specials() {
    let f =
        ok("#1=A(.T.,.F.,.UNSPECIFIED.,$,*,7,-12,+3,0,1.,-0.,1.E-05,1.0E+01,2.5e3,\"0F3\",\"\");");
    let p = params(&f, 1);
    assert_eq!(p[0], Param::Enum("T".into()));
    assert_eq!(p[1], Param::Enum("F".into()));
    assert_eq!(p[2], Param::Enum("UNSPECIFIED".into()));
    assert_eq!(p[3], Param::Null);
    assert_eq!(p[4], Param::Derived);
    assert_eq!(p[5], Param::Int(7));
    assert_eq!(p[6], Param::Int(-12));
    assert_eq!(p[7], Param::Int(3));
    assert_eq!(p[8], Param::Int(0));
    assert_eq!(p[9], Param::Real(1.0));
    match p[10] {
        Param::Real(x) => assert!(x == 0.0 && x.is_sign_negative()),
        ref other => panic!("{other:?}"),
    }
    assert_eq!(p[11], Param::Real(1e-5));
    assert_eq!(p[12], Param::Real(10.0));
    assert_eq!(p[13], Param::Real(2500.0));
    assert_eq!(p[14], Param::Binary("0F3".into()));
    assert_eq!(p[15], Param::Binary(String::new()));
    assert_eq!(one("#1=A(9223372036854775807);"), Param::Int(i64::MAX));
}

#[test]
fn p21_bad_numbers_are_errors_not_panics() {
    for bad in [
        "#1=A(.5);",
        "#1=A(-.5);",
        "#1=A(1.E);",
        "#1=A(-);",
        "#1=A(1.5.2);",
        "#1=A(99999999999999999999);",
        "#1=A(.T);",
        "#1=A(\"0G\");",
    ] {
        let e = err(bad);
        assert!(
            matches!(e, P21Error::Syntax { line: 8, .. }),
            "{bad}: {e:?}"
        );
        assert!(e.to_string().contains("#1"), "{bad}: {e}");
    }
}

#[test]
fn p21_typed_and_nested_params() {
    assert_eq!(
        one("#1=A(LENGTH_MEASURE(2.));"),
        Param::Typed("LENGTH_MEASURE".into(), Box::new(Param::Real(2.0)))
    );
    assert_eq!(
        one("#1=A( OUTER ( INNER ( ( 1 , 2 ) ) ) );"),
        Param::Typed(
            "OUTER".into(),
            Box::new(Param::Typed(
                "INNER".into(),
                Box::new(Param::List(vec![Param::Int(1), Param::Int(2)]))
            ))
        )
    );
    assert_eq!(
        one("#1=A(((),(()),((#1,#2),(#3))));"),
        Param::List(vec![
            Param::List(vec![]),
            Param::List(vec![Param::List(vec![])]),
            Param::List(vec![
                Param::List(vec![Param::Ref(1), Param::Ref(2)]),
                Param::List(vec![Param::Ref(3)])
            ]),
        ])
    );
    assert_eq!(one("#1=A( ( ) );"), Param::List(vec![]));
    let f = ok("#1=EMPTY();");
    assert!(params(&f, 1).is_empty());
}

#[test]
fn p21_complex_instances() {
    for data in [
        "#3=(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.));",
        "#3 = ( NAMED_UNIT ( * )\n  PLANE_ANGLE_UNIT ( )\n  SI_UNIT ( $ , .RADIAN. ) ) ;",
    ] {
        let f = ok(data);
        let e = f.get(3).expect("#3");
        assert_eq!(e.line, 8);
        let Instance::Complex(recs) = &e.instance else {
            panic!("not complex")
        };
        assert_eq!(recs.len(), 3);
        assert_eq!(
            e.instance.names(),
            vec!["NAMED_UNIT", "PLANE_ANGLE_UNIT", "SI_UNIT"]
        );
        let si = e.instance.record("SI_UNIT").expect("si");
        assert_eq!(si.params, vec![Param::Null, Param::Enum("RADIAN".into())]);
        assert!(e.instance.record("plane_angle_unit").is_some());
        assert!(e.instance.record("LENGTH_UNIT").is_none());
    }
    let f = ok("#1=POINT('');");
    let inst = &f.get(1).expect("#1").instance;
    assert_eq!(inst.record("POINT").map(|r| r.params.len()), Some(1));
    assert!(inst.record("LINE").is_none());
    assert_eq!(inst.names(), vec!["POINT"]);
    assert!(matches!(err("#1=();"), P21Error::Syntax { .. }));
}

#[test]
fn p21_sections() {
    let text = format!(
        "{HEADER}ANCHOR;\n<a> = #1;\nENDSEC;\n\
             DATA('one',('AP214'));\n#1=A(#20);\nENDSEC;\n\
             REFERENCE;\n#9 = <http://x/y#z>;\n'ENDSEC;' /* ENDSEC; */\nENDSEC;\n\
             DATA;\n#20=B(#1);\nENDSEC;\n\
             SIGNATURE;\nQUJDREVG\"0A\"==\nENDSEC;\n\
             END-ISO-10303-21;\ntrailing garbage ignored ((("
    );
    let f = parse(text.as_bytes()).expect("sections");
    assert_eq!(f.entities.len(), 2);
    assert_eq!(f.get(20).expect("#20").line, 18);
    assert_eq!(f.first_dangling_ref(), None);
    // Ids are unique across sections.
    let dup =
        format!("{HEADER}DATA;\n#1=A();\nENDSEC;\nDATA;\n#1=B();\nENDSEC;\nEND-ISO-10303-21;\n");
    assert_eq!(
        parse(dup.as_bytes()).unwrap_err(),
        P21Error::DuplicateId { id: 1, line: 11 }
    );
}

#[test]
fn p21_ids_order_and_references() {
    let f = ok("#18446744073709551615=A(#7);\n#7=B(#18446744073709551615,#3);\n#3=C((#7));");
    assert_eq!(f.entities.len(), 3);
    assert_eq!(f.entities[0].id, u64::MAX);
    assert_eq!(f.get(u64::MAX).expect("max").line, 8);
    assert_eq!(params(&f, 7)[0], Param::Ref(u64::MAX));
    assert_eq!(f.first_dangling_ref(), None);
    let f = ok("#1=A(#2);\n#2=B((X(#3)),#99);\n#3=C(#1);");
    assert_eq!(f.first_dangling_ref(), Some((2, 99)));
    let f = ok("#1=A(#2);\n#2=B(LIST((#3,(#55))));");
    assert_eq!(f.first_dangling_ref(), Some((2, 3)));
    let e = err("#18446744073709551616=A();");
    assert!(matches!(e, P21Error::Syntax { line: 8, .. }), "{e:?}");
}

#[test]
fn p21_duplicate_id() {
    assert_eq!(
        err("#5=A();\n#6=B();\n#5=C();"),
        P21Error::DuplicateId { id: 5, line: 10 }
    );
}

#[test]
fn p21_too_deep_is_an_error() {
    let deep = format!("#1=A({}1{});", "(".repeat(64), ")".repeat(64));
    assert_eq!(err(&deep), P21Error::TooDeep { line: 8 });
    let ok_depth = format!("#1=A({}1{});", "(".repeat(63), ")".repeat(63));
    ok(&ok_depth);
    let typed = format!("#1=A({}1{});", "T(".repeat(100), ")".repeat(100));
    assert_eq!(err(&typed), P21Error::TooDeep { line: 8 });
    // Huge nesting: no stack overflow.
    let huge = format!("#1=A({}", "(".repeat(1_000_000));
    assert_eq!(err(&huge), P21Error::TooDeep { line: 8 });
}

#[test]
fn p21_truncation_errors() {
    let full = wrap("#1=A('x',(1,2));");
    for (cut, what) in [
        ("#1=A('x',(1", "in list"),
        ("#1=A('x", "in string"),
        ("#1=A", "after name"),
        ("#1=", "after ="),
        ("#1=A('x',(1,2))", "before ;"),
        ("#1=A('x',(1,2));\nENDSEC;\n", "before end"),
    ] {
        let n = full.find(cut).expect("cut") + cut.len();
        let e = parse(&full.as_bytes()[..n]).unwrap_err();
        assert!(matches!(e, P21Error::Truncated { .. }), "{what}: {e:?}");
    }
    assert!(matches!(
        parse(wrap("/* unterminated").as_bytes()).unwrap_err(),
        P21Error::Truncated { .. }
    ));
    let e = parse(b"ISO-10303-21;\nHEADER;\n").unwrap_err();
    assert_eq!(e, P21Error::Truncated { line: 3 });
}

#[test]
fn p21_syntax_error_messages() {
    let e = err("#45=A(1)\n#46=B();");
    assert_eq!(
        e.to_string(),
        "syntax error at line 9: expected ';' after entity #45"
    );
    let e = err("#12=A(1 2);");
    assert_eq!(
            e.to_string(),
            "syntax error at line 8: expected ',' or ')' in parameter list, found a digit in entity #12"
        );
    let e = err("#12 A(1);");
    assert!(e
        .to_string()
        .contains("expected '=' after instance name in entity #12"));
    let e = err("#7=A(%);");
    assert!(e.to_string().contains("found '%' in entity #7"), "{e}");
    let e = err("FOO;");
    assert!(matches!(e, P21Error::Syntax { line: 8, .. }), "{e:?}");
    // Every kind of error displays as one lower-case line without a period.
    let errors = vec![
        P21Error::Empty,
        P21Error::NotPart21,
        P21Error::Truncated { line: 3 },
        P21Error::DuplicateId { id: 5, line: 10 },
        P21Error::TooDeep { line: 8 },
        err("#1=A(\u{7}\u{1b});"),
        err("#1=A()B;"),
        err("#1=1;"),
        err("#1=A(.5);"),
    ];
    for e in errors {
        let text = e.to_string();
        assert!(!text.contains('\n'), "{text}");
        assert!(!text.ends_with('.'), "{text}");
        assert_eq!(text, text.to_lowercase(), "{text}");
    }
}

/// Tiny xorshift64 PRNG for the fuzz-style tests.
struct XorShift(u64);

impl XorShift {
    fn next(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.0 = x;
        x
    }
}

#[test]
fn p21_reals_match_std_bit_for_bit() {
    let mut rng = XorShift(0x1234_5678_9ABC_DEF1);
    for _ in 0..5 {
        let mut texts = Vec::new();
        for _ in 0..20_000 {
            let mut t = String::new();
            match rng.next() % 3 {
                0 => t.push('-'),
                1 => t.push('+'),
                _ => {}
            }
            // Zeros are frequent in real files, so draw them often.
            let digit = |rng: &mut XorShift| {
                if rng.next() % 3 == 0 {
                    '0'
                } else {
                    char::from(b'0' + (rng.next() % 10) as u8)
                }
            };
            for _ in 0..=(rng.next() % 12) {
                t.push(digit(&mut rng));
            }
            t.push('.');
            for _ in 0..(rng.next() % 24) {
                t.push(digit(&mut rng));
            }
            if rng.next() % 2 == 0 {
                t.push(if rng.next() % 2 == 0 { 'E' } else { 'e' });
                match rng.next() % 3 {
                    0 => t.push('-'),
                    1 => t.push('+'),
                    _ => {}
                }
                t.push_str(&(rng.next() % 40).to_string());
            }
            texts.push(t);
        }
        let f = ok(&format!("#1=A(({}));", texts.join(",")));
        let Param::List(values) = &params(&f, 1)[0] else {
            panic!("not a list")
        };
        assert_eq!(values.len(), texts.len());
        for (t, v) in texts.iter().zip(values) {
            let want: f64 = t.parse().expect("std parses");
            match v {
                Param::Real(got) => assert_eq!(got.to_bits(), want.to_bits(), "{t}"),
                other => panic!("{t}: {other:?}"),
            }
        }
    }
    for t in [
        "0.",
        "-0.",
        "1.E-05",
        "0.0174532925",
        "11.50000000000000000",
        "-7.177253269393304400",
        "0.0000000000000000000",
        "1.000000E-05",
        "100.",
        "1.0E+01",
        "123456789012345678901234567890.",
        "1.E308",
        "4.9E-324",
        "1.E99999999999999999999",
    ] {
        let want: f64 = t.parse().expect("std");
        match one(&format!("#1=A({t});")) {
            Param::Real(got) => assert_eq!(got.to_bits(), want.to_bits(), "{t}"),
            other => panic!("{t}: {other:?}"),
        }
    }
    assert_eq!(one("#1=A(-9223372036854775808);"), Param::Int(i64::MIN));
    assert_eq!(
        one("#1=A(999999999999999999);"),
        Param::Int(999_999_999_999_999_999)
    );
    assert_eq!(one("#1=A(-0000000000000000000000042);"), Param::Int(-42));
    assert!(matches!(
        err("#1=A(9223372036854775808);"),
        P21Error::Syntax { .. }
    ));
}

#[test]
fn p21_random_bytes_never_panic() {
    let mut rng = XorShift(0x9E37_79B9_7F4A_7C15);
    // Pure noise, and noise after a valid prelude.
    for round in 0..2000 {
        let len = (rng.next() % 300) as usize;
        let mut bytes: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
        if round % 2 == 1 {
            bytes.splice(0..0, wrap("").bytes().take(HEADER.len() + 6));
        }
        let _ = parse(&bytes);
    }
    // Token soup: characters that matter to the grammar.
    const ALPHABET: &[u8] = b"#=;(),'\"$*.-+0123456789EAZ_ /*\\\nX2S";
    for _ in 0..5000 {
        let len = (rng.next() % 200) as usize;
        let soup: Vec<u8> = (0..len)
            .map(|_| ALPHABET[(rng.next() % ALPHABET.len() as u64) as usize])
            .collect();
        let mut bytes = format!("{HEADER}DATA;\n").into_bytes();
        bytes.extend_from_slice(&soup);
        let _ = parse(&bytes);
    }
    // Mutations of a valid file.
    let base = SMALL.as_bytes();
    for _ in 0..5000 {
        let mut bytes = base.to_vec();
        for _ in 0..(1 + rng.next() % 4) {
            let at = (rng.next() % bytes.len() as u64) as usize;
            match rng.next() % 3 {
                0 => bytes[at] = rng.next() as u8,
                1 => {
                    bytes.remove(at);
                }
                _ => bytes.insert(at, ALPHABET[(rng.next() % ALPHABET.len() as u64) as usize]),
            }
        }
        let _ = parse(&bytes);
    }
}

#[test]
fn p21_every_prefix_never_panics() {
    let bytes = SMALL.as_bytes();
    let end = SMALL.find("END-ISO-10303-21;").expect("end") + "END-ISO-10303-21;".len();
    for n in 0..=bytes.len() {
        let r = parse(&bytes[..n]);
        if n >= end {
            assert!(r.is_ok(), "prefix {n}: {r:?}");
        } else {
            assert!(r.is_err(), "prefix {n} parsed");
        }
        if n > 0 && n < end && n > SMALL.find("HEADER").expect("h") {
            assert!(
                matches!(r, Err(P21Error::Truncated { .. })),
                "prefix {n}: {r:?}"
            );
        }
    }
}

#[test]
fn p21_corpus_files_parse() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus");
    let Ok(read) = std::fs::read_dir(&dir) else {
        eprintln!("note: {} not found, corpus test skipped", dir.display());
        return;
    };
    let mut paths: Vec<_> = read
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension()
                .is_some_and(|x| x.eq_ignore_ascii_case("step"))
        })
        .collect();
    paths.sort();
    for path in &paths {
        let bytes = std::fs::read(path).expect("read corpus file");
        let f = match parse(&bytes) {
            Ok(f) => f,
            Err(e) => panic!("{}: {e}", path.display()),
        };
        assert!(f.entities.len() > 100, "{}", path.display());
        assert!(!f.schemas().is_empty(), "{}", path.display());
        assert_eq!(f.first_dangling_ref(), None, "{}", path.display());
        for e in &f.entities {
            assert!(std::ptr::eq(f.get(e.id).expect("indexed"), e));
        }
        eprintln!("{}: {} entities", path.display(), f.entities.len());
    }
    assert!(
        paths.len() >= 8,
        "expected the 8 corpus files, found {}",
        paths.len()
    );
}

#[test]
fn an_stl_mesh_is_named_as_one() {
    let ascii = b"solid part\n  facet normal 0 0 1\n    outer loop\n";
    assert_eq!(parse(ascii).unwrap_err(), P21Error::Stl);
    let mut binary = vec![0u8; 80];
    binary.extend_from_slice(&2u32.to_le_bytes());
    binary.extend(std::iter::repeat_n(0u8, 100));
    assert_eq!(parse(&binary).unwrap_err(), P21Error::Stl);
    // One byte short is not an STL: just not Part 21.
    binary.pop();
    assert_eq!(parse(&binary).unwrap_err(), P21Error::NotPart21);
}

/// A header left with a merge conflict (markers and two FILE_NAME records) is read: the marker
/// lines are skipped and listed with their line numbers, the records kept.
#[test]
fn header_lines_that_are_no_record_are_skipped_and_listed() {
    let text = "ISO-10303-21;\nHEADER;\n\
        FILE_DESCRIPTION(('test'),'2;1');\n\
        <<<<<<< HEAD\n\
        FILE_NAME('a.step','2024-01-01T00:00:00',(''),(''),'','','');\n\
        =======\n\
        FILE_NAME('b.step','2024-01-02T00:00:00',(''),(''),'','','');\n\
        >>>>>>> other\n\
        FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\n\
        STRAY WORDS HERE\n\
        ENDSEC;\nDATA;\n#1=CARTESIAN_POINT('',(0.,0.,0.));\nENDSEC;\nEND-ISO-10303-21;\n";
    let f = parse(text.as_bytes()).expect("parses");
    let names: Vec<&str> = f.header.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(
        names,
        ["FILE_DESCRIPTION", "FILE_NAME", "FILE_NAME", "FILE_SCHEMA"]
    );
    let lines: Vec<u32> = f.header_skipped.iter().map(|s| s.line).collect();
    assert_eq!(lines, [4, 6, 8, 10]);
    assert_eq!(f.header_skipped[0].text, "<<<<<<< HEAD");
    assert_eq!(f.header_skipped[3].text, "STRAY WORDS HERE");
    assert_eq!(f.entities.len(), 1);
}

/// The DATA section stays strict, and a header that never ends is still an error.
#[test]
fn a_header_without_endsec_and_a_broken_entity_are_still_errors() {
    let no_endsec = "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('t'),'2;1');\n\
        DATA;\n#1=CARTESIAN_POINT('',(0.,0.,0.));\nENDSEC;\nEND-ISO-10303-21;\n";
    match parse(no_endsec.as_bytes()) {
        Err(P21Error::Syntax { line, msg }) => {
            assert_eq!(line, 4);
            assert!(msg.contains("DATA"), "{msg}");
        }
        other => panic!("{other:?}"),
    }
    match parse(wrap("<<<<<<< HEAD\n#1=CARTESIAN_POINT('',(0.,0.,0.));").as_bytes()) {
        Err(P21Error::Syntax { line, .. }) => assert_eq!(line, 8),
        other => panic!("{other:?}"),
    }
}
