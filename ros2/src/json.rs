//! Between a value's JSON and a ROS 2 message, for tools and tests (a running part
//! writes CDR straight from the port's value, [`serde_cdr`](crate::serde_cdr)). The
//! JSON of a value's serde form names struct fields as a library type's fields are
//! named, which the checks of area R matched against the message field by field
//! (R102). So a value becomes a message by name: [`from_json`] fills a [`Value`]
//! of a message type (missing fields zero, unknown ones refused), [`to_json`] gives the
//! JSON a port's type reads back. With a field path (`field="linear.x"`, or `data` of a
//! one-field wrapper) only that field is set or read.

use crate::def::{Arity, BaseType, Field, Message, Primitive, TypeName};
use crate::{Registry, Value};
use serde_json::Value as Json;

/// Nested messages deeper than this are refused.
const MAX_DEPTH: usize = 32;

fn message<'r>(reg: &'r Registry, ty: &TypeName) -> Result<&'r Message, String> {
    reg.message(ty)
        .ok_or_else(|| format!("unknown message type `{ty}`"))
}

/// The zero value of a message type: numbers 0, strings empty, sequences empty, fixed
/// arrays of zeros.
pub fn zero(reg: &Registry, ty: &TypeName) -> Result<Value, String> {
    zero_message(reg, message(reg, ty)?, 0)
}

fn zero_message(reg: &Registry, m: &Message, depth: usize) -> Result<Value, String> {
    if depth > MAX_DEPTH {
        return Err("messages are nested too deeply".into());
    }
    m.fields
        .iter()
        .map(|f| zero_field(reg, f, depth))
        .collect::<Result<_, _>>()
        .map(Value::Struct)
}

fn zero_field(reg: &Registry, f: &Field, depth: usize) -> Result<Value, String> {
    let bytes = is_bytes(&f.ty.base);
    Ok(match f.ty.arity {
        Arity::Single => zero_base(reg, &f.ty.base, depth)?,
        Arity::Fixed(n) if bytes => Value::Bytes(vec![0; n as usize]),
        Arity::Fixed(n) => Value::Array(
            (0..n)
                .map(|_| zero_base(reg, &f.ty.base, depth))
                .collect::<Result<_, _>>()?,
        ),
        _ if bytes => Value::Bytes(Vec::new()),
        _ => Value::Array(Vec::new()),
    })
}

fn zero_base(reg: &Registry, base: &BaseType, depth: usize) -> Result<Value, String> {
    use Primitive::*;
    Ok(match base {
        BaseType::Primitive(p) => match p {
            Bool => Value::Bool(false),
            Byte | Char | UInt8 => Value::U8(0),
            Int8 => Value::I8(0),
            Int16 => Value::I16(0),
            UInt16 => Value::U16(0),
            Int32 => Value::I32(0),
            UInt32 => Value::U32(0),
            Int64 => Value::I64(0),
            UInt64 => Value::U64(0),
            Float32 => Value::F32(0.0),
            Float64 => Value::F64(0.0),
        },
        BaseType::String { .. } | BaseType::WString { .. } => Value::String(String::new()),
        BaseType::Nested(n) => zero_message(reg, message(reg, n)?, depth + 1)?,
    })
}

/// A message of type `ty` from a port's JSON value: the whole message, or with `field`
/// (a dotted path) only that field, the others zero.
pub fn from_json(
    reg: &Registry,
    ty: &TypeName,
    field: Option<&str>,
    json: &Json,
) -> Result<Value, String> {
    let m = message(reg, ty)?;
    let Some(path) = field else {
        return message_from(reg, m, json, 0);
    };
    let mut value = zero_message(reg, m, 0)?;
    let (slot, f) = locate(reg, m, &mut value, path)?;
    *slot = field_from(reg, f, json, 0)?;
    Ok(value)
}

/// The JSON of the part of a message a port carries (all of it, or `field`).
pub fn to_json(
    reg: &Registry,
    ty: &TypeName,
    field: Option<&str>,
    value: &Value,
) -> Result<Json, String> {
    let m = message(reg, ty)?;
    let Some(path) = field else {
        return message_to(reg, m, value, 0);
    };
    let mut value = value.clone();
    let (slot, f) = locate(reg, m, &mut value, path)?;
    field_to(reg, f, slot, 0)
}

