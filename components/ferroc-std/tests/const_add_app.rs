//! `Const` (FlexiConst) and element-wise `Sum` (FlexiAdd), run in lockstep and observed
//! through a `Logger`'s JSON channel.

mod common;

use common::{registry, run_lockstep, scratch};
use ferroc_runtime::behaviour::ViolationPolicy;
use ferroc_runtime::builder::{BuildError, Builder, ModuleSpec};
use ferroc_runtime::module::{Direction, PortGroup, Value};
use ferroc_runtime::port::ConnectOptions;
use ferroc_std::recording::Recording;
use std::path::Path;
use std::time::Duration;

/// Adds a module whose parameters are all given as text, as a model writes them.
fn add(
    b: &mut Builder<'_>,
    path: &str,
    ty: &str,
    params: &[(&str, &str)],
    ports: &[PortGroup],
) -> Result<(), BuildError> {
    let params: Vec<(&str, Value)> = params
        .iter()
        .map(|&(n, v)| (n, Value::Text(v.to_string())))
        .collect();
    common::add(b, path, ty, &params, ports)
}

fn out(ty: &str, n: u32) -> [PortGroup<'_>; 1] {
    [PortGroup::new("out", Direction::Out, ty, Some(n))]
}

/// Adds a logger of `n` inputs of `ty` at `file`, runs `steps` (plus the logger) for
/// `cycles` 10 ms cycles in lockstep, and returns the JSON texts of each input.
fn run(
    mut b: Builder<'_>,
    file: &Path,
    ty: &str,
    sources: &[(&str, &str)],
    steps: &[&str],
    cycles: u64,
) -> Vec<Vec<String>> {
    let n = sources.len() as u32;
    let ports = [PortGroup::new("in", Direction::In, ty, Some(n))];
    let f = file.to_string_lossy().into_owned();
    add(&mut b, "log", "ferroc_std.Logger", &[("file", &f)], &ports).unwrap();
    for (k, from) in sources.iter().enumerate() {
        b.connect(
            *from,
            ("log", &format!("in/{k}")),
            Default::default(),
            ConnectOptions::default(),
        )
        .unwrap();
    }
    let mut order = steps.to_vec();
    order.push("log");
    run_lockstep(b, &order, cycles);
    let rec = match Recording::read(file) {
        Ok(r) => r,
        Err(_) => return vec![Vec::new(); sources.len()],
    };
    (0..n)
        .map(|k| {
            let topic = format!("log/in/{k}");
            let Some(c) = rec
                .channels
                .values()
                .find(|c| c.topic == topic && c.message_encoding == "json")
            else {
                return Vec::new();
            };
            rec.messages
                .iter()
                .filter(|m| m.channel == c.id)
                .map(|m| String::from_utf8(m.data.clone()).unwrap())
                .collect()
        })
        .collect()
}

#[test]
fn arrays_add_element_by_element() {
    let dir = scratch("add_arrays");
    let r = registry();
    let mut b = Builder::new(&r);
    let three = out("f64[3]", 1);
    add(
        &mut b,
        "a",
        "ferroc_std.Const",
        &[("values", "[[1, 2, 3]]")],
        &three,
    )
    .unwrap();
    add(
        &mut b,
        "b",
        "ferroc_std.Const",
        &[("values", "[[0.5, 0.5, -3]]")],
        &three,
    )
    .unwrap();
    let ins = [PortGroup::new("in", Direction::In, "f64[3]", Some(2))];
    add(&mut b, "sum", "ferroc_std.Sum", &[], &ins).unwrap();
    for (k, from) in ["a", "b"].iter().enumerate() {
        b.connect(
            (from, "out/0"),
            ("sum", &format!("in/{k}")),
            Default::default(),
            ConnectOptions::default(),
        )
        .unwrap();
    }
    let got = run(
        b,
        &dir.join("x.mcap"),
        "f64[3]",
        &[("sum", "out")],
        &["a", "b", "sum"],
        2,
    );
    assert_eq!(got[0], ["[1.5,2.5,0.0]", "[1.5,2.5,0.0]"]);
}

#[test]
fn vectors_of_different_lengths_publish_nothing_and_do_not_panic() {
    let dir = scratch("add_vectors");
    let r = registry();
    let mut b = Builder::new(&r);
    let vec_out = out("[f64]", 2);
    add(
        &mut b,
        "c",
        "ferroc_std.Const",
        &[("values", "[[1, 2], [1, 2, 3]]")],
        &vec_out,
    )
    .unwrap();
    let ins = [PortGroup::new("in", Direction::In, "[f64]", Some(2))];
    add(&mut b, "bad", "ferroc_std.Sum", &[], &ins).unwrap();
    add(&mut b, "good", "ferroc_std.Sum", &[], &ins).unwrap();
    let wires = [
        ("bad", "in/0", "out/0"),
        ("bad", "in/1", "out/1"),
        ("good", "in/0", "out/1"),
        ("good", "in/1", "out/1"),
    ];
    for (sum, input, output) in wires {
        b.connect(
            ("c", output),
            (sum, input),
            Default::default(),
            ConnectOptions::default(),
        )
        .unwrap();
    }
    let got = run(
        b,
        &dir.join("x.mcap"),
        "[f64]",
        &[("bad", "out"), ("good", "out")],
        &["c", "bad", "good"],
        3,
    );
    assert!(got[0].is_empty(), "{got:?}");
    assert_eq!(got[1], ["[2.0,4.0,6.0]", "[2.0,4.0,6.0]", "[2.0,4.0,6.0]"]);
}

