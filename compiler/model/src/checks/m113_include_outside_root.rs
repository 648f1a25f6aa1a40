//! M113 `include-outside-root`: An include or config file points outside the model root directory.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M113",
    name: "include-outside-root",
    severity: Severity::Error,
    summary: "An include or config file points outside the model root directory.",
    explanation:
        "`<include href>` is resolved relative to the including file and must stay inside the
directory of the model being checked, so a model from elsewhere cannot make the checker or
the bundler read `../../etc/passwd` or a file on another mount. Absolute paths and `..` that
climb out are refused; symbolic links are followed before the test. The same rule holds
for `config=\"file.xml#/entry\"` files and for `<use manifest>` files, except that a
manifest outside the directory is read when it is named `*.lib.xml` (written and after
symbolic links): libraries usually sit next to the models.

Bad:
    <include href=\"../../etc/passwd\"/>

Fix: keep included fragments under the model's directory, or pass
`--allow-outside-includes` when you trust the model.",
    fixtures: "compiler/model/src/checks/m113_include_outside_root",
};
