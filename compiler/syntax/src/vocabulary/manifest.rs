//! The elements of library manifests, one constant per context key.

use super::AttrKind::*;
use super::{opt, req, AttrSpec, ElementSpec, DIRECTIONS, GROUP_CONTENT, MODULE_KINDS};

/// The steps of an activity or a service body, in program order (deadlock analysis).
const STEPS: &[&str] = &[
    "step-lock",
    "step-unlock",
    "step-read",
    "step-write",
    "step-call",
    "step-await",
];

pub(super) const LIBRARY: ElementSpec = ElementSpec {
    key: "library",
    tag: "library",
    attrs: &[
        req("name", Ident),
        opt("version", Text),
        opt("rust-crate", Text),
    ],
    children: &["depends", "type", "module-type", "lib-group-type"],
    text: false,
};

pub(super) const DEPENDS: ElementSpec = ElementSpec {
    key: "depends",
    tag: "depends",
    attrs: &[req("library", Ident), opt("manifest", Text)],
    children: &[],
    text: false,
};

pub(super) const TYPE: ElementSpec = ElementSpec {
    key: "type",
    tag: "type",
    attrs: &[
        req("name", Ident),
        req("rust", Text),
        opt("copy", Bool),
        opt("serde", Bool),
        opt("unit", Text),
        opt("ros2", Text),
    ],
    children: &["field"],
    text: false,
};

pub(super) const FIELD: ElementSpec = ElementSpec {
    key: "field",
    tag: "field",
    attrs: &[req("name", Ident), req("type", Text), opt("unit", Text)],
    children: &[],
    text: false,
};

pub(super) const MODULE_TYPE: ElementSpec = ElementSpec {
    key: "module-type",
    tag: "module-type",
    attrs: &[
        req("name", Ident),
        req("rust", Text),
        opt("kind", Choice(MODULE_KINDS)),
        opt("budget", Text),
        opt("nondeterministic", Bool),
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
};

pub(super) const IN: ElementSpec = ElementSpec {
    key: "in",
    tag: "in",
    attrs: INPUT_ATTRS,
    children: &[],
    text: false,
};

pub(super) const SENSOR_IN: ElementSpec = ElementSpec {
    key: "sensor-in",
    tag: "sensor-in",
    attrs: INPUT_ATTRS,
    children: &[],
    text: false,
};

pub(super) const CONTROLLER_IN: ElementSpec = ElementSpec {
    key: "controller-in",
    tag: "controller-in",
    attrs: INPUT_ATTRS,
    children: &[],
    text: false,
};

pub(super) const OUT: ElementSpec = ElementSpec {
    key: "out",
    tag: "out",
    attrs: OUTPUT_ATTRS,
    children: &[],
    text: false,
};

pub(super) const SENSOR_OUT: ElementSpec = ElementSpec {
    key: "sensor-out",
    tag: "sensor-out",
    attrs: OUTPUT_ATTRS,
    children: &[],
    text: false,
};

pub(super) const CONTROLLER_OUT: ElementSpec = ElementSpec {
    key: "controller-out",
    tag: "controller-out",
    attrs: OUTPUT_ATTRS,
    children: &[],
    text: false,
};

pub(super) const PARAM_DECL: ElementSpec = ElementSpec {
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
        opt("nondeterministic-value", Text),
    ],
    children: &[],
    text: false,
};

pub(super) const SERVICE: ElementSpec = ElementSpec {
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
};

pub(super) const CLIENT: ElementSpec = ElementSpec {
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
};

pub(super) const LOCKS: ElementSpec = ElementSpec {
    key: "locks",
    tag: "locks",
    attrs: &[req("order", Text)],
    children: &[],
    text: false,
};

pub(super) const ACTIVITY: ElementSpec = ElementSpec {
    key: "activity",
    tag: "activity",
    attrs: &[opt("name", Choice(&["update", "sense", "control"]))],
    children: STEPS,
    text: false,
};

pub(super) const STEP_LOCK: ElementSpec = ElementSpec {
    key: "step-lock",
    tag: "lock",
    attrs: &[req("slot", Ident), opt("timeout", Text)],
    children: &[],
    text: false,
};

pub(super) const STEP_UNLOCK: ElementSpec = ElementSpec {
    key: "step-unlock",
    tag: "unlock",
    attrs: &[req("slot", Ident)],
    children: &[],
    text: false,
};

pub(super) const STEP_READ: ElementSpec = ElementSpec {
    key: "step-read",
    tag: "read",
    attrs: &[req("port", Text), opt("timeout", Text)],
    children: &[],
    text: false,
};

pub(super) const STEP_WRITE: ElementSpec = ElementSpec {
    key: "step-write",
    tag: "write",
    attrs: &[
        req("port", Text),
        opt("count", Count),
        opt("optional", Bool),
    ],
    children: &[],
    text: false,
};

pub(super) const STEP_CALL: ElementSpec = ElementSpec {
    key: "step-call",
    tag: "call",
    attrs: &[
        req("client", Ident),
        opt("mode", Choice(&["sync", "async"])),
        opt("timeout", Text),
    ],
    children: &[],
    text: false,
};

pub(super) const STEP_AWAIT: ElementSpec = ElementSpec {
    key: "step-await",
    tag: "await",
    attrs: &[req("client", Ident), opt("timeout", Text)],
    children: &[],
    text: false,
};

pub(super) const DERIVED_ACTIVITY: ElementSpec = ElementSpec {
    key: "derived-activity",
    tag: "derived-activity",
    attrs: &[req("name", Ident)],
    children: &[],
    text: false,
};

pub(super) const CHANNEL_IN: ElementSpec = ElementSpec {
    key: "channel-in",
    tag: "channel-in",
    attrs: &[req("name", Ident), req("type", Text), opt("unit", Text)],
    children: &[],
    text: false,
};

pub(super) const FLEXIBLE: ElementSpec = ElementSpec {
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
};

pub(super) const LIB_GROUP_TYPE: ElementSpec = ElementSpec {
    key: "lib-group-type",
    tag: "group-type",
    attrs: &[req("name", Ident), opt("file", Text)],
    children: GROUP_CONTENT,
    text: false,
};

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
