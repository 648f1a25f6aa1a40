use super::*;
use ferroc_ports::port::ConnectOptions;

fn table() -> ValueTable {
    ValueTable::default()
}

#[test]
fn built_in_types_are_registered_with_their_port_kind() {
    let t = table();
    for name in [
        "f64",
        "f32",
        "i8",
        "i64",
        "u32",
        "u64",
        "bool",
        "string",
        "timestamp",
    ] {
        assert!(t.get(name).is_some(), "{name} missing");
    }
    assert!(t.get("f64").unwrap().is_number() && t.get("f64").unwrap().is_copy());
    assert!(t.get("u32").unwrap().is_number());
    assert!(!t.get("string").unwrap().is_number() && !t.get("string").unwrap().is_copy());
    assert!(!t.get("timestamp").unwrap().is_number() && t.get("timestamp").unwrap().is_copy());
    assert!(!t.get("[f64]").unwrap().is_copy());
    assert!(t.get("f64[3]").unwrap().is_copy());
    assert!(t.get("warehouse.RobotStatus").is_none());
    // Meta signals are f64 numbers under their own names; durations are pooled.
    let activity = t.get("Activity").unwrap();
    assert!(activity.is_number() && activity.is_copy());
    assert!(!t.get("duration").unwrap().is_copy());
    let (out, inp) = wire(&t, "duration");
    out.typed::<std::time::Duration>()
        .unwrap()
        .publish(std::time::Duration::from_millis(1500));
    let (mut human, mut json) = (String::new(), String::new());
    inp.write_human(&mut human);
    inp.write_json(&mut json);
    assert_eq!((human.as_str(), json.as_str()), ("1.5s", "1.5"));
}

/// A wire between a fresh output of `ty` and a fresh input of `ty`.
fn wire(t: &ValueTable, ty: &str) -> (DynOut, DynIn) {
    let vt = t.get(ty).unwrap();
    let (out, oh) = vt.output("out");
    let (inp, ih) = vt.input("in", None);
    oh.connect(&ih, ConnectOptions::default()).unwrap();
    (out, inp)
}

#[test]
fn numbers_convert_and_print() {
    let t = table();
    let (out, inp) = wire(&t, "u32");
    assert!(!inp.changed());
    assert!(out.publish_f64(41.7));
    assert!(inp.changed());
    assert!(!inp.changed(), "changed is taken once");
    assert_eq!(inp.get_f64(), Some(41.0), "`as` truncates");
    // Saturating at the type's bounds, NaN → 0.
    out.publish_f64(-3.0);
    assert_eq!(inp.get_f64(), Some(0.0));
    out.publish_f64(1e12);
    assert_eq!(inp.get_f64(), Some(u32::MAX as f64));
    let mut text = String::new();
    inp.write_human(&mut text);
    assert_eq!(text, "4294967295");

    let (out, inp) = wire(&t, "f64");
    out.publish_f64(f64::NAN);
    let mut text = String::new();
    inp.write_json(&mut text);
    assert_eq!(text, "null", "JSON has no NaN");
    out.publish_f64(0.25);
    text.clear();
    inp.write_human(&mut text);
    text.push(' ');
    inp.write_json(&mut text);
    assert_eq!(text, "0.25 0.25");
    assert_eq!(inp.typed::<f64>().map(|i| i.get()), Some(0.25));
    assert!(inp.typed::<u32>().is_none());
}

#[test]
fn non_numbers_refuse_numbers_and_quote_in_json() {
    let t = table();
    let (out, inp) = wire(&t, "string");
    assert!(!out.publish_f64(1.0));
    assert_eq!(inp.get_f64(), None);
    out.typed::<String>()
        .unwrap()
        .publish("say \"hi\"\n\\".to_owned());
    let (mut human, mut json) = (String::from("> "), String::from("> "));
    inp.write_human(&mut human);
    inp.write_json(&mut json);
    assert_eq!(human, "> say \"hi\"\n\\");
    assert_eq!(json, r#"> "say \"hi\"\n\\""#);

    let (out, inp) = wire(&t, "timestamp");
    out.typed::<Timestamp>()
        .unwrap()
        .publish(Timestamp { nanos: 0 });
    let mut json = String::new();
    inp.write_json(&mut json);
    assert_eq!(json, "\"1970-01-01T00:00:00.000000Z\"");
}

#[test]
fn forwarding_copies_the_value_for_both_port_kinds() {
    let t = table();
    for ty in ["f64", "[f64]", "string", "bool"] {
        let (src, mid) = wire(&t, ty);
        let (out, end) = wire(&t, ty);
        match ty {
            "f64" => assert!(src.publish_f64(2.5)),
            "[f64]" => src.typed::<Vec<f64>>().unwrap().publish(vec![1.0, 2.0]),
            "string" => src.typed::<String>().unwrap().publish("x".into()),
            _ => src.typed::<bool>().unwrap().publish(true),
        }
        assert!(out.forward(&mid), "{ty}");
        assert!(end.changed(), "{ty}");
        let (mut a, mut b) = (String::new(), String::new());
        mid.write_human(&mut a);
        end.write_human(&mut b);
        assert_eq!(a, b, "{ty}");
        assert!(!a.is_empty() && a != "false" && a != "[]", "{ty}: {a}");
    }
    // Different value types: nothing is forwarded.
    let (_, f) = wire(&t, "f64");
    let (out, end) = wire(&t, "u32");
    assert!(!out.forward(&f));
    assert!(!end.changed());
}

#[test]
fn an_unbound_output_does_nothing() {
    let out = DynOut::unbound("out");
    let (_, inp) = wire(&table(), "f64");
    assert!(!out.is_bound());
    assert!(!out.publish_f64(1.0));
    assert!(!out.forward(&inp));
    assert!(out.typed::<f64>().is_none());
}

#[test]
fn quoting_escapes_only_when_needed() {
    let mut s = String::from("a=");
    s.push_str("plain");
    quote_tail(&mut s, 2);
    assert_eq!(s, "a=\"plain\"");
    let mut s = String::from("tab\there\u{1}");
    quote_tail(&mut s, 0);
    assert_eq!(s, "\"tab\\there\\u0001\"");
}
