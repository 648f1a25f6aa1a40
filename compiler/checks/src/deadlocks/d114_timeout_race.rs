//! D114 `timeout-race`: Threads can wait for each other in a cycle that only a timeout breaks: a possible stall.
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "D114",
    name: "timeout-race",
    severity: Severity::Note,
    summary:
        "Threads can wait for each other in a cycle that only a timeout breaks: a possible stall.",
    explanation:
        "When two threads call into each other at the same time and one call has a timeout,
they do not deadlock: the timed call gives up. But the threads stall for up to the
timeout and the call fails. This is a note; it becomes a warning when the timeout is at
least the period of a periodic thread container on the cycle (it then overruns).

Bad:
    <client name=\"c\" request=\"f64\" response=\"f64\" timeout=\"20ms\"/>  <!-- a calls b -->
    <!-- and b's update calls a's service without a timeout -->

Fix: make one direction asynchronous, or accept the stall.",
    fixtures: "compiler/checks/src/deadlocks/d114_timeout_race",
};
