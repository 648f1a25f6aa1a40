//! The flexible `ferroc_std` modules built and run as `ferroc run` builds them: the
//! instance's `<port>` declarations arrive as `ModuleSpec::ports`.

mod common;

use common::{add as try_add, registry, run_free, scratch, wire};
use ferroc_runtime::builder::Builder;
use ferroc_runtime::module::{Direction, PortGroup, Value};
use ferroc_runtime::port::{ConnectOptions, CopyInputPort, InputPort};
use std::time::Duration;

fn run(b: Builder<'_>, order: &[&str], cycles: u64) {
    let app = run_free(b, order, Duration::from_micros(500), cycles);
    assert!(app.panics().is_empty(), "{:?}", app.panics());
}

fn constant(b: &mut Builder<'_>, path: &str, value: f64) {
    try_add(
        b,
        path,
        "ferroc_std.Constant",
        &[("value", Value::Float(value))],
        &[],
    )
    .unwrap();
}

fn inputs<'a>(ty: &'a str, n: u32) -> [PortGroup<'a>; 1] {
    [PortGroup::new("in", Direction::In, ty, Some(n))]
}

#[test]
fn sum_of_u32_inputs_fed_by_f64_constants() {
    let r = registry();
    let mut b = Builder::new(&r);
    constant(&mut b, "a", 2.0);
    constant(&mut b, "c", 40.0);
    try_add(&mut b, "sum", "ferroc_std.Sum", &[], &inputs("u32", 2)).unwrap();
    assert_eq!(
        b.interface("sum").unwrap().port("out").unwrap().model_type,
        "u32"
    );
    // f64 → u32: the Builder converts on the connection.
    wire(&mut b, ("a", "value"), ("sum", "in/0"));
    wire(&mut b, ("c", "value"), ("sum", "in/1"));
    let probe = CopyInputPort::<u32>::new("probe");
    b.output("sum", "out")
        .unwrap()
        .connect(&probe.handle(), ConnectOptions::default())
        .unwrap();
    run(b, &["a", "c", "sum"], 3);
    assert_eq!(probe.get(), 42);
}

#[test]
fn flexiselect_clamps_the_selection_and_reports_the_index() {
    let r = registry();
    let mut b = Builder::new(&r);
    for (k, v) in [1.5, 2.5, 3.5].into_iter().enumerate() {
        constant(&mut b, &format!("c{k}"), v);
    }
    constant(&mut b, "choice", 7.0);
    try_add(
        &mut b,
        "sel",
        "ferroc_std.FlexiSelect",
        &[],
        &inputs("f64", 3),
    )
    .unwrap();
    for k in 0..3 {
        wire(
            &mut b,
            (&format!("c{k}"), "value"),
            ("sel", &format!("in/{k}")),
        );
    }
    wire(&mut b, ("choice", "value"), ("sel", "select"));
    let out = CopyInputPort::<f64>::new("out");
    let index = CopyInputPort::<u32>::new("index");
    b.output("sel", "out")
        .unwrap()
        .connect(&out.handle(), ConnectOptions::default())
        .unwrap();
    b.output("sel", "index")
        .unwrap()
        .connect(&index.handle(), ConnectOptions::default())
        .unwrap();
    run(b, &["c0", "c1", "c2", "choice", "sel"], 3);
    assert_eq!((out.get(), index.get()), (3.5, 2));
}

#[test]
fn flexiselect_forwards_a_pooled_string() {
    let r = registry();
    let mut b = Builder::new(&r);
    try_add(
        &mut b,
        "sel",
        "ferroc_std.FlexiSelect",
        &[],
        &inputs("string", 2),
    )
    .unwrap();
    let out = InputPort::<String>::new("out");
    b.output("sel", "out")
        .unwrap()
        .connect(&out.handle(), ConnectOptions::default())
        .unwrap();
    let feed = ferroc_runtime::port::OutputPort::<String>::new("feed");
    feed.handle()
        .connect(b.input("sel", "in/0").unwrap(), ConnectOptions::default())
        .unwrap();
    feed.publish("hello".to_owned());
    run(b, &["sel"], 2);
    assert_eq!(*out.get(), "hello");
}

