//! T107 `duplicate-connection`: The same two ports are connected twice.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "T107",
    name: "duplicate-connection",
    severity: Severity::Warning,
    summary: "The same two ports are connected twice.",
    explanation: "A second identical connection adds nothing and usually is a copy-paste slip where another
port was meant.

Bad:
    <connect from=\"robot/main/a/out\" to=\"robot/main/b/in\"/>
    <connect from=\"robot/main/a/out\" to=\"robot/main/b/in\"/>

Fix: delete one, or correct the port it was meant for.",
    pass: None,
    fixtures: "connections/t107_duplicate_connection",
};
