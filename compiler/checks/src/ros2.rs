//! Checks of area R: the model's ROS 2 ends (`<ros2>`, `<ros2-external>`; docs/ros2.md)
//! against ROS 2's message definitions, REP-103's units, ROS 2's name rules and QoS
//! matching. What they share: the shipped message registry, topic ends with their fully
//! qualified names, and the walk that lays a port's type over a message type field by
//! field.

pub mod r101_invalid_ros2_end;
pub mod r102_ros2_type_mismatch;
pub mod r103_ros2_unit_convention;
pub mod r104_invalid_ros2_name;
pub mod r105_topic_type_conflict;
pub mod r106_ros2_qos_incompatible;
pub mod r107_ros2_topic_without_publisher;
pub mod r108_ros2_service_mismatch;
pub mod r109_invalid_ros2_interfaces;
mod team;

use crate::PassContext;
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{PortView, Ros2Node, Ros2Topic, TopicDirection};
use ferroc_model::library::LibrarySet;
use ferroc_ros2::def::{Arity, BaseType, FieldType, Message, Primitive, TypeName};
use ferroc_ros2::Registry;
use ferroc_values::types::Type;
use ferroc_values::units::Unit;

pub(crate) use team::Team;

/// The ROS 2 packages the model knows: the shipped ones (parsed once per process, only
/// when a model names ROS 2) and its own (`<ros2-interfaces>`, parsed once per check).
pub(crate) fn registry<'c>(ctx: &'c PassContext<'_>) -> &'c Registry {
    if ctx.app.ros2.interfaces.is_empty() {
        return Registry::shipped_shared();
    }
    &ctx.ros2_team().registry
}

/// A topic end whose name ROS 2 accepts, with its fully qualified name.
pub(crate) struct TopicEnd<'a> {
    pub node: &'a Ros2Node,
    pub topic: &'a Ros2Topic,
    pub full: String,
}

/// Every topic end of the model and of the external nodes whose name expands (R104
/// reports the others).
pub(crate) fn topic_ends<'a>(ctx: &PassContext<'a>) -> Vec<TopicEnd<'a>> {
    let mut ends = Vec::new();
    for node in &ctx.app.ros2.nodes {
        for topic in &node.topics {
            if let Ok(full) = ferroc_ros2::names::expand_topic_name(
                &topic.topic.0,
                &node.name.0,
                node.namespace(),
            ) {
                ends.push(TopicEnd { node, topic, full });
            }
        }
    }
    ends
}

/// What `type=` and `field=` of a topic end designate: a whole message or one field.
pub(crate) enum Target<'r> {
    Message(&'r Message),
    Field {
        ty: &'r FieldType,
        /// The REP-103 unit of the field, if one applies.
        unit: Option<&'static str>,
    },
}

/// The message type a topic end names and the part of it `field=` selects, or why not
/// (with the span of the attribute at fault).
pub(crate) fn target<'r>(
    reg: &'r Registry,
    topic: &Ros2Topic,
) -> Result<Target<'r>, (Span, String)> {
    let (text, ty_span) = &topic.ty;
    let name = TypeName::parse(text)
        .filter(|n| n.kind == "msg")
        .ok_or_else(|| {
            (
                *ty_span,
                format!("`{text}` is not a message type name (`package/msg/Name`)"),
            )
        })?;
    let mut msg = reg
        .message(&name)
        .ok_or_else(|| (*ty_span, format!("no message type `{text}` is known")))?;
    let Some((field, field_span)) = &topic.field else {
        return Ok(Target::Message(msg));
    };
    let field_error = |why: String| (*field_span, why);
    let mut unit = None;
    let mut segments = field.split('.').peekable();
    while let Some(seg) = segments.next() {
        let f = msg.fields.iter().find(|f| f.name == seg).ok_or_else(|| {
            let names: Vec<&str> = msg.fields.iter().map(|f| f.name.as_str()).collect();
            field_error(format!(
                "`{}` has no field `{seg}` (it has {})",
                msg.name,
                names.join(", ")
            ))
        })?;
        unit = ferroc_ros2::units::convention(&msg.name.to_string(), seg).or(unit);
        if segments.peek().is_none() {
            return Ok(Target::Field { ty: &f.ty, unit });
        }
        match (&f.ty.base, f.ty.arity) {
            (BaseType::Nested(n), Arity::Single) => {
                msg = reg
                    .message(n)
                    .ok_or_else(|| field_error(format!("no message type `{n}` is known")))?;
            }
            _ => {
                return Err(field_error(format!(
                    "field `{seg}` of `{}` has no fields",
                    msg.name
                )))
            }
        }
    }
    unreachable!("split yields at least one segment")
}

/// A topic of one of the model's own nodes whose port is bound and whose message type is
/// known, with the port's type laid over the message: what R102 (types) and R103
/// (units) each judge.
pub(crate) struct Walked<'a> {
    pub topic: &'a Ros2Topic,
    /// The port's place in the `<publish>`/`<subscribe>` element.
    pub span: Span,
    pub port: PortView<'a>,
    pub found: Vec<Found>,
}

