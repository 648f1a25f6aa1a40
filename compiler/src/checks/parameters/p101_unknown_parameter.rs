//! P101 `unknown-parameter`: A `<param>` the module type does not declare.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "P101",
    name: "unknown-parameter",
    severity: Severity::Error,
    summary: "A `<param>` the module type does not declare.",
    explanation: "Parameter names come from the module type. A misspelt name would leave the real parameter
at its default.

Bad:
    <module name=\"laser\" type=\"nav.LaserDriver\"><param name=\"rte\">20 Hz</param></module>

Fix: use a declared name (the message suggests the closest).",
    pass: None,
    fixtures: "parameters/p101_unknown_parameter",
};
