//! P105 `wrong-unit-dimension`: A parameter value carries a unit of another dimension.
//!
//! Raised by the value pass in `p103_unparsable_value.rs` (one parse, three verdicts).

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "P105",
    name: "wrong-unit-dimension",
    severity: Severity::Error,
    summary: "A parameter value carries a unit of another dimension.",
    explanation:
        "A value in a compatible unit is converted (`15 cm` for a parameter in `m`). A value in
another dimension is wrong, and so is a unit on a parameter that declares none.

Bad:
    <param name=\"safety_distance\">0.3 s</param>   <!-- declared unit=\"m\" -->

Fix: write the value in a unit of the declared dimension.",
    fixtures: "compiler/model/src/checks/p105_wrong_unit_dimension",
};
