//! T111 `not-serialisable-across-parts`: A connection between parts carries a type that cannot be serialised.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "T111",
    name: "not-serialisable-across-parts",
    severity: Severity::Error,
    summary: "A connection between parts carries a type that cannot be serialised.",
    explanation: "Parts are separate processes, possibly on separate hosts: data between them is serialised.
A library type declared without `serde=\"true\"` cannot cross.

Bad:
    <connect from=\"robot/main/cam/image_view\" to=\"station/ui/viewer/image\"/>  <!-- type has serde=\"false\" -->

Fix: connect a serialisable type, or move both modules into one part.",
    pass: None,
    fixtures: "connections/t111_not_serialisable_across_parts",
};
