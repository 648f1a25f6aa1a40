//! P104 `out-of-range`: A parameter value lies outside the declared `min`/`max`.
//!
//! Raised by the value pass in `p103_unparsable_value.rs` (one parse, three verdicts).

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "P104",
    name: "out-of-range",
    severity: Severity::Error,
    summary: "A parameter value lies outside the declared `min`/`max`.",
    explanation:
        "Module types declare the range their logic supports; values outside it would be clamped
or crash at run time. The comparison is made after unit conversion.

Bad:
    <param name=\"rate\">500 Hz</param>   <!-- declared max=\"100\" -->

Fix: use a value within the range.",
    fixtures: "compiler/model/src/checks/p104_out_of_range",
};
