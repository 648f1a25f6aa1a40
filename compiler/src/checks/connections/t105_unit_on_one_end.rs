//! T105 `unit-on-one-end`: Only one end of a connection declares a unit.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "T105",
    name: "unit-on-one-end",
    severity: Severity::Warning,
    summary: "Only one end of a connection declares a unit.",
    explanation: "When one end says `m` and the other says nothing, the checker cannot tell whether the
consumer expects metres. Usually the unit-less port was declared carelessly.

Bad:
    <connect from=\"robot/main/sim/ir_front\" to=\"robot/main/dump/in/0\"/>  <!-- m → unit-less -->

Fix: declare the unit on the other port, or add an `<allow code=\"T105\" reason=\"...\"/>`.",
    pass: None,
    fixtures: "connections/t105_unit_on_one_end",
};
