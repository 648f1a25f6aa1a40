//! Writes a library manifest from the module types its crate registers.
//!
//! The Rust code knows a module type's ports, parameters, kind, docs and Rust path; it
//! does not know the library's data types, its dependencies, budgets, how an input is
//! read (`read`, `timeout`, `fan-in`), services, locks or behaviour details. So the
//! export regenerates what the code declares and keeps everything else from the
//! manifest it replaces, verbatim (element text as written, comments inside kept
//! elements included). Module types without Rust code in this binary are kept whole.

use ferroc_compiler::library::Library;
use ferroc_compiler::source::SourceMap;
use ferroc_compiler::syntax::xml::Element;
use ferroc_runtime::module::{Direction, Interface, Kind, ParamInfo, PortInfo, Role};
use std::fmt::Write;

/// Port attributes only a manifest can say; copied from the manifest's port.
const MANIFEST_PORT_ATTRS: &[&str] = &["read", "timeout", "fan-in"];
/// Parameters every behaviour (and fusion) has by its kind.
const IMPLIED_BEHAVIOUR_PARAMS: &[&str] =
    &["stimulation_mode", "inhibitions", "channels", "method"];
/// Module-type children only a manifest can say; copied verbatim.
const MANIFEST_CHILDREN: &[&str] = &[
    "service",
    "client",
    "locks",
    "derived-activity",
    "channel-in",
    "activity",
];

/// The manifest text of library `name`. `existing` is kept byte for byte (comments and
/// layout included) except the module types in `rewrite`, which are regenerated from
/// their code in place or, when the manifest lacks them, appended. So a manifest that
/// agrees with the code exports to itself.
pub fn library_xml(
    name: &str,
    rewrite: &[&Interface],
    existing: Option<(&Library, &SourceMap)>,
) -> String {
    let Some((lib, sources)) = existing.filter(|(lib, _)| !lib.root().children.is_empty()) else {
        return new_library(name, rewrite);
    };
    let root = lib.root();
    let text = &sources.get(lib.file).text;
    let mut out = String::new();
    let mut at = 0usize;
    let mut written = vec![false; rewrite.len()];
    for child in &root.children {
        let target = (child.name == "module-type")
            .then(|| child.value("name"))
            .flatten()
            .and_then(|n| rewrite.iter().position(|t| bare(&t.name) == n));
        let Some(i) = target else { continue };
        out.push_str(&text[at..child.span.start as usize]);
        module_type(&mut out, rewrite[i], Some((child, sources)));
        at = child.span.end as usize;
        written[i] = true;
    }
    let last = root.children.last().map_or(0, |c| c.span.end as usize);
    out.push_str(&text[at..last.max(at)]);
    for (t, done) in rewrite.iter().zip(written) {
        if !done {
            out.push_str(
                "

  ",
            );
            module_type(&mut out, t, None);
        }
    }
    out.push_str(&text[last.max(at)..]);
    out
}

/// A manifest for a library that has none yet: its module types only.
fn new_library(name: &str, types: &[&Interface]) -> String {
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    out.push_str(
        "<!--\n  Written by `ferroc types export` from the module types its crate registers.\n  \
         Add the library's data types, dependencies and budgets by hand.\n-->\n<library",
    );
    attr(&mut out, "name", name);
    out.push_str(">\n");
    for t in types {
        out.push_str("  ");
        module_type(&mut out, t, None);
        out.push('\n');
    }
    out.push_str("</library>\n");
    out
}

/// The library a qualified type name belongs to (`crash_course.AddNoise` → `crash_course`).
pub fn library_of(qualified: &str) -> &str {
    qualified.split_once('.').map_or(qualified, |(lib, _)| lib)
}

fn bare(qualified: &str) -> &str {
    qualified.split_once('.').map_or(qualified, |(_, t)| t)
}

fn module_type(out: &mut String, t: &Interface, old: Option<(&Element, &SourceMap)>) {
    let old_el = old.map(|(e, _)| e);
    out.push_str("<module-type");
    attr(out, "name", bare(&t.name));
    let kind = match t.kind {
        Kind::SenseControl => Some("sense-control"),
        Kind::Behaviour => Some("behaviour"),
        Kind::Fusion => Some("fusion"),
        Kind::Plain => None,
    };
    let behaviour = matches!(t.kind, Kind::Behaviour | Kind::Fusion);
    if let Some(k) = kind {
        attr(out, "kind", k);
    }
    // The manifest may name a re-export (`crate::Type` for `crate::module::Type`).
    let rust = match old_el.and_then(|e| e.value("rust")) {
        Some(r) if same_item(r, &t.rust) => r,
        _ => &t.rust,
    };
    attr(out, "rust", rust);
    if let Some(b) = old_el.and_then(|e| e.value("budget")) {
        attr(out, "budget", b);
    }
    doc(out, t.doc.as_deref(), old_el);
    out.push_str(">\n");
    // Flexible groups first, as manifests declare them before the `$group` ports.
    for f in &t.flexible {
        out.push_str("    <flexible");
        attr(out, "port", &f.group);
        attr(
            out,
            "dir",
            if f.dir == Direction::In { "in" } else { "out" },
        );
        attr(out, "same-type", if f.same_type { "true" } else { "false" });
        if f.min_count > 0 {
            attr(out, "min-count", &f.min_count.to_string());
        }
        if let Some(max) = f.max_count {
            attr(out, "max-count", &max.to_string());
        }
        out.push_str("/>\n");
    }
    // What the behaviour kind implies is not written: the compiler adds it (meta ports,
    // per-instance ports such as `inhibition/k` and `in/k/…`, and the kind's parameters).
    for p in t
        .ports
        .iter()
        .filter(|p| p.role != Role::Meta && !p.name.contains('/'))
    {
        let old_port = old_el.and_then(|e| {
            e.children
                .iter()
                .find(|c| c.name != "param" && c.value("name") == Some(&p.name))
        });
        port(out, p, old_port);
    }
    for p in t
        .params
        .iter()
        .filter(|p| !(behaviour && IMPLIED_BEHAVIOUR_PARAMS.contains(&p.name.as_str())))
    {
        let old_param = old_el.and_then(|e| {
            e.children
                .iter()
                .find(|c| c.name == "param" && c.value("name") == Some(&p.name))
        });
        param(out, p, old_param);
    }
    if let Some((e, sources)) = old {
        for c in e
            .children
            .iter()
            .filter(|c| MANIFEST_CHILDREN.contains(&c.name.as_str()))
        {
            verbatim(out, c, sources, "    ");
        }
    }
    out.push_str("  </module-type>");
}

