//! X104 `pointless-connection-settings`: Connection settings that have no effect where they are used.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "X104",
    name: "pointless-connection-settings",
    severity: Severity::Warning,
    summary: "Connection settings that have no effect where they are used.",
    explanation: "`sharing`, `reliability`, `min-interval` and `period` configure the transport between parts;
inside one part they do nothing. `period` needs `sharing=\"periodic\"`, `min-interval` goes
with `sharing=\"on-change\"`, and a periodic sample of a queue would drop queued items.

Bad:
    <connect from=\"robot/a/x/out\" to=\"robot/b/y/in\" reliability=\"reliable\"/>  <!-- same part -->

Fix: remove the setting, or correct the sharing mode.",
    pass: None,
    fixtures: "deployment/x104_pointless_connection_settings",
};
