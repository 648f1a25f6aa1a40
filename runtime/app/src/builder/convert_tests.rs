//! Connections that take values apart: `<convert field>` and `<convert index>`.

use super::tests::add;
use super::*;
use ferroc_module::{In, ModuleType, Out};
use ferroc_ports::port::{ConnectOptions, CopyInputPort};

/// A small padding-free struct, as library crates declare them.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::NoUninit)]
struct Twist {
    linear: f64,
    angular: f64,
}
ferroc_module::port_value!(Twist, "test.Twist", copy);

/// Publishes twist n = (n, -n) and the list [n, 2n, 3n] on cycle n.
struct Source {
    twist: Out<Twist>,
    list: Out<Vec<f64>>,
    n: f64,
}
impl Module for Source {
    fn update(&mut self) {
        self.n += 1.0;
        let n = self.n;
        self.twist.publish(Twist {
            linear: n,
            angular: -n,
        });
        self.list.publish_with(|l| {
            l.clear();
            l.extend([n, 2.0 * n, 3.0 * n]);
        });
    }
}
impl ModuleType for Source {
    const NAME: &'static str = "test.Source";
    fn create(m: &mut Setup<'_>) -> Self {
        Source {
            twist: m.output("twist").build(),
            list: m.output("list").build(),
            n: 0.0,
        }
    }
}

/// Forwards what it reads, so a probe can see what the connection delivered.
struct Relay {
    input: In<f64>,
    output: Out<f64>,
}
impl Module for Relay {
    fn update(&mut self) {
        self.output.publish(self.input.get());
    }
}
impl ModuleType for Relay {
    const NAME: &'static str = "test.Relay";
    fn create(m: &mut Setup<'_>) -> Self {
        Relay {
            input: m.input("input").build(),
            output: m.output("output").build(),
        }
    }
}

fn registry(with_fields: bool) -> Registry {
    let mut r = Registry::new();
    r.register::<Source>().register::<Relay>();
    if with_fields {
        r.register_field::<Twist, f64>("linear", |t| t.linear)
            .register_field::<Twist, f64>("angular", |t| t.angular);
    }
    r
}

/// Runs `source → relay` with `conversion` for three cycles; what the relay saw last.
fn deliver(registry: &Registry, port: &str, conversion: Conversion) -> Result<f64, BuildError> {
    let mut b = Builder::new(registry);
    add(&mut b, "source", "test.Source", &[]);
    add(&mut b, "relay", "test.Relay", &[]);
    b.connect(
        ("source", port),
        ("relay", "input"),
        conversion,
        ConnectOptions::default(),
    )?;
    let probe = CopyInputPort::<f64>::new("probe");
    b.output("relay", "output")?
        .connect(&probe.handle(), ConnectOptions::default())
        .unwrap();
    b.add_thread(ThreadSpec {
        path: "main".into(),
        schedule: Schedule::Periodic(Duration::from_micros(100)),
        options: ThreadOptions::default(),
        steps: vec![
            ("source".into(), StepKind::Update),
            ("relay".into(), StepKind::Update),
        ],
    })?;
    let mut app = b.start(Some(3))?;
    app.join();
    Ok(probe.get())
}

#[test]
fn a_field_reaches_the_reader_in_the_same_cycle() {
    let r = registry(true);
    assert_eq!(
        deliver(&r, "twist", Conversion::default().field("linear")),
        Ok(3.0)
    );
    assert_eq!(
        deliver(&r, "twist", Conversion::default().field("angular")),
        Ok(-3.0)
    );
}

#[test]
fn a_field_is_taken_before_the_scale_applies() {
    let r = registry(true);
    let conversion = Conversion::linear(100.0, 1.0).field("angular");
    assert_eq!(deliver(&r, "twist", conversion), Ok(-299.0));
}

#[test]
fn list_elements_are_built_in_and_a_missing_one_reads_as_default() {
    let r = registry(false);
    assert_eq!(deliver(&r, "list", Conversion::default().index(2)), Ok(9.0));
    assert_eq!(deliver(&r, "list", Conversion::default().index(7)), Ok(0.0));
}

#[test]
fn an_unregistered_field_is_refused_with_the_fix() {
    let Err(BuildError::Connect(why)) = deliver(
        &registry(false),
        "twist",
        Conversion::default().field("linear"),
    ) else {
        panic!("an unregistered field must not connect");
    };
    assert!(why.contains("`source/twist` → `relay/input`"), "{why}");
    assert!(why.contains("the field `linear`"), "{why}");
    assert!(why.contains("register_field"), "{why}");
}

#[test]
fn a_struct_without_a_selected_field_does_not_connect_to_a_number() {
    let Err(BuildError::Connect(why)) = deliver(&registry(true), "twist", Conversion::default())
    else {
        panic!("a struct must not connect to an f64 input");
    };
    assert!(why.contains("only numbers are converted"), "{why}");
}
