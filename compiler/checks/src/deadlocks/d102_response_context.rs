//! D102 `response-context-deadlock`: A synchronous call whose response must be processed by the caller's own, blocked thread container.
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "D102",
    name: "response-context-deadlock",
    severity: Severity::Error,
    summary: "A synchronous call whose response must be processed by the caller's own, blocked thread container.",
    explanation: "With response-via=\"caller\" (ROS 2 callback groups) the response of a call is not handed
to the blocked caller directly: it is a callback that the caller's own thread container
must run. If that container is exclusive, it is busy in the caller, waiting for the
response, and the response is never processed. Where the server runs does not matter.

Bad:
    <client name=\"plan\" request=\"f64\" response=\"f64\" response-via=\"caller\"/>
    <thread name=\"node\" period=\"100ms\"> <module name=\"n\" type=\"ros.Node\"/> </thread>

Fix: run the caller in a thread container with pool=\"2\" or more (a reentrant group),
or call asynchronously.",
    fixtures: "compiler/checks/src/deadlocks/d102_response_context",
};
