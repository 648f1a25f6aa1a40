//! M118 `unknown-code-in-allow`: An `<allow>` names a code no check has.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M118",
    name: "unknown-code-in-allow",
    severity: Severity::Warning,
    summary: "An `<allow>` names a code no check has.",
    explanation:
        "`<allow code reason>` silences one finding on the element that holds it and everything
inside. A code that no check has silences nothing; usually it is a typo.

Bad:
    <allow code=\"S1O1\" reason=\"intended feedback\"/>

Fix: use a code listed by `ferroc explain --list`.",
    fixtures: "compiler/src/checks/m118_unknown_code_in_allow",
};
