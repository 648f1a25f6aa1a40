//! X101 `part-without-threads`: A part (process) has no thread container.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "X101",
    name: "part-without-threads",
    severity: Severity::Warning,
    summary: "A part (process) has no thread container.",
    explanation: "A part is an OS process; without a thread container it executes nothing.

Bad:
    <part name=\"station\" host=\"base-pc\"/>

Fix: add a `<thread>` with the modules it should run, or remove the part.",
    pass: None,
    fixtures: "deployment/x101_part_without_threads",
};
