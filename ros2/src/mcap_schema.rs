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
//! nothing a reader decodes with depends on them. [`registry_of`] reads such a text back
//! (ours or another tool's), to decode a recorded channel's messages.

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

/// The definitions a `ros2msg` schema text holds, read back (a recording another tool
/// wrote, to decode its messages): the text's first block is `name`, each later block
/// the type its `MSG:` line names (`package/msg/Name` or `package/Name`). An error names
/// what does not parse, a type used but not in the text, or a cycle of nested types,
/// with the block's line in the text.
pub fn registry_of(name: &TypeName, text: &str) -> Result<Registry, String> {
    let mut registry = Registry::new();
    let lines: Vec<&str> = text.lines().collect();
    let mut start = 0;
    let mut current = (name.clone(), 1);
    let mut k = 0;
    while k <= lines.len() {
        let separator = lines.get(k).is_some_and(|l| is_separator(l));
        if k < lines.len() && !separator {
            k += 1;
            continue;
        }
        let block = lines[start..k].join("\n");
        let (ty, first_line) = &current;
        registry
            .add_text(
                &ty.package,
                "msg",
                &ty.name,
                &block,
                &format!("schema of {name}, block {ty}"),
            )
            .map_err(|e| shifted(&e, first_line - 1))?;
        if !separator {
            break;
        }
        let header = lines.get(k + 1).copied().unwrap_or("");
        let ty = header
            .strip_prefix("MSG: ")
            .map(str::trim)
            .and_then(block_type)
            .ok_or_else(|| {
                format!(
                    "line {} of the schema of {name}: `MSG: package/msg/Name` expected after \
                     the line of `=`, found `{header}`",
                    k + 2
                )
            })?;
        current = (ty, k + 3);
        start = k + 2;
        k = start;
    }
    match registry.check().first() {
        Some(e) => Err(e.to_string()),
        None => Ok(registry),
    }
}

/// The messages of a recorded ROS 2 channel as JSON, read with the definitions its
/// schema text holds ([`registry_of`]), not the program's: `ferroc log cat` prints any
/// tool's recording with it.
pub struct Decoder {
    registry: Registry,
    ty: TypeName,
}

impl Decoder {
    /// The decoder of the channel whose schema is named `name` and holds `text`.
    pub fn new(name: &str, text: &str) -> Result<Decoder, String> {
        let ty = block_type(name)
            .ok_or_else(|| format!("`{name}` is not a ROS 2 message type (package/msg/Name)"))?;
        Ok(Decoder {
            registry: registry_of(&ty, text)?,
            ty,
        })
    }

    /// One message as JSON (fields by name); hostile bytes are an error.
    pub fn json(&self, cdr: &[u8]) -> Result<serde_json::Value, String> {
        let value = crate::cdr::decode(&self.registry, &self.ty, cdr).map_err(|e| e.to_string())?;
        crate::json::to_json(&self.registry, &self.ty, None, &value)
    }
}

/// A line of `=` only (80 of them as written; readers accept any run of them).
fn is_separator(line: &str) -> bool {
    let line = line.trim_end();
    line.len() >= 3 && line.bytes().all(|b| b == b'=')
}

/// `package/msg/Name` or `package/Name` as a message type.
fn block_type(text: &str) -> Option<TypeName> {
    TypeName::parse(text)
        .filter(|t| t.kind == "msg")
        .or_else(|| match text.split('/').collect::<Vec<_>>()[..] {
            [package, name] if !package.is_empty() && !name.is_empty() => {
                Some(TypeName::new(package, "msg", name))
            }
            _ => None,
        })
}

/// `e` with its line counted from the start of the whole text.
fn shifted(e: &crate::DefinitionError, before: usize) -> String {
    format!(
        "{}:{}:{}: {} (help: {})",
        e.file,
        e.line + before,
        e.col,
        e.message,
        e.help
    )
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
    fn every_shipped_message_s_text_reads_back_to_the_same_type_hash() {
        let shipped = Registry::shipped_shared();
        for m in shipped.messages().filter(|m| m.name.kind == "msg") {
            let text = schema_text(shipped, &m.name).unwrap();
            let read = registry_of(&m.name, &text).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(
                crate::hash::rihs01(&read, &m.name),
                crate::hash::rihs01(shipped, &m.name),
                "{}",
                m.name
            );
        }
    }

    #[test]
    fn a_foreign_text_with_short_names_reads_and_a_broken_one_is_an_error_with_its_line() {
        let name = TypeName::parse("team/msg/Pair").unwrap();
        let text =
            "# two points\nPoint a\ngeometry_msgs/Point b\n=====\nMSG: team/Point\nint32 x\n\
                    ==========\nMSG: geometry_msgs/msg/Point\nfloat64 x\n";
        let reg = registry_of(&name, text).unwrap();
        assert_eq!(reg.message(&name).unwrap().fields.len(), 2);
        let bad = "int32 x\n=====\nMSG: team/Point\nint32 y\nfloat65 z\n";
        let err = registry_of(&name, bad).unwrap_err();
        assert!(err.contains(":5:"), "the line in the whole text: {err}");
        let no_msg = registry_of(&name, "int32 x\n=====\nPoint\n").unwrap_err();
        assert!(no_msg.contains("line 3"), "{no_msg}");
        let missing = registry_of(&name, "Point a\n").unwrap_err();
        assert!(missing.contains("team/msg/Point"), "{missing}");
        let cycle = "Loop a\n=====\nMSG: team/Loop\nPair p\n";
        assert!(registry_of(&name, cycle).unwrap_err().contains("cycle"));
    }

    #[test]
    fn a_decoder_reads_a_sample_with_the_text_s_definitions_and_refuses_a_short_one() {
        let name = TypeName::parse("geometry_msgs/msg/Vector3").unwrap();
        let decoder = Decoder::new("geometry_msgs/msg/Vector3", &text(&name.to_string())).unwrap();
        let mut cdr = vec![0, 1, 0, 0];
        for x in [1.5f64, -2.0, 0.25] {
            cdr.extend(x.to_le_bytes());
        }
        assert_eq!(
            decoder.json(&cdr).unwrap(),
            serde_json::json!({"x": 1.5, "y": -2.0, "z": 0.25})
        );
        assert!(decoder.json(&cdr[..10]).is_err());
        assert!(Decoder::new("Vector3", "float64 x\n").is_err());
    }

    #[test]
    fn an_unknown_type_is_an_error_naming_it() {
        let err = schema_text(&Registry::new(), &TypeName::parse("a/msg/B").unwrap());
        assert_eq!(err.unwrap_err(), "unknown message type `a/msg/B`");
    }
}
