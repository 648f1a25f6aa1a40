//! The vocabulary of the model language: which elements exist, where they may appear,
//! which attributes they take. One table serves the checker, the "did you mean" hints and
//! the test that keeps `schemas/*.xsd` in agreement with the parser.

use AttrKind::*;

/// What an attribute's value must look like, as far as the vocabulary can tell.
/// Values with richer syntax (types, durations, paths) are checked by the resolver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AttrKind {
    Text,
    /// `[A-Za-z_][A-Za-z0-9_]*`
    Ident,
    Bool,
    /// A non-negative integer.
    Count,
    Choice(&'static [&'static str]),
}

#[derive(Debug)]
pub struct AttrSpec {
    pub name: &'static str,
    pub required: bool,
    pub kind: AttrKind,
}

/// One element in one context. The same tag may mean different things in different
/// places (`<param>` in a model vs. in a manifest), so each context has its own key.
#[derive(Debug)]
pub struct ElementSpec {
    pub key: &'static str,
    pub tag: &'static str,
    pub attrs: &'static [AttrSpec],
    /// Keys of the elements allowed as children.
    pub children: &'static [&'static str],
    /// Whether the element carries a text value.
    pub text: bool,
}

const fn req(name: &'static str, kind: AttrKind) -> AttrSpec {
    AttrSpec {
        name,
        required: true,
        kind,
    }
}
const fn opt(name: &'static str, kind: AttrKind) -> AttrSpec {
    AttrSpec {
        name,
        required: false,
        kind,
    }
}

/// Allowed on every element.
pub const COMMON_ATTRS: &[&str] = &["doc"];
/// Allowed on root elements (schema binding).
pub const ROOT_ATTRS: &[&str] = &[
    "xmlns:xsi",
    "xsi:noNamespaceSchemaLocation",
    "xsi:schemaLocation",
];

pub const ON_FULL: &[&str] = &["block", "drop-oldest", "drop-newest"];
pub const DIRECTIONS: &[&str] = &["in", "out"];
pub const PROFILES: &[&str] = &["generic", "finroc"];
/// The steps of an activity or a service body, in program order (deadlock analysis).
const STEPS: &[&str] = &[
    "step-lock",
    "step-unlock",
    "step-read",
    "step-write",
    "step-call",
    "step-await",
];
pub const MODULE_KINDS: &[&str] = &["module", "sense-control", "behaviour", "fusion"];

/// What the runtime does when a behaviour violates an iB2C principle (`<application>`
/// for every behaviour, `<module>` for one; default `warn`).
pub const IB2C_VIOLATIONS: &[&str] = &["warn", "clamp", "stop"];

const GROUP_CONTENT: &[&str] = &[
    "group-port",
    "group",
    "thread",
    "module",
    "connect",
    "allow",
];

