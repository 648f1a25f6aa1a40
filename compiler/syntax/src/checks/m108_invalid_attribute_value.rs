//! M108 `invalid-attribute-value`: An attribute value outside what the attribute allows.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M108",
    name: "invalid-attribute-value",
    severity: Severity::Error,
    summary: "An attribute value outside what the attribute allows.",
    explanation:
        "Attributes with a fixed set of values (`on-full`, `dir`, `kind`, booleans, counts) and
attributes with a syntax (`period`, `timeout`) are checked when read. A thread container
needs exactly one of `period` (0 < period <= 60 s) or `trigger=\"data\"`. A part's
`shared-memory-pool` is a size from 64 KiB to 4 GiB (`64 MiB`), its
`shared-memory-threshold` at least 1 byte and at most the pool (docs/zenoh.md).

Bad:
    <thread name=\"main\" period=\"0ms\"/>
    <connect from=\"a/out\" to=\"b/in\" on-full=\"drop\"/>

Fix: use an allowed value (`period=\"10ms\"`, `on-full=\"drop-oldest\"`).",
    fixtures: "compiler/syntax/src/checks/m108_invalid_attribute_value",
};
