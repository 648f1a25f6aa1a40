//! T102 `incompatible-types`: The types of the two ends are incompatible.
//!
//! Raised by the resolver (where it already knows the types); the pass over every
//! connection is `ferroc_checks::connections::t102_incompatible_types`.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "T102",
    name: "incompatible-types",
    severity: Severity::Error,
    summary: "The types of the two ends are incompatible.",
    explanation:
        "A connection is accepted when the types are identical, losslessly widening (`i32`→`i64`,
`f32`→`f64`, `u16`→`f32`), or made compatible by an explicit `<convert>` chain. Anything else
would reinterpret data. The message names both types and suggests the conversion that
would work.

Bad:
    <connect from=\"robot/main/gps/fix_valid\" to=\"robot/main/ctrl/speed\"/>   <!-- bool → f64 -->

Fix: connect the right ports, or add a conversion module.",
    fixtures: "compiler/model/src/checks/t102_incompatible_types",
};
