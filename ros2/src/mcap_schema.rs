//! A message type's schema as MCAP's `ros2msg` schema encoding holds it (the `ros2`
//! profile of the MCAP specification; rosbag2's "complete message definition"): the
//! type's own `.msg` definition first, then every type it uses, directly or deeper,
//! once each, each after a line of exactly 80 `=` and a line `MSG: package/msg/Name`.
//! ROS 2 tools, Foxglove and Python `rosbags` read a recorded channel's `cdr` messages
//! with it.
//!
//! The text is written from the parsed definition (the registry keeps no file text):
//! constants first (`TYPE NAME=VALUE`), then the fields in order (`TYPE NAME [DEFAULT]`),
//! nested types as `package/Name`, as `.msg` files write them. Comments are not kept;
//! nothing a reader decodes with depends on them.

use crate::def::{Arity, BaseType, Constant, Field, Message, TypeName};
use crate::Registry;
use std::collections::BTreeSet;
use std::fmt::Write;

/// The schema encoding of these texts.
pub const SCHEMA_ENCODING: &str = "ros2msg";

/// The message encoding of channels whose schema is one of these texts.
pub const MESSAGE_ENCODING: &str = "cdr";

/// The line before each dependency's `MSG:` line.
const SEPARATOR: &str =
    "================================================================================";

/// The `ros2msg` schema text of the message `name` with every type it depends on; an
/// error naming the first type the registry does not know.
pub fn schema_text(registry: &Registry, name: &TypeName) -> Result<String, String> {
    let mut out = String::new();
    let mut seen = BTreeSet::from([name.clone()]);
    let mut todo = vec![name.clone()];
    let mut first = true;
    // Depth first, in field order: a dependency follows the first type that uses it.
    while let Some(next) = todo.pop() {
        let message = registry
            .message(&next)
            .ok_or_else(|| format!("unknown message type `{next}`"))?;
        if !first {
            let _ = write!(out, "{SEPARATOR}\nMSG: {next}\n");
        }
        first = false;
        definition(&mut out, message);
        let nested: Vec<TypeName> = (message.fields.iter())
            .filter_map(|f| match &f.ty.base {
                BaseType::Nested(n) => Some(n.clone()),
                _ => None,
            })
            .filter(|n| seen.insert(n.clone()))
            .collect();
        todo.extend(nested.into_iter().rev());
    }
    Ok(out)
}

/// One message's `.msg` text.
fn definition(out: &mut String, message: &Message) {
    for c in &message.constants {
        constant(out, c);
    }
    for f in &message.fields {
        field(out, f);
    }
}

fn constant(out: &mut String, c: &Constant) {
    let _ = writeln!(out, "{} {}={}", base(&c.ty), c.name, c.value);
}

fn field(out: &mut String, f: &Field) {
    let arity = match f.ty.arity {
        Arity::Single => String::new(),
        Arity::Fixed(n) => format!("[{n}]"),
        Arity::Bounded(n) => format!("[<={n}]"),
        Arity::Unbounded => "[]".to_owned(),
    };
    let _ = write!(out, "{}{arity} {}", base(&f.ty.base), f.name);
    if let Some(default) = &f.default {
        let _ = write!(out, " {default}");
    }
    out.push('\n');
}

/// A base type as a `.msg` file writes it.
fn base(ty: &BaseType) -> String {
    let bounded = |name: &str, bound: &Option<u32>| match bound {
        Some(n) => format!("{name}<={n}"),
        None => name.to_owned(),
    };
    match ty {
        BaseType::Primitive(p) => p.msg_name().to_owned(),
        BaseType::String { bound } => bounded("string", bound),
        BaseType::WString { bound } => bounded("wstring", bound),
        BaseType::Nested(n) => format!("{}/{}", n.package, n.name),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(name: &str) -> String {
        schema_text(Registry::shipped_shared(), &TypeName::parse(name).unwrap()).unwrap()
    }

    #[test]
    fn a_message_without_nested_types_is_its_definition_alone() {
        assert_eq!(
            text("geometry_msgs/msg/Vector3"),
            "float64 x\nfloat64 y\nfloat64 z\n"
        );
    }

    #[test]
    fn every_dependency_follows_once_after_its_separator() {
        let odom = text("nav_msgs/msg/Odometry");
        let blocks: Vec<&str> = odom.split(&format!("{SEPARATOR}\n")).collect();
        assert!(blocks[0].starts_with("std_msgs/Header header\nstring child_frame_id\n"));
        let names: Vec<&str> = blocks[1..]
            .iter()
            .map(|b| b.lines().next().unwrap())
            .collect();
        assert_eq!(
            names,
            [
                "MSG: std_msgs/msg/Header",
                "MSG: builtin_interfaces/msg/Time",
                "MSG: geometry_msgs/msg/PoseWithCovariance",
                "MSG: geometry_msgs/msg/Pose",
                "MSG: geometry_msgs/msg/Point",
                "MSG: geometry_msgs/msg/Quaternion",
                "MSG: geometry_msgs/msg/TwistWithCovariance",
                "MSG: geometry_msgs/msg/Twist",
                "MSG: geometry_msgs/msg/Vector3",
            ],
            "depth first, each type once (Vector3 serves linear and angular)"
        );
        assert!(odom.contains("float64[36] covariance\n"));
        assert_eq!(SEPARATOR.len(), 80);
    }

    #[test]
    fn constants_defaults_bounds_and_arrays_are_written_as_msg_files_write_them() {
        let status = text("sensor_msgs/msg/NavSatStatus");
        assert!(status.contains("int8 STATUS_NO_FIX=-1\n"), "{status}");
        assert!(status.contains("uint16 SERVICE_GPS=1\n"), "{status}");
        let mut reg = Registry::new();
        reg.add_text(
            "team",
            "msg",
            "Sample",
            "string<=8 name \"robot\"\nint32[<=4] ids\nuint8[] data\nfloat32 x 1.5\n",
            "Sample.msg",
        )
        .unwrap();
        let sample = schema_text(&reg, &TypeName::parse("team/msg/Sample").unwrap()).unwrap();
        assert_eq!(
            sample,
            "string<=8 name \"robot\"\nint32[<=4] ids\nuint8[] data\nfloat32 x 1.5\n"
        );
    }

    #[test]
    fn an_unknown_type_is_an_error_naming_it() {
        let err = schema_text(&Registry::new(), &TypeName::parse("a/msg/B").unwrap());
        assert_eq!(err.unwrap_err(), "unknown message type `a/msg/B`");
    }
}
