//! A parameter's new value from its text, parsed as a model file's `<param>` is: the
//! type's syntax, and a number's unit converted into the parameter's (`36 km/h` for a
//! parameter in m/s is 10) or refused if it measures something else. `ferroc run
//! --inspect`, `ferroc inspect --set` through either, and a bundle's part programs all
//! parse with this one function (the rules are `ferroc-values`', the compiler's own),
//! so a change that works on one works on all. The parameter's own checks (range,
//! choices) run after it, as always.

use ferroc_runtime::inspect::view::ParamView;
use ferroc_runtime::module::Value;
use ferroc_values::types::parse_type;
use ferroc_values::units::parse_unit;
use ferroc_values::values::{parse_value, Value as ModelValue, ValueError};
use std::time::Duration;

/// `text` as a value of `param`'s type, in `param`'s unit.
pub fn parse(param: &ParamView, text: &str) -> Result<Value, String> {
    // Named types need a library's manifest, which a running program does not have.
    let ty = parse_type(&param.r#type, &mut |_| None).map_err(|e| {
        format!(
            "parameters of type `{}` cannot be changed while running ({e:?})",
            param.r#type
        )
    })?;
    let unit = match &param.unit {
        Some(u) => Some(parse_unit(u).map_err(|e| format!("the unit `{u}`: {e}"))?),
        None => None,
    };
    let value = parse_value(text, &ty, unit.as_ref()).map_err(|e| match e {
        ValueError::Syntax(s) | ValueError::WrongDimension(s) => s,
    })?;
    Ok(runtime_value(&value))
}

/// A model's parameter value as the runtime's modules receive it (a plan's values
/// for `ferroc run` take the same way).
pub fn runtime_value(v: &ModelValue) -> Value {
    match v {
        ModelValue::Bool(b) => Value::Bool(*b),
        ModelValue::Int(i) => Value::Int(*i),
        ModelValue::Float(x) => Value::Float(*x),
        ModelValue::Str(s) | ModelValue::Opaque(s) => Value::Text(s.clone()),
        ModelValue::Duration(s) => Value::Duration(Duration::from_secs_f64(s.max(0.0))),
        ModelValue::List(items) => Value::List(items.iter().map(runtime_value).collect()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn param(ty: &str, unit: Option<&str>) -> ParamView {
        ParamView {
            module: "robot/m".into(),
            name: "p".into(),
            r#type: ty.into(),
            unit: unit.map(Into::into),
            min: None,
            max: None,
            choices: Vec::new(),
            value: String::new(),
        }
    }

    fn float(param: &ParamView, text: &str) -> f64 {
        match parse(param, text) {
            Ok(Value::Float(x)) => x,
            other => panic!("`{text}`: {other:?}"),
        }
    }

    #[test]
    fn numbers_take_any_unit_of_the_parameters_dimension() {
        let speed = param("f64", Some("m/s"));
        assert_eq!(float(&speed, "0.3"), 0.3);
        assert_eq!(float(&speed, " 0.3 m/s "), 0.3);
        assert_eq!(float(&speed, "3e-1 m/s"), 0.3);
        // The case bundle programs refused before they parsed with the model's rules.
        assert!((float(&speed, "30 cm/s") - 0.3).abs() < 1e-12);
        assert!((float(&speed, "36 km/h") - 10.0).abs() < 1e-9);
        let e = parse(&speed, "3 kg").unwrap_err();
        assert!(e.contains("measures"), "{e}");
        let e = parse(&param("f64", None), "3 m").unwrap_err();
        assert!(e.contains("has no unit"), "{e}");
        assert!(parse(&speed, "fast").is_err());
        assert!(parse(&speed, "inf").is_err());
    }

    #[test]
    fn integers_booleans_durations_and_text_follow_their_types() {
        assert_eq!(parse(&param("u8", None), "255"), Ok(Value::Int(255)));
        assert!(parse(&param("u8", None), "256").is_err());
        assert!(parse(&param("u32", None), "-1").is_err());
        assert_eq!(parse(&param("i8", None), "-128"), Ok(Value::Int(-128)));
        assert!(parse(&param("i64", None), "1.5").is_err());
        assert_eq!(parse(&param("bool", None), "true"), Ok(Value::Bool(true)));
        assert!(parse(&param("bool", None), "yes").is_err());
        assert_eq!(
            parse(&param("duration", None), "250ms"),
            Ok(Value::Duration(Duration::from_millis(250)))
        );
        assert_eq!(
            parse(&param("string", None), "right"),
            Ok(Value::Text("right".into()))
        );
        assert!(parse(&param("nav.Pose2D", None), "x").is_err());
    }
}
