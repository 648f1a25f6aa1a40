//! T101 `wrong-direction`: A connection goes from something that does not emit to something that does not accept.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "T101",
    name: "wrong-direction",
    severity: Severity::Error,
    summary: "A connection goes from something that does not emit to something that does not accept.",
    explanation: "Data flows from an output (or a group's input, seen from inside) to an input (or a group's
output, seen from inside). Connecting two inputs or two outputs is a mistake in the path or
in the direction of the `<connect>`.

Bad:
    <connect from=\"robot/main/controller/velocity_in\" to=\"robot/main/motor/speed\"/>

Fix: swap `from` and `to`, or correct the port name.",
    pass: None,
    fixtures: "connections/t101_wrong_direction",
};
