//! Parameter declarations in manifests, and the value check they share with models' `<param>`s.

use super::ParamDecl;
use crate::checks::{p103_unparsable_value, p104_out_of_range};
use crate::library::{unit_attr, LibraryId, LibrarySet};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_diagnostics::source::Span;
use ferroc_syntax::Element;
use ferroc_values::types::Type;
use ferroc_values::values::{parse_value, Value};

pub(super) fn param_decl(
    set: &LibrarySet,
    visible: &[LibraryId],
    e: &Element,
    diags: &mut Diagnostics,
) -> Option<ParamDecl> {
    let name = e.value("name")?;
    let ty = set.resolve_type(e.value("type")?, e.value_span("type"), visible, diags)?;
    let unit = unit_attr(e, diags);
    // Bounds are values of the parameter's type: `15 cm`, `10ms` and plain numbers work.
    let mut bound = |attr: &str| -> Option<f64> {
        let a = e.attr(attr)?;
        match parse_value(a.value, &ty, unit.as_ref()) {
            Ok(Value::Int(i)) => Some(i as f64),
            Ok(Value::Float(f)) => Some(f),
            Ok(Value::Duration(s)) => Some(s),
            _ => {
                diags.push(
                    Diagnostic::new(&p103_unparsable_value::CHECK, a.value_span, format!("`{}` is not a number of type `{ty}`", a.value))
                        .label(format!("`{attr}` must be a number in the parameter's type and unit"))
                        .help("write a plain number, or a number with a unit of the parameter's dimension"),
                );
                None
            }
        }
    };
    let min = bound("min");
    let max = bound("max");
    let decl = ParamDecl {
        name: name.to_string(),
        ty,
        unit,
        min,
        max,
        default: e.value("default").map(str::to_string),
        required: e.value("required") == Some("true"),
        choices: e
            .value("choices")
            .map(|c| c.split_whitespace().map(str::to_string).collect())
            .unwrap_or_default(),
        nondeterministic_value: nondeterministic_value(e),
        span: e.value_span("name"),
    };
    if let Some(default) = e.attr("default") {
        check_value(&decl, default.value, default.value_span, None, diags);
    }
    Some(decl)
}

/// The value at which the parameter makes its module read the wall clock or the OS's
/// randomness: `nondeterministic-value`, else a `doc` that documents 0 that way ("0
/// seeds from the system clock", "0 = from the clock", "0: random seed from the OS's
/// entropy"): the word `0` and one of clock, entropy, system time, urandom.
fn nondeterministic_value(e: &Element) -> Option<(String, Span)> {
    if let Some(a) = e.attr("nondeterministic-value") {
        return Some((a.value.trim().to_string(), a.value_span));
    }
    let doc = e.attr("doc")?;
    let text = doc.value.to_ascii_lowercase();
    let zero = text
        .split(|c: char| !c.is_ascii_alphanumeric() && c != '.')
        .any(|w| w == "0");
    let source = ["clock", "entropy", "system time", "urandom"]
        .iter()
        .any(|w| text.contains(w));
    (zero && source).then(|| ("0".to_string(), doc.value_span))
}

