//! P102 `missing-required-parameter`: A required parameter has no value.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "P102",
    name: "missing-required-parameter",
    severity: Severity::Error,
    summary: "A required parameter has no value.",
    explanation: "Parameters declared `required=\"true\"` have no sensible default (a device path, a map file).

Bad:
    <module name=\"laser\" type=\"nav.LaserDriver\"/>   <!-- `device` is required -->

Fix: add `<param name=\"device\">/dev/ttyUSB0</param>`, or give it from a config file
(`config=`) or the command line (`cmdline=`).",
    pass: None,
    fixtures: "parameters/p102_missing_required_parameter",
};
