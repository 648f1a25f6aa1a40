//! FINROC build descriptions (`make.xml`): targets and the `libs` between them.
//!
//! A `make.xml` has a `<targets>` root holding build targets: `<library>`, `<program>`,
//! `<testprogram>`, `<rrlib>`, `<finroclibrary>`, `<finrocplugin>`, `<finrocprogram>`, their
//! Java variants and more. Each target has `name`, `libs` and `optionallibs` (as
//! attributes, or as child elements with the same name), plus `<sources>` and other
//! parameters that do not matter here. The vocabulary is open: unknown elements are
//! skipped, and targets are found at any depth, as FINROC's loader does.
//!
//! A `libs` entry is a local dependency when it equals the *reference name* of a target of
//! the same file — otherwise it names an external library (pkg-config, the library
//! database, another repository). Reference names follow FINROC's `make_builder`:
//!
//! - current rules (library file name without `lib` and extension): a library is
//!   `PREFIX` or `PREFIX_name`, a test program `PREFIX_test_name`, a unit test
//!   `PREFIX_unit_test_name`, a program just `name`; Java targets end in `.jar`. The
//!   prefix comes from where the file lives: `rrlib/x` → `rrlib_x`, `plugins/x` →
//!   `finroc_plugins_x`, `libraries/x` → `finroc_libraries_x`, `projects/x` →
//!   `finroc_projects_x`, `core` → `finroc_core` (see [`target_prefix`]);
//! - older rules, by name alone: `<rrlib name="x">` is `rrlib_x`, `<finroclibrary>`
//!   `finroc_x`, `<finrocplugin>` `finroc_plugin_x`, and the Java tags likewise with `.jar`.
//!
//! Matching is exact, as in FINROC: `rrlib-x` is not `rrlib_x`, and `<rrlib name="jni"
//! libs="jni">` depends on the system's `jni`, not on itself.

use ferroc_diagnostics::source::{FileId, Span};
use ferroc_syntax::Element;
use std::collections::HashMap;
use std::path::Path;

/// What a target builds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TargetKind {
    Library,
    Program,
    TestProgram,
    UnitTest,
}

/// One `libs` or `optionallibs` entry.
#[derive(Clone, Debug)]
pub struct LibRef {
    pub name: String,
    /// The name inside the attribute value (or element text); the whole value when the
    /// written text differs from the value (entities).
    pub span: Span,
    pub optional: bool,
}

/// One build target.
#[derive(Clone, Debug)]
pub struct Target {
    /// The element name as written: `rrlib`, `testprogram`, …
    pub tag: String,
    pub kind: TargetKind,
    pub name: Option<String>,
    /// The `name` value, or the tag name when there is none.
    pub span: Span,
    /// The names other targets use for it in `libs`, current rules first.
    pub reference_names: Vec<String>,
    /// `libs` entries, then `optionallibs` entries, each in written order.
    pub libs: Vec<LibRef>,
}

impl Target {
    /// How findings name the target: its first reference name, else its `name`, else its tag.
    pub fn display_name(&self) -> &str {
        self.reference_names
            .first()
            .or(self.name.as_ref())
            .unwrap_or(&self.tag)
    }
}

/// The targets of one `make.xml`.
#[derive(Clone, Debug)]
pub struct MakeFile {
    pub file: FileId,
    /// The FINROC target prefix of the file's folder, when its location tells it.
    pub prefix: Option<String>,
    pub targets: Vec<Target>,
    /// Each reference name to the first target that has it: [`MakeFile::resolve`] in
    /// constant time, so a file of many targets is checked in linear time.
    by_reference: HashMap<String, usize>,
}

impl MakeFile {
    /// The local target a `libs` entry refers to (the first one with that reference name).
    pub fn resolve(&self, lib: &str) -> Option<usize> {
        self.by_reference.get(lib).copied()
    }
}

