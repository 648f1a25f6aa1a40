//! D107 `full-queue-ring`: A ring of queues with on-full=block that an over-producing member can fill until every writer blocks.
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "D107",
    name: "full-queue-ring",
    severity: Severity::Error,
    summary: "A ring of queues with on-full=block that an over-producing member can fill until every writer blocks.",
    explanation: "When every hop of a ring blocks on a full queue, every thread waits for the next one to
drain its input: an artificial deadlock (Parks 1995). A ring whose members each write
one item per item they read keeps a constant number of items and cannot fill up; a
member that writes more (a free-running periodic writer, a batch write, a second
writer into the ring) can.

Bad (a writes every cycle without reading the ring; all queues block):
    <connect from=\"r/t1/a/out\" to=\"r/t2/b/in\" queue=\"4\" on-full=\"block\"/>
    <connect from=\"r/t2/b/out\" to=\"r/t1/a/back\" queue=\"4\" on-full=\"block\"/>

Fix: make one hop drop instead of block (on-full=\"drop-oldest\"), give a write a
timeout, or make the over-producing member write once per item it reads.",
    fixtures: "compiler/checks/src/deadlocks/d107_full_queue_ring",
};
