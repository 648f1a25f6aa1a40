//! JSON Schemas of the display channels.
//!
//! The built-in types have fixed schemas. A library type's schema is read off the
//! serde form of its first recorded value (objects, arrays, strings, numbers as they
//! appear there): the runtime knows its values through serde only, and serde has no
//! schema of its own. Wherever a number appears `null` is allowed too, because
//! serde_json writes NaN and infinities as `null`.

use serde_json::{json, Value};

/// The JSON Schema of `model_type`'s display form; `first` is its first value.
pub fn json_schema(model_type: &str, first: &Value) -> Value {
    let mut schema = match builtin(model_type) {
        Some(s) => s,
        None => infer(first),
    };
    if let Value::Object(map) = &mut schema {
        map.insert(
            "$schema".into(),
            json!("https://json-schema.org/draft/2020-12/schema"),
        );
        map.insert("title".into(), json!(model_type));
    }
    schema
}

fn float() -> Value {
    json!({"type": ["number", "null"]})
}

fn integer(min: f64, max: f64) -> Value {
    json!({"type": "integer", "minimum": min, "maximum": max})
}

fn builtin(model_type: &str) -> Option<Value> {
    let int = |t: &str| -> Option<Value> {
        Some(match t {
            "i8" => integer(i8::MIN.into(), i8::MAX.into()),
            "i16" => integer(i16::MIN.into(), i16::MAX.into()),
            "i32" => integer(i32::MIN.into(), i32::MAX.into()),
            "i64" => integer(i64::MIN as f64, i64::MAX as f64),
            "u8" => integer(0.0, u8::MAX.into()),
            "u16" => integer(0.0, u16::MAX.into()),
            "u32" => integer(0.0, u32::MAX.into()),
            "u64" => integer(0.0, u64::MAX as f64),
            "f32" | "f64" | "Stimulation" | "Inhibition" | "Activity" | "TargetRating" => float(),
            _ => return None,
        })
    };
    if let Some(s) = int(model_type) {
        return Some(s);
    }
    // `[f64]`: a vector; `f64[4][4]`: 4 arrays of 4 (the outer length first).
    if let Some(inner) = model_type
        .strip_prefix('[')
        .and_then(|t| t.strip_suffix(']'))
    {
        return Some(json!({"type": "array", "items": builtin(inner)?}));
    }
    if let Some(at) = model_type.find('[') {
        let (element, dims) = model_type.split_at(at);
        let lengths: Option<Vec<u64>> = dims
            .strip_prefix('[')?
            .strip_suffix(']')?
            .split("][")
            .map(|n| n.parse().ok())
            .collect();
        let mut schema = builtin(element)?;
        for n in lengths?.into_iter().rev() {
            schema = json!({"type": "array", "items": schema, "minItems": n, "maxItems": n});
        }
        return Some(schema);
    }
    Some(match model_type {
        "bool" => json!({"type": "boolean"}),
        "string" => json!({"type": "string"}),
        "timestamp" => json!({"type": "object", "required": ["nanos"],
            "properties": {"nanos": integer(i64::MIN as f64, i64::MAX as f64)}}),
        "duration" => json!({"type": "object", "required": ["secs", "nanos"],
            "properties": {"secs": integer(0.0, u64::MAX as f64),
                           "nanos": integer(0.0, 999_999_999.0)}}),
        _ => return None,
    })
}

/// The schema of values shaped like `v`.
fn infer(v: &Value) -> Value {
    match v {
        Value::Null => json!({}),
        Value::Bool(_) => json!({"type": "boolean"}),
        // serde_json writes integers without a point, floats always with one.
        Value::Number(n) if !n.is_f64() => json!({"type": "integer"}),
        Value::Number(_) => float(),
        Value::String(_) => json!({"type": "string"}),
        Value::Array(items) => match items.first() {
            Some(first) => json!({"type": "array", "items": infer(first)}),
            None => json!({"type": "array"}),
        },
        Value::Object(fields) => {
            let properties: serde_json::Map<String, Value> =
                fields.iter().map(|(k, v)| (k.clone(), infer(v))).collect();
            json!({"type": "object", "properties": properties})
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_allow_null_for_non_finite_floats_and_integers_have_bounds() {
        assert_eq!(
            json_schema("f64", &json!(null))["type"],
            json!(["number", "null"])
        );
        assert_eq!(json_schema("u8", &json!(3))["maximum"], json!(255.0));
        let arr = json_schema("f64[3]", &json!([1.0, 2.0, 3.0]));
        assert_eq!(arr["minItems"], json!(3));
        assert_eq!(arr["items"]["type"], json!(["number", "null"]));
        let matrix = json_schema("f64[2][4]", &json!(null));
        assert_eq!(matrix["maxItems"], json!(2));
        assert_eq!(matrix["items"]["maxItems"], json!(4));
        assert_eq!(
            json_schema("[u8]", &json!([]))["items"]["minimum"],
            json!(0.0)
        );
    }

    #[test]
    fn library_types_are_read_off_the_first_value() {
        let s = json_schema("rescue.Pose2D", &json!({"x": 1.0, "y": null, "tag": "a"}));
        assert_eq!(s["type"], "object");
        assert_eq!(s["properties"]["y"], json!({}), "a null says nothing");
        assert_eq!(s["properties"]["tag"]["type"], "string");
        assert_eq!(s["properties"]["x"]["type"], json!(["number", "null"]));
        let counted = json_schema("a.Count", &json!({"n": 3}));
        assert_eq!(counted["properties"]["n"]["type"], "integer");
        assert_eq!(s["title"], "rescue.Pose2D");
    }
}
