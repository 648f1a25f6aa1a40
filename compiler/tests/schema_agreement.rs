//! Keeps the XML Schemas in `schemas/` in agreement with the parser's vocabulary table,
//! `compiler/src/syntax/vocabulary.rs` (`ELEMENTS`).
//!
//! The schemas are read with ferroc's own XML parser, following `xs:include`/`xs:import`.
//! Every vocabulary context key is compared with its complexType `<key>Type` (the naming
//! convention of `schemas/README.md`): the child elements (tag, and the key their
//! `type="<key>Type"` names), the attribute names, `use="required"`, each attribute's
//! kind (identifier, count, plain text, enumeration values) and whether the element holds
//! text. Named types, `xs:extension` bases, `xs:group`/`xs:attributeGroup` references and
//! derived simple types are resolved, so an equivalent rewrite of a schema is no difference.
//! Also checked: the global elements are exactly the document roots, and no definition is
//! duplicated. (Unresolved references need no test here: `xmllint` in CI rejects them.)
//! All differences are reported in one message, one line each, starting with the file.

use ferroc_compiler::source::FileId;
use ferroc_compiler::syntax::vocabulary::{self, AttrKind, ElementSpec, COMMON_ATTRS, ELEMENTS};
use ferroc_compiler::syntax::xml::{self, Element};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The schemas documents are validated with; the other files are reached by includes.
const ENTRY_SCHEMAS: &[&str] = &["application.xsd", "library.xsd"];
/// The pattern of the `Ident` simple type (see `vocabulary::is_identifier`).
const IDENT_PATTERN: &str = "[A-Za-z_][A-Za-z0-9_]*";
/// Bounds reference chains, so that a cyclic schema is reported instead of followed forever.
const MAX_DEPTH: usize = 32;

/// What an attribute value may be, in terms both sides can express.
#[derive(Clone, Debug, PartialEq)]
enum Kind {
    Text,
    Ident,
    Count,
    /// `Bool` and `Choice` in the vocabulary; a list of `xs:enumeration`s in an XSD.
    Enum(BTreeSet<String>),
    /// Anything else an XSD can say (other built-in types or facets, lists, unions).
    Other(String),
}

impl Kind {
    fn of(kind: AttrKind) -> Kind {
        let values = |v: &[&str]| Kind::Enum(v.iter().map(|s| s.to_string()).collect());
        match kind {
            AttrKind::Text => Kind::Text,
            AttrKind::Ident => Kind::Ident,
            AttrKind::Count => Kind::Count,
            AttrKind::Bool => values(&["true", "false"]),
            AttrKind::Choice(v) => values(v),
        }
    }

    /// How an XSD spells this kind (table "Kinds map as" in `schemas/README.md`).
    fn xsd(&self) -> String {
        match self {
            Kind::Text => "type=\"xs:string\"".into(),
            Kind::Ident => "type=\"Ident\"".into(),
            Kind::Count => "type=\"xs:nonNegativeInteger\"".into(),
            Kind::Enum(v) if *v == ["false", "true"].map(String::from).into() => {
                "type=\"Bool\"".into()
            }
            Kind::Enum(v) => format!("an enumeration of {}", quoted(v)),
            Kind::Other(s) => s.clone(),
        }
    }
}

fn quoted<S: AsRef<str>>(values: impl IntoIterator<Item = S>) -> String {
    let v: Vec<String> = values
        .into_iter()
        .map(|s| format!("\"{}\"", s.as_ref()))
        .collect();
    v.join(", ")
}

/// `xs:complexType` → `complexType`.
fn local(name: &str) -> &str {
    name.rsplit(':').next().unwrap_or(name)
}

/// The first child of `el` that is the XSD construct `construct`.
fn first<'e>(el: &'e Element, construct: &str) -> Option<&'e Element> {
    el.children.iter().find(|c| local(&c.name) == construct)
}

/// One schema file: its path relative to `schemas/` and its `<xs:schema>` root.
type SchemaFile = (String, Element);