/// Every bound topic of the model's own nodes, walked.
pub(crate) fn walked_topics<'a>(ctx: &PassContext<'a>) -> Vec<Walked<'a>> {
    let reg = registry(ctx);
    let mut out = Vec::new();
    for node in ctx.app.ros2.nodes.iter().filter(|n| !n.is_external()) {
        for topic in &node.topics {
            let (Some((ep, span)), Ok(target)) = (&topic.port, target(reg, topic)) else {
                continue;
            };
            let Some(port) = ctx.app.view(ctx.libraries, *ep) else {
                continue;
            };
            let mut walk = Walk::new(ctx, topic.direction);
            walk.mapped = true;
            walk.target(port.ty, port.unit, &target);
            out.push(Walked {
                topic,
                span: *span,
                port,
                found: walk.found,
            });
        }
    }
    out
}

/// What the walk over a port's type and a message type finds.
pub(crate) enum Found {
    /// The types disagree at `path`.
    Mismatch { path: String, why: String },
    /// A numeric leaf: the port's unit there and the unit REP-103 fixes.
    Leaf {
        path: String,
        unit: Option<Unit>,
        expected: Option<&'static str>,
    },
}

/// Lays a port's type over a message type field by field.
pub(crate) struct Walk<'a> {
    pub libs: &'a LibrarySet,
    pub reg: &'a Registry,
    /// Publishing (the port writes the message) or subscribing (it reads it).
    pub publish: bool,
    /// A type its library maps to a message (`<type ros2=…>`) may be that whole
    /// message: a topic's, not a field of it nor a service's request or response
    /// (only a topic's end writes and reads through the type's mapping).
    pub mapped: bool,
    pub found: Vec<Found>,
}

