//! M115 `file-not-found`: A referenced file cannot be read.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M115",
    name: "file-not-found",
    severity: Severity::Error,
    summary: "A referenced file cannot be read.",
    explanation:
        "Includes and config files are read relative to the file that names them. A missing file
or one that is not UTF-8 text is reported at the attribute that names it.

Bad:
    <include href=\"groups/naviagtion.xml\"/>

Fix: correct the path.",
    fixtures: "compiler/model/src/checks/m115_file_not_found",
};
