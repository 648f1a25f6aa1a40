//! L105 `conflicting-library`: Two different manifests define the same library name.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "L105",
    name: "conflicting-library",
    severity: Severity::Error,
    summary: "Two different manifests define the same library name.",
    explanation:
        "A library name must mean one manifest in one check run; otherwise which types a model
gets depends on load order.

Bad:
    <use library=\"nav\" manifest=\"a/nav.lib.xml\"/>  and a dependency reaching b/nav.lib.xml

Fix: point every reference at the same manifest.",
    pass: None,
    fixtures: "libraries/l105_conflicting_library",
};
