//! M115 `file-not-found`: A referenced file cannot be read.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

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
    pass: None,
    fixtures: "model/m115_file_not_found",
};
