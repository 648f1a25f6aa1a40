//! L105 `conflicting-library`: Two different manifests define the same library name.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

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
    fixtures: "compiler/model/src/checks/l105_conflicting_library",
};
