//! The elements of application models and fragments, one constant per context key.

use super::AttrKind::*;
use super::{opt, req, ElementSpec, DIRECTIONS, GROUP_CONTENT, IB2C_VIOLATIONS, ON_FULL, PROFILES};

pub(super) const APPLICATION: ElementSpec = ElementSpec {
    key: "application",
    tag: "application",
    attrs: &[
        req("name", Ident),
        req("version", Choice(&["1"])),
        opt("profile", Choice(PROFILES)),
        opt("utilisation-warning", Text),
        opt("ib2c-violations", Choice(IB2C_VIOLATIONS)),
        opt("seed", Count),
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
        "ros2-external",
        "ros2-interfaces",
    ],
    text: false,
};

pub(super) const USE: ElementSpec = ElementSpec {
    key: "use",
    tag: "use",
    attrs: &[req("library", Ident), opt("manifest", Text)],
    children: &[],
    text: false,
};

pub(super) const RESOURCE: ElementSpec = ElementSpec {
    key: "resource",
    tag: "resource",
    attrs: &[
        req("name", Ident),
        opt("level", Count),
        opt("kind", Choice(&["mutex", "recursive"])),
    ],
    children: &["allow"],
    text: false,
};

pub(super) const PART: ElementSpec = ElementSpec {
    key: "part",
    tag: "part",
    attrs: &[
        req("name", Ident),
        opt("host", Text),
        opt("cores", Count),
        opt("shared-memory", Choice(&["on", "off"])),
        opt("shared-memory-threshold", Text),
        opt("shared-memory-pool", Text),
    ],
    children: &["thread", "group", "module", "connect", "allow", "ros2"],
    text: false,
};

pub(super) const THREAD: ElementSpec = ElementSpec {
    key: "thread",
    tag: "thread",
    attrs: &[
        req("name", Ident),
        opt("period", Text),
        opt("trigger", Choice(&["data", "continuous"])),
        opt("wait", Choice(&["park", "spin", "adaptive", "inline"])),
        opt("priority", Count),
        opt("realtime", Bool),
        opt("cpu", Count),
        opt("warn-overrun", Bool),
        opt("pool", Count),
    ],
    children: &["thread", "group", "module", "connect", "allow"],
    text: false,
};

pub(super) const GROUP: ElementSpec = ElementSpec {
    key: "group",
    tag: "group",
    attrs: &[req("name", Ident), opt("type", Text)],
    children: GROUP_CONTENT,
    text: false,
};

pub(super) const GROUP_TYPE: ElementSpec = ElementSpec {
    key: "group-type",
    tag: "group-type",
    attrs: &[req("name", Ident)],
    children: GROUP_CONTENT,
    text: false,
};

pub(super) const GROUP_PORT: ElementSpec = ElementSpec {
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
};

pub(super) const MODULE: ElementSpec = ElementSpec {
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
};

pub(super) const MODULE_PORT: ElementSpec = ElementSpec {
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
};

pub(super) const PARAM: ElementSpec = ElementSpec {
    key: "param",
    tag: "param",
    attrs: &[
        req("name", Ident),
        opt("config", Text),
        opt("cmdline", Text),
    ],
    children: &[],
    text: true,
};

pub(super) const BIND: ElementSpec = ElementSpec {
    key: "bind",
    tag: "bind",
    attrs: &[req("lock", Ident), req("resource", Ident)],
    children: &[],
    text: false,
};

pub(super) const CONNECT: ElementSpec = ElementSpec {
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
        opt("deadline", Text),
    ],
    children: &["convert", "allow"],
    text: false,
};

pub(super) const CONVERT: ElementSpec = ElementSpec {
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
};

pub(super) const INCLUDE: ElementSpec = ElementSpec {
    key: "include",
    tag: "include",
    attrs: &[req("href", Text)],
    children: &[],
    text: false,
};

pub(super) const FLOW: ElementSpec = ElementSpec {
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
};

pub(super) const ALLOW: ElementSpec = ElementSpec {
    key: "allow",
    tag: "allow",
    attrs: &[req("code", Text), req("reason", Text)],
    children: &[],
    text: false,
};

pub(super) const FRAGMENT: ElementSpec = ElementSpec {
    key: "fragment",
    tag: "fragment",
    attrs: &[],
    children: &["group-type", "resource", "include"],
    text: false,
};
