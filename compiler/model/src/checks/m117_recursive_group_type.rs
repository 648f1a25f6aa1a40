//! M117 `recursive-group-type`: A group type contains an instance of itself.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M117",
    name: "recursive-group-type",
    severity: Severity::Error,
    summary: "A group type contains an instance of itself.",
    explanation:
        "A group type that instantiates itself, directly or through other group types, would expand
forever.

Bad:
    <group-type name=\"Leg\">
      <group name=\"inner\" type=\"local.Leg\"/>
    </group-type>

Fix: break the recursion; group types form a tree of instances.",
    fixtures: "compiler/model/src/checks/m117_recursive_group_type",
};