/// Reads the entry schemas and, transitively, every schema they include or import.
/// `read` gives the text of a file by its path relative to `schemas/`.
fn load(read: &dyn Fn(&str) -> Result<String, String>, out: &mut Vec<String>) -> Vec<SchemaFile> {
    let mut files: Vec<SchemaFile> = Vec::new();
    let mut queue: Vec<String> = ENTRY_SCHEMAS.iter().map(|s| s.to_string()).collect();
    while let Some(name) = queue.pop() {
        if files.iter().any(|f| f.0 == name) {
            continue;
        }
        let file = FileId(files.len() as u32);
        let parsed =
            read(&name).and_then(|text| xml::parse(file, &text, 64).map_err(|e| e.message));
        let root = match parsed {
            Ok(root) => root,
            Err(e) => {
                out.push(format!("{name}: cannot be read as XML: {e}"));
                continue;
            }
        };
        let dir = Path::new(&name).parent().unwrap_or(Path::new(""));
        let includes = (root.children.iter())
            .filter(|c| matches!(local(&c.name), "include" | "import"))
            .filter_map(|c| c.value("schemaLocation"));
        queue.extend(includes.map(|to| dir.join(to).to_string_lossy().into_owned()));
        files.push((name, root));
    }
    files
}

/// The flattened content model of one complexType.
#[derive(Default)]
struct Content {
    /// Child tag → the context key its `type="<key>Type"` names.
    children: BTreeMap<String, String>,
    /// Attribute name → (required, kind).
    attrs: BTreeMap<String, (bool, Kind)>,
    /// Whether the element may hold character data (simple content or `mixed="true"`).
    text: bool,
    /// Constructs that cannot be compared with the vocabulary.
    unsupported: Vec<String>,
}

impl Content {
    fn odd(&mut self, problem: impl Into<String>) {
        self.unsupported.push(problem.into());
    }
}

/// The top-level definitions of all loaded files: construct (`complexType`, `simpleType`,
/// `group`, `attributeGroup`, `element`, `attribute`) → name → (file, definition).
struct Index<'a> {
    defs: BTreeMap<&'a str, BTreeMap<&'a str, Vec<Def<'a>>>>,
}

/// A top-level definition: the file holding it, and its element.
type Def<'a> = (&'a str, &'a Element);

impl<'a> Index<'a> {
    fn new(files: &'a [SchemaFile]) -> Self {
        let mut defs: BTreeMap<_, BTreeMap<_, Vec<_>>> = BTreeMap::new();
        for (file, root) in files {
            for def in &root.children {
                if let Some(name) = def.value("name") {
                    let by_name = defs.entry(local(&def.name)).or_default();
                    by_name.entry(name).or_default().push((file.as_str(), def));
                }
            }
        }
        Index { defs }
    }

    fn all(&self, construct: &str, name: &str) -> &[Def<'a>] {
        let found = self.defs.get(construct).and_then(|m| m.get(name));
        found.map_or(&[], |v| v.as_slice())
    }

