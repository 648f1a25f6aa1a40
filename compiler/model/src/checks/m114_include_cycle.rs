//! M114 `include-cycle`: Files include each other in a cycle.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M114",
    name: "include-cycle",
    severity: Severity::Error,
    summary: "Files include each other in a cycle.",
    explanation:
        "An include cycle would be read forever. The finding names the include that closes the
cycle and the include where the cycle started.

Bad (a.xml):
    <include href=\"b.xml\"/>    <!-- and b.xml includes a.xml -->

Fix: move shared group types into a third fragment that both include.",
    fixtures: "compiler/model/src/checks/m114_include_cycle",
};
