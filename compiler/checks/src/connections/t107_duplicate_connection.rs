//! T107 `duplicate-connection`: The same two ports are connected twice.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use hashbrown::HashTable;
use std::hash::BuildHasher;

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
    fixtures: "compiler/checks/src/connections/t107_duplicate_connection",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    // The first connection of each pair of ends, as indices hashed by the ends they
    // name: 4 bytes an entry where a map of key copies and references took 48 (B1: at
    // 100,000 modules it was the largest table of the passes, +14 MiB of peak memory).
    let connections = &ctx.app.connections;
    let key = |i: u32| {
        let c = &connections[i as usize];
        (c.from, c.from_index, c.to, c.to_index)
    };
    let hasher = hashbrown::DefaultHashBuilder::default();
    let mut seen = HashTable::<u32>::with_capacity(connections.len());
    for (i, c) in connections.iter().enumerate() {
        let i = i as u32;
        let hash = hasher.hash_one(key(i));
        let first = match seen.find(hash, |&j| key(j) == key(i)) {
            Some(&j) => &connections[j as usize],
            None => {
                seen.insert_unique(hash, i, |&j| hasher.hash_one(key(j)));
                continue;
            }
        };
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
