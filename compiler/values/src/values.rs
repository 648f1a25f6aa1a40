//! Parameter values: text parsed according to the declared type and unit.
//!
//! Shared by the parameter checks and (later) the runtime builder, so a value that checks
//! is exactly the value that runs.

use crate::types::Type;
use crate::units::{describe_dimension, parse_unit, relate, Unit, UnitRelation};

#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Bool(bool),
    Int(i128),
    /// In the declared unit of the parameter.
    Float(f64),
    Str(String),
    /// Seconds.
    Duration(f64),
    List(Vec<Value>),
    /// Library types are opaque to the compiler; the text goes to the module as is.
    Opaque(String),
}

#[derive(Debug, PartialEq)]
pub enum ValueError {
    /// The text does not parse as the type.
    Syntax(String),
    /// The text carries a unit of another dimension.
    WrongDimension(String),
}

/// Splits `0.5 m/s` into the number text and the unit text (which may be empty).
pub fn split_number(text: &str) -> (&str, &str) {
    let t = text.trim();
    let bytes = t.as_bytes();
    let mut end = 0;
    let mut seen_e = false;
    while end < bytes.len() {
        let c = bytes[end];
        let ok = c.is_ascii_digit()
            || c == b'.'
            || ((c == b'-' || c == b'+') && (end == 0 || matches!(bytes[end - 1], b'e' | b'E')))
            || ((c == b'e' || c == b'E')
                && !seen_e
                && end > 0
                && bytes
                    .get(end + 1)
                    .is_some_and(|n| n.is_ascii_digit() || *n == b'-' || *n == b'+'));
        if !ok {
            break;
        }
        seen_e |= c == b'e' || c == b'E';
        end += 1;
    }
    (t[..end].trim(), t[end..].trim())
}

/// Parses one value of `ty`; numbers with a unit are converted into `unit` (the declared).
pub fn parse_value(text: &str, ty: &Type, unit: Option<&Unit>) -> Result<Value, ValueError> {
    let t = text.trim();
    match ty {
        Type::Bool => match t {
            "true" => Ok(Value::Bool(true)),
            "false" => Ok(Value::Bool(false)),
            _ => Err(ValueError::Syntax(format!(
                "`{t}` is not a bool (write `true` or `false`)"
            ))),
        },
        Type::String => Ok(Value::Str(text.to_string())),
        Type::Named(..) => Ok(Value::Opaque(text.to_string())),
        Type::Duration => parse_duration(t).map(Value::Duration),
        Type::Timestamp => Err(ValueError::Syntax(
            "timestamps cannot be given as parameter values".into(),
        )),
        Type::Array(elem, _) | Type::Seq(elem) => {
            let items: Vec<&str> = t
                .split([',', ' ', '\t', '\n', ';'])
                .filter(|s| !s.trim().is_empty())
                .collect();
            // A unit written once at the end (`1, 2, 3 m`) applies to all elements.
            let values = items
                .iter()
                .map(|i| parse_value(i, elem, unit))
                .collect::<Result<Vec<_>, _>>()?;
            if let Type::Array(_, n) = ty {
                if values.len() != *n as usize {
                    return Err(ValueError::Syntax(format!(
                        "expected {} elements, found {}",
                        n,
                        values.len()
                    )));
                }
            }
            Ok(Value::List(values))
        }
        Type::Int { .. } | Type::Float { .. } | Type::Meta(_) => parse_number(t, ty, unit),
    }
}

