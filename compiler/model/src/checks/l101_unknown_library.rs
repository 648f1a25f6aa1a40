//! L101 `unknown-library`: A library is named that cannot be found.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "L101",
    name: "unknown-library",
    severity: Severity::Error,
    summary: "A library is named that cannot be found.",
    explanation:
        "`<use library>` and `<depends library>` without `manifest` are looked up on the library
path (`--lib-path`, `FERROC_LIB_PATH`, then the built-in libraries). A type `lib.Name`
whose `lib` is not loaded at all is reported the same way.

Bad:
    <use library=\"navigation\"/>   <!-- no navigation.lib.xml on the library path -->

Fix: give `manifest=\"path/to/navigation.lib.xml\"` or extend the library path.",
    fixtures: "compiler/model/src/checks/l101_unknown_library",
};