pub static ELEMENTS: &[ElementSpec] = &[
    // ----- application models -----
    ElementSpec {
        key: "application",
        tag: "application",
        attrs: &[
            req("name", Ident),
            req("version", Choice(&["1"])),
            opt("profile", Choice(PROFILES)),
            opt("utilisation-warning", Text),
            opt("ib2c-violations", Choice(IB2C_VIOLATIONS)),
        ],
        children: &[
            "use",
            "include",
            "resource",
            "group-type",
            "part",
            "connect",
            "flow",
            "allow",
        ],
        text: false,
    },
    ElementSpec {
        key: "use",
        tag: "use",
        attrs: &[req("library", Ident), opt("manifest", Text)],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "resource",
        tag: "resource",
        attrs: &[
            req("name", Ident),
            opt("level", Count),
            opt("kind", Choice(&["mutex", "recursive"])),
        ],
        children: &["allow"],
        text: false,
    },
    ElementSpec {
        key: "part",
        tag: "part",
        attrs: &[req("name", Ident), opt("host", Text), opt("cores", Count)],
        children: &["thread", "group", "module", "connect", "allow"],
        text: false,
    },
    ElementSpec {
        key: "thread",
        tag: "thread",
        attrs: &[
            req("name", Ident),
            opt("period", Text),
            opt("trigger", Choice(&["data", "continuous"])),
            opt("priority", Count),
            opt("realtime", Bool),
            opt("cpu", Count),
            opt("warn-overrun", Bool),
            opt("pool", Count),
        ],
        children: &["thread", "group", "module", "connect", "allow"],
        text: false,
    },
    ElementSpec {
        key: "group",
        tag: "group",
        attrs: &[req("name", Ident), opt("type", Text)],
        children: GROUP_CONTENT,
        text: false,
    },
    ElementSpec {
        key: "group-type",
        tag: "group-type",
        attrs: &[req("name", Ident)],
        children: GROUP_CONTENT,
        text: false,
    },
    ElementSpec {
        key: "group-port",
        tag: "port",
        attrs: &[
            req("name", Ident),
            req("dir", Choice(DIRECTIONS)),
            req("type", Text),
            opt("unit", Text),
        ],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "module",
        tag: "module",
        attrs: &[
            req("name", Ident),
            req("type", Text),
            opt("budget", Text),
            opt("characteristic", Bool),
            opt("ib2c-violations", Choice(IB2C_VIOLATIONS)),
        ],
        children: &["param", "module-port", "bind", "allow"],
        text: false,
    },
    ElementSpec {
        key: "module-port",
        tag: "port",
        attrs: &[
            req("name", Ident),
            req("dir", Choice(DIRECTIONS)),
            req("type", Text),
            opt("unit", Text),
            opt("count", Count),
        ],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "param",
        tag: "param",
        attrs: &[
            req("name", Ident),
            opt("config", Text),
            opt("cmdline", Text),
        ],
        children: &[],
        text: true,
    },
    ElementSpec {
        key: "bind",
        tag: "bind",
        attrs: &[req("lock", Ident), req("resource", Ident)],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "connect",
        tag: "connect",
        attrs: &[
            req("from", Text),
            req("to", Text),
            opt("queue", Count),
            opt("on-full", Choice(ON_FULL)),
            opt("delay", Choice(&["0", "1"])),
            opt("initial", Count),
            opt("sharing", Choice(&["on-change", "periodic"])),
            opt("min-interval", Text),
            opt("period", Text),
            opt("reliability", Choice(&["reliable", "best-effort"])),
        ],
        children: &["convert", "allow"],
        text: false,
    },
    ElementSpec {
        key: "convert",
        tag: "convert",
        attrs: &[
            opt("to-type", Text),
            opt("scale", Text),
            opt("offset", Text),
            opt("index", Count),
            opt("field", Ident),
        ],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "include",
        tag: "include",
        attrs: &[req("href", Text)],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "flow",
        tag: "flow",
        attrs: &[
            req("name", Ident),
            req("from", Text),
            req("to", Text),
            req("max-latency", Text),
        ],
        children: &["allow"],
        text: false,
    },
    ElementSpec {
        key: "allow",
        tag: "allow",
        attrs: &[req("code", Text), req("reason", Text)],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "fragment",
        tag: "fragment",
        attrs: &[],
        children: &["group-type", "resource", "include"],
        text: false,
    },
    // ----- library manifests -----
    ElementSpec {
        key: "library",
        tag: "library",
        attrs: &[
            req("name", Ident),
            opt("version", Text),
            opt("rust-crate", Text),
        ],
        children: &["depends", "type", "module-type", "lib-group-type"],
        text: false,
    },
    ElementSpec {
        key: "depends",
        tag: "depends",
        attrs: &[req("library", Ident), opt("manifest", Text)],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "type",
        tag: "type",
        attrs: &[
            req("name", Ident),
            req("rust", Text),
            opt("copy", Bool),
            opt("serde", Bool),
            opt("unit", Text),
        ],
        children: &["field"],
        text: false,
    },
    ElementSpec {
        key: "field",
        tag: "field",
        attrs: &[req("name", Ident), req("type", Text), opt("unit", Text)],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "module-type",
        tag: "module-type",
        attrs: &[
            req("name", Ident),
            req("rust", Text),
            opt("kind", Choice(MODULE_KINDS)),
            opt("budget", Text),
        ],
        children: &[
            "in",
            "out",
            "sensor-in",
            "sensor-out",
            "controller-in",
            "controller-out",
            "param-decl",
            "service",
            "client",
            "locks",
            "derived-activity",
            "channel-in",
            "flexible",
            "activity",
        ],
        text: false,
    },
    ElementSpec {
        key: "in",
        tag: "in",
        attrs: INPUT_ATTRS,
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "sensor-in",
        tag: "sensor-in",
        attrs: INPUT_ATTRS,
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "controller-in",
        tag: "controller-in",
        attrs: INPUT_ATTRS,
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "out",
        tag: "out",
        attrs: OUTPUT_ATTRS,
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "sensor-out",
        tag: "sensor-out",
        attrs: OUTPUT_ATTRS,
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "controller-out",
        tag: "controller-out",
        attrs: OUTPUT_ATTRS,
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "param-decl",
        tag: "param",
        attrs: &[
            req("name", Ident),
            req("type", Text),
            opt("unit", Text),
            opt("min", Text),
            opt("max", Text),
            opt("default", Text),
            opt("required", Bool),
            opt("choices", Text),
        ],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "service",
        tag: "service",
        attrs: &[
            req("name", Ident),
            req("request", Text),
            req("response", Text),
            opt("executes", Choice(&["server", "caller"])),
        ],
        children: STEPS,
        text: false,
    },
    ElementSpec {
        key: "client",
        tag: "client",
        attrs: &[
            req("name", Ident),
            req("request", Text),
            req("response", Text),
            opt("blocking", Bool),
            opt("timeout", Text),
            opt("response-via", Choice(&["transport", "caller"])),
        ],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "locks",
        tag: "locks",
        attrs: &[req("order", Text)],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "activity",
        tag: "activity",
        attrs: &[opt("name", Choice(&["update", "sense", "control"]))],
        children: STEPS,
        text: false,
    },
    ElementSpec {
        key: "step-lock",
        tag: "lock",
        attrs: &[req("slot", Ident), opt("timeout", Text)],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "step-unlock",
        tag: "unlock",
        attrs: &[req("slot", Ident)],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "step-read",
        tag: "read",
        attrs: &[req("port", Text), opt("timeout", Text)],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "step-write",
        tag: "write",
        attrs: &[
            req("port", Text),
            opt("count", Count),
            opt("optional", Bool),
        ],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "step-call",
        tag: "call",
        attrs: &[
            req("client", Ident),
            opt("mode", Choice(&["sync", "async"])),
            opt("timeout", Text),
        ],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "step-await",
        tag: "await",
        attrs: &[req("client", Ident), opt("timeout", Text)],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "derived-activity",
        tag: "derived-activity",
        attrs: &[req("name", Ident)],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "channel-in",
        tag: "channel-in",
        attrs: &[req("name", Ident), req("type", Text), opt("unit", Text)],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "flexible",
        tag: "flexible",
        attrs: &[
            req("port", Ident),
            req("dir", Choice(DIRECTIONS)),
            opt("same-type", Bool),
            opt("min-count", Count),
            opt("max-count", Count),
        ],
        children: &[],
        text: false,
    },
    ElementSpec {
        key: "lib-group-type",
        tag: "group-type",
        attrs: &[req("name", Ident), opt("file", Text)],
        children: GROUP_CONTENT,
        text: false,
    },
];

