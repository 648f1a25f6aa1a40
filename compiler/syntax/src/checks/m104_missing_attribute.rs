//! M104 `missing-attribute`: A required attribute is missing.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M104",
    name: "missing-attribute",
    severity: Severity::Error,
    summary: "A required attribute is missing.",
    explanation:
        "Some attributes carry the meaning of an element: a `<module>` without `type` cannot be
instantiated, a `<connect>` without `to` connects nothing, an `<allow>` without `reason`
would silence a finding without telling the next reader why.

Bad:
    <module name=\"laser\"/>

Fix: add the attribute: `<module name=\"laser\" type=\"nav.LaserDriver\"/>`.",
    fixtures: "compiler/syntax/src/checks/m104_missing_attribute",
};
