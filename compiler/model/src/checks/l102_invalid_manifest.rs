//! L102 `invalid-manifest`: A library manifest is missing, unreadable, or not the library it claims.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "L102",
    name: "invalid-manifest",
    severity: Severity::Error,
    summary: "A library manifest is missing, unreadable, or not the library it claims.",
    explanation: "A manifest named by `manifest=` must exist, have root `<library>`, and its `name` must be
the library that was asked for.

Bad:
    <use library=\"nav\" manifest=\"../components/navigation.lib.xml\"/>  <!-- file says name=\"navigation\" -->

Fix: correct the path or the library name.",
    fixtures: "compiler/model/src/checks/l102_invalid_manifest",
};
