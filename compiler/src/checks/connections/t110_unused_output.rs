//! T110 `unused-output`: An output nobody reads.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "T110",
    name: "unused-output",
    severity: Severity::Note,
    summary: "An output nobody reads.",
    explanation: "An output with no connection is computed for nobody. Often that is fine (debug outputs);
sometimes a connection was forgotten.

Example:
    <module name=\"odom\" type=\"nav.Odometry\"/>   <!-- its output `pose` is not connected -->

Nothing to fix when intended; `--allow T110` hides these notes.",
    pass: None,
    fixtures: "connections/t110_unused_output",
};
