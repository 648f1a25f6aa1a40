//! D108 `pool-exhaustion`: Nested synchronous calls inside a worker pool can park every worker (thread-starvation deadlock).
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "D108",
    name: "pool-exhaustion",
    severity: Severity::Error,
    summary: "Nested synchronous calls inside a worker pool can park every worker (thread-starvation deadlock).",
    explanation: "A thread container with pool=\"n\" runs services on n workers. A service that calls
another service of the same pool synchronously parks its worker until a second worker
is free. When the callers from outside can park n workers at once, no worker is left
and they all wait (Goetz, Java Concurrency in Practice §8.1.1).

Bad (two exclusive callers, a chain s -> t inside a pool of 2):
    <thread name=\"srv\" trigger=\"data\" pool=\"2\"> <module name=\"s\" type=\"x.Server\"/> </thread>

Fix: give the pool more workers than the calls that can park in it, or make the nested
call asynchronous or inline (executes=\"caller\").",
    fixtures: "compiler/checks/src/deadlocks/d108_pool_exhaustion",
};