/// (tag, kind, Java-only tag, older by-name prefix)
const TARGET_TAGS: &[(&str, TargetKind, bool, Option<&str>)] = &[
    ("library", TargetKind::Library, false, None),
    ("rrlib", TargetKind::Library, false, Some("rrlib_")),
    ("finroclibrary", TargetKind::Library, false, Some("finroc_")),
    (
        "finrocplugin",
        TargetKind::Library,
        false,
        Some("finroc_plugin_"),
    ),
    ("mcalibrary", TargetKind::Library, false, None),
    ("mcaplugin", TargetKind::Library, false, None),
    ("rrjavalib", TargetKind::Library, true, Some("rrlib_")),
    (
        "finrocjavalibrary",
        TargetKind::Library,
        true,
        Some("finroc_"),
    ),
    (
        "finrocjavaplugin",
        TargetKind::Library,
        true,
        Some("finroc_plugin_"),
    ),
    ("program", TargetKind::Program, false, None),
    ("finrocprogram", TargetKind::Program, false, None),
    ("mcaprogram", TargetKind::Program, false, None),
    ("finrocjavaprogram", TargetKind::Program, true, None),
    ("javaprogram", TargetKind::Program, true, None),
    ("testprogram", TargetKind::TestProgram, false, None),
    ("javatestprogram", TargetKind::TestProgram, true, None),
    ("unittest", TargetKind::UnitTest, false, None),
];

/// Reads the targets of a parsed `make.xml`. `prefix` is [`target_prefix`] of its path.
pub fn read(file: FileId, root: &Element, prefix: Option<&str>) -> MakeFile {
    let mut targets = Vec::new();
    collect(root, prefix, &mut targets);
    let mut by_reference = HashMap::new();
    for (i, t) in targets.iter().enumerate() {
        for r in &t.reference_names {
            by_reference.entry(r.clone()).or_insert(i);
        }
    }
    MakeFile {
        file,
        prefix: prefix.map(str::to_string),
        targets,
        by_reference,
    }
}

fn collect(element: &Element, prefix: Option<&str>, out: &mut Vec<Target>) {
    for child in &element.children {
        match TARGET_TAGS.iter().find(|t| t.0 == child.name) {
            Some(&(_, kind, java_tag, legacy)) => {
                out.push(target(child, kind, java_tag, legacy, prefix))
            }
            None => collect(child, prefix, out),
        }
    }
}

fn target(
    e: &Element,
    kind: TargetKind,
    java_tag: bool,
    legacy: Option<&str>,
    prefix: Option<&str>,
) -> Target {
    let name = param(e, "name")
        .map(|(v, _)| v.trim().to_string())
        .filter(|n| !n.is_empty());
    let span = param(e, "name").map_or(e.name_span, |(_, s)| s.whole);
    // FINROC decides Java by the source files.
    let java = java_tag || param(e, "sources").is_some_and(|(v, _)| v.contains(".java"));
    let jar = if java { ".jar" } else { "" };
    let suffix = name.as_ref().map(|n| format!("_{n}")).unwrap_or_default();
    let mut reference_names = Vec::new();
    match kind {
        TargetKind::Library => {
            if let (Some(p), false) = (prefix, java_tag) {
                reference_names.push(format!("{p}{suffix}{jar}"));
            }
            if let (Some(l), Some(n)) = (legacy, &name) {
                reference_names.push(format!("{l}{n}{jar}"));
            }
        }
        TargetKind::Program => reference_names.extend(name.as_ref().map(|n| format!("{n}{jar}"))),
        TargetKind::TestProgram => {
            reference_names.extend(prefix.map(|p| format!("{p}_test{suffix}{jar}")))
        }
        TargetKind::UnitTest => {
            reference_names.extend(prefix.map(|p| format!("{p}_unit_test{suffix}")))
        }
    }
    reference_names.retain(|r| !r.is_empty());
    reference_names.dedup();
    let mut libs = Vec::new();
    for (key, optional) in [("libs", false), ("optionallibs", true)] {
        if let Some((value, spans)) = param(e, key) {
            libs.extend(split_names(value, spans).map(|(name, span)| LibRef {
                name: name.to_string(),
                span,
                optional,
            }));
        }
    }
    Target {
        tag: e.name.to_string(),
        kind,
        name,
        span,
        reference_names,
        libs,
    }
}

/// Where a parameter's value is written.
#[derive(Clone, Copy)]
struct ValueSpans {
    whole: Span,
    /// Whether byte offsets into the value are offsets into the file from `whole.start`.
    exact: bool,
}

/// A target parameter: the child element of that name (FINROC lets it override the
/// attribute), else the attribute.
fn param<'a>(e: &'a Element, key: &str) -> Option<(&'a str, ValueSpans)> {
    if let Some(child) = e.children.iter().rfind(|c| c.name == key) {
        let whole = child.text_span();
        let exact = whole != child.span && (whole.end - whole.start) as usize == child.text().len();
        return Some((child.text(), ValueSpans { whole, exact }));
    }
    let attr = e.attr(key)?;
    let whole = attr.value_span;
    let exact = (whole.end - whole.start) as usize == attr.value.len();
    Some((attr.value, ValueSpans { whole, exact }))
}

