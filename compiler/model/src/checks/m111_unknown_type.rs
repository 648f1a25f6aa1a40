//! M111 `unknown-type`: A module type, group type or data type that no library defines.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M111",
    name: "unknown-type",
    severity: Severity::Error,
    summary: "A module type, group type or data type that no library defines.",
    explanation:
        "Types are referred to as `library.Type` (`local.Name` for group types of this file and its
includes); data types are built-in (`f64`, `u8[4]`, `[f64]`, …) or come from a library.

Bad:
    <module name=\"laser\" type=\"nav.LaserDrivr\"/>

Fix: correct the name (the message suggests the closest type of that library) or `<use>` the
library that defines it.",
    fixtures: "compiler/model/src/checks/m111_unknown_type",
};
