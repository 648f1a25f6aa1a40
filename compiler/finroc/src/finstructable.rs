//! FINROC application and group files (`*.finroc`, `*.h.xml`, `*.cpp.xml`): the model.
//!
//! One grammar for both (root `<Finstructable>`, or `<FinstructableGroup>` as 13.10 and
//! earlier wrote it; FINROC never checks the root's name): `interface*`, `element*`,
//! `edge*`, legacy `<parameter link>` and `<parameter_links>`. `version="1703"` turns on
//! percent-encoded edge paths and `<conversion>`. Everything keeps its span; the reader
//! is in `read.rs`, the writer (export) in `write.rs`.

use ferroc_diagnostics::source::{FileId, Span};

/// A name or value with where it is written.
#[derive(Clone, Debug, PartialEq)]
pub struct Named {
    pub text: String,
    pub span: Span,
}

/// One parsed application or group file.
#[derive(Clone, Debug)]
pub struct Finstructable {
    pub file: FileId,
    /// The root element's tag, as written.
    pub root_tag: String,
    pub root_span: Span,
    /// `version`: `None` = 0, the legacy semantics (literal paths, no conversions).
    pub version: Option<u32>,
    pub defaultname: Option<Named>,
    /// `dependencies`, split at commas (each name with its own span when feasible).
    pub dependencies: Vec<Named>,
    /// Whether the file has a `dependencies` attribute at all.
    pub has_dependencies: bool,
    pub interfaces: Vec<Interface>,
    pub elements: Vec<Element>,
    pub edges: Vec<Edge>,
    /// Legacy `<parameter link>` entries and the flattened `<parameter_links>` tree.
    pub links: Vec<ParamLink>,
}

impl Finstructable {
    /// Every element, depth first, with its path below the file's group.
    pub fn all_elements(&self) -> Vec<(String, &Element)> {
        fn walk<'a>(prefix: &str, list: &'a [Element], out: &mut Vec<(String, &'a Element)>) {
            for e in list {
                let path = if prefix.is_empty() {
                    e.name.text.clone()
                } else {
                    format!("{prefix}/{}", e.name.text)
                };
                walk(&path, &e.children, out);
                out.push((path, e));
            }
        }
        let mut out = Vec::new();
        walk("", &self.elements, &mut out);
        out
    }

    /// The element at a relative element path (`Group 1/Inner`), if the file creates it.
    pub fn element_at(&self, path: &[String]) -> Option<&Element> {
        let mut list = &self.elements;
        let mut found = None;
        for seg in path {
            let e = list.iter().find(|e| &e.name.text == seg)?;
            list = &e.children;
            found = Some(e);
        }
        found
    }
}

/// `<interface name>` with its `<port>`s: an editable interface of this group.
#[derive(Clone, Debug)]
pub struct Interface {
    pub name: Named,
    pub span: Span,
    pub ports: Vec<InterfacePort>,
}

#[derive(Clone, Debug)]
pub struct InterfacePort {
    pub name: Named,
    /// The rrlib type name (`uint32`, `List<double>`).
    pub ty: Option<Named>,
    pub output: bool,
    pub shared: bool,
    pub span: Span,
}

/// `<element name group type>`: a component instance.
#[derive(Clone, Debug)]
pub struct Element {
    pub name: Named,
    /// The shared library (`finroc_plugins_structure`).
    pub group: Option<Named>,
    /// The registered create-action name (`Group`, `AddNoise`).
    pub ty: Option<Named>,
    pub span: Span,
    pub constructor: Vec<StaticParam>,
    /// `None` when the element has no `<parameters>` child.
    pub parameters: Option<Vec<StaticParam>>,
    pub children: Vec<Element>,
}

impl Element {
    /// A static parameter by name (FINROC also accepts the legacy `Par ` prefix).
    pub fn param(&self, name: &str) -> Option<&StaticParam> {
        self.parameters
            .iter()
            .flatten()
            .find(|p| p.name.text == name || p.name.text.strip_prefix("Par ") == Some(name))
    }

    /// `XML file`: the group file this instance loads.
    pub fn xml_file(&self) -> Option<&StaticParam> {
        self.param("XML file")
    }
}

/// `<parameter name …>value</parameter>` of `<constructor>` or `<parameters>`.
#[derive(Clone, Debug)]
pub struct StaticParam {
    pub name: Named,
    pub value: Named,
    /// Further attributes in written order (`type`, `enforcevalue`, `cmdline`,
    /// `attachouter`, `config`).
    pub attrs: Vec<(String, Named)>,
    pub span: Span,
}

impl StaticParam {
    pub fn attr(&self, name: &str) -> Option<&Named> {
        self.attrs.iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }
}

/// A connection flag as `flags="Optional (2)"` writes it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flag {
    Finstructed,
    Reconnect,
    Optional,
    SchedulingNeutral,
    DirectionToDestination,
    DirectionToSource,
}

/// (flag, its enum string, its index) as `tConnectOptions.h` numbers them.
pub const FLAGS: &[(Flag, &str, u32)] = &[
    (Flag::Finstructed, "Finstructed", 0),
    (Flag::Reconnect, "Reconnect", 1),
    (Flag::Optional, "Optional", 2),
    (Flag::SchedulingNeutral, "Scheduling Neutral", 3),
    (Flag::DirectionToDestination, "Direction To Destination", 4),
    (Flag::DirectionToSource, "Direction To Source", 5),
];

/// One end of an edge.
#[derive(Clone, Debug)]
pub struct EdgeEnd {
    /// The attribute value as read (entities resolved, escapes kept).
    pub raw: Named,
    /// A URI scheme (`tcp`) makes this end a URI connector.
    pub scheme: Option<String>,
    /// A path starting with `/` is from the runtime root.
    pub absolute: bool,
    /// Path segments, percent-decoded in version-1703 files. Empty when undecodable.
    pub segments: Vec<String>,
}

impl EdgeEnd {
    /// The decoded path, segments joined by `/`.
    pub fn path(&self) -> String {
        self.segments.join("/")
    }
}

/// `<conversion>`: one or two operations with optional parameters and intermediate type.
#[derive(Clone, Debug)]
pub struct Conversion {
    /// Attributes in written order (`operation`, `operation1`, `parameter1`, …).
    pub attrs: Vec<(String, Named)>,
    pub span: Span,
}

impl Conversion {
    pub fn operations(&self) -> Vec<&str> {
        ["operation", "operation1", "operation2"]
            .iter()
            .filter_map(|k| self.attrs.iter().find(|(n, _)| n == k))
            .map(|(_, v)| v.text.as_str())
            .collect()
    }
}

/// `<edge src dest flags?>`.
#[derive(Clone, Debug)]
pub struct Edge {
    pub src: EdgeEnd,
    pub dest: EdgeEnd,
    pub flags: Vec<Flag>,
    pub conversion: Option<Conversion>,
    /// `<parameter name>` children (URI connector parameters).
    pub params: Vec<(Named, Named)>,
    pub span: Span,
}

/// A parameter tied to a config entry or a command-line option.
#[derive(Clone, Debug)]
pub struct ParamLink {
    /// The parameter's path below this group (`Simulation/AddNoise Front/Parameters/Standard
    /// Deviation`, or from `<parameter_links>` the element path plus the name).
    pub path: Vec<String>,
    /// Where the path is written (`link=` value, or the `<parameter name>` value).
    pub path_span: Span,
    pub config: Option<Named>,
    pub cmdline: Option<Named>,
    pub default: Option<Named>,
    /// Whether it came from the legacy `<parameter link>` form.
    pub legacy: bool,
    pub span: Span,
}
