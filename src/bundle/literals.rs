//! Rust literals and calls as the generated code writes them: values that read back
//! exactly, durations with the shortest constructor, calls laid out as rustfmt does.

use super::code::LIST_WIDTH;
use super::text::rust_str;
use ferroc_compiler::values::Value;
use std::time::Duration;

/// `head(args)` (a tuple without head) on one line when it is short enough for rustfmt
/// (`fn_call_width`), else one argument a line.
pub(super) fn call(head: &str, args: &[String]) -> String {
    let one_line = format!("{head}({})", args.join(", "));
    if one_line.len() <= LIST_WIDTH && !one_line.contains('\n') {
        return one_line;
    }
    let mut out = format!("{head}(\n");
    for a in args {
        for l in format!("{a},").lines() {
            out.push_str("    ");
            out.push_str(l);
            out.push('\n');
        }
    }
    out.push(')');
    out
}

/// One entry of `ModuleSpec::ports`: `PortGroup::new("in", Direction::In, "f64", Some(3))`.
pub(super) fn port_group(g: &ferroc_compiler::plan::PlannedPortGroup) -> String {
    let dir = match g.dir {
        ferroc_compiler::library::PortDir::In => "Direction::In",
        ferroc_compiler::library::PortDir::Out => "Direction::Out",
    };
    let count = g.count.map_or("None".to_string(), |n| format!("Some({n})"));
    call(
        "PortGroup::new",
        &[rust_str(&g.name), dir.to_string(), rust_str(&g.ty), count],
    )
}

/// The Rust expression of a parameter value (the conversion `ferroc run` makes).
pub(super) fn value(v: &Value, uses_duration: &mut bool) -> String {
    match v {
        Value::Bool(b) => format!("Value::Bool({b})"),
        Value::Int(i) if *i == i128::MIN => "Value::Int(i128::MIN)".into(),
        Value::Int(i) => format!("Value::Int({i})"),
        Value::Float(x) => format!("Value::Float({})", float(*x)),
        Value::Str(s) | Value::Opaque(s) => format!("Value::Text({}.to_string())", rust_str(s)),
        Value::Duration(s) => {
            *uses_duration = true;
            format!(
                "Value::Duration({})",
                duration(Duration::from_secs_f64(s.max(0.0)))
            )
        }
        Value::List(items) => {
            let items: Vec<String> = items.iter().map(|i| value(i, uses_duration)).collect();
            format!("Value::List(vec![{}])", items.join(", "))
        }
    }
}

/// An `f64` literal that reads back as exactly the same number.
pub(super) fn float(x: f64) -> String {
    if x.is_nan() {
        "f64::NAN".into()
    } else if x.is_infinite() {
        if x > 0.0 {
            "f64::INFINITY"
        } else {
            "f64::NEG_INFINITY"
        }
        .into()
    } else {
        format!("{x:?}")
    }
}

/// The shortest constructor that gives exactly `d`.
pub(super) fn duration(d: Duration) -> String {
    let nanos = d.as_nanos();
    if nanos.is_multiple_of(1_000_000_000) {
        format!("Duration::from_secs({})", d.as_secs())
    } else if nanos.is_multiple_of(1_000_000) {
        format!("Duration::from_millis({})", d.as_millis())
    } else if nanos.is_multiple_of(1_000) {
        format!("Duration::from_micros({})", d.as_micros())
    } else {
        format!("Duration::new({}, {})", d.as_secs(), d.subsec_nanos())
    }
}

pub(super) fn human_duration(seconds: f64) -> String {
    format!("{:?}", Duration::from_secs_f64(seconds))
}