#[test]
fn clock_counts_cycles_and_tells_the_time() {
    let r = registry();
    let mut b = Builder::new(&r);
    try_add(&mut b, "clock", "ferroc_std.Clock", &[], &[]).unwrap();
    let tick = CopyInputPort::<u64>::new("tick");
    let time = CopyInputPort::<ferroc_runtime::module::Timestamp>::new("time");
    b.output("clock", "tick")
        .unwrap()
        .connect(&tick.handle(), ConnectOptions::default())
        .unwrap();
    b.output("clock", "time")
        .unwrap()
        .connect(&time.handle(), ConnectOptions::default())
        .unwrap();
    let before = ferroc_runtime::module::Timestamp::now();
    run(b, &["clock"], 5);
    assert_eq!(tick.get(), 5);
    assert!(time.get() >= before && time.get() <= ferroc_runtime::module::Timestamp::now());
}

fn logger_problem(file: &str) -> String {
    let r = registry();
    let mut b = Builder::new(&r);
    let ports = [PortGroup::new("in", Direction::In, "f64", Some(1))];
    match try_add(
        &mut b,
        "fleet/log",
        "ferroc_std.Logger",
        &[("file", Value::Text(file.into()))],
        &ports,
    ) {
        Err(e) => e.to_string(),
        Ok(()) => panic!("`{file}` was accepted"),
    }
}

#[test]
fn logger_refuses_hostile_paths_at_creation() {
    let dir = scratch("logger_paths");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let d = dir.to_string_lossy().into_owned();
    let cases = [
        (String::new(), "is empty"),
        (format!("{d}/../escape.log"), "climbs out of a folder"),
        (format!("{d}/sub/../x.log"), "climbs out of a folder"),
        (format!("{d}/sub"), "a folder"),
        (format!("{d}/sub/"), "names a folder"),
        (format!("{d}/bell\u{7}.log"), "control characters"),
    ];
    for (file, why) in cases {
        let e = logger_problem(&file);
        assert!(
            e.starts_with("`fleet/log` could not be created: parameter `file`: "),
            "{e}"
        );
        assert!(e.contains(why), "{file}: {e}");
    }
    #[cfg(unix)]
    {
        let link = dir.join("link.log");
        std::os::unix::fs::symlink("/etc/passwd", &link).unwrap();
        let e = logger_problem(&link.to_string_lossy());
        assert!(e.contains("a symbolic link"), "{e}");
        assert!(logger_problem("/dev/null").contains("a special file"));
    }
    // A missing required file parameter is an error too, not a panic.
    let r = registry();
    let mut b = Builder::new(&r);
    let ports = [PortGroup::new("in", Direction::In, "f64", Some(1))];
    let e = try_add(&mut b, "log", "ferroc_std.Logger", &[], &ports).unwrap_err();
    assert!(
        e.to_string().contains("parameter `file` has no value"),
        "{e}"
    );
}

#[test]
fn sum_of_strings_and_unknown_types_are_refused() {
    let r = registry();
    let mut b = Builder::new(&r);
    let e = try_add(&mut b, "sum", "ferroc_std.Sum", &[], &inputs("string", 2)).unwrap_err();
    assert!(
        e.to_string().contains(
            "Sum adds numbers, vectors or arrays of numbers; its inputs have type `string`"
        ),
        "{e}"
    );
    let e = try_add(
        &mut b,
        "dump",
        "ferroc_std.Dump",
        &[],
        &inputs("warehouse.RobotStatus", 1),
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "`dump` could not be created: port `in/0`: the value type `warehouse.RobotStatus` is not \
         registered in this binary (its library registers it with `registry.register_value::<T>()`)"
    );
}
