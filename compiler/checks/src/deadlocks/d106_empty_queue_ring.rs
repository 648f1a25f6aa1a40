//! D106 `empty-queue-ring`: A ring of blocking reads with no item in it: every member waits for the previous one (Kahn deadlock).
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "D106",
    name: "empty-queue-ring",
    severity: Severity::Error,
    summary: "A ring of blocking reads with no item in it: every member waits for the previous one (Kahn deadlock).",
    explanation: "Modules that each block reading a queue fed by the previous module of a ring wait
forever when the ring holds no item: nobody can produce the first one. In a marked
graph (Commoner et al. 1971) a ring is live exactly when it holds at least one token;
ferroc counts the initial items (initial=\"k\" on a <connect>) and writes made before the
blocking read in the same activation.

Bad:
    <connect from=\"p1/t1/a/out\" to=\"p2/t2/b/in\" queue=\"4\"/>
    <connect from=\"p2/t2/b/out\" to=\"p1/t1/a/in\" queue=\"4\"/>   <!-- both read blocking -->

Fix: add initial=\"1\" to one <connect> of the ring, or let one member write before it
reads.",
    fixtures: "compiler/checks/src/deadlocks/d106_empty_queue_ring",
};
