use super::*;
use crate::builder::{BuildError, Builder, ModuleSpec, Registry};
use crate::module::{Direction, Module, ModuleType, PortGroup, Setup};
use crate::port::ConnectOptions;
use std::fmt::Write;

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

/// A library struct on the pooled path, printed by `Debug`.
#[derive(Clone, Debug, Default, PartialEq)]
struct Report {
    robot: u32,
    note: String,
}
crate::port_value!(Report, "test.Report", pooled);

/// The module under test: one flexible input group forwarded to a same-typed output.
struct First {
    inputs: Vec<DynIn>,
    out: DynOut,
}
impl Module for First {
    fn update(&mut self) {
        if let Some(first) = self.inputs.first() {
            self.out.forward(first);
        }
    }
}
impl ModuleType for First {
    const NAME: &'static str = "test.First";
    fn create(m: &mut Setup<'_>) -> Self {
        let inputs = m.flexible_inputs("in").same_type().min_count(1).build_dyn();
        First {
            inputs,
            out: m.output_like("out", "in"),
        }
    }
}

fn registry() -> Registry {
    let mut r = Registry::new();
    r.register::<First>();
    r
}

fn add(b: &mut Builder<'_>, ports: &[PortGroup<'_>]) -> Result<(), BuildError> {
    b.add_module(ModuleSpec {
        path: "robot/first",
        type_name: "test.First",
        params: &[],
        queues: &[],
        ports,
        violations: Default::default(),
    })
}

#[test]
fn the_type_interface_names_the_group_and_the_same_type_output() {
    let i = registry().interface("test.First").unwrap();
    assert_eq!(i.flexible.len(), 1);
    let f = &i.flexible[0];
    assert_eq!(
        (f.group.as_str(), f.dir, f.same_type, f.min_count),
        ("in", Direction::In, true, 1)
    );
    assert_eq!(i.ports.len(), 1, "{:?}", i.ports);
    assert_eq!(i.port("out").unwrap().model_type, "$in");
}

