use super::*;

#[test]
fn entries_with_scale_offset_and_cast() {
    let m = parse("in/0 -> out[0] * 1000 as i32; in/2[1] -> out/1*0.5 - 3\n\n").unwrap();
    assert_eq!(m.len(), 2);
    assert_eq!(m[0].from.port, "in/0");
    assert_eq!((m[0].to.port, m[0].to.index), ("out", Some(0)));
    assert_eq!((m[0].scale, m[0].offset), (1000.0, 0.0));
    assert_eq!(m[0].cast.as_ref().map(|c| c.0), Some("i32"));
    assert_eq!((m[1].from.port, m[1].from.index), ("in/2", Some(1)));
    assert_eq!((m[1].scale, m[1].offset), (0.5, -3.0));
    let text = "in/0 -> out[0] * 1000 as i32; in/2[1] -> out/1*0.5 - 3";
    assert_eq!(&text[m[1].from.span.clone()], "in/2[1]");
}

#[test]
fn mistakes_point_at_their_place() {
    let text = "in/0 -> out[x]";
    let e = parse(text).unwrap_err();
    assert_eq!(&text[e.span], "out[x]");
    assert!(e.what.contains("not a whole number"), "{}", e.what);
    let text = "in/0 -> out * many";
    let e = parse(text).unwrap_err();
    assert_eq!(&text[e.span], "many");
    let e = parse("in/0 out").unwrap_err();
    assert!(e.what.contains("INPUT -> OUTPUT"));
    assert!(parse(" ; ").unwrap_err().what.contains("empty"));
    let text = "in/0 -> out as i32 please";
    assert_eq!(&text[parse(text).unwrap_err().span], "please");
}

#[test]
fn shapes_and_lossy_conversions() {
    let s = shape("f64[4][4]").unwrap();
    assert_eq!((s.element, s.len, s.scalar), ("f64", Some(16), false));
    assert_eq!(shape("i32").unwrap().len, Some(1));
    assert!(shape("i32").unwrap().scalar);
    assert_eq!(shape("[u8]").unwrap().len, None);
    assert_eq!(shape("string"), None);
    assert_eq!(shape("rescue.Pose2D"), None);
    assert!(loses_data("f64", "i32"));
    assert!(loses_data("f64", "f32"));
    assert!(loses_data("i32", "u32"));
    assert!(loses_data("u32", "i32"));
    assert!(loses_data("i64", "f64"));
    assert!(!loses_data("i32", "f64"));
    assert!(!loses_data("u8", "i16"));
    assert!(!loses_data("f32", "f64"));
    assert!(!loses_data("i32", "i64"));
}

fn ports(name: &str) -> Option<(Dir, &'static str)> {
    match name {
        "in/0" | "in/1" => Some((Dir::In, "f64")),
        "in/2" => Some((Dir::In, "f64[3]")),
        "name" => Some((Dir::In, "string")),
        "out" => Some((Dir::Out, "i32[3]")),
        "out/1" => Some((Dir::Out, "f64")),
        _ => None,
    }
}

fn misfits(text: &str) -> Vec<String> {
    validate(&parse(text).unwrap(), ports)
        .into_iter()
        .map(|m| format!("{} @{}", m.what, &text[m.span]))
        .collect()
}

#[test]
fn a_map_that_fits_has_no_misfits() {
    let ok = "in/0 -> out[0] * 1000 as i32; in/1 -> out[1] * 1000 as i32; in/2[2] -> out/1";
    assert_eq!(misfits(ok), Vec::<String>::new());
}

#[test]
fn misfits_name_the_pin() {
    assert_eq!(
        misfits("in/9 -> out/1"),
        ["the filter has no port `in/9` @in/9"]
    );
    assert_eq!(
        misfits("in/0 -> out[3] as i32"),
        ["index 3 is out of range: `out` (`i32[3]`) has 3 elements @out[3]"]
    );
    assert_eq!(
        misfits("in/0[0] -> out/1"),
        ["`in/0` is a single `f64`: it has no elements to index @in/0[0]"]
    );
    assert_eq!(
        misfits("in/0 -> out[0]"),
        ["converting `f64` to `i32` can lose data and is not marked @in/0 -> out[0]"]
    );
    assert_eq!(
        misfits("in/0 -> out[0] as i64"),
        ["`as i64`, but `out` holds `i32` elements @i64"]
    );
    assert_eq!(misfits("out/1 -> out[0] as i32").len(), 1);
    assert_eq!(
        misfits("name -> out/1"),
        ["`name` carries `string`, which is not numbers @name"]
    );
    assert_eq!(
        misfits("in/2 -> out/1").len(),
        1,
        "whole array onto a number"
    );
    assert_eq!(
        misfits("in/0 -> out/1; in/1 -> out/1"),
        ["`out/1` is written by two entries @out/1"]
    );
}

proptest::proptest! {
    #[test]
    fn any_text_parses_or_reports_a_span_inside_it(text in "\\PC{0,80}") {
        match parse(&text) {
            Ok(entries) => proptest::prop_assert!(!entries.is_empty()),
            Err(e) => {
                proptest::prop_assert!(e.span.end <= text.len());
                proptest::prop_assert!(text.get(e.span.clone()).is_some());
            }
        }
    }
}
