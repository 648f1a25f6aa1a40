//! D101 `call-cycle`: Synchronous calls wait for each other in a cycle (including a call into the caller's own thread container).
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "D101",
    name: "call-cycle",
    severity: Severity::Error,
    summary: "Synchronous calls wait for each other in a cycle (including a call into the caller's own thread container).",
    explanation: "A thread container runs one thing at a time. A synchronous call without a timeout into
a service executed by thread container Y waits until Y runs the service; if Y is the
caller's own container (a self-call), or Y is itself blocked in a call back into the
caller's container (A -> B -> A), nobody ever runs the service and both threads hang.
ferroc treats every thread container as a lock its activities hold; a call is taking
that lock, so a call cycle is a lock-order cycle across threads.

Bad (Planner and Map share thread container `main`):
    <thread name=\"main\" period=\"20ms\">
      <module name=\"planner\" type=\"nav.Planner\"/>   <!-- <client name=\"map\"/> -->
      <module name=\"map\" type=\"nav.MapServer\"/>     <!-- <service name=\"get\"/> -->
    </thread>
    <connect from=\"robot/main/planner/map\" to=\"robot/main/map/get\"/>

Fix: move the server module to another thread container, declare the service
executes=\"caller\" (it then runs inline in the caller's thread), call asynchronously
(<call client=\"map\" mode=\"async\"/>), or add a timeout (the call then always times
out: D113).",
    fixtures: "compiler/checks/src/deadlocks/d101_call_cycle",
};

/// The pass of every D check: the analysis runs once, here.
pub(crate) use super::run;
