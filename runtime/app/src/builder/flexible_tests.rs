//! Flexible modules and library value types through the Builder (moved here from
//! `ferroc_module`'s value-table tests, which cannot build an application).

use crate::builder::{BuildError, Builder, ModuleSpec, Registry};
use ferroc_module::{
    Direction, DynIn, DynOut, Module, ModuleType, NumberText, PortGroup, Setup, ValueTable,
    ValueText,
};
use ferroc_ports::port::ConnectOptions;
use std::fmt::Write;

/// A wire between a fresh output of `ty` and a fresh input of `ty`.
fn wire(t: &ValueTable, ty: &str) -> (DynOut, DynIn) {
    let vt = t.get(ty).unwrap();
    let (out, oh) = vt.output("out");
    let (inp, ih) = vt.input("in", None);
    oh.connect(&ih, ConnectOptions::default()).unwrap();
    (out, inp)
}

/// A library struct on the pooled path, printed by `Debug`.
#[derive(Clone, Debug, Default, PartialEq)]
struct Report {
    robot: u32,
    note: String,
}
ferroc_module::port_value!(Report, "test.Report", pooled);

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
    status: Vec<ferroc_module::In<u32>>,
    task: Vec<ferroc_module::Out<f64>>,
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
ferroc_module::port_value!(Meters, "test.Meters", copy);

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