    fn get(&self, construct: &str, name: &str) -> Option<&'a Element> {
        self.all(construct, name).first().map(|d| d.1)
    }

    /// Collects the children, attributes and text of a complexType (or of a part of one).
    fn walk(&self, el: &Element, out: &mut Content, depth: usize) {
        if depth > MAX_DEPTH {
            return out.odd("references nest too deep (a cycle?)");
        }
        out.text |= el.value("mixed") == Some("true");
        for c in &el.children {
            match (local(&c.name), c.value("ref")) {
                ("annotation", ..) => {}
                ("sequence" | "choice" | "all" | "complexContent" | "simpleContent", ..) => {
                    self.walk(c, out, depth + 1)
                }
                (construct @ ("group" | "attributeGroup"), Some(r), ..) => {
                    match self.get(construct, r) {
                        Some(def) => self.walk(def, out, depth + 1),
                        None => out.odd(format!("{construct} \"{r}\" is undefined")),
                    }
                }
                ("extension", ..) => {
                    let base = c.value("base").unwrap_or("xs:anyType");
                    match self.get("complexType", base) {
                        Some(def) => self.walk(def, out, depth + 1),
                        // A simple base type is the type of the element's text.
                        None => out.text |= base != "xs:anyType",
                    }
                    self.walk(c, out, depth + 1);
                }
                ("attribute", ..) => self.attribute(c, out),
                ("element", None) => match (c.value("name"), c.value("type")) {
                    (Some(tag), Some(ty)) => {
                        let key = ty.strip_suffix("Type").unwrap_or(ty);
                        out.children.insert(tag.into(), key.into());
                    }
                    (tag, _) => out.odd(format!("child {tag:?} needs type=\"<key>Type\"")),
                },
                ("element", Some(r)) => out.odd(format!("child ref=\"{r}\" needs name= and type=")),
                _ => out.odd(format!("<{}> cannot be compared (README.md)", c.name)),
            }
        }
    }

    fn attribute(&self, a: &Element, out: &mut Content) {
        let def = match a.value("ref") {
            Some(r) => self.get("attribute", r),
            None => Some(a),
        };
        let Some((def, name)) = def.and_then(|d| Some((d, d.value("name")?))) else {
            return out.odd("an attribute without name or definition");
        };
        let kind = self.kind(def, 0);
        match a.value("use") {
            Some("prohibited") => drop(out.attrs.remove(name)),
            u => drop(out.attrs.insert(name.into(), (u == Some("required"), kind))),
        }
    }

    /// The kind of an attribute or restriction: by `type=`/`base=`, by an inline
    /// `xs:simpleType`, or (for neither) any text.
    fn kind(&self, holder: &Element, depth: usize) -> Kind {
        let (named, inline) = (holder.value("type"), first(holder, "simpleType"));
        match (named.or(holder.value("base")), inline) {
            (Some(name), _) => self.named_kind(name, depth),
            (None, Some(simple)) => self.simple_kind(simple, depth),
            (None, None) => Kind::Text,
        }
    }

    fn named_kind(&self, name: &str, depth: usize) -> Kind {
        match (name, self.get("simpleType", name)) {
            ("xs:string", _) => Kind::Text,
            ("xs:nonNegativeInteger", _) => Kind::Count,
            (_, Some(simple)) if depth < MAX_DEPTH => self.simple_kind(simple, depth + 1),
            _ => Kind::Other(format!("type=\"{name}\"")),
        }
    }

    fn simple_kind(&self, simple: &Element, depth: usize) -> Kind {
        let Some(r) = first(simple, "restriction") else {
            return Kind::Other("a list or union type".into());
        };
        let facets = |facet: &str| -> Vec<String> {
            let v = r.children.iter().filter(|c| local(&c.name) == facet);
            v.map(|c| c.value("value").unwrap_or("").to_string())
                .collect()
        };
        let (enums, patterns) = (facets("enumeration"), facets("pattern"));
        let plain = |c: &&Element| {
            matches!(
                local(&c.name),
                "enumeration" | "pattern" | "annotation" | "simpleType"
            )
        };
        match patterns.as_slice() {
            _ if !r.children.iter().all(|c| plain(&c)) => Kind::Other("other facets".into()),
            [] if !enums.is_empty() => Kind::Enum(enums.into_iter().collect()),
            [] => self.kind(r, depth + 1),
            [p] if p == IDENT_PATTERN && enums.is_empty() => Kind::Ident,
            _ => Kind::Other(format!("patterns {patterns:?}")),
        }
    }
}

/// Appends one line per difference between vocabulary key `spec` and its complexType,
/// which is defined in `file` and flattens to `xsd`.
fn compare(spec: &ElementSpec, file: &str, xsd: &Content, out: &mut Vec<String>) {
    let key = format!("vocabulary.rs key \"{}\"", spec.key);
    // One report line: `FILE KEYType: message`.
    macro_rules! say {
        ($($message:tt)*) => {
            out.push(format!("{file} {}Type: {}", spec.key, format_args!($($message)*)))
        };
    }
    for problem in &xsd.unsupported {
        say!("{problem}");
    }
    let tags = spec.children.iter().map(|k| (vocabulary::spec(k).tag, *k));
    let children: BTreeMap<&str, &str> = tags.collect();
    for (&tag, &child) in &children {
        let want = format!("type=\"{child}Type\"");
        match xsd.children.get(tag) {
            None => say!("child <{tag}> missing ({key} has it: {want})"),
            Some(k) if k != child => say!("child <{tag}> has type=\"{k}Type\" ({key}: {want})"),
            Some(_) => {}
        }
    }
    let unknown = |tag: &&String| !children.contains_key(tag.as_str());
    for tag in xsd.children.keys().filter(unknown) {
        say!("child <{tag}> is not in {key} (remove it here, or add it there)");
    }
    let own = (spec.attrs.iter()).map(|a| (a.name, (a.required, Kind::of(a.kind))));
    let common = COMMON_ATTRS.iter().map(|&n| (n, (false, Kind::Text)));
    let attrs: BTreeMap<&str, (bool, Kind)> = own.chain(common).collect();
    let use_of = |required: bool| if required { "required" } else { "optional" };
    for (&name, (required, kind)) in &attrs {
        let (want_use, want_kind) = (use_of(*required), kind.xsd());
        let Some((xsd_required, xsd_kind)) = xsd.attrs.get(name) else {
            say!("attribute \"{name}\" missing ({key} has it: use=\"{want_use}\", {want_kind})");
            continue;
        };
        if xsd_required != required {
            let have = use_of(*xsd_required);
            say!("attribute \"{name}\" is use=\"{have}\" ({key} has it {want_use})");
        }
        if let (Kind::Enum(want), Kind::Enum(have)) = (kind, xsd_kind) {
            let lacks = want.difference(have).map(|v| format!(" lacks \"{v}\""));
            let extra = have.difference(want).map(|v| format!(" has extra \"{v}\""));
            let diff: Vec<String> = lacks.chain(extra).collect();
            if !diff.is_empty() {
                let diff = diff.join(",");
                say!("attribute \"{name}\" enumeration{diff} ({key} has {want_kind})");
            }
        } else if kind != xsd_kind {
            let have = xsd_kind.xsd();
            say!("attribute \"{name}\" is {have} ({key} needs {want_kind})");
        }
    }
    for name in xsd.attrs.keys().filter(|n| !attrs.contains_key(n.as_str())) {
        say!("attribute \"{name}\" is not in {key} (remove it here, or add it there)");
    }
    match (spec.text, xsd.text) {
        (true, false) => say!("allows no text ({key} has text: use xs:simpleContent)"),
        (false, true) => say!("allows text ({key} has none)"),
        _ => {}
    }
}

