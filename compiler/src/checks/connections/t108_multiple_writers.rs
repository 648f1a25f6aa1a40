//! T108 `multiple-writers`: Several connections write into one latest-value input.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "T108",
    name: "multiple-writers",
    severity: Severity::Warning,
    summary: "Several connections write into one latest-value input.",
    explanation: "A latest-value input keeps only the newest value; with two writers the last writer wins and
the consumer sees an arbitrary interleaving. Queues (`queue=\"N\"`) and inputs declared
`fan-in=\"merge\"` accept several writers by design.

Bad:
    <connect from=\"robot/main/joystick/speed\" to=\"robot/main/motor/speed\"/>
    <connect from=\"robot/main/planner/speed\" to=\"robot/main/motor/speed\"/>

Fix: add an arbitration module (e.g. `ferroc_std.FlexiSelect`) or make the input a queue.",
    pass: None,
    fixtures: "connections/t108_multiple_writers",
};
