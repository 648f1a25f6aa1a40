//! RIHS01 type hashes (REP-2016), computed as rosidl_generator_type_description does:
//! the SHA-256 of the type description's JSON (the type's individual description and
//! those of every type it references, sorted by name; field types as
//! `type_description_interfaces/FieldType` ids; no default values), written with
//! Python's `json.dumps` separators `", "` and `": "`.
use sha2::{Digest, Sha256};
use std::collections::BTreeSet;
use std::fmt::Write as _;

use crate::def::{Arity, BaseType, Field, Primitive, TypeName, EMPTY_STRUCT_MEMBER};
use crate::Registry;

/// A field as the type description has it.
struct DescField {
    name: String,
    type_id: u32,
    capacity: u32,
    string_capacity: u32,
    nested: String,
}

/// `RIHS01_<64 hex digits>` of a message or service type, `None` if the registry does
/// not know it (or a type it references).
pub fn rihs01(registry: &Registry, name: &TypeName) -> Option<String> {
    let json = type_description_json(registry, name)?;
    let digest = Sha256::digest(json.as_bytes());
    let mut out = String::from("RIHS01_");
    for b in digest {
        let _ = write!(out, "{b:02x}");
    }
    Some(out)
}

/// The hashed JSON text of a type's description (exposed so that a mismatch can be shown).
pub fn type_description_json(registry: &Registry, name: &TypeName) -> Option<String> {
    let top = individual(registry, name)?;
    let mut referenced = BTreeSet::new();
    let mut queue: Vec<String> = top.iter().map(|f| f.nested.clone()).collect();
    while let Some(next) = queue.pop() {
        if next.is_empty() || !referenced.insert(next.clone()) {
            continue;
        }
        let fields = individual(registry, &TypeName::parse(&next)?)?;
        queue.extend(fields.into_iter().map(|f| f.nested));
    }
    let mut json = String::from("{\"type_description\": ");
    write_individual(&mut json, &name.to_string(), &top);
    json.push_str(", \"referenced_type_descriptions\": [");
    // BTreeSet<String> iterates in the byte order Python's sorted() uses.
    for (i, r) in referenced.iter().enumerate() {
        if i > 0 {
            json.push_str(", ");
        }
        let fields = individual(registry, &TypeName::parse(r)?)?;
        write_individual(&mut json, r, &fields);
    }
    json.push_str("]}");
    Some(json)
}

/// The fields of one type's individual description.
fn individual(registry: &Registry, name: &TypeName) -> Option<Vec<DescField>> {
    if let Some(service) = registry.service(name) {
        let nested = |field: &str, ty: &TypeName| DescField {
            name: field.to_string(),
            type_id: 1,
            capacity: 0,
            string_capacity: 0,
            nested: ty.to_string(),
        };
        return Some(vec![
            nested("request_message", &service.request.name),
            nested("response_message", &service.response.name),
            nested("event_message", &service.event_name()),
        ]);
    }
    let message = registry.message(name)?;
    if message.fields.is_empty() {
        return Some(vec![DescField {
            name: EMPTY_STRUCT_MEMBER.to_string(),
            type_id: 3,
            capacity: 0,
            string_capacity: 0,
            nested: String::new(),
        }]);
    }
    Some(message.fields.iter().map(desc_field).collect())
}

fn desc_field(field: &Field) -> DescField {
    let (base_id, string_capacity, nested) = match &field.ty.base {
        BaseType::Primitive(p) => (primitive_id(*p), 0, String::new()),
        BaseType::String { bound: None } => (17, 0, String::new()),
        BaseType::WString { bound: None } => (18, 0, String::new()),
        BaseType::String { bound: Some(b) } => (21, *b, String::new()),
        BaseType::WString { bound: Some(b) } => (22, *b, String::new()),
        BaseType::Nested(n) => (1, 0, n.to_string()),
    };
    // type_description_interfaces/FieldType: arrays +48, bounded sequences +96,
    // unbounded sequences +144.
    let (offset, capacity) = match field.ty.arity {
        Arity::Single => (0, 0),
        Arity::Fixed(n) => (48, n),
        Arity::Bounded(n) => (96, n),
        Arity::Unbounded => (144, 0),
    };
    DescField {
        name: field.name.clone(),
        type_id: base_id + offset,
        capacity,
        string_capacity,
        nested,
    }
}

/// FieldType ids of the primitives, after rosidl's `.msg` → IDL mapping (`char` is
/// `uint8`, `byte` is `octet`, `float32`/`float64` are `float`/`double`).
fn primitive_id(p: Primitive) -> u32 {
    use Primitive::*;
    match p {
        Int8 => 2,
        UInt8 | Char => 3,
        Int16 => 4,
        UInt16 => 5,
        Int32 => 6,
        UInt32 => 7,
        Int64 => 8,
        UInt64 => 9,
        Float32 => 10,
        Float64 => 11,
        Bool => 15,
        Byte => 16,
    }
}

fn write_individual(out: &mut String, name: &str, fields: &[DescField]) {
    let _ = write!(out, "{{\"type_name\": \"{name}\", \"fields\": [");
    for (i, f) in fields.iter().enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        let _ = write!(
            out,
            "{{\"name\": \"{}\", \"type\": {{\"type_id\": {}, \"capacity\": {}, \
             \"string_capacity\": {}, \"nested_type_name\": \"{}\"}}}}",
            f.name, f.type_id, f.capacity, f.string_capacity, f.nested
        );
    }
    out.push_str("]}");
}
