//! X105 `bundle-output-collision`: Two parts would write the same files in a bundle.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "X105",
    name: "bundle-output-collision",
    severity: Severity::Error,
    summary: "Two parts would write the same files in a bundle.",
    explanation: "Each part becomes a binary crate, a systemd unit and a launch entry named after it. Names
that differ only in letter case collide on case-insensitive file systems and in unit names.

Bad:
    <part name=\"Robot\"/> <part name=\"robot\"/>

Fix: give the parts names that differ in more than case.",
    pass: None,
    fixtures: "deployment/x105_bundle_output_collision",
};