/// The whitespace-separated names of a value, each with its own span when feasible.
fn split_names(value: &str, spans: ValueSpans) -> impl Iterator<Item = (&str, Span)> + '_ {
    value
        .split(|c: char| c.is_ascii_whitespace())
        .filter(|s| !s.is_empty())
        .map(move |name| {
            let span = if spans.exact {
                // `name` is a sub-slice of `value`: its offset is exact.
                let offset = name.as_ptr() as usize - value.as_ptr() as usize;
                let start = spans.whole.start as usize + offset;
                Span::new(spans.whole.file, start, start + name.len())
            } else {
                spans.whole
            };
            (name, span)
        })
}

/// The FINROC target prefix of a `make.xml` at `path` (see the module documentation), or
/// `None` when its location does not tell.
///
/// Inside a FINROC tree (`…/sources/cpp/rrlib/x/…`) the two folders after `sources/LANG`
/// decide. A repository cloned on its own is recognised by its folder name (`rrlib_x`,
/// `finroc_plugins_x`, `finroc_core`, also with `-java`). The nearest ancestor that tells wins.
pub fn target_prefix(path: &Path) -> Option<String> {
    let dirs: Vec<&str> = path
        .parent()?
        .components()
        .filter_map(|c| c.as_os_str().to_str())
        .collect();
    for i in (0..dirs.len()).rev() {
        if i >= 2 && dirs[i - 2] == "sources" {
            let second = dirs.get(i + 1).copied();
            return Some(match (dirs[i], second) {
                ("rrlib", Some(x)) => format!("rrlib_{x}"),
                ("plugins", Some(x)) => format!("finroc_plugins_{x}"),
                ("libraries", Some(x)) => format!("finroc_libraries_{x}"),
                ("projects", Some(x)) => format!("finroc_projects_{x}"),
                ("core", _) => "finroc_core".to_string(),
                _ => String::new(),
            });
        }
        let dir = dirs[i].strip_suffix("-java").unwrap_or(dirs[i]);
        if dir == "finroc_core" {
            return Some(dir.to_string());
        }
        let tail = [
            "rrlib_",
            "finroc_plugins_",
            "finroc_libraries_",
            "finroc_projects_",
        ]
        .iter()
        .find_map(|p| dir.strip_prefix(p));
        if tail.is_some_and(|t| !t.is_empty()) {
            return Some(dir.to_string());
        }
        if dir
            .strip_prefix("finroc_tools_")
            .is_some_and(|t| !t.is_empty())
        {
            // FINROC gives tools no prefix.
            return Some(String::new());
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use ferroc_syntax::xml::parse;

    fn make(text: &str, prefix: Option<&str>) -> MakeFile {
        read(FileId(0), &parse(FileId(0), text, 64).unwrap(), prefix)
    }

    #[test]
    fn prefixes_follow_finroc_layout_and_repository_names() {
        let p = |s: &str| target_prefix(Path::new(s));
        assert_eq!(
            p("/f/sources/cpp/rrlib/util/make.xml").as_deref(),
            Some("rrlib_util")
        );
        assert_eq!(
            p("/f/sources/cpp/rrlib/util/tests/make.xml").as_deref(),
            Some("rrlib_util")
        );
        assert_eq!(
            p("/f/sources/cpp/plugins/tcp/make.xml").as_deref(),
            Some("finroc_plugins_tcp")
        );
        assert_eq!(
            p("/f/sources/cpp/core/make.xml").as_deref(),
            Some("finroc_core")
        );
        assert_eq!(p("/f/sources/cpp/make.xml"), None);
        assert_eq!(p("/f/sources/cpp/tools/x/make.xml").as_deref(), Some(""));
        assert_eq!(
            p("rrlib_getopt/examples/make.xml").as_deref(),
            Some("rrlib_getopt")
        );
        assert_eq!(
            p("finroc_core-java/make.xml").as_deref(),
            Some("finroc_core")
        );
        assert_eq!(p("rrlib_/make.xml"), None);
        assert_eq!(p("/home/u/checks/libraries/l106/make.xml"), None);
        assert_eq!(p("make.xml"), None);
    }

    #[test]
    fn reference_names_by_current_and_older_rules() {
        let text = r#"<targets>
  <library libs="boost"><sources>a.cpp</sources></library>
  <rrlib name="jni" libs="jni"/>
  <library name="gui"><sources>X.java</sources></library>
  <testprogram name="t" libs="rrlib_x rrlib_x_jni"/>
  <finrocprogram name="p"/>
  <unittest/>
</targets>"#;
        let m = make(text, Some("rrlib_x"));
        let names: Vec<_> = m
            .targets
            .iter()
            .map(|t| t.reference_names.clone())
            .collect();
        assert_eq!(names[0], ["rrlib_x"]);
        assert_eq!(names[1], ["rrlib_x_jni", "rrlib_jni"]);
        assert_eq!(names[2], ["rrlib_x_gui.jar"]);
        assert_eq!(names[3], ["rrlib_x_test_t"]);
        assert_eq!(names[4], ["p"]);
        assert_eq!(names[5], ["rrlib_x_unit_test"]);
        assert_eq!(m.resolve("jni"), None);
        assert_eq!(m.resolve("rrlib_x"), Some(0));
        assert_eq!(m.resolve("rrlib_jni"), Some(1));
        let unknown = make(text, None);
        assert!(unknown.targets[0].reference_names.is_empty());
        assert_eq!(unknown.targets[1].reference_names, ["rrlib_jni"]);
        assert_eq!(unknown.targets[1].display_name(), "rrlib_jni");
    }

    #[test]
    fn every_name_in_a_list_has_its_own_span() {
        let text = "<targets>\n <rrlib name='a' libs=' x  yy\tz ' optionallibs='w'>\n  <libs>p &amp; q</libs>\n </rrlib>\n <rrlib name='b' libs='m\nn'/>\n <rrlib name='c' libs=' x  yy\tz '/>\n</targets>";
        let m = make(text, None);
        let at = |s: Span| &text[s.start as usize..s.end as usize];
        // The <libs> child wins over the attribute; its text has an entity: whole span.
        let a = &m.targets[0];
        assert_eq!(
            a.libs.iter().map(|l| l.name.as_str()).collect::<Vec<_>>(),
            ["p", "&", "q", "w"]
        );
        assert_eq!(at(a.libs[0].span), "p &amp; q");
        assert_eq!(at(a.libs[3].span), "w");
        assert!(a.libs[3].optional);
        let b = &m.targets[1];
        assert_eq!(at(b.span), "b");
        assert_eq!(
            b.libs.iter().map(|l| at(l.span)).collect::<Vec<_>>(),
            ["m", "n"]
        );
        let c = &m.targets[2];
        assert_eq!(
            c.libs.iter().map(|l| at(l.span)).collect::<Vec<_>>(),
            ["x", "yy", "z"]
        );
    }

    #[test]
    fn targets_are_found_inside_unknown_elements_and_others_skipped() {
        let m = make("<targets><group><rrlib name='a'/></group><whatever libs='x'/><root><node/></root></targets>", None);
        assert_eq!(m.targets.len(), 1);
        assert_eq!(m.targets[0].name.as_deref(), Some("a"));
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: 256, ..Default::default() })]

        /// Edited make files never panic the reader or the checks, and findings point inside.
        #[test]
        fn edited_make_files_never_panic(
            edits in proptest::collection::vec((0usize..2000, 0u8..3, 0usize..64), 1..6)
        ) {
            const SNIPPETS: &[&str] = &[" ", "&amp;", "rrlib_a", "finroc_b", "finroc_plugin_tcp", "\"", "<libs>", "</libs>", "é"];
            let mut text = include_str!("checks/l106_make_cycle/fires_2.xml").to_string();
            for (at, kind, pick) in edits {
                let mut at = at % text.len().max(1);
                while !text.is_char_boundary(at) {
                    at -= 1;
                }
                match kind {
                    0 => text.insert_str(at, SNIPPETS[pick % SNIPPETS.len()]),
                    1 => {
                        let mut end = (at + pick).min(text.len());
                        while !text.is_char_boundary(end) {
                            end -= 1;
                        }
                        text.replace_range(at..end, "");
                    }
                    _ => text.insert_str(at, " libs='finroc_a finroc_a' "),
                }
            }
            if let Ok(root) = parse(FileId(0), &text, 64) {
                let make = read(FileId(0), &root, Some("rrlib_x"));
                let mut out = ferroc_diagnostics::diagnostic::Diagnostics::default();
                crate::check_make(&make, &mut out);
                for d in &out.items {
                    for s in std::iter::once(&d.primary).chain(&d.secondary).map(|l| l.span) {
                        proptest::prop_assert!(s.start <= s.end && s.end as usize <= text.len());
                    }
                }
            }
        }
    }
}
