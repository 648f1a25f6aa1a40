//! M109 `duplicate-name`: Two elements with the same name in one scope.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M109",
    name: "duplicate-name",
    severity: Severity::Error,
    summary: "Two elements with the same name in one scope.",
    explanation:
        "Every named element opens a scope and its name is a path segment, so two children of one
scope with the same name make paths ambiguous. Within one module, port names are unique
across all directions. Group types, resources and flows have one namespace each.

Bad:
    <thread name=\"main\" period=\"10ms\">
      <module name=\"laser\" type=\"nav.LaserDriver\"/>
      <module name=\"laser\" type=\"nav.LaserDriver\"/>
    </thread>

Fix: rename one of them (`laser_front`, `laser_rear`).",
    fixtures: "compiler/model/src/checks/m109_duplicate_name",
};
