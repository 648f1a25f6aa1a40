//! X103 `host-label-conflict`: Host labels that differ only in letter case.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "X103",
    name: "host-label-conflict",
    severity: Severity::Warning,
    summary: "Host labels that differ only in letter case.",
    explanation: "Host names are case-insensitive, so `Robot-PC` and `robot-pc` are one machine, yet the
bundle would treat them as two. Usually one of them is a typo.

Bad:
    <part name=\"a\" host=\"Robot-PC\"/>
    <part name=\"b\" host=\"robot-pc\"/>

Fix: write the host label the same way everywhere.",
    pass: None,
    fixtures: "deployment/x103_host_label_conflict",
};
