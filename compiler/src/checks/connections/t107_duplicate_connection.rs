//! T107 `duplicate-connection`: The same two ports are connected twice.

use crate::checks::CheckInfo;
use crate::checks::PassContext;
use crate::diagnostic::Severity;
use crate::diagnostic::{Diagnostic, Diagnostics};
use hashbrown::HashMap;

pub static CHECK: CheckInfo = CheckInfo {
    code: "T107",
    name: "duplicate-connection",
    severity: Severity::Warning,
    summary: "The same two ports are connected twice.",
    explanation:
        "A second identical connection adds nothing and usually is a copy-paste slip where another
port was meant.

Bad:
    <connect from=\"robot/main/a/out\" to=\"robot/main/b/in\"/>
    <connect from=\"robot/main/a/out\" to=\"robot/main/b/in\"/>

Fix: delete one, or correct the port it was meant for.",
    pass: Some(run),
    fixtures: "connections/t107_duplicate_connection",
};

fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let mut seen = HashMap::with_capacity(ctx.app.connections.len());
    for c in &ctx.app.connections {
        let key = (c.from, c.from_index, c.to, c.to_index);
        match seen.get(&key) {
            None => {
                seen.insert(key, c);
            }
            Some(first) => {
                if first.span == c.span {
                    continue; // the same <connect> of a group type, in another instance
                }
                out.push(
                    Diagnostic::new(
                        &CHECK,
                        c.span,
                        format!("`{}` is connected twice", super::describe(ctx, c)),
                    )
                    .label("duplicate")
                    .secondary(first.span, "first connection")
                    .help("delete one, or correct the port it was meant for"),
                );
            }
        }
    }
}
