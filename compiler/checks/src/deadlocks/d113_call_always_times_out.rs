//! D113 `call-always-times-out`: A call with a timeout that always times out, because the request chain it starts needs the caller's own thread.
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "D113",
    name: "call-always-times-out",
    severity: Severity::Warning,
    summary: "A call with a timeout that always times out, because the request chain it starts needs the caller's own thread.",
    explanation: "A call with a timeout cannot hang, but if the service it calls (directly or through a
chain of calls) needs the caller's own thread container, which is blocked in the call,
the call times out every single time: the caller never gets a result and its thread
stalls for the whole timeout each time.

Bad (self-call with a timeout):
    <client name=\"map\" request=\"f64\" response=\"f64\" timeout=\"5ms\"/>
    <!-- connected to a service executed by the caller's own thread container -->

Fix: move the server module to another thread container, declare the service
executes=\"caller\", or call asynchronously.",
    fixtures: "compiler/checks/src/deadlocks/d113_call_always_times_out",
};