#[test]
fn const_publishes_once_every_period_or_always() {
    let dir = scratch("const_when");
    let r = registry();
    let mut b = Builder::new(&r);
    let scalar = out("f64", 1);
    add(
        &mut b,
        "once",
        "ferroc_std.Const",
        &[("values", "[1]"), ("publish", "once")],
        &scalar,
    )
    .unwrap();
    let p = [("values", "[2]"), ("publish", "period")];
    b.add_module(ModuleSpec {
        path: "periodic",
        type_name: "ferroc_std.Const",
        params: &[
            ("values".into(), Value::Text(p[0].1.into())),
            ("publish".into(), Value::Text(p[1].1.into())),
            ("period".into(), Value::Duration(Duration::from_millis(20))),
        ],
        queues: &[],
        ports: &scalar,
        violations: ViolationPolicy::Warn,
    })
    .unwrap();
    add(
        &mut b,
        "always",
        "ferroc_std.Const",
        &[("values", "[3.5]")],
        &scalar,
    )
    .unwrap();
    let got = run(
        b,
        &dir.join("x.mcap"),
        "f64",
        &[
            ("once", "out/0"),
            ("periodic", "out/0"),
            ("always", "out/0"),
        ],
        &["once", "periodic", "always"],
        6,
    );
    assert_eq!(got[0], ["1.0"]);
    assert_eq!(got[1], ["2.0", "2.0", "2.0"]);
    assert_eq!(got[2].len(), 6);
}

#[test]
fn values_that_do_not_fit_are_refused_naming_the_output() {
    let r = registry();
    let mut b = Builder::new(&r);
    let e = add(
        &mut b,
        "c",
        "ferroc_std.Const",
        &[("values", "[[1, 2]]")],
        &out("f64[3]", 1),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("output `out/0`: [1,2] is not a f64[3] value"),
        "{e}"
    );
    let e = add(
        &mut b,
        "d",
        "ferroc_std.Const",
        &[("values", "1.5")],
        &out("f64", 1),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("write a JSON array"), "{e}");
    let e = add(
        &mut b,
        "e",
        "ferroc_std.Const",
        &[("values", "[1, 2]")],
        &out("f64", 1),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("2 value(s) for 1 output(s)"), "{e}");
    let e = add(
        &mut b,
        "s",
        "ferroc_std.Sum",
        &[],
        &[PortGroup::new("in", Direction::In, "string", Some(2))],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("Sum adds numbers, vectors or arrays"), "{e}");
}

/// Two inputs into one f64[3]: `a` every step, `b` once; element 2 is not mapped.
fn filter_run(unmapped: &str, dir: &Path) -> Vec<String> {
    let r = registry();
    let mut b = Builder::new(&r);
    add(
        &mut b,
        "a",
        "ferroc_std.Const",
        &[("values", "[1.5]")],
        &out("f64", 1),
    )
    .unwrap();
    let once = [("values", "[7]"), ("publish", "once")];
    add(&mut b, "b", "ferroc_std.Const", &once, &out("f64", 1)).unwrap();
    let ports = [
        PortGroup::new("in", Direction::In, "f64", Some(2)),
        PortGroup::new("out", Direction::Out, "f64[3]", None),
    ];
    let params = [
        ("map", "in/0 -> out[0] * 2 + 1; in/1 -> out[1]"),
        ("unmapped", unmapped),
    ];
    add(&mut b, "f", "ferroc_std.Filter", &params, &ports).unwrap();
    for (k, from) in ["a", "b"].iter().enumerate() {
        b.connect(
            (from, "out/0"),
            ("f", &format!("in/{k}")),
            Default::default(),
            ConnectOptions::default(),
        )
        .unwrap();
    }
    let got = run(
        b,
        &dir.join(format!("{unmapped}.mcap")),
        "f64[3]",
        &[("f", "out")],
        &["a", "b", "f"],
        3,
    );
    got[0].clone()
}

#[test]
fn filter_maps_scales_and_keeps_or_resets_elements_without_new_values() {
    let dir = scratch("filter_keep_reset");
    assert_eq!(filter_run("keep", &dir), ["[4.0,7.0,0.0]"; 3]);
    assert_eq!(
        filter_run("reset", &dir),
        ["[4.0,7.0,0.0]", "[4.0,0.0,0.0]", "[4.0,0.0,0.0]"]
    );
}

#[test]
fn a_filter_map_that_does_not_fit_is_refused_at_creation() {
    let r = registry();
    let mut b = Builder::new(&r);
    let ports = [
        PortGroup::new("in", Direction::In, "f64", Some(1)),
        PortGroup::new("out", Direction::Out, "i32", None),
    ];
    let e = add(
        &mut b,
        "f",
        "ferroc_std.Filter",
        &[("map", "in/0 -> out")],
        &ports,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("converting `f64` to `i32` can lose data"), "{e}");
    assert!(e.contains("help: add `as i32`"), "{e}");
    let e = add(
        &mut b,
        "g",
        "ferroc_std.Filter",
        &[("map", "in/0 => out")],
        &ports,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("INPUT -> OUTPUT"), "{e}");
}
