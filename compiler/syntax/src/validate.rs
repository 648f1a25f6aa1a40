//! Checks a parsed tree against the vocabulary: unknown, misplaced and duplicate things,
//! missing attributes, names and enumerated values. Also collects `<allow>` regions.

use super::vocabulary::{self, AttrKind, ElementSpec, COMMON_ATTRS, ROOT_ATTRS};
use super::xml::Element;
use crate::checks::*;
use ferroc_diagnostics::diagnostic::{did_you_mean, Diagnostic, Diagnostics};
use ferroc_diagnostics::source::Span;
use std::collections::hash_map::Entry;
use std::collections::{HashMap, HashSet};

/// `<allow code reason>`: silences `code` for findings inside `region`.
#[derive(Clone, Debug)]
pub struct AllowRegion {
    pub code: String,
    pub region: Span,
    pub span: Span,
}

/// Validates `root` as an element of context `key`.
///
/// A misspelt attribute is reported once (M103) and then read as the attribute it was
/// meant to be, when the element takes that attribute and does not have it yet:
/// `perod="40ms"` is one finding, not also "thread container has neither `period` nor
/// `trigger`", and `nme="x"` does not also lose the module and every path to it.
pub fn validate(
    root: &mut Element,
    key: &str,
    out: &mut Diagnostics,
    allows: &mut Vec<AllowRegion>,
) {
    let spec = vocabulary::spec(key);
    let mut stack: Vec<(&mut Element, &'static ElementSpec, bool)> = vec![(root, spec, true)];
    while let Some((element, spec, is_root)) = stack.pop() {
        check_attributes(element, spec, is_root, out);
        if !spec.text && !element.text().trim().is_empty() {
            out.push(
                Diagnostic::new(
                    &m105_misplaced_element::CHECK,
                    element.text_span(),
                    format!("<{}> holds no text", element.name),
                )
                .label("unexpected text")
                .help("remove the text, or put it in a `doc` attribute"),
            );
        }
        let mut keys = Vec::with_capacity(element.children.len());
        for child in &element.children {
            let key = vocabulary::child_key(spec, &child.name);
            match key {
                Some(_) => {
                    if child.name == "allow" {
                        if let (Some(code), Some(_)) = (child.value("code"), child.value("reason"))
                        {
                            allows.push(AllowRegion {
                                code: code.to_string(),
                                region: element.span,
                                span: child.value_span("code"),
                            });
                        }
                    }
                }
                None => out.push(unplaced(element, spec, child)),
            }
            keys.push(key);
        }
        for (child, key) in element.children.iter_mut().zip(keys) {
            if let Some(key) = key {
                stack.push((child, vocabulary::spec(key), false));
            }
        }
    }
}

fn unplaced(parent: &Element, spec: &ElementSpec, child: &Element) -> Diagnostic {
    let allowed: Vec<&str> = spec
        .children
        .iter()
        .map(|k| vocabulary::spec(k).tag)
        .collect();
    let list = if allowed.is_empty() {
        format!("<{}> takes no child elements", parent.name)
    } else {
        format!(
            "<{}> may contain {}",
            parent.name,
            allowed
                .iter()
                .map(|t| format!("<{t}>"))
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    if vocabulary::all_tags().any(|t| t == child.name) {
        Diagnostic::new(
            &m105_misplaced_element::CHECK,
            child.name_span,
            format!("<{}> cannot appear inside <{}>", child.name, parent.name),
        )
        .label("misplaced here")
        .secondary(parent.name_span, "in this element")
        .help(list)
    } else {
        let d = Diagnostic::new(
            &m102_unknown_element::CHECK,
            child.name_span,
            format!("unknown element <{}>", child.name),
        )
        .label("not an element of the model language");
        match did_you_mean(&child.name, allowed.iter().copied()) {
            Some(s) => d.help(format!("did you mean <{s}>?")),
            None => d.help(list),
        }
    }
}

fn check_attributes(
    element: &mut Element,
    spec: &ElementSpec,
    is_root: bool,
    out: &mut Diagnostics,
) {
    // One pass: the first occurrence of each repeated name, and which names of the
    // vocabulary the element has (a misspelt one is only read as a name it lacks), so an
    // element of 100,000 attributes is checked in linear time.
    let count = element.attrs().len();
    let mut first_of = vec![None; count];
    let mut present: HashSet<&'static str> = HashSet::new();
    {
        let mut seen: HashMap<&str, Span> = HashMap::with_capacity(count);
        for (i, attr) in element.attrs().enumerate() {
            match seen.entry(attr.name) {
                Entry::Occupied(first) => first_of[i] = Some(*first.get()),
                Entry::Vacant(slot) => {
                    slot.insert(attr.name_span);
                }
            }
            let known = spec.attrs.iter().map(|a| a.name);
            if let Some(name) = known
                .chain(COMMON_ATTRS.iter().copied())
                .find(|n| *n == attr.name)
            {
                present.insert(name);
            }
        }
    }
    for (i, first) in first_of.into_iter().enumerate() {
        let Some(attr) = element.attr_at(i) else {
            break;
        };
        if let Some(first) = first {
            out.push(
                Diagnostic::new(
                    &m106_duplicate_attribute::CHECK,
                    attr.name_span,
                    format!("attribute `{}` appears twice", attr.name),
                )
                .label("second occurrence")
                .secondary(first, "first occurrence")
                .help("keep one of them"),
            );
            continue;
        }
        let known = spec.attrs.iter().find(|a| a.name == attr.name);
        let Some(known) = known else {
            let free = COMMON_ATTRS.contains(&attr.name)
                || (is_root && (ROOT_ATTRS.contains(&attr.name) || attr.name.starts_with("xmlns")));
            if !free {
                let names = spec
                    .attrs
                    .iter()
                    .map(|a| a.name)
                    .chain(COMMON_ATTRS.iter().copied());
                let d = Diagnostic::new(
                    &m103_unknown_attribute::CHECK,
                    attr.name_span,
                    format!("<{}> has no attribute `{}`", element.name, attr.name),
                )
                .label("unknown attribute");
                let all: Vec<&str> = names.collect();
                let meant = did_you_mean(attr.name, all.iter().copied());
                // Read it as the attribute it was meant to be, if that one is free.
                let recovered = meant
                    .filter(|s| !present.contains(*s))
                    .and_then(|s| spec.attrs.iter().find(|a| a.name == s));
                out.push(match (meant, recovered) {
                    (Some(s), Some(_)) => d.help(format!(
                        "did you mean `{s}`? (the rest of the model is checked as if it were)"
                    )),
                    (Some(s), None) => d.help(format!("did you mean `{s}`?")),
                    (None, _) => d.help(format!("<{}> takes: {}", element.name, all.join(", "))),
                });
                if let Some(known) = recovered {
                    present.insert(known.name);
                    element.rename_attr(i, known.name);
                    if let Some(attr) = element.attr_at(i) {
                        check_value(element, &attr, known.kind, out);
                    }
                }
            }
            continue;
        };
        check_value(element, &attr, known.kind, out);
    }
    for required in spec.attrs.iter().filter(|a| a.required) {
        if element.attr(required.name).is_none() {
            out.push(
                Diagnostic::new(
                    &m104_missing_attribute::CHECK,
                    element.name_span,
                    format!("<{}> needs the attribute `{}`", element.name, required.name),
                )
                .label(format!("`{}` missing", required.name))
                .help(format!("add {}=\"…\"", required.name)),
            );
        }
    }
}

fn check_value(element: &Element, attr: &super::xml::Attr, kind: AttrKind, out: &mut Diagnostics) {
    let v = attr.value;
    let problem = match kind {
        AttrKind::Text => None,
        AttrKind::Ident => {
            if !vocabulary::is_identifier(v) {
                invalid_name(attr, out);
            }
            None
        }
        AttrKind::Bool => (!matches!(v, "true" | "false")).then(|| "`true` or `false`".to_string()),
        AttrKind::Count => match v.parse::<u32>() {
            Err(_) => Some("a non-negative whole number".to_string()),
            Ok(n) if element.name == "connect" && attr.name == "queue" => {
                if n > vocabulary::MAX_QUEUE {
                    queue_over_limit(attr, n, out);
                }
                None
            }
            Ok(n) if element.name == "port" && attr.name == "count" => {
                if n > vocabulary::MAX_GROUP_PORTS {
                    group_over_limit(attr, n, out);
                }
                None
            }
            Ok(_) => None,
        },
        AttrKind::Choice(options) => (!options.contains(&v)).then(|| {
            options
                .iter()
                .map(|o| format!("`{o}`"))
                .collect::<Vec<_>>()
                .join(", ")
        }),
    };
    if let Some(expected) = problem {
        invalid_value(element, attr, kind, &expected, out);
    }
}

/// M107: a name that is not an identifier, with one made of it.
#[cold]
fn invalid_name(attr: &super::xml::Attr, out: &mut Diagnostics) {
    let v = attr.value;
    let fixed: String = v
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    let fixed = if fixed.starts_with(|c: char| c.is_ascii_digit()) || fixed.is_empty() {
        format!("_{fixed}")
    } else {
        fixed
    };
    out.push(
        Diagnostic::new(
            &m107_invalid_name::CHECK,
            attr.value_span,
            format!("`{v}` is not a valid name"),
        )
        .label("names are identifiers: letters, digits and `_`, not starting with a digit")
        .help(format!("use `{fixed}`")),
    );
}

/// M116: a `queue="n"` over the limit.
#[cold]
fn queue_over_limit(attr: &super::xml::Attr, n: u32, out: &mut Diagnostics) {
    out.push(
        Diagnostic::new(
            &m116_limit_exceeded::CHECK,
            attr.value_span,
            format!(
                "a queue of {n} values is over the limit of {}",
                vocabulary::MAX_QUEUE
            ),
        )
        .label("too many values")
        .help(format!(
            "a queue is allocated in full when the run starts: give at most \
             queue=\"{}\" (a few values are usual)",
            vocabulary::MAX_QUEUE
        )),
    );
}

/// M116: a flexible port group's `count="n"` over the limit.
#[cold]
fn group_over_limit(attr: &super::xml::Attr, n: u32, out: &mut Diagnostics) {
    out.push(
        Diagnostic::new(
            &m116_limit_exceeded::CHECK,
            attr.value_span,
            format!(
                "a port group of {n} ports is over the limit of {}",
                vocabulary::MAX_GROUP_PORTS
            ),
        )
        .label("too many ports")
        .help(format!(
            "every port of a group is made when the module is created: give at most \
             count=\"{}\", or split the values over several modules or into a vector type",
            vocabulary::MAX_GROUP_PORTS
        )),
    );
}

/// M108: a value not of the attribute's kind (`expected` says what would be).
#[cold]
fn invalid_value(
    element: &Element,
    attr: &super::xml::Attr,
    kind: AttrKind,
    expected: &str,
    out: &mut Diagnostics,
) {
    let v = attr.value;
    let d = Diagnostic::new(
        &m108_invalid_attribute_value::CHECK,
        attr.value_span,
        format!(
            "`{v}` is not a valid value for `{}` of <{}>",
            attr.name, element.name
        ),
    )
    .label("invalid value");
    let suggestion = match kind {
        AttrKind::Choice(options) => {
            did_you_mean(v, options.iter().copied()).map(|s| format!("did you mean `{s}`?"))
        }
        _ => None,
    };
    out.push(d.help(suggestion.unwrap_or(format!("expected {expected}"))));
}
