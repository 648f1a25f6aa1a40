//! T106 `narrowing-without-convert`: A lossy conversion needs an explicit `<convert to-type>`.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_values::types::{compat, Compat};

pub static CHECK: CheckInfo = CheckInfo {
    code: "T106",
    name: "narrowing-without-convert",
    severity: Severity::Error,
    summary: "A lossy conversion needs an explicit `<convert to-type>`.",
    explanation:
        "Narrowing (`f64`→`f32`, `i64`→`i32`), float to integer and sign changes can lose data, so
they must be written down.

Bad:
    <connect from=\"robot/main/nav/speed\" to=\"robot/main/motor/speed_mm\"/>   <!-- f64 → i32 -->

Fix:
    <connect from=\"robot/main/nav/speed\" to=\"robot/main/motor/speed_mm\">
      <convert to-type=\"i32\"/>
    </connect>",
    fixtures: "compiler/checks/src/connections/t106_narrowing_without_convert",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (c, from, to) in ctx.connections_with_ends() {
        let Ok((value, dest)) = super::flow_types(ctx, c, from, to) else {
            continue;
        };
        if compat(&value, &dest) == Compat::NeedsConvert {
            out.push(
                Diagnostic::new(&CHECK, c.to_span, format!("`{value}` into `{dest}` can lose data"))
                    .label(format!("expects `{dest}`"))
                    .secondary(c.from_span, format!("sends `{value}`"))
                    .help(format!("make the conversion explicit: <convert to-type=\"{dest}\"/> inside this <connect>")),
            );
        }
    }
}
