//! M110 `unresolved-path`: A path names no element, port or parameter.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M110",
    name: "unresolved-path",
    severity: Severity::Error,
    summary: "A path names no element, port or parameter.",
    explanation:
        "Paths in `<connect>` and `<flow>` are names from the enclosing scope down to a port,
joined by `/` (threads are segments too); inside a group they are relative to the group and
the group's own ports are bare names. A path that does not resolve would leave the
connection out of the running system.

Bad:
    <connect from=\"robot/control/lasr/scan\" to=\"robot/control/nav/scan\"/>

Fix: correct the path; the message shows how far it resolved and suggests a close name.",
    fixtures: "compiler/model/src/checks/m110_unresolved_path",
};
