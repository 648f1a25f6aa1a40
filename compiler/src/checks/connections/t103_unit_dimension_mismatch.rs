//! T103 `unit-dimension-mismatch`: The two ends carry units of different physical dimensions.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "T103",
    name: "unit-dimension-mismatch",
    severity: Severity::Error,
    summary: "The two ends carry units of different physical dimensions.",
    explanation: "Units of the same dimension are scaled automatically (`m`→`mm`). Units of different
dimensions (`m` and `m/s`, `rad` and `m`) mean the connection is wrong: a distance fed into
a speed input.

Bad:
    <connect from=\"robot/main/odom/distance\" to=\"robot/main/ctrl/velocity\"/>  <!-- m → m/s -->

Fix: connect the port that carries the right quantity.",
    pass: None,
    fixtures: "connections/t103_unit_dimension_mismatch",
};
