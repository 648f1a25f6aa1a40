//! D112 `deadlock-unverified`: Wait-states that can block each other in a cycle, whose consistency the bounded search could not establish.
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "D112",
    name: "deadlock-unverified",
    severity: Severity::Warning,
    summary: "Wait-states that can block each other in a cycle, whose consistency the bounded search could not establish.",
    explanation: "The deadlock search is linear except for the search for a consistent witness inside
each strongly connected set of waits, which is capped (a budget of node expansions and
at most 12 threads per cycle). When the cap cuts the search short, ferroc does not stay
silent: it shows the shortest cycle without checking it, as a warning.

Bad: thousands of modules taking pairs of 2000 locks, in an order whose cycles are all
longer than 12 steps:
    <activity><lock slot=\"l0\"/><lock slot=\"l1\"/></activity>   <!-- l1 l2, l2 l3, ... -->

Fix: simplify the lock structure (a global order), or check the cycle shown by hand.",
    fixtures: "compiler/checks/src/deadlocks/d112_deadlock_unverified",
};
