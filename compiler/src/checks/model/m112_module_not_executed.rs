//! M112 `module-not-executed`: A module with no thread container above it never runs.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M112",
    name: "module-not-executed",
    severity: Severity::Error,
    summary: "A module with no thread container above it never runs.",
    explanation: "A module is executed by the nearest thread container above it. A module placed directly in a
part (or in a group that is not inside a thread) would be instantiated and never updated.

Bad:
    <part name=\"robot\">
      <module name=\"laser\" type=\"nav.LaserDriver\"/>
    </part>

Fix: put it in a thread container: `<thread name=\"main\" period=\"10ms\"> ... </thread>`.",
    pass: None,
    fixtures: "model/m112_module_not_executed",
};
