//! P107 `duplicate-parameter`: The same parameter is set twice on one module.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "P107",
    name: "duplicate-parameter",
    severity: Severity::Error,
    summary: "The same parameter is set twice on one module.",
    explanation: "Two `<param>` elements with the same name leave the reader guessing which applies.

Bad:
    <param name=\"rate\">10 Hz</param>
    <param name=\"rate\">20 Hz</param>

Fix: keep one.",
    pass: None,
    fixtures: "parameters/p107_duplicate_parameter",
};