/// Parses a value for a parameter and checks choices and range. Shared by defaults in
/// manifests and `<param>` values in models. Returns the value when it is acceptable.
pub fn check_value(
    decl: &ParamDecl,
    text: &str,
    span: Span,
    context: Option<Span>,
    diags: &mut Diagnostics,
) -> Option<Value> {
    use crate::checks::p105_wrong_unit_dimension;
    if !decl.choices.is_empty() && !decl.choices.iter().any(|c| c == text.trim()) {
        diags.push(with_context(
            Diagnostic::new(
                &p103_unparsable_value::CHECK,
                span,
                format!(
                    "`{}` is not one of the choices of `{}`",
                    text.trim(),
                    decl.name
                ),
            )
            .label("not a valid choice")
            .help(format!("use one of: {}", decl.choices.join(", "))),
            context,
        ));
        return None;
    }
    match parse_value(text, &decl.ty, decl.unit.as_ref()) {
        Ok(value) => {
            let number = match &value {
                Value::Int(i) => Some(*i as f64),
                Value::Float(f) => Some(*f),
                Value::Duration(s) => Some(*s),
                _ => None,
            };
            match number {
                Some(n) if !in_range(decl, text, n, span, context, diags) => None,
                _ => Some(value),
            }
        }
        Err(ferroc_values::values::ValueError::Syntax(msg)) => {
            diags.push(with_context(
                Diagnostic::new(
                    &p103_unparsable_value::CHECK,
                    span,
                    format!("invalid value for `{}`: {msg}", decl.name),
                )
                .label(format!("expected a `{}`", decl.ty))
                .help(match &decl.unit {
                    Some(u) => format!(
                        "write a `{}` value, optionally with a unit of the same dimension as `{u}`",
                        decl.ty
                    ),
                    None => format!("write a `{}` value", decl.ty),
                }),
                context,
            ));
            None
        }
        Err(ferroc_values::values::ValueError::WrongDimension(msg)) => {
            diags.push(with_context(
                Diagnostic::new(
                    &p105_wrong_unit_dimension::CHECK,
                    unit_span(text, span),
                    format!("wrong unit for `{}`: {msg}", decl.name),
                )
                .label("unit of another dimension")
                .help(match &decl.unit {
                    Some(u) => format!("write the value in `{u}` or a unit of the same dimension"),
                    None => "write the value without a unit".to_string(),
                }),
                context,
            ));
            None
        }
    }
}

/// The span of the unit in the value `text` written at `span` (`s` of `0.3 s`): the
/// part a wrong-unit finding is about. When `span` is not the text itself (a value
/// from a config file, entities in it) it stays as it is.
fn unit_span(text: &str, span: Span) -> Span {
    let (_, unit) = ferroc_values::values::split_number(text);
    let written = (span.end - span.start) as usize;
    if unit.is_empty() || written != text.len() {
        return span;
    }
    // The unit ends the trimmed text.
    let start = span.start + (text.trim_end().len() - unit.len()) as u32;
    Span {
        file: span.file,
        start,
        end: start + unit.len() as u32,
    }
}

/// Points a finding at the parameter's declaration too, when it is elsewhere.
fn with_context(d: Diagnostic, context: Option<Span>) -> Diagnostic {
    match context {
        Some(c) => d.secondary(c, "the parameter is declared here"),
        None => d,
    }
}

/// Whether the number `n` (the value `text`) lies within the declaration's bounds,
/// and within 0..=1 for a meta signal; reports it when not.
fn in_range(
    decl: &ParamDecl,
    text: &str,
    n: f64,
    span: Span,
    context: Option<Span>,
    diags: &mut Diagnostics,
) -> bool {
    let below = decl.min.filter(|m| n < *m);
    let above = decl.max.filter(|m| n > *m);
    if below.is_some() || above.is_some() {
        // Durations are compared in seconds; say so.
        let unit = match (&decl.unit, &decl.ty) {
            (Some(u), _) => format!(" {u}"),
            (None, Type::Duration) => " s".to_string(),
            _ => String::new(),
        };
        let written = text.trim();
        let value = if written == format!("{n}{unit}") || written == n.to_string() {
            format!("{n}{unit}")
        } else {
            format!("`{written}` (= {n}{unit})")
        };
        let range = match (decl.min, decl.max) {
            (Some(a), Some(b)) => format!("{a}{unit} ..= {b}{unit}"),
            (Some(a), None) => format!(">= {a}{unit}"),
            (None, Some(b)) => format!("<= {b}{unit}"),
            _ => String::new(),
        };
        diags.push(with_context(
            Diagnostic::new(
                &p104_out_of_range::CHECK,
                span,
                format!("{value} is outside the range of `{}` ({range})", decl.name),
            )
            .label(if below.is_some() {
                "too small"
            } else {
                "too large"
            })
            .help(format!("use a value in {range}")),
            context,
        ));
        return false;
    }
    if matches!(decl.ty, Type::Meta(_)) && !(0.0..=1.0).contains(&n) {
        use crate::checks::b101_meta_constant_out_of_range as b101;
        diags.push(b101::report(decl, text, n, span, context));
        return false;
    }
    true
}