#[test]
fn instance_ports_of_a_registered_library_type_are_created_and_forwarded() {
    let mut r = registry();
    r.register_value::<Report>();
    let mut b = Builder::new(&r);
    let group = [PortGroup::new("in", Direction::In, "test.Report", Some(2))];
    add(&mut b, &group).unwrap();
    let i = b.interface("robot/first").unwrap();
    let names: Vec<_> = i
        .ports
        .iter()
        .map(|p| (p.name.as_str(), p.model_type.as_str()))
        .collect();
    assert_eq!(
        names,
        [
            ("in/0", "test.Report"),
            ("in/1", "test.Report"),
            ("out", "test.Report")
        ]
    );
    assert!(b.input("robot/first", "in/1").is_ok());
    assert!(b.output("robot/first", "out").is_ok());
    // Printing goes through Debug.
    let (out, inp) = wire(r.values(), "test.Report");
    out.typed::<Report>().unwrap().publish(Report {
        robot: 3,
        note: "ok".into(),
    });
    let mut text = String::new();
    inp.write_human(&mut text);
    assert_eq!(text, r#"Report { robot: 3, note: "ok" }"#);
    text.clear();
    inp.write_json(&mut text);
    assert_eq!(text, r#""Report { robot: 3, note: \"ok\" }""#);
}

fn problems(r: &Registry, ports: &[PortGroup<'_>]) -> Vec<String> {
    let mut b = Builder::new(r);
    match add(&mut b, ports) {
        Err(BuildError::Create { path, problems }) => {
            assert_eq!(path, "robot/first");
            problems
        }
        other => panic!("expected a creation error, got {other:?}"),
    }
}

#[test]
fn an_unregistered_type_is_an_error_naming_port_and_type() {
    let r = registry();
    let p = problems(
        &r,
        &[PortGroup::new("in", Direction::In, "test.Report", Some(1))],
    );
    assert_eq!(p.len(), 2, "{p:?}");
    assert!(
        p[0].contains("port `in/0`") && p[0].contains("`test.Report` is not registered"),
        "{p:?}"
    );
    assert!(p[1].contains("port `out`"), "{p:?}");
    let mut b = Builder::new(&r);
    let e = add(
        &mut b,
        &[PortGroup::new("in", Direction::In, "test.Report", None)],
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("`robot/first` could not be created: port `in`:"),
        "{e}"
    );
}

#[test]
fn declarations_the_type_does_not_accept_are_errors() {
    let r = registry();
    let p = problems(&r, &[]);
    assert!(
        p[0].contains("needs between 1 and any number ports, the model declares 0"),
        "{p:?}"
    );
    let p = problems(
        &r,
        &[
            PortGroup::new("in", Direction::In, "f64", Some(1)),
            PortGroup::new("in", Direction::In, "u32", Some(1)),
        ],
    );
    assert!(
        p.iter().any(|x| x.contains("`u32` differs from `f64`")),
        "{p:?}"
    );
    let p = problems(
        &r,
        &[
            PortGroup::new("in", Direction::In, "f64", Some(1)),
            PortGroup::new("extra", Direction::Out, "f64", Some(1)),
        ],
    );
    assert_eq!(
        p,
        ["the type has no flexible port group `extra` (the model declares one)"]
    );
    let p = problems(&r, &[PortGroup::new("in", Direction::Out, "f64", Some(1))]);
    assert!(
        p[0].contains("the model declares it as an output, the type as an input"),
        "{p:?}"
    );
    let p = problems(
        &r,
        &[PortGroup::new("in", Direction::In, "f64", Some(u32::MAX))],
    );
    assert!(p[0].contains("at most 4096 ports"), "{p:?}");
}

/// A type that knows its value type but not the count (`warehouse.FleetManager`).
struct Fleet {
    status: Vec<crate::module::In<u32>>,
    task: Vec<crate::module::Out<f64>>,
}
impl Module for Fleet {
    fn update(&mut self) {
        for (s, t) in self.status.iter().zip(&self.task) {
            t.publish(f64::from(s.get()) * 2.0);
        }
    }
}
impl ModuleType for Fleet {
    const NAME: &'static str = "test.Fleet";
    fn create(m: &mut Setup<'_>) -> Self {
        Fleet {
            status: m.flexible_inputs("status").same_type().max_count(4).build(),
            task: m
                .flexible_outputs("task")
                .same_type()
                .max_count(4)
                .build_outputs(),
        }
    }
}

#[test]
fn typed_flexible_groups_take_the_count_from_the_model() {
    let mut r = Registry::new();
    r.register::<Fleet>();
    let spec = |ports| ModuleSpec {
        path: "fleet",
        type_name: "test.Fleet",
        params: &[],
        queues: &[],
        ports,
        violations: Default::default(),
    };
    let mut b = Builder::new(&r);
    let ports = [
        PortGroup::new("status", Direction::In, "u32", Some(3)),
        PortGroup::new("task", Direction::Out, "f64", Some(3)),
    ];
    b.add_module(spec(&ports)).unwrap();
    assert!(b.input("fleet", "status/2").is_ok());
    assert!(b.output("fleet", "task/2").is_ok());
    assert!(b.input("fleet", "status/3").is_err());
    let i = b.interface("fleet").unwrap();
    assert_eq!(i.flexible.len(), 2);
    assert_eq!(i.flexible[1].dir, Direction::Out);
    // Another model type than the code's, and too many ports, are refused.
    let mut b = Builder::new(&r);
    let bad = [
        PortGroup::new("status", Direction::In, "f64", Some(1)),
        PortGroup::new("task", Direction::Out, "f64", Some(5)),
    ];
    let e = b.add_module(spec(&bad)).unwrap_err().to_string();
    assert!(
        e.contains("port `status/0`: the model declares type `f64`, the module takes `u32`"),
        "{e}"
    );
    assert!(
        e.contains("port group `task` needs between 0 and 4 ports, the model declares 5"),
        "{e}"
    );
}

/// A number-like library type with its own text style.
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::NoUninit)]
#[repr(C)]
struct Meters {
    m: f64,
}
crate::port_value!(Meters, "test.Meters", copy);

struct MetersText;
impl ValueText<Meters> for MetersText {
    fn human(value: &Meters, out: &mut String) {
        let _ = write!(out, "{} m", value.m);
    }
    fn json(value: &Meters, out: &mut String) {
        NumberText::json(&value.m, out)
    }
    fn to_f64(value: &Meters) -> Option<f64> {
        Some(value.m)
    }
    fn from_f64(x: f64) -> Option<Meters> {
        Some(Meters { m: x })
    }
}

#[test]
fn a_library_type_may_bring_its_own_text_and_number_conversion() {
    let mut r = Registry::new();
    r.register_value_with::<Meters, MetersText>();
    let vt = r.values().get("test.Meters").unwrap();
    assert!(vt.is_number() && vt.is_copy());
    assert!(vt.rust().ends_with("Meters"), "{}", vt.rust());
    let (out, inp) = wire(r.values(), "test.Meters");
    assert!(out.publish_f64(2.5));
    let (mut human, mut json) = (String::new(), String::new());
    inp.write_human(&mut human);
    inp.write_json(&mut json);
    assert_eq!((human.as_str(), json.as_str()), ("2.5 m", "2.5"));
    assert_eq!(
        inp.typed::<Meters>().map(|i| i.get()),
        Some(Meters { m: 2.5 })
    );
    let (out2, end) = wire(r.values(), "test.Meters");
    assert!(out2.forward(&inp));
    assert_eq!(end.get_f64(), Some(2.5));
}
