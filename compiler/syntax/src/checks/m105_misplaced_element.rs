//! M105 `misplaced-element`: A known element where it may not appear, or text where none is allowed.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M105",
    name: "misplaced-element",
    severity: Severity::Error,
    summary: "A known element where it may not appear, or text where none is allowed.",
    explanation:
        "Elements of the language have fixed places: `<param>` belongs in a `<module>`, `<thread>`
in a `<part>` or a group, `<use>` at the top of the application. An element elsewhere is a
structural mistake (often a missing closing tag earlier).

Bad:
    <part name=\"robot\">
      <param name=\"rate\">10 Hz</param>
    </part>

Fix: move the element to where it belongs (here: into the `<module>` it configures).",
    fixtures: "compiler/syntax/src/checks/m105_misplaced_element",
};
