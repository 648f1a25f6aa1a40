//! The vocabulary of the model language: which elements exist, where they may appear,
//! which attributes they take. One table serves the checker, the "did you mean" hints and
//! the test that keeps `schemas/*.xsd` in agreement with the parser.

mod manifest;
mod model;
mod ros2;

pub use ros2::{DURABILITY, RELIABILITY};

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
/// What a queue does when full if `on-full=` is not written (the language's default).
/// The deadlock analysis, the plan `ferroc run` executes and the bundles all read it
/// through [`Connection::on_full_policy`](ferroc_model::ir::Connection::on_full_policy), so
/// the checked behaviour and the run behaviour cannot differ.
pub const DEFAULT_ON_FULL: &str = "drop-oldest";
/// The largest `queue=`: the runtime allocates a queue in full when a run starts, so an
/// unbounded size would let a model exhaust memory (M116 above it).
pub const MAX_QUEUE: u32 = 65_536;
/// The largest `count=` of a flexible port group (`<port count>` on a module): the
/// runtime makes every port when the module is created and refuses more
/// (`ferroc_module::MAX_GROUP_PORTS`, the same number; M116 above it).
pub const MAX_GROUP_PORTS: u32 = 4096;
pub const DIRECTIONS: &[&str] = &["in", "out"];
pub const PROFILES: &[&str] = &["generic", "finroc"];
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

/// Every element in every context. The entries are defined in `model.rs` and `manifest.rs`
/// (one constant per key); one that is defined but not listed here is dead code, a warning.
pub static ELEMENTS: &[ElementSpec] = &[
    // ----- application models -----
    model::APPLICATION,
    model::USE,
    model::RESOURCE,
    model::PART,
    model::THREAD,
    model::GROUP,
    model::GROUP_TYPE,
    model::GROUP_PORT,
    model::MODULE,
    model::MODULE_PORT,
    model::PARAM,
    model::BIND,
    model::CONNECT,
    model::CONVERT,
    model::INCLUDE,
    model::FLOW,
    model::ALLOW,
    model::FRAGMENT,
    ros2::ROS2,
    ros2::ROS2_PUBLISH,
    ros2::ROS2_SUBSCRIBE,
    ros2::ROS2_SERVICE,
    ros2::ROS2_CLIENT,
    ros2::ROS2_EXTERNAL,
    ros2::ROS2_EXTERNAL_PUBLISH,
    ros2::ROS2_EXTERNAL_SUBSCRIBE,
    ros2::ROS2_INTERFACES,
    // ----- library manifests -----
    manifest::LIBRARY,
    manifest::DEPENDS,
    manifest::TYPE,
    manifest::FIELD,
    manifest::MODULE_TYPE,
    manifest::IN,
    manifest::SENSOR_IN,
    manifest::CONTROLLER_IN,
    manifest::OUT,
    manifest::SENSOR_OUT,
    manifest::CONTROLLER_OUT,
    manifest::PARAM_DECL,
    manifest::SERVICE,
    manifest::CLIENT,
    manifest::LOCKS,
    manifest::ACTIVITY,
    manifest::STEP_LOCK,
    manifest::STEP_UNLOCK,
    manifest::STEP_READ,
    manifest::STEP_WRITE,
    manifest::STEP_CALL,
    manifest::STEP_AWAIT,
    manifest::DERIVED_ACTIVITY,
    manifest::CHANNEL_IN,
    manifest::FLEXIBLE,
    manifest::LIB_GROUP_TYPE,
];

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
