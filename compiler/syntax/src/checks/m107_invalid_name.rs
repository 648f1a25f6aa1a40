//! M107 `invalid-name`: A name is not an identifier.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M107",
    name: "invalid-name",
    severity: Severity::Error,
    summary: "A name is not an identifier.",
    explanation:
        "Names of parts, threads, groups, modules, ports, parameters and libraries are identifiers
(`[A-Za-z_][A-Za-z0-9_]*`): they become path segments, Rust identifiers in bundles and file
names on deployment hosts. Spaces, dashes, slashes or non-ASCII letters break one of those.

Bad:
    <module name=\"ir distance\" type=\"std.Constant\"/>

Fix: use `ir_distance`.",
    fixtures: "compiler/syntax/src/checks/m107_invalid_name",
};
