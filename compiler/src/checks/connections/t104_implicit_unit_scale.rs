//! T104 `implicit-unit-scale`: A scale between compatible units is inserted.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "T104",
    name: "implicit-unit-scale",
    severity: Severity::Note,
    summary: "A scale between compatible units is inserted.",
    explanation: "When both ends declare units of the same dimension but different scale (`m` and `cm`), the
value is scaled on the connection. This is correct and reported as a note so that the
factor is visible in reviews.

Example:
    <connect from=\"robot/main/sim/ir_front\" to=\"robot/main/viz/distance_cm\"/>  <!-- m → cm: ×100 -->

Nothing to fix; `--allow T104` hides these notes.",
    pass: None,
    fixtures: "connections/t104_implicit_unit_scale",
};
