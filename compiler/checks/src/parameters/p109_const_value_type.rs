//! P109 `const-value-type`: A Const value does not fit its output's declared type.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_model::ir::ElementKind;
use ferroc_model::library::module_type::{PortDir, PortType};
use ferroc_model::library::LibrarySet;
use ferroc_values::types::{NamedTypeId, Type};
use serde_json::Value;
use std::ops::Range;

pub static CHECK: CheckInfo = CheckInfo {
    code: "P109",
    name: "const-value-type",
    severity: Severity::Error,
    summary: "A Const value does not fit its output's declared type.",
    explanation: "`ferroc_std.Const` publishes the values of its `values` parameter, a JSON array
with one value per declared output, each in the serde form of the output's type: a
number for `f64`, an integer in range for `i32` or `u8`, `true`/`false` for `bool`, a
string for `string`, an array of exactly N values for `f64[N]`, any length for `[f64]`,
an object with the manifest's fields for a library struct (`{\"x\": 1.0, \"y\": 2.0}`).
The module refuses a value that does not fit when it is created; the check finds it
before a run, at the value.

Bad:
    <port name=\"out\" dir=\"out\" type=\"f64[3]\" count=\"1\"/>
    <param name=\"values\">[[1.0, 2.0]]</param>     <!-- two numbers for f64[3] -->

Fix:
    <param name=\"values\">[[1.0, 2.0, 0.0]]</param>",
    fixtures: "compiler/checks/src/parameters/p109_const_value_type",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for pt in super::texts_of(ctx, "ferroc_std.Const", "values") {
        let (id, p, text) = (pt.id, pt.param, pt.text);
        let at = |r| pt.span_of(r);
        let ElementKind::Module(inst) = &ctx.app.element(id).kind else {
            continue;
        };
        let outputs: Vec<_> = (inst.extra_ports.iter())
            .filter(|d| d.dir == PortDir::Out)
            .collect();
        let parsed: Result<Vec<Value>, _> = serde_json::from_str(text);
        let (Ok(values), Some(items)) = (parsed, elements(text)) else {
            out.push(
                Diagnostic::new(&CHECK, p.span, "`values` is not a JSON array")
                    .label("not a JSON array of values")
                    .help("write one value per output in a JSON array, e.g. [1.5, [1, 2, 3]]"),
            );
            continue;
        };
        if values.len() != outputs.len() || items.len() != values.len() {
            out.push(
                Diagnostic::new(
                    &CHECK,
                    p.span,
                    format!("{} value(s) for {} output(s)", values.len(), outputs.len()),
                )
                .label("one value per output")
                .help("give exactly one value per declared output, in the order they are declared"),
            );
            continue;
        }
        for ((value, range), decl) in values.iter().zip(items).zip(outputs) {
            let PortType::Fixed(ty) = &decl.ty else {
                continue;
            };
            if let Err(why) = fits(ctx.libraries, value, ty) {
                let shown = &text[range.clone()];
                out.push(
                    Diagnostic::new(
                        &CHECK,
                        at(range),
                        format!(
                            "the value `{}` of output `{}` is not a `{ty}`: {why}",
                            short(shown),
                            decl.name
                        ),
                    )
                    .label(format!("not a `{ty}`"))
                    .secondary(decl.span, format!("`{}` declared as `{ty}` here", decl.name))
                    .help(format!("write a value of `{ty}` in its serde form, or declare the output with the type of this value")),
                );
            }
        }
    }
}

/// At most 40 characters of a value, for the message.
fn short(text: &str) -> String {
    match text.char_indices().nth(40) {
        Some((at, _)) => format!("{}…", &text[..at]),
        None => text.to_owned(),
    }
}

/// Why `value` is not of type `ty` in serde's JSON form (what the runtime's
/// `from_json` would refuse); `Ok` when it fits or cannot be known (a library type
/// whose manifest lists no fields).
fn fits(libs: &LibrarySet, value: &Value, ty: &Type) -> Result<(), String> {
    let kind = || kind_of(value);
    match ty {
        Type::Bool => value
            .is_boolean()
            .then_some(())
            .ok_or_else(|| format!("{} where `true` or `false` is needed", kind())),
        Type::String => value
            .is_string()
            .then_some(())
            .ok_or_else(|| format!("{} where a string is needed", kind())),
        Type::Float { .. } | Type::Meta(_) => value
            .is_number()
            .then_some(())
            .ok_or_else(|| format!("{} where a number is needed", kind())),
        Type::Int { signed, bits } => int_fits(value, *signed, *bits),
        Type::Duration => fields(
            libs,
            value,
            &[
                (
                    "secs",
                    &Type::Int {
                        signed: false,
                        bits: 64,
                    },
                ),
                (
                    "nanos",
                    &Type::Int {
                        signed: false,
                        bits: 32,
                    },
                ),
            ],
        ),
        Type::Timestamp => fields(
            libs,
            value,
            &[(
                "nanos",
                &Type::Int {
                    signed: true,
                    bits: 64,
                },
            )],
        ),
        Type::Array(e, n) => {
            let Value::Array(items) = value else {
                return Err(format!("{} where an array of {n} is needed", kind()));
            };
            if items.len() != *n as usize {
                return Err(format!("{} element(s) where {n} are needed", items.len()));
            }
            elements_fit(libs, items, e)
        }
        Type::Seq(e) => match value {
            Value::Array(items) => elements_fit(libs, items, e),
            _ => Err(format!("{} where an array is needed", kind())),
        },
        Type::Named(id, name) => named_fits(libs, value, *id, name),
    }
}