/// The field at `path` in `value` (a message of `m`) and its definition.
fn locate<'v, 'r>(
    reg: &'r Registry,
    mut m: &'r Message,
    mut value: &'v mut Value,
    path: &str,
) -> Result<(&'v mut Value, &'r Field), String> {
    let mut segments = path.split('.').peekable();
    while let Some(seg) = segments.next() {
        let i = m
            .fields
            .iter()
            .position(|f| f.name == seg)
            .ok_or_else(|| format!("`{}` has no field `{seg}`", m.name))?;
        let Value::Struct(values) = value else {
            return Err(format!("`{}` is not a message value", m.name));
        };
        let f = &m.fields[i];
        let slot = values
            .get_mut(i)
            .ok_or_else(|| format!("the `{}` value has too few fields", m.name))?;
        if segments.peek().is_none() {
            return Ok((slot, f));
        }
        match (&f.ty.base, f.ty.arity) {
            (BaseType::Nested(n), Arity::Single) => m = message(reg, n)?,
            _ => return Err(format!("field `{seg}` of `{}` has no fields", m.name)),
        }
        value = slot;
    }
    Err("an empty field path".into())
}

fn message_from(reg: &Registry, m: &Message, json: &Json, depth: usize) -> Result<Value, String> {
    if depth > MAX_DEPTH {
        return Err("messages are nested too deeply".into());
    }
    let Json::Object(map) = json else {
        return Err(format!("`{}` needs an object, found {json}", m.name));
    };
    if let Some(k) = map.keys().find(|k| !m.fields.iter().any(|f| &f.name == *k)) {
        return Err(format!("`{}` has no field `{k}`", m.name));
    }
    m.fields
        .iter()
        .map(|f| match map.get(&f.name) {
            Some(j) => field_from(reg, f, j, depth).map_err(|e| format!("{}: {e}", f.name)),
            None => zero_field(reg, f, depth),
        })
        .collect::<Result<_, _>>()
        .map(Value::Struct)
}

fn field_from(reg: &Registry, f: &Field, json: &Json, depth: usize) -> Result<Value, String> {
    if f.ty.arity == Arity::Single {
        return base_from(reg, &f.ty.base, json, depth);
    }
    let Json::Array(items) = json else {
        return Err(format!("needs an array, found {json}"));
    };
    if is_bytes(&f.ty.base) {
        return items
            .iter()
            .map(|j| {
                j.as_u64()
                    .and_then(|v| u8::try_from(v).ok())
                    .ok_or(format!("{j} is not a byte"))
            })
            .collect::<Result<_, _>>()
            .map(Value::Bytes);
    }
    items
        .iter()
        .map(|j| base_from(reg, &f.ty.base, j, depth))
        .collect::<Result<_, _>>()
        .map(Value::Array)
}

fn base_from(reg: &Registry, base: &BaseType, json: &Json, depth: usize) -> Result<Value, String> {
    use Primitive::*;
    let int = |lo: i128, hi: i128| -> Result<i128, String> {
        let v = json
            .as_i64()
            .map(i128::from)
            .or(json.as_u64().map(i128::from))
            .ok_or_else(|| format!("{json} is not an integer"))?;
        (lo..=hi)
            .contains(&v)
            .then_some(v)
            .ok_or_else(|| format!("{v} is out of range"))
    };
    // serde_json writes non-finite floats as null: they travel as NaN.
    let float = || json.as_f64().or(json.is_null().then_some(f64::NAN));
    Ok(match base {
        BaseType::Primitive(p) => match p {
            Bool => Value::Bool(
                json.as_bool()
                    .ok_or_else(|| format!("{json} is not a bool"))?,
            ),
            Byte | Char | UInt8 => Value::U8(int(0, 255)? as u8),
            Int8 => Value::I8(int(-128, 127)? as i8),
            Int16 => Value::I16(int(i16::MIN.into(), i16::MAX.into())? as i16),
            UInt16 => Value::U16(int(0, u16::MAX.into())? as u16),
            Int32 => Value::I32(int(i32::MIN.into(), i32::MAX.into())? as i32),
            UInt32 => Value::U32(int(0, u32::MAX.into())? as u32),
            Int64 => Value::I64(int(i64::MIN.into(), i64::MAX.into())? as i64),
            UInt64 => Value::U64(int(0, u64::MAX.into())? as u64),
            Float32 => Value::F32(float().ok_or_else(|| format!("{json} is not a number"))? as f32),
            Float64 => Value::F64(float().ok_or_else(|| format!("{json} is not a number"))?),
        },
        BaseType::String { .. } | BaseType::WString { .. } => Value::String(
            json.as_str()
                .ok_or_else(|| format!("{json} is not a string"))?
                .to_string(),
        ),
        BaseType::Nested(n) => message_from(reg, message(reg, n)?, json, depth + 1)?,
    })
}

