//! L104 `library-not-used`: A type comes from a library the file does not `<use>` (or depend on).

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "L104",
    name: "library-not-used",
    severity: Severity::Error,
    summary: "A type comes from a library the file does not `<use>` (or depend on).",
    explanation:
        "An application may use types only from libraries it `<use>`s; a library only from itself
and what it `<depends>` on. Relying on a library that is loaded only because some other
library depends on it breaks when that dependency changes.

Bad:
    <use library=\"nav\"/>            <!-- nav depends on geometry -->
    <module name=\"t\" type=\"geometry.Transform\"/>

Fix: add `<use library=\"geometry\"/>`.",
    fixtures: "compiler/model/src/checks/l104_library_not_used",
};
