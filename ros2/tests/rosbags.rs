//! Proof against an implementation we did not write: Python `rosbags` (PyPI) reads our
//! shipped .msg/.srv files and, for every shipped type, computes the same RIHS01 hash,
//! deserialises our CDR to the values we encoded, and serialises them back to the same
//! bytes, which we decode to the same values. (tests/rosbags_check.py is its side.)
mod common;

use std::io::Write;
use std::process::{Command, Stdio};

use ferroc_ros2::def::{Arity, BaseType, Message, Primitive, TypeName};
use ferroc_ros2::{cdr, hash, Registry, Value};
use serde_json::{json, Value as Json};

/// Our value as the JSON the Python side writes for rosbags' message objects.
fn to_json(registry: &Registry, message: &Message, value: &Value) -> Json {
    let Value::Struct(values) = value else {
        panic!("a message value is a struct")
    };
    let mut object = serde_json::Map::new();
    for (field, v) in message.fields.iter().zip(values) {
        let nested = match &field.ty.base {
            BaseType::Nested(n) => registry.message(n),
            _ => None,
        };
        // rosbags reads `byte` as a signed int8 (ROS 1's meaning); ROS 2's `byte` is an
        // octet. The wire byte is the same (the byte-for-byte CDR check covers it), only
        // the printed number differs.
        let signed_byte = field.ty.base == BaseType::Primitive(Primitive::Byte);
        let one = |v: &Value| match (nested, v) {
            (Some(m), v) => to_json(registry, m, v),
            (None, Value::U8(b)) if signed_byte => json!(*b as i8),
            (None, v) => scalar(v),
        };
        let j = match (field.ty.arity, v) {
            (Arity::Single, v) => one(v),
            (_, Value::Bytes(b)) if signed_byte => {
                json!(b.iter().map(|b| *b as i8).collect::<Vec<_>>())
            }
            (_, Value::Bytes(b)) => json!(b),
            (_, Value::Array(items)) => Json::Array(items.iter().map(one).collect()),
            (_, other) => panic!("array field holds {other:?}"),
        };
        object.insert(field.name.clone(), j);
    }
    Json::Object(object)
}

fn scalar(v: &Value) -> Json {
    match v {
        Value::Bool(b) => json!(b),
        Value::I8(x) => json!(x),
        Value::U8(x) => json!(x),
        Value::I16(x) => json!(x),
        Value::U16(x) => json!(x),
        Value::I32(x) => json!(x),
        Value::U32(x) => json!(x),
        Value::I64(x) => json!(x),
        Value::U64(x) => json!(x),
        Value::F32(x) => json!(f64::from(*x)),
        Value::F64(x) => json!(x),
        Value::String(s) => json!(s),
        other => panic!("not a scalar: {other:?}"),
    }
}

/// Whether the type or one it references has a `char` field (see rosbags_check.py).
fn has_char(registry: &Registry, name: &TypeName) -> bool {
    let mut todo = vec![name.clone()];
    let mut seen = std::collections::BTreeSet::new();
    while let Some(n) = todo.pop() {
        if !seen.insert(n.clone()) {
            continue;
        }
        if let Some(s) = registry.service(&n) {
            todo.extend([
                s.request.name.clone(),
                s.response.name.clone(),
                s.event_name(),
            ]);
            continue;
        }
        for f in &registry.message(&n).expect("known").fields {
            match &f.ty.base {
                BaseType::Primitive(Primitive::Char) => return true,
                BaseType::Nested(inner) => todo.push(inner.clone()),
                _ => {}
            }
        }
    }
    false
}

#[test]
fn rosbags_agrees_on_every_shipped_types_hash_and_cdr() {
    let Some(python) = ferroc_testkit::python(&["rosbags", "numpy"]) else {
        return;
    };
    let registry = Registry::shipped();
    let mut all: Vec<TypeName> = registry.messages().map(|m| m.name.clone()).collect();
    all.extend(registry.services().map(|s| s.name.clone()));
    let messages: Vec<&Message> = registry.messages().collect();
    let mut samples = Vec::new();
    let mut values = Vec::new();
    for (i, m) in messages.iter().enumerate() {
        for seed in [1, 2, 3] {
            let mut g = common::Gen::new(seed * 1000 + i as u64);
            let value = common::value_of(&registry, &m.name, &mut g);
            let bytes = cdr::encode(&registry, &m.name, &value).expect("encodes");
            samples.push(json!({"type": m.name.to_string(), "cdr": hex(&bytes)}));
            values.push((*m, value, bytes));
        }
    }
    let request = json!({
        "interfaces": concat!(env!("CARGO_MANIFEST_DIR"), "/interfaces"),
        "hash": all.iter().map(ToString::to_string).collect::<Vec<_>>(),
        "samples": samples,
    });
    let answer = run(&python, &request);

    let mut with_char = 0;
    for ty in &all {
        let ours = hash::rihs01(&registry, ty).expect("hashes");
        let theirs = &answer["hashes"][ty.to_string()];
        // [rosbags as is, rosbags with rosidl's char → uint8]
        assert_eq!(theirs[1], json!(ours), "RIHS01 of {ty}");
        if has_char(&registry, ty) {
            with_char += 1;
        } else {
            assert_eq!(theirs[0], json!(ours), "RIHS01 of {ty} (rosbags as is)");
        }
    }
    assert!(
        all.len() > 120,
        "every shipped type is hashed ({})",
        all.len()
    );
    assert!(with_char < all.len() / 4);

    for ((message, value, bytes), back) in values.iter().zip(answer["samples"].as_array().unwrap())
    {
        let ty = &message.name;
        // Both sides print floats in their shortest round-trip form; parsing our text with
        // the same parser as theirs compares the printed values exactly.
        let ours: Json =
            serde_json::from_str(&to_json(&registry, message, value).to_string()).expect("JSON");
        assert_eq!(back["value"], ours, "rosbags read our {ty}");
        let their_bytes = unhex(back["cdr"].as_str().unwrap());
        assert_eq!(hex(&their_bytes), hex(bytes), "rosbags wrote {ty} as we do");
        assert_eq!(
            &cdr::decode(&registry, ty, &their_bytes).expect("decodes"),
            value,
            "{ty}"
        );
    }
}

fn run(python: &std::path::Path, request: &Json) -> Json {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/rosbags_check.py");
    let mut child = Command::new(python)
        .arg(script)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("python starts");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(request.to_string().as_bytes())
        .unwrap();
    let out = child.wait_with_output().expect("python ends");
    assert!(
        out.status.success(),
        "rosbags_check.py failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("JSON answer")
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn unhex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
        .collect()
}
