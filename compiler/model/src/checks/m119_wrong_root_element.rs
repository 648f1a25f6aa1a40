//! M119 `wrong-root-element`: The file has the wrong root element for its role.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M119",
    name: "wrong-root-element",
    severity: Severity::Error,
    summary: "The file has the wrong root element for its role.",
    explanation: "A model must have `<application>` as root, an included file `<fragment>`, a library manifest
`<library>`, a config file `<root>`. FINROC files (`<Finstructable>`) are a different
language.

Bad (a model):
    <library name=\"nav\"> ... </library>

Fix: check the file passed to `ferroc check`, or the `href`/`manifest` that names it.",
    fixtures: "compiler/model/src/checks/m119_wrong_root_element",
};