impl Walk<'_> {
    pub(crate) fn new<'c>(ctx: &'c PassContext<'_>, dir: TopicDirection) -> Walk<'c> {
        Walk {
            libs: ctx.libraries,
            reg: registry(ctx),
            publish: dir == TopicDirection::Publish,
            mapped: false,
            found: Vec::new(),
        }
    }

    fn mismatch(&mut self, path: &str, why: String) {
        self.found.push(Found::Mismatch {
            path: path.to_string(),
            why,
        });
    }

    pub(crate) fn target(&mut self, port: &Type, unit: Option<&Unit>, target: &Target<'_>) {
        match target {
            Target::Message(m) => self.message(port, unit, m, None, ""),
            Target::Field { ty, unit: expected } => {
                self.mapped = false;
                self.field(port, unit, ty, *expected, "")
            }
        }
    }

    fn message(
        &mut self,
        port: &Type,
        unit: Option<&Unit>,
        m: &Message,
        expected: Option<&'static str>,
        path: &str,
    ) {
        let full = m.name.to_string();
        match (port, full.as_str()) {
            (Type::Timestamp, "builtin_interfaces/msg/Time")
            | (Type::Duration, "builtin_interfaces/msg/Duration") => return,
            _ => {}
        }
        let join = |name: &str| {
            if path.is_empty() {
                name.to_string()
            } else {
                format!("{path}.{name}")
            }
        };
        if let Type::Named(id, qualified) = port {
            let named = self.libs.named_type(*id);
            if let Some(mapped) = &named.ros2 {
                return self.mapped_type(qualified, mapped, &full, path);
            }
            let ours: Vec<&str> = named.fields.iter().map(|(n, _, _)| n.as_str()).collect();
            let theirs: Vec<&str> = m.fields.iter().map(|f| f.name.as_str()).collect();
            if ours != theirs {
                self.mismatch(
                    path,
                    format!(
                        "`{qualified}` has the fields ({}), `{full}` has ({})",
                        ours.join(", "),
                        theirs.join(", ")
                    ),
                );
                return;
            }
            for ((name, ty, u), f) in named.fields.iter().zip(&m.fields) {
                let conv = ferroc_ros2::units::convention(&full, name).or(expected);
                // A field without a unit of its own is in its enclosing one's.
                self.field(ty, u.as_ref().or(unit), &f.ty, conv, &join(name));
            }
        } else if let [only] = m.fields.as_slice() {
            // A wrapper such as std_msgs/msg/Float64 carries one value.
            let conv = ferroc_ros2::units::convention(&full, &only.name).or(expected);
            self.field(port, unit, &only.ty, conv, &join(&only.name));
        } else {
            let names: Vec<&str> = m.fields.iter().map(|f| f.name.as_str()).collect();
            let fields = match names.is_empty() {
                true => "no fields".to_string(),
                false => format!("fields {}", names.join(", ")),
            };
            self.mismatch(
                path,
                format!("a port of type `{port}` cannot carry the message `{full}` ({fields})"),
            );
        }
    }

    /// A port type its library maps to the message `mapped` (`<type ros2=…>`), laid
    /// over the message `full` at `path`.
    fn mapped_type(&mut self, qualified: &str, mapped: &str, full: &str, path: &str) {
        if mapped != full {
            let why = format!(
                "`{qualified}` is carried as `{mapped}` (its library maps it to that message), not as `{full}`"
            );
            return self.mismatch(path, why);
        }
        if !(self.mapped && path.is_empty()) {
            let why = format!(
                "`{qualified}` is carried as `{mapped}` only as the whole message of a topic, not inside another message, as one field or in a service"
            );
            self.mismatch(path, why);
        }
    }

    fn field(
        &mut self,
        port: &Type,
        unit: Option<&Unit>,
        ft: &FieldType,
        expected: Option<&'static str>,
        path: &str,
    ) {
        let elem = match (ft.arity, port) {
            (Arity::Single, _) => return self.base(port, unit, &ft.base, expected, path),
            (Arity::Fixed(n), Type::Array(t, m)) if *m == n => t,
            (Arity::Bounded(n), Type::Array(t, m)) if *m <= n => t,
            (Arity::Bounded(_), Type::Seq(t)) if !self.publish => t,
            (Arity::Unbounded, Type::Seq(t)) => t,
            (Arity::Unbounded, Type::Array(t, _)) if self.publish => t,
            (arity, _) => {
                let ros = describe(&ft.base, arity);
                let why = match (arity, port) {
                    (Arity::Bounded(n), Type::Seq(_)) => {
                        format!("`{port}` may hold more than the {n} elements of `{ros}`")
                    }
                    (Arity::Unbounded, Type::Array(_, m)) => {
                        format!("a `{ros}` sample may have another length than the {m} of `{port}`")
                    }
                    _ => format!("`{port}` against `{ros}`"),
                };
                return self.mismatch(path, why);
            }
        };
        self.base(elem, unit, &ft.base, expected, path);
    }

    fn base(
        &mut self,
        port: &Type,
        unit: Option<&Unit>,
        base: &BaseType,
        expected: Option<&'static str>,
        path: &str,
    ) {
        match base {
            BaseType::Primitive(p) => {
                if primitive_of(port).is_some_and(|ours| same_primitive(ours, *p)) {
                    if port.is_numeric() {
                        self.found.push(Found::Leaf {
                            path: path.to_string(),
                            unit: unit.cloned(),
                            expected,
                        });
                    }
                } else {
                    self.mismatch(path, format!("`{port}` against `{}`", p.msg_name()));
                }
            }
            BaseType::String { bound } => match (port, bound) {
                (Type::String, None) => {}
                (Type::String, Some(_)) if !self.publish => {}
                _ => self.mismatch(
                    path,
                    format!("`{port}` against `{}`", describe(base, Arity::Single)),
                ),
            },
            BaseType::WString { .. } => {
                self.mismatch(path, "wide strings are not supported".to_string())
            }
            BaseType::Nested(n) => match self.reg.message(n) {
                Some(m) => self.message(port, unit, m, expected, path),
                None => self.mismatch(path, format!("no message type `{n}` is known")),
            },
        }
    }
}

/// The `.msg` primitive a port type is (before `byte`/`char` aliases).
fn primitive_of(t: &Type) -> Option<Primitive> {
    use Primitive::*;
    Some(match t {
        Type::Bool => Bool,
        Type::Float { bits: 32 } => Float32,
        Type::Float { bits: 64 } => Float64,
        Type::Int { signed, bits } => match (signed, bits) {
            (true, 8) => Int8,
            (false, 8) => UInt8,
            (true, 16) => Int16,
            (false, 16) => UInt16,
            (true, 32) => Int32,
            (false, 32) => UInt32,
            (true, 64) => Int64,
            (false, 64) => UInt64,
            _ => return None,
        },
        _ => return None,
    })
}

/// `byte` and `char` are `uint8` on the wire (rosidl's mapping).
fn same_primitive(ours: Primitive, theirs: Primitive) -> bool {
    let norm = |p| match p {
        Primitive::Byte | Primitive::Char => Primitive::UInt8,
        p => p,
    };
    norm(ours) == norm(theirs)
}

/// A field type the `.msg` way: `float64[<=3]`.
pub(crate) fn describe(base: &BaseType, arity: Arity) -> String {
    let b = match base {
        BaseType::Primitive(p) => p.msg_name().to_string(),
        BaseType::String { bound: None } => "string".into(),
        BaseType::String { bound: Some(n) } => format!("string<={n}"),
        BaseType::WString { bound: None } => "wstring".into(),
        BaseType::WString { bound: Some(n) } => format!("wstring<={n}"),
        BaseType::Nested(n) => n.to_string(),
    };
    match arity {
        Arity::Single => b,
        Arity::Fixed(n) => format!("{b}[{n}]"),
        Arity::Bounded(n) => format!("{b}[<={n}]"),
        Arity::Unbounded => format!("{b}[]"),
    }
}