fn parse_number(t: &str, ty: &Type, unit: Option<&Unit>) -> Result<Value, ValueError> {
    let (num, unit_text) = split_number(t);
    if num.is_empty() {
        return Err(ValueError::Syntax(format!(
            "`{t}` is not a number of type `{ty}`"
        )));
    }
    let mut factor = 1.0;
    if !unit_text.is_empty() {
        let given = parse_unit(unit_text).map_err(|e| ValueError::Syntax(format!("`{t}`: {e}")))?;
        match unit {
            None => {
                return Err(ValueError::WrongDimension(format!(
                    "`{t}` carries the unit `{given}` but the parameter has no unit"
                )))
            }
            Some(declared) => match relate(&given, declared) {
                UnitRelation::Same => {}
                UnitRelation::Scaled(f) => factor = f,
                UnitRelation::DifferentDimension => {
                    return Err(ValueError::WrongDimension(format!(
                        "`{given}` measures {}, but the parameter is in `{declared}`, which measures {}",
                        describe_dimension(&given.dimension),
                        describe_dimension(&declared.dimension)
                    )))
                }
            },
        }
    }
    match ty {
        Type::Int { signed, bits } => {
            if factor != 1.0 || num.contains(['.', 'e', 'E']) {
                let f: f64 = num
                    .parse()
                    .map_err(|_| ValueError::Syntax(format!("`{num}` is not a number")))?;
                let scaled = scale(f, factor);
                if scaled.fract() != 0.0 {
                    return Err(ValueError::Syntax(format!(
                        "`{t}` is not a whole number of `{ty}`"
                    )));
                }
                return check_int(scaled as i128, *signed, *bits, ty);
            }
            let i: i128 = num
                .parse()
                .map_err(|_| ValueError::Syntax(format!("`{num}` is not an integer")))?;
            check_int(i, *signed, *bits, ty)
        }
        _ => {
            let f: f64 = num
                .parse()
                .map_err(|_| ValueError::Syntax(format!("`{num}` is not a number")))?;
            if !f.is_finite() {
                return Err(ValueError::Syntax(format!(
                    "`{num}` is not a finite number"
                )));
            }
            Ok(Value::Float(scale(f, factor)))
        }
    }
}

/// `value` converted by `factor` as a person would: `70 cm` in metres is `0.7`, not
/// `70 * 0.01 = 0.7000000000000001`. Dividing by a whole inverse (100) rounds once,
/// correctly; multiplying by its inexact reciprocal (0.01) rounds twice.
pub fn scale(value: f64, factor: f64) -> f64 {
    let inverse = 1.0 / factor;
    if factor < 1.0 && inverse.fract() == 0.0 && inverse.is_finite() {
        value / inverse
    } else {
        value * factor
    }
}

fn check_int(i: i128, signed: bool, bits: u8, ty: &Type) -> Result<Value, ValueError> {
    let (lo, hi) = if signed {
        (-(1i128 << (bits - 1)), (1i128 << (bits - 1)) - 1)
    } else {
        (0, (1i128 << bits) - 1)
    };
    if i < lo || i > hi {
        return Err(ValueError::Syntax(format!(
            "{i} does not fit in `{ty}` ({lo}..={hi})"
        )));
    }
    Ok(Value::Int(i))
}

/// `10ms`, `1.5 s`, `250us`, `2min`, or ISO 8601 `PT0.04S` / `P1DT2H`. Seconds.
pub fn parse_duration(text: &str) -> Result<f64, ValueError> {
    let t = text.trim();
    if let Some(iso) = t.strip_prefix('P') {
        return parse_iso_duration(iso)
            .ok_or_else(|| ValueError::Syntax(format!("`{t}` is not an ISO 8601 duration")));
    }
    let (num, unit) = split_number(t);
    let n: f64 = num.parse().map_err(|_| {
        ValueError::Syntax(format!(
            "`{t}` is not a duration (write e.g. `10ms`, `1.5s` or `PT0.04S`)"
        ))
    })?;
    if unit.is_empty() {
        return Err(ValueError::Syntax(format!(
            "`{t}` needs a unit (`ms`, `s`, `us`, …)"
        )));
    }
    let u = parse_unit(unit).map_err(|e| ValueError::Syntax(format!("`{t}`: {e}")))?;
    if u.dimension != [0, 0, 1, 0, 0, 0, 0, 0] {
        return Err(ValueError::WrongDimension(format!(
            "`{unit}` is not a unit of time"
        )));
    }
    let s = n * u.scale;
    if !s.is_finite() || s < 0.0 {
        return Err(ValueError::Syntax(format!(
            "`{t}` is not a non-negative duration"
        )));
    }
    Ok(s)
}

