//! Keeps the language reference, `docs/model-language.md`, true to the parser's
//! vocabulary table (`ELEMENTS`), as `schema_agreement.rs` keeps the XSDs.
//!
//! The reference has one section per context key: a heading naming the element's tag
//! (`` ### `<thread>` ``) and the key in an HTML comment (`<!-- key: thread -->`), then a
//! table of attributes (`` | `period` | no | duration | … | ``) and, for elements with
//! children, a line `Contains: <a>, <b>`. Compared: the keys (every element documented,
//! no section for an element that does not exist), the tag of each, the attribute names
//! and whether each is required, every value of a choice attribute named in its value
//! column, and the children's tags. All differences are reported in one message.

use ferroc_compiler::syntax::vocabulary::{spec, AttrKind, ElementSpec, ELEMENTS};
use std::collections::{BTreeMap, BTreeSet};

/// One documented element: its heading's tag, attributes (name → required, value
/// column) and children's tags.
#[derive(Default)]
struct Section {
    tag: String,
    attrs: BTreeMap<String, (bool, String)>,
    children: Option<BTreeSet<String>>,
}

/// The sections of the reference by key, and the problems of its form.
fn sections(text: &str, problems: &mut Vec<String>) -> BTreeMap<String, Section> {
    let mut out: BTreeMap<String, Section> = BTreeMap::new();
    let mut current: Option<String> = None;
    for (n, line) in text.lines().enumerate() {
        let at = n + 1;
        if line.starts_with('#') {
            current = None;
            let Some((_, rest)) = line.split_once("<!-- key: ") else {
                continue;
            };
            let key = rest.trim_end_matches("-->").trim().to_string();
            let tag = line
                .split_once("`<")
                .and_then(|(_, t)| t.split_once(">`"))
                .map(|(t, _)| t.to_string())
                .unwrap_or_default();
            if out.contains_key(&key) {
                problems.push(format!("line {at}: a second section for `{key}`"));
            }
            out.insert(
                key.clone(),
                Section {
                    tag,
                    ..Section::default()
                },
            );
            current = Some(key);
            continue;
        }
        let Some(section) = current.as_ref().and_then(|k| out.get_mut(k)) else {
            continue;
        };
        if let Some(rest) = line.strip_prefix("| `") {
            let cells: Vec<&str> = rest.split(" | ").collect();
            let name = cells[0].trim_end_matches('`').to_string();
            let required = match cells.get(1).map(|c| c.trim()) {
                Some("yes") => true,
                Some("no") => false,
                other => {
                    problems.push(format!("line {at}: `{name}` required is {other:?}"));
                    false
                }
            };
            let value = cells.get(2).copied().unwrap_or("").to_string();
            section.attrs.insert(name, (required, value));
        } else if let Some(rest) = line.strip_prefix("Contains: ") {
            let tags = rest
                .split("`<")
                .skip(1)
                .filter_map(|t| t.split_once(">`").map(|(t, _)| t.to_string()))
                .collect();
            section.children = Some(tags);
        }
    }
    out
}

/// What the reference says of `e` that the vocabulary does not (or the reverse).
fn compare(e: &ElementSpec, s: &Section, problems: &mut Vec<String>) {
    let key = e.key;
    if s.tag != e.tag {
        problems.push(format!(
            "`{key}`: the heading names `<{}>`, the tag is `<{}>`",
            s.tag, e.tag
        ));
    }
    for a in e.attrs {
        match s.attrs.get(a.name) {
            None => problems.push(format!("`{key}`: attribute `{}` is not documented", a.name)),
            Some((required, value)) => {
                if *required != a.required {
                    problems.push(format!(
                        "`{key}`: `{}` is {}required, the reference says otherwise",
                        a.name,
                        if a.required { "" } else { "not " }
                    ));
                }
                let values: &[&str] = match a.kind {
                    AttrKind::Choice(v) => v,
                    AttrKind::Bool => &["true", "false"],
                    _ => &[],
                };
                for v in values {
                    if !value.contains(&format!("`{v}`")) {
                        problems.push(format!(
                            "`{key}`: `{}` may be `{v}`, not documented",
                            a.name
                        ));
                    }
                }
            }
        }
    }
    for name in s.attrs.keys() {
        if !e.attrs.iter().any(|a| a.name == name) {
            problems.push(format!(
                "`{key}`: the reference names attribute `{name}`, which does not exist"
            ));
        }
    }
    let children: BTreeSet<String> = e.children.iter().map(|k| spec(k).tag.to_string()).collect();
    let documented = s.children.clone().unwrap_or_default();
    if children != documented {
        problems.push(format!(
            "`{key}`: contains {children:?}, the reference says {documented:?}"
        ));
    }
}

#[test]
fn the_language_reference_documents_exactly_the_vocabulary() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/model-language.md");
    let text = std::fs::read_to_string(path).expect("docs/model-language.md");
    let mut problems = Vec::new();
    let documented = sections(&text, &mut problems);
    for e in ELEMENTS {
        match documented.get(e.key) {
            Some(s) => compare(e, s, &mut problems),
            None => problems.push(format!("`{}` (`<{}>`) has no section", e.key, e.tag)),
        }
    }
    for key in documented.keys() {
        if !ELEMENTS.iter().any(|e| e.key == key) {
            problems.push(format!(
                "a section for `{key}`, which is no element of the language"
            ));
        }
    }
    assert!(
        problems.is_empty(),
        "docs/model-language.md and compiler/syntax/src/vocabulary.rs differ:\n{}",
        problems.join("\n")
    );
}

/// The comparison finds what it should: a missing attribute, an invented one, a wrong
/// requirement, an undocumented choice, a wrong list of children.
#[test]
fn the_comparison_reports_each_kind_of_difference() {
    let text = "### `<thread>` <!-- key: thread -->\n\
                | `name` | no | identifier | x |\n\
                | `colour` | no | text | x |\n\
                | `trigger` | no | `data` | x |\n\
                Contains: `<module>`\n";
    let mut problems = Vec::new();
    let s = sections(text, &mut problems);
    compare(spec("thread"), &s["thread"], &mut problems);
    let all = problems.join("\n");
    for expected in [
        "`name` is required",
        "attribute `period` is not documented",
        "attribute `colour`, which does not exist",
        "`trigger` may be `continuous`",
        "contains",
    ] {
        assert!(all.contains(expected), "{expected}: {all}");
    }
}
