//! FINROC config files (`finroc_plugins_parameters` `tConfigFile`): a `<root>` of nested
//! `<node name>` branches and `<value name>` leaves. A value is text (`15 cm`), a list of
//! `<element>`s, or a lookup table: `<element>`s holding a `<key>` and a `<value>`. The
//! same file may configure plugins in `<runtime>`, which is not parameter data.

use crate::checks::f101_finroc_structure::CHECK;
use crate::finstructable::Named;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_diagnostics::source::FileId;
use ferroc_syntax::Element as Xml;

/// What a config entry holds.
#[derive(Clone, Debug)]
pub enum ConfigValue {
    Text(Named),
    List(Vec<Named>),
    /// Lookup table rows: (key, value).
    Table(Vec<(Named, Named)>),
}

/// One `<value>` leaf with its path (`/some structural element/destructive_collision_speed`).
#[derive(Clone, Debug)]
pub struct ConfigEntry {
    pub path: String,
    pub name: Named,
    pub value: ConfigValue,
}

#[derive(Clone, Debug)]
pub struct ConfigFile {
    pub file: FileId,
    pub entries: Vec<ConfigEntry>,
}

impl ConfigFile {
    /// The entry at a `config="/a/b"` path, as `tConfigFile` finds it (leading `/` optional).
    pub fn entry(&self, path: &str) -> Option<&ConfigEntry> {
        let want = normalise(path);
        self.entries.iter().find(|e| e.path == want)
    }
}

fn normalise(path: &str) -> String {
    let parts: Vec<&str> = path.split('/').filter(|s| !s.is_empty()).collect();
    format!("/{}", parts.join("/"))
}

/// Reads a parsed config file.
pub fn read(file: FileId, root: &Xml, out: &mut Diagnostics) -> ConfigFile {
    let mut entries = Vec::new();
    walk(root, "", &mut entries, out);
    ConfigFile { file, entries }
}

fn walk(e: &Xml, prefix: &str, entries: &mut Vec<ConfigEntry>, out: &mut Diagnostics) {
    for c in &e.children {
        match c.name.as_str() {
            "runtime" => {} // plugin configuration, not parameters
            "node" | "value" => {
                let Some(a) = c.attr("name") else {
                    out.push(
                        Diagnostic::new(&CHECK, c.name_span, format!("<{}> has no `name`", c.name))
                            .label("no parameter can refer to it")
                            .help("add `name=\"…\"`")
                            .severity(Severity::Warning),
                    );
                    continue;
                };
                let path = format!("{prefix}/{}", a.value);
                let name = Named {
                    text: a.value.to_string(),
                    span: a.value_span,
                };
                if c.name == "node" {
                    walk(c, &path, entries, out);
                } else {
                    entries.push(ConfigEntry {
                        path,
                        name,
                        value: value(c, out),
                    });
                }
            }
            _ => out.push(
                Diagnostic::new(
                    &CHECK,
                    c.name_span,
                    format!("<{}> is not part of a FINROC config file", c.name),
                )
                .label("FINROC's config file ignores it")
                .help("config files hold <node name> branches and <value name> leaves")
                .severity(Severity::Warning),
            ),
        }
    }
}

fn text(e: &Xml) -> Named {
    Named {
        text: e.text().trim().to_string(),
        span: if e.text().is_empty() {
            e.span
        } else {
            e.text_span()
        },
    }
}

fn value(v: &Xml, out: &mut Diagnostics) -> ConfigValue {
    let elements: Vec<&Xml> = v.children_named("element").collect();
    if elements.is_empty() {
        return ConfigValue::Text(text(v));
    }
    let keyed = elements
        .iter()
        .any(|e| e.children_named("key").next().is_some());
    if !keyed {
        return ConfigValue::List(elements.iter().map(|e| text(e)).collect());
    }
    let mut rows = Vec::new();
    for e in elements {
        match (
            e.children_named("key").next(),
            e.children_named("value").next(),
        ) {
            (Some(k), Some(val)) => rows.push((text(k), text(val))),
            _ => out.push(
                Diagnostic::new(
                    &CHECK,
                    e.name_span,
                    "lookup table row without both <key> and <value>",
                )
                .label("FINROC cannot read this row")
                .help("write `<element><key>…</key><value>…</value></element>`")
                .severity(Severity::Warning),
            ),
        }
    }
    ConfigValue::Table(rows)
}