/// What a JSON value is, for a message (`a string`).
fn kind_of(value: &Value) -> &'static str {
    match value {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// Whether `value` is a whole number in the range of the integer type.
fn int_fits(value: &Value, signed: bool, bits: u8) -> Result<(), String> {
    let Value::Number(n) = value else {
        return Err(format!("{} where an integer is needed", kind_of(value)));
    };
    let (min, max): (i128, i128) = match (signed, bits.min(64)) {
        (true, b) => (-(1i128 << (b - 1)), (1i128 << (b - 1)) - 1),
        (false, b) => (0, (1i128 << b) - 1),
    };
    let whole = n.as_i64().map(i128::from).or(n.as_u64().map(i128::from));
    match whole {
        None => Err(format!("{n} is not a whole number")),
        Some(v) if v < min || v > max => Err(format!("{v} lies outside {min}..={max}")),
        Some(_) => Ok(()),
    }
}

/// Whether `value` fits a library type by the fields its manifest lists.
fn named_fits(libs: &LibrarySet, value: &Value, id: NamedTypeId, name: &str) -> Result<(), String> {
    let named = libs.named_type(id);
    if !named.serde {
        return Err(format!("`{name}` has no serde form (its manifest says serde=\"false\"), so no value can be given"));
    }
    if named.fields.is_empty() {
        return Ok(()); // opaque to the manifest
    }
    let declared: Vec<(&str, &Type)> = (named.fields.iter())
        .map(|(f, t, _)| (f.as_str(), t))
        .collect();
    fields(libs, value, &declared)
}

fn elements_fit(libs: &LibrarySet, items: &[Value], e: &Type) -> Result<(), String> {
    for (i, item) in items.iter().enumerate() {
        fits(libs, item, e).map_err(|why| format!("element {i}: {why}"))?;
    }
    Ok(())
}

/// A struct in serde's JSON form: an object with every field (others are ignored, as
/// serde does), or an array of the fields in order.
fn fields(libs: &LibrarySet, value: &Value, declared: &[(&str, &Type)]) -> Result<(), String> {
    match value {
        Value::Object(map) => {
            for (name, ty) in declared {
                let Some(v) = map.get(*name) else {
                    let names: Vec<&str> = declared.iter().map(|(n, _)| *n).collect();
                    return Err(format!(
                        "the field `{name}` is missing (fields: {})",
                        names.join(", ")
                    ));
                };
                fits(libs, v, ty).map_err(|why| format!("field `{name}`: {why}"))?;
            }
            Ok(())
        }
        Value::Array(items) if items.len() == declared.len() => {
            for (v, (name, ty)) in items.iter().zip(declared) {
                fits(libs, v, ty).map_err(|why| format!("field `{name}`: {why}"))?;
            }
            Ok(())
        }
        _ => {
            let names: Vec<&str> = declared.iter().map(|(n, _)| *n).collect();
            Err(format!(
                "an object with the fields {} is needed",
                names.join(", ")
            ))
        }
    }
}

/// The byte ranges of the top-level elements of the JSON array `text` (already known
/// to parse): split at the commas outside strings and nested brackets.
fn elements(text: &str) -> Option<Vec<Range<usize>>> {
    let open = text.find('[')?;
    let (mut depth, mut in_string, mut escaped) = (0usize, false, false);
    let mut out = Vec::new();
    let mut start = open + 1;
    for (i, c) in text.char_indices().skip_while(|(i, _)| *i <= open) {
        if in_string {
            match (escaped, c) {
                (true, _) => escaped = false,
                (false, '\\') => escaped = true,
                (false, '"') => in_string = false,
                _ => {}
            }
            continue;
        }
        match c {
            '"' => in_string = true,
            '[' | '{' => depth += 1,
            ']' | '}' if depth > 0 => depth -= 1,
            ',' | ']' if depth == 0 => {
                let item = trimmed(text, start..i);
                if !item.is_empty() {
                    out.push(item);
                }
                if c == ']' {
                    return Some(out);
                }
                start = i + 1;
            }
            _ => {}
        }
    }
    None
}

/// `range` without the whitespace around it.
fn trimmed(text: &str, range: Range<usize>) -> Range<usize> {
    let slice = &text[range.clone()];
    let lead = slice.len() - slice.trim_start().len();
    let trail = slice.len() - slice.trim_end().len();
    range.start + lead..range.end - trail
}

#[cfg(test)]
mod tests {
    use super::elements;

    #[test]
    fn elements_split_outside_strings_and_brackets() {
        let text = r#" [1.5, [1, 2], {"a": [3, 4]}, "x, ]\" y", true ] "#;
        let items: Vec<&str> = elements(text)
            .unwrap()
            .into_iter()
            .map(|r| &text[r])
            .collect();
        assert_eq!(
            items,
            ["1.5", "[1, 2]", r#"{"a": [3, 4]}"#, r#""x, ]\" y""#, "true"]
        );
        assert_eq!(elements("[]").unwrap().len(), 0);
        assert_eq!(elements("[1"), None);
    }
}