fn port(out: &mut String, p: &PortInfo, old: Option<&Element>) {
    let _ = write!(out, "    <{}", p.role.element(p.dir));
    attr(out, "name", &p.name);
    attr(out, "type", &p.model_type);
    if let Some(u) = &p.unit {
        attr(out, "unit", u);
    }
    if p.required && p.dir == Direction::In {
        attr(out, "required", "true");
    }
    if let Some(old) = old {
        for name in MANIFEST_PORT_ATTRS {
            if let Some(v) = old.value(name) {
                attr(out, name, v);
            }
        }
    }
    doc(out, p.doc.as_deref(), old);
    out.push_str("/>\n");
}

/// The code's doc, else the manifest's (docs are written where people read them).
fn doc(out: &mut String, code: Option<&str>, old: Option<&Element>) {
    if let Some(d) = code.or(old.and_then(|e| e.value("doc"))) {
        attr(out, "doc", d);
    }
}

/// Same crate and same item name: one path is a re-export of the other.
fn same_item(a: &str, b: &str) -> bool {
    let ends = |p: &str| {
        (
            p.split("::").next().unwrap_or("").to_string(),
            p.rsplit("::").next().unwrap_or("").to_string(),
        )
    };
    ends(a) == ends(b)
}

fn param(out: &mut String, p: &ParamInfo, old: Option<&Element>) {
    out.push_str("    <param");
    attr(out, "name", &p.name);
    attr(out, "type", &p.model_type);
    if let Some(u) = &p.unit {
        attr(out, "unit", u);
    }
    if let Some(min) = p.min {
        attr(out, "min", &min.to_string());
    }
    if let Some(max) = p.max {
        attr(out, "max", &max.to_string());
    }
    if let Some(d) = &p.default {
        attr(out, "default", d);
    }
    if !p.choices.is_empty() {
        attr(out, "choices", &p.choices.join(" "));
    }
    doc(out, p.doc.as_deref(), old);
    out.push_str("/>\n");
}

/// An element as written in its manifest, re-indented to `indent`.
fn verbatim(out: &mut String, e: &Element, sources: &SourceMap, indent: &str) {
    out.push_str(indent);
    out.push_str(sources.text(e.span));
    out.push('\n');
}

/// ` name="value"` with the value escaped for an XML attribute (the compiler's one
/// escaper, `ferroc_compiler::syntax::escape`).
fn attr(out: &mut String, name: &str, value: &str) {
    let value = ferroc_compiler::syntax::escape::attr(value);
    let _ = write!(out, " {name}=\"{value}\"");
}

#[cfg(test)]
mod tests {
    use super::*;

    fn interface() -> Interface {
        Interface {
            name: "lib.Thing".into(),
            rust: "lib::Thing".into(),
            kind: Kind::Plain,
            doc: Some("a \"quoted\" <doc> & more".into()),
            ports: vec![PortInfo {
                name: "x".into(),
                dir: Direction::In,
                role: Role::Plain,
                model_type: "f64".into(),
                unit: Some("m/s".into()),
                required: true,
                doc: None,
            }],
            params: vec![ParamInfo {
                name: "gain".into(),
                model_type: "f64".into(),
                unit: None,
                min: Some(0.0),
                max: Some(2.5),
                default: Some("1".into()),
                choices: Vec::new(),
                doc: None,
            }],
            flexible: Vec::new(),
            services: Vec::new(),
        }
    }

    #[test]
    fn a_new_library_holds_exactly_the_code_s_declarations_escaped() {
        let xml = library_xml("lib", &[&interface()], None);
        assert!(xml.contains("<library name=\"lib\">"), "{xml}");
        assert!(xml.contains(
            "<module-type name=\"Thing\" rust=\"lib::Thing\" doc=\"a &quot;quoted&quot; &lt;doc&gt; &amp; more\">"
        ));
        assert!(xml.contains("<in name=\"x\" type=\"f64\" unit=\"m/s\" required=\"true\"/>"));
        assert!(
            xml.contains("<param name=\"gain\" type=\"f64\" min=\"0\" max=\"2.5\" default=\"1\"/>")
        );
        assert!(xml.ends_with("</library>\n"));
    }

    #[test]
    fn library_of_takes_the_prefix() {
        assert_eq!(library_of("crash_course.AddNoise"), "crash_course");
        assert_eq!(bare("crash_course.AddNoise"), "AddNoise");
    }
}