/// Every difference between the schemas (read through `read`) and the vocabulary, sorted.
fn disagreements(read: &dyn Fn(&str) -> Result<String, String>) -> Vec<String> {
    let mut out = Vec::new();
    macro_rules! say {
        ($($message:tt)*) => { out.push(format!($($message)*)) };
    }
    let files = load(read, &mut out);
    let index = Index::new(&files);
    for (construct, by_name) in &index.defs {
        for (name, defs) in by_name.iter().filter(|(_, d)| d.len() > 1) {
            let places: Vec<&str> = defs.iter().map(|d| d.0).collect();
            let (first, all) = (places[0], places.join(", "));
            say!("{first}: {construct} \"{name}\" is defined more than once ({all})");
        }
    }
    // The keys that are no key's child are the document roots, the only global elements.
    let is_root = |k: &str| !ELEMENTS.iter().any(|p| p.children.contains(&k));
    for spec in ELEMENTS.iter().filter(|e| is_root(e.key)) {
        let (tag, key, want) = (spec.tag, spec.key, format!("{}Type", spec.key));
        match index.all("element", tag).first() {
            None => say!("schemas: global element <{tag}> missing (vocabulary.rs key \"{key}\" is a root; type=\"{want}\")"),
            Some((file, def)) if def.value("type") != Some(&want) => {
                say!("{file}: global element <{tag}> needs type=\"{want}\"")
            }
            Some(_) => {}
        }
    }
    for (tag, defs) in index.defs.get("element").into_iter().flatten() {
        if !ELEMENTS.iter().any(|e| e.tag == *tag && is_root(e.key)) {
            let file = defs[0].0;
            say!("{file}: global element <{tag}> is no root in vocabulary.rs");
        }
    }
    for spec in ELEMENTS {
        let (key, name) = (spec.key, format!("{}Type", spec.key));
        match index.all("complexType", &name).first() {
            Some((file, def)) => {
                let mut content = Content::default();
                index.walk(def, &mut content, 0);
                compare(spec, file, &content, &mut out);
            }
            None => {
                say!("schemas: complexType \"{name}\" missing (vocabulary.rs has key \"{key}\")")
            }
        }
    }
    out.sort();
    out.dedup();
    out
}

/// The differences after applying `edits` (file, text, replacement; each text must occur)
/// to the schemas in memory.
fn differences_after(edits: &[(&str, &str, &str)]) -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../schemas");
    disagreements(&|name: &str| {
        let mut text = std::fs::read_to_string(dir.join(name)).map_err(|e| e.to_string())?;
        for (_, from, to) in edits.iter().filter(|e| e.0 == name) {
            assert!(text.contains(from), "{name} does not contain {from:?}");
            text = text.replacen(from, to, 1);
        }
        Ok(text)
    })
}

#[test]
fn schemas_agree_with_the_vocabulary() {
    let problems = differences_after(&[]);
    assert!(
        problems.is_empty(),
        "schemas/*.xsd and compiler/src/syntax/vocabulary.rs disagree in {} places \
         (schemas/README.md describes the conventions):\n  {}\n",
        problems.len(),
        problems.join("\n  ")
    );
}

