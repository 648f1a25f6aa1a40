//! JSON Schemas of the channels, so Foxglove knows the fields of a message (for plots
//! and message paths): a port's message is its `value/…` answer, `{port, type, unit,
//! published, value}`; `value`'s schema follows the port's model type where the type
//! says the JSON form (numbers, booleans, text, sequences and arrays of them), and
//! otherwise the form of one value read when the bridge starts (a library's struct
//! may be registered with or without serde). Nothing here is strict: a schema
//! describes, it does not reject.

use serde_json::{json, Value};

/// The schema of a port's messages, for the model type `ty` and (if one could be
/// read) a `sample` of its `value`.
pub fn port(ty: &str, sample: Option<&Value>) -> Value {
    json!({
        "type": "object",
        "title": ty,
        "properties": {
            "port": {"type": "string", "description": "the output the value was read from"},
            "type": {"type": "string"},
            "unit": {"type": ["string", "null"]},
            "published": {"type": "boolean", "description": "false while the output holds its initial value"},
            "value": value(ty, sample),
        }
    })
}

/// The schema of a value of the model type `ty`.
pub fn value(ty: &str, sample: Option<&Value>) -> Value {
    let t = ty.trim();
    if let Some(inner) = t.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
        let item = sample.and_then(|s| s.as_array()?.first());
        return json!({"type": "array", "items": value(inner, item)});
    }
    if let Some((inner, count)) = t.rsplit_once('[') {
        if let Ok(n) = count.trim_end_matches(']').trim().parse::<u32>() {
            let item = sample.and_then(|s| s.as_array()?.first());
            return json!({"type": "array", "items": value(inner, item), "minItems": n, "maxItems": n});
        }
    }
    match t {
        // Non-finite floats are `null` in the answers.
        "f32" | "f64" | "Stimulation" | "Inhibition" | "Activity" | "TargetRating" => {
            json!({"type": ["number", "null"]})
        }
        "i8" | "i16" | "i32" | "i64" | "u8" | "u16" | "u32" | "u64" => json!({"type": "integer"}),
        "bool" => json!({"type": "boolean"}),
        "string" => json!({"type": "string"}),
        _ => sample.map_or_else(|| json!({}), shape),
    }
}

/// The schema of values shaped like `v` (objects with its fields, arrays of its
/// first element's shape), permissive beyond that.
pub fn shape(v: &Value) -> Value {
    match v {
        Value::Null => json!({}),
        Value::Bool(_) => json!({"type": "boolean"}),
        Value::Number(_) => json!({"type": ["number", "null"]}),
        Value::String(_) => json!({"type": "string"}),
        Value::Array(items) => match items.first() {
            Some(first) => json!({"type": "array", "items": shape(first)}),
            None => json!({"type": "array"}),
        },
        Value::Object(fields) => {
            let properties: serde_json::Map<String, Value> = (fields.iter())
                .map(|(k, v)| (k.clone(), shape(v)))
                .collect();
            json!({"type": "object", "properties": properties})
        }
    }
}

/// The schema of a part's list messages (`containers`, `activities`, `links`):
/// `{FIELD: [ITEM…]}`, items shaped like the first `sample` item.
pub fn list(field: &str, sample: Option<&Value>) -> Value {
    let items = sample
        .and_then(|s| s.as_array()?.first())
        .map_or_else(|| json!({"type": "object"}), shape);
    json!({
        "type": "object",
        "properties": {field: {"type": "array", "items": items}}
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_types_say_the_json_form() {
        assert_eq!(value("f64", None), json!({"type": ["number", "null"]}));
        assert_eq!(value("Activity", None), json!({"type": ["number", "null"]}));
        assert_eq!(value("u32", None), json!({"type": "integer"}));
        assert_eq!(value("bool", None), json!({"type": "boolean"}));
        assert_eq!(
            value("[f32]", None),
            json!({"type": "array", "items": {"type": ["number", "null"]}})
        );
        assert_eq!(
            value("i8[3]", None),
            json!({"type": "array", "items": {"type": "integer"}, "minItems": 3, "maxItems": 3})
        );
        // The type wins over a sample of another form.
        assert_eq!(
            value("f64", Some(&json!("x"))),
            json!({"type": ["number", "null"]})
        );
    }

    #[test]
    fn other_types_take_the_form_of_a_sample_or_anything() {
        // A struct registered without serde answers its text form.
        assert_eq!(
            value("nav.Pose2D", Some(&json!("Pose2D { x: 1 }"))),
            json!({"type": "string"})
        );
        assert_eq!(
            value("nav.Scan", Some(&json!({"ranges": [1.0, 2.0], "ok": true}))),
            json!({"type": "object", "properties": {
                "ranges": {"type": "array", "items": {"type": ["number", "null"]}},
                "ok": {"type": "boolean"}
            }})
        );
        assert_eq!(value("nav.Unread", None), json!({}));
        assert_eq!(
            value("[nav.Unread]", Some(&json!([]))),
            json!({"type": "array", "items": {}})
        );
        let port = port("f64", None);
        assert_eq!(
            port["properties"]["value"],
            json!({"type": ["number", "null"]})
        );
        assert_eq!(port["title"], "f64");
        assert_eq!(
            list("containers", Some(&json!([{"cycles": 3}])))["properties"]["containers"]["items"],
            json!({"type": "object", "properties": {"cycles": {"type": ["number", "null"]}}})
        );
    }
}
