//! M103 `unknown-attribute`: An attribute the element does not take.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M103",
    name: "unknown-attribute",
    severity: Severity::Error,
    summary: "An attribute the element does not take.",
    explanation:
        "Unknown attributes are errors: `<connect queu=\"4\">` would otherwise silently give a
latest-value connection instead of a queue. The message lists the attribute the element
takes that is closest to what was written; when the element does not have that attribute
yet, the rest of the model is checked as if it were written (so `perod=\"40ms\"` is this
one finding, not also a thread container without a period).

Bad:
    <connect from=\"a/out\" to=\"b/in\" queu=\"4\"/>

Fix: correct the name (`queue=\"4\"`) or remove the attribute.",
    fixtures: "compiler/syntax/src/checks/m103_unknown_attribute",
};
