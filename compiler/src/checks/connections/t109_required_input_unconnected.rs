//! T109 `required-input-unconnected`: An input declared `required="true"` has no connection.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "T109",
    name: "required-input-unconnected",
    severity: Severity::Error,
    summary: "An input declared `required=\"true\"` has no connection.",
    explanation: "A module type declares `required=\"true\"` on inputs it cannot work without. Such a module
would wait or compute garbage forever.

Bad:
    <module name=\"loc\" type=\"nav.Localizer\"/>   <!-- its required input `scan` is never connected -->

Fix: connect the input.",
    pass: None,
    fixtures: "connections/t109_required_input_unconnected",
};