/// One edit per line, `file | text | replacement | start of the expected report line`.
const BREAKING_EDITS: &str = r#"
common.xsd | name="delay" use | name="delays" use | common.xsd connectType: attribute "delay" missing (vocabulary.rs key "connect" has it
common.xsd | name="delay" use | name="delays" use | common.xsd connectType: attribute "delays" is not in vocabulary.rs key "connect"
common.xsd | <xs:enumeration value="drop-newest"/> |  | common.xsd connectType: attribute "on-full" enumeration lacks "drop-newest" (vocabulary.rs key "connect" has an enumeration of "block", "drop-newest", "drop-oldest")
common.xsd | name="lock" type="Ident" use="required" | name="lock" type="Ident" | common.xsd bindType: attribute "lock" is use="optional"
common.xsd | name="realtime" type="Bool" | name="realtime" type="xs:boolean" | common.xsd threadType: attribute "realtime" is type="xs:boolean" (vocabulary.rs key "thread" needs type="Bool")
common.xsd | <xs:extension base="xs:string"> | <xs:extension base="xs:anyType"> | common.xsd paramType: allows no text
common.xsd | name="allowType" | name="allowedType" | schemas: complexType "allowType" missing
application.xsd | name="level" type="xs:nonNegativeInteger" | name="level" type="Ident" | application.xsd resourceType: attribute "level" is type="Ident"
application.xsd | <xs:element name="fragment" type="fragmentType"/> |  | schemas: global element <fragment> missing
library.xsd | <xs:element name="flexible" type="flexibleType"/> |  | library.xsd module-typeType: child <flexible> missing
library.xsd | type="fieldType" | type="channel-inType" | library.xsd typeType: child <field> has type="channel-inType"
library.xsd | name="fieldType" | name="fieldType" mixed="true" | library.xsd fieldType: allows text
"#;

/// Each kind of difference is reported, with a line naming the file to change.
#[test]
fn each_kind_of_difference_is_reported() {
    for line in BREAKING_EDITS.lines().filter(|l| !l.is_empty()) {
        let [file, from, to, expected] =
            <[&str; 4]>::try_from(line.split(" | ").collect::<Vec<_>>())
                .unwrap_or_else(|_| panic!("malformed case {line:?}"));
        let found = differences_after(&[(file, from, to.trim())]);
        assert!(
            found.iter().any(|p| p.starts_with(expected)),
            "replacing {from:?} with {to:?} in {file} should report\n  {expected}\nbut reported:\n  {}",
            found.join("\n  ")
        );
    }
}

/// Extension bases, attribute groups, model groups and derived simple types are resolved:
/// an equivalent rewrite of a type is no difference.
#[test]
fn equivalent_rewrites_are_no_difference() {
    let rewritten = r#"
  <xs:complexType name="module-portType"><xs:complexContent><xs:extension base="group-portType">
    <xs:attribute name="count" type="xs:nonNegativeInteger" use="optional"/>
  </xs:extension></xs:complexContent></xs:complexType>
  <xs:simpleType name="Name"><xs:restriction base="Ident"/></xs:simpleType>
  <xs:attributeGroup name="bindAttributes">
    <xs:attribute name="lock" type="Name" use="required"/>
    <xs:attribute name="resource" type="Name" use="required"/>
  </xs:attributeGroup>
  <xs:complexType name="bindType">
    <xs:sequence/>
    <xs:attributeGroup ref="bindAttributes"/>
    <xs:attribute name="doc" type="xs:string"/>
  </xs:complexType>
  <xs:group name="connectContent">
    <xs:choice><xs:element name="convert" type="convertType"/><xs:element name="allow" type="allowType"/></xs:choice>
  </xs:group>
  <!-- key `allow`: <allow> -->"#;
    let connect_children = r#"<xs:choice minOccurs="0" maxOccurs="unbounded">
      <xs:element name="convert" type="convertType"/>
      <xs:element name="allow" type="allowType"/>
    </xs:choice>"#;
    let group = r#"<xs:group ref="connectContent" minOccurs="0" maxOccurs="unbounded"/>"#;
    let found = differences_after(&[
        (
            "common.xsd",
            r#"name="module-portType""#,
            r#"name="old_port""#,
        ),
        ("common.xsd", r#"name="bindType""#, r#"name="old_bind""#),
        ("common.xsd", "<!-- key `allow`: <allow> -->", rewritten),
        ("common.xsd", connect_children, group),
    ]);
    assert!(
        found.is_empty(),
        "unexpected differences:\n  {}",
        found.join("\n  ")
    );
}
