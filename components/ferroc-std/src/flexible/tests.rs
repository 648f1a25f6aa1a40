//! The flexible modules on hand-made ports (the Builder path is in
//! `tests/flexible_app.rs`).

use super::*;
use ferroc_runtime::builder::Registry;
use ferroc_runtime::module::ValueTable;
use ferroc_runtime::port::ConnectOptions;

fn values() -> ValueTable {
    Registry::new().values().clone()
}

/// `n` inputs of `ty` and an output feeding each.
fn inputs(t: &ValueTable, ty: &str, n: usize) -> (Vec<DynOut>, Vec<DynIn>) {
    let vt = t.get(ty).unwrap();
    (0..n)
        .map(|k| {
            let (out, oh) = vt.output("src");
            let (inp, ih) = vt.input(&format!("in/{k}"), None);
            oh.connect(&ih, ConnectOptions::default()).unwrap();
            (out, inp)
        })
        .unzip()
}

/// An output of `ty` and an input it feeds, read back as text.
fn sink(t: &ValueTable, ty: &str) -> (DynOut, DynIn) {
    let vt = t.get(ty).unwrap();
    let (out, oh) = vt.output("out");
    let (inp, ih) = vt.input("probe", None);
    oh.connect(&ih, ConnectOptions::default()).unwrap();
    (out, inp)
}

fn text(i: &DynIn) -> String {
    let mut s = String::new();
    i.write_human(&mut s);
    s
}

#[test]
fn sum_adds_in_the_inputs_type() {
    let t = values();
    let (src, ins) = inputs(&t, "u32", 3);
    let (out, probe) = sink(&t, "u32");
    let mut sum = Sum {
        inputs: ins,
        out,
        path: "sum".into(),
        elementwise: false,
        sum: Vec::new(),
        scratch: Vec::new(),
        warned: false,
    };
    for (k, s) in src.iter().enumerate() {
        s.publish_f64(10.0 * (k + 1) as f64);
    }
    sum.update();
    assert_eq!(text(&probe), "60");
    // Saturates at the type's maximum instead of wrapping.
    src[0].publish_f64(u32::MAX as f64);
    sum.update();
    assert_eq!(probe.get_f64(), Some(u32::MAX as f64));

    let (src, ins) = inputs(&t, "f64", 2);
    let (out, probe) = sink(&t, "f64");
    let mut sum = Sum {
        inputs: ins,
        out,
        path: "sum".into(),
        elementwise: false,
        sum: Vec::new(),
        scratch: Vec::new(),
        warned: false,
    };
    src[0].publish_f64(0.5);
    src[1].publish_f64(-2.0);
    sum.update();
    assert_eq!(probe.get_f64(), Some(-1.5));
}

#[test]
fn dump_prints_only_changed_inputs_prefixed_by_the_label() {
    let t = values();
    let (nums, mut ins) = inputs(&t, "f64", 2);
    let (words, more) = inputs(&t, "string", 1);
    ins.extend(more);
    let n = ins.len();
    let mut dump = Dump {
        inputs: ins,
        serde: vec![None; n],
        bytes: Vec::new(),
        label: Parameter::fixed("speed".to_owned()),
        line: String::new(),
        print: |_| {},
    };
    let mut lines = Vec::new();
    dump.dump(|l| lines.push(l.to_owned()));
    assert!(lines.is_empty(), "nothing arrived yet: {lines:?}");
    nums[1].publish_f64(2.5);
    words[0].typed::<String>().unwrap().publish("fast".into());
    dump.dump(|l| lines.push(l.to_owned()));
    assert_eq!(lines, ["speed: in/1 = 2.5", "speed: in/0 = fast"]);
    lines.clear();
    dump.dump(|l| lines.push(l.to_owned()));
    assert!(lines.is_empty(), "printed once per delivery: {lines:?}");
}

#[test]
fn dump_prints_serde_types_in_their_serde_form() {
    let t = values();
    let (pairs, ins) = inputs(&t, "f64[2]", 1);
    let wire = *t.get("f64[2]").unwrap().wire().unwrap();
    let mut dump = Dump {
        inputs: ins,
        serde: vec![Some(wire)],
        bytes: Vec::new(),
        label: Parameter::fixed("pair".to_owned()),
        line: String::new(),
        print: |_| {},
    };
    pairs[0]
        .typed::<[f64; 2]>()
        .unwrap()
        .publish([1.5, f64::NAN]);
    let mut lines = Vec::new();
    dump.dump(|l| lines.push(l.to_owned()));
    assert_eq!(lines, ["pair: in/0 = [1.5,null]"]);
}
