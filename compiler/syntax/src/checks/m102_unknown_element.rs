//! M102 `unknown-element`: An element the model language does not know.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M102",
    name: "unknown-element",
    severity: Severity::Error,
    summary: "An element the model language does not know.",
    explanation:
        "Unknown elements are errors, never silently ignored: a misspelt `<conect>` would otherwise
drop a connection without a word. The message suggests the closest known element.

Bad:
    <conect from=\"robot/main/a/out\" to=\"robot/main/b/in\"/>

Fix: use an element of the language (`<connect>`); see docs/model-language.md or `schemas/`.",
    fixtures: "compiler/syntax/src/checks/m102_unknown_element",
};
