//! P103 `unparsable-value`: A parameter value does not parse as its declared type.
//!
//! Raised by the resolver (where it already knows the types); the pass over every
//! connection is `ferroc_checks::parameters::p103_unparsable_value`.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "P103",
    name: "unparsable-value",
    severity: Severity::Error,
    summary: "A parameter value does not parse as its declared type.",
    explanation:
        "Values are parsed by the declared type: numbers (with optional unit), `true`/`false`,
durations (`10ms`, `PT0.04S`), arrays (`1, 2, 3`), or one of the declared `choices`.

Bad:
    <param name=\"rate\">fast</param>

Fix: write a value of the declared type (`20 Hz`).",
    fixtures: "compiler/model/src/checks/p103_unparsable_value",
};