const INPUT_ATTRS: &[AttrSpec] = &[
    req("name", Ident),
    req("type", Text),
    opt("unit", Text),
    opt("required", Bool),
    opt("read", Choice(&["non-blocking", "blocking"])),
    opt("timeout", Text),
    opt("fan-in", Choice(&["single", "merge"])),
];
const OUTPUT_ATTRS: &[AttrSpec] = &[req("name", Ident), req("type", Text), opt("unit", Text)];

/// The spec for a context key. Panics only on a key missing from the table above,
/// which the unit test below rules out.
pub fn spec(key: &str) -> &'static ElementSpec {
    ELEMENTS
        .iter()
        .find(|e| e.key == key)
        .unwrap_or_else(|| panic!("vocabulary has no element key `{key}`"))
}

/// The context key of child `tag` under `parent`, if it may appear there.
pub fn child_key(parent: &ElementSpec, tag: &str) -> Option<&'static str> {
    parent.children.iter().copied().find(|k| spec(k).tag == tag)
}

/// Every tag name the language knows (for "did you mean").
pub fn all_tags() -> impl Iterator<Item = &'static str> {
    ELEMENTS.iter().map(|e| e.tag)
}

pub fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c == '_' || c.is_ascii_alphabetic())
        && chars.all(|c| c == '_' || c.is_ascii_alphanumeric())
}

#[cfg(test)]
mod tests;
