//! D105 `mixed-wait-cycle`: A deadlock cycle mixing locks with calls or blocking queues (a lock held across a blocking step).
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "D105",
    name: "mixed-wait-cycle",
    severity: Severity::Error,
    summary: "A deadlock cycle mixing locks with calls or blocking queues (a lock held across a blocking step).",
    explanation: "A lock held across a blocking call or a blocking queue write is a classic deadlock: the
thread that would end the wait (run the service, drain the queue) first needs the lock.

Bad (arm holds can_bus while it calls the gripper, whose service takes can_bus):
    <activity><lock slot=\"can_bus\"/><call client=\"query\"/></activity>
    <service name=\"query\" request=\"f64\" response=\"f64\"><lock slot=\"can_bus\"/></service>

Fix: release the lock before the blocking step, give that step a timeout, or make the
queue drop when full (on-full=\"drop-oldest\").",
    fixtures: "compiler/checks/src/deadlocks/d105_mixed_wait_cycle",
};
