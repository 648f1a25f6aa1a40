//! X102 `invalid-host-label`: A `host` is not a valid host name.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "X102",
    name: "invalid-host-label",
    severity: Severity::Error,
    summary: "A `host` is not a valid host name.",
    explanation: "`host` labels become host names in launch scripts and the distributed transport: letters,
digits and `-`, dot-separated labels of at most 63 characters, not starting or ending
with `-`.

Bad:
    <part name=\"robot\" host=\"robot pc\"/>

Fix: `host=\"robot-pc\"`.",
    pass: None,
    fixtures: "deployment/x102_invalid_host_label",
};
