//! M113 `include-outside-root`: An include points outside the model root directory.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M113",
    name: "include-outside-root",
    severity: Severity::Error,
    summary: "An include points outside the model root directory.",
    explanation:
        "`<include href>` is resolved relative to the including file and must stay inside the
directory of the model being checked, so a model from elsewhere cannot make the checker or
the bundler read `../../etc/passwd` or a file on another mount. Absolute paths and `..` that
climb out are refused; symbolic links are followed before the test.

Bad:
    <include href=\"../../etc/passwd\"/>

Fix: keep included fragments under the model's directory, or pass
`--allow-outside-includes` when you trust the model.",
    pass: None,
    fixtures: "model/m113_include_outside_root",
};