fn parse_iso_duration(s: &str) -> Option<f64> {
    let (date, time) = match s.split_once('T') {
        Some((d, t)) => (d, Some(t)),
        None => (s, None),
    };
    let mut total = 0.0;
    let mut any = false;
    let mut take = |part: &str, units: &[(char, f64)]| -> Option<()> {
        let mut num = String::new();
        let mut idx = 0;
        for c in part.chars() {
            if c.is_ascii_digit() || c == '.' {
                num.push(c);
            } else {
                let pos = units[idx..].iter().position(|(u, _)| *u == c)?;
                idx += pos + 1;
                total += num.parse::<f64>().ok()? * units[idx - 1].1;
                num.clear();
                any = true;
            }
        }
        num.is_empty().then_some(())
    };
    take(date, &[('D', 86400.0)])?;
    if let Some(t) = time {
        if t.is_empty() {
            return None;
        }
        take(t, &[('H', 3600.0), ('M', 60.0), ('S', 1.0)])?;
    }
    any.then_some(total)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::types::builtin;

    fn unit(s: &str) -> Unit {
        parse_unit(s).unwrap()
    }

    #[test]
    fn numbers_with_units_convert() {
        let f64t = builtin("f64").unwrap();
        match parse_value("15 cm", &f64t, Some(&unit("m"))) {
            Ok(Value::Float(v)) => assert!((v - 0.15).abs() < 1e-12),
            other => panic!("{other:?}"),
        }
        assert_eq!(
            parse_value("2", &f64t, Some(&unit("m"))),
            Ok(Value::Float(2.0))
        );
        assert!(matches!(
            parse_value("2 s", &f64t, Some(&unit("m"))),
            Err(ValueError::WrongDimension(_))
        ));
        assert!(matches!(
            parse_value("fast", &f64t, None),
            Err(ValueError::Syntax(_))
        ));
        assert!(matches!(
            parse_value("1e400", &f64t, None),
            Err(ValueError::Syntax(_))
        ));
        let u8t = builtin("u8").unwrap();
        assert_eq!(parse_value("255", &u8t, None), Ok(Value::Int(255)));
        assert!(parse_value("256", &u8t, None).is_err());
        assert!(parse_value("-1", &u8t, None).is_err());
        assert_eq!(
            parse_value("1.5 m", &builtin("i32").unwrap(), Some(&unit("mm"))),
            Ok(Value::Int(1500))
        );
    }

    /// Converted values are the numbers people write: before, `70 cm` in metres was
    /// `0.7000000000000001` (70 × 0.01) and printed so.
    #[test]
    fn converted_values_are_the_numbers_written() {
        let f64t = builtin("f64").unwrap();
        for (text, unit_text, want) in [
            ("70 cm", "m", 0.7),
            ("30 cm/s", "m/s", 0.3),
            ("15 cm", "m", 0.15),
            ("7 mm", "m", 0.007),
            ("1.5 m", "cm", 150.0),
            ("90 deg/s", "deg/s", 90.0),
        ] {
            assert_eq!(
                parse_value(text, &f64t, Some(&unit(unit_text))),
                Ok(Value::Float(want)),
                "{text} in {unit_text}"
            );
        }
        assert_eq!(format!("{}", scale(70.0, 0.01)), "0.7");
    }

    #[test]
    fn durations() {
        assert_eq!(parse_duration("10ms"), Ok(0.01));
        assert_eq!(parse_duration("PT0.04S"), Ok(0.04));
        assert_eq!(parse_duration("P1DT1M"), Ok(86460.0));
        assert!(parse_duration("10").is_err());
        assert!(parse_duration("10 m").is_err());
        assert!(parse_duration("PT").is_err());
        assert!(parse_duration("PTS").is_err());
        assert!(parse_duration("-1s").is_err());
    }

    #[test]
    fn arrays_need_their_length() {
        let t = crate::types::parse_type("f64[3]", &mut |_| None).unwrap();
        assert!(parse_value("1, 2, 3", &t, None).is_ok());
        assert!(parse_value("1 2", &t, None).is_err());
    }
}