fn message_to(reg: &Registry, m: &Message, value: &Value, depth: usize) -> Result<Json, String> {
    if depth > MAX_DEPTH {
        return Err("messages are nested too deeply".into());
    }
    let Value::Struct(values) = value else {
        return Err(format!("`{}` needs a message value", m.name));
    };
    let mut map = serde_json::Map::new();
    for (f, v) in m.fields.iter().zip(values) {
        map.insert(f.name.clone(), field_to(reg, f, v, depth)?);
    }
    Ok(Json::Object(map))
}

fn field_to(reg: &Registry, f: &Field, value: &Value, depth: usize) -> Result<Json, String> {
    match (f.ty.arity, value) {
        (Arity::Single, v) => base_to(reg, &f.ty.base, v, depth),
        (_, Value::Bytes(b)) => Ok(Json::Array(b.iter().map(|x| Json::from(*x)).collect())),
        (_, Value::Array(items)) => items
            .iter()
            .map(|v| base_to(reg, &f.ty.base, v, depth))
            .collect::<Result<_, _>>()
            .map(Json::Array),
        (_, v) => Err(format!("`{}` needs an array, found {}", f.name, v.kind())),
    }
}

fn base_to(reg: &Registry, base: &BaseType, value: &Value, depth: usize) -> Result<Json, String> {
    Ok(match value {
        Value::Bool(b) => Json::from(*b),
        Value::I8(v) => Json::from(*v),
        Value::U8(v) => Json::from(*v),
        Value::I16(v) => Json::from(*v),
        Value::U16(v) => Json::from(*v),
        Value::I32(v) => Json::from(*v),
        Value::U32(v) => Json::from(*v),
        Value::I64(v) => Json::from(*v),
        Value::U64(v) => Json::from(*v),
        Value::F32(v) => Json::from(f64::from(*v)),
        Value::F64(v) => Json::from(*v),
        Value::String(s) => Json::from(s.as_str()),
        Value::Struct(_) => match base {
            BaseType::Nested(n) => message_to(reg, message(reg, n)?, value, depth + 1)?,
            _ => return Err("a message value where a plain value belongs".into()),
        },
        Value::Bytes(_) | Value::Array(_) => return Err("an array where one value belongs".into()),
    })
}

fn is_bytes(base: &BaseType) -> bool {
    matches!(
        base,
        BaseType::Primitive(Primitive::Byte | Primitive::Char | Primitive::UInt8)
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn twist() -> TypeName {
        TypeName::parse("geometry_msgs/msg/Twist").unwrap()
    }

    #[test]
    fn a_library_value_becomes_a_twist_by_field_names_and_back() {
        let reg = Registry::shipped();
        let j = json!({"linear": {"x": 0.5, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": -0.25}});
        let v = from_json(&reg, &twist(), None, &j).unwrap();
        assert_eq!(
            v,
            Value::Struct(vec![
                Value::Struct(vec![Value::F64(0.5), Value::F64(0.0), Value::F64(0.0)]),
                Value::Struct(vec![Value::F64(0.0), Value::F64(0.0), Value::F64(-0.25)]),
            ])
        );
        assert_eq!(to_json(&reg, &twist(), None, &v).unwrap(), j);
    }

    #[test]
    fn one_field_is_set_and_read_the_others_zero() {
        let reg = Registry::shipped();
        let v = from_json(&reg, &twist(), Some("linear.x"), &json!(1.5)).unwrap();
        let zero3 = || Value::Struct(vec![Value::F64(0.0); 3]);
        assert_eq!(
            v,
            Value::Struct(vec![
                Value::Struct(vec![Value::F64(1.5), Value::F64(0.0), Value::F64(0.0)]),
                zero3(),
            ])
        );
        assert_eq!(
            to_json(&reg, &twist(), Some("linear.x"), &v).unwrap(),
            json!(1.5)
        );
        let scan = TypeName::parse("sensor_msgs/msg/LaserScan").unwrap();
        let s = from_json(&reg, &scan, Some("ranges"), &json!([1.0, 2.5])).unwrap();
        assert_eq!(
            to_json(&reg, &scan, Some("ranges"), &s).unwrap(),
            json!([1.0, 2.5])
        );
        assert!(crate::cdr::encode(&reg, &scan, &s).is_ok());
    }

    #[test]
    fn wrong_json_is_an_error_naming_the_field() {
        let reg = Registry::shipped();
        let e = from_json(&reg, &twist(), None, &json!({"linear": {"x": "fast"}})).unwrap_err();
        assert!(e.contains("linear") && e.contains("not a number"), "{e}");
        let e = from_json(&reg, &twist(), None, &json!({"speed": 1})).unwrap_err();
        assert!(e.contains("no field `speed`"), "{e}");
        let i8ty = TypeName::parse("std_msgs/msg/Int8").unwrap();
        assert!(from_json(&reg, &i8ty, Some("data"), &json!(300)).is_err());
    }
}
