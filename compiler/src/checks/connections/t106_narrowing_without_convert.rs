//! T106 `narrowing-without-convert`: A lossy conversion needs an explicit `<convert to-type>`.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "T106",
    name: "narrowing-without-convert",
    severity: Severity::Error,
    summary: "A lossy conversion needs an explicit `<convert to-type>`.",
    explanation: "Narrowing (`f64`→`f32`, `i64`→`i32`), float to integer and sign changes can lose data, so
they must be written down.

Bad:
    <connect from=\"robot/main/nav/speed\" to=\"robot/main/motor/speed_mm\"/>   <!-- f64 → i32 -->

Fix:
    <connect from=\"robot/main/nav/speed\" to=\"robot/main/motor/speed_mm\">
      <convert to-type=\"i32\"/>
    </connect>",
    pass: None,
    fixtures: "connections/t106_narrowing_without_convert",
};
