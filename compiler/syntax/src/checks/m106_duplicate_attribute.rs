//! M106 `duplicate-attribute`: The same attribute appears twice on one element.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M106",
    name: "duplicate-attribute",
    severity: Severity::Error,
    summary: "The same attribute appears twice on one element.",
    explanation:
        "XML forbids an attribute twice on one element, and tools that read such files anyway disagree
about which value wins: one would run the thread at 10 ms, another at 20 ms. ferroc reports
both places instead of picking one.

Bad:
    <thread name=\"main\" period=\"10ms\" period=\"20ms\"/>

Fix: keep one of them.",
    fixtures: "compiler/syntax/src/checks/m106_duplicate_attribute",
};
