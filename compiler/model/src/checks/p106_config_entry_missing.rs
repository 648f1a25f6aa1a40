//! P106 `config-entry-missing`: A `config=` reference points to a missing file or entry.
//!
//! Raised by the resolver when it reads the config file (`resolve/module.rs`).

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "P106",
    name: "config-entry-missing",
    severity: Severity::Error,
    summary: "A `config=` reference points to a missing file or entry.",
    explanation:
        "`config=\"etc/robot.xml#/noise/level\"` reads the value from a FINROC-style config file
(`<root>`, `<node name>` branches, `<value name>` leaves), relative to the model file. A
missing file or entry would leave the parameter unset at start-up.

Bad:
    <param name=\"standard_deviation\" config=\"etc/robot.xml#/noise/levl\"/>

Fix: correct the pointer or add the entry to the config file.",
    fixtures: "compiler/model/src/checks/p106_config_entry_missing",
};
